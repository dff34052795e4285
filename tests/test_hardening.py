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

from cavex.cli import main
from cavex.config import default_config_text, load_config
from cavex.errors import CavexInputError
from cavex.verification.cases import config_tables, make_fe_cases, probe_cases
from cavex.verification.runner import read_store, run_cases, write_case
from cavex.verification.table import analytic_table, load_table, write_table

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


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def refused(capsys, tmp_path, argv, name, untouched=()):
    """The command exits 2 with one line naming ``name`` and leaves ``tmp_path`` as it was."""
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    code, out, err = run(capsys, *argv)
    assert code == 2, (out, err)
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("cavex: error: "), err
    assert name in lines[0], lines[0]
    after = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    assert after == before, "a refused command wrote something"
    return lines[0]


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
    refused(capsys, tmp_path, ["penetrate", "--config", latin, "--out", tmp_path / "o"],
            "not UTF-8")
    noise = tmp_path / "noise.toml"
    noise.write_bytes(bytes(range(128, 256)) * 4)
    refused(capsys, tmp_path, ["penetrate", "--config", noise, "--out", tmp_path / "o"],
            "not UTF-8")
    named = tmp_path / "named.toml"
    named.write_text(default_config_text().replace('name = "concrete"', "name = 5"))
    refused(capsys, tmp_path, ["penetrate", "--config", named, "--out", tmp_path / "o"],
            "'layers[0].name'")


def test_sweep_not_utf8_or_named_outside_its_folder(capsys, tmp_path):
    noise = tmp_path / "noise.toml"
    noise.write_bytes(b"[grid]\nvelocities = [\xff\xfe]\n")
    refused(capsys, tmp_path, ["batch", noise, "--out", tmp_path / "b"], "not UTF-8")
    escape = tmp_path / "escape.toml"
    escape.write_text(SMALL_SWEEP.replace('name = "small"', 'name = "/tmp/elsewhere"'))
    refused(capsys, tmp_path, ["batch", escape], "'sweep.name'")
    numerics = tmp_path / "coarse.toml"
    numerics.write_text(SMALL_SWEEP.replace("elements_per_decade = 8",
                                            "elements_per_decade = 0.6"))
    refused(capsys, tmp_path, ["batch", numerics, "--out", tmp_path / "b"],
            "'numerics.elements_per_decade'")


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
        from cavex.verification.cases import probe_cases
        from cavex.verification.runner import run_cases
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
    ["stress", "--velocity", "1e300", "--depth", "0.3", "--model", "paper"],
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

    command = (f"{sys.executable} -m cavex.cli stress --velocity 300 --depth 0.3 | head -c 10")
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
])
def test_validation_commands_check_before_work(capsys, tmp_path, argv, name):
    shots = Path(__file__).resolve().parents[1] / "examples" / "shots_forrestal1994.csv"
    refused(capsys, tmp_path, [a.format(shots=shots, tmp=tmp_path) for a in argv], name)
