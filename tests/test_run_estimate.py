"""``cavex validate``'s run estimate (issue 32, item 6): measured by a probe on the run's own
shots, within 2x of the time the predictions take, naming the models that dominate.

The whole-command figures (1000 and 20 000 shots, each model set, on the loaded machine) are
benchmarks/estimate_accuracy.py's; here a small run in this process."""

import re
import time

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


def test_the_estimate_is_within_a_factor_2_of_the_predictions_and_names_them():
    shots = synthetic(120)
    columns = {label: (label, Mapping()) for label in ("derived-quasi-static", "paper",
                                                       "forrestal-1994")}
    tables = TableCache()
    line = run_estimate(shots, columns, tables, workers=1)
    estimated = float(re.search(r"\[~([0-9.e+-]+) s\]", line).group(1))
    start = time.perf_counter()
    depths, failures = predictions(shots, columns, tables)
    actual = time.perf_counter() - start
    assert not failures
    assert 0.5 <= actual / estimated <= 2.0, (line, actual)
    # the flown closed forms take the time, the empirical formula next to none
    assert re.search(r"mostly (derived-quasi-static|paper) \d+ %, (derived-quasi-static|paper)"
                     r" \d+ %$", line), line
