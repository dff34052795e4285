"""Speed of one default FE run: Table 1 concrete, V = 500 m/s, nu = 0.4999, a = 12.5 mm.

Prints the median wall time of repeated runs (with and without the error-estimate run), the
time per element-step (per element per time step of the main run), Newton iterations and the
peak memory of the process. Run: ``python benchmarks/fem_run.py [repeats]``.
"""

import resource
import sys
import time
import tracemalloc

import numpy as np

from cavex.fem import expand_cavity
from cavex.materials import Material

CONCRETE = Material(E=25e9, nu=0.4999, rho=2500.0, lam=0.15, tau=25e6, name="concrete")


def timed(repeats, **numerics):
    seconds, result = [], None
    for _ in range(repeats):
        started = time.perf_counter()
        result = expand_cavity([CONCRETE], [], 500.0, 0.0125, **numerics)
        seconds.append(time.perf_counter() - started)
    return float(np.median(seconds)), result


def main(repeats=11):
    expand_cavity([CONCRETE], [], 500.0, 0.0125)  # warm-up (imports, caches)
    with_estimate, result = timed(repeats)
    main_only, plain = timed(repeats, error_estimate=False)
    tracemalloc.start()
    expand_cavity([CONCRETE], [], 500.0, 0.0125)
    _, traced_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    s = plain.stats
    element_steps = s["elements"] * s["steps"]
    print(f"cavity stress      : {result.cavity_stress / 1e6:.2f} MPa (S = {result.S:.3f})")
    print(f"error estimate     : {100 * result.error_estimate:.3f} %")
    print(f"model              : {s['elements']} P2 elements, {s['dofs']} dofs, "
          f"{s['steps']} steps, {s['newton_iterations']} Newton iterations, "
          f"{s['cutbacks']} cut-backs")
    print(f"default run        : {with_estimate:.3f} s median of {repeats} (incl. error estimate)")
    print(f"main run only      : {main_only:.3f} s median of {repeats}")
    print(f"per element-step   : {1e6 * main_only / element_steps:.2f} us")
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak traced memory : {traced_peak / 2**20:.1f} MB (allocations of one run)")
    print(f"peak RSS           : {rss:.1f} MB (whole process, interpreter and libraries)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 11)
