"""Debonded interfaces (issue 20): the config key and option, the 1-D rear face and the crater
at an interface, each against an independent closed form; the bonded default unchanged."""

import json
import math
import tomllib

import numpy as np
import pytest
from scipy.optimize import brentq

from cavex.analytic.cavity import cavity_stress
from cavex.analytic.models import make_resistance
from cavex.analytic.penetration.integrator import crater_stage, penetrate
from cavex.analytic.penetration.nose import nose_rule
from cavex.analytic.penetration.resistance import ClosedFormResistance
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
    assert "stage" in (tmp_path / "phases_target.csv").read_text().splitlines()[0]


def test_zones_of_the_3d_model(debonded):
    target, projectile = debonded
    zones = open_zones(target, projectile)
    lc, s = crater_depth(projectile), 2.12 * 2 * projectile.r
    expected = []
    for H in target.interface_depths:
        expected += [(H - s, H), (H, H + lc)]
    assert np.allclose(zones, expected, rtol=1e-15)
    assert open_zones(target.with_interfaces("bonded"), projectile) == []


# --- 3-D: the stress law's open faces, the zones as events, mirror and work-energy ----------

def _open_ray_problem(target, radius, z, nz):
    """The spherical problem of an element at depth ``z`` with normal ``n_z``, derived here
    independently: the layers met along the normal up to the first traction-free face (a
    debonded interface, the free surface), each interface at ``radius +`` its distance along
    the normal, the face as the free sphere."""
    layers, depths = target.layers, target.interface_depths
    own = target.layer_at(z)
    sequence, radii, free = [layers[own]], [], None
    if nz > 1e-12:
        for j in range(own, len(depths)):
            distance = radius + min((depths[j] - z) / nz, 1e6)
            if target.bottoms[j] == "debonded":
                free = radius + (depths[j] - z) / nz
                break
            radii.append(distance)
            sequence.append(layers[j + 1])
    elif nz < -1e-12:
        free = radius + z / -nz
        for j in range(own - 1, -1, -1):
            if target.bottoms[j] == "debonded":
                free = radius + (z - depths[j]) / -nz
                break
            radii.append(radius + min((z - depths[j]) / -nz, 1e6))
            sequence.append(layers[j])
    return tuple(sequence), radii, free


@pytest.mark.parametrize("bottoms", [("debonded", "debonded"), ("debonded", "bonded"),
                                     ("bonded", "debonded")])
def test_derived_law_sees_the_open_faces_element_by_element(default, bottoms):
    from cavex.analytic.penetration.stress_laws import DerivedLaw
    from cavex.materials import Target

    target, projectile = default
    target = Target(target.layers, target.thicknesses, bottoms)
    law = DerivedLaw(target, projectile.r, "dynamic", free_surface=True)
    rng = np.random.default_rng(5)
    n = 300
    z = rng.uniform(0.001, 1.6, n)
    normals = rng.normal(size=(n, 3))
    normals[:10, 2] = 0.0
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    vn = rng.uniform(0.0, 900.0, n)
    sigma = law.stress(z, normals, vn)
    for i in range(n):
        layers, radii, free = _open_ray_problem(target, projectile.r, z[i], normals[i, 2])
        ref = cavity_stress(layers, radii, vn[i], projectile.r, boundary="dynamic",
                            free_radius=free)
        assert sigma[i] == pytest.approx(ref, rel=1e-14)



@pytest.fixture(scope="module")
def oblique_pair(debonded):
    from cavex.analytic.models import fly
    from cavex.analytic.penetration.oblique import Strike

    target, projectile = debonded
    runs = {}
    for ramp in (0.01, 0.003):
        for name, t in (("bonded", target.with_interfaces("bonded")), ("debonded", target)):
            runs[name, ramp] = fly(t, projectile, Strike(600.0, 20.0), contact_ramp=ramp)
    return runs


def _turn_after(result, interface=1):
    k = next(i for i, p in enumerate(result.phases)
             if p["end_reason"].startswith(f"nose tip crossed interface {interface}"))
    end = result.phases[k + 1]["end_pitch_deg"]
    return end - result.phases[k]["end_pitch_deg"]


def test_zones_open_at_their_events(oblique_pair, debonded):
    target, projectile = debonded
    result = oblique_pair["debonded", 0.01]
    reasons = [p["end_reason"] for p in result.phases]
    top = target.interface_depths[0] - scab_depth(target, projectile, 0)
    assert reasons[:2] == [f"nose tip reached a rear zone (z = {top:g} m)",
                           "nose tip crossed interface 1 (z = 0.65 m)"]
    assert result.phases[0]["end_nose_tip_m"][2] == pytest.approx(top, abs=1e-9)
    assert result.phases[1]["end_nose_tip_m"][2] == pytest.approx(0.65, abs=1e-9)
    # the zones the nose tip has reached are open at the end: the rear zone and the crater
    assert np.allclose(result.model.opened, open_zones(target, projectile)[:2], rtol=1e-15)


def test_first_debonded_interface_adds_a_nose_up_turn(oblique_pair):
    """Done-when (issue 20), with the converged nose rule (16 points, issue 30): after the nose
    tip crosses the first interface the debonded runway turns nose up by 0.071 deg more than
    the bonded one at ramp 0.01 m/s and 0.068 deg at 0.003 m/s (measured; bonded: below 0.01
    deg). The 8-point rule's +0.16 deg was a discretisation artefact: over nose points 16-64,
    azimuths, shank rings, rtol and the contact the added turn spans +0.06 to +0.12 deg
    (docs/oblique.md "Convergence"), so the bound here is that band's lower edge, and the two
    ramps agree within 10 % (measured 4 %)."""
    added = {ramp: _turn_after(oblique_pair["debonded", ramp])
             - _turn_after(oblique_pair["bonded", ramp]) for ramp in (0.01, 0.003)}
    print("added turn (deg) at ramp 0.01, 0.003:", added)
    assert added[0.01] > 0.05 and added[0.003] > 0.05
    for ramp in (0.01, 0.003):
        assert abs(_turn_after(oblique_pair["bonded", ramp])) < 0.01
    assert abs(added[0.003] / added[0.01] - 1.0) < 0.1  # measured 0.0679 / 0.0709: -4 %


def test_no_axial_overload_peak_survives_after_the_debonded_interface(oblique_pair, debonded):
    """The converged answer to the paper's (ii) (issue 30): with the 16-point nose rule no
    peak of the axial overload is reported after the first interface, debonded or bonded, by
    the product's peak rule (oblique.overload_peaks, ripples of one event merged). The 8-point
    rule's peak there (10 860 g at 0.673 m) was an artefact; a bump of about 5 %, at the rule's
    own threshold, shows at rtol 3e-4 and with the held contact but survives no refinement
    (docs/oblique.md)."""
    from cavex.analytic.penetration.oblique import overload_peaks

    target, projectile = debonded
    H = target.interface_depths[0]
    window = (H, H + crater_depth(projectile) + 0.05)
    for name in ("debonded", "bonded"):
        peaks = overload_peaks(oblique_pair[name, 0.01].history)
        after = [z for z, _ in peaks if window[0] < z <= window[1]]
        assert after == [], (name, peaks)


def test_debonded_shot_mirrors_to_the_last_bit(debonded):
    """A property of the arithmetic at any resolution: a shot that stops (600 m/s, 20 deg, in
    3.5 ms; 1.5 s of CPU a shot). The 650 m/s, 25 deg shot flown here before turned back up
    through interface 1 and was still moving at the 1 s time limit (4.3 s a shot)."""
    from cavex.analytic.models import fly
    from cavex.analytic.penetration.oblique import Strike
    from cavex.analytic.penetration.surface_force import mirror_state

    target, projectile = debonded
    a = fly(target, projectile, Strike(600.0, 20.0, attack=3.0, attack_plane=40.0, spin=500.0))
    b = fly(target, projectile, Strike(600.0, -20.0, attack=3.0, attack_plane=40.0,
                                       spin=-500.0))
    assert len(a.model.opened) >= 2
    assert a.end["state"] == "stopped"
    ya = np.concatenate([s.y for s in a.solutions], axis=1)
    yb = np.concatenate([s.y for s in b.solutions], axis=1)
    assert ya.shape == yb.shape
    for k in range(ya.shape[1]):
        assert np.array_equal(mirror_state(ya[:, k]), yb[:, k])


def test_debonded_work_is_the_kinetic_energy_lost(debonded):
    """The zones switch the load at events, not inside a step: the work of the surface
    forces still balances the kinetic energy lost, to the integrator's global error (the
    bonded bound of tests/test_oblique.py at rtol 1e-5: 5e-4), and the mismatch falls with the
    tolerance: measured 7.1e-6 and 5.4e-7 at rtol 1e-3 and 1e-4 (1.5 s and 7.8 s of CPU) on a
    shot that stops in the macadam in 3.5 ms (600 m/s, 20 deg). The 700 m/s, 30 deg shot
    flown here before (4.2e-6, 1.2e-7) turned back and left the target through its entry
    face after 0.4 s of flight (4 s and 17 s of CPU); rtol 1e-5, which this test ran before
    that, took 22 % of the suite's summed durations."""
    from cavex.analytic.models import fly
    from cavex.analytic.penetration.oblique import Strike

    target, projectile = debonded
    mismatch = []
    for rtol in (1e-3, 1e-4):
        result = fly(target, projectile, Strike(600.0, 20.0, attack=3.0, attack_plane=40.0,
                                                spin=500.0), rtol=rtol, atol=1e-3 * rtol)
        assert len(result.model.opened) >= 2
        assert result.end["state"] == "stopped"
        y0, y1 = result.solutions[0].y[:, 0], result.solutions[-1].y[:, -1]
        mismatch.append(-y1[13] / (result.model.energy(y0) - result.model.energy(y1)) - 1.0)
    print("work-energy mismatch at rtol 1e-3, 1e-4:", mismatch)
    assert all(abs(m) < 5e-4 for m in mismatch)
    assert abs(mismatch[1]) < abs(mismatch[0])


def test_trajectory_json_peaks_and_pitch_change_per_phase(capsys, tmp_path):
    code = main(["trajectory", "--velocity", "600", "--obliquity", "20", "--interfaces",
                 "debonded", "--no-figures", "--json", "--out", str(tmp_path)])
    out, _ = capsys.readouterr()
    assert code == 0
    document = json.loads(out)
    run = document["runs"]["runway"]
    assert document["settings"]["interfaces"] == ["debonded", "debonded"]
    changes = [p["pitch_change_deg"] for p in run["phases"]]
    assert sum(changes) == pytest.approx(run["end"]["pitch_deg"] - 20.0, abs=1e-9)
    # the turn after the interface (the last phase, in the macadam) is nose up
    assert run["phases"][-1]["label"] == "macadam" and changes[-1] > 0.05  # measured 0.093
    peaks = run["overload_peaks"]
    assert all(set(p) == {"tip_depth_m", "axial_g"} for p in peaks)
    # the converged answer to (ii) at this shot (issue 30): no peak in the first interface's
    # window (results/oblique/debonded/report.md; test_no_axial_overload_peak_survives_...)
    assert not any(0.65 < p["tip_depth_m"] < 0.65 + crater_depth_default() + 0.05
                   for p in peaks)
    code = main(["trajectory", "--interfaces", "debonded", "--resistance", "law", "--law-A",
                 "1e8", "--law-B", "1000", "--out", str(tmp_path / "x")])
    assert code == 2 and "--resistance derived" in capsys.readouterr().err


def crater_depth_default():
    return crater_depth(load_config()[1])
