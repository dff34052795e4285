r"""How well the concrete cavity-expansion model predicts measured depths (issue 19, phase 1).

``python -m cavex.verification.studies.concrete_validation [--shots FILE] [--out DIR]
[--workers N]`` writes ``DIR/predictions.csv`` (per shot: every model's depth, the rigid flag,
``A``, ``B``), ``DIR/grid_depths.csv`` (the model's depth of every shot at every grid point of the
constants) and ``DIR/report.md`` (the tables). Default shots: ``examples/shots_compilation_dev.csv``
(286 shots, 21 references), default folder ``results/concrete``.

Models compared (:mod:`cavex.analytic.penetration.concrete_table`):

- ``concrete (published)``: the concrete cavity expansion with every constant at its published
  value (:class:`~cavex.concrete.Constants`), no fit;
- ``concrete (fitted)``: ``S_max`` and ``p_l`` chosen on :data:`GRID` to minimise the mean
  ``|ln(predicted/measured)|`` over all shots (in-sample);
- ``concrete (LORO)``: the same fit repeated with each reference left out in turn, its shots
  predicted with the constants fitted on the other references (cross-validated);
- ``Li & Chen 2003``, ``Forrestal 1994`` (empirical) and ``cavex derived dynamic``
  (:func:`cavex.verification.validation.predict.predict`).

Regimes (:data:`REGIMES`): all shots; normal strength (``f_c <= 100`` MPa) at ``V0 <= 1000`` m/s;
``V0 > 1000`` m/s; ``f_c > 100`` MPa; and the shots not flagged non-rigid.
"""

import argparse
import csv
import io
import itertools
import math
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from cavex.analytic import empirical
from cavex.analytic.empirical import li_chen_depth
from cavex.analytic.penetration.concrete_table import TableResistance, table_depth
from cavex.concrete import Constants
from cavex.errors import CavexInputError, CavexNumericalError
from cavex.verification.output.files import write_text_atomic
from cavex.verification.output.number_format import round_significant
from cavex.verification.studies.inputs import study_inputs
from cavex.verification.validation.predict import predict
from cavex.verification.validation.regimes import rigid_flag

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_SHOTS = ROOT / "examples" / "shots_compilation_dev.csv"
DEFAULT_OUT = ROOT / "results" / "concrete"
# significant digits of every depth and constant written (the statistics are computed from the
# written depths): regenerated with numpy's AVX2/AVX-512 code paths disabled and numba compiling
# for a generic CPU, 1 of the 5720 grid depths moved in its 6th digit (a relative change of
# ~2e-10), so at 4 digits a flip on another CPU is ~100 times less likely than one unit of
# the 6th was; a measured depth has 2-3 digits
DIGITS = 4
# the integrator's tolerances of the study's flights, tighter than the model's 1e-9 (whose
# share of a depth is at most 6e-7, docs/concrete.md "Discretisation of the flight"): at 1e-9
# two CPUs' depths differ by up to 5e-8 where a step is taken differently, enough to flip a
# 4th digit that lies at a rounding boundary (C380 at S_max = 7, p_l = 0.3 GPa: 0.670950004
# and 0.670949969 m under the emulation of results/regenerate.sh); at 1e-12 by about 1e-9
RTOL, ATOL = 1e-12, 1e-15
FITTED = ("cap", "lock_pressure")
# the grid of the fitted constants: S_max = tau_max/f_c and the locking pressure p_l (Pa)
GRID = tuple(itertools.product((4.0, 5.5, 7.0, 10.0, 14.0), (0.3e9, 0.5e9, 0.8e9, 1.2e9)))
PUBLISHED = (Constants().cap, Constants().lock_pressure)
MODEL = "concrete (published)"
FIT = "concrete (fitted)"
LORO = "concrete (LORO)"
LI_CHEN = "Li & Chen 2003"
FORRESTAL = "Forrestal 1994"
CAVEX = "cavex derived-dynamic"
MODELS = (MODEL, FIT, LORO, LI_CHEN, FORRESTAL, CAVEX)
REGIMES = {
    "all": lambda s, flag: True,
    "f_c <= 100 MPa, V0 <= 1000 m/s": lambda s, flag: s.fc <= 100e6 and s.V0 <= 1000.0,
    "V0 > 1000 m/s": lambda s, flag: s.V0 > 1000.0,
    "f_c > 100 MPa": lambda s, flag: s.fc > 100e6,
    "not flagged non-rigid": lambda s, flag: flag == "",
}


def source(shot):
    """The reference a shot comes from (column ``source``; the id if there is none)."""
    return shot.extra.get("source", shot.id)


def grid_depths(shots, point):
    """Depths (m) of the model for ``shots`` with ``(S_max, p_l) = point`` (NaN where the cavity
    expansion has no self-similar solution, or where the hydrostat has no compaction range for
    that concrete, ``p_l`` above the elastic line at HJC's ``mu_l``: the point is then left out
    of the fits)."""
    constants = Constants().with_values(FITTED, point)
    out = []
    for s in shots:
        try:
            out.append(round_significant(table_depth(s, TableResistance(s, constants),
                                                     rtol=RTOL, atol=ATOL), DIGITS))
        except (CavexInputError, CavexNumericalError):
            out.append(math.nan)
    return out


def all_grid_depths(shots, workers=1):
    """``{point: [depth]}`` over :data:`GRID` (``workers`` processes)."""
    if workers <= 1:
        return {point: grid_depths(shots, point) for point in GRID}
    with ProcessPoolExecutor(workers) as pool:
        results = pool.map(grid_depths, itertools.repeat(shots), GRID)
        return dict(zip(GRID, results, strict=True))


def mean_abs_log(depths, shots, indices):
    """Mean ``|ln(depth/measured)|`` over ``indices`` (inf if a depth is missing)."""
    values = [abs(math.log(depths[i] / shots[i].depth)) for i in indices]
    return float(np.mean(values)) if all(map(math.isfinite, values)) else math.inf


def admissible(grid):
    """The grid points at which every shot has a depth (the cavity expansion has a solution for
    every shot's inputs; no measured depth enters)."""
    return [point for point in GRID if all(map(math.isfinite, grid[point]))]


def best_point(grid, shots, indices):
    """The admissible grid point with the smallest mean ``|ln ratio|`` over ``indices`` (first
    on ties)."""
    return min(admissible(grid), key=lambda point: mean_abs_log(grid[point], shots, indices))


def loro(grid, shots):
    """Leave-one-reference-out: ``(depths, {reference: point})``: every reference's shots
    predicted at the point fitted on the other references."""
    depths = [None] * len(shots)
    chosen = {}
    for ref in sorted({source(s) for s in shots}):
        held = [i for i, s in enumerate(shots) if source(s) == ref]
        rest = [i for i, s in enumerate(shots) if source(s) != ref]
        point = chosen[ref] = best_point(grid, shots, rest)
        for i in held:
            depths[i] = grid[point][i]
    return depths, chosen


def baseline_depths(shots):
    """``{model: [depth or None]}`` of the empirical models and cavex's derived dynamic one."""
    out = {LI_CHEN: [], FORRESTAL: [], CAVEX: []}
    for s in shots:
        out[LI_CHEN].append(round_significant(li_chen_depth(s), DIGITS))
        out[FORRESTAL].append(round_significant(empirical.shot_depth(s), DIGITS))
        try:
            value = round_significant(predict(s, "derived-dynamic"), DIGITS)
        except (CavexInputError, CavexNumericalError):
            value = None
        out[CAVEX].append(value)
    return out


def statistics(depths, shots, flags):
    """``{regime: (n, mean |ln ratio|, mean ln ratio)}`` of one model (None depths skipped)."""
    out = {}
    for name, member in REGIMES.items():
        logs = [math.log(d / s.depth) for d, s, f in zip(depths, shots, flags, strict=True)
                if d is not None and member(s, f)]
        out[name] = ((len(logs), float(np.mean(np.abs(logs))), float(np.mean(logs))) if logs
                     else (0, None, None))
    return out


def study(shots, workers=1):
    """Every model's depths, the flags, the fitted points and the statistics."""
    published = Constants()
    resistances = [TableResistance(s, published) for s in shots]
    flags = [rigid_flag(s, r) for s, r in zip(shots, resistances, strict=True)]
    grid = all_grid_depths(shots, workers)
    everyone = range(len(shots))
    fitted = best_point(grid, shots, everyone)
    loro_depths, chosen = loro(grid, shots)
    depths = {MODEL: grid[PUBLISHED], FIT: grid[fitted], LORO: loro_depths,
              **baseline_depths(shots)}
    return {"shots": shots, "flags": flags, "grid": grid, "fitted": fitted, "chosen": chosen,
            "depths": depths, "A": [r.A for r in resistances], "B": [r.B for r in resistances],
            "statistics": {m: statistics(depths[m], shots, flags) for m in MODELS}}


def predictions_csv(result):
    shots, depths = result["shots"], result["depths"]
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["id", "source", "fc_Pa", "rho_kg_m3", "V0_m_s", "measured_m", "flag", "A",
                     "B", *MODELS])
    for i, s in enumerate(shots):
        writer.writerow([s.id, source(s), s.fc, s.rho, s.V0, s.depth, result["flags"][i],
                         round_significant(result["A"][i], DIGITS),
                         round_significant(result["B"][i], DIGITS),
                         *("" if depths[m][i] is None else depths[m][i] for m in MODELS)])
    return out.getvalue()


def grid_csv(result):
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["id", *(f"S_max={c:g};p_l={p:g}" for c, p in GRID)])
    for i, s in enumerate(result["shots"]):
        writer.writerow([s.id, *(result["grid"][point][i] for point in GRID)])
    return out.getvalue()


def report_md(result, shots_file):
    stats = result["statistics"]
    lines = ["# Concrete cavity expansion against measured depths (issue 19, phase 1)", "",
             f"Shots: `{shots_file}` ({len(result['shots'])} shots, "
             f"{len({source(s) for s in result['shots']})} references). "
             "Made by `python -m cavex.verification.studies.concrete_validation`.", "",
             "Mean |ln(predicted/measured)| / mean ln(predicted/measured) (bias), per regime "
             "(n shots):", ""]
    regimes = list(REGIMES)
    counts = [stats[LI_CHEN][r][0] for r in regimes]
    lines.append("| model | " + " | ".join(f"{r} ({n})" for r, n in zip(regimes, counts,
                                                                          strict=True)) + " |")
    lines.append("|---|" + "---:|" * len(regimes))
    for m in MODELS:
        cells = [f"{stats[m][r][1]:.3f} / {stats[m][r][2]:+.3f}" if stats[m][r][0] else "n/a"
                 for r in regimes]
        failed = counts[0] - stats[m][regimes[0]][0]
        lines.append(f"| {m}{f' ({failed} shots failed)' if failed else ''} | "
                     + " | ".join(cells) + " |")
    c, p = result["fitted"]
    left_out = [f"S_max = {c:g}, p_l = {p / 1e9:g} GPa" for c, p in GRID
                if (c, p) not in admissible(result["grid"])]
    lines += ["", f"Published constants: S_max = {PUBLISHED[0]:g}, p_l = {PUBLISHED[1] / 1e9:g} "
              "GPa. Fitted on all shots (grid "
              f"S_max x p_l = {len(GRID)} points): S_max = {c:g}, p_l = {p / 1e9:g} GPa. "
              "Grid points left out (no self-similar solution for some shot's inputs): "
              f"{'; '.join(left_out) or 'none'}.", "",
              "Leave-one-reference-out choices:", "", "| left out | S_max | p_l (GPa) |",
              "|---|---:|---:|"]
    for ref, (c, p) in result["chosen"].items():
        lines.append(f"| {ref} | {c:g} | {p / 1e9:g} |")
    flagged = sum(1 for f in result["flags"] if f)
    lines += ["", f"Shots flagged non-rigid (mean nose pressure at impact above the projectile's "
              f"yield strength, published constants): {flagged}.", ""]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m cavex.verification.studies."
                                     "concrete_validation", description=__doc__.splitlines()[0])
    parser.add_argument("--shots", default=str(DEFAULT_SHOTS))
    parser.add_argument("--out", default=str(DEFAULT_OUT))
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args(argv)
    inputs = study_inputs(args)
    if inputs is None:
        return 2
    folder, shots = inputs
    result = study(shots, max(1, args.workers))
    folder.mkdir(parents=True, exist_ok=True)
    write_text_atomic(folder / "predictions.csv", predictions_csv(result))
    write_text_atomic(folder / "grid_depths.csv", grid_csv(result))
    write_text_atomic(folder / "report.md", report_md(result, Path(args.shots).name))
    print(report_md(result, Path(args.shots).name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
