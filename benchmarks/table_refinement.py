"""Refinement study of the FE-table trajectory on the default target (issue 30, item 4).

The FE table of the default verification report (``results/verification/grid.nc``: 11
velocities 0-1200 m/s x 48 nose depths, default FE numerics refined to a 0.5 % error
estimate) is flown with :class:`~cavex.analytic.penetration.tabulated.TabulatedResistance` on
grid levels in ``V`` and in ``L`` separately:

- coarser levels: the committed table with every other node, twice and three times
  (:func:`cavex.analytic.penetration.table_error.coarsened`). An FE cell depends on its own
  ``(V, L)`` only, so these *are* the FE tables on twice and four times the spacing;
- a finer level (``--refine``): new FE cells at the midpoints between the committed nodes
  (in ``V``: 10 velocities; in ``L``: the midpoints below the last switch depth, where
  ``sigma_r`` depends on ``L``), at the same numerics, merged with the committed cells.

For each level: the final depth and the phase-end velocities, the change against the finest
level, the rate fitted with ``np.polyfit`` to log|d(h) - d(h/2)| against log h, and the
table's own interpolation-error estimate (:func:`~cavex.analytic.penetration.table_error.
interpolation_error`, the level coarsened once more) beside its error against the finest level.

Run: ``python benchmarks/table_refinement.py [--refine] [--store DIR] [--workers N]``
(``--refine`` runs ~900 FE cells; the store makes it resumable). Prints a Markdown table
(docs/verification.md, "Interpolation error").
"""

import argparse
import json
import time

import numpy as np

from cavex.analytic.geometry import switch_depths
from cavex.analytic.penetration.table_error import (
    coarsened,
    flown,
    interpolation_error,
    table_at_nodes,
)
from cavex.analytic.penetration.tabulated import read_table
from cavex.config import load_config
from cavex.netcdf3 import PlainDataset

COMMITTED = "results/verification/grid.nc"
LEVELS = 3  # coarsenings of the committed table per axis
FITTED = 3  # the rate is fitted to the finest three changes (four levels)


def midpoints(x):
    x = np.asarray(x, dtype=float)
    return 0.5 * (x[:-1] + x[1:])


def refined(table, axis, target, projectile, store=None, workers=None):
    """The committed table with FE cells added at the midpoints of ``axis``."""
    from cavex.verification.fedata.table import tabulate

    v = np.asarray(table["velocity"], dtype=float)
    d = np.asarray(table["depth"], dtype=float)
    settings = json.loads(table.attrs["solver_settings"])
    if axis == "velocity":
        new_v, new_d, refine = np.concatenate([[0.0], midpoints(v)]), d, ()
    else:
        last = max(switch_depths(target, projectile))
        new_v, new_d, refine = v, midpoints(d)[midpoints(d) < last], ()
    extra = tabulate(target, projectile, new_v, new_d, numerics=settings["numerics"],
                     error_target=settings["error_target"], refine=refine, store=store,
                     workers=workers)
    return merged(table, extra)


def merged(a, b):
    """The union of two tables' nodes (``a``'s cells where both have one); every cell of the
    union must be in one of them."""
    v = np.union1d(a["velocity"], b["velocity"])
    d = np.union1d(np.round(a["depth"], 12), np.round(b["depth"], 12))
    grid = {k: np.full((v.size, d.size), np.nan) for k in ("sigma_r", "failed")}
    first = {k: np.full(v.size, np.nan) for k in ("sigma_r_first_layer", "failed_first_layer")}
    wall = np.full(d.size, -1)
    for t in (b, a):  # a last: its cells win
        iv = np.searchsorted(v, t["velocity"])
        idp = np.searchsorted(d, np.round(t["depth"], 12))
        for k in grid:
            grid[k][np.ix_(iv, idp)] = t[k]
        for k in first:
            first[k][iv] = t[k]
        wall[idp] = t["wall_layer"]
    assert np.all(np.isfinite(grid["sigma_r"])) and np.all(wall >= 0), "cells missing"
    data = {k: (("velocity", "depth"), grid[k] if k == "sigma_r" else grid[k].astype(bool), {})
            for k in grid}
    data |= {k: (("velocity",), first[k] if k.startswith("sigma") else first[k].astype(bool),
                 {}) for k in first}
    data["wall_layer"] = (("depth",), wall, {})
    coords = {"velocity": (("velocity",), v, {}), "depth": (("depth",), d, {})}
    return PlainDataset(data, coords, {**a.attrs, "source": f"{a.attrs['source']} refined"})


def levels(table, axis, target, projectile, count):
    """``table`` and its ``count`` successive coarsenings in ``axis``, finest first."""
    out = [table]
    for _ in range(count):
        coarse = coarsened(out[-1], axis, target, projectile)
        if coarse is None:
            break
        out.append(coarse)
    return out


def study(target, projectile, tables_by_axis):
    """Rows per axis and level: nodes, final depth, change against the finest, phase-end
    velocity change, the estimate; and the fitted rate per axis."""
    result = {}
    for axis, tables in tables_by_axis.items():
        runs = [flown(target, projectile, t) for t in tables]
        finest = runs[0]
        rows = []
        for k, (t, run) in enumerate(zip(tables, runs, strict=True)):
            estimate = interpolation_error(target, projectile, t, reference=run)
            dv = (max(abs(a - b) for a, b in zip(run["phase_end_velocities_m_s"],
                                                 finest["phase_end_velocities_m_s"],
                                                 strict=True))
                  if run["phase_labels"] == finest["phase_labels"] else None)
            rows.append({"level": k, "nodes": int(np.asarray(t[axis]).size),
                         "final_depth_m": run["final_depth_m"],
                         "error_vs_finest_m": run["final_depth_m"] - finest["final_depth_m"],
                         "phase_end_velocity_error_m_s": dv,
                         "estimate_axis_m": (None if estimate[axis] is None
                                             else abs(estimate[axis]["difference_m"])),
                         "estimate_m": estimate["estimate_m"]})
        depths = [r["final_depth_m"] for r in rows]
        changes = np.abs(np.diff(depths))  # |d(2h) - d(h)|, finest pair first
        result[axis] = {"rows": rows, "rate": fitted_rate(changes[:FITTED]),
                        "local_rates": np.log2(changes[1:] / changes[:-1]).tolist(),
                        "changes_m": changes.tolist()}
    return result


def fitted_rate(changes):
    """``p`` of ``|d(2h) - d(h)| = C h^p`` by ``np.polyfit`` in log-log (finest first)."""
    h = 2.0 ** np.arange(changes.size)
    if changes.size < 2 or not np.all(changes > 0):
        return None
    return float(np.polyfit(np.log(h), np.log(changes), 1)[0])


def markdown(result):
    lines = ["| axis | level (spacing) | nodes | final depth (m) | minus finest (m) | "
             "largest phase-end V change (m/s) | this axis's estimate (m) | estimate E (m) |",
             "|---|---|---|---|---|---|---|---|"]
    for axis, r in result.items():
        for row in r["rows"]:
            dv, ea, e = (row[k] for k in ("phase_end_velocity_error_m_s", "estimate_axis_m",
                                          "estimate_m"))
            lines.append(
                f"| {axis} | {2 ** row['level']} h | {row['nodes']} | "
                f"{row['final_depth_m']:.4f} | {row['error_vs_finest_m']:+.4f} | "
                f"{'n/a' if dv is None else f'{dv:.3f}'} | "
                f"{'n/a' if ea is None else f'{ea:.4f}'} | "
                f"{'n/a' if e is None else f'{e:.4f}'} |")
    lines.append("")
    for axis, r in result.items():
        rate = "n/a" if r["rate"] is None else f"{r['rate']:.2f}"
        local = ", ".join(f"{p:.2f}" for p in r["local_rates"])
        lines.append(f"- {axis}: changes |d(2h) - d(h)| = "
                     f"{', '.join(f'{c:.2e}' for c in r['changes_m'])} m (finest first); "
                     f"rate fitted to the finest {FITTED} changes {rate}; local rates "
                     f"log2 of successive ratios {local}")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--refine", action="store_true",
                        help="add FE cells at the midpoints (the finest level)")
    parser.add_argument("--store", default=None, help="case store of the FE runs (resumable)")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--json", default=None, help="also write the numbers to this file")
    args = parser.parse_args()
    target, projectile = load_config()
    committed = read_table(COMMITTED)
    tables = {}
    for axis in ("velocity", "depth"):
        top = []
        if args.refine:
            started = time.perf_counter()
            top = [refined(committed, axis, target, projectile, args.store, args.workers)]
            print(f"refined in {axis}: {time.perf_counter() - started:.1f} s")
        tables[axis] = top + levels(committed, axis, target, projectile, LEVELS)
    result = study(target, projectile, tables)
    print(markdown(result))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()


__all__ = ["refined", "merged", "levels", "study", "table_at_nodes"]
