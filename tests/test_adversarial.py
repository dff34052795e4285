"""An adversarial pass over every command (issue 22): inputs at and past the edges of each
accepted range, malformed files, bad output locations, through ``cavex.verification.cli.main``
as a user runs them.

Each case states the exit code. Every case checks: a refusal (2) or a numerical failure (1) is
one line on stderr in the command line's form, with nothing on stdout and no traceback; a
success (0) prints and writes no ``nan`` or ``inf`` (the files it wrote are read back).
"""

import re

import pytest

from cavex.config import default_config_text
from cavex.verification.cli import main

COLUMNS = "id,mass_kg,diameter_m,length_m,crh,V0_m_s,fc_Pa,rho_kg_m3,depth_m"
ROWS = ["A1,0.906,0.0269,0.2424,2.0,277.0,35200000.0,2370.0,0.173",
        "A2,0.906,0.0269,0.2424,2.0,550.0,35200000.0,2370.0,0.5"]
SHOTS = "\n".join([COLUMNS, *ROWS]) + "\n"
CONFIG = default_config_text()
NOT_FINITE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)
PREFIX = {1: "cavex: numerical failure: ", 2: "cavex: error: "}

# values no number option accepts
BAD_NUMBERS = ["nan", "inf", "-inf", "1e400", "abc", ""]


def _config(old, new):
    assert old in CONFIG, old
    return CONFIG.replace(old, new, 1)


def _shots(*rows, header=COLUMNS):
    return "\n".join([header, *rows]) + "\n"


CASES = []  # (id, argv with {tmp}, files {name: text or bytes}, exit code)


def case(name, argv, code, files=None):
    CASES.append(pytest.param(argv, files or {}, code, id=name))


# --- the command line itself ----------------------------------------------------------------
case("no-such-command", ["nosuch"], 2)
case("unknown-option", ["penetrate", "--nosuch"], 2)
case("missing-value", ["stress", "--velocity"], 2)
case("missing-required", ["stress", "--velocity", "500"], 2)
case("choice-not-offered", ["penetrate", "--crater", "tail"], 2)
case("boundary-not-offered", ["penetrate", "--boundary", "static"], 2)
case("old-model-option", ["penetrate", "--model", "derived"], 2)
case("old-resistance-value", ["penetrate", "--resistance", "closed-form"], 2)
case("stress-table-refused", ["stress", "--resistance", "table", "--velocity", "500",
                              "--depth", "0.1"], 2)
case("paper-with-dynamic", ["penetrate", "--resistance", "paper", "--boundary", "dynamic",
                            "--out", "{tmp}/o"], 2)
for command, argv in (("penetrate", ["--out", "{tmp}/o"]),
                      ("stress", ["--velocity", "500", "--depth", "0.1"]),
                      ("trajectory", ["--out", "{tmp}/o"])):
    case(f"epsilon-without-paper-{command}", [command, "--epsilon", "cylindrical", *argv], 2)
case("calibrate-repeated-id", ["calibrate", "--shots", "{tmp}/s.csv", "--ids", "A1", "A1",
                               "--params", "lam", "--out", "{tmp}/c.toml"], 2, {"s.csv": SHOTS})
case("table-without-file", ["penetrate", "--resistance", "table", "--out", "{tmp}/o"], 2)
case("file-without-table", ["penetrate", "--table", "{tmp}/t.nc", "--out", "{tmp}/o"], 2,
     {"t.nc": b"CDF\x01"})

# --- numbers past their ranges, every command's number options -------------------------------
for value in BAD_NUMBERS + ["-1", "1e5"]:
    case(f"stress-velocity-{value or 'empty'}", ["stress", "--velocity", value, "--depth", "0.1"],
         2)
for value in BAD_NUMBERS + ["-0.1"]:
    case(f"stress-depth-{value or 'empty'}", ["stress", "--velocity", "500", "--depth", value], 2)
for value in BAD_NUMBERS + ["0.5", "-1", "0.6"]:
    case(f"fem-nu-{value or 'empty'}", ["fem", "--velocity", "500", "--depth", "0.1", "--nu",
                                        value], 2)
for value in BAD_NUMBERS + ["-5", "2e4"]:
    case(f"fem-velocity-{value or 'empty'}", ["fem", "--velocity", value, "--depth", "0.1"], 2)
for value in BAD_NUMBERS + ["-1", "2e4"]:
    case(f"table-velocities-{value or 'empty'}", ["table", "--velocities", "100", value,
                                                  "--depths", "0", "-o", "{tmp}/t.nc"], 2)
for value in BAD_NUMBERS + ["-0.5"]:
    case(f"table-depths-{value or 'empty'}", ["table", "--velocities", "100", "--depths", value,
                                              "-o", "{tmp}/t.nc"], 2)
for option in ("--velocity", "--obliquity", "--attack", "--attack-plane", "--spin",
               "--contact-ramp", "--contact-hold"):
    for value in BAD_NUMBERS:
        case(f"trajectory{option}-{value or 'empty'}",
             ["trajectory", option, value, "--no-figures", "--out", "{tmp}/o"], 2)
for option, value in (("--velocity", "0"), ("--velocity", "-600"), ("--velocity", "1.00001e4"),
                      ("--obliquity", "90"), ("--obliquity", "-90"), ("--attack", "-1"),
                      ("--attack", "90"), ("--spin", "1e6"), ("--contact-ramp", "0"),
                      ("--contact-ramp", "0.0009"), ("--contact-ramp", "0.05"),
                      ("--contact-ramp", "100"), ("--contact-hold", "0"),
                      ("--contact-hold", "-1e-6"), ("--contact-hold", "1e-3")):
    case(f"trajectory{option}-{value}", ["trajectory", option, value, "--no-figures",
                                         "--out", "{tmp}/o"], 2)
for option in ("--law-A", "--law-B"):
    for value in BAD_NUMBERS + ["-1"]:
        other = "--law-B" if option == "--law-A" else "--law-A"
        case(f"trajectory{option}-{value or 'empty'}",
             ["trajectory", "--resistance", "law", option, value, other, "1000",
              "--no-figures", "--out", "{tmp}/o"], 2)
case("trajectory-law-A-alone", ["trajectory", "--resistance", "law", "--law-A", "1e8",
                                "--out", "{tmp}/o"], 2)
case("trajectory-law-options-without-law", ["trajectory", "--law-A", "1e8", "--law-B", "1000",
                                            "--out", "{tmp}/o"], 2)
case("trajectory-law-boundary", ["trajectory", "--resistance", "law", "--law-A", "1e8",
                                 "--law-B", "1000", "--boundary", "dynamic", "--out", "{tmp}/o"],
     2)
case("trajectory-paper-no-free-surface", ["trajectory", "--resistance", "paper",
                                          "--no-free-surface", "--out", "{tmp}/o"], 2)
case("trajectory-compare-one-layer", ["trajectory", "--config", "{tmp}/c.toml",
                                      "--compare-homogeneous", "--out", "{tmp}/o"], 2,
     {"c.toml": CONFIG[:CONFIG.index("[[layers]]", CONFIG.index("[[layers]]") + 1)]})
for value in ("0", "-1", "1.5", "abc", "1e400"):
    case(f"workers-{value}", ["table", "--velocities", "100", "--depths", "0", "--workers",
                              value, "-o", "{tmp}/t.nc"], 2)
case("scheduler-not-an-address", ["table", "--velocities", "100", "--depths", "0",
                                  "--scheduler", "nowhere", "-o", "{tmp}/t.nc"], 2)

CALIBRATION = CONFIG + """
[calibration]
model = "derived-dynamic"
params = ["lam", "strength_factor"]
lam = 0.5
strength_factor = 1.0
modulus_factor = 1.0
nu = 0.2
shots = ["A1", "A2"]
"""

# --- configuration files: every command that reads one ---------------------------------------
CONFIG_FAULTS = {
    "missing": None,
    "empty": "",
    "binary": b"\x00\xff\xfe garbage \x80",
    "latin1": "# caf\xe9\n".encode("latin-1") + CONFIG.encode(),
    "syntax": CONFIG.replace("[projectile]", "[projectile", 1),
    "unknown-key": CONFIG.replace("[projectile]", "[projectile]\nspeed = 3", 1),
    "r-huge": _config("r = 0.0125", "r = 1e150"),
    "r-tiny": _config("r = 0.0125", "r = 1e-300"),
    "R-huge": _config("R = 0.075", "R = 1e300"),
    "m-huge": _config("m = 0.505", "m = 1e308"),
    "m-zero": _config("m = 0.505", "m = 0"),
    "V0-nan": _config("V0 = 1000.0", "V0 = nan"),
    "V0-fast": _config("V0 = 1000.0", "V0 = 2e4"),
    "V0-string": _config("V0 = 1000.0", 'V0 = "fast"'),
    "no-layers": CONFIG[:CONFIG.index("[[layers]]")],
}
CONFIG_COMMANDS = {
    "penetrate": ["penetrate", "--out", "{tmp}/o"],
    "stress": ["stress", "--velocity", "500", "--depth", "0.1"],
    "fem": ["fem", "--velocity", "500", "--depth", "0.1"],
    "trajectory": ["trajectory", "--no-figures", "--out", "{tmp}/o"],
    "table": ["table", "--velocities", "100", "--depths", "0", "-o", "{tmp}/t.nc"],
    "verify": ["verify", "--quick", "--out", "{tmp}/o"],
    "config": ["config"],
}
for fault, text in CONFIG_FAULTS.items():
    for command, argv in CONFIG_COMMANDS.items():
        case(f"config-{fault}-{command}", [*argv, "--config", "{tmp}/c.toml"], 2,
             None if text is None else {"c.toml": text})
case("config-default-and-file", ["config", "--default", "--config", "{tmp}/c.toml"], 2,
     {"c.toml": CONFIG})
case("config-reads-a-calibration", ["config", "--config", "{tmp}/cal.toml"], 0,
     {"cal.toml": CALIBRATION.replace('["A1", "A2"]', '["\U0001F600", "x\\ny"]')})
case("config-is-a-folder", ["penetrate", "--config", "{tmp}", "--out", "{tmp}/o"], 2)

# --- shot files: calibrate and validate ------------------------------------------------------
SHOT_FAULTS = {
    "missing": None,
    "empty": "",
    "header-only": COLUMNS + "\n",
    "binary": b"\x00\xff\xfe\x80",
    "latin1": (SHOTS + "Z\xe9,0.9,0.0269,,2,300,3.5e7,2370,0.2\n").encode("latin-1"),
    "missing-column": _shots(*[r.rsplit(",", 1)[0] for r in ROWS], header=COLUMNS[:-8]),
    "short-row": _shots(ROWS[0], "B,0.9,0.0269"),
    "duplicate-id": _shots(ROWS[0], ROWS[0]),
    "empty-id": _shots(ROWS[0], "," + ROWS[1].split(",", 1)[1]),
    "mass-huge": _shots(ROWS[0], "B,1e308,0.0269,,2,300,3.5e7,2370,0.2"),
    "mass-zero": _shots(ROWS[0], "B,0,0.0269,,2,300,3.5e7,2370,0.2"),
    "diameter-huge": _shots(ROWS[0], "B,0.9,1e300,,2,300,3.5e7,2370,0.2"),
    "crh-huge": _shots(ROWS[0], "B,0.9,0.0269,,1e300,300,3.5e7,2370,0.2"),
    "crh-small": _shots(ROWS[0], "B,0.9,0.0269,,0.4,300,3.5e7,2370,0.2"),
    "V0-fast": _shots(ROWS[0], "B,0.9,0.0269,,2,2e4,3.5e7,2370,0.2"),
    "V0-slow": _shots(ROWS[0], "B,0.9,0.0269,,2,1e-300,3.5e7,2370,0.2"),
    "fc-MPa": _shots(ROWS[0], "B,0.9,0.0269,,2,300,35.2,2370,0.2"),
    "rho-g-cm3": _shots(ROWS[0], "B,0.9,0.0269,,2,300,3.5e7,2.37,0.2"),
    "depth-nan": _shots(ROWS[0], "B,0.9,0.0269,,2,300,3.5e7,2370,nan"),
    "depth-huge": _shots(ROWS[0], "B,0.9,0.0269,,2,300,3.5e7,2370,1e300"),
}
for fault, text in SHOT_FAULTS.items():
    files = None if text is None else {"s.csv": text}
    case(f"shots-{fault}-calibrate", ["calibrate", "--shots", "{tmp}/s.csv", "--out",
                                      "{tmp}/c.toml"], 2, files)
    case(f"shots-{fault}-validate", ["validate", "--shots", "{tmp}/s.csv", "--out", "{tmp}/v"], 2,
         files)
# length_m is not used by the rigid-projectile models (docs/validation.md): accepted as given
case("shots-length-short-calibrate", ["calibrate", "--shots", "{tmp}/s.csv", "--params", "lam",
                                      "--out", "{tmp}/c.toml"], 0,
     {"s.csv": _shots(ROWS[0], "B,0.9,0.0269,0.01,2,300,3.5e7,2370,0.2")})
case("calibrate-unknown-id", ["calibrate", "--shots", "{tmp}/s.csv", "--ids", "A9", "--out",
                              "{tmp}/c.toml"], 2, {"s.csv": SHOTS})
case("calibrate-unknown-param", ["calibrate", "--shots", "{tmp}/s.csv", "--params", "lamb",
                                 "--out", "{tmp}/c.toml"], 2, {"s.csv": SHOTS})
case("calibrate-repeated-param", ["calibrate", "--shots", "{tmp}/s.csv", "--params", "lam",
                                  "lam", "--out", "{tmp}/c.toml"], 2, {"s.csv": SHOTS})
case("calibrate-too-few-shots", ["calibrate", "--shots", "{tmp}/s.csv", "--ids", "A1",
                                 "--params", "lam", "strength_factor", "--out", "{tmp}/c.toml"],
     2, {"s.csv": SHOTS})
case("calibrate-out-not-toml", ["calibrate", "--shots", "{tmp}/s.csv", "--out", "{tmp}/c.txt"],
     2, {"s.csv": SHOTS})
case("calibrate-out-folder", ["calibrate", "--shots", "{tmp}/s.csv", "--out", "{tmp}"], 2,
     {"s.csv": SHOTS})

# --- calibration files: validate --calibration and --config ---------------------------------
CALIBRATION_FAULTS = {
    "no-table": CONFIG,
    "old-label": CALIBRATION.replace('"derived-dynamic"', '"fe-table"'),
    "unknown-key": CALIBRATION.replace("nu = 0.2", "nu = 0.2\nmystery = 1"),
    "lam-out-of-range": CALIBRATION.replace("lam = 0.5", "lam = 5.0"),
    "params-not-array": CALIBRATION.replace('["lam", "strength_factor"]', '"lam"'),
    "shots-empty": CALIBRATION.replace('["A1", "A2"]', "[]"),
    "skipped-not-array": CALIBRATION.replace("nu = 0.2", 'nu = 0.2\nskipped = "A1"'),
    "outliers-numbers": CALIBRATION.replace("nu = 0.2", "nu = 0.2\noutliers = [1]"),
    "surrogate-escape": CALIBRATION.replace('["A1", "A2"]', '["\\ud800"]'),
}
for fault, text in CALIBRATION_FAULTS.items():
    case(f"calibration-{fault}", ["validate", "--shots", "{tmp}/s.csv", "--calibration",
                                  "{tmp}/cal.toml", "--out", "{tmp}/v"], 2,
         {"s.csv": SHOTS, "cal.toml": text})
case("calibration-twice", ["validate", "--shots", "{tmp}/s.csv", "--calibration",
                           "{tmp}/cal.toml", "{tmp}/cal.toml", "--out", "{tmp}/v"], 2,
     {"s.csv": SHOTS, "cal.toml": CALIBRATION})

# --- FE tables and sweeps --------------------------------------------------------------------
for fault, data in (("missing", None), ("empty", b""), ("garbage", b"not a netcdf file"),
                    ("text", CONFIG)):
    files = None if data is None else {"t.nc": data}
    case(f"table-file-{fault}-penetrate", ["penetrate", "--resistance", "table", "--table",
                                           "{tmp}/t.nc", "--out", "{tmp}/o"], 2, files)
    case(f"table-file-{fault}-trajectory", ["trajectory", "--resistance", "table", "--table",
                                            "{tmp}/t.nc", "--out", "{tmp}/o"], 2, files)
SWEEP_FAULTS = {
    "missing": None,
    "empty": "",
    "syntax": "[grid\n",
    "unknown-key": 'name = "s"\nmystery = 1\n',
    "velocity-negative": 'name = "s"\n[grid]\nvelocities = [-1]\ndepths = [0.0]\n',
    "velocity-nan": 'name = "s"\n[grid]\nvelocities = [nan]\ndepths = [0.0]\n',
}
for fault, text in SWEEP_FAULTS.items():
    case(f"sweep-{fault}", ["batch", "{tmp}/sweep.toml", "--out", "{tmp}/b"], 2,
         None if text is None else {"sweep.toml": text})

# --- output locations ------------------------------------------------------------------------
OUTPUT_COMMANDS = {
    "penetrate": ["penetrate", "--out"],
    "trajectory": ["trajectory", "--no-figures", "--out"],
    "verify": ["verify", "--quick", "--out"],
    "table": ["table", "--velocities", "100", "--depths", "0", "-o"],
}
for command, argv in OUTPUT_COMMANDS.items():
    target = "{tmp}/file.txt/x.nc" if command == "table" else "{tmp}/file.txt/sub"
    case(f"out-under-a-file-{command}", [*argv, target], 2, {"file.txt": "x"})
    case(f"out-empty-{command}", [*argv, ""], 2)
    case(f"out-proc-{command}", [*argv, "/proc/cavex-out" + (".nc" if command == "table"
                                                             else "")], 2)
case("validate-out-is-a-file", ["validate", "--shots", "{tmp}/s.csv", "--out", "{tmp}/s.csv"],
     2, {"s.csv": SHOTS})

# --- runs at the edges of the accepted ranges: they answer, in finite numbers ---------------
case("stress-depth-zero", ["stress", "--velocity", "500", "--depth", "0"], 0)
case("stress-velocity-zero", ["stress", "--velocity", "0", "--depth", "0.1", "--json"], 0)
case("stress-velocity-max", ["stress", "--velocity", "1e4", "--depth", "5", "--json"], 0)
case("stress-paper-cylindrical", ["stress", "--resistance", "paper", "--epsilon",
                                  "cylindrical-sigma_c", "--velocity", "800", "--depth", "0.3"],
     0)
case("fem-at-rest-on-the-surface", ["fem", "--velocity", "0", "--depth", "0", "--json"], 0)
case("fem-fastest-deepest", ["fem", "--velocity", "1e4", "--depth", "5", "--json"], 0)
case("fem-nu-lowest", ["fem", "--velocity", "500", "--depth", "0.1", "--nu", "-0.99"], 0)
case("table-grid-corners", ["table", "--velocities", "0", "1e4", "--depths", "0", "0.5",
                            "--workers", "1", "--no-progress", "--json", "-o", "{tmp}/t.nc"], 0)
case("penetrate-nose-tip", ["penetrate", "--crater", "nose-tip", "--json", "--out", "{tmp}/o"],
     0)
case("penetrate-quasi-static", ["penetrate", "--boundary", "quasi-static", "--out",
                                "{tmp}/o"], 0)
case("penetrate-slow", ["penetrate", "--config", "{tmp}/c.toml", "--out", "{tmp}/o"], 0,
     {"c.toml": _config("V0 = 1000.0", "V0 = 1.0")})
# a 0.5 kg needle and a 1e6 kg body are still moving after the integrator's 10 s phase limit:
# a numerical failure that says so
case("penetrate-smallest-body", ["penetrate", "--config", "{tmp}/c.toml", "--out", "{tmp}/o"],
     1, {"c.toml": _config("r = 0.0125", "r = 1e-4").replace("l = 0.06", "l = 4e-4")
         .replace("R = 0.075", "R = 6e-4")})
case("penetrate-heaviest", ["penetrate", "--config", "{tmp}/c.toml", "--json", "--out",
                            "{tmp}/o"], 1, {"c.toml": _config("m = 0.505", "m = 1e6")})
case("trajectory-spin-at-bound", ["trajectory", "--spin", "-8e4", "--no-figures", "--out",
                                  "{tmp}/o"], 0)
case("trajectory-attack-plane-wraps", ["trajectory", "--attack", "5", "--attack-plane", "725",
                                       "--obliquity", "20", "--no-figures", "--out", "{tmp}/o"],
     0)
case("trajectory-ramp-at-bounds", ["trajectory", "--contact-ramp", "0.001", "--obliquity",
                                   "45", "--no-figures", "--out", "{tmp}/o"], 0)
case("trajectory-tail-first", ["trajectory", "--attack", "89.99", "--no-figures", "--out",
                               "{tmp}/o"], 1)
case("trajectory-too-heavy-to-stop", ["trajectory", "--config", "{tmp}/c.toml", "--no-figures",
                                      "--out", "{tmp}/o"], 1,
     {"c.toml": _config("m = 0.505", "m = 1e6\nlength = 2.0")})
case("trajectory-lightest", ["trajectory", "--config", "{tmp}/c.toml", "--no-figures", "--out",
                             "{tmp}/o"], 0,
     {"c.toml": _config("m = 0.505", "m = 1e-6\nlength = 0.2")})
case("trajectory-friction-10", ["trajectory", "--config", "{tmp}/c.toml", "--obliquity", "80",
                                "--no-figures", "--out", "{tmp}/o"], 0,
     {"c.toml": _config("m = 0.505", "m = 0.505\nmu = 10")})
case("calibrate-bom-crlf", ["calibrate", "--shots", "{tmp}/s.csv", "--params", "lam",
                            "--out", "{tmp}/c.toml"], 0,
     {"s.csv": ("\ufeff" + SHOTS.replace("\n", "\r\n")).encode("utf-8")})
case("calibrate-paper", ["calibrate", "--shots", "{tmp}/s.csv", "--resistance", "paper",
                         "--params", "strength_factor", "--json", "--out", "{tmp}/c.toml"], 0,
     {"s.csv": SHOTS})
case("calibrate-shot-beyond-the-model", ["calibrate", "--shots", "{tmp}/s.csv", "--params",
                                         "strength_factor", "--out", "{tmp}/c.toml"], 0,
     {"s.csv": _shots(*ROWS, "HEAVY,1e6,2e-4,,1000,10000,1e6,1000,1")})
# five identical shots: the three parameters are not determined (J^T J singular): once
# "+- inf" and a JSON Infinity, now "no standard error" and null
case("calibrate-undetermined-parameters", ["calibrate", "--shots", "{tmp}/s.csv", "--params",
                                           "lam", "strength_factor", "modulus_factor", "--json",
                                           "--out", "{tmp}/c.toml"], 0,
     {"s.csv": _shots(*(f"S{i}" + ROWS[0][2:] for i in range(5)))})
case("calibrate-every-shot-beyond", ["calibrate", "--shots", "{tmp}/s.csv", "--params",
                                     "strength_factor", "--out", "{tmp}/c.toml"], 1,
     {"s.csv": _shots("H1,1e6,2e-4,,1000,10000,1e6,1000,1", "H2,1e6,2e-4,,1000,9000,1e6,1000,1")})


def _materialise(tmp_path, files):
    for name, content in files.items():
        path = tmp_path / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content, encoding="utf-8")


def _written_text(tmp_path, before):
    """Text of every file the command wrote under ``tmp_path`` (NetCDF and PNG skipped)."""
    for path in sorted(tmp_path.rglob("*")):
        if path.is_file() and path not in before and path.suffix in (".json", ".csv", ".md",
                                                                     ".toml", ".txt"):
            yield path, path.read_text(encoding="utf-8")


@pytest.mark.parametrize("argv, files, code", CASES)
def test_adversarial(tmp_path, capsys, argv, files, code):
    _materialise(tmp_path, files)
    before = set(tmp_path.rglob("*"))
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    got = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    if code == 0:
        assert got == 0, err
        assert not NOT_FINITE.search(err), err
        assert not NOT_FINITE.search(out), out
        for path, text in _written_text(tmp_path, before):
            assert not NOT_FINITE.search(text), path
        return
    assert got == code, (out, err)
    assert out == ""
    assert err.count("\n") == 1 and err.startswith(PREFIX[code]), err
    if code == 2:  # a refusal writes nothing
        assert set(tmp_path.rglob("*")) == before


def test_the_pass_has_at_least_150_cases():
    assert len(CASES) >= 150
