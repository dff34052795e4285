"""``cavex validate``'s run estimate against the time the run takes (issue 32, item 6).

Writes a shot file of ``N`` synthetic shots in the ranges of the development compilation
(``examples/shots_compilation_dev.csv``, 286 shots): shot ``k`` takes the projectile of a
development shot drawn at random (mass, diameter, length, crh), its striking velocity scaled by
a factor drawn in [0.8, 1.2] (kept in the compilation's range, 27-1877 m/s), and one of
``--concretes`` concretes, each a development shot's ``(f_c, rho)`` scaled by factors drawn in
[0.9, 1.1]; the measured depth is the development shot's, scaled as ``V0^2`` (validate only
divides by it). Seeded: the same file every run.

Then runs ``cavex validate --shots FILE --models ... --no-figures --no-progress --workers W``
as a user runs it (a subprocess, its own fresh FE-table cache ``CAVEX_CACHE_DIR``), reads the
estimate line from its stderr as it arrives and prints, per model set and size: the estimate
(seconds, from the line's ``[~S s]``), the actual time from that line to the end of the run,
their ratio (actual / estimate; within [0.5, 2] is what the issue asks), the whole command's
time and the load average while it ran.

Run as ``python benchmarks/estimate_accuracy.py [--shots 1000 20000] [--sets cheap concrete]
[--workers 2]`` from the repository root.
"""

import argparse
import csv
import os
import random
import re
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEV = ROOT / "examples" / "shots_compilation_dev.csv"
CAVEX = str(Path(sys.executable).with_name("cavex"))
#: the model sets timed: the cheap ones (closed forms flown by the integrator and the
#: empirical formulas), the concrete cavity model (a cavity table per concrete), the FE table
SETS = {
    "cheap": ("derived-quasi-static", "derived-dynamic", "paper", "li-chen-2003",
              "forrestal-1994"),
    "concrete": ("concrete", "li-chen-concrete"),
    "table": ("table",),
    "all": (),
}
SECONDS = re.compile(r"\[~([0-9.e+]+) s\]")


def development_rows():
    lines = DEV.read_text(encoding="utf-8").splitlines()
    return list(csv.DictReader([line for line in lines if not line.startswith("#")]))


def synthetic_shots(path, count, concretes, seed=32):
    """The ``count``-shot file described in the module docstring."""
    rows = development_rows()
    rng = random.Random(seed)
    low = min(float(r["V0_m_s"]) for r in rows)
    high = max(float(r["V0_m_s"]) for r in rows)
    pool = []
    for _ in range(concretes):
        source = rng.choice(rows)
        pool.append((float(source["fc_Pa"]) * rng.uniform(0.9, 1.1),
                     float(source["rho_kg_m3"]) * rng.uniform(0.9, 1.1)))
    columns = ["id", "mass_kg", "diameter_m", "length_m", "crh", "V0_m_s", "fc_Pa",
               "rho_kg_m3", "depth_m"]
    with open(path, "w", encoding="utf-8", newline="") as handle:
        handle.write("# synthetic shots in the development compilation's ranges "
                     "(benchmarks/estimate_accuracy.py)\n")
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(columns)
        for k in range(count):
            row = rng.choice(rows)
            scale = rng.uniform(0.8, 1.2)
            v0 = min(max(float(row["V0_m_s"]) * scale, low), high)
            fc, rho = rng.choice(pool)
            depth = max(float(row["depth_m"]) * (v0 / float(row["V0_m_s"])) ** 2, 1e-3)
            writer.writerow([f"S{k}", row["mass_kg"], row["diameter_m"], row["length_m"],
                             row["crh"], f"{v0:.6g}", f"{fc:.6g}", f"{rho:.6g}",
                             f"{depth:.6g}"])


def estimate_seconds(line):
    """The estimate's seconds: the line's ``[~S s]``; an older cavex's "about N min" or
    "about N h" (rounded), "under a minute" as NaN."""
    match = SECONDS.search(line)
    if match:
        return float(match.group(1))
    match = re.search(r"about ([0-9.]+) (min|h)", line)
    if match:
        return float(match.group(1)) * (60.0 if match.group(2) == "min" else 3600.0)
    return float("nan")


def timed_run(argv, env):
    """``(estimate line, its seconds, seconds after the line, whole seconds, load, code)``."""
    start = time.monotonic()
    process = subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, text=True)
    seen = {}
    loads = []

    def sample_load():
        while process.poll() is None:
            loads.append(os.getloadavg()[0])
            time.sleep(1.0)

    sampler = threading.Thread(target=sample_load, daemon=True)
    sampler.start()
    lines = []
    for line in process.stderr:
        lines.append(line.rstrip("\n"))
        if line.startswith("cavex: validate") and "line" not in seen:
            seen["line"], seen["at"] = line.strip(), time.monotonic()
    code = process.wait()
    end = time.monotonic()
    sampler.join()
    if "line" not in seen:
        raise SystemExit(f"no estimate line (exit {code}): {lines}")
    estimated = estimate_seconds(seen["line"])
    load = sum(loads) / len(loads) if loads else os.getloadavg()[0]
    return seen["line"], estimated, end - seen["at"], end - start, load, code, lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shots", type=int, nargs="+", default=[1000, 20000])
    parser.add_argument("--sets", nargs="+", default=["cheap", "concrete"],
                        choices=sorted(SETS))
    parser.add_argument("--concretes", type=int, default=40,
                        help="distinct concretes in the file (default 40)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--figures", action="store_true", help="draw the figures too")
    args = parser.parse_args(argv)
    print(f"{'set':<9} {'shots':>6} {'estimate s':>10} {'actual s':>9} {'ratio':>6} "
          f"{'whole s':>8} {'load':>5}")
    with tempfile.TemporaryDirectory() as folder:
        for count in args.shots:
            path = Path(folder) / f"shots_{count}.csv"
            synthetic_shots(path, count, args.concretes)
            for name in args.sets:
                cache = Path(folder) / f"cache_{name}_{count}"
                env = {**os.environ, "CAVEX_CACHE_DIR": str(cache)}
                command = [CAVEX, "validate", "--shots", str(path), "--no-progress",
                           "--workers", str(args.workers),
                           "--out", str(Path(folder) / f"out_{name}_{count}")]
                command += ["--models", *SETS[name]] if SETS[name] else []
                command += [] if args.figures else ["--no-figures"]
                line, estimated, actual, whole, load, code, lines = timed_run(command, env)
                if code != 0:
                    raise SystemExit(f"exit {code}: {lines[-3:]}")
                print(f"{name:<9} {count:>6} {estimated:>10.1f} {actual:>9.1f} "
                      f"{actual / estimated:>6.2f} {whole:>8.1f} {load:>5.1f}", flush=True)
                print(f"  {line}", flush=True)


if __name__ == "__main__":
    main()
