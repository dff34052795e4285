"""``cavex validate``'s run estimate (issue 32, item 6): measured by a probe on the run's own
shots, naming the models that dominate.

How close it comes to the time taken (within 2x: 1000 and 20 000 shots, each model set, on the
loaded machine) is benchmarks/estimate_accuracy.py's figure (docs/validation.md); here its
arithmetic and its naming."""

import re

import pytest

from cavex.concrete import Mapping
from cavex.verification.validation.predict import TableCache, predictions
from cavex.verification.validation.run_estimate import (
    cases_per_table,
    parallel_speedup,
    run_estimate,
    spread,
)
from cavex.verification.validation.shots import Shot, shot_projectile, shot_target


def synthetic(n):
    """``n`` shots between 200 and 800 m/s into two concretes (the Forrestal projectile)."""
    return [Shot(id=f"S{i}", mass=0.906, diameter=0.0269, length=None, crh=2.0,
                 V0=200.0 + 600.0 * i / max(1, n - 1), fc=(35e6, 60e6)[i % 2],
                 rho=2300.0, depth=0.2) for i in range(n)]


def test_parallel_speedup_on_a_quiet_and_a_loaded_machine():
    # unloaded (load 1: the probe itself): w processes on w free CPUs run w times as fast
    assert parallel_speedup(2, 100, cpus=2, load=1.0) == pytest.approx(2.0)
    # 5 other processes on 2 CPUs: one process gets 2/6 of a CPU, two get 2/7 each
    assert parallel_speedup(2, 100, cpus=2, load=6.0) == pytest.approx(2 * (2 / 7) / (2 / 6))
    assert parallel_speedup(4, 1, cpus=2, load=1.0) == 1.0  # one task: one process


def test_the_probe_spreads_over_the_file():
    shots = synthetic(10)
    chosen = spread(shots, 4)
    assert chosen[0] is shots[0] and chosen[-1] is shots[-1] and len(chosen) == 4
    assert spread(shots[:3], 4) == shots[:3]


def test_a_table_counts_its_first_layer_row():
    shot = synthetic(1)[0]
    velocities = tuple(50.0 * i for i in range(9))
    assert cases_per_table(shot_target(shot, Mapping()), shot_projectile(shot),
                           velocities) == 9 * 3  # depths 0 and 1 m, and the first layer


def test_the_estimate_is_the_probed_costs_times_the_shots(monkeypatch):
    """The estimate's arithmetic, with the probe's costs fixed: ``T = f sum_m n t_m`` for
    models flown per shot, the models named by their share. (How close the estimate comes to
    the time a run takes is a speed figure: benchmarks/estimate_accuracy.py measures it
    through the whole command, every model set at 1000 and 20 000 shots, docs/validation.md;
    a timed unit test here would depend on the machine's load.)"""
    from cavex.verification.validation import run_estimate as estimate

    costs = {"derived-quasi-static": 2e-3, "paper": 3e-3, "forrestal-1994": 1e-6}
    monkeypatch.setattr(estimate, "prediction_seconds",
                        lambda clock, model, *args: costs[model])
    monkeypatch.setattr(estimate.Clock, "slowdown", lambda self, cpus=None, load=None: 1.5)
    shots = synthetic(120)
    columns = {label: (label, Mapping()) for label in costs}
    line = run_estimate(shots, columns, TableCache(), workers=1)
    seconds = float(re.search(r"\[~([0-9.e+-]+) s\]", line).group(1))
    assert seconds == pytest.approx(1.5 * 120 * sum(costs.values()), rel=1e-3)
    assert line.endswith("mostly paper 60 %, derived-quasi-static 40 %"), line


def test_the_probe_names_the_models_that_take_the_time():
    """The real probe on a small run: the flown closed forms take the time, the empirical
    formula next to none (their costs differ by about a thousand times)."""
    shots = synthetic(120)
    columns = {label: (label, Mapping()) for label in ("derived-quasi-static", "paper",
                                                       "forrestal-1994")}
    tables = TableCache()
    line = run_estimate(shots, columns, tables, workers=1)
    depths, failures = predictions(shots, columns, tables)
    assert not failures and all(d is not None for c in depths.values() for d in c)
    assert re.search(r"mostly (derived-quasi-static|paper) \d+ %, (derived-quasi-static|paper)"
                     r" \d+ %$", line), line
