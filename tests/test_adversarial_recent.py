"""An adversarial pass over what the model-home, convergence and concrete issues added (issue
32, item 7): the model registry and a layer's ``concrete = {fc, rho, capped}``, the concrete
hydrostat keys, ``--erosion``, the 3-D options of ``trajectory`` and of the oblique model
(nose points, azimuths, shank rings, tolerances, contact settings, ``--estimate``,
``--interfaces debonded``), ``verify --quick``'s refusals, the concrete cavity solver at the
ends of its ranges, shot files and TOML files with odd contents; then faults: read-only and
full folders, planted symlinks at the commands' final names.

Every case states its exit code. A refusal (2): one line on stderr in the command line's form
naming the parameter (and its accepted range), nothing on stdout, no traceback, nothing
written. A numerical failure (1): one line, no number given as an answer. A success (0): no
``nan`` or ``inf`` printed or written. Cases run in this process (``cli.main``): the pass costs
seconds, not minutes.

Bugs this pass found, each with its cases (marked ``# bug``): a concrete's ``fc`` and ``rho``
were not ranged (35 Pa, 1e300 Pa, 2.4 kg/m^3 accepted; 1e300 kg/m^3 a traceback); a refused
value was printed whole (a 100 000-element array: a 300 kB "line"); the oblique model's
``rtol``, ``atol`` and ``method`` were not checked (a negative ``rtol`` flew, NaN failed as a
numerical error); ``nose_points = True`` made a one-point body; ``3_00`` in a shot file was
read as 300; bidirectional formatting characters were accepted in ids and names.
"""

import math
import re

import pytest
from tmpfs_helpers import fill, small_tmpfs, unmount

from cavex.config import default_config_text
from cavex.errors import CavexInputError
from cavex.verification.cli import main

HEADER = "id,mass_kg,diameter_m,length_m,crh,V0_m_s,fc_Pa,rho_kg_m3,depth_m"
ROW = "A1,0.906,0.0269,0.2424,2.0,277.0,35200000.0,2370.0,0.173"
CONFIG = default_config_text()
PROJECTILE = CONFIG[:CONFIG.index("[[layers]]")]
MOHR_COULOMB = "E = 25e9\nnu = 0.2\nrho = 2500.0\nlam = 0.15\ntau = 25e6\n"
HYDROSTAT = {"crush_pressure": "20e6", "lock_pressure": "1e9", "lock_strain": "0.1",
             "locked_modulus": "1e10"}
NOT_FINITE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)
PREFIX = {1: "cavex: numerical failure: ", 2: "cavex: error: "}

CASES = []  # (argv with {tmp}, files {name: text}, exit code, the name a refusal gives)


def case(name, argv, code, files=None, names=None):
    CASES.append(pytest.param(argv, files or {}, code, names, id=name))


def one_layer(*lines):
    """A configuration of the default projectile over one layer of ``lines``."""
    return PROJECTILE + "[[layers]]\n" + "\n".join(lines) + "\n"


def hydrostat(**changed):
    keys = {**HYDROSTAT, **changed}
    return one_layer(MOHR_COULOMB, *(f"{k} = {v}" for k, v in keys.items() if v is not None))


def shots(*rows):
    return "\n".join([HEADER, *rows]) + "\n"


# --- a layer's concrete = {fc, rho, capped} (read by `cavex config`) ------------------------
CONCRETE = {
    "fc-string": ('concrete = {fc = "35e6", rho = 2400.0}', 2, "concrete.fc"),
    "fc-nan": ("concrete = {fc = nan, rho = 2400.0}", 2, "concrete.fc"),
    "fc-inf": ("concrete = {fc = inf, rho = 2400.0}", 2, "concrete.fc"),
    "fc-negative": ("concrete = {fc = -35e6, rho = 2400.0}", 2, "concrete.fc"),
    "fc-in-MPa": ("concrete = {fc = 35.0, rho = 2400.0}", 2, "concrete.fc"),  # bug
    "fc-huge": ("concrete = {fc = 1e300, rho = 2400.0}", 2, "concrete.fc"),  # bug
    "fc-above-1-GPa": ("concrete = {fc = 1.0001e9, rho = 2400.0}", 2, "concrete.fc"),  # bug
    "fc-bool": ("concrete = {fc = true, rho = 2400.0}", 2, "concrete.fc"),
    "fc-array": ("concrete = {fc = [35e6], rho = 2400.0}", 2, "concrete.fc"),
    "rho-in-g-cm3": ("concrete = {fc = 35e6, rho = 2.4}", 2, "concrete.rho"),  # bug
    "rho-huge": ("concrete = {fc = 35e6, rho = 1e300}", 2, "concrete.rho"),  # bug: traceback
    "rho-missing": ("concrete = {fc = 35e6}", 2, "concrete.rho"),
    "capped-string": ('concrete = {fc = 35e6, rho = 2400.0, capped = "yes"}', 2,
                      "concrete.capped"),
    "capped-integer": ("concrete = {fc = 35e6, rho = 2400.0, capped = 1}", 2, "concrete.capped"),
    "not-a-table": ("concrete = 35e6", 2, "concrete"),
    "unknown-key": ("concrete = {fc = 35e6, rho = 2400.0, E = 3e10}", 2, "concrete.E"),
    "with-E": ("concrete = {fc = 35e6, rho = 2400.0}\nE = 3e10", 2, "layers[0].E"),
    "with-hydrostat": ("concrete = {fc = 35e6, rho = 2400.0}\ncrush_pressure = 20e6", 2,
                       "crush_pressure"),
    "name-bidi": ('name = "a\\u202Eb"\nconcrete = {fc = 35e6, rho = 2400.0}', 2,
                  "layers[0].name"),  # bug
    "name-bell": ('name = "a\\u0007b"\nconcrete = {fc = 35e6, rho = 2400.0}', 2,
                  "layers[0].name"),
    "name-unicode": ('name = "b\u00e9ton \u2603"\nconcrete = {fc = 35e6, rho = 2400.0}', 0,
                     None),
    "capped-at-the-ends": ("concrete = {fc = 1e9, rho = 1000.0, capped = true}", 0, None),
    "lowest-strength": ("concrete = {fc = 1e6, rho = 4000.0}", 0, None),
}
for fault, (text, code, name) in CONCRETE.items():
    case(f"concrete-{fault}", ["config", "--config", "{tmp}/c.toml"], code,
         {"c.toml": one_layer(text)}, name)

# --- the hydrostat keys -------------------------------------------------------------------
HYDROSTATS = {
    "crush-alone": ({"lock_pressure": None, "lock_strain": None, "locked_modulus": None}, 2,
                    "lock_pressure"),
    "crush-negative": ({"crush_pressure": "-20e6"}, 2, "crush_pressure"),
    "crush-nan": ({"crush_pressure": "nan"}, 2, "crush_pressure"),
    "lock-below-crush": ({"lock_pressure": "1e6"}, 2, "lock_pressure"),
    "lock-inf": ({"lock_pressure": "inf"}, 2, "lock_pressure"),
    "lock-string": ({"lock_pressure": '"1e9"'}, 2, "lock_pressure"),
    "strain-one": ({"lock_strain": "1.0"}, 2, "lock_strain"),
    "strain-nan": ({"lock_strain": "nan"}, 2, "lock_strain"),
    "strain-stiffer-than-K": ({"lock_strain": "1e-6"}, 2, "lock_strain"),
    "locked-zero": ({"locked_modulus": "0.0"}, 2, "locked_modulus"),
    "locked-inf": ({"locked_modulus": "inf"}, 2, "locked_modulus"),
    "huge-array": ({"locked_modulus": "[" + ", ".join(["1"] * 100_000) + "]"}, 2,
                   "locked_modulus"),  # bug: the whole array in the message
    "valid": ({}, 0, None),
}
for fault, (changed, code, name) in HYDROSTATS.items():
    case(f"hydrostat-{fault}", ["config", "--config", "{tmp}/c.toml"], code,
         {"c.toml": hydrostat(**changed)}, name)

# --- odd TOML -------------------------------------------------------------------------------
TOML = {
    "V0-inf": (CONFIG.replace("V0 = 1000.0", "V0 = inf", 1), 2, "projectile.V0"),
    "r-array": (CONFIG.replace("r = 0.0125", "r = [0.0125]", 1), 2, "projectile.r"),
    "layers-a-table": (PROJECTILE + "[layers]\nE = 1.0\n", 2, "layers"),
    "layers-huge-array": (PROJECTILE + "layers = [" + ", ".join(["1"] * 100_000) + "]\n", 2,
                          "layers"),
    "thickness-nan": (CONFIG.replace("thickness = 0.65", "thickness = nan", 1), 2,
                      "layers[0].thickness"),
    "tau-datetime": (CONFIG.replace("tau = 25e6", "tau = 1979-05-27", 1), 2, "layers[0].tau"),
    "integer-of-5000-digits": (CONFIG.replace('name = "concrete"', 'name = ' + "9" * 5000, 1),
                               2, "TOML"),  # bug: a traceback (tomllib's ValueError)
    "bottom-number": (CONFIG.replace("thickness = 0.65", "thickness = 0.65\nbottom = 1", 1),
                      2, "layers[0].bottom"),
}
for fault, (text, code, name) in TOML.items():
    case(f"toml-{fault}", ["config", "--config", "{tmp}/c.toml"], code, {"c.toml": text}, name)

# --- --erosion ------------------------------------------------------------------------------
case("erosion-unknown-penetrate", ["penetrate", "--erosion", "abrasion", "--no-figures",
                                   "--out", "{tmp}/o"], 2, names="--erosion")
case("erosion-empty-validate", ["validate", "--shots", "{tmp}/s.csv", "--erosion", "",
                                "--out", "{tmp}/v"], 2, {"s.csv": shots(ROW)}, "--erosion")
case("erosion-empirical-only", ["validate", "--shots", "{tmp}/s.csv", "--erosion",
                                "silling-forrestal", "--models", "forrestal-1994",
                                "--no-figures", "--out", "{tmp}/v"], 0, {"s.csv": shots(ROW)})
case("erosion-slowest-shot", ["validate", "--shots", "{tmp}/s.csv", "--erosion",
                              "silling-forrestal", "--models", "derived-dynamic",
                              "--no-figures", "--out", "{tmp}/v"], 0,
     {"s.csv": shots(ROW.replace("277.0", "1.0"))})

# --- trajectory's 3-D options -----------------------------------------------------------------
TRAJECTORY = {
    "hold-with-psi": (["--contact-hold", "1e-6", "--tangency-psi", "5"], "contact_hold"),
    "hold-with-ramp": (["--contact-hold", "1e-6", "--contact-ramp", "0.01"], "contact_hold"),
    "psi-nan": (["--tangency-psi", "nan"], "tangency-psi"),
    "psi-above-30": (["--tangency-psi", "31"], "tangency-psi"),
    "wall-negative": (["--tunnel-wall", "-0.1"], "tunnel-wall"),
    "wall-above-1": (["--tunnel-wall", "2"], "tunnel-wall"),
    "debonded-table": (["--interfaces", "debonded", "--resistance", "table", "--table",
                        "{tmp}/none.nc"], "--interfaces"),
    "debonded-law": (["--interfaces", "debonded", "--resistance", "law", "--law-A", "1e8",
                      "--law-B", "1000"], "--interfaces"),
    "debonded-paper": (["--interfaces", "debonded", "--resistance", "paper"], "--interfaces"),
    "crater-without-zones": (["--crater", "nose-tip"], "--crater"),
    "estimate-refused-run": (["--estimate", "--contact-ramp", "0"], "contact_ramp"),
}
for fault, (argv, name) in TRAJECTORY.items():
    case(f"trajectory-{fault}", ["trajectory", *argv, "--no-figures", "--out", "{tmp}/o"], 2,
         names=name)
case("trajectory-velocity-vanishing", ["trajectory", "--velocity", "1e-300", "--no-figures",
                                       "--out", "{tmp}/o"], 1)

# --- verify --quick: refused before any FE ---------------------------------------------------
case("verify-quick-debonded", ["verify", "--quick", "--config", "{tmp}/c.toml", "--out",
                               "{tmp}/o"], 2,
     {"c.toml": CONFIG.replace("thickness = 0.65", 'thickness = 0.65\nbottom = "debonded"',
                               1)}, "bottom")
case("verify-quick-concrete-in-MPa", ["verify", "--quick", "--config", "{tmp}/c.toml",
                                      "--out", "{tmp}/o"], 2,
     {"c.toml": one_layer("concrete = {fc = 40.0, rho = 2300.0}")}, "concrete.fc")  # bug
case("verify-quick-workers-zero", ["verify", "--quick", "--workers", "0", "--out", "{tmp}/o"],
     2, names="workers")

# --- shot files with odd contents (validate) -----------------------------------------------
SHOTS = {
    "depth-negative": (ROW.replace("0.173", "-0.1"), "depth_m"),
    "V0-nan": (ROW.replace("277.0", "nan"), "V0_m_s"),
    "V0-Infinity": (ROW.replace("277.0", "Infinity"), "V0_m_s"),
    "V0-hex": (ROW.replace("277.0", "0x115"), "V0_m_s"),
    "V0-underscore": (ROW.replace("277.0", "2_77.0"), "V0_m_s"),  # bug: read as 277
    "fc-huge-cell": (ROW.replace("35200000.0", "9" * 5000), "fc_Pa"),
    "id-bell": (ROW.replace("A1", "A\x07"), "column id"),
    "id-bidi": (ROW.replace("A1", "A\u202e1"), "column id"),  # bug
    "length-negative": (ROW.replace("0.2424", "-1"), "length_m"),
    "extra-cells": (ROW + ",7,8", "line 2"),
}
for fault, (row, name) in SHOTS.items():
    case(f"shots-{fault}", ["validate", "--shots", "{tmp}/s.csv", "--models", "forrestal-1994",
                            "--out", "{tmp}/v"], 2, {"s.csv": shots(row)}, name)
case("shots-duplicate-ids", ["validate", "--shots", "{tmp}/s.csv", "--out", "{tmp}/v"], 2,
     {"s.csv": shots(ROW, ROW.replace("277.0", "300.0"))}, "column id")
case("shots-unicode-and-quoted-ids", ["validate", "--shots", "{tmp}/s.csv", "--models",
                                      "forrestal-1994", "li-chen-2003", "--no-figures",
                                      "--out", "{tmp}/v"], 0,
     {"s.csv": shots(ROW.replace("A1", "b\u00e9ton\u2603"), ROW.replace("A1", '"A,2"'))})
case("shots-unknown-model", ["validate", "--shots", "{tmp}/s.csv", "--models", "concrete-2",
                             "--out", "{tmp}/v"], 2, {"s.csv": shots(ROW)}, "models")


def _materialise(tmp_path, files):
    for name, content in files.items():
        (tmp_path / name).write_text(content, encoding="utf-8")


def _written_text(tmp_path, before):
    for path in sorted(tmp_path.rglob("*")):
        if path.is_file() and path not in before and path.suffix in (".json", ".csv", ".md",
                                                                     ".toml", ".txt"):
            yield path, path.read_text(encoding="utf-8")


@pytest.mark.parametrize("argv, files, code, name", CASES)
def test_recent_features_adversarial(tmp_path, capsys, argv, files, code, name):
    _materialise(tmp_path, files)
    before = set(tmp_path.rglob("*"))
    got = main([a.replace("{tmp}", str(tmp_path)) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    if code == 0:
        assert got == 0, err
        assert not NOT_FINITE.search(out) and not NOT_FINITE.search(err), (out, err)
        for path, text in _written_text(tmp_path, before):
            assert not NOT_FINITE.search(text), path
        return
    assert got == code, (out, err)
    assert out == ""
    lines = [line for line in err.splitlines() if not line.startswith("cavex: validate ")]
    assert len(lines) == 1 and lines[0].startswith(PREFIX[code]), err
    assert len(lines[0]) < 500, "a message of one short line"
    if code == 2:
        assert name in lines[0], lines[0]
        assert set(tmp_path.rglob("*")) == before, "a refused command wrote something"


# --- the oblique model's options (the Python API) --------------------------------------------
BODY = [("nose_points", 0), ("nose_points", True), ("nose_points", 2.0), ("nose_points", 10**6),
        ("azimuths", 3), ("azimuths", None), ("shank_rings", 0), ("shank_rings", -1)]


@pytest.mark.parametrize("key, value", BODY)
def test_a_bad_body_discretisation_is_refused(key, value):
    from cavex.analytic.penetration.body import build_body
    from cavex.config import load_config

    projectile = load_config()[1]
    with pytest.raises(CavexInputError, match=key):
        build_body(projectile, **{key: value})


MODEL = [("rtol", math.nan), ("rtol", -1e-3), ("rtol", 0.0), ("rtol", 0.5), ("rtol", "1e-3"),
         ("atol", math.inf), ("atol", -1.0), ("atol", 0.0), ("method", "Euler"),
         ("contact_ramp", math.nan), ("contact_hold", 0.02), ("hold_time", math.nan),
         ("tangency_psi", -1.0)]


@pytest.mark.parametrize("key, value", MODEL)
def test_a_bad_oblique_setting_is_refused_before_flying(key, value):
    from cavex.analytic.models import make_law
    from cavex.analytic.penetration.oblique import ObliqueModel
    from cavex.config import load_config

    target, projectile = load_config()
    law = make_law(target, projectile)
    with pytest.raises(CavexInputError, match=key):
        ObliqueModel(target, projectile, law, **{key: value})


# --- the concrete cavity solver at the ends of its ranges -------------------------------------
EXTREMES = [(fc, rho, v0) for fc in (1e6, 1e9) for rho in (1000.0, 4000.0)
            for v0 in (1.0, 1e4)]


@pytest.mark.parametrize("fc, rho, v0", EXTREMES)
def test_the_concrete_model_answers_or_fails_plainly_at_the_ends(fc, rho, v0):
    """The concrete model at the corners of the accepted (f_c, rho, V0) (rho V0^2/f_c from
    1e-6 to 4e5): a finite depth > 0 with a flag, or no depth and a reason; never NaN."""
    from cavex.verification.validation.predict import concrete_group
    from cavex.verification.validation.shots import Shot

    shot = Shot(id="X", mass=0.906, diameter=0.0269, length=None, crh=2.0, V0=v0, fc=fc,
                rho=rho, depth=0.1)
    [(depth, flag, reason)] = concrete_group([shot])
    if depth is None:
        assert isinstance(reason, str) and reason and flag is None
        assert not NOT_FINITE.search(reason)
    else:
        assert math.isfinite(depth) and depth > 0.0 and reason is None


# --- faults: read-only and full folders, planted symlinks at final names ------------------

READ_ONLY = {
    "trajectory": ["trajectory", "--no-figures", "--out", "{disk}/out"],
    "penetrate": ["penetrate", "--no-figures", "--out", "{disk}/out"],
    "table": ["table", "--velocities", "0", "100", "--depths", "0", "0.1", "-o",
              "{disk}/t.nc"],
    "calibrate": ["calibrate", "--shots", "{shots}", "--params", "lam", "--out",
                  "{disk}/c.toml"],
    "batch": ["batch", "{sweep}", "--out", "{disk}/b"],
    "verify": ["verify", "--quick", "--out", "{disk}/v"],
}


@pytest.mark.parametrize("command", sorted(READ_ONLY))
def test_a_read_only_folder_is_refused_in_one_line(tmp_path, capsys, command):
    (tmp_path / "s.csv").write_text(shots(ROW, ROW.replace("A1", "A2").replace("277.0",
                                                                                 "550.0")))
    (tmp_path / "sweep.toml").write_text('[sweep]\nname = "s"\n[grid]\n'
                                         'velocities = [100.0]\ndepths = [0.0]\n')
    disk = small_tmpfs(tmp_path / "disk", "ro,size=200k")
    try:
        argv = [a.format(disk=disk, shots=tmp_path / "s.csv", sweep=tmp_path / "sweep.toml")
                for a in READ_ONLY[command]]
        code = main(argv)
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and len(err) == 1 and err[0].startswith("cavex: error: "), err
        assert "'out'" in err[0] or "'o'" in err[0] or "output" in err[0], err[0]
        assert not list(disk.iterdir())
    finally:
        unmount(disk)


def test_a_full_disk_under_table_is_named_and_nothing_is_left(tmp_path, capsys):
    disk = small_tmpfs(tmp_path / "disk", "size=200k")
    try:
        fill(disk / "filler")
        code = main(["table", "--velocities", "0", "100", "--depths", "0", "0.1", "--workers",
                     "1", "--no-progress", "-o", str(disk / "t.nc")])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and "No space left" in err[-1] and "'out'" in err[-1], err  # bug
        assert "Traceback" not in "\n".join(err)
        assert sorted(p.name for p in disk.iterdir()) == ["filler"]  # bug: t.nc.cases/
    finally:
        unmount(disk)


FINAL_NAMES = {
    "trajectory": (["trajectory", "--no-figures"], ["summary.json", "history_target.csv"]),
    "penetrate": (["penetrate", "--no-figures"], ["phases_target.csv"]),
}


@pytest.mark.parametrize("command", sorted(FINAL_NAMES))
def test_a_symlink_planted_at_a_final_name_is_replaced_not_followed(tmp_path, capsys,
                                                                    command):
    argv, names = FINAL_NAMES[command]
    outside = tmp_path / "outside.txt"
    outside.write_text("outside\n")
    out = tmp_path / "out"
    out.mkdir()
    for name in names:
        (out / name).symlink_to(outside)
    code = main([*argv, "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    assert outside.read_text() == "outside\n"
    for name in names:
        assert not (out / name).is_symlink() and (out / name).stat().st_size > 0


def test_the_pass_has_at_least_60_cases():
    assert len(CASES) + len(BODY) + len(MODEL) + len(EXTREMES) + len(READ_ONLY) + 1 \
        + len(FINAL_NAMES) >= 60
