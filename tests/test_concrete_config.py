"""A layer's material read from a concrete's strength and density: ``concrete = {fc = <Pa>,
rho = <kg/m^3>}`` in a target file builds :meth:`cavex.concrete.Concrete.layer` (``capped =
true``: :meth:`~cavex.concrete.Concrete.fe_layer`), the one description the closed forms and
the FE share; bad values are one line naming the key, exit 2."""

import json

import pytest
from cli_helpers import run

from cavex.concrete import Concrete
from cavex.config import config_text, load_config, parse_config
from cavex.errors import CavexInputError

PROJECTILE = "[projectile]\nr = 0.0125\nl = 0.06\nR = 0.075\nm = 0.505\nV0 = 300.0\n"
SOIL = '[[layers]]\nname = "soil"\nE = 0.12e9\nnu = 0.4999\nrho = 1600.0\nlam = 0.5\ntau = 6e6\n'


def config(tmp_path, concrete, extra=""):
    """A two-layer target file: 0.5 m of the concrete ``concrete`` (TOML inline table) over
    soil."""
    path = tmp_path / "concrete.toml"
    path.write_text(f"{PROJECTILE}\n[[layers]]\nthickness = 0.5\nconcrete = {concrete}\n"
                    f"{extra}\n{SOIL}")
    return path


def test_concrete_layer_is_the_concrete_description(tmp_path):
    """The layer is ``Concrete(fc, rho).layer()`` (ACI modulus, nu 0.2, Richart's lam,
    ``tau = (3 - lam) f_c/3``), named "concrete" unless named; capped: ``fe_layer()``."""
    target, _ = load_config(config(tmp_path, "{ fc = 40e6, rho = 2300 }"))
    assert target.layers[0] == Concrete(40e6, 2300.0).layer()
    assert target.layers[0].name == "concrete" and target.layers[1].name == "soil"
    assert target.thicknesses == (0.5,)
    target, _ = load_config(config(tmp_path, "{ fc = 40e6, rho = 2300, capped = true }",
                                   'name = "slab"'))
    expected = Concrete(40e6, 2300.0).fe_layer()
    assert target.layers[0].tau_max == expected.tau_max == 7 * 40e6
    assert target.layers[0].tensile_strength == expected.tensile_strength
    assert target.layers[0].name == "slab"


def test_concrete_layer_is_written_back_as_its_material(tmp_path):
    """``config_text`` writes the concrete's material keys; read back, the same target."""
    target, projectile = load_config(config(tmp_path, "{ fc = 40e6, rho = 2300 }"))
    again = tmp_path / "again.toml"
    again.write_text(config_text(target, projectile))
    assert load_config(again) == (target, projectile)


def test_concrete_layer_flies_in_penetrate(tmp_path, capsys):
    """``penetrate --config`` with a concrete layer runs, and gives the depth of the same
    target written with explicit material keys."""
    path = config(tmp_path, "{ fc = 40e6, rho = 2300 }")
    target, projectile = load_config(path)
    explicit = tmp_path / "explicit.toml"
    explicit.write_text(config_text(target, projectile))
    depths = []
    for file in (path, explicit):
        code, out, err = run(capsys, "penetrate", "--config", file, "--json", "--no-figures",
                             "--out", tmp_path / file.stem)
        assert code == 0, err
        depths.append(json.loads(out)["phases"][-1]["end_depth_m"])
    assert depths[0] == depths[1]


@pytest.mark.parametrize("concrete, extra, where, accepted", [
    ("{ fc = -40e6, rho = 2300 }", "", "layers[0].concrete.fc", "a number in [1e+06, 1e+09]"),
    ("{ fc = 40e6, rho = 0 }", "", "layers[0].concrete.rho", "a number in [1000, 4000]"),
    ("{ fc = inf, rho = 2300 }", "", "layers[0].concrete.fc", "a number in [1e+06, 1e+09]"),
    ("{ fc = 40, rho = 2300 }", "", "layers[0].concrete.fc", "(is it in MPa?)"),
    ("{ fc = 40e6, rho = 2.3 }", "", "layers[0].concrete.rho", "(is it in g/cm^3?)"),
    ('{ fc = "40 MPa", rho = 2300 }', "", "layers[0].concrete.fc", "a number"),
    ("{ fc = 40e6 }", "", "layers[0].concrete.rho", "is missing"),
    ("{ fc = 40e6, rho = 2300, E = 30e9 }", "", "layers[0].concrete.E", "is not a known key"),
    ("{ fc = 40e6, rho = 2300, capped = 1 }", "", "layers[0].concrete.capped", "true or false"),
    ("40e6", "", "layers[0].concrete", "a table {fc = <Pa>, rho = <kg/m^3>}"),
    ("{ fc = 40e6, rho = 2300 }", "E = 30e9", "layers[0].E", "must be absent with concrete"),
])
def test_bad_concrete_is_one_line_naming_the_key(tmp_path, capsys, concrete, extra, where,
                                                 accepted):
    path = config(tmp_path, concrete, extra)
    with pytest.raises(CavexInputError) as info:
        load_config(path)
    assert f"{where} " in str(info.value) and accepted in str(info.value)
    code, out, err = run(capsys, "penetrate", "--config", path, "--no-figures", "--out",
                         tmp_path / "p")
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and where in err and accepted in err


def test_concrete_parsed_from_a_mapping_names_the_key():
    """From a parsed mapping (no file), the error names the key path alone."""
    data = {"projectile": {"r": 0.0125, "l": 0.06, "m": 0.5, "V0": 300.0},
            "layers": [{"concrete": {"fc": 40e6, "rho": -1.0}}]}
    with pytest.raises(CavexInputError) as info:
        parse_config(data)
    assert info.value.where == "layers[0].concrete.rho"
