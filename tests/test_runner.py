"""The case runner: identical results serially, on a process pool and on Dask; failures; resume.

``probe_cases`` (cheap, deterministic, can fail or leave a marker file per computation) checks the
machinery; three coarse FE cases check that real FE results are bit-for-bit the same everywhere.
"""

import json
import math
import os
import re
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from cavex.errors import CavexInputError
from cavex.verification.fedata.cases import config_tables, fe_cases, make_fe_cases, probe_cases
from cavex.verification.fedata.comparison import with_closed_forms
from cavex.verification.fedata.runner import read_store, run_cases, write_case

COARSE = {"elements_per_decade": 8, "growth_per_step": 0.15, "seed_ratio": 5,
          "error_estimate": False, "snapshots": 1}


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=None) as local:
        yield local


def probes(n, **extra):
    return [{"id": f"p{i:03d}", "x": 0.37 * i - 1.1, **extra} for i in range(n)]


def grid_cases():
    layers, projectile = config_tables()
    return make_fe_cases(layers, projectile, [300.0, 800.0], [0.3, 0.9],
                         numerics=COARSE)[:3]


def without_seconds(results):
    """FE results without the wall-clock time (the only non-deterministic entry)."""
    return [{k: v for k, v in r.items() if k != "wall_time_s"} for r in results]


def test_probe_results_identical_serial_pool_and_dask(cluster):
    cases = probes(20) + [{"id": "boom", "x": 1.0, "fail": "Newton failed"}]
    serial = run_cases(probe_cases, cases, workers=1)
    pool = run_cases(probe_cases, cases, workers=2)
    dask = run_cases(probe_cases, cases, scheduler=cluster.scheduler_address)
    assert serial == pool == dask
    assert [r["id"] for r in dask] == [c["id"] for c in cases]
    x = 0.37 * 7 - 1.1
    assert serial[7]["value"] == math.exp(math.sin(x)) / 3.0  # exact, through JSON
    assert serial[7]["values"] == [x / 7.0, math.sqrt(abs(x)) / 3.0, abs(x) ** 0.1]
    assert serial[-1] == {"id": "boom", "status": "failed",
                          "reason": "CavexNumericalError: Newton failed (x = 1.0)"}
    assert sum(r["status"] == "ok" for r in dask) == 20


def test_fe_results_bitwise_identical_serial_pool_and_dask(cluster):
    from dask.distributed import Client

    cases = grid_cases()
    assert [c["id"] for c in cases] == ["v0300.000_L0.30000", "v0300.000_L0.90000",
                                        "v0800.000_L0.30000"]
    serial = without_seconds(run_cases(fe_cases, cases, workers=1))
    pool = without_seconds(run_cases(fe_cases, cases, workers=2))
    with Client(cluster) as client:
        dask = without_seconds(run_cases(fe_cases, cases, scheduler=client))
    assert serial == pool == dask
    hexes = [[r["fe_sigma_r_Pa"].hex(), r["S"].hex()] for r in serial]
    assert hexes == [[r["fe_sigma_r_Pa"].hex(), r["S"].hex()] for r in dask]
    first = serial[0]
    assert first["status"] == "ok" and first["layers"] == ["concrete", "macadam", "soil"]
    assert first["fe_sigma_r_Pa"] == pytest.approx(612.485e6, rel=1e-4)  # coarse, measured
    assert first["S"] == pytest.approx(first["fe_sigma_r_Pa"] / 25e6, rel=1e-15)
    assert "analytic_sigma_r_Pa" not in first  # the closed forms are evaluated where kept
    compared = with_closed_forms(serial, {c["id"]: c.problem for c in cases})
    for r in compared:  # coarse mesh, nu = 0.4999: within a few % of the closed form
        assert abs(r["relative_difference"]["dynamic"]) < 0.08


def test_built_cases_are_not_parsed_or_checked_again(monkeypatch):
    """A case is built and checked once where it is made: the work unit parses no table, makes
    no Numerics and builds no SphericalProblem (and so checks none) again."""
    import cavex.fem.expansion
    import cavex.verification.fedata.cases as cases_module
    from cavex.problem import SphericalProblem

    case = grid_cases()[0]
    reference, = fe_cases([dict(case)])  # a plain description: built in the work unit

    def again(*args, **kwargs):
        raise AssertionError("parsed or checked again")

    for module, name in ((cases_module, "parse_target"), (cases_module, "parse_projectile"),
                         (cases_module, "make_numerics"), (cavex.fem.expansion, "make_numerics")):
        monkeypatch.setattr(module, name, again)
    monkeypatch.setattr(SphericalProblem, "__post_init__", again)
    built, = fe_cases([case])
    assert without_seconds([built]) == without_seconds([reference])


def test_failing_case_is_recorded_and_the_others_finish():
    cases = probes(3) + [{"id": "bad", "x": 2.0, "fail": "singular tangent\nsecond line"}]
    bad_fe = {**grid_cases()[0], "id": "fe_bad", "depth": -1.0}
    results = run_cases(probe_cases, cases, workers=2)
    assert [r["status"] for r in results] == ["ok", "ok", "ok", "failed"]
    assert results[3]["reason"] == "CavexNumericalError: singular tangent"
    broken = run_cases(fe_cases, [bad_fe, grid_cases()[0]], workers=1)
    assert broken[0]["status"] == "failed"
    assert re.fullmatch(r"CavexInputError: parameter 'depth' must be .*>= 0 \(got -1\.0\)",
                        broken[0]["reason"])
    assert broken[1]["status"] == "ok"


def test_store_resume_computes_only_missing_cases(tmp_path):
    store, markers = tmp_path / "store", tmp_path / "markers"
    markers.mkdir()
    cases = probes(10, marker_dir=str(markers), sleep=0.15)
    reference = run_cases(probe_cases, probes(10), workers=1)
    run_cases(probe_cases, cases[:2], store=store, workers=1)  # a subset first
    script = textwrap.dedent(f"""
        import json
        from cavex.verification.fedata.cases import probe_cases
        from cavex.verification.fedata.runner import run_cases
        run_cases(probe_cases, json.loads({json.dumps(json.dumps(cases))}),
                  store={str(store)!r}, workers=1, chunk_size=1)
    """)
    process = subprocess.Popen([sys.executable, "-c", script])
    try:
        _wait_for_files(store, 5, process)
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait()
    stored = set(read_store(store))
    assert 5 <= len(stored) < 10
    before = set(os.listdir(markers))
    results = run_cases(probe_cases, cases, store=store, workers=2)
    recomputed = {name.split(".")[0] for name in set(os.listdir(markers)) - before}
    assert recomputed == {c["id"] for c in cases} - stored
    assert len(set(os.listdir(markers)) - before) == len(recomputed)  # each once
    assert results == reference
    assert not [n for n in os.listdir(store) if n.endswith(".tmp")]
    before = set(os.listdir(markers))
    assert run_cases(probe_cases, cases, store=store, workers=1) == reference
    assert set(os.listdir(markers)) == before  # all stored: nothing recomputed


def _wait_for_files(store, count, process, timeout=60.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if store.is_dir() and len([n for n in os.listdir(store) if n.endswith(".json")]) >= count:
            return
        assert process.poll() is None, "the sweep finished before it could be killed"
        time.sleep(0.02)
    raise AssertionError("the sweep did not store cases in time")


def test_partial_files_are_never_read(tmp_path):
    cases = probes(3)
    store = tmp_path / "store"
    store.mkdir()
    (store / "p000.json.tmp").write_text('{"case": {"id": "p000"}, "result": {"val')
    (store / "p001.json").write_text('{"case": {"id": "p001", "x": -0.73}, "res')
    write_case(store, cases[2], {"id": "p002", "status": "ok", "value": 0.1})
    results = run_cases(probe_cases, cases, store=store, workers=1)
    assert results[:2] == run_cases(probe_cases, cases[:2], workers=1)
    assert results[2] == {"id": "p002", "status": "ok", "value": 0.1}  # loaded, not recomputed
    assert sorted(os.listdir(store)) == ["p000.json", "p001.json", "p002.json"]
    entry = json.loads((store / "p001.json").read_text())
    assert entry["case"] == cases[1] and entry["result"] == results[1]


def test_store_with_a_different_case_under_the_same_id_is_an_error(tmp_path):
    run_cases(probe_cases, probes(2), store=tmp_path, workers=1)
    changed = [{"id": "p000", "x": 5.0}]
    with pytest.raises(CavexInputError, match="different case under id 'p000'"):
        run_cases(probe_cases, changed, store=tmp_path, workers=1)


@pytest.mark.parametrize("cases, message", [
    ([{"x": 1.0}], r"cases\[0\]"),
    ([{"id": "a", "x": 1.0}, {"id": "a", "x": 2.0}], r"cases\[1\]\.id' must be unique"),
    ([{"id": "../a", "x": 1.0}], r"cases\[0\]\.id"),
    ([{"id": "a", "x": object()}], "not JSON-able"),
])
def test_bad_cases_are_input_errors(cases, message):
    with pytest.raises(CavexInputError, match=message):
        run_cases(probe_cases, cases, workers=1)


def test_bad_workers_is_an_input_error():
    with pytest.raises(CavexInputError, match=r"parameter 'workers' must be an integer in \[1, "):
        run_cases(probe_cases, probes(1), workers=0)


def test_progress_bar_on_request_only(capsys):
    run_cases(probe_cases, probes(3), workers=1, progress=True)
    assert "100%" in (err := capsys.readouterr().err) and "3/3" in err  # tqdm
    run_cases(probe_cases, probes(3), workers=1)
    assert capsys.readouterr().err == ""  # stderr is not a terminal under pytest


def test_fe_case_ids_are_stable_and_unique():
    layers, projectile = config_tables()
    cases = make_fe_cases(layers, projectile, [500.0, 1000.0], [0.3], nu=0.4999)
    assert [c["id"] for c in cases] == ["v0500.000_L0.30000_nu0.499900",
                                        "v1000.000_L0.30000_nu0.499900"]
    assert cases[0]["target"][0] == {"name": "concrete", "thickness": 0.65, "E": 25e9,
                                      "nu": 0.4999, "rho": 2500.0, "lam": 0.15, "tau": 25e6}
    with pytest.raises(CavexInputError, match="too close"):
        make_fe_cases(layers, projectile, [500.0001, 500.0002], [0.3])
    with pytest.raises(CavexInputError, match=r"velocities\[0\]"):
        make_fe_cases(layers, projectile, [-1.0], [0.3])
    with pytest.raises(CavexInputError, match="growth_per_step"):
        make_fe_cases(layers, projectile, [500.0], [0.3], numerics={"growth_per_step": 2.0})


def test_bad_scheduler_address_is_an_input_error():
    with pytest.raises(CavexInputError, match="'scheduler' must be a Dask scheduler address"):
        run_cases(probe_cases, probes(1), scheduler="nonsense://nowhere")


def test_while_running_is_called_once_while_the_workers_compute(cluster, tmp_path):
    """``while_running`` runs once in the parent after the first units are handed out, on a
    pool and on Dask (the results unchanged), and not at all serially or with nothing to run."""
    cases = probes(12)
    serial = run_cases(probe_cases, cases, workers=1, while_running=lambda: 1 / 0)
    calls = []
    pool = run_cases(probe_cases, cases, workers=2, while_running=lambda: calls.append("pool"))
    dask = run_cases(probe_cases, cases, scheduler=cluster.scheduler_address,
                     while_running=lambda: calls.append("dask"))
    assert serial == pool == dask
    assert calls == ["pool", "dask"]
    run_cases(probe_cases, cases, workers=2, store=tmp_path / "store")
    run_cases(probe_cases, cases, workers=2, store=tmp_path / "store",
              while_running=lambda: calls.append("nothing left"))
    assert calls == ["pool", "dask"]
