"""Speed and convergence of one oblique trajectory (issue 10): 800 m/s at 30 deg into the
default runway, derived dynamic resistance (the default of ``cavex trajectory``).

Prints
- the time of one trajectory in-process (``fly``; the default compiled ROS2 integrator, and
  once the old default, RK45 at rtol 1e-6 with a 0.1 m/s contact ramp) and through the
  command a user runs (``cavex trajectory --obliquity 30 --velocity 800 --json``, with and
  without ``--no-figures``), medians of wall and CPU time (the machine may be shared);
- the number of right-hand sides and steps;
- the change of the end state under a one-ulp change of the striking speed;
- convergence of the final nose-tip depth and pitch in the surface discretisation (elements),
  the integrator tolerance and the contact regularisation ``contact_ramp``, with the relative
  change of the depth against the last level.

Run as ``python benchmarks/oblique_speed.py [--quick | --paired]`` (``--paired``: the default
shot before and after issue 30's 16-point nose rule, interleaved).
"""

import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from cavex.analytic.models import make_law
from cavex.analytic.penetration.body import AZIMUTHS, NOSE_POINTS, SHANK_RINGS, build_body
from cavex.analytic.penetration.oblique import CONTACT_RAMP, RTOL, ObliqueModel, Strike
from cavex.config import load_config

STRIKE = Strike(800.0, obliquity=30.0)
CAVEX = str(Path(sys.executable).with_name("cavex"))  # the installed command
COMMAND = ["trajectory", "--obliquity", "30", "--velocity", "800", "--json"]
BEFORE = {"method": "RK45", "rtol": 1e-6, "atol": 1e-9, "contact_ramp": 0.1}  # the old default


def run(target, projectile, law, body=None, strike=STRIKE, **options):
    model = ObliqueModel(target, projectile, law, body=body, **options)
    start, start_cpu = time.perf_counter(), time.process_time()
    result = model.run(strike)
    wall, cpu = time.perf_counter() - start, time.process_time() - start_cpu
    steps = sum(s.t.size - 1 for s in result.solutions)
    return result, model, steps, wall, cpu


def timing(target, projectile, law, repeats):
    for name, options in (("default (ROS2)", {}), ("before: RK45, ramp 0.1 m/s", BEFORE)):
        walls, cpus = [], []
        for _ in range(repeats if not options else 1):
            result, model, steps, wall, cpu = run(target, projectile, law, **options)
            walls.append(wall)
            cpus.append(cpu)
        print(f"one trajectory (fly), {name}: median {statistics.median(walls):.3f} s wall "
              f"({statistics.median(cpus):.3f} s CPU) over {len(walls)}; "
              f"{model.body.elements} elements, {steps} steps, {model.evaluations} right-hand "
              f"sides ({1e6 * statistics.median(cpus) / model.evaluations:.1f} us each incl. "
              "steps)")
    with tempfile.TemporaryDirectory() as folder:
        for extra in ([], ["--no-figures"]):
            walls = []
            for _ in range(repeats):
                start = time.perf_counter()
                subprocess.run([CAVEX, *COMMAND, *extra, "--out", folder], check=True,
                               capture_output=True)
                walls.append(time.perf_counter() - start)
            print(f"  cavex {' '.join(COMMAND + extra)} (a process: imports, files"
                  f"{'' if extra else ', figures'}): median {statistics.median(walls):.3f} s "
                  f"over {repeats}")


def paired(target, projectile, law, repeats):
    """The default shot in-process before and after issue 30's default surface rule (8 nose
    points before, :data:`NOSE_POINTS` now; the same code otherwise), interleaved runs,
    medians of wall and CPU time and their ratio."""
    bodies = {"before (8 nose points)": build_body(projectile, 8),
              f"now ({NOSE_POINTS} nose points)": build_body(projectile)}
    times = {name: ([], []) for name in bodies}
    for _ in range(repeats):
        for name, body in bodies.items():
            _, _, steps, wall, cpu = run(target, projectile, law, body=body)
            times[name][0].append(wall)
            times[name][1].append(cpu)
    medians = {name: (statistics.median(w), statistics.median(c))
               for name, (w, c) in times.items()}
    for name, (wall, cpu) in medians.items():
        print(f"paired, {name}: median {wall:.3f} s wall ({cpu:.3f} s CPU) over {repeats}")
    (w0, c0), (w1, c1) = medians.values()
    print(f"paired ratio now / before: {w1 / w0:.2f} wall, {c1 / c0:.2f} CPU")


def series(label, rows):
    depth = np.array([r[1] for r in rows])
    print(f"\n{label}:")
    for (name, z, pitch, steps, wall), change in zip(rows, depth / depth[-1] - 1.0,
                                                     strict=True):
        print(f"  {name:>28}: tip depth {z:.6f} m, pitch {pitch:8.4f} deg, {steps:6d} steps, "
              f"{wall:6.2f} s; depth vs last {change:+.2e}")


def spread(target, projectile, law):
    """Change of the end state under a one-ulp change of the striking speed: the
    sensitivity of the (piecewise smooth) trajectory to the integrator's step decisions."""
    ends = [run(target, projectile, law, strike=replace(STRIKE, speed=float(v)))[0].end
            for v in (STRIKE.speed, np.nextafter(STRIKE.speed, 0.0),
                      np.nextafter(STRIKE.speed, 1e9))]
    z = np.array([e["nose_tip_m"][2] for e in ends])
    pitch = np.array([e["pitch_deg"] for e in ends])
    print(f"\none-ulp change of the speed: tip depth spread {np.ptp(z) / z[0]:.2e} relative, "
          f"pitch {np.ptp(pitch):.2e} deg")


def main(quick=False, pair=False):
    target, projectile = load_config()
    law = make_law(target, projectile, "derived")
    if pair:
        run(target, projectile, law)  # compiled and warm
        paired(target, projectile, law, 11)
        return
    timing(target, projectile, law, 5)
    if quick:
        return
    spread(target, projectile, law)
    rows = []
    for f in (0.5, 1, 2, 4):
        shape = (int(NOSE_POINTS * f), int(AZIMUTHS * f), int(SHANK_RINGS * f))
        body = build_body(projectile, *shape)
        result, _, steps, wall, _ = run(target, projectile, law, body=body)
        rows.append((f"{body.elements} elements {shape}", result.end["nose_tip_m"][2],
                     result.end["pitch_deg"], steps, wall))
    series(f"surface elements (contact ramp {CONTACT_RAMP} m/s, rtol {RTOL:g})", rows)
    rows = []
    for rtol in (1e-2, 3e-3, 1e-3, 3e-4, 1e-4):
        result, _, steps, wall, _ = run(target, projectile, law, rtol=rtol, atol=rtol * 1e-3)
        rows.append((f"rtol {rtol:g}", result.end["nose_tip_m"][2], result.end["pitch_deg"],
                     steps, wall))
    series(f"integrator tolerance (atol = 1e-3 rtol, contact ramp {CONTACT_RAMP} m/s)", rows)
    rows, ramps = [], (0.3, 0.1, 0.03, 0.01, 0.003, 0.001)
    for ramp in ramps:
        result, _, steps, wall, _ = run(target, projectile, law, contact_ramp=ramp)
        rows.append((f"ramp {ramp:g} m/s", result.end["nose_tip_m"][2],
                     result.end["pitch_deg"], steps, wall))
    series(f"contact regularisation (rtol {RTOL:g})", rows)
    depth = np.array([r[1] for r in rows])
    pitch = np.array([r[2] for r in rows])
    # first order in the ramp: extrapolate the two smallest ramps to ramp -> 0
    for name, values in (("depth", depth), ("pitch", pitch)):
        rate = np.polyfit(np.log(ramps[:4]), np.log(np.abs(np.diff(values))[:4]), 1)[0]
        limit = values[-1] + (values[-1] - values[-2]) * ramps[-1] / (ramps[-2] - ramps[-1])
        k = ramps.index(CONTACT_RAMP)
        print(f"  {name}: fitted order in the ramp (0.3-0.003 m/s) {rate:.2f}; ramp -> 0 "
              f"(linear from the two smallest) {limit:.6f}; error of the default "
              f"{CONTACT_RAMP:g} m/s: {values[k] - limit:+.3e}")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv, pair="--paired" in sys.argv)
