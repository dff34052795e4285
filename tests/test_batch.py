"""Batch sweeps: the example runs into one Dataset; bad files fail before any case; Dask; resume."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from cavex.errors import CavexInputError
from cavex.verification.commands import batch as batch_command
from cavex.verification.fedata.batch import (
    load_sweep,
    parse_sweep,
    run_sweep,
    sweep_cases,
)
from cavex.verification.fedata.cases import fe_cases

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "sweep.toml"

COARSE_SWEEP = """
[sweep]
name = "coarse"
[grid]
velocities = [300.0, 800.0]
depths = [0.3, 0.8]
[numerics]
elements_per_decade = 8
growth_per_step = [0.15, 0.2]
seed_ratio = 5
error_estimate = false
snapshots = 1
"""


def without_wall_time(dataset):
    return dataset.drop_vars("wall_time")


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    out = tmp_path_factory.mktemp("example")
    return out, run_sweep(EXAMPLE, out, workers=2, progress=False)


def test_example_sweep_is_one_dataset(example):
    out, ds = example
    assert dict(ds.sizes) == {"velocity": 2, "depth": 2, "nu": 1, "concrete_E": 2,
                              "elements_per_decade": 2}
    assert ds.velocity.values.tolist() == [300.0, 800.0]
    assert ds.depth.values.tolist() == [0.3, 0.8]
    assert ds.concrete_E.values.tolist() == [20e9, 30e9]
    assert ds.elements_per_decade.values.tolist() == [10, 20]
    assert ds.velocity.attrs["units"] == "m s-1" and ds.fe_sigma_r.attrs["units"] == "Pa"
    assert ds.attrs["cases"] == 16 and ds.attrs["failed_cases"] == 0
    assert not ds.failed.any() and (ds.status == "ok").all()
    concrete = ds.sel(depth=0.3)  # wall in concrete: S = sigma_r / 25 MPa
    np.testing.assert_array_equal(concrete.S, concrete.fe_sigma_r / 25e6)
    rel = ds.fe_sigma_r / ds.analytic_sigma_r_dynamic - 1.0
    np.testing.assert_allclose(ds.relative_difference_dynamic, rel, rtol=0, atol=1e-15)
    assert float(abs(ds.relative_difference_dynamic).max()) < 0.1
    stiffer = concrete.sel(concrete_E=30e9).fe_sigma_r - concrete.sel(concrete_E=20e9).fe_sigma_r
    assert float(stiffer.min()) > 0  # a stiffer concrete resists more
    assert float(np.isnan(ds.error_estimate).sum()) == 16  # error_estimate = false
    # one cell against the same case run alone
    case = next(c for c in sweep_cases(parse_sweep(EXAMPLE))
                if c["id"] == str(ds.case_id.sel(velocity=800.0, depth=0.8, nu=0.4999,
                                                 concrete_E=20e9, elements_per_decade=20).item()))
    alone, = fe_cases([case])
    cell = ds.sel(velocity=800.0, depth=0.8, nu=0.4999, concrete_E=20e9, elements_per_decade=20)
    assert float(cell.fe_sigma_r) == alone["fe_sigma_r_Pa"]
    assert case["target"][2] == {"name": "soil", "E": 0.12e9, "nu": 0.4999, "rho": 1600.0,
                                 "lam": 0.5, "sigma_c": 7e6}


def test_example_loads_back_identically(example):
    out, ds = example
    assert load_sweep(out).identical(ds)
    with xr.open_dataset(out / "results.nc", engine="scipy") as stored:
        assert stored.load().identical(ds)
    assert sorted(os.listdir(out)) == ["cases", "results.nc", "sweep.json"]
    assert len(os.listdir(out / "cases")) == 16


GRID = "[grid]\nvelocities = [300.0]\ndepths = [0.3]\n"
BAD_SWEEPS = [  # the text, the message (or its start) after "'<path>': "
    ("[grid]\nvelocitys = [300.0]\ndepths = [0.3]\n",
     "grid.velocitys is not a known key (accepted: depths, nu, velocities)"),
    ("[grid]\nvelocities = [-1]\ndepths = [0.3]\n",
     "grid.velocities[0] must be a finite number > 0 (got -1)"),
    ("[grid]\nvelocities = 300.0\ndepths = [0.3]\n",
     "grid.velocities must be a non-empty array of numbers (got 300.0)"),
    (GRID + "[numerics]\ngrowth_per_step = [0.1, 2.0]\n",
     "numerics.growth_per_step must be in (0, 0.5] (got 2.0)"),
    (GRID + "[numerics]\nelements_per_decad = 3\n",
     "numerics.elements_per_decad is not a known key (accepted: "),
    (GRID + "[[materials]]\nlayer = 'concrete'\nE = [1e9, -1e9]\n",
     "materials[0].E[1] must be a finite number > 0 (got -1000000000.0)"),
    (GRID + "[[materials]]\nlayer = 'clay'\nE = 1e9\n",
     "materials[0].layer must be a layer name ('concrete', 'macadam', 'soil') or index "
     "(got 'clay')"),
    (GRID.replace("depths = [0.3]", "depths = [0.3]\nnu = [0.3, 0.5]"),
     "grid.nu[1] must be a finite number in (-1, 0.5) (got 0.5)"),
    (GRID + "[sweep]\nworkers = '2'\n", "sweep.workers must be an integer >= 1 (got '2')"),
    (GRID + "[target]\nlayers = [{E = 1e9}]\n",
     "target.layers[0].lam is missing, as are nu, rho (required)"),
    (GRID + "[grids]\n",
     "grids is not a known key (accepted: grid, materials, numerics, sweep, target)"),
    ("[grid\n", "line 1, column 6 is not valid TOML (Expected ']' at the end of a table "
     "declaration)"),
    (GRID + "[target]\nconfig = 'absent.toml'\n",
     "target.config names a bad target file: '{dir}/absent.toml': cannot be read (No such file "
     "or directory)"),
]


@pytest.mark.parametrize("text, message", BAD_SWEEPS)
def test_bad_sweeps_are_rejected_before_any_case_runs(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    out = tmp_path / "out"
    with pytest.raises(CavexInputError) as error:
        run_sweep(path, out, workers=1)
    assert str(error.value).startswith(f"'{path}': " + message.format(dir=tmp_path))
    assert not out.exists()  # no case file, not even the folder


def test_sweep_on_dask_gives_identical_numbers(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    sweep = tmp_path / "coarse.toml"
    sweep.write_text(COARSE_SWEEP)
    local = run_sweep(sweep, tmp_path / "local", workers=1)
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=None) as cluster:
        dask = run_sweep(sweep, tmp_path / "dask", scheduler=cluster.scheduler_address)
    assert dict(dask.sizes) == {"velocity": 2, "depth": 2, "growth_per_step": 2}
    assert without_wall_time(dask).identical(without_wall_time(local))
    assert not dask.failed.any()


def batch_text(sweep, out):
    """What ``cavex batch SWEEP --out OUT --workers 1`` prints."""
    return batch_command.text(batch_command.job(sweep, out, workers=1))


def test_batch_command_summary_and_resume_from_the_store(tmp_path):
    sweep = tmp_path / "coarse.toml"
    sweep.write_text(COARSE_SWEEP)
    first = batch_text(str(sweep), str(tmp_path / "out"))
    assert "sweep 'coarse': 8 cases (8 run, 0 loaded from the store), 0 failed" in first
    assert "dimensions: velocity=2, depth=2, growth_per_step=2" in first
    assert f"wrote {tmp_path / 'out' / 'results.nc'}" in first
    again = batch_text(str(sweep), str(tmp_path / "out"))
    assert "8 cases (0 run, 8 loaded from the store), 0 failed" in again


def test_sweep_killed_and_resumed_computes_only_the_missing_cases(tmp_path):
    text = COARSE_SWEEP.replace("depths = [0.3, 0.8]", "depths = [0.2, 0.3, 0.5, 0.8]")
    text = text.replace("elements_per_decade = 8", "elements_per_decade = 12")
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(text)
    out = tmp_path / "out"
    script = textwrap.dedent(f"""
        from cavex.verification.fedata.batch import run_sweep
        run_sweep({str(sweep)!r}, {str(out)!r}, workers=1, chunk_size=2)
    """)
    process = subprocess.Popen([sys.executable, "-c", script])
    try:
        _wait_for_cases(out / "cases", 4, process)
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait()
    stored = {p.name: p.stat().st_mtime_ns for p in (out / "cases").glob("*.json")}
    assert 4 <= len(stored) < 16
    partial = load_sweep(out)
    assert partial.attrs["missing_cases"] == 16 - len(stored)
    assert int(partial.failed.sum()) == 16 - len(stored)
    assert int(np.isnan(partial.fe_sigma_r).sum()) == 16 - len(stored)

    resumed = run_sweep(sweep, out, workers=2)
    after = {p.name: p.stat().st_mtime_ns for p in (out / "cases").glob("*.json")}
    assert {name: after[name] for name in stored} == stored  # stored cases not recomputed
    assert len(after) == 16 and not list((out / "cases").glob("*.tmp"))
    reference = run_sweep(sweep, tmp_path / "reference", workers=1)
    assert without_wall_time(resumed).identical(without_wall_time(reference))
    description = json.loads((out / "sweep.json").read_text())
    assert len(description["case_ids"]) == 16


def _wait_for_cases(store, count, process, timeout=60.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if store.is_dir() and len(list(store.glob("*.json"))) >= count:
            return
        assert process.poll() is None, "the sweep finished before it could be killed"
        time.sleep(0.02)
    raise AssertionError("the sweep did not store cases in time")
