"""Adversarial inputs and faults (issue 12): every one refused with one line on stderr naming the
parameter, exit code 2, and nothing written; stores and tables that are damaged are refused or
recomputed, never used."""

import fcntl
import json
import math
import os
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from cli_helpers import refused, run

from cavex.analytic.penetration.tabulated import load_table
from cavex.config import default_config_text, load_config
from cavex.errors import CavexInputError
from cavex.verification.cli import main
from cavex.verification.fedata.cases import config_tables, make_fe_cases, probe_cases
from cavex.verification.fedata.runner import read_store, run_cases, write_case
from cavex.verification.fedata.table import analytic_table, write_table

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "sweep.toml"
SMALL_SWEEP = """
[sweep]
name = "small"
[grid]
velocities = [300.0]
depths = [0.3]
[numerics]
elements_per_decade = 8
error_estimate = false
"""


@pytest.fixture
def files(tmp_path):
    (tmp_path / "afile").write_text("not a folder")
    sweep = tmp_path / "small.toml"
    sweep.write_text(SMALL_SWEEP)
    return {"afile": tmp_path / "afile", "sweep": sweep}


# --- output locations: checked before any work ---------------------------------------------

@pytest.mark.parametrize("command", [
    ["penetrate", "--out", "{afile}/x"],
    ["table", "-o", "{afile}/t.nc", "--velocities", "0", "100", "--depths", "0.3", "0.4"],
    ["verify", "--quick", "--out", "{afile}/v"],
    ["batch", "{sweep}", "--out", "{afile}/b"],
    ["penetrate", "--out", "/proc/cavex-test"],
    ["table", "-o", "/proc/cavex-test.nc", "--velocities", "0", "100", "--depths", "0.3", "0.4"],
    ["verify", "--quick", "--out", "/proc/cavex-test"],
    ["batch", "{sweep}", "--out", "/proc/cavex-test"],
    ["penetrate", "--out", ""],
    ["table", "-o", "", "--velocities", "0", "100", "--depths", "0.3", "0.4"],
    ["table", "-o", "{tmp}", "--velocities", "0", "100", "--depths", "0.3", "0.4"],
])
def test_unwritable_output_is_refused_before_any_work(capsys, tmp_path, files, command):
    argv = [a.format(afile=files["afile"], sweep=files["sweep"], tmp=tmp_path) for a in command]
    refused(capsys, tmp_path, argv, "'out'")


# --- execution settings: refused before anything is created --------------------------------

@pytest.mark.parametrize(("option", "value", "name"), [
    ("--workers", "0", "'workers'"), ("--workers", "-1", "'workers'"),
    ("--workers", "100000", "'workers'"), ("--scheduler", "bogus", "'scheduler'"),
    ("--scheduler", "tcp://127.0.0.1:1", "reachable"),
    ("--scheduler", "tcp://:99999", "'scheduler'"),
])
@pytest.mark.parametrize("command", [
    ["batch", "{sweep}", "--out", "{tmp}/b"],
    ["table", "-o", "{tmp}/t.nc", "--velocities", "0", "100", "--depths", "0.3", "0.4"],
    ["verify", "--quick", "--out", "{tmp}/v"],
])
def test_bad_workers_or_scheduler_leave_nothing(capsys, tmp_path, files, command, option, value,
                                                 name):
    argv = [a.format(sweep=files["sweep"], tmp=tmp_path) for a in command] + [option, value]
    refused(capsys, tmp_path, argv, name)


def test_a_large_sweep_needs_an_explicit_flag(capsys, tmp_path):
    sweep = tmp_path / "large.toml"
    velocities = ", ".join(str(float(v)) for v in range(1, 1501))
    depths = ", ".join(f"{0.1 + 0.001 * i:.3f}" for i in range(15))
    sweep.write_text(f"[grid]\nvelocities = [{velocities}]\ndepths = [{depths}]\n")
    line = refused(capsys, tmp_path, ["batch", sweep, "--out", tmp_path / "b"],
                   "--allow-large")
    assert "22500 FE cases" in line


# --- inputs that were accepted or crashed ----------------------------------------------------

@pytest.mark.parametrize(("argv", "name"), [
    (["table", "-o", "{tmp}/t.nc", "--velocities", "0", "-100", "600"], "'velocities'"),
    (["table", "-o", "{tmp}/t.nc", "--velocities", "0", "100", "--depths", "0.5", "0.5"],
     "'depths'"),
    (["table", "-o", "{tmp}/t.nc", "--velocities", "0", "0"], "'velocities'"),
    (["table", "-o", "{tmp}/t.nc", "--velocities", "0", "nan"], "'velocities'"),
])
def test_bad_table_grids(capsys, tmp_path, argv, name):
    line = refused(capsys, tmp_path, [a.format(tmp=tmp_path) for a in argv], name)
    assert "np.float64" not in line


def test_config_not_utf8_or_with_a_numeric_name(capsys, tmp_path):
    latin = tmp_path / "latin1.toml"
    latin.write_bytes(default_config_text().replace("concrete", "b\u00e9ton").encode("latin-1"))
    line = refused(capsys, tmp_path, ["penetrate", "--config", latin, "--out", tmp_path / "o"],
                   "is not UTF-8 text (byte 0xe9)")
    assert line.startswith(f"cavex: error: '{latin}': line ")
    noise = tmp_path / "noise.toml"
    noise.write_bytes(bytes(range(128, 256)) * 4)
    refused(capsys, tmp_path, ["penetrate", "--config", noise, "--out", tmp_path / "o"],
            f"'{noise}': line 1, column 1 is not UTF-8 text (byte 0x80)")
    named = tmp_path / "named.toml"
    named.write_text(default_config_text().replace('name = "concrete"', "name = 5"))
    refused(capsys, tmp_path, ["penetrate", "--config", named, "--out", tmp_path / "o"],
            f"'{named}': layers[0].name must be a string (got 5)")


def test_sweep_not_utf8_or_named_outside_its_folder(capsys, tmp_path):
    noise = tmp_path / "noise.toml"
    noise.write_bytes(b"[grid]\nvelocities = [\xff\xfe]\n")
    refused(capsys, tmp_path, ["batch", noise, "--out", tmp_path / "b"],
            f"'{noise}': line 2, column 15 is not UTF-8 text (byte 0xff)")
    escape = tmp_path / "escape.toml"
    escape.write_text(SMALL_SWEEP.replace('name = "small"', 'name = "/tmp/elsewhere"'))
    refused(capsys, tmp_path, ["batch", escape], f"'{escape}': sweep.name must be a plain")
    numerics = tmp_path / "coarse.toml"
    numerics.write_text(SMALL_SWEEP.replace("elements_per_decade = 8",
                                            "elements_per_decade = 0.6"))
    refused(capsys, tmp_path, ["batch", numerics, "--out", tmp_path / "b"],
            f"'{numerics}': numerics.elements_per_decade must be")


# --- damaged tables --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def good_table(tmp_path_factory):
    target, projectile = load_config()
    table = analytic_table(target, projectile, [0.0, 600.0, 1200.0], [0.1, 0.5, 1.0, 1.3])
    return table


@pytest.mark.parametrize("damage", ["truncated", "nan_first_layer", "sign_flipped", "nan_depth",
                                    "nan_cell", "not_netcdf"])
def test_damaged_table_is_refused_in_one_line(capsys, tmp_path, good_table, damage):
    path = tmp_path / f"{damage}.nc"
    table = good_table.copy(deep=True)
    if damage == "nan_first_layer":
        table["sigma_r_first_layer"].values[1] = np.nan
    elif damage == "sign_flipped":
        table["sigma_r"].values[:] *= -1.0
    elif damage == "nan_depth":
        table = table.assign_coords(depth=np.where(np.arange(table.sizes["depth"]) == 2, np.nan,
                                                   table.depth.values))
    elif damage == "nan_cell":
        table["sigma_r"].values[1, 1] = np.nan
    write_table(table, path, reproducible=False)
    if damage == "truncated":
        path.write_bytes(path.read_bytes()[:700])
    elif damage == "not_netcdf":
        path.write_text("velocity,depth\n0,0\n")
    line = refused(capsys, tmp_path, ["penetrate", "--resistance", "table", "--table", path,
                                      "--out", tmp_path / "o"], "table")
    if damage == "nan_cell":
        assert "1 non-finite" in line


def test_truncated_table_load_is_an_input_error(tmp_path, good_table):
    path = tmp_path / "t.nc"
    write_table(good_table, path)
    path.write_bytes(path.read_bytes()[:300])
    with pytest.raises(CavexInputError, match="cannot be read"):
        load_table(path)


# --- the case store ----------------------------------------------------------------------

def probes(n):
    return [{"id": f"p{i}", "x": 0.1 * i} for i in range(n)]


def test_damaged_store_entries_are_recomputed_not_used(tmp_path):
    cases = probes(4)
    reference = run_cases(probe_cases, cases, workers=1)
    store = tmp_path / "store"
    run_cases(probe_cases, cases, store=store, workers=1)
    (store / "p0.json").write_text(json.dumps({"case": cases[0], "result": [1, 2]}))
    (store / "p1.json").write_text('{"case": {"id": "p1", "x": 0.1}, "result": {"id": "p1", '
                                   '"status": "ok", "value": NaN}}')
    (store / "p2.json").write_text(json.dumps({"case": cases[2], "result": {"id": "p9",
                                                                          "status": "ok"}}))
    (store / ".stale.json.tmp").write_text("{")
    assert set(read_store(store)) == {"p3"}
    assert run_cases(probe_cases, cases, store=store, workers=1) == reference
    assert not (store / ".stale.json.tmp").exists()
    assert all(math.isfinite(r["value"]) for r in reference)


def test_a_store_in_use_is_refused(tmp_path):
    store = tmp_path / "store"
    store.mkdir()
    handle = os.open(store, os.O_RDONLY)
    try:  # another run holds the store
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(CavexInputError, match="in use by another cavex run"):
            run_cases(probe_cases, probes(2), store=store, workers=1)
    finally:
        os.close(handle)
    assert len(run_cases(probe_cases, probes(2), store=store, workers=1)) == 2


def test_refused_rerun_keeps_the_sweep_description(capsys, tmp_path):
    """A store holding other cases under the same ids is refused before sweep.json changes."""
    layers, projectile = config_tables()
    out = tmp_path / "b"
    sweep = tmp_path / "small.toml"
    sweep.write_text(SMALL_SWEEP)
    store = out / "cases"
    store.mkdir(parents=True)
    case = make_fe_cases(layers, projectile, [300.0], [0.3], numerics={"elements_per_decade": 9,
                                                                       "error_estimate": False})
    write_case(store, case[0], {"id": case[0]["id"], "status": "ok"})
    (out / "sweep.json").write_text("{}")
    refused(capsys, tmp_path, ["batch", sweep, "--out", out], "holds a different case")
    assert (out / "sweep.json").read_text() == "{}"


def test_pool_workers_end_with_their_parent():
    import signal
    import subprocess
    import sys
    import textwrap
    import time

    script = textwrap.dedent("""
        import os, sys, time
        from cavex.verification.fedata.cases import probe_cases
        from cavex.verification.fedata.runner import run_cases
        cases = [{"id": f"p{i}", "x": 1.0, "sleep": 30.0} for i in range(2)]
        run_cases(probe_cases, cases, workers=2, chunk_size=1)
    """)
    process = subprocess.Popen([sys.executable, "-c", script])
    deadline = time.monotonic() + 30.0
    children = []
    while time.monotonic() < deadline and len(children) < 2:
        time.sleep(0.2)
        children = [int(p) for p in os.popen(f"pgrep -P {process.pid}").read().split()]
    assert len(children) >= 2, "the pool did not start"
    process.send_signal(signal.SIGKILL)
    process.wait()
    deadline = time.monotonic() + 10.0
    alive = children
    while alive and time.monotonic() < deadline:
        time.sleep(0.2)
        alive = [pid for pid in children if Path(f"/proc/{pid}").exists()
                 and "Z" not in Path(f"/proc/{pid}/stat").read_text().split()[2]]
    assert not alive, f"workers {alive} outlived their parent"


def test_dataset_written_by_write_table_loads(tmp_path, good_table):
    path = tmp_path / "ok.nc"
    write_table(good_table, path)
    assert isinstance(load_table(path), xr.Dataset)


# --- huge values, crater notes, other targets ------------------------------------------

@pytest.mark.parametrize("argv", [
    ["stress", "--velocity", "1.2e154", "--depth", "0.3", "--json"],
    ["stress", "--velocity", "1e300", "--depth", "0.3"],
    ["stress", "--velocity", "1e300", "--depth", "0.3", "--resistance", "paper"],
    ["stress", "--velocity", "1.5e154", "--depth", "0.3", "--boundary", "dynamic"],
    ["fem", "--velocity", "1e300", "--depth", "0.3"],
    ["table", "-o", "{tmp}/t.nc", "--velocities", "0", "2e4"],
])
def test_velocities_beyond_rigid_penetration_are_refused(capsys, tmp_path, argv):
    line = refused(capsys, tmp_path, [a.format(tmp=tmp_path) for a in argv], "m/s")
    assert "10000" in line and "problems[" not in line


def test_largest_velocity_gives_finite_numbers(capsys):
    code, out, _ = run(capsys, "stress", "--velocity", "1e4", "--depth", "0.3", "--json")
    assert code == 0 and math.isfinite(json.loads(out)["sigma_r_Pa"])


def test_a_config_with_a_thin_first_layer_says_so_and_skips_table2(capsys, tmp_path):
    thin = tmp_path / "thin.toml"
    thin.write_text(default_config_text().replace("thickness = 0.65", "thickness = 0.05"))
    code, out, err = run(capsys, "penetrate", "--config", thin, "--out", tmp_path / "o", "--json")
    assert code == 0, err
    job = json.loads(out)
    assert job["table2"] is None and job["target_label"] == "layered target"
    assert len(job["notes"]) == 1 and "below the first layer" in job["notes"][0]
    code, out, _ = run(capsys, "penetrate", "--out", tmp_path / "d", "--json")
    default = json.loads(out)
    assert default["notes"] == [] and len(default["table2"]) == 4


def test_a_closed_pipe_is_not_an_error(tmp_path):
    import subprocess
    import sys

    command = (f"{sys.executable} -m cavex.verification.cli stress --velocity 300 --depth 0.3 "
               "| head -c 10")
    done = subprocess.run(["bash", "-o", "pipefail", "-c", command], capture_output=True,
                          text=True, timeout=120)
    assert "Traceback" not in done.stderr and "BrokenPipe" not in done.stderr


# --- what the command line says about itself ----------------------------------------------

def test_version_bare_usage_and_help_with_defaults(capsys):
    from cavex import __version__

    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0 and capsys.readouterr().out.strip() == f"cavex {__version__}"
    code, out, err = run(capsys)
    assert code == 0 and out.startswith("usage: cavex") and "penetrate" in out and err == ""
    for command in ("penetrate", "stress", "fem", "table", "verify", "batch"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = capsys.readouterr().out
        description = text.split("\n\n")[1]
        assert not description.startswith("options"), (command, text)
    with pytest.raises(SystemExit):
        main(["penetrate", "--help"])
    assert "(default: results/penetration)" in capsys.readouterr().out


@pytest.mark.parametrize(("argv", "name"), [
    (["validate", "--shots", "{shots}", "--out", "{tmp}/v", "--workers", "0"], "'workers'"),
    (["validate", "--shots", "{shots}", "--out", "{tmp}/v", "--scheduler", "bogus"],
     "'scheduler'"),
    (["calibrate", "--shots", "{shots}", "--out", "{tmp}/c.toml", "--workers", "0"],
     "'workers'"),
    (["validate", "--shots", "{shots}", "--out", "/proc/cavex-test"], "'out'"),
    (["calibrate", "--shots", "{shots}", "--out", "{tmp}"], "'out'"),
    (["validate", "--shots", "{shots}", "--out", ""], "'out'"),  # was: results/validation
])
def test_validation_commands_check_before_work(capsys, tmp_path, argv, name):
    shots = Path(__file__).resolve().parents[1] / "examples" / "shots_forrestal1994.csv"
    refused(capsys, tmp_path, [a.format(shots=shots, tmp=tmp_path) for a in argv], name)


# --- the adversarial pass over every command (issue 12) ------------------------------------

LAW = ["--resistance", "law", "--law-A", "2e8", "--law-B", "2500"]
PROJECTILE_LINE = "V0 = 1000.0"


def _config(tmp_path, name, old, new):
    text = default_config_text()
    assert old in text
    path = tmp_path / f"{name}.toml"
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize(("extra", "name"), [
    (["--velocity", "1e5"], "'velocity'"), (["--velocity", "0"], "'velocity'"),
    (["--velocity", "nan"], "'velocity'"), (["--velocity", "-1e3"], "'velocity'"),
    (["--velocity", "inf"], "'velocity'"),
    (["--spin", "1e12"], "'spin'"), (["--spin", "-1e12"], "'spin'"), (["--spin", "nan"], "'spin'"),
    (["--obliquity", "90"], "'obliquity'"), (["--obliquity", "-90"], "'obliquity'"),
    (["--obliquity", "nan"], "'obliquity'"), (["--obliquity", "-inf"], "'obliquity'"),
    (["--obliquity", "1e308"], "'obliquity'"),
    (["--attack", "-5"], "'attack'"), (["--attack", "90"], "'attack'"),
    (["--attack", "nan"], "'attack'"), (["--attack-plane", "nan"], "'attack_plane'"),
    (["--contact-ramp", "nan"], "'contact_ramp'"), (["--contact-ramp", "-1"], "'contact_ramp'"),
])
def test_trajectory_shot_out_of_range(capsys, tmp_path, extra, name):
    refused(capsys, tmp_path, ["trajectory", *LAW, "--out", tmp_path / "o", *extra], name)


@pytest.mark.parametrize(("law", "name"), [
    (["--resistance", "law", "--law-A", "1e100", "--law-B", "0"], "'law_A'"),  # ricochet at t=0
    (["--resistance", "law", "--law-A", "1e40", "--law-B", "0"], "'law_A'"),  # stalled
    (["--resistance", "law", "--law-A", "2e8", "--law-B", "1e300"], "'law_B'"),  # overflow
    (["--resistance", "law", "--law-A", "nan", "--law-B", "0"], "'law_A'"),
    (["--resistance", "law", "--law-A", "2e8", "--law-B", "-1"], "'law_B'"),
    (["--resistance", "law", "--law-B", "2500"], "--law-A"),
    (["--law-A", "2e8"], "--law-A"),  # was silently ignored by the derived law
    (["--resistance", "derived", "--law-B", "2500"], "--law-A"),
    (["--resistance", "table"], "--table"),
])
def test_trajectory_law_options(capsys, tmp_path, law, name):
    refused(capsys, tmp_path, ["trajectory", *law, "--out", tmp_path / "o"], name)


@pytest.mark.parametrize(("name", "old", "new", "parameter"), [
    ("short", PROJECTILE_LINE, PROJECTILE_LINE + "\nlength = 0.03", "': projectile.length "),
    ("long", PROJECTILE_LINE, PROJECTILE_LINE + "\nlength = 1e300", "': projectile.length "),
    ("heavy", "m = 0.505", "m = 1e300", "projectile.m"),  # beyond the accepted mass (1e6 kg)
    # below the accepted mass (1e-6 kg, which stops in 1 mm): once a numerical failure
    ("featherweight", "m = 0.505", "m = 1e-300\nlength = 0.15", "projectile.m"),
    ("light", "m = 0.505", "m = 0.01", "'length'"),  # the steel body is shorter than its nose
    ("cg", PROJECTILE_LINE, PROJECTILE_LINE + "\nlength = 0.15\ncg = 0.2", "': projectile.cg "),
    ("inertia", PROJECTILE_LINE, PROJECTILE_LINE + "\ninertia = 0", "': projectile.inertia "),
    ("inertia_nan", PROJECTILE_LINE, PROJECTILE_LINE + "\ninertia = nan",
     "': projectile.inertia "),
    ("mu", PROJECTILE_LINE, PROJECTILE_LINE + "\nmu = 1e300", "': projectile.mu "),
    ("mu_neg", PROJECTILE_LINE, PROJECTILE_LINE + "\nmu = -0.1", "': projectile.mu "),
])
def test_trajectory_projectile_out_of_range(capsys, tmp_path, name, old, new, parameter):
    config = _config(tmp_path, name, old, new)
    refused(capsys, tmp_path, ["trajectory", "--config", config, *LAW, "--out", tmp_path / "o"],
            parameter)


@pytest.mark.parametrize(("old", "new", "extra"), [
    (PROJECTILE_LINE, PROJECTILE_LINE + "\ninertia = 1e-300", ["--obliquity", "30"]),
])
def test_trajectory_that_cannot_advance_is_a_numerical_failure(capsys, tmp_path, old, new,
                                                               extra):
    """Forces far beyond the body's mass or inertia overflowed (RuntimeWarnings, then a
    'ricochet' at t = 0 and 1000 m/s printed as a result); now exit 1, one line, no files."""
    if old is not None:
        extra = [*extra, "--config", _config(tmp_path, "body", old, new)]
    code, out, err = run(capsys, "trajectory", *LAW, "--out", tmp_path / "o", *extra)
    assert (code, out) == (1, "") and len(err.splitlines()) == 1, err
    assert err.startswith("cavex: numerical failure: ") and not (tmp_path / "o").exists()


def test_grazing_body_at_rest_advances_and_gains_nothing(capsys, tmp_path):
    """1e-9 m/s at 89.9 deg: the body touches the surface at rest. It used to end at t = 0 (a
    numerical failure); with the element fractions (issue 30) an element's contact opens over
    its cell, so the run advances and ends (measured: a ricochet at 0.15 ms, 8.0e-8 m/s, work
    -6.2e-18 J). It must not gain energy: the surface forces' work is not positive and the
    final speed stays at the scale of the striking speed's."""
    code, out, err = run(capsys, "trajectory", *LAW, "--out", tmp_path / "o", "--velocity",
                         "1e-9", "--obliquity", "89.9", "--no-figures")
    assert code == 0 and err == "", err
    end = json.loads((tmp_path / "o" / "summary.json").read_text())["runs"]["runway"]["end"]
    assert end["state"] in ("ricochet", "stopped")
    assert end["work_J"] <= 1e-15 and end["speed_m_s"] < 1e-6


@pytest.mark.parametrize("damage", ["not_a_table", "garbage", "other_target", "too_slow"])
def test_trajectory_table_refused(capsys, tmp_path, good_table, damage):
    path = tmp_path / "t.nc"
    argv = ["trajectory", "--resistance", "table", "--table", path, "--out", tmp_path / "o"]
    if damage == "not_a_table":
        xr.Dataset({"x": ("a", np.arange(3.0))}).to_netcdf(path, engine="scipy")
    elif damage == "garbage":
        path.write_text("hello")
    elif damage == "other_target":
        write_table(good_table, path, reproducible=False)
        argv += ["--config", _config(tmp_path, "other", "tau = 25e6", "tau = 30e6")]
    else:  # the elements' normal velocities (543 m/s) exceed the table's (300 m/s)
        target, projectile = load_config()
        write_table(analytic_table(target, projectile, [0.0, 300.0], [0.1, 0.5, 1.0, 1.3]), path,
                    reproducible=False)
    refused(capsys, tmp_path, argv, "table")


@pytest.mark.parametrize("command", [
    ["trajectory", *LAW, "--out", "{afile}"], ["trajectory", *LAW, "--out", "{afile}/x"],
    ["trajectory", *LAW, "--out", ""], ["trajectory", *LAW, "--out", "/proc/cavex-test"],
    ["fem", "--velocity", "300", "--depth", "0.3", "--fields", "{afile}"],
    ["fem", "--velocity", "300", "--depth", "0.3", "--fields", ""],
    ["fem", "--velocity", "300", "--depth", "0.3", "--fields", "/proc/cavex-test"],
    ["verify", "--quick", "--out", ""], ["batch", "{sweep}", "--out", ""],
])
def test_unwritable_output_of_the_other_commands(capsys, tmp_path, files, command):
    argv = [a.format(afile=files["afile"], sweep=files["sweep"]) for a in command]
    refused(capsys, tmp_path, argv, "'out'" if "--out" in argv else "'fields'")


@pytest.fixture
def read_only(tmp_path):
    """A folder nobody may write into: mode 555, or, for root (whom modes do not stop), the
    immutable attribute (chattr +i); skipped where neither holds."""
    import shutil
    import subprocess

    folder = tmp_path / "read-only"
    folder.mkdir()
    immutable = os.geteuid() == 0
    if immutable:
        if shutil.which("chattr") is None or subprocess.run(
                ["chattr", "+i", folder], capture_output=True).returncode != 0:
            pytest.skip("root without chattr +i: no folder is read-only here")
    else:
        folder.chmod(0o555)
    try:
        (folder / "probe").touch()
    except OSError:
        pass
    else:
        pytest.skip("the read-only folder is writable here")
    yield folder
    if immutable:
        subprocess.run(["chattr", "-i", folder], check=True)
    else:
        folder.chmod(0o755)


@pytest.mark.parametrize("command", [
    ["penetrate", "--out", "{ro}"], ["penetrate", "--out", "{ro}/sub"],
    ["trajectory", *LAW, "--out", "{ro}"], ["trajectory", *LAW, "--out", "{ro}/sub"],
    ["table", "-o", "{ro}/t.nc", "--velocities", "0", "100", "--depths", "0.3", "0.4"],
    ["batch", "{sweep}", "--out", "{ro}/b"], ["verify", "--quick", "--out", "{ro}/v"],
    ["fem", "--velocity", "300", "--depth", "0.3", "--fields", "{ro}/f"],
    ["validate", "--shots", "{shots}", "--out", "{ro}"],
    ["calibrate", "--shots", "{shots}", "--out", "{ro}/c.toml"],
])
def test_read_only_or_immutable_output_folder(capsys, tmp_path, files, read_only, command):
    shots = Path(__file__).resolve().parents[1] / "examples" / "shots_forrestal1994.csv"
    argv = [a.format(ro=read_only, sweep=files["sweep"], shots=shots) for a in command]
    line = refused(capsys, tmp_path, argv, "'fields'" if "--fields" in argv else "'out'")
    assert "writable" in line


@pytest.mark.parametrize(("argv", "name"), [
    (["stress", "--velocity", "-1e2", "--depth", "0.3"], "'velocity'"),  # was "expected one
    (["stress", "--velocity", "100", "--depth", "-inf"], "'depth'"),  # argument"
    (["table", "-o", "{tmp}/t.nc", "--velocities", "0", "100", "--depths", "0.3", "1e308"],
     "'depths'"),  # np.round overflowed: RuntimeWarning lines, then 'depths[13]' = inf
    (["stress", "--velocity", "300", "--depth", "0.3", "--config", "{thick}"],
     "': layers[1].thickness "),  # lost to round-off below 1e300 m: was 'interfaces[1]'
    (["batch", "{fast}", "--out", "{tmp}/b"], "': grid.velocities[0] "),  # ran, exit 0, failed
])
def test_other_commands_out_of_range(capsys, tmp_path, argv, name):
    thick = _config(tmp_path, "thick", "thickness = 0.65", "thickness = 1e300")
    fast = tmp_path / "fast.toml"
    fast.write_text(SMALL_SWEEP.replace("velocities = [300.0]", "velocities = [1e5]"))
    refused(capsys, tmp_path, [a.format(tmp=tmp_path, thick=thick, fast=fast) for a in argv],
            name)


def test_an_interrupt_while_writing_leaves_no_files(tmp_path):
    """SIGINT or SIGTERM inside the staged writing removes what was written (and the folder it
    created); the files move into the folder only all together."""
    import signal

    from cavex.verification.output.paths import staged_output

    handlers = [signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)]
    for signum in (signal.SIGINT, signal.SIGTERM):
        out = tmp_path / f"out{signum}"
        with pytest.raises(KeyboardInterrupt), staged_output(out) as stage:
            (stage / "history.csv").write_text("t\n0\n")
            os.kill(os.getpid(), signum)
        assert not out.exists()
    assert [signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)] == handlers
    kept = tmp_path / "kept"
    kept.mkdir()
    (kept / "old.txt").write_text("old")
    with pytest.raises(RuntimeError), staged_output(kept) as stage:
        (stage / "new.txt").write_text("new")
        raise RuntimeError("failed while writing")
    assert sorted(p.name for p in kept.iterdir()) == ["old.txt"]
    with staged_output(kept) as stage:
        (stage / "new.txt").write_text("new")
    assert sorted(p.name for p in kept.iterdir()) == ["new.txt", "old.txt"]


@pytest.mark.parametrize("program", [False, True])
def test_an_interrupt_during_the_moves_leaves_every_file(tmp_path, monkeypatch, program):
    """A signal while the staged files are moved (the commit) never leaves a part of them: one
    the main thread receives is held back, and one Python's handler runs for mid-commit (as it
    does when another thread, numba's or dask's, received it) is only recorded (it raised
    between two moves). After the moves a library caller gets the interrupt, the cavex program
    (``program_ends_at_commit``) ignores it and every later one (CI saw 'complete' with exit
    130 when Ctrl-C came at the commit)."""
    import signal

    from cavex.verification.output import paths
    from cavex.verification.output import program as cavex_program

    handlers = [signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)]
    monkeypatch.setattr(cavex_program, "_ENDS_AT_COMMIT", [True] if program else [])
    replace, moved = os.replace, []

    def interrupted_replace(source, destination):
        if not moved:  # at the first move: one signal pending, one run by Python's handler
            os.kill(os.getpid(), signal.SIGTERM)
            signal.getsignal(signal.SIGINT)(signal.SIGINT, None)
        replace(source, destination)
        moved.append(destination)

    monkeypatch.setattr(paths.os, "replace", interrupted_replace)
    out = tmp_path / "out"
    try:
        if program:
            with paths.staged_output(out) as stage:
                for name in ("a.csv", "b.csv", "c.csv"):
                    (stage / name).write_text(name)
            assert [signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)] == [
                signal.SIG_IGN, signal.SIG_IGN]
            os.kill(os.getpid(), signal.SIGINT)  # after the commit: ignored
        else:
            with pytest.raises(KeyboardInterrupt), paths.staged_output(out) as stage:
                for name in ("a.csv", "b.csv", "c.csv"):
                    (stage / name).write_text(name)
            assert [signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)] == handlers
    finally:
        for s, handler in zip((signal.SIGINT, signal.SIGTERM), handlers, strict=True):
            signal.signal(s, handler)
    assert len(moved) == 3
    assert sorted(p.name for p in out.iterdir()) == ["a.csv", "b.csv", "c.csv"]


def test_ctrl_c_during_a_trajectory_run(tmp_path):
    """Ctrl-C while the files are being written: one line, exit 130, and no --out folder (it
    was a traceback, or a SystemError out of the compiled kernel, and a partial set of files)."""
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "o"
    process = subprocess.Popen([sys.executable, "-m", "cavex.verification.cli", "trajectory",
                                *LAW, "--out", str(out)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline and process.poll() is None:
        if out.exists() and any(out.glob(".cavex-partial-*/*")):
            break  # writing has begun
        time.sleep(0.005)
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, (stdout, stderr)
    from cavex.verification.cli import COMPILING  # said by the program on a cold cache

    said = [line for line in stderr.splitlines() if line != COMPILING]
    assert said == ["cavex: interrupted"] and stdout == "", (stdout, stderr)
    assert not out.exists()


def test_an_interrupt_wrapped_by_compiled_code_is_an_interrupt():
    """numba wraps a Ctrl-C that arrives inside a compiled call (or the unpickling of one of
    its constants) in SystemErrors, each the cause of the next (seen three deep in a run of
    ``cavex trajectory`` interrupted at 0.95 s), Python in a RuntimeError inside
    ``__set_name__``; any such chain counts as an interrupt, one without a KeyboardInterrupt
    does not."""
    from cavex.verification.cli import interrupted

    def chain(depth, root):
        exc = root
        for _ in range(depth):
            try:
                raise SystemError("returned a result with an exception set") from exc
            except SystemError as wrapped:
                exc = wrapped
        return exc

    assert all(interrupted(chain(depth, KeyboardInterrupt())) for depth in range(5))
    try:  # Python's wrapping of an interrupt raised in __set_name__ (seen in matplotlib)
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as exc:
            raise RuntimeError("Error calling __set_name__") from exc
    except RuntimeError as wrapped:
        assert interrupted(wrapped)
    assert not interrupted(chain(2, ValueError("no")))
    assert not interrupted(SystemError("alone"))
    assert not interrupted(ValueError("not a SystemError"))


def test_a_run_that_reaches_the_time_limit_ends_there():
    from cavex.analytic.models import fly
    from cavex.analytic.penetration.oblique import MAX_TIME, Strike

    target, projectile = load_config()
    result = fly(target.single(0), projectile, Strike(1000.0), "law", law_A=0.0, law_B=0.0)
    assert result.phases[-1]["end_reason"] == "time limit"
    assert result.end["state"] == "time limit" and result.end["time_s"] == MAX_TIME
    assert result.end["nose_tip_m"] == result.phases[-1]["end_nose_tip_m"]


def test_verify_writes_its_report_complete_or_not_at_all(tmp_path, monkeypatch):
    """A verify run that fails (or is interrupted) after writing part of its report leaves the
    previous report in place and no hidden folder behind; a finished one replaces it."""
    from cavex.verification.commands import verify as verify_command
    from cavex.verification.report import build as report

    out = tmp_path / "report"
    out.mkdir()
    (out / "report.md").write_text("old report")

    def failing(target, projectile, *, out_dir, **options):
        (Path(out_dir) / "report.md").write_text("half a new report")
        raise KeyboardInterrupt("signal 2")

    monkeypatch.setattr(report, "verify", failing)
    with pytest.raises(KeyboardInterrupt):
        verify_command.job(*load_config(), out_dir=out)
    assert sorted(p.name for p in out.iterdir()) == ["report.md"]
    assert (out / "report.md").read_text() == "old report"

    def finishing(target, projectile, *, out_dir, **options):
        (Path(out_dir) / "report.md").write_text("new report")
        return {"out_dir": str(out_dir), "files": {"report": str(Path(out_dir) / "report.md")},
                "quick": True}

    monkeypatch.setattr(report, "verify", finishing)
    assert verify_command.job(*load_config(), out_dir=out)["files"] == {
        "report": str(out / "report.md")}
    assert sorted(p.name for p in out.iterdir()) == ["report.md"]
    assert (out / "report.md").read_text() == "new report"


def test_compare_homogeneous_needs_two_layers(capsys, tmp_path):
    """It was silently ignored: the first layer alone is the target itself."""
    from cavex.config import default_config_text

    text = default_config_text()
    one_layer = text[:text.index("[[layers]]", text.index("[[layers]]") + 1)]
    one_layer = one_layer.replace("thickness = 0.65\n", "")
    config = tmp_path / "one_layer.toml"
    config.write_text(one_layer)
    refused(capsys, tmp_path, ["trajectory", "--config", config, *LAW, "--compare-homogeneous",
                               "--out", tmp_path / "o"], "--compare-homogeneous")
