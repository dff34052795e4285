r"""The published options of :mod:`cavex.concrete_confinement` on the development shots, chosen
by leaving out one reference and one kind of shot (issue 31, item 2's rule).

``python -m cavex.verification.studies.confinement_selection [--shots FILE] [--workers N]
[--out DIR]`` writes ``DIR/confinement_selection.csv`` (each shot's depth under each option,
empty where the cavity expansion has no self-similar solution) and prints the tables; default
shots ``examples/shots_compilation_dev.csv``, no default output (nothing committed: the choice
is to be made again once the hydrostat has landed in the closed form, docs/concrete.md).

Options (:data:`OPTIONS`), each the concrete cavity model (:mod:`cavex.concrete`) with one
change and every other constant at its published value:

- ``today``: Richart's line capped at ``7 f_c``, HJC's hydrostat;
- ``hjc``, ``rht``: the comminuted strength the power law of that meridian normalised by
  ``f_c`` (:func:`cavex.concrete_confinement.cavity_power_law`);
- ``rht unscaled``: RHT's meridian of its 46 MPa concrete for every ``f_c``;
- ``porosity lock``: today's strength with ``mu_lock`` from the porosity law
  (:func:`cavex.concrete_confinement.hydrostat`).

Choice (:func:`cross_validated_choice`): an option is admissible on a set of shots if it gives
every one of them a depth; of the admissible ones, the one with the smallest mean
``|ln(predicted/measured)|`` on the other groups is chosen for each group left out, and scored on
it. Groups: the references, then the kinds of shot :data:`KINDS` (each left out against the
rest).
"""

import argparse
import csv
import io
import math
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from cavex.analytic.penetration.concrete_table import TableResistance, table_depth
from cavex.concrete import Constants
from cavex.concrete_confinement import cavity_power_law, hydrostat
from cavex.errors import CavexInputError, CavexNumericalError
from cavex.verification.output.files import write_text_atomic
from cavex.verification.output.paths import check_output_dir
from cavex.verification.validation.shots import read_shots

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_SHOTS = ROOT / "examples" / "shots_compilation_dev.csv"
POWER = ("cap", "power_B", "power_N")


def _power(meridian, scaling):
    def constants(shot):
        B, N, cap = cavity_power_law(shot.fc, meridian, scaling)
        return Constants().with_values(POWER, (cap, B, N))
    return constants


OPTIONS = {
    "today": lambda shot: Constants(),
    "hjc": _power("hjc", "fc"),
    "rht": _power("rht", "fc"),
    "rht unscaled": _power("rht", "none"),
    "porosity lock": lambda shot: Constants().with_values(
        ("lock_strain",), (hydrostat(shot.fc, shot.rho).mu_lock,)),
}
KINDS = {
    "calibre <= 13 mm": lambda s: s.diameter <= 0.013,
    "projectile yield < 1 GPa": lambda s: float(s.extra.get("proj_yield_MPa") or "inf") < 1000.0,
    "V0 > 1000 m/s": lambda s: s.V0 > 1000.0,
}


def option_depths(args):
    """``(option, [depth or nan])`` of ``shots`` under ``option`` (``args = (option, shots)``)."""
    option, shots = args
    out = []
    for s in shots:
        try:
            out.append(table_depth(s, TableResistance(s, OPTIONS[option](s))))
        except CavexNumericalError:
            out.append(math.nan)
    return option, out


def mean_abs_log(depths, measured, indices):
    """Mean ``|ln(depth/measured)|`` over ``indices``; inf if a depth there is missing."""
    logs = [math.log(depths[i] / measured[i]) for i in indices]
    return float(np.mean(np.abs(logs))) if all(map(math.isfinite, logs)) else math.inf


def cross_validated_choice(depths, measured, groups):
    """For each group (``{name: [shot indices]}``) left out: ``(option chosen on the others,
    its mean |ln ratio| there, on the group left out)``; ``depths`` is ``{option: [depth]}``.
    Admissible: a finite depth for every shot of the others (None if no option is)."""
    out = {}
    everyone = set(range(len(measured)))
    for name, held in groups.items():
        rest = sorted(everyone - set(held))
        admissible = [o for o in depths if all(math.isfinite(depths[o][i]) for i in rest)]
        if not admissible:
            out[name] = None
            continue
        chosen = min(admissible, key=lambda o: mean_abs_log(depths[o], measured, rest))
        out[name] = (chosen, mean_abs_log(depths[chosen], measured, rest),
                     mean_abs_log(depths[chosen], measured, held))
    return out


def groups_of(shots):
    """``(references, kinds)``: ``{name: [indices]}`` of each reference and each kind."""
    refs = {}
    for i, s in enumerate(shots):
        refs.setdefault(s.extra.get("source", s.id), []).append(i)
    kinds = {k: [i for i, s in enumerate(shots) if member(s)] for k, member in KINDS.items()}
    return refs, kinds


def report(depths, shots):
    measured = [s.depth for s in shots]
    everyone = range(len(shots))
    refs, kinds = groups_of(shots)
    lines = ["| option | shots without a depth | mean |ln ratio| (shots with a depth) |",
             "|---|---:|---:|"]
    for o, d in depths.items():
        have = [i for i in everyone if math.isfinite(d[i])]
        lines.append(f"| {o} | {len(shots) - len(have)} | "
                     f"{mean_abs_log(d, measured, have):.3f} |")
    loro = cross_validated_choice(depths, measured, refs)
    chosen = [v[0] for v in loro.values() if v]
    lines += ["", "Leaving out one reference: chosen " + ", ".join(
        f"{o} {chosen.count(o)} times" for o in depths if chosen.count(o)), ""]
    for kind, v in cross_validated_choice(depths, measured, kinds).items():
        lines.append(f"Leaving out {kind}: " + ("no option gives every other shot a depth"
                     if v is None else f"{v[0]} chosen ({v[1]:.3f} on the rest, "
                     f"{v[2]:.3f} on the kind)"))
    return "\n".join(lines)


def depths_csv(depths, shots):
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(["id", "source", "measured_m", *depths])
    for i, s in enumerate(shots):
        writer.writerow([s.id, s.extra.get("source", ""), s.depth,
                         *("" if not math.isfinite(d[i]) else f"{d[i]:.4g}"
                           for d in depths.values())])
    return buf.getvalue()


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m cavex.verification.studies.confinement_selection",
        description=__doc__.splitlines()[0])
    parser.add_argument("--shots", default=str(DEFAULT_SHOTS))
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--out", default=None)
    args = parser.parse_args(argv)
    try:
        folder = None if args.out is None else check_output_dir(args.out, "out")
        shots = list(read_shots(args.shots).shots)
    except CavexInputError as exc:
        print(f"cavex: {exc}", file=sys.stderr)
        return 2
    tasks = [(o, shots) for o in OPTIONS]
    if args.workers > 1:
        with ProcessPoolExecutor(args.workers) as pool:
            depths = dict(pool.map(option_depths, tasks))
    else:
        depths = dict(map(option_depths, tasks))
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
        write_text_atomic(folder / "confinement_selection.csv", depths_csv(depths, shots))
    print(report(depths, shots))
    return 0


if __name__ == "__main__":
    sys.exit(main())
