"""The ``cavex`` command line, in process (``main(argv)`` with capsys) and once as a subprocess.

The CLI only prints what the library computes, so its numbers are compared with the library
called here to round-off (JSON round-trips floats exactly; 1e-15 relative allows a few ulps);
the CSV files carry 6 significant digits (``number_format.TRAJECTORY_DIGITS``), half a unit
of the 6th digit is 5e-6 relative.
"""

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from cavex.analytic.cavity import cavity_solution
from cavex.analytic.geometry import spherical_problem
from cavex.analytic.paper_model import paper_coefficients
from cavex.analytic.penetration.integrator import penetrate
from cavex.analytic.penetration.resistance import ClosedFormResistance
from cavex.config import default_config_text, load_config
from cavex.verification.cli import COMPILING, main
from cavex.verification.output.number_format import TRAJECTORY_QUANTA, Decimals

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
TRAJECTORY_COLUMNS = ["t_s", "depth_m", "velocity_m_s", "deceleration_m_s2", "phase"]
PHASE_COLUMNS = ["phase", "label", "end_depth_m", "end_velocity_m_s", "end_time_s", "end_reason"]
# docs/problem.md section 3, Table 2: (L m, v m/s, t ms)
PAPER_TABLE2 = [(0.12, 894.7, 0.12), (0.40, 506.4, 0.53), (0.65, 284.3, 1.20), (0.79, 0.0, 2.40)]
ROUNDOFF = 1e-15
CSV_ROUNDING = 5e-6 * (1 + 1e-6)  # half a unit in the 6th significant digit, relative


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def default():
    return load_config()


def _read_csv(path):
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    return rows[0], rows[1:]


def test_penetrate_json_outputs_and_files(capsys, tmp_path, default):
    target, projectile = default
    out_dir = tmp_path / "fresh" / "run"
    code, out, err = run(capsys, "penetrate", "--json", "--out", str(out_dir))
    assert (code, err) == (0, "")
    result = json.loads(out)
    assert {k: result[k] for k in ("model", "resistance", "boundary", "epsilon", "crater")} == {
        "model": "derived-dynamic", "resistance": "derived", "boundary": "dynamic",
        "epsilon": "quasi-static", "crater": "nose-base"}  # default: dynamic (README "Commands")
    trajectory = penetrate(target, projectile, ClosedFormResistance(target, projectile,
                                                                    boundary="dynamic"))
    assert len(result["phases"]) == len(trajectory.phases) == 10
    for row, phase in zip(result["phases"], trajectory.phases, strict=True):
        assert row["label"] == phase.label and row["end_reason"] == phase.end_reason
        assert row["end_depth_m"] == pytest.approx(phase.end_depth, rel=ROUNDOFF)
        assert row["end_velocity_m_s"] == pytest.approx(phase.end_velocity, rel=ROUNDOFF)
        assert row["end_time_s"] == pytest.approx(phase.end_time, rel=ROUNDOFF)
    # Table 2: the paper's four rows beside ours (crater, b reaches H1, nose at H1, stop)
    table2 = result["table2"]
    assert [row["phase"] for row in table2] == [1, 2, 3, 4]
    for row, (depth, velocity, ms) in zip(table2, PAPER_TABLE2, strict=True):
        assert row["paper"] == pytest.approx(
            {"depth_m": depth, "velocity_m_s": velocity, "time_s": ms * 1e-3}, rel=1e-12)
    phases = trajectory.phases
    for row, phase in zip(table2, (phases[0], phases[1], phases[2], phases[-1]), strict=True):
        assert row["ours"] == pytest.approx({"depth_m": phase.end_depth, "velocity_m_s":
                                             phase.end_velocity, "time_s": phase.end_time},
                                            rel=ROUNDOFF)
    # files: two trajectories, the phase table and two PNG figures, all inside out_dir
    names = {"trajectory_target.csv", "trajectory_first_layer_only.csv", "phases_target.csv",
             "velocity_time.png", "deceleration_depth.png"}
    assert {Path(p).name for p in result["outputs"]} == names
    assert {p.name for p in out_dir.iterdir()} == names  # no temporary files left
    for name in ("velocity_time.png", "deceleration_depth.png"):
        data = (out_dir / name).read_bytes()
        assert data[:8] == PNG_SIGNATURE and len(data) > 1000
    header, rows = _read_csv(out_dir / "trajectory_target.csv")
    assert header == TRAJECTORY_COLUMNS
    written = trajectory.rows()  # equal intervals of time within each phase
    assert len(rows) == len(written["t_s"])
    columns = list(zip(*rows, strict=True))
    for name, column in zip(header, columns, strict=True):
        rule = TRAJECTORY_QUANTA.get(name)  # number_format: a Decimals quantum or digits
        quantum = rule if isinstance(rule, Decimals) else None
        half = 0.0 if quantum is None else 0.5 * 10.0 ** -int(quantum) * (1 + 1e-6)
        rel = CSV_ROUNDING if quantum is not None or rule is None else (
            0.5 * 10.0 ** (1 - rule) * (1 + 1e-6))
        assert [float(v) for v in column] == pytest.approx(list(written[name]), rel=rel,
                                                           abs=half)
    header, rows = _read_csv(out_dir / "trajectory_first_layer_only.csv")
    assert header == TRAJECTORY_COLUMNS and len(rows) > 10
    assert float(rows[-1][2]) == 0.0  # velocity at the stop
    header, rows = _read_csv(out_dir / "phases_target.csv")
    assert header == PHASE_COLUMNS
    assert [row[1] for row in rows] == [p.label for p in trajectory.phases]
    assert [float(row[2]) for row in rows] == pytest.approx(
        [p.end_depth for p in trajectory.phases], rel=CSV_ROUNDING)


def test_penetrate_text_paper_model(capsys, tmp_path, default):
    target, projectile = default
    code, out, err = run(capsys, "penetrate", "--resistance", "paper", "--out", str(tmp_path))
    assert (code, err) == (0, "")
    trajectory = penetrate(target, projectile, ClosedFormResistance(target, projectile, "paper"))
    for phase in trajectory.phases:
        assert f"{phase.end_depth:8.4f}" in out and phase.label in out
    assert "beside the paper's Table 2" in out and "894.7" in out
    code, out, err = run(capsys, "penetrate", "--resistance", "paper", "--json", "--out",
                         str(tmp_path))
    result = json.loads(out)
    assert result["model"] == "paper"
    assert [p["end_depth_m"] for p in result["phases"]] == pytest.approx(
        [p.end_depth for p in trajectory.phases], rel=ROUNDOFF)


@pytest.mark.parametrize("boundary", ["quasi-static", "dynamic"])
def test_stress_json_equals_cavity_solution(capsys, default, boundary):
    target, projectile = default
    code, out, err = run(capsys, "stress", "--velocity", "500", "--depth", "0.3", "--json",
                         "--boundary", boundary)
    assert (code, err) == (0, "")
    result = json.loads(out)
    layers, interfaces = spherical_problem(target, projectile, 0.3)
    state = cavity_solution(layers, interfaces, 500.0, projectile.r, boundary=boundary)
    assert result["sigma_r_Pa"] == pytest.approx(state.stress, rel=ROUNDOFF)
    assert result["S"] == pytest.approx(state.stress / 25e6, rel=ROUNDOFF)
    assert result["plastic_radius_m"] == pytest.approx(state.plastic_radius, rel=ROUNDOFF)
    assert result["response_state"] == state.state == "a"
    # h_i = H_i - L + l (Eq. 16)
    assert result["interface_radii_m"] == pytest.approx([0.65 - 0.3 + 0.06, 1.1 - 0.3 + 0.06],
                                                        rel=ROUNDOFF)
    assert (result["depth_m"], result["velocity_m_s"]) == (0.3, 500.0)
    assert result["wall_layer"] == "concrete"


def test_stress_paper_model(capsys, default):
    target, projectile = default
    code, out, err = run(capsys, "stress", "--velocity", "500", "--depth", "0.3", "--json",
                         "--resistance", "paper")
    assert (code, err) == (0, "")
    result = json.loads(out)
    c = paper_coefficients(target, projectile, 0.3)
    assert result["sigma_r_Pa"] == pytest.approx(c.tau * c.A + c.B * c.rho * 500.0 ** 2,
                                                 rel=ROUNDOFF)
    assert (result["equation"], result["response_state"]) == (19, "a")
    assert (result["A"], result["B"]) == (c.A, c.B)


def test_fem_json_against_analytic(capsys, default):
    target, projectile = default
    code, out, err = run(capsys, "fem", "--velocity", "300", "--depth", "0.3", "--json")
    assert (code, err) == (0, "")
    result = json.loads(out)
    layers, interfaces = spherical_problem(target, projectile, 0.3)
    fe = result["fe_sigma_r_Pa"]
    for boundary in ("dynamic", "quasi-static"):
        analytic = cavity_solution(layers, interfaces, 300.0, projectile.r, boundary=boundary)
        assert result["analytic_sigma_r_Pa"][boundary] == pytest.approx(analytic.stress,
                                                                        rel=ROUNDOFF)
        assert result["relative_difference"][boundary] == pytest.approx(
            fe / analytic.stress - 1.0, rel=1e-12, abs=1e-15)
    # measured -0.91 % (dynamic): the FE check of the closed form at this depth
    assert abs(result["relative_difference"]["dynamic"]) < 0.05
    assert result["interface_radii_m"] == pytest.approx(interfaces, rel=ROUNDOFF)
    assert result["S"] == pytest.approx(fe / 25e6, rel=ROUNDOFF)


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def _bad_configs(tmp_path):
    default = default_config_text()
    return {
        "malformed": _write(tmp_path, "malformed.toml", "[projectile\nr = 0.0125\n"),
        "unknown_key": _write(tmp_path, "unknown.toml",
                              default.replace("lam = 0.15", "lam = 0.15\nfoo = 1.0")),
        "lam": _write(tmp_path, "lam.toml", default.replace("lam = 0.15", "lam = 3.5")),
        "negative_V0": _write(tmp_path, "v0.toml", default.replace("V0 = 1000.0", "V0 = -5.0")),
    }


BAD_INPUTS = [
    # (argv, text the one-line error must name); OUT is replaced by a fresh directory,
    # CONFIG:<name> by a bad TOML file
    (["stress", "--velocity", "-1", "--depth", "0.3"], "'velocity'"),
    (["stress", "--velocity", "500", "--depth", "-0.3"], "'depth'"),
    (["stress", "--velocity", "500", "--depth", "-0.3", "--resistance", "paper"], "'depth'"),
    (["stress", "--velocity", "abc", "--depth", "0.3"], "--velocity"),
    (["stress", "--depth", "0.3"], "--velocity"),
    (["fem", "--velocity", "300", "--depth", "0.3", "--nu", "0.6"], "'nu'"),
    (["fem", "--velocity", "-300", "--depth", "0.3"], "'velocity'"),
    (["penetrate", "--out", "OUT", "--foo"], "--foo"),
    (["penetrate", "--out", "OUT", "--resistance", "paper", "--boundary", "dynamic"],
     "'boundary'"),
    (["penetrate", "--out", "OUT", "--config", "CONFIG:malformed"], "malformed.toml"),
    (["penetrate", "--out", "OUT", "--config", "CONFIG:unknown_key"], "': layers[0].foo "),
    (["penetrate", "--out", "OUT", "--config", "CONFIG:lam"], "': layers[0].lam "),
    (["penetrate", "--out", "OUT", "--config", "CONFIG:negative_V0"], "': projectile.V0 "),
    (["penetrate", "--out", "OUT", "--config", "missing.toml"], "missing.toml"),
    # BUG: `--velocity inf` passes the `>= 0` check of the paper path of stress_at_depth and
    # prints "Infinity" (not JSON) with exit code 0.
    (["stress", "--velocity", "inf", "--depth", "0.3", "--resistance", "paper", "--json"],
     "'velocity'"),
    # BUG: an infinite depth passes spherical_problem's `depth >= 0` and returns the soil's
    # single-medium stress at "depth_m": Infinity with exit code 0.
    (["stress", "--velocity", "500", "--depth", "inf", "--json"], "'depth'"),
    # BUG: stress silently ignores --boundary for the paper model (penetrate rejects it).
    (["stress", "--velocity", "500", "--depth", "0.3", "--resistance", "paper", "--boundary",
      "dynamic"], "'boundary'"),
    (["stress", "--velocity", "500", "--depth", "0.3", "--resistance", "table"],
     "a table is no closed form"),
    (["penetrate", "--out", "OUT", "--resistance", "table"], "'--table FILE' goes with"),
]

# the earlier spellings of the resistance choice (issue 18), each refused with the new one
MODEL_REPLACED = ("option --model was replaced by --resistance derived|paper|table (with "
                  "--boundary dynamic|quasi-static)")
OLD_SPELLINGS = [
    (["penetrate", "--out", "OUT", "--model", "paper"],
     f"{MODEL_REPLACED}; for 'paper' use --resistance paper"),
    (["penetrate", "--out", "OUT", "--model", "derived"],
     f"{MODEL_REPLACED}; for 'derived' use --resistance derived"),
    (["stress", "--velocity", "500", "--depth", "0.3", "--model", "paper"],
     f"{MODEL_REPLACED}; for 'paper' use --resistance paper"),
    (["penetrate", "--out", "OUT", "--resistance", "closed-form"],
     "option --resistance closed-form was replaced by --resistance derived or --resistance "
     "paper"),
    (["trajectory", "--out", "OUT", "--resistance", "derived-quasi-static"],
     "option --resistance derived-quasi-static was replaced by --resistance derived "
     "--boundary quasi-static"),
    (["calibrate", "--shots", "examples/shots_forrestal1994.csv", "--out", "OUT.toml",
      "--model", "fe-table"],
     f"{MODEL_REPLACED}; for 'fe-table' use --resistance table"),
    (["calibrate", "--shots", "examples/shots_forrestal1994.csv", "--out", "OUT.toml",
      "--model", "derived-quasi-static"],
     f"{MODEL_REPLACED}; for 'derived-quasi-static' use --resistance derived --boundary "
     "quasi-static"),
    (["calibrate", "--shots", "examples/shots_forrestal1994.csv", "--out", "OUT.toml",
      "--resistance", "fe-table"], "option --resistance fe-table was replaced by --resistance "
     "table"),
]


def test_resistance_options_of_every_command():
    """One vocabulary: the settings each command reads from its options (calibrate builds its
    FE tables, so it has no --table; stress has no table)."""
    from cavex.verification.cli import build_parser
    from cavex.verification.commands.options import CLOSED_FORMS, FLOWN, resistance_settings

    parser = build_parser()
    calibrate = ["calibrate", "--shots", "s.csv", "--out", "c.toml"]
    cases = [
        (["penetrate"], {"resistance": "derived", "boundary": "dynamic",
                         "epsilon": "quasi-static", "table": None}),
        (["penetrate", "--resistance", "paper", "--epsilon", "cylindrical"],
         {"resistance": "paper", "boundary": "quasi-static", "epsilon": "cylindrical",
          "table": None}),
        (["penetrate", "--resistance", "table", "--table", "t.nc", "--boundary",
          "quasi-static"], {"resistance": "table", "boundary": "quasi-static",
                            "epsilon": "quasi-static", "table": "t.nc"}),
        (["trajectory", "--resistance", "law"], {"resistance": "law", "boundary": "dynamic",
                                                 "epsilon": "quasi-static", "table": None}),
        ([*calibrate, "--resistance", "table"], {"resistance": "table", "boundary": "dynamic",
                                                 "epsilon": "quasi-static", "table": None}),
        ([*calibrate, "--boundary", "quasi-static"],
         {"resistance": "derived", "boundary": "quasi-static", "epsilon": "quasi-static",
          "table": None}),
    ]
    for argv, settings in cases:
        offered = CLOSED_FORMS if argv[0] == "stress" else FLOWN
        assert resistance_settings(parser.parse_args(argv), offered) == settings, argv


def test_every_command_module_has_the_one_shape():
    """The parser is gathered from the command modules (``COMMANDS``, in its order), and each
    module has the shape of verification/commands/__init__.py: ``HELP``, ``add_arguments(parser)``,
    ``run(args, target, projectile)``, ``text(result)``, ``summary(result)`` exactly where the
    command has ``--json``, ``write_outputs(result, out, ...)`` where it writes files."""
    import inspect

    from cavex.verification.cli import COMMANDS, build_parser, command_module

    commands = build_parser()._subparsers._group_actions[0]  # argparse keeps them only here
    assert list(commands.choices) == list(COMMANDS)
    helps = {action.dest: action.help for action in commands._choices_actions}
    writes = {"penetrate", "trajectory", "validate", "table", "calibrate", "view"}
    for name in COMMANDS:
        module = command_module(name)
        assert helps[name] == module.HELP, name

        def parameters(function):
            return list(inspect.signature(function).parameters)

        assert parameters(module.add_arguments) == ["parser"], name
        assert parameters(module.run) == ["args", "target", "projectile"], name
        assert len(parameters(module.text)) == 1, name
        has_json = "--json" in commands.choices[name]._option_string_actions
        assert hasattr(module, "summary") == has_json, name
        if has_json:
            assert len(parameters(module.summary)) == 1, name
        assert hasattr(module, "write_outputs") == (name in writes), name
        if name in writes:
            required = [p for p in inspect.signature(module.write_outputs).parameters.values()
                        if p.default is inspect.Parameter.empty]
            assert len(required) == 2, name


def test_a_command_parses_as_in_the_whole_parser_and_imports_only_its_module():
    """``cavex COMMAND ...`` builds only COMMAND's options (``build_parser(COMMAND)``): the same
    help and defaults as in the whole parser, and no other command's module is imported (a
    command starts as fast as before the parser was gathered from the modules)."""
    from cavex.verification.cli import COMMANDS, build_parser, named_command

    whole = build_parser()._subparsers._group_actions[0].choices
    for name in COMMANDS:
        assert named_command([name, "--json"]) == name
        alone = build_parser(name)._subparsers._group_actions[0].choices[name]
        assert alone.format_help() == whole[name].format_help(), name
        assert [(a.dest, a.default, a.required) for a in alone._actions] == \
            [(a.dest, a.default, a.required) for a in whole[name]._actions], name
    assert named_command(["--version"]) is None and named_command(["penetrat"]) is None
    probe = ("import sys; from cavex.verification.cli import main; main(['config']); "
             "print(' '.join(m.rsplit('.', 1)[1] for m in sys.modules "
             "if m.startswith('cavex.verification.commands.')))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=True)
    loaded = set(done.stdout.splitlines()[-1].split())
    assert "config" in loaded and not loaded & (set(COMMANDS) - {"config"}), loaded


@pytest.mark.parametrize("argv, message", OLD_SPELLINGS, ids=lambda v: " ".join(v)
                         if isinstance(v, list) else None)
def test_old_spellings_are_refused_with_the_new_one(capsys, tmp_path, argv, message):
    out = tmp_path / "fresh"
    argv = [str(out) if a == "OUT" else f"{out}.toml" if a == "OUT.toml" else a for a in argv]
    code, stdout, err = run(capsys, *argv)
    assert (code, stdout) == (2, "")
    assert err.splitlines() == [f"cavex: error: {message}"]
    assert not out.exists() and not Path(f"{out}.toml").exists()



@pytest.mark.parametrize("argv, names", BAD_INPUTS, ids=lambda v: " ".join(v)
                         if isinstance(v, list) else None)
def test_bad_input_exit_code_2_one_line_no_output(capsys, tmp_path, argv, names):
    configs = _bad_configs(tmp_path)
    out_dir = tmp_path / "fresh"
    argv = [str(out_dir) if a == "OUT" else configs[a[7:]] if a.startswith("CONFIG:")
            else str(tmp_path / a) if a == "missing.toml" else a for a in argv]
    code, out, err = run(capsys, *argv)
    assert code == 2, (out, err)
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and err.endswith("\n"), err
    assert lines[0].startswith("cavex: error: ") and names in lines[0], lines[0]
    assert not out_dir.exists()


def test_fem_nu_with_sigma_c_config(capsys, tmp_path):
    """BUG: ``fem --nu`` on a config giving ``sigma_c`` (instead of ``tau``) fails with a spurious
    "parameter 'sigma_c' must be omitted when tau is given": ``dataclasses.replace`` passes the
    stored ``sigma_c`` and the derived ``tau`` back to ``Material``."""
    text = default_config_text().replace("tau = 25e6", "sigma_c = 26.3157894736842e6")
    config = _write(tmp_path, "sigma_c.toml", text)
    target, _ = load_config(config)
    # tau = (3 - lam) sigma_c / 3 = 25 MPa, as the default
    assert target.layers[0].tau == pytest.approx(25e6, rel=1e-13)
    code, out, err = run(capsys, "fem", "--config", config, "--velocity", "300", "--depth",
                         "0.3", "--nu", "0.45", "--json")
    assert (code, err) == (0, "")
    assert math.isfinite(json.loads(out)["fe_sigma_r_Pa"])


def test_console_script_exit_codes(tmp_path):
    script = Path(sys.executable).parent / "cavex"
    assert script.exists()
    bad = subprocess.run([str(script), "stress", "--velocity", "-1", "--depth", "0.3"],
                         capture_output=True, text=True, timeout=120, check=False)
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.splitlines() == [
        "cavex: error: parameter 'velocity' must be in [0, 10000] m/s (got -1.0)"]
    good = subprocess.run([str(script), "stress", "--velocity", "500", "--depth", "0.3",
                           "--json"], capture_output=True, text=True, timeout=120, check=False)
    # the program says it compiles (a cold numba cache, also where stderr is no terminal)
    assert good.returncode == 0
    assert [line for line in good.stderr.splitlines() if line != COMPILING] == []
    assert json.loads(good.stdout)["response_state"] == "a"
