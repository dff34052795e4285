"""The FE work of ``cavex table`` on the issue grid, in one process: what a worker computes.

Builds the 105 cases of ``cavex table`` on issue 8's grid (7 velocities 0..1200 m/s x 8 depths,
the switch depths added, and the first layer alone) as the command does, and runs them with
:func:`cavex.verification.fedata.cases.fe_cases` (stacks of the one solver, error estimates,
refinement above 0.5 %) in this process, after a warm-up on two cases (numba's kernels loaded).
Prints, as medians of ``--repeats`` runs, the CPU time, cases per CPU second, and the work:
residual evaluations (kernel passes) and element evaluations (elements x passes, companions and
refinements included), and the CPU per element evaluation, i.e. the cost of one element's
share of a Newton iteration (return map, force and tangent, step equations, banded solve, and
the solver's bookkeeping between iterations).

Run: ``python benchmarks/fe_cases.py [--repeats 5]``.
"""

import argparse
import statistics
import time

import numpy as np

from cavex.config import load_config
from cavex.fem import expansion
from cavex.verification.fedata import table
from cavex.verification.fedata.cases import fe_cases

VELOCITIES = [0.0, 200.0, 400.0, 600.0, 800.0, 1000.0, 1200.0]
DEPTHS = [0.15, 0.25, 0.35, 0.45, 0.55, 0.7, 0.8, 0.9]


def issue_grid_cases():
    """The FE cases ``cavex table`` runs on the issue grid (with the first layer alone)."""
    target, projectile = load_config()
    v = np.unique(np.asarray(VELOCITIES))
    d = table.grid_depths(DEPTHS, target, projectile, table.SWITCH_REFINEMENT)
    grid = table.table_cases(target, projectile, v, d, None, None)
    first = table.table_cases(target.single(0), projectile, v, [table.FIRST_LAYER_DEPTH], None,
                              None)
    return grid + [case.renamed(f"first-layer-{case['id']}") for case in first]


def counted_run(cases):
    """``(CPU seconds, residual evaluations, element evaluations)`` of one run of ``cases``."""
    counts = {"evaluations": 0, "element_evaluations": 0}
    result = expansion._result

    def counting(solver, c, *args):  # every run's result, companions and refinements included
        one = result(solver, c, *args)
        counts["evaluations"] += one.stats["residual_evaluations"]
        counts["element_evaluations"] += (one.stats["residual_evaluations"]
                                          * one.stats["elements"])
        return one

    expansion._result = counting
    try:
        started = time.process_time()
        fe_cases(cases)
        seconds = time.process_time() - started
    finally:
        expansion._result = result
    return seconds, counts["evaluations"], counts["element_evaluations"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    cases = issue_grid_cases()
    fe_cases(cases[:2])  # warm-up: numba's kernels from its cache
    runs = [counted_run(cases) for _ in range(args.repeats)]
    seconds = statistics.median(r[0] for r in runs)
    _, evaluations, elements = runs[0]
    print(f"{len(cases)} FE cases of the issue grid in one process: CPU median {seconds:.3f} s "
          f"(min {min(r[0] for r in runs):.3f}, max {max(r[0] for r in runs):.3f}; "
          f"{args.repeats} runs) -> {len(cases) / seconds:.1f} cases per CPU second")
    print(f"work: {evaluations} residual evaluations, {elements} element evaluations; "
          f"{seconds / elements * 1e9:.0f} ns of CPU per element evaluation")


if __name__ == "__main__":
    main()
