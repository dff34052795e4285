"""Speed of the analytic half: cavity_stress for three layers and one full penetration run.

Targets (issue 2): cavity_stress <= 50 us per call (three layers), one penetration <= 50 ms.
Prints medians over repeats; run as ``python benchmarks/analytic_speed.py``.
"""

import statistics
import time

from cavex.analytic.cavity import cavity_stress
from cavex.analytic.geometry import spherical_problem
from cavex.analytic.penetration import penetrate
from cavex.analytic.resistance import ClosedFormResistance
from cavex.config import load_config


def median_seconds(call, number, repeats=7):
    """Median over ``repeats`` of the mean time of ``number`` calls."""
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(number):
            call()
        samples.append((time.perf_counter() - start) / number)
    return statistics.median(samples)


def main():
    target, projectile = load_config()
    layers, interfaces = spherical_problem(target, projectile, 0.45)
    print(f"three-layer problem at L = 0.45 m: interfaces {interfaces}")
    for boundary in ("quasi-static", "dynamic"):
        seconds = median_seconds(
            lambda b=boundary: cavity_stress(layers, interfaces, 600.0, projectile.r, boundary=b),
            2000)
        print(f"cavity_stress ({boundary:12s}): {seconds * 1e6:7.1f} us per call (target 50)")
    for model, boundary in (("derived", "quasi-static"), ("paper", "quasi-static"),
                            ("derived", "dynamic")):
        resistance = ClosedFormResistance(target, projectile, model, boundary)
        seconds = median_seconds(lambda r=resistance: penetrate(target, projectile, r), 1,
                                 repeats=5)
        print(f"penetration {model:8s} {boundary:12s}: {seconds * 1e3:7.1f} ms per run "
              "(target 50 ms for the default derived quasi-static)")


if __name__ == "__main__":
    main()
