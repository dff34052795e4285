"""What a user waits for (issue 21): the interactive commands timed as a user runs them (the
whole process, from start to exit), beside the computation they do timed in one process.

Prints medians (and min, max) of wall time over ``--runs`` runs (default 7, after one warm-up
that is not counted, so numba's cache is warm) of

- ``cavex --help``, ``cavex penetrate --help`` and bad input (exit code 2): refused by the
  parser, or by the command's checks before it loads the numerical libraries it runs on;
- ``python -c "import numba, scipy.integrate"``: the floor of every command that computes (the
  libraries the 1-D integrator and the 3-D body need, imported and nothing else);
- ``cavex penetrate --no-figures`` and ``cavex penetrate``; ``cavex trajectory --no-figures``
  and ``cavex trajectory`` (default: normal incidence at V0);
- in one process, after a warm-up: ``penetration_job`` (the runway and its first layer alone)
  and ``trajectory_job`` (the default shot), the computations of those two commands, and
  ``trajectory.figures`` (the four figures of the default shot, matplotlib imported);

and the overhead of each ``--no-figures`` command over its in-process computation, and the
time the figures add to each command (median with figures less median without: drawing,
saving and importing matplotlib).

Run as ``python benchmarks/commands.py [--runs N]`` from the repository root.
"""

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CAVEX = str(Path(sys.executable).with_name("cavex"))  # the installed command


def wall(argv, runs, expect=0):
    """Wall seconds of ``argv`` as a subprocess (one warm-up run not counted)."""
    times = []
    for k in range(runs + 1):
        start = time.perf_counter()
        done = subprocess.run(argv, capture_output=True, text=True, check=False)
        elapsed = time.perf_counter() - start
        if done.returncode != expect:
            raise SystemExit(f"{' '.join(argv)}: exit {done.returncode}\n{done.stderr}")
        if k:
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


def line(name, times):
    print(f"{name:<48} median {statistics.median(times):7.3f} s   (min {min(times):.3f}, "
          f"max {max(times):.3f}, {len(times)} runs)")
    return statistics.median(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    runs = parser.parse_args().runs

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
        line("cavex stress --velocity x (bad input, exit 2)",
             wall([CAVEX, "stress", "--velocity", "x", "--depth", "0.3"], runs, expect=2))
        line("cavex stress --velocity -1 (out of range, exit 2)",
             wall([CAVEX, "stress", "--velocity", "-1", "--depth", "0.3"], runs, expect=2))
        line("cavex fem --velocity 1e9 (out of range, exit 2)",
             wall([CAVEX, "fem", "--velocity", "1e9", "--depth", "0.3"], runs, expect=2))
        floor = line("python -c 'import numba, scipy.integrate'",
                     wall([sys.executable, "-c", "import numba, scipy.integrate"], runs))
        measured = {}
        for command in ("penetrate", "trajectory"):
            for figures in ("--no-figures", "--figures"):
                argv = [CAVEX, command, figures, "--out", str(out / command)]
                measured[command, figures] = line(f"cavex {command} {figures}", wall(argv, runs))
        computation = {
            "penetrate": line("in process: penetration_job (runway + first layer)",
                              in_process(lambda: penetration_job(target, projectile), runs)),
            "trajectory": line("in process: trajectory_job (default shot)", in_process(
                lambda: trajectory_job(target, projectile, Strike(projectile.V0)), runs))}
        job = trajectory_job(target, projectile, Strike(projectile.V0))
        (out / "figures").mkdir()
        line("in process: trajectory figures (default shot)",
             in_process(lambda: trajectory_figures(job, out / "figures"), runs))
    print()
    for command, seconds in computation.items():
        overhead = measured[command, "--no-figures"] - seconds
        print(f"cavex {command} --no-figures: {overhead:.3f} s over its in-process computation "
              f"(of which {floor:.3f} s: start-up and numba + scipy.integrate imports)")
    for command in computation:
        extra = measured[command, "--figures"] - measured[command, "--no-figures"]
        print(f"cavex {command}: the figures add {extra:.3f} s (median with less median "
              "without)")


if __name__ == "__main__":
    main()
