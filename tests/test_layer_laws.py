"""Per-layer plain law (issue 20 item 5): the ``law_A``, ``law_B`` keys of a layer, read,
written back and refused; ``cavex trajectory --resistance law`` with each layer's own
``S = A + B rho V^2 / tau``."""

import json
import tomllib

import numpy as np
import pytest
from cli_helpers import refused

from cavex.analytic.models import fly, make_law
from cavex.analytic.penetration.oblique import Strike
from cavex.analytic.penetration.stress_laws import LayerPlainLaw, PlainLaw
from cavex.config import config_text, default_config_text, fingerprint, load_config, parse_config
from cavex.errors import CavexInputError
from cavex.verification.cli import main

NAMES = ("concrete", "macadam", "soil")  # the default runway's layers
LAWS = [(20.0, 1.0), (12.0, 1.2), (8.0, 1.5)]  # Forrestal-like S for concrete, then softer


def _config_with_laws(laws=LAWS):
    data = tomllib.loads(default_config_text())
    for table, law in zip(data["layers"], laws, strict=True):
        if law is not None:
            table["law_A"], table["law_B"] = law
    return data


def _toml(laws=LAWS):
    """The default configuration's text with ``law_A``/``law_B`` lines in each layer."""
    parts = default_config_text().split("[[layers]]")
    text = parts[0]
    for part, law in zip(parts[1:], laws, strict=True):
        text += "[[layers]]" + part.rstrip("\n") + "\n"
        for key, value in zip(("law_A", "law_B"), law or (), strict=False):
            text += f"{key} = {value!r}\n"
        text += "\n"
    return text


def test_keys_read_and_written_back():
    target, projectile = parse_config(_config_with_laws())
    assert target.plain_laws == tuple(LAWS)
    again, _ = load_config_text(config_text(target, projectile))
    assert again.plain_laws == tuple(LAWS)
    # a target without the keys writes none: its fingerprint (FE tables, caches) is unchanged
    default, _ = load_config()
    assert default.plain_laws == (None, None, None)
    assert "law_A" not in config_text(default, projectile)
    assert fingerprint(default, projectile) != fingerprint(target, projectile)
    # the first layer alone keeps its law; the interface option keeps every law
    assert target.single(0).plain_laws == (LAWS[0],)
    assert target.with_interfaces("debonded").plain_laws == tuple(LAWS)


def load_config_text(text):
    return parse_config(tomllib.loads(text))


@pytest.mark.parametrize(("law", "where", "what"), [
    ((20.0, None), "layers[1].law_B", "law_A and law_B both"),
    ((None, 1.0), "layers[1].law_A", "law_A and law_B both"),
    ((-1.0, 1.0), "layers[1].law_A", "in [0, 1000]"),
    ((1e4, 1.0), "layers[1].law_A", "in [0, 1000]"),
    ((20.0, 101.0), "layers[1].law_B", "in [0, 100]"),
    ((20.0, float("nan")), "layers[1].law_B", "in [0, 100]"),
])
def test_bad_keys_refused(law, where, what):
    data = tomllib.loads(default_config_text())
    for key, value in zip(("law_A", "law_B"), law, strict=True):
        if value is not None:
            data["layers"][1][key] = value
    with pytest.raises(CavexInputError) as error:
        parse_config(data)
    assert where in str(error.value) and what in str(error.value)


def test_command_refusals(capsys, tmp_path):
    """One line on stderr naming the parameter, exit 2, nothing written."""
    partial = tmp_path / "partial.toml"
    partial.write_text(_toml([LAWS[0], None, LAWS[2]]))
    bad = tmp_path / "bad.toml"
    bad.write_text(_toml([LAWS[0], (20.0, 500.0), LAWS[2]]))
    for argv, expect in (
            (["--resistance", "law"], "layers[0].law_A"),  # the default has no law keys
            (["--config", str(partial), "--resistance", "law"], "layers[1].law_A"),
            (["--config", str(bad), "--resistance", "law"], "layers[1].law_B"),
            (["--resistance", "law", "--law-A", "1e8"], "--law-A"),
            (["--law-A", "1e8", "--law-B", "1000"], "--law-A")):
        refused(capsys, tmp_path, ["trajectory", *argv, "--out", tmp_path / "out",
                                   "--no-figures"], expect)


def test_layer_law_is_each_layers_own():
    """The compiled law at depths in every layer against ``tau_k A_k + B_k rho_k V^2``
    computed here from the layers (the same floating-point operations: bound 4 ulp)."""
    target, projectile = parse_config(_config_with_laws())
    law = make_law(target, projectile, "law")
    assert isinstance(law, LayerPlainLaw)
    depths = np.array([0.0, 0.3, 0.6499999, 0.65, 0.9, 1.0999, 1.1, 5.0])
    layer = [0, 0, 0, 1, 1, 1, 2, 2]  # an interface belongs to the deeper layer
    vn = np.linspace(0.0, 900.0, depths.size)
    normals = np.tile([0.0, 0.0, 1.0], (depths.size, 1))
    got = law.stress(depths, normals, vn)
    for i, k in enumerate(layer):
        m, (A, B) = target.layers[k], LAWS[k]
        assert got[i] == pytest.approx(m.tau * A + B * m.rho * vn[i] ** 2, rel=1e-15)


def test_one_layer_law_flies_as_the_global_law():
    """A one-layer target with its own law flies the same trajectory as ``--law-A tau A
    --law-B B rho`` (two kernel paths of one formula: bound 1e-12 relative)."""
    target, projectile = parse_config(_config_with_laws())
    single = target.single(0)
    m, (A, B) = single.layers[0], LAWS[0]
    strike = Strike(500.0, 20.0)
    own = fly(single, projectile, strike, "law")
    plain = fly(single, projectile, strike, "law", law_A=m.tau * A, law_B=B * m.rho)
    assert isinstance(make_law(single, projectile, "law", law_A=1.0, law_B=1.0), PlainLaw)
    a, b = own.end["nose_tip_m"], plain.end["nose_tip_m"]
    assert np.allclose(a, b, rtol=1e-12, atol=1e-12 * abs(a[2]))
    assert own.end["pitch_deg"] == pytest.approx(plain.end["pitch_deg"], rel=1e-12)


def test_trajectory_with_layer_laws_runs_and_reports_them(capsys, tmp_path):
    config = tmp_path / "laws.toml"
    config.write_text(_toml())
    code = main(["trajectory", "--config", str(config), "--resistance", "law", "--velocity",
                 "600", "--obliquity", "20", "--json", "--no-figures", "--out",
                 str(tmp_path / "t")])
    out, _ = capsys.readouterr()
    assert code == 0
    document = json.loads(out)
    assert document["settings"]["law"] == [{"layer": name, "law_A": A, "law_B": B}
                                           for name, (A, B) in zip(NAMES, LAWS, strict=True)]
    # concrete with S = 20 + rho V^2 / tau stops the 600 m/s shot in the concrete
    assert 0.0 < document["end"]["nose_tip_m"][2] < 0.65
