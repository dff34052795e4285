"""Throughput of a full S(V, L) table: batched FE path against a naive one-case baseline.

The table is the verification grid of the default target (Table 1) at each layer's own nu:
30 velocities 0...1200 m/s times 40 nose depths 0.12...1.30 m, the spherical problem of each
depth from ``spherical_problem``, every case at the default settings (error estimate included,
<= 0.5 % aimed at). Printed:

- batched: :func:`cavex.fem.batch.expand_cavities` on all 1200 cases in one process (median of
  ``--repeats`` runs; ``error_target=0.005``: the few cases whose estimate exceeds 0.5 % at the
  default settings are re-run at twice the resolution), cases per second, peak memory (RSS of
  a fresh process that only builds the table, and the traced allocations of one build);
- baseline: a subset (``--baseline`` cases spread over the grid) run one case at a time, the
  residual and tangent re-assembled from the scikit-fem forms every Newton iteration
  (``expand_cavity(..., assembly="forms")``), one process; the ratio of the two rates;
- identity: the batched results against the one-case fast path at the same settings on the
  same subset plus four refined cases (and the wall stress against the forms baseline):
  largest relative difference of the wall stress, the error estimate, the plastic radius and
  the nodal displacements;
- the largest error estimate of the table, the cases whose estimate comes from a 2x finer
  companion run (V = 0 in soil, where the 2x coarser run fails) and any failed cases;
- scaling: the same table on a local Dask cluster of 1..N single-threaded workers, and on 1..N
  local processes, through :func:`cavex.verification.runner.run_cases` (chunks of ``--chunk``
  consecutive cases), speed-up and efficiency ``T1 / (N T_N)``; the results are checked equal
  to the in-process ones.

Run: ``python benchmarks/table.py [--repeats 3] [--baseline 24] [--workers 2] [--chunk 50]``.
Also prints the load average before and after (the machine is shared).
"""

import argparse
import json
import os
import resource
import subprocess
import sys
import time
import tracemalloc

import numpy as np

from cavex import load_config
from cavex.analytic.geometry import spherical_problem
from cavex.fem import expand_cavity
from cavex.fem.batch import expand_cavities

ERROR_TARGET = 0.005  # cases estimated above it are re-run at twice the resolution
VELOCITIES = np.linspace(0.0, 1200.0, 30)
DEPTHS = np.linspace(0.12, 1.30, 40)


def table_problems():
    """The 1200 ``(layers, interfaces, velocity, radius)`` of the grid, velocity outermost."""
    target, projectile = load_config()
    spheres = [spherical_problem(target, projectile, float(L)) for L in DEPTHS]
    return [(layers, interfaces, float(V), projectile.r)
            for V in VELOCITIES for layers, interfaces in spheres]


def layer_table(m):
    return {"E": m.E, "nu": m.nu, "rho": m.rho, "lam": m.lam, "tau": m.tau, "name": m.name}


def chunks(problems, size):
    """JSON-able chunk cases for :func:`cavex.fem.batch.expand_chunk`: consecutive cases of
    the grid (velocity outermost), so that the slow quasi-static V = 0 cases share a stack."""
    return [{"id": f"chunk{k:03d}", "error_target": ERROR_TARGET,
             "problems": [{"layers": [layer_table(m) for m in layers],
                           "interfaces": list(interfaces), "velocity": V, "radius": a}
                          for layers, interfaces, V, a in problems[start:start + size]]}
            for k, start in enumerate(range(0, len(problems), size))]


def load():
    return "load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def rel(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300)))


def memory_child():
    """Build the table once in this (fresh) process; print peak RSS and traced peak (MB)."""
    problems = table_problems()
    tracemalloc.start()
    expand_cavities(problems, error_target=ERROR_TARGET)
    _, traced = tracemalloc.get_traced_memory()
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps({"rss_mb": rss, "traced_mb": traced / 2**20}))


def identity(subset, batched):
    """Largest relative differences between batched and one-case results on ``subset``."""
    worst = {"cavity_stress": 0.0, "error_estimate": 0.0, "plastic_radius": 0.0, "u": 0.0}
    for (layers, interfaces, V, a), b in zip(subset, batched, strict=True):
        try:
            one = expand_cavity(layers, interfaces, V, a, **b.numerics)
        except Exception as exc:  # noqa: BLE001 - a failure must be a failure in both paths
            assert b.error is not None and str(b.error) == str(exc), (str(exc), b.error)
            continue
        worst["cavity_stress"] = max(worst["cavity_stress"], rel(b.cavity_stress,
                                                                 one.cavity_stress))
        worst["error_estimate"] = max(worst["error_estimate"], rel(b.error_estimate,
                                                                   one.error_estimate))
        worst["plastic_radius"] = max(worst["plastic_radius"], rel(b.plastic_radius,
                                                                   one.plastic_radius))
        worst["u"] = max(worst["u"], float(np.max(np.abs(b.u - one.fields["u"]))) / a)
    return worst


def scaling(problems, workers, chunk, reference, kind):
    """The table through ``run_cases`` on 1..``workers`` local Dask workers (one thread each)
    or local processes; checks the results equal the in-process ``reference`` stresses."""
    import dask
    from dask.distributed import Client, LocalCluster

    from cavex.fem.batch import expand_chunk
    from cavex.verification.runner import run_cases

    cases = chunks(problems, chunk)
    # no statistical profiler in the workers, and no aggressive heap trimming (Dask's default
    # MALLOC_TRIM_THRESHOLD_ = 64 kB makes every large numpy temporary fault its pages in)
    config = {"distributed.worker.profile.enabled": False,
              "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": 2**28}
    seconds = {}
    for n in range(1, workers + 1):
        if kind == "dask":
            with dask.config.set(config), LocalCluster(
                    n_workers=n, threads_per_worker=1, processes=True,
                    dashboard_address=None) as cluster, Client(cluster) as client:
                run_cases(expand_chunk, chunks(problems[:4], 4), scheduler=client,
                          progress=False)
                started = time.perf_counter()
                out = run_cases(expand_chunk, cases, scheduler=client, progress=False)
                seconds[n] = time.perf_counter() - started
        else:
            started = time.perf_counter()
            out = run_cases(expand_chunk, cases, workers=n, progress=False)
            seconds[n] = time.perf_counter() - started
        stresses = [x for r in out for x in r["cavity_stress"]]
        assert stresses == reference, f"{kind} results differ from the in-process ones"
        print(f"{kind + f' {n} worker(s)':21}: {seconds[n]:.1f} s, "
              f"{len(problems) / seconds[n]:.1f} cases/s, speed-up "
              f"{seconds[1] / seconds[n]:.2f}, efficiency {seconds[1] / (n * seconds[n]):.2f}"
              f"   ({load()})", flush=True)
    return seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--baseline", type=int, default=24)
    parser.add_argument("--workers", type=int, default=os.cpu_count())
    parser.add_argument("--chunk", type=int, default=50)
    parser.add_argument("--memory-child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.memory_child:
        return memory_child()
    print(f"start: {load()} on {os.cpu_count()} cores", flush=True)
    problems = table_problems()
    expand_cavities(problems[:3])  # warm-up: imports, compiled-kernel cache
    seconds = []
    for _ in range(args.repeats):
        started = time.perf_counter()
        results = expand_cavities(problems, error_target=ERROR_TARGET)
        seconds.append(time.perf_counter() - started)
        print(f"  batched table run   : {seconds[-1]:.1f} s ({load()})", flush=True)
    batched = float(np.median(seconds))
    rate = len(problems) / batched
    estimates = np.array([r.error_estimate for r in results if r.ok])
    refined = [r for r in results if r.ok and r.stats["refinements"]]
    failed = [r for r in results if not r.ok]
    child = subprocess.run([sys.executable, __file__, "--memory-child"], capture_output=True,
                           text=True, check=True)
    memory = json.loads(child.stdout.strip().splitlines()[-1])
    print(f"table                : {len(VELOCITIES)} x {len(DEPTHS)} = {len(problems)} cases "
          f"(V 0...1200 m/s, L 0.12...1.30 m), default settings with error estimate")
    print(f"batched              : {batched:.1f} s median of {args.repeats} -> {rate:.1f} cases/s")
    print(f"memory (table build) : peak RSS {memory['rss_mb']:.0f} MB (fresh process), "
          f"traced numpy/python allocations {memory['traced_mb']:.0f} MB")
    print(f"error estimate       : max {100 * estimates.max():.3f} %, median "
          f"{100 * np.median(estimates):.3f} %, {np.sum(estimates > ERROR_TARGET)} cases > "
          f"{100 * ERROR_TARGET:g} %; {len(refined)} cases refined (2x space and time)"
          + "".join(f"\n    V = {r.velocity:g} m/s: {100 * r.error_estimate:.3f} % after "
                    f"{r.stats['refinements']} refinement(s)" for r in refined))
    finer = sum(r.stats.get("error_companion") == "finer" for r in results)
    print(f"finer companions     : {finer} cases (their 2x coarser run failed)")
    print(f"failed cases         : {len(failed)}"
          + "".join(f"\n    {r.error}" for r in failed[:6]))
    steps = np.array([r.stats["newton_iterations"] for r in results if r.ok])
    print(f"newton iterations    : {steps.sum()} (main runs), cut-backs "
          f"{sum(r.stats['cutbacks'] for r in results)}")
    # baseline on a subset spread over the grid
    pick = np.linspace(0, len(problems) - 1, args.baseline).round().astype(int)
    subset = [problems[i] for i in pick]
    started = time.perf_counter()
    forms = []
    for layers, interfaces, V, a in subset:
        try:
            forms.append(expand_cavity(layers, interfaces, V, a, assembly="forms"))
        except Exception:  # noqa: BLE001 - counted as done: the baseline fails there too
            forms.append(None)
    base = time.perf_counter() - started
    base_rate = len(subset) / base
    print(f"baseline (forms)     : {len(subset)} cases in {base:.1f} s -> {base_rate:.2f} "
          f"cases/s (one at a time, one process)   ({load()})")
    print(f"ratio                : {rate / base_rate:.1f} x")
    vs_forms = max((rel(results[i].cavity_stress, f.cavity_stress) for i, f in zip(pick, forms,
                                                                                  strict=True)
                    if f is not None and not results[i].stats["refinements"]), default=0.0)
    pick = np.union1d(pick, [i for i, r in enumerate(results) if r.ok and
                             r.stats["refinements"]][:4])  # identity also where refined
    worst = identity([problems[i] for i in pick], [results[i] for i in pick])
    print("identity vs one-case : " + ", ".join(f"{k} {v:.1e}" for k, v in worst.items())
          + f" ({len(pick)} cases)")
    print(f"identity vs forms    : cavity_stress {vs_forms:.1e}")
    if args.workers:
        reference = [None if not r.ok else r.cavity_stress for r in results]
        scaling(problems, args.workers, args.chunk, reference, "dask")
        scaling(problems, args.workers, args.chunk, reference, "processes")
    print(f"end: {load()}")


if __name__ == "__main__":
    main()
