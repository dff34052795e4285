"""Debonded interfaces (issue 20): the config key and option, the 1-D rear face and the crater
at an interface, each against an independent closed form; the bonded default unchanged."""

import json
import math
import tomllib

import numpy as np
import pytest
from scipy.optimize import brentq

from cavex.analytic.cavity import cavity_stress
from cavex.analytic.penetration.integrator import crater_stage, penetrate
from cavex.analytic.penetration.nose import nose_rule
from cavex.analytic.penetration.resistance import ClosedFormResistance, make_resistance
from cavex.analytic.penetration.zones import crater_depth, open_zones, scab_depth
from cavex.config import config_text, default_config_text, fingerprint, load_config, parse_config
from cavex.errors import CavexInputError
from cavex.materials import Projectile
from cavex.verification.cli import main


@pytest.fixture(scope="module")
def default():
    return load_config()


@pytest.fixture(scope="module")
def debonded(default):
    target, projectile = default
    return target.with_interfaces("debonded"), projectile


@pytest.fixture(scope="module")
def flight(debonded):
    target, projectile = debonded
    return penetrate(target, projectile, make_resistance(target, projectile))


def _config(**bottom_keys):
    data = tomllib.loads(default_config_text())
    for i, keys in bottom_keys.items():
        data["layers"][int(i[1:])].update(keys)
    return data


# --- the config key and the option ---------------------------------------------------------

def test_bottom_key_default_bonded_and_round_trip(default):
    target, projectile = default
    assert target.bottoms == ("bonded", "bonded") and target.debonded == ()
    data = _config(l0={"bottom": "debonded", "scab_depth": 0.08})
    mixed, _ = parse_config(data)
    assert mixed.bottoms == ("debonded", "bonded") and mixed.debonded == (0,)
    assert scab_depth(mixed, projectile, 0) == 0.08
    assert scab_depth(mixed.with_interfaces("debonded"), projectile, 1) == pytest.approx(
        2.12 * 2 * projectile.r, rel=1e-15)
    again, _ = parse_config(tomllib.loads(config_text(mixed, projectile)))
    assert again == mixed
    # the bonded default writes no new key: the fingerprints of bonded targets are unchanged
    assert "bottom" not in config_text(target, projectile)
    assert fingerprint(target, projectile) != fingerprint(mixed, projectile)


@pytest.mark.parametrize(("keys", "where", "what"), [
    ({"l2": {"bottom": "debonded"}}, "layers[2].bottom", "must be absent"),
    ({"l2": {"scab_depth": 0.05}}, "layers[2].scab_depth", "must be absent"),
    ({"l0": {"bottom": "glued"}}, "layers[0].bottom", "one of bonded, debonded"),
    ({"l0": {"bottom": 1}}, "layers[0].bottom", "a string"),
    ({"l0": {"scab_depth": 0.7}}, "layers[0].scab_depth", "in (0, 0.65) m"),
    ({"l1": {"scab_depth": -1.0}}, "layers[1].scab_depth", "in (0, 0.45) m"),
])
def test_bad_bottom_keys_refused(keys, where, what):
    with pytest.raises(CavexInputError) as error:
        parse_config(_config(**keys))
    assert where in str(error.value) and what in str(error.value)


def test_interfaces_option_refusals(capsys, tmp_path):
    code = main(["penetrate", "--interfaces", "debonded", "--resistance", "paper", "--out",
                 str(tmp_path / "a")])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "--resistance derived" in err and not (tmp_path / "a").exists()
    code = main(["penetrate", "--interfaces", "glued", "--out", str(tmp_path / "b")])
    assert code == 2 and "--interfaces" in capsys.readouterr().err
    bad = tmp_path / "bad.toml"
    bad.write_text(default_config_text().replace('name = "soil"', 'name = "soil"\nbottom = '
                                                 '"debonded"'))
    code = main(["penetrate", "--config", str(bad), "--out", str(tmp_path / "c")])
    out, err = capsys.readouterr()
    assert code == 2 and "layers[2].bottom" in err and len(err.strip().splitlines()) == 1


# --- 1-D: the rear face against the finite sphere, the crater against the entry's ----------

@pytest.mark.parametrize("depth", [0.3, 0.6, 0.64])
@pytest.mark.parametrize("boundary", ["dynamic", "quasi-static"])
def test_rear_face_force_is_the_finite_sphere(debonded, depth, boundary):
    """Above a debonded interface the nose force is the ogive quadrature of the one-layer
    cavity cut by the traction-free sphere c = H - L + l (cavity_stress with free_radius)."""
    target, projectile = debonded
    resistance = ClosedFormResistance(target, projectile, "derived", boundary)
    cosines, weights = nose_rule(projectile)
    velocity = 640.0
    c = target.interface_depths[0] - depth + projectile.l
    sigma = cavity_stress(target.layers[:1], np.empty((cosines.size, 0)), velocity * cosines,
                          projectile.r, boundary=boundary, free_radius=c)
    expected = float(np.sum(weights * sigma))
    assert resistance.force(depth, velocity) == pytest.approx(expected, rel=1e-12)
    bonded = ClosedFormResistance(target.with_interfaces("bonded"), projectile, "derived",
                                  boundary)
    assert resistance.force(depth, velocity) < bonded.force(depth, velocity)


def test_interface_crater_is_the_entry_crater_of_the_layer_below(flight, debonded):
    """The crater stage below a debonded interface: the closed form of Eqs. 31-34 for the
    layer below alone, started at the interface with the velocity the nose tip reaches it at
    (solved here by brentq on m (V_H^2 - V_c^2) = L_c F(V_c) independently)."""
    target, projectile = debonded
    H = target.interface_depths[0]
    phases = flight.phases
    k = next(i for i, p in enumerate(phases) if p.stage == "crater" and i > 0)
    before, crater = phases[k - 1], phases[k]
    assert before.end_depth == pytest.approx(H, rel=1e-12)
    assert before.end_reason == "nose tip reached interface 1 (debonded)"
    macadam = ClosedFormResistance(target.single(1), projectile)
    lc = crater_depth(projectile)
    vh = before.end_velocity
    vc = brentq(lambda v: projectile.m * (vh ** 2 - v ** 2) - lc * macadam.force(0.0, v),
                0.0, vh, xtol=1e-13)
    stiffness = projectile.m * (vh ** 2 - vc ** 2) / lc ** 2
    omega = math.sqrt(stiffness / projectile.m)
    assert crater.end_velocity == pytest.approx(vc, rel=1e-10)
    assert crater.end_depth == pytest.approx(H + lc, rel=1e-14)
    assert crater.end_time - before.end_time == pytest.approx(math.acos(vc / vh) / omega,
                                                              rel=1e-10)
    # the samples: L = H + V_H/omega sin(omega (t - t_H)), a = K (L - H) / m
    inside = flight.phase == k
    t, depth = flight.t[inside], flight.depth[inside]
    assert np.allclose(depth[1:-1], H + vh / omega * np.sin(omega * (t[1:-1] - before.end_time)),
                       rtol=1e-12, atol=0)
    assert np.allclose(flight.deceleration[inside], stiffness * (depth - H) / projectile.m,
                       rtol=1e-9, atol=1e-6)
    # and the entry crater of macadam alone struck at V_H is the same stage
    alone = Projectile(r=projectile.r, l=projectile.l, R=projectile.R, m=projectile.m, V0=vh)
    _, t_entry, v_entry = crater_stage(alone, macadam.crater_force, lc)
    assert v_entry == pytest.approx(crater.end_velocity, rel=1e-13)
    assert t_entry == pytest.approx(crater.end_time - before.end_time, rel=1e-9)


def test_debonded_phases_and_stages(flight, debonded):
    target, projectile = debonded
    stages = [p.stage for p in flight.phases]
    assert stages[0] == "crater" and stages.count("crater") == 3
    reasons = [p.end_reason for p in flight.phases]
    for j, H in enumerate(target.interface_depths):
        top = H - scab_depth(target, projectile, j)
        at_top = reasons.index(f"nose tip reached the rear zone of interface {j + 1}")
        assert flight.phases[at_top].end_depth == pytest.approx(top, rel=1e-12)
        at_h = reasons.index(f"nose tip reached interface {j + 1} (debonded)")
        assert all(p.stage == "rear face" for p in flight.phases[at_top + 1:at_h + 1])
        assert flight.phases[at_h + 1].stage == "crater"
    assert flight.phases[-1].end_velocity == 0.0
    # velocity never rises; depth never falls
    assert np.all(np.diff(flight.depth) >= 0.0) and np.all(np.diff(flight.velocity) <= 1e-9)


def test_penetrate_json_lists_stages(capsys, tmp_path):
    code = main(["penetrate", "--interfaces", "debonded", "--json", "--out", str(tmp_path)])
    out, _ = capsys.readouterr()
    assert code == 0
    document = json.loads(out)
    assert [i["bottom"] for i in document["interfaces"]] == ["debonded", "debonded"]
    assert {p["stage"] for p in document["phases"]} == {"crater", "tunnel", "rear face"}
    assert "stage" in (tmp_path / "phases_runway.csv").read_text().splitlines()[0]


def test_zones_of_the_3d_model(debonded):
    target, projectile = debonded
    zones = open_zones(target, projectile)
    lc, s = crater_depth(projectile), 2.12 * 2 * projectile.r
    expected = []
    for H in target.interface_depths:
        expected += [(H - s, H), (H, H + lc)]
    assert np.allclose(zones, expected, rtol=1e-15)
    assert open_zones(target.with_interfaces("bonded"), projectile) == []
