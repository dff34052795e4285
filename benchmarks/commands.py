"""What a user waits for (issue 21): the interactive commands timed as a user runs them (the
whole process, from start to exit), beside the computation they do timed in one process.

Prints medians (and min, max) of wall time over ``--runs`` runs (default 7, after one warm-up
that is not counted, so numba's cache is warm) of

- ``cavex --help``, ``cavex penetrate --help`` and bad input (exit code 2) of ``stress``,
  ``fem``, ``penetrate``, ``trajectory``, ``table``, ``verify``, ``batch``, ``calibrate`` and
  ``validate`` (:data:`BAD_INPUTS`): refused by the parser, or by the command's checks before it
  loads the numerical libraries it runs on (verification/commands/__init__.py);
- yardsticks (:data:`YARDSTICKS`): a Python process that does nothing, imports numpy, numba,
  calls one compiled kernel that does nothing (loaded from numba's cache: the floor of every
  command that computes with numba), and also imports scipy.integrate;
- ``cavex penetrate --no-figures`` and ``cavex penetrate``; ``cavex trajectory --no-figures``
  and ``cavex trajectory`` (default: normal incidence at V0);
- in one process, after a warm-up: ``penetration_job`` (the runway and its first layer alone)
  and ``trajectory_job`` (the default shot), the computations of those two commands, and
  ``trajectory.figures`` (the four figures of the default shot, matplotlib imported);
- where the time of each ``--no-figures`` command goes (its budget), each part the median over
  ``--runs`` fresh processes of a probe that does what the command does, timed in parts: the
  interpreter's start (to the probe's first line); importing numpy, numba, scipy.integrate
  (which loads scipy.optimize and scipy.special) and the command's cavex modules, in that
  order; "kernels from cache", the first call of the job less a warm call (numba loading the
  compiled kernels from its cache: its typing and target registries once per process, then
  each kernel); the warm call (the computation); the interpreter's exit (from the last line
  to the process reaped, the objects frozen first as ``cli.console`` does); and the rest of
  the command (parsing, the configuration, checking and writing the files), what is left of
  the command's median. The probe runs in turn with the command, so that the machine's load
  moves them alike; "the command" in this table is the median of these runs;

and, for ``penetrate`` and ``trajectory``, the command's median with ``--no-figures``, the
median of the same computation in one process and their difference (the issue's floor: at most
0.4 s, read strictly: the computation timed with every import done and numba's kernels
loaded), the command against the same job run through the API in a fresh process (the
budget's parts summed: the issue's own yardstick, "the same job through the API in one Python
process, imports included"), and the time the figures add to each command (median with
figures less median without: drawing, saving and importing matplotlib).

Run as ``python benchmarks/commands.py [--runs N] [--no-figure-runs]`` from the repository
root; the figures measured on this machine are in benchmarks/commands.md.
"""

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CAVEX = str(Path(sys.executable).with_name("cavex"))  # the installed command
SHOTS = str(Path(__file__).resolve().parents[1] / "examples" / "shots_forrestal1994.csv")
FLOOR = 0.4  # s: the bound on a --no-figures command over its in-process computation

#: Bad input, each refused with exit code 2 (``{out}``: the benchmark's temporary folder, which
#: holds ``bad_key.toml``, a sweep with a key the batch schema does not have).
BAD_INPUTS = {
    "cavex stress --velocity x (parser)": ["stress", "--velocity", "x", "--depth", "0.3"],
    "cavex stress --velocity -1": ["stress", "--velocity", "-1", "--depth", "0.3"],
    "cavex fem --velocity 1e9": ["fem", "--velocity", "1e9", "--depth", "0.3"],
    "cavex penetrate --resistance table (no --table)": ["penetrate", "--resistance", "table"],
    "cavex trajectory --velocity -1": ["trajectory", "--velocity", "-1"],
    "cavex trajectory --spin 1e9": ["trajectory", "--spin", "1e9"],
    "cavex table --velocities -5 0": ["table", "--velocities", "-5", "0"],
    "cavex table --depths 0": ["table", "--depths", "0"],
    "cavex verify --workers 0": ["verify", "--workers", "0"],
    "cavex batch (a sweep with a bad key)": ["batch", "{out}/bad_key.toml"],
    "cavex calibrate --shots missing.csv": ["calibrate", "--shots", "{out}/missing.csv",
                                            "--out", "{out}/c.toml"],
    "cavex validate --shots missing.csv": ["validate", "--shots", "{out}/missing.csv"],
    "cavex validate --models nosuch": ["validate", "--shots", SHOTS, "--models", "nosuch"],
}
BAD_SWEEP = '[sweep]\nname = "bad"\n\n[grid]\nvelocity = [0.0, 100.0]\n'

#: A kernel that does nothing, compiled once into numba's cache (the warm-up run) and loaded
#: from it after: what calling any compiled kernel costs a fresh process.
KERNEL = """from numba import njit


@njit(cache=True)
def kernel(x):
    return x + 1.0
"""
#: Yardsticks, each a fresh process that freezes its objects before it exits (as the program
#: does, cavex.verification.cli.console): the interpreter, numpy, numba, one compiled kernel
#: (the floor of every command that computes with numba: numba's typing and target registries,
#: scipy.linalg, which numba loads to check its BLAS, the kernel from the cache), and with
#: scipy.integrate (which penetrate and trajectory need: solve_ivp, quad) imported too.
YARDSTICKS = {
    "python: nothing (the interpreter's start)": "pass",
    "python: import numpy": "import numpy",
    "python: import numba": "import numba",
    "python: one compiled kernel from numba's cache": "from kernel import kernel; kernel(1.0)",
    "python: scipy.integrate and one compiled kernel":
        "import scipy.integrate; from kernel import kernel; kernel(1.0)",
}

#: The job each command runs and the cavex modules it computes with (imported by the job, not
#: by the command's module: benchmarks the budget's "cavex modules" part).
JOBS = {
    "penetrate": ("from cavex.verification.commands.penetrate import penetration_job as job",
                  ("cavex.analytic.penetration.integrator",
                   "cavex.analytic.penetration.resistance"),
                  "job(target, projectile)"),
    "trajectory": ("from cavex.verification.commands.trajectory import trajectory_job as job\n"
                   "from cavex.analytic.penetration.oblique import Strike",
                   ("cavex.analytic.penetration.oblique",),
                   "job(target, projectile, Strike(projectile.V0))"),
}

#: One process's budget: each import and the job's first and second call, timed in turn; the
#: marks are ``time.perf_counter()`` (the system's monotonic clock on Linux, so that the parent
#: times the interpreter's start before the first mark and its exit after the last).
BUDGET_PROBE = """
import time
marks = [time.perf_counter()]
import gc
import json
import numpy
marks.append(time.perf_counter())
import numba
marks.append(time.perf_counter())
import scipy.integrate
marks.append(time.perf_counter())
from cavex.config import load_config
{job_import}
{modules}
target, projectile = load_config()
marks.append(time.perf_counter())
{call}
marks.append(time.perf_counter())
{call}
marks.append(time.perf_counter())
print(json.dumps(marks))
gc.freeze()  # as the program does before it exits (cavex.verification.cli.console)
"""
BUDGET_PARTS = ("interpreter start", "import numpy", "import numba", "import scipy.integrate",
                "import cavex modules", "kernels from cache", "computation", "interpreter exit")


def wall(argv, runs, expect=0, warm_up=True, cwd=None):
    """Wall seconds of ``argv`` as a subprocess (after one warm-up run not counted)."""
    times = []
    for k in range(runs + warm_up):
        start = time.perf_counter()
        done = subprocess.run(argv, capture_output=True, text=True, check=False, cwd=cwd)
        elapsed = time.perf_counter() - start
        if done.returncode != expect:
            raise SystemExit(f"{' '.join(argv)}: exit {done.returncode}\n{done.stderr}")
        if k or not warm_up:
            times.append(elapsed)
    return times


def in_process(function, runs):
    """Wall seconds of ``function()`` in this process (one warm-up call not counted)."""
    function()
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return times


def budget(command, argv, runs):
    """``{part: median seconds}`` of :data:`BUDGET_PARTS` for ``command``'s job and of the
    command itself (``argv``, "the command"), each the median over ``runs`` fresh processes
    (after one warm-up round not counted), the probe and the command run in turn, so that a
    drift of the machine's load moves them alike."""
    job_import, modules, call = JOBS[command]
    code = BUDGET_PROBE.format(job_import=job_import, call=call,
                               modules="\n".join(f"import {m}" for m in modules))
    rows = []
    for k in range(runs + 1):
        launch = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              check=True)
        end = time.perf_counter()
        marks = json.loads(done.stdout.splitlines()[-1])
        *imports, first, warm = (b - a for a, b in zip(marks, marks[1:], strict=False))
        total = wall(argv, 1, warm_up=False)[0]
        if k:  # the first call less the warm one: numba loading the kernels
            rows.append([marks[0] - launch, *imports, first - warm, warm, end - marks[-1],
                         total])
    names = (*BUDGET_PARTS, "the command")
    return {name: statistics.median(row[i] for row in rows) for i, name in enumerate(names)}


def line(name, times):
    print(f"{name:<52} median {statistics.median(times):7.3f} s   (min {min(times):.3f}, "
          f"max {max(times):.3f}, {len(times)} runs)")
    return statistics.median(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--no-figure-runs", dest="figures", action="store_false",
                        help="skip the runs with figures and the in-process figure time")
    args = parser.parse_args()
    runs = args.runs

    from cavex.analytic.penetration.oblique import Strike
    from cavex.config import load_config
    from cavex.verification.commands.penetrate import penetration_job
    from cavex.verification.commands.trajectory import figures as trajectory_figures
    from cavex.verification.commands.trajectory import trajectory_job

    target, projectile = load_config()
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        line("cavex --help", wall([CAVEX, "--help"], runs))
        line("cavex penetrate --help", wall([CAVEX, "penetrate", "--help"], runs))
        (out / "bad_key.toml").write_text(BAD_SWEEP)
        for name, argv in BAD_INPUTS.items():
            line(f"{name} (bad input, exit 2)",
                 wall([CAVEX, *(a.format(out=out) for a in argv)], runs, expect=2))
        (out / "kernel.py").write_text(KERNEL)
        yardstick = {name: line(name, wall([sys.executable, "-c", f"{code}; import gc; "
                                           "gc.freeze()"], runs, cwd=out))
                     for name, code in YARDSTICKS.items()}
        measured = {}
        for command in ("penetrate", "trajectory"):
            for figures in ("--no-figures", "--figures")[:2 if args.figures else 1]:
                argv = [CAVEX, command, figures, "--out", str(out / command)]
                measured[command, figures] = line(f"cavex {command} {figures}", wall(argv, runs))
        computation = {
            "penetrate": line("in process: penetration_job (runway + first layer)",
                              in_process(lambda: penetration_job(target, projectile), runs)),
            "trajectory": line("in process: trajectory_job (default shot)", in_process(
                lambda: trajectory_job(target, projectile, Strike(projectile.V0)), runs))}
        if args.figures:
            job = trajectory_job(target, projectile, Strike(projectile.V0))
            (out / "figures").mkdir()
            line("in process: trajectory figures (default shot)",
                 in_process(lambda: trajectory_figures(job, out / "figures"), runs))
        budgets = {command: budget(command, [CAVEX, command, "--no-figures", "--out",
                                             str(out / command)], runs)
                   for command in computation}
    print(f"\nwhere a --no-figures command's time goes (medians of {runs} fresh processes, "
          "a probe run in turn with the command; 'rest': the command less the parts)")
    print(f"{'':<24}" + "".join(f"{command:>12}" for command in budgets))
    for name in BUDGET_PARTS:
        print(f"{name:<24}" + "".join(f"{b[name]:12.3f}" for b in budgets.values()))
    rest = {c: b["the command"] - sum(b[name] for name in BUDGET_PARTS)
            for c, b in budgets.items()}
    print(f"{'rest (CLI, files)':<24}" + "".join(f"{rest[c]:12.3f}" for c in budgets))
    print(f"{'the command':<24}" + "".join(f"{b['the command']:12.3f}"
                                          for b in budgets.values()))
    print()
    floor_name = list(YARDSTICKS)[-1]
    for command, seconds in computation.items():
        total = measured[command, "--no-figures"]
        print(f"cavex {command} --no-figures: {total:.3f} s, in process {seconds:.3f} s, "
              f"difference {total - seconds:.3f} s (floor {FLOOR} s); over '{floor_name}' "
              f"({yardstick[floor_name]:.3f} s): {total - yardstick[floor_name]:.3f} s")
    for command, b in budgets.items():
        api = sum(b[name] for name in BUDGET_PARTS)
        print(f"cavex {command} --no-figures over the same job through the API in a fresh "
              f"process (imports and numba's kernels included, as the issue timed it): "
              f"{b['the command']:.3f} s against {api:.3f} s, difference "
              f"{b['the command'] - api:.3f} s (floor {FLOOR} s)")
    for command in computation if args.figures else ():
        extra = measured[command, "--figures"] - measured[command, "--no-figures"]
        print(f"cavex {command}: the figures add {extra:.3f} s (median with less median "
              "without)")


if __name__ == "__main__":
    main()
