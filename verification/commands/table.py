"""``cavex table``: the FE-tabulated ``sigma_r(V, L)`` of the target, written as NetCDF.

Defaults: velocities 0, 100, ..., 1200 m/s (13), depths 0.10 ... 1.30 m every 0.04 m (31, plus
the two wall-layer switch depths): concrete, macadam and into the soil
(:data:`cavex.verification.fedata.table.DEFAULT_VELOCITIES`, ``DEFAULT_DEPTHS``).
"""

import math
import shutil
import sys
import time

import numpy as np

from cavex.errors import CavexInputError
from cavex.verification.commands.shared_options import (
    add_config_option,
    add_figures_option,
    add_parallel_options,
    scheduler_of,
)

HELP = "FE-tabulated sigma_r(V, L) for the target"
STORE_SUFFIX = ".cases"  # the resumable case store: <out>.cases/ until the table is written


def add_arguments(parser):
    """The options of ``cavex table``."""
    add_config_option(parser)
    parser.add_argument("--velocities", nargs="+", type=float,
                        help="m/s (default 0, 100, ..., 1200)")
    parser.add_argument("--depths", nargs="+", type=float, help="nose depths, m (default: the "
                        "target's default grid; the layer switch and refinement depths are "
                        "added, and the run states the grid)")
    parser.add_argument("-o", "--out", default="results/table.nc", help="NetCDF file to write")
    parser.add_argument("--nu", type=float, help="Poisson's ratio for every layer (default: "
                        "file's)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    add_figures_option(parser, "the NetCDF table")
    add_parallel_options(parser)


def run(args, target, projectile):
    """Build and write the table; returns the result (:func:`job`) with the file written
    (``outputs``)."""
    from cavex.verification.commands.options import refuse_debonded

    refuse_debonded(target, "table")
    result = job(target, projectile, args.velocities, args.depths, args.out, nu=args.nu,
                 workers=args.workers, scheduler=scheduler_of(args), progress=args.progress)
    refuse_failed_cells(result)
    result["outputs"] = write_outputs(result, result["output"], draw=args.figures)
    return result


def refuse_failed_cells(job):
    """A table with a failed FE cell answers no penetration (``--resistance table`` refuses
    it): a numerical failure naming the count and the first failed cell, before anything is
    written; the cells stay in the case store, which a rerun loads (a failed cell too: a
    deterministic failure is not retried, docs/verification.md)."""
    import json

    from cavex.errors import CavexNumericalError

    failures = json.loads(job["table"].attrs["failures"])
    if not failures:
        return
    first = failures[0]
    raise CavexNumericalError(
        f"{len(failures)} of {summary(job)['cases']} FE cells failed (first at V = "
        f"{first['velocity']:g} m/s, L = {first['depth']:g} m: {first['reason']}); no table "
        f"written (the cells are kept in '{job['store']}', which a rerun loads; delete a failed "
        "cell's file there to run it again)")


def job(target, projectile, velocities=None, depths=None, out_path="results/table.nc", *,
        nu=None, workers=None, scheduler=None, numerics=None, progress=None):
    """Build the table: ``{"table", "seconds", "output", "store", "grid"}`` (a
    :class:`~cavex.verification.fedata.table.Table`: no xarray in this command); nothing is
    written but the case store.

    The output location, the grid, ``workers`` and ``scheduler`` are checked before any FE
    work; finished cells are kept in ``<out>.cases/`` while the table is built, so that a killed
    run resumes where it stopped (:func:`write_outputs` removes it once the table is written).
    """
    from cavex.verification.fedata.runner import check_execution
    from cavex.verification.fedata.table import (
        DEFAULT_DEPTHS,
        DEFAULT_VELOCITIES,
        check_grid,
        grid_depths,
        tabulate,
    )
    from cavex.verification.output.paths import check_output_file, output_refusals

    velocities = DEFAULT_VELOCITIES if velocities is None else velocities
    depths = DEFAULT_DEPTHS if depths is None else depths
    check_grid(velocities, depths)
    out_path = check_output_file(out_path, "out")
    check_execution(workers, scheduler)
    store = out_path.with_name(out_path.name + STORE_SUFFIX)
    grid = depth_grid(depths, grid_depths(depths, target, projectile))
    if sys.stderr.isatty():  # said before the run, as the progress bar (the text says it too)
        print(f"cavex table: {grid_line(grid)}", file=sys.stderr, flush=True)
    start = time.perf_counter()
    resumed = store.exists()  # a killed run's store: kept; this run's: removed on a refusal
    try:
        with output_refusals("out", out_path):  # a full disk: one line naming --out
            table = tabulate(target, projectile, velocities, depths, nu=nu, numerics=numerics,
                             scheduler=scheduler, workers=workers, progress=progress,
                             store=store)
    except CavexInputError:
        if not resumed:
            shutil.rmtree(store, ignore_errors=True)
        raise
    return {"table": table, "seconds": time.perf_counter() - start, "output": out_path,
            "store": store, "grid": grid}


def depth_grid(requested, run):
    """``{"requested": [...], "added": [...]}`` (m): the depths asked for and those the table
    adds at the wall-layer switches (:func:`cavex.verification.fedata.table.grid_depths`:
    each switch depth's node and the refinement depths above it)."""
    asked = sorted({float(d) for d in requested})
    added = [float(d) for d in run if not any(abs(d - a) < 1e-6 for a in asked)]
    return {"requested": asked, "added": added}


def grid_line(grid):
    """One sentence: how many depths run, of which how many were added, and where."""
    asked, added = grid["requested"], grid["added"]
    line = f"{len(asked) + len(added)} depths run ({len(asked)} requested"
    if not added:
        return line + ", none added)"
    return (line + f" + {len(added)} added at the layer switches: "
            + ", ".join(f"{d:.4g}" for d in added) + " m)")


def write_outputs(job, out, draw=True):
    """Write the table into the file ``out``, remove the case store (the table holds every cell
    now) and, if ``draw``, the figure of S(V, L) beside it, ``<out stem>_S.png``
    (:mod:`cavex.verification.report.table_figures`); return the paths written."""
    from cavex.verification.fedata.table import write_table

    written = [write_table(job["table"], out)]
    shutil.rmtree(job["store"], ignore_errors=True)
    if draw:
        from cavex.verification.report.table_figures import figure, figure_path

        written.append(figure(job["table"], figure_path(written[0])))
    return [str(path) for path in written]


def summary(job):
    """What ``cavex table --json`` prints: FE cases (the grid plus the first layer alone),
    the grid's axes, failed cells, the largest error estimate (None: none estimated), the wall
    time, the table's file and the files written (the table and its figure; none before they
    are)."""
    table = job["table"]
    estimates = table["error_estimate"]
    estimate = float(np.nanmax(estimates)) if np.any(np.isfinite(estimates)) else None
    velocities, depths = table["velocity"], table["depth"]
    return {"cases": velocities.size * (depths.size + 1),
            "velocities_m_s": [float(x) for x in velocities],
            "depths_m": [float(x) for x in depths],
            "depths_requested_m": job["grid"]["requested"],
            "depths_added_m": job["grid"]["added"],
            "failed": int(table["failed"].sum()) + int(table["failed_first_layer"].sum()),
            "max_error_estimate": estimate, "wall_time_s": float(job["seconds"]),
            "output": str(job["output"]), "outputs": list(job.get("outputs", ()))}


def text(job):
    """Cases, failed cells, time and path of a built table, one item per line."""
    s = summary(job)
    v, d = s["velocities_m_s"], s["depths_m"]
    estimate = math.nan if s["max_error_estimate"] is None else s["max_error_estimate"]
    return "\n".join([
        f"cases   {s['cases']} ({len(v)} velocities {v[0]:g}..{v[-1]:g} m/s x "
        f"{len(d)} depths {d[0]:g}..{d[-1]:g} m, + first layer alone)",
        "depths  " + grid_line({"requested": s["depths_requested_m"],
                                "added": s["depths_added_m"]}),
        f"failed  {s['failed']}",
        f"largest FE error estimate {estimate:.3%}",
        f"time    {s['wall_time_s']:.1f} s",
        f"wrote   {', '.join(s['outputs'] or [s['output']])}",
    ])
