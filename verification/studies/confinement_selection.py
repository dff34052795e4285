r"""The published options of the concrete model's shear limit and lock strain on the
development shots, chosen by leaving out one reference and one kind of shot (issue 31, item
2's rule).

``python -m cavex.verification.studies.confinement_selection [--shots FILE] [--workers N]
[--out DIR]`` writes ``DIR/confinement_selection.csv`` (each shot's depth under each option,
empty where the cavity expansion has no self-similar solution) and
``DIR/confinement_selection.md`` (the tables); default shots
``examples/shots_compilation_dev.csv``, default ``--out results/concrete``.

Options (:data:`OPTIONS`), each the concrete cavity model (:mod:`cavex.concrete`) with every
other constant at its published value:

- ``hjc lock``, ``porosity lock``: the concrete model's two options
  (:func:`cavex.analytic.models.concrete.option_constants`): Richart's line capped at
  ``7 f_c``, the lock strain HJC's 0.1 or from the porosity law;
- ``hjc meridian``, ``rht meridian``: the porosity lock with the comminuted strength the power
  law of that flattening meridian normalised by ``f_c``
  (:func:`cavex.concrete_confinement.cavity_power_law`; HJC's keeps its cap ``7 f_c``, RHT's
  has none);
- ``hjc meridian unscaled``, ``rht meridian unscaled``: the same meridians of their reference
  concretes (48 and 46 MPa) for every ``f_c`` (the high-confinement strength independent of
  ``f_c``, as Malecot et al. 2009 report for 21-57 MPa).

The choice and the folds are ``cavex validate``'s (:mod:`cavex.verification.validation.
cross_validation`: ``choose``, the fewest shots without a depth, then the smallest mean
``|ln(predicted/measured)|``, on the shots not left out; ``fold_indices``, each reference,
and each kind of shot against the rest). Depths flown at the concrete study's
tolerances (:data:`cavex.verification.studies.concrete_validation.RTOL`), written to
:data:`DIGITS` significant digits.
"""

import argparse
import csv
import io
import math
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from cavex.analytic.empirical import li_chen_depth
from cavex.analytic.models.concrete import option_constants
from cavex.analytic.penetration.concrete_table import TableResistance, table_depth
from cavex.concrete_confinement import cavity_power_law
from cavex.errors import CavexInputError, CavexNumericalError
from cavex.verification.output.files import write_text_atomic
from cavex.verification.output.number_format import round_significant
from cavex.verification.studies.concrete_validation import ATOL, RTOL
from cavex.verification.studies.inputs import study_inputs
from cavex.verification.validation.cross_validation import FOLDS, choose, fold_indices
from cavex.verification.validation.regimes import (
    DEPTH_DIGITS,
    REGIME_TITLES,
    REGIMES,
    log_statistics,
)

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_SHOTS = ROOT / "examples" / "shots_compilation_dev.csv"
DEFAULT_OUT = ROOT / "results" / "concrete"
DIGITS = 4
SHOWN = ("all", "normal_strength", "fast", "high_strength")  # the regimes of the tables
POWER = ("cap", "power_B", "power_N")
LI_CHEN = "li-chen-2003 (not an option)"


def _meridian(meridian, scaling):
    def constants(shot):
        B, N, cap = cavity_power_law(shot.fc, meridian, scaling)
        return option_constants(shot, "porosity lock").with_values(POWER, (cap, B, N))
    return constants


OPTIONS = {
    "hjc lock": lambda shot: option_constants(shot, "hjc"),
    "porosity lock": lambda shot: option_constants(shot, "porosity lock"),
    "hjc meridian": _meridian("hjc", "fc"),
    "rht meridian": _meridian("rht", "fc"),
    "hjc meridian unscaled": _meridian("hjc", "none"),
    "rht meridian unscaled": _meridian("rht", "none"),
}


def option_depths(args):
    """``(option, [depth or None])`` of ``shots`` under ``option`` (``args = (option, shots)``),
    each depth to :data:`DIGITS` significant digits; None where the cavity expansion has no
    self-similar solution, or where the option gives the concrete no admissible material (the
    unscaled HJC meridian's cap ``7 x 48`` MPa below ``f_c`` above 336 MPa)."""
    option, shots = args
    out = []
    for s in shots:
        try:
            depth = table_depth(s, TableResistance(s, OPTIONS[option](s)), rtol=RTOL, atol=ATOL)
            out.append(round_significant(depth, DIGITS))
        except (CavexInputError, CavexNumericalError):
            out.append(None)
    return option, out


def all_option_depths(shots, workers=1):
    """``{option: [depth or None]}`` over :data:`OPTIONS` (``workers`` processes)."""
    tasks = [(option, shots) for option in OPTIONS]
    if workers <= 1:
        return dict(map(option_depths, tasks))
    with ProcessPoolExecutor(workers) as pool:
        return dict(pool.map(option_depths, tasks))


def _in_regime(shot, regime):
    return REGIMES[regime](shot.fc, shot.V0, None)


def _cell(depths, shots, indices):
    """``"mean |ln| / bias (missing)"`` of ``depths`` over ``indices``."""
    stats = log_statistics([None if depths[i] is None else depths[i] / shots[i].depth
                            for i in indices], DEPTH_DIGITS)
    missing = len(indices) - stats["n"]
    if stats["n"] == 0:
        return f"- ({missing} missing)"
    text = f"{stats['mean_abs_log_ratio']:.3f} / {stats['mean_log_ratio']:+.3f}"
    return text + (f" ({missing} missing)" if missing else "")


def _spread(depths, shots, indices):
    """Mean ``|ln ratio - bias|`` over ``indices`` (the bias the mean ``ln ratio`` there): the
    score a correct level would leave, the shape's share of the error."""
    logs = [math.log(depths[i] / shots[i].depth) for i in indices if depths[i] is not None]
    return f"{sum(abs(x - sum(logs) / len(logs)) for x in logs) / len(logs):.3f}"


def strength_slope(depths, shots, indices):
    """The slope of ``ln(depth/measured)`` in ``ln f_c`` over ``indices`` (the shots with a
    depth), least squares on ``1, ln f_c, ln V0, ln d, ln CRH`` together: how much faster
    than the measured depths the predicted ones fall with the concrete's strength."""
    have = [i for i in indices if depths[i] is not None]
    columns = [[1.0, math.log(shots[i].fc), math.log(shots[i].V0), math.log(shots[i].diameter),
                math.log(shots[i].crh)] for i in have]
    logs = [math.log(depths[i] / shots[i].depth) for i in have]
    return float(np.linalg.lstsq(np.array(columns), np.array(logs), rcond=None)[0][1])


def report_md(depths, shots):
    """The report of ``depths`` (``{option: [depth or None]}``) on ``shots``: each option by
    regime (Li and Chen's 2003 formula beside them, not an option), and the choice without
    each fold."""
    measured = [s.depth for s in shots]
    everyone = list(range(len(shots)))
    regimes = {r: [i for i in everyone if _in_regime(shots[i], r)] for r in SHOWN}
    shown = {**depths, LI_CHEN: [round_significant(li_chen_depth(s), DEPTH_DIGITS)
                                 for s in shots]}  # as validate writes them
    lines = ["# The concrete model's published options on the development shots",
             "", "Written by `python -m cavex.verification.studies.confinement_selection` "
             "(module docstring: the options). Mean |ln(predicted/measured)| / bias over the "
             "shots with a depth, the shots without one in brackets.", "",
             "| option | " + " | ".join(f"{REGIME_TITLES[r]} ({len(regimes[r])})"
                                       for r in SHOWN) + " |",
             "|---|" + "---:|" * len(SHOWN)]
    for option, d in shown.items():
        lines.append(f"| {option} | " + " | ".join(_cell(d, shots, regimes[r]) for r in SHOWN)
                     + " |")
    lines += ["", "The shape's share: mean |ln ratio - bias| in each regime over the shots with "
              "a depth (the score if each option's level were right in that regime; a level no "
              "published constant sets).", "",
              "| option | " + " | ".join(REGIME_TITLES[r] for r in SHOWN) + " |",
              "|---|" + "---:|" * len(SHOWN)]
    for option, d in shown.items():
        lines.append(f"| {option} | " + " | ".join(_spread(d, shots, regimes[r]) for r in SHOWN)
                     + " |")
    normal = regimes["normal_strength"]
    lines += ["", "Slope of ln(predicted/measured) in ln f_c over the "
              f"{REGIME_TITLES['normal_strength']} shots (least squares on 1, ln f_c, ln V0, "
              "ln d, ln CRH): "
              + ", ".join(f"{o} {strength_slope(d, shots, normal):+.2f}" for o, d in shown.items())
              + "."]
    folds = fold_indices(shots, FOLDS)
    chosen_all = choose(depths, measured, everyone)
    lines += ["", f"Chosen on all shots: **{chosen_all}**.", "",
              "| fold left out | n | chosen on the others | on the fold |", "|---|---:|---|---:|"]
    held_out = [None] * len(shots)
    for name, (family, held) in folds.items():
        rest = sorted(set(everyone) - set(held))
        option = choose(depths, measured, rest)
        lines.append(f"| {name} | {len(held)} | {option} | {_cell(depths[option], shots, held)} |")
        if family == "reference":
            for i in held:
                held_out[i] = depths[option][i]
    lines += ["", "Each shot predicted by the option chosen without its reference: "
              + "; ".join(f"{REGIME_TITLES[r]} {_cell(held_out, shots, regimes[r])}"
                          for r in SHOWN) + "."]
    return "\n".join(lines) + "\n"


def depths_csv(depths, shots):
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(["id", "source", "measured_m", *depths])
    for i, s in enumerate(shots):
        writer.writerow([s.id, s.extra.get("source", ""), s.depth,
                         *("" if d[i] is None else repr(d[i]) for d in depths.values())])
    return buf.getvalue()


def read_depths_csv(text):
    """``{option: [depth or None]}`` of a :func:`depths_csv` text."""
    rows = list(csv.DictReader(io.StringIO(text)))
    options = [k for k in rows[0] if k not in ("id", "source", "measured_m")]
    return {o: [float(r[o]) if r[o] else None for r in rows] for o in options}


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m cavex.verification.studies.confinement_selection",
        description=__doc__.splitlines()[0])
    parser.add_argument("--shots", default=str(DEFAULT_SHOTS))
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--out", default=str(DEFAULT_OUT))
    args = parser.parse_args(argv)
    inputs = study_inputs(args)
    if inputs is None:
        return 2
    folder, shots = inputs[0], list(inputs[1])
    depths = all_option_depths(shots, max(1, args.workers))
    folder.mkdir(parents=True, exist_ok=True)
    text = report_md(depths, shots)
    write_text_atomic(folder / "confinement_selection.csv", depths_csv(depths, shots))
    write_text_atomic(folder / "confinement_selection.md", text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
