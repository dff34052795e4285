"""Layered convergence study: the default target at V = 500 m/s over nose depths L.

For each depth the spherical problem comes from ``spherical_problem`` and is solved at three
resolutions (space and time refined together by 2). Prints S(L) at each level, the relative
change between consecutive levels, and the smoothness of S(L) (second difference relative to
S). Run: ``python benchmarks/fem_layered.py [n_depths]``.
"""

import sys
import time

import numpy as np

from cavex import load_config
from cavex.verification.fedata.comparison import compare_at_depth

LEVELS = [(15.0, 0.06), (30.0, 0.03), (60.0, 0.015)]


def main(n_depths=25, velocity=500.0):
    target, projectile = load_config()
    depths = np.linspace(0.10, 1.08, n_depths)
    S = np.zeros((len(LEVELS), n_depths))
    analytic = np.zeros(n_depths)
    started = time.perf_counter()
    for j, L in enumerate(depths):
        for i, (epd, growth) in enumerate(LEVELS):
            out = compare_at_depth(target, projectile, L, velocity, elements_per_decade=epd,
                                   growth_per_step=growth, error_estimate=False)
            S[i, j] = out["fe_sigma_r_Pa"]
        analytic[j] = out["analytic_sigma_r_Pa"]["dynamic"]
    change = np.abs(np.diff(S, axis=0)) / S[1:]
    second = np.abs(S[-1, 2:] - 2 * S[-1, 1:-1] + S[-1, :-2]) / S[-1, 1:-1]
    print(f"{'L (m)':>7} {'S coarse':>10} {'S mid':>10} {'S fine':>10} {'d1 %':>7} {'d2 %':>7} "
          f"{'FE/analytic-1 %':>15}")
    for j, L in enumerate(depths):
        print(f"{L:7.3f} {S[0, j] / 1e6:10.2f} {S[1, j] / 1e6:10.2f} {S[2, j] / 1e6:10.2f} "
              f"{100 * change[0, j]:7.3f} {100 * change[1, j]:7.3f} "
              f"{100 * (S[2, j] / analytic[j] - 1):15.2f}")
    print(f"max consecutive-refinement change: {100 * change[0].max():.3f} % (coarse->mid), "
          f"{100 * change[1].max():.3f} % (mid->fine)")
    print(f"max |second difference| of S(L) on the fine level: {100 * second.max():.3f} % of S")
    print(f"elapsed {time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 25)
