"""Speed and convergence of one oblique trajectory (issue 10): 800 m/s at 30 deg into the
default runway, derived dynamic resistance (the default of ``cavex trajectory``).

Prints
- the time of one trajectory in-process (``fly``) and through the command a user runs
  (``cavex trajectory --obliquity 30 --velocity 800 --json``, figures included), medians of
  wall and CPU time over repeats (the machine may be shared);
- the number of right-hand sides and steps;
- convergence of the final nose-tip depth and pitch in the surface discretisation (elements),
  the integrator tolerance and the contact regularisation ``contact_ramp``, with the relative change
  of the depth against the finest level.

Run as ``python benchmarks/oblique_speed.py [--quick]``.
"""

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from cavex.analytic.oblique import CONTACT_RAMP, RTOL, ObliqueModel, Shot
from cavex.analytic.projectile_body import AZIMUTHS, NOSE_POINTS, SHANK_RINGS, build_body
from cavex.analytic.stress_laws import make_law
from cavex.config import load_config

SHOT = Shot(800.0, obliquity=30.0)
FAST_RAMP = 1.0  # m/s: the element and tolerance series run at it (6x cheaper than default)
CAVEX = str(Path(sys.executable).with_name("cavex"))  # the installed command


def run(target, projectile, law, body=None, **options):
    model = ObliqueModel(target, projectile, law, body=body, **options)
    start, start_cpu = time.perf_counter(), time.process_time()
    result = model.run(SHOT)
    wall, cpu = time.perf_counter() - start, time.process_time() - start_cpu
    steps = sum(s.t.size - 1 for s in result.solutions)
    return result, model, steps, wall, cpu


def timing(target, projectile, law, repeats):
    for ramp in (CONTACT_RAMP, FAST_RAMP):
        walls, cpus = [], []
        for _ in range(repeats):
            result, model, steps, wall, cpu = run(target, projectile, law, contact_ramp=ramp)
            walls.append(wall)
            cpus.append(cpu)
        print(f"one trajectory (fly), contact ramp {ramp:g} m/s: median "
              f"{statistics.median(walls):.3f} s wall ({statistics.median(cpus):.3f} s CPU) "
              f"over {repeats}; {model.body.elements} elements, {steps} steps, "
              f"{model.evaluations} right-hand sides "
              f"({1e6 * statistics.median(cpus) / model.evaluations:.1f} us each incl. steps)")
        walls = []
        with tempfile.TemporaryDirectory() as folder:
            for _ in range(repeats):
                start = time.perf_counter()
                subprocess.run([CAVEX, "trajectory", "--obliquity", "30", "--velocity", "800",
                                "--contact-ramp", f"{ramp:g}", "--json", "--out", folder],
                               check=True, capture_output=True)
                walls.append(time.perf_counter() - start)
        print(f"  cavex trajectory --obliquity 30 --velocity 800 --contact-ramp {ramp:g} "
              f"--json (process, imports and figures included): median "
              f"{statistics.median(walls):.3f} s over {repeats}")


def series(label, rows):
    depth = np.array([r[1] for r in rows])
    print(f"\n{label}:")
    for (name, z, pitch, steps, wall), change in zip(rows, depth / depth[-1] - 1.0,
                                                     strict=True):
        print(f"  {name:>28}: tip depth {z:.6f} m, pitch {pitch:8.4f} deg, {steps:6d} steps, "
              f"{wall:6.2f} s; depth vs finest {change:+.2e}")


def main(quick=False):
    target, projectile = load_config()
    law = make_law(target, projectile, "derived")
    timing(target, projectile, law, 3)
    if quick:
        return
    rows = []
    for f in (0.5, 1, 2, 4):
        shape = (int(NOSE_POINTS * f), int(AZIMUTHS * f), int(SHANK_RINGS * f))
        body = build_body(projectile, *shape)
        result, _, steps, wall, _ = run(target, projectile, law, body=body,
                                        contact_ramp=FAST_RAMP)
        rows.append((f"{body.elements} elements {shape}", result.end["nose_tip_m"][2],
                     result.end["pitch_deg"], steps, wall))
    series(f"surface elements (contact ramp {FAST_RAMP} m/s, rtol {RTOL:g})", rows)
    rows = []
    for rtol in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
        result, _, steps, wall, _ = run(target, projectile, law, rtol=rtol, atol=rtol * 1e-3,
                                        contact_ramp=FAST_RAMP)
        rows.append((f"rtol {rtol:g}", result.end["nose_tip_m"][2], result.end["pitch_deg"],
                     steps, wall))
    series(f"integrator tolerance (atol = 1e-3 rtol, contact ramp {FAST_RAMP} m/s)", rows)
    rows, ramps = [], (3.0, 1.0, 0.3, 0.1, 0.03)
    for ramp in ramps:
        result, _, steps, wall, _ = run(target, projectile, law, contact_ramp=ramp)
        rows.append((f"ramp {ramp:g} m/s", result.end["nose_tip_m"][2],
                     result.end["pitch_deg"], steps, wall))
    series("contact regularisation", rows)
    depth = np.array([r[1] for r in rows])
    pitch = np.array([r[2] for r in rows])
    # first-order in the ramp: extrapolate the two smallest ramps to ramp -> 0
    for name, values in (("depth", depth), ("pitch", pitch)):
        rate = np.polyfit(np.log(ramps[1:-1]), np.log(np.abs(np.diff(values))[1:]), 1)[0]
        limit = values[-1] + (values[-1] - values[-2]) * ramps[-1] / (ramps[-2] - ramps[-1])
        print(f"  {name}: fitted order in the ramp {rate:.2f}; ramp -> 0 (linear) {limit:.6f};"
              f" error of ramp {ramps[-2]:g}: {values[-2] - limit:+.3e}, of ramp "
              f"{ramps[1]:g}: {values[1] - limit:+.3e}")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
