"""Speed of the analytic half: the layered closed form on arrays and full penetration runs.

Targets (issue 9): at least 10^6 three-layer wall stresses per second on one core, dynamic
convention (<= 1 us each), through ``cavity_stress`` on arrays; one penetration run (in-process,
default target) <= 50 ms for the derived dynamic model and for the paper model. Also printed:
the cost of one scalar ``cavity_stress`` call (the same compiled walk on one point).

Prints medians over repeats of the wall-clock time and, in brackets, of the process CPU time
(the machine may be shared; CPU time is what one core spends). Run as
``python benchmarks/analytic_speed.py``.
"""

import statistics
import time

import numpy as np

from cavex.analytic.cavity import cavity_stress
from cavex.analytic.geometry import spherical_problem
from cavex.analytic.penetration.integrator import penetrate
from cavex.analytic.penetration.resistance import ClosedFormResistance
from cavex.config import load_config

ARRAY_POINTS = 200_000


def median_seconds(call, number, repeats=7):
    """Medians over ``repeats`` of the mean wall and CPU time of ``number`` calls."""
    wall, cpu = [], []
    for _ in range(repeats):
        start, start_cpu = time.perf_counter(), time.process_time()
        for _ in range(number):
            call()
        wall.append((time.perf_counter() - start) / number)
        cpu.append((time.process_time() - start_cpu) / number)
    return statistics.median(wall), statistics.median(cpu)


def three_layer_sample(target, projectile, n, seed=0):
    """``n`` three-layer problems of the default target: interfaces at random nose depths in
    ``[0, 0.6]`` m (three layers around the cavity) and random velocities in ``[0, 1000]`` m/s."""
    rng = np.random.default_rng(seed)
    depth = rng.uniform(0.0, 0.6, n)
    interfaces = (np.asarray(target.interface_depths)[None, :] - depth[:, None] + projectile.l)
    return interfaces, rng.uniform(0.0, 1000.0, n)


def main():
    target, projectile = load_config()
    layers, interfaces = spherical_problem(target, projectile, 0.45)
    assert len(layers) == 3
    print(f"three-layer problem at L = 0.45 m: interfaces {interfaces}")
    for boundary in ("quasi-static", "dynamic"):
        wall, cpu = median_seconds(
            lambda b=boundary: cavity_stress(layers, interfaces, 600.0, projectile.r, boundary=b),
            2000)
        print(f"cavity_stress, one point ({boundary:12s}): {wall * 1e6:7.1f} us per call "
              f"[cpu {cpu * 1e6:.1f} us]")
    radii, velocities = three_layer_sample(target, projectile, ARRAY_POINTS)
    for boundary in ("quasi-static", "dynamic"):
        wall, cpu = median_seconds(
            lambda b=boundary: cavity_stress(layers, radii, velocities, projectile.r, boundary=b),
            1, repeats=7)
        each, each_cpu = wall / ARRAY_POINTS, cpu / ARRAY_POINTS
        print(f"cavity_stress on {ARRAY_POINTS} three-layer points ({boundary:12s}): "
              f"{1e-6 / each:5.2f} million per second, {each * 1e9:6.0f} ns each "
              f"[cpu {each_cpu * 1e9:.0f} ns] (target dynamic >= 1 million/s)")
    for model, boundary in (("derived", "quasi-static"), ("paper", "quasi-static"),
                            ("derived", "dynamic")):
        resistance = ClosedFormResistance(target, projectile, model, boundary)
        wall, cpu = median_seconds(lambda r=resistance: penetrate(target, projectile, r), 1,
                                   repeats=9)
        print(f"penetration {model:8s} {boundary:12s}: {wall * 1e3:7.1f} ms per run "
              f"[cpu {cpu * 1e3:.1f} ms] (target 50 ms for derived dynamic and paper)")


if __name__ == "__main__":
    main()
