"""Throughput of ``cavex table`` end to end, measured through the command a user runs.

Runs ``cavex table`` as a subprocess on three grids of the default target (Table 1, each layer's
own nu, default FE settings: error estimate on, every cell refined while its estimate exceeds
0.5 %, at most twice):

- ``issue``: 7 velocities 0..1200 m/s x the 8 depths 0.15..0.9 m of issue 8 (the table adds
  the wall-layer switch depths and their refinement depths);
- ``default``: ``cavex table`` without a grid (13 velocities x 31 depths, + switch depths);
- ``1200``: 30 velocities 0..1200 m/s x 40 depths 0.12..1.30 m (1200 requested cells, more
  with the switch depths).

For each: the cells (FE cases incl. the first-layer-alone column), the median wall time of
``--repeats`` runs (process start, imports, numba's cached kernels, pool, FE, NetCDF), cases per
second, the median CPU time (user + system of the whole process tree, from the operating
system's accounting of the finished processes), the largest error estimate in the written
table and the number of cells above 0.5 %, failed cells, and the peak resident memory of the
whole process tree (parent and workers, sampled every 50 ms with psutil in one more run that
is not timed: the sampling competes with the run for the cores).

Run it as a user's machine would: with Python writing its bytecode caches (an environment
that sets ``PYTHONDONTWRITEBYTECODE`` compiles cavex's sources at every start).

``--baseline PYTHON`` also runs ``PYTHON -m cavex table`` (the program as the ``cavex``
command runs it, in another checkout's environment, e.g. the main branch's) in turn with this
one, A B A B ..., and prints the median of the pairwise ratios: on a shared machine whose
speed drifts, the ratio of neighbouring runs is steadier than either median.

Run: ``python benchmarks/table.py [--repeats 3] [--workers N] [--grids issue 1200]
[--baseline /path/to/other/venv/bin/python]``.

Measured (issue 21, branch fem-speed against main, issue grid, 7 pairs, a 2-core machine
shared with other jobs, load average ~5 during the runs, so absolute times are ~2-3x a quiet
machine's): wall 8.3 s against 13.2 s (median ratio 0.68), CPU 4.9 s against 7.4 s (0.66);
default grid, 3 pairs: wall 29.8 s against 54.6 s (0.59), CPU 20.6 s against 30.8 s (0.67);
see docs/fem.md, "Throughput". A later stop (the FE's bookkeeping and predictor compiled,
OpenBLAS without its threads), issue grid, 9 pairs against the main branch before it:
1.9 s, 54.0 cases/s against 2.2 s, 48.2 cases/s (wall ratio 0.855, CPU 0.771).
"""

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import psutil
import xarray as xr

GRIDS = {
    "default": (None, None),
    "issue": ([0, 200, 400, 600, 800, 1000, 1200],
              [0.15, 0.25, 0.35, 0.45, 0.55, 0.7, 0.8, 0.9]),
    "1200": (np.round(np.linspace(0.0, 1200.0, 30), 6).tolist(),
             np.round(np.linspace(0.12, 1.30, 40), 6).tolist()),
}
TARGET = 0.005


def tree_rss(process):
    """Resident memory of ``process`` and its children (bytes)."""
    total = 0
    for p in [process, *process.children(recursive=True)]:
        try:
            total += p.memory_info().rss
        except psutil.Error:
            pass
    return total


def children_cpu():
    """User + system seconds of this process's finished (waited-for) children so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_once(velocities, depths, workers, out, python=sys.executable, sample_memory=False):
    """``(wall s, peak tree RSS bytes or None, CPU s)`` of one ``cavex table`` run.

    The timed runs are not watched (``sample_memory`` False): sampling the process tree's
    memory every 50 ms reads /proc for every process and competes with the run for the two
    cores (measured: ~10 % of the wall time of the issue grid); the peak memory comes from a
    separate run that is not timed."""
    command = [python, "-m", "cavex", "table", "-o", out]
    if velocities is not None:
        command += ["--velocities", *map(str, velocities), "--depths", *map(str, depths)]
    if workers:
        command += ["--workers", str(workers)]
    cpu = children_cpu()
    started = time.perf_counter()
    process = psutil.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    peak = None
    if sample_memory:
        peak = 0
        while process.poll() is None:
            peak = max(peak, tree_rss(process))
            time.sleep(0.05)
    stdout, stderr = process.communicate()
    seconds = time.perf_counter() - started
    if process.returncode != 0:
        raise SystemExit(f"cavex table failed ({process.returncode}): {stderr.strip()}")
    return seconds, peak, children_cpu() - cpu


def describe(path):
    with xr.open_dataset(path, engine="scipy") as ds:
        estimate = np.concatenate([ds["error_estimate"].values.ravel()])
        cells = ds.sizes["velocity"] * (ds.sizes["depth"] + 1)
        failed = int(ds["failed"].sum()) + int(ds["failed_first_layer"].sum())
        return cells, float(np.nanmax(estimate)), int(np.sum(estimate > TARGET)), failed


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workers", type=int, default=None, help="default: cavex's (CPUs)")
    parser.add_argument("--grids", nargs="+", default=list(GRIDS), choices=list(GRIDS))
    parser.add_argument("--baseline", default=None,
                        help="another environment's python, run in turn with this one")
    args = parser.parse_args()
    print(f"machine: {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.grids:
            velocities, depths = GRIDS[name]
            out = os.path.join(tmp, f"{name}.nc")
            base_out = os.path.join(tmp, f"{name}-baseline.nc")
            runs, base = [], []
            for _ in range(args.repeats):
                runs.append(run_once(velocities, depths, args.workers, out))
                if args.baseline:
                    base.append(run_once(velocities, depths, args.workers, base_out,
                                         args.baseline))
            _, peak, _ = run_once(velocities, depths, args.workers, out, sample_memory=True)
            cells, worst, above, failed = describe(out)
            seconds = statistics.median(r[0] for r in runs)
            print(f"grid {name}: {cells} FE cases, wall time median {seconds:.1f} s "
                  f"(min {min(r[0] for r in runs):.1f}, max {max(r[0] for r in runs):.1f}; "
                  f"{args.repeats} runs) -> {cells / seconds:.1f} cases/s end to end; "
                  f"CPU median {statistics.median(r[2] for r in runs):.1f} s; "
                  f"largest error estimate {worst:.3%}, {above} cells above 0.5 %, "
                  f"{failed} failed; peak memory {peak / 2**20:.0f} MiB (a separate run)")
            if base:
                pairs = list(zip(runs, base, strict=True))
                b_seconds = statistics.median(r[0] for r in base)
                print(f"  baseline {args.baseline}: wall median {b_seconds:.1f} s -> "
                      f"{cells / b_seconds:.1f} cases/s, CPU median "
                      f"{statistics.median(r[2] for r in base):.1f} s; this/baseline, median "
                      f"of the pairs: wall "
                      f"{statistics.median(a[0] / b[0] for a, b in pairs):.3f}, CPU "
                      f"{statistics.median(a[2] / b[2] for a, b in pairs):.3f}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
