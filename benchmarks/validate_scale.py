"""Validating 1000 shots with the recommended model through the command (issue 19, item 6).

Writes a shot file of ``--shots`` (default 1000) shots made from the development compilation
(``examples/shots_compilation_dev.csv``, 286 shots): shot ``k`` is development shot
``k mod 286`` with its ``f_c`` scaled by ``1 + 0.001 k`` and its ``V0`` by ``1 + 0.0005 k``, so
that every shot has its own concrete (no cavity table is shared: the worst case for the
concrete model, which tabulates one cavity solution per concrete) and its own velocity. Then
times ``cavex validate --shots FILE --models MODEL --no-figures --no-progress --workers W``
with the recommended model (the registry's: the concrete model, one cavity table per
concrete) as a user runs it (the whole process, cold: the concrete tables live in the process)
over ``--runs`` runs and prints the median, min and max of the wall time and the CPU time of
the command's processes (the CPU time is the steadier figure on a shared machine: divided by
the workers it is the wall time of an unloaded one).

Run as ``python benchmarks/validate_scale.py [--shots N] [--runs R] [--workers W]`` from the
repository root.
"""

import argparse
import csv
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEV = ROOT / "examples" / "shots_compilation_dev.csv"
CAVEX = str(Path(sys.executable).with_name("cavex"))


def shot_file(path, count):
    """The ``count``-shot file described in the module docstring."""
    lines = DEV.read_text(encoding="utf-8").splitlines()
    comments = [line for line in lines if line.startswith("#")]
    rows = list(csv.DictReader([line for line in lines if not line.startswith("#")]))
    with open(path, "w", encoding="utf-8", newline="") as handle:
        handle.write("\n".join(comments) + "\n")
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]), lineterminator="\n")
        writer.writeheader()
        for k in range(count):
            row = dict(rows[k % len(rows)])
            row["id"] = f"S{k}"
            row["fc_Pa"] = repr(float(row["fc_Pa"]) * (1.0 + 0.001 * k))
            row["V0_m_s"] = repr(float(row["V0_m_s"]) * (1.0 + 0.0005 * k))
            writer.writerow(row)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shots", type=int, default=1000)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "shots.csv"
        shot_file(path, args.shots)
        from cavex.analytic.models import names

        model = names(recommended=True)[0]
        argv = [CAVEX, "validate", "--shots", str(path), "--models", model,
                "--no-figures", "--no-progress", "--workers", str(args.workers),
                "--out", str(Path(folder) / "out")]
        times, cpu = [], []
        for _ in range(args.runs):
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            start = time.perf_counter()
            done = subprocess.run(argv, capture_output=True, text=True, check=False)
            times.append(time.perf_counter() - start)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
            if done.returncode != 0:
                raise SystemExit(f"exit {done.returncode}: {done.stderr}")
        print(f"cavex validate, {args.shots} shots, --models {model}, --workers "
              f"{args.workers}: median {statistics.median(times):.1f} s (min {min(times):.1f}, "
              f"max {max(times):.1f}, {len(times)} runs); CPU median "
              f"{statistics.median(cpu):.1f} s (min {min(cpu):.1f}, max {max(cpu):.1f})")
        print(done.stdout.splitlines()[0])


if __name__ == "__main__":
    main()
