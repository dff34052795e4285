r"""The concrete model's depth against its two discretisation parameters of the flight.

``python -m cavex.verification.studies.concrete_table_convergence [--shots FILE] [--out DIR]
[--workers N]`` flies every shot of ``FILE`` (default the 286 development shots) with the
concrete model (:class:`~cavex.analytic.penetration.concrete_table.TableResistance`, the
model's own lock strain) at

- table points ``n_t`` = 33 (the default), 65, 129: the wall stress tabulated at ``n_t``
  velocities uniform in ``V`` up to the table top and interpolated (PCHIP in ``V``), with
  8 nose points;
- nose points ``n_q`` = 8 (the default), 16, 32: the Gauss rule over the ogive's normal angle
  (:func:`~cavex.analytic.penetration.nose.nose_rule`), with 129 table points,

and writes ``DIR/table_convergence.csv`` (per shot the depths, 7 significant digits) and
``DIR/table_convergence.md`` (per refinement the largest and median ``|d/d_finest - 1|`` and
the rate fitted with ``np.polyfit`` to ``log`` of the largest change against ``log`` of the
spacing). Default ``DIR``: ``results/concrete``. The cavity solution's own steps (256 RK4
steps; ``tests/test_concrete_cavity_sweep.py``) and the integrator's tolerance (``rtol``
1e-9) are refined elsewhere (docs/concrete.md); here the integrator runs at :data:`RTOL`.
"""

import argparse
import csv
import io
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from cavex.analytic.penetration.concrete_table import TABLE_POINTS, TableResistance, table_depth
from cavex.analytic.penetration.nose import QUADRATURE_POINTS
from cavex.verification.output.files import write_text_atomic

# the integrator's tolerances of the concrete studies' flights: at the model's rtol 1e-9 the
# depths of one shot differ by up to 5e-8 between two CPUs' vector maths (7 of this study's
# 1430 depths, written with 7 digits, then read one unit differently under the emulation of
# results/regenerate.sh); at 1e-12 by about 1e-9, and the emulation wrote the same CSV byte
# for byte
from cavex.verification.studies.concrete_validation import ATOL, RTOL
from cavex.verification.studies.inputs import study_inputs

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_SHOTS = ROOT / "examples" / "shots_compilation_dev.csv"
DEFAULT_OUT = ROOT / "results" / "concrete"
DIGITS = 7  # the depths' changes go down to ~1e-7: 7 digits resolve them
TABLE_SERIES = (TABLE_POINTS, 2 * TABLE_POINTS - 1, 4 * TABLE_POINTS - 3)  # 33, 65, 129
NOSE_SERIES = (QUADRATURE_POINTS, 2 * QUADRATURE_POINTS, 4 * QUADRATURE_POINTS)  # 8, 16, 32
#: the settings flown, ``(table points, nose points)``; the two series share the finest table
SETTINGS = tuple((n, QUADRATURE_POINTS) for n in TABLE_SERIES) + tuple(
    (TABLE_SERIES[-1], n) for n in NOSE_SERIES[1:])


def column(setting):
    return f"depth_t{setting[0]}_q{setting[1]}_m"


def shot_depths(shot):
    """The depth (m) of ``shot`` at every one of :data:`SETTINGS`, the integrator at
    :data:`RTOL`."""
    return [table_depth(shot, TableResistance(shot, table_points=t, nose_points=q),
                        rtol=RTOL, atol=ATOL) for t, q in SETTINGS]


def all_depths(shots, workers=1):
    """Per shot its :func:`shot_depths` (``workers`` processes; the shots of one concrete
    share its tables, so they go to one task)."""
    groups = {}
    for i, shot in enumerate(shots):
        groups.setdefault((shot.fc, shot.rho), []).append(i)
    tasks = list(groups.values())
    chunks = [[shots[i] for i in task] for task in tasks]
    if workers <= 1:
        results = [list(map(shot_depths, chunk)) for chunk in chunks]
    else:
        with ProcessPoolExecutor(workers) as pool:
            results = list(pool.map(_chunk_depths, chunks))
    out = [None] * len(shots)
    for task, result in zip(tasks, results, strict=True):
        for i, depths in zip(task, result, strict=True):
            out[i] = depths
    return np.array(out)


def _chunk_depths(chunk):
    return [shot_depths(shot) for shot in chunk]


def series_changes(depths, settings):
    """``(largest, median)`` of ``|d/d_finest - 1|`` over the shots for each of ``settings``
    but the last (the finest)."""
    index = [SETTINGS.index(s) for s in settings]
    finest = depths[:, index[-1]]
    changes = [np.abs(depths[:, k] / finest - 1.0) for k in index[:-1]]
    return [(float(c.max()), float(np.median(c))) for c in changes]


def fitted_rate(points, changes):
    """Order of a change against the spacing ``1/points``, ``np.polyfit`` in logs over the two
    coarse levels (their change against the finest, which holds the finest's own error: a
    lower bound of the rate)."""
    spacing = 1.0 / np.asarray(points, dtype=float)
    return float(np.polyfit(np.log(spacing), np.log(changes), 1)[0])


def stalled(depths, settings):
    """Indices of the shots whose change does not fall by half from the coarsest level of
    ``settings`` to the next (both against the finest): where the depth is limited by
    something the series does not refine."""
    index = [SETTINGS.index(s) for s in settings]
    finest = depths[:, index[-1]]
    coarse, middle = (np.abs(depths[:, k] / finest - 1.0) for k in index[:2])
    return [int(i) for i in np.flatnonzero((middle > 0.5 * coarse) & (coarse > 1e-6))]


def report(shots, depths):
    table_settings = [(n, QUADRATURE_POINTS) for n in TABLE_SERIES]
    nose_settings = [(TABLE_SERIES[-1], n) for n in NOSE_SERIES]
    table = series_changes(depths, table_settings)
    nose = series_changes(depths, nose_settings)
    lines = [
        "# The concrete model's depth against its table and nose discretisation",
        "",
        "Written by `python -m cavex.verification.studies.concrete_table_convergence` "
        f"({len(shots)} shots; docs/concrete.md \"Discretisation of the flight\"). Change of "
        "the depth against the finest of each series, over the shots (the largest to two "
        "digits, the median to one: the digits two CPUs agree on):",
        "",
        "| series | setting | largest | median |",
        "|---|---|---:|---:|",
    ]
    for n, (largest, median) in zip(TABLE_SERIES, table, strict=False):
        lines.append(f"| table points (nose 8) | {n} | {largest:.1e} | {median:.0e} |")
    for n, (largest, median) in zip(NOSE_SERIES, nose, strict=False):
        lines.append(f"| nose points (table {TABLE_SERIES[-1]}) | {n} | {largest:.1e} | "
                     f"{median:.0e} |")
    rate_t = fitted_rate([n - 1 for n in TABLE_SERIES[:2]], [c[1] for c in table])
    lines += ["", f"Fitted order of the median change in the table points: {rate_t:.1f} (the "
              "nose rule's median change is below the 7 digits written).", ""]
    for name, settings in (("table", table_settings), ("nose", nose_settings)):
        ids = [shots[i].id for i in stalled(depths, settings)]
        lines.append(f"Shots whose change does not halve from the coarsest {name} level to the "
                     f"next: {', '.join(ids) if ids else 'none'}.")
    lines.append("")
    return "\n".join(lines)


def write_csv(shots, depths):
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["id", *map(column, SETTINGS)])
    for shot, row in zip(shots, depths, strict=True):
        writer.writerow([shot.id, *(f"{d:.{DIGITS}g}" for d in row)])
    return out.getvalue()


def read_depths(path):
    """``(ids, depths)`` of a written ``table_convergence.csv``."""
    with open(path, newline="") as handle:
        rows = list(csv.reader(handle))
    if rows[0][1:] != [column(s) for s in SETTINGS]:
        raise ValueError(f"{path}: columns {rows[0][1:]} are not this study's settings")
    return [r[0] for r in rows[1:]], np.array([[float(x) for x in r[1:]] for r in rows[1:]])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shots", default=str(DEFAULT_SHOTS))
    parser.add_argument("--out", default=str(DEFAULT_OUT))
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    inputs = study_inputs(args)
    if inputs is None:
        return 2
    out, shots = inputs[0], list(inputs[1])
    out.mkdir(parents=True, exist_ok=True)
    depths = all_depths(shots, args.workers)
    if not np.all(np.isfinite(depths)):
        print("concrete_table_convergence: a depth is not finite", file=sys.stderr)
        return 1
    # the report reads the written (rounded) depths, as the test does
    write_text_atomic(Path(out) / "table_convergence.csv", write_csv(shots, depths))
    _, written = read_depths(Path(out) / "table_convergence.csv")
    text = report(shots, written)
    write_text_atomic(Path(out) / "table_convergence.md", text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
