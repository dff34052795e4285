"""Verification of materials, targets, projectiles and the strict TOML configuration.

Every bad input must raise :class:`cavex.errors.CavexInputError` with a one-line message that
names the parameter (with its ``layers[i].`` / ``projectile.`` prefix when read from TOML) and,
for out-of-range values, the accepted range.
"""

import math

import pytest

from cavex.config import default_config_text, load_config
from cavex.errors import CavexInputError
from cavex.materials import Material, Projectile, Target

NAN = float("nan")
INF = float("inf")

GOOD_MATERIAL = {"E": 25e9, "nu": 0.2, "rho": 2500.0, "lam": 0.15, "tau": 25e6}


def assert_input_error(error, *fragments):
    """The message is one line and contains every fragment."""
    message = str(error.value)
    assert "\n" not in message, message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


# --------------------------------------------------------------------------------------------
# Material, Target, Projectile
# --------------------------------------------------------------------------------------------

def test_material_derived_quantities():
    """``alpha``, ``k``, ``epsilon`` and elastic moduli from their definitions."""
    material = Material(**GOOD_MATERIAL)
    lam, tau, E = 0.15, 25e6, 25e9
    assert material.alpha == pytest.approx(3 * lam / (3 + 2 * lam), rel=1e-15)
    assert material.yield_intercept == pytest.approx(3 * tau / (3 + 2 * lam), rel=1e-15)
    # alpha (sigma_r + tau/lam) is the paper's lam sigma + tau with sigma = sigma_r - 2D/3
    assert material.yield_intercept == pytest.approx(material.alpha * tau / lam, rel=1e-14)
    assert material.quasi_static_epsilon ** 3 == pytest.approx(1.5 * tau / E, rel=1e-14)
    assert material.shear_modulus == pytest.approx(E / 2.4, rel=1e-15)
    assert material.bulk_modulus == pytest.approx(E / (3 * 0.6), rel=1e-15)


@pytest.mark.parametrize("lam", [0.0, 0.15, 0.75, 2.9])
def test_material_tau_from_sigma_c(lam):
    """Only ``sigma_c`` given: ``tau = (3 - lam) sigma_c / 3`` (paper Eq. 2)."""
    fields = {**GOOD_MATERIAL, "lam": lam}
    del fields["tau"]
    material = Material(**fields, sigma_c=40e6)
    assert material.tau == pytest.approx((3.0 - lam) * 40e6 / 3.0, rel=1e-15)


@pytest.mark.parametrize(("change", "parameter", "accepted"), [
    ({"E": 0.0}, "E", "> 0"),
    ({"E": -1e9}, "E", "> 0"),
    ({"E": NAN}, "E", "> 0"),
    ({"E": INF}, "E", "finite"),
    ({"E": "25e9"}, "E", "> 0"),
    ({"rho": 0.0}, "rho", "> 0"),
    ({"rho": -2500.0}, "rho", "> 0"),
    ({"rho": NAN}, "rho", "> 0"),
    ({"tau": 0.0}, "tau", "> 0"),
    ({"tau": -25e6}, "tau", "> 0"),
    ({"tau": NAN}, "tau", "> 0"),
    ({"lam": -0.01}, "lam", "in [0, 3)"),
    ({"lam": 3.0}, "lam", "in [0, 3)"),
    ({"lam": 7.0}, "lam", "in [0, 3)"),
    ({"lam": NAN}, "lam", "in [0, 3)"),
    ({"nu": 0.5}, "nu", "in (-1, 0.5)"),
    ({"nu": -1.0}, "nu", "in (-1, 0.5)"),
    ({"nu": 0.7}, "nu", "in (-1, 0.5)"),
    ({"nu": NAN}, "nu", "in (-1, 0.5)"),
    ({"tau": None}, "tau", "sigma_c"),
    ({"tau": None, "sigma_c": 0.0}, "sigma_c", "> 0"),
    ({"tau": None, "sigma_c": NAN}, "sigma_c", "> 0"),
])
def test_material_rejects_bad_values(change, parameter, accepted):
    """Out-of-range, NaN, infinite or missing material parameters."""
    with pytest.raises(CavexInputError) as error:
        Material(**{**GOOD_MATERIAL, **change})
    assert_input_error(error, f"'{parameter}'", accepted)


def test_target_interface_depths_and_layer_lookup():
    """Interfaces are cumulative thicknesses; an interface belongs to the deeper layer."""
    layers = [Material(**GOOD_MATERIAL)] * 3
    target = Target(layers, [0.65, 0.45])
    assert target.interface_depths == pytest.approx((0.65, 1.1), rel=1e-15)
    assert [target.layer_at(d) for d in (0.0, 0.649, 0.65, 1.0, 1.1, 5.0)] == [0, 0, 1, 1, 2, 2]
    assert target.single(1).layers == (layers[1],) and target.single(1).thicknesses == ()


def test_target_layer_names_are_names_or_numbers_from_one():
    named = Material(**GOOD_MATERIAL, name="concrete")
    target = Target([named, Material(**GOOD_MATERIAL), named], [0.65, 0.45])
    assert target.layer_names() == ["concrete", "layer 2", "concrete"]
    assert target.layer_name(1) == "layer 2"


@pytest.mark.parametrize(("thicknesses", "parameter", "accepted"), [
    ([0.0, 0.45], "layers[0].thickness", "> 0"),
    ([0.65, -0.1], "layers[1].thickness", "> 0"),
    ([0.65, NAN], "layers[1].thickness", "> 0"),
    ([0.65], "thickness", "every layer but the last"),
    ([0.65, 0.45, 1.0], "thickness", "every layer but the last"),
])
def test_target_rejects_bad_thickness(thicknesses, parameter, accepted):
    """Non-positive or NaN thickness, or one thickness too many / too few."""
    with pytest.raises(CavexInputError) as error:
        Target([Material(**GOOD_MATERIAL)] * 3, thicknesses)
    assert_input_error(error, f"'{parameter}'", accepted)


def test_projectile_from_crh():
    """``crh = R / (2 r)`` may replace ``R``."""
    projectile = Projectile(r=0.0125, l=0.06, m=0.505, V0=1000.0, crh=3.0)
    assert projectile.R == pytest.approx(0.075, rel=1e-15)
    assert projectile.psi == pytest.approx(3.0, rel=1e-15)
    assert projectile.ogive_length == pytest.approx(math.sqrt(2 * 0.075 * 0.0125 - 0.0125 ** 2))


@pytest.mark.parametrize(("change", "parameter", "accepted"), [
    ({"r": 0.0}, "r", "> 0"),
    ({"m": -1.0}, "m", "> 0"),
    ({"V0": NAN}, "V0", "> 0"),
    ({"l": INF}, "l", "finite"),
    ({"R": 0.01}, "R", ">= r"),
    ({"R": None}, "R", "crh"),
    ({"R": None, "crh": 0.0}, "crh", "> 0"),
])
def test_projectile_rejects_bad_values(change, parameter, accepted):
    """Non-positive, NaN or infinite projectile data; an ogive radius below the shank radius."""
    fields = {"r": 0.0125, "l": 0.06, "m": 0.505, "V0": 1000.0, "R": 0.075, **change}
    with pytest.raises(CavexInputError) as error:
        Projectile(**fields)
    assert_input_error(error, f"'{parameter}'", accepted)


# --------------------------------------------------------------------------------------------
# TOML configuration
# --------------------------------------------------------------------------------------------

def test_default_config_is_table1(table1):
    """The embedded default loads to the paper's Table 1 numbers."""
    target, projectile = load_config()
    for key, value in table1["projectile"].items():
        assert getattr(projectile, key) == pytest.approx(value, rel=1e-15), key
    assert projectile.psi == pytest.approx(3.0, rel=1e-15)
    assert len(target.layers) == 3
    for material, expected in zip(target.layers, table1["layers"], strict=True):
        for key, value in expected.items():
            assert getattr(material, key) == pytest.approx(value, rel=1e-15) \
                if key != "name" else material.name == value, key
    assert target.interface_depths == pytest.approx(table1["interface_depths"], rel=1e-15)


def test_default_config_text_matches_load(tmp_path):
    """Writing the default text to a file and loading it gives the same objects."""
    path = write_config(tmp_path, default_config_text())
    assert load_config(path) == load_config()


BASE_CONFIG = """\
[projectile]
r = 0.0125
l = 0.06
R = 0.075
m = 0.505
V0 = 1000.0

[[layers]]
name = "concrete"
thickness = 0.65
E = 25e9
nu = 0.2
rho = 2500.0
lam = 0.15
tau = 25e6

[[layers]]
name = "macadam"
thickness = 0.45
E = 10e9
nu = 0.25
rho = 1800.0
lam = 0.35
tau = 10e6

[[layers]]
name = "soil"
E = 0.12e9
nu = 0.3
rho = 1600.0
lam = 0.50
tau = 6e6
"""


def write_config(tmp_path, text):
    """Write ``text`` to ``tmp_path/case.toml`` and return the path."""
    path = tmp_path / "case.toml"
    path.write_text(text, encoding="utf-8")
    return path


def edited(old, new, count=1):
    """``BASE_CONFIG`` with the ``count``-th occurrence of line ``old`` replaced by ``new``."""
    lines = BASE_CONFIG.splitlines()
    hits = [i for i, line in enumerate(lines) if line == old]
    assert len(hits) >= count, old
    lines[hits[count - 1]] = new
    return "\n".join(lines) + "\n"


def test_base_config_loads(tmp_path):
    """The hand-written configuration used below is valid."""
    target, projectile = load_config(write_config(tmp_path, BASE_CONFIG))
    assert [m.name for m in target.layers] == ["concrete", "macadam", "soil"]
    assert [m.nu for m in target.layers] == [0.2, 0.25, 0.3]
    assert projectile.R == 0.075


@pytest.mark.parametrize(("text", "where", "fragments"), [
    # malformed TOML: the line and column of the fault
    (BASE_CONFIG.replace("rho = 2500.0", "rho 2500.0"), "line 13, column 5",
     ("is not valid TOML (Expected '='",)),
    (BASE_CONFIG + "[[layers]\n", "line 33, column 9", ("is not valid TOML",)),
    (edited("E = 25e9", "E = 25 GPa"), "line 11, column 8", ("is not valid TOML",)),
    # unknown keys
    (edited("E = 10e9", "Young = 10e9"), "layers[1].Young",
     ("is not a known key (accepted:", "tau")),
    (edited("m = 0.505", "mass = 0.505"), "projectile.mass", ("is not a known key",)),
    (BASE_CONFIG + "units = 'SI'\n", "layers[2].units", ("is not a known key",)),
    ("title = 'runway'\n" + BASE_CONFIG, "title", ("is not a known key",)),
    # missing keys
    (edited("rho = 1800.0", ""), "layers[1].rho", ("is missing (required)",)),
    (edited("lam = 0.50", ""), "layers[2].lam", ("is missing (required)",)),
    (edited("V0 = 1000.0", ""), "projectile.V0", ("is missing (required)",)),
    (BASE_CONFIG.split("[[layers]]")[0], "layers", ("is missing (required)",)),
    (edited("tau = 10e6", ""), "layers[1].tau", ("must be given (or sigma_c given)",)),
    (edited("R = 0.075", ""), "projectile.R", ("must be given (or crh given)",)),
    # wrong types
    (edited("E = 25e9", 'E = "25e9"'), "layers[0].E", ("must be a number (got '25e9')",)),
    (edited("lam = 0.35", "lam = true"), "layers[1].lam", ("must be a number (got True)",)),
    (edited("V0 = 1000.0", "V0 = false"), "projectile.V0", ("must be a number",)),
    (edited("thickness = 0.65", "thickness = [0.65]"), "layers[0].thickness",
     ("must be a number",)),
    (edited("tau = 6e6", "tau = 1979-05-27"), "layers[2].tau", ("must be a number",)),
    ("projectile = 3\n[[layers]]" + BASE_CONFIG.split("[[layers]]", 1)[1], "projectile",
     ("must be a table",)),
    # thickness placement
    (edited("tau = 6e6", "tau = 6e6\nthickness = 2.0"), "layers[2].thickness",
     ("must be absent",)),
    (edited("thickness = 0.45", ""), "layers[1].thickness", ("is missing (required)",)),
    (edited("thickness = 0.65", "thickness = -0.65"), "layers[0].thickness", ("> 0",)),
    (edited("thickness = 0.45", "thickness = nan"), "layers[1].thickness", ("> 0",)),
    # out-of-range and non-finite numbers, prefixed with where they were read
    (edited("lam = 0.35", "lam = 3.0"), "layers[1].lam", ("must be in [0, 3) (got 3.0)",)),
    (edited("lam = 0.15", "lam = -0.1"), "layers[0].lam", ("in [0, 3)",)),
    (edited("nu = 0.3", "nu = 0.5"), "layers[2].nu", ("in (-1, 0.5)",)),
    (edited("E = 0.12e9", "E = 0"), "layers[2].E", ("> 0",)),
    (edited("E = 10e9", "E = nan"), "layers[1].E", ("> 0",)),
    (edited("rho = 1600.0", "rho = -1600.0"), "layers[2].rho", ("> 0",)),
    (edited("tau = 25e6", "tau = inf"), "layers[0].tau", ("finite",)),
    (edited("V0 = 1000.0", "V0 = -1.0"), "projectile.V0", ("> 0",)),
    (edited("V0 = 1000.0", "V0 = 2e4"), "projectile.V0", ("<= 10000 m/s",)),
    (edited("r = 0.0125", "r = nan"), "projectile.r", ("> 0",)),
    (edited("R = 0.075", "R = 0.01"), "projectile.R", (">= r",)),
])
def test_bad_config_raises_input_error(tmp_path, text, where, fragments):
    """Malformed TOML, unknown, missing or mistyped keys and bad values: one line
    ``'<path>': <where> <what>``."""
    path = write_config(tmp_path, text)
    with pytest.raises(CavexInputError) as error:
        load_config(path)
    assert str(error.value).startswith(f"'{path}': {where} "), str(error.value)
    assert_input_error(error, *fragments)


def test_unreadable_config_raises_input_error(tmp_path):
    """A missing file, or a folder, is an input error naming the file."""
    path = tmp_path / "absent.toml"
    with pytest.raises(CavexInputError) as error:
        load_config(path)
    assert str(error.value) == f"'{path}': cannot be read (No such file or directory)"
    with pytest.raises(CavexInputError) as error:
        load_config(tmp_path)
    assert str(error.value).startswith(f"'{tmp_path}': cannot be read (")


def test_config_with_a_byte_order_mark_loads(tmp_path):
    """A UTF-8 byte-order mark at the start (some editors write one) is accepted."""
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + BASE_CONFIG.encode())
    assert load_config(path) == load_config(write_config(tmp_path, BASE_CONFIG))


def test_config_parsed_from_a_mapping_names_the_parameter():
    """Without a file (``parse_config`` of a mapping) the message names the parameter."""
    import tomllib

    from cavex.config import parse_config

    data = tomllib.loads(edited("E = 10e9", "E = -1.0"))
    with pytest.raises(CavexInputError) as error:
        parse_config(data)
    assert str(error.value) == "parameter 'layers[1].E' must be a finite number > 0 (got -1.0)"


@pytest.mark.parametrize("lam", [0.0, 0.35, 2.5])
def test_config_sigma_c_only_derives_tau(tmp_path, lam):
    """A layer given by ``sigma_c`` gets ``tau = (3 - lam) sigma_c / 3``."""
    text = edited("tau = 10e6", "sigma_c = 12e6").replace("lam = 0.35", f"lam = {lam}")
    target, _ = load_config(write_config(tmp_path, text))
    assert target.layers[1].tau == pytest.approx((3.0 - lam) * 12e6 / 3.0, rel=1e-15)
    assert target.layers[1].lam == lam


def test_config_crh_instead_of_R(tmp_path):
    """``crh`` in place of ``R``: ``R = 2 r crh``."""
    _, projectile = load_config(write_config(tmp_path, edited("R = 0.075", "crh = 3.0")))
    assert projectile.R == pytest.approx(2 * 0.0125 * 3.0, rel=1e-15)
    assert projectile.psi == pytest.approx(3.0, rel=1e-15)


def test_config_integers_accepted_as_numbers(tmp_path):
    """TOML integers are numbers (``E = 25000000000``) and become floats."""
    target, projectile = load_config(write_config(
        tmp_path, edited("E = 25e9", "E = 25_000_000_000").replace("V0 = 1000.0", "V0 = 1000")))
    assert target.layers[0].E == 25e9 and isinstance(target.layers[0].E, float)
    assert projectile.V0 == 1000.0 and isinstance(projectile.V0, float)


def test_two_layer_and_single_layer_configs(tmp_path):
    """Fewer layers: the last one still carries no thickness."""
    two = BASE_CONFIG.split("[[layers]]\nname = \"soil\"")[0].replace(
        "thickness = 0.45\n", "")
    target, _ = load_config(write_config(tmp_path, two))
    assert len(target.layers) == 2 and target.interface_depths == (0.65,)
    one = BASE_CONFIG.split("[[layers]]\nname = \"macadam\"")[0].replace(
        "thickness = 0.65\n", "")
    target, _ = load_config(write_config(tmp_path, one))
    assert len(target.layers) == 1 and target.interface_depths == ()
