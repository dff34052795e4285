"""Nose erosion on the development shots above 800 m/s: each integrating model rigid and with
the Silling-Forrestal abrasion law (:mod:`cavex.analytic.penetration.erosion`), the depth bias
by striking-velocity band. Nothing is fitted: the law's constants are its flagged ones
(docs/erosion.md).

Per model and band: ``n``, the bias (mean ``ln(predicted/measured)``, positive: too deep) and
the mean ``|ln(predicted/measured)|``, rigid and eroded; per shot both depths and, for the
concrete model, the mass lost and the final CRH. Writes ``erosion_bias.csv`` and
``erosion_bias.md`` into ``--out`` (default ``results/erosion``).
"""

import argparse
import csv
import io
import math
import sys
from pathlib import Path

from cavex.verification.output.files import write_text_atomic
from cavex.verification.output.number_format import round_significant

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_SHOTS = ROOT / "examples" / "shots_compilation_dev.csv"
DEFAULT_OUT = ROOT / "results" / "erosion"
FASTER_THAN = 800.0  # m/s: the shots studied (the "above ~800 m/s")
BANDS = ((800.0, 1000.0), (1000.0, 1200.0), (1200.0, 1500.0), (1500.0, math.inf))
def _models():
    """The labels of the models whose shots erode, but those that need FE tables."""
    from cavex.analytic.models.registry import models

    return tuple(label for model in models(erodes=True, takes_table=False)
                 for label in model.labels())


MODELS = _models()
DIGITS = 6


def shot_rows(shots, models=MODELS, law=None):
    """Per shot: ``id``, ``V0_m_s``, ``measured_m``, ``{model: (rigid, eroded)}`` depths (m,
    None where a prediction failed) and the concrete model's ``mass_loss_fraction`` and
    ``crh_final`` (None without it)."""
    from cavex.analytic.models.registry import parse_label
    from cavex.analytic.penetration.concrete_table import TableResistance, table_flight
    from cavex.analytic.penetration.erosion import SILLING_FORRESTAL
    from cavex.errors import CavexInputError, CavexNumericalError
    from cavex.verification.validation.predict import predict

    law = law or SILLING_FORRESTAL
    rows = []
    for shot in shots:
        row = {"id": shot.id, "V0_m_s": shot.V0, "measured_m": shot.depth, "depths": {},
               "mass_loss_fraction": None, "crh_final": None}
        for model in models:
            try:
                if parse_label(model)[0].concrete_table_seconds > 0.0:  # its summary
                    resistance = TableResistance(shot)
                    rigid = table_flight(shot, resistance)[0]
                    eroded, summary = table_flight(shot, resistance, law)
                    if summary is not None:
                        row["mass_loss_fraction"] = summary["mass_loss_fraction"]
                        row["crh_final"] = summary["crh_final"]
                else:
                    rigid, eroded = predict(shot, model), predict(shot, model, erosion=law)
                pair = (round_significant(rigid, DIGITS), round_significant(eroded, DIGITS))
            except (CavexInputError, CavexNumericalError):
                pair = (None, None)
            row["depths"][model] = pair
        rows.append(row)
    return rows


def band_statistics(rows, models=MODELS, bands=BANDS):
    """``[{band, model, n, bias_rigid, bias_eroded, abs_rigid, abs_eroded}]`` over the rows
    whose ``V0`` is in ``(low, high]`` and both depths exist (4 significant digits)."""
    out = []
    for low, high in bands:
        for model in models:
            logs = [(math.log(r["depths"][model][0] / r["measured_m"]),
                     math.log(r["depths"][model][1] / r["measured_m"])) for r in rows
                    if low < r["V0_m_s"] <= high and None not in r["depths"][model]]
            if not logs:
                continue

            def mean(values):
                return round_significant(sum(values) / len(values), 4)

            out.append({"band": f"({low:g}, {high:g}] m/s", "model": model, "n": len(logs),
                        "bias_rigid": mean([a for a, _ in logs]),
                        "bias_eroded": mean([b for _, b in logs]),
                        "abs_rigid": mean([abs(a) for a, _ in logs]),
                        "abs_eroded": mean([abs(b) for _, b in logs])})
    return out


def within_group_exponents(rows, shots, columns=None):
    """``(n, {column: slope})``: the velocity exponent ``d ln P / d ln V0`` within groups of
    one reference, projectile (mass, diameter, CRH) and ``f_c`` (least squares on the
    deviations from each group's means; groups of 2 or more shots whose ``V0`` spans over 2 %),
    of the measured depths and of each model's rigid and eroded ones. ``shots``: id -> shot."""
    import numpy as np

    columns = columns or ["measured"] + [f"{m} {k}" for m in MODELS for k in ("rigid", "eroded")]
    groups = {}
    for row in rows:
        s = shots[row["id"]]
        groups.setdefault((s.extra.get("source"), s.mass, s.diameter, s.crh, s.fc),
                          []).append(row)
    x, y = [], {c: [] for c in columns}
    for group in groups.values():
        complete = [r for r in group if all(None not in r["depths"][m] for m in MODELS)]
        lv = np.log([r["V0_m_s"] for r in complete])
        if len(complete) < 2 or lv.max() - lv.min() < 0.02:
            continue
        x += list(lv - lv.mean())
        for c in columns:
            model, _, kind = c.partition(" ")
            ly = np.log([r["measured_m"] if c == "measured" else
                         r["depths"][model][kind == "eroded"] for r in complete])
            y[c] += list(ly - ly.mean())
    x = np.array(x)
    return len(x), {c: round_significant(float(np.dot(x, y[c]) / np.dot(x, x)), 3)
                    for c in columns}


def study_csv(rows, models=MODELS):
    """The per-shot CSV text."""
    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(["id", "V0_m_s", "measured_m", *[f"{m} {kind}" for m in models
                                                     for kind in ("rigid_m", "eroded_m")],
                     "concrete mass_loss_fraction", "concrete crh_final"])
    for r in rows:
        writer.writerow([r["id"], r["V0_m_s"], r["measured_m"],
                         *["" if d is None else d for m in models for d in r["depths"][m]],
                         _g(r["mass_loss_fraction"]), _g(r["crh_final"])])
    return text.getvalue()


def _g(value):
    return "" if value is None else f"{round_significant(value, 4):g}"


def report_md(rows, statistics, shots_name, exponents=None):
    """The bias table by band and model, in markdown (and the within-group exponents)."""
    fractions = sorted(r["mass_loss_fraction"] for r in rows
                       if r["mass_loss_fraction"] is not None)
    lines = [f"# Nose erosion on the development shots above {FASTER_THAN:g} m/s", "",
             f"{len(rows)} shots of `{shots_name}` with `V0 > {FASTER_THAN:g}` m/s; each model "
             "rigid and with `--erosion silling-forrestal` (mu 0.1, Q 1.31 MJ/kg: not the "
             "source's constants, none fitted; docs/erosion.md). Bias: mean "
             "ln(predicted/measured), positive too deep. Written by `python -m "
             "cavex.verification.studies.erosion_study`.", "",
             "| band | model | n | bias rigid | bias eroded | mean abs ln rigid | "
             "mean abs ln eroded |", "|---|---|---|---|---|---|---|"]
    lines += [f"| {s['band']} | {s['model']} | {s['n']} | {s['bias_rigid']:+.3f} | "
              f"{s['bias_eroded']:+.3f} | {s['abs_rigid']:.3f} | {s['abs_eroded']:.3f} |"
              for s in statistics]
    if fractions:
        lines += ["", f"Concrete model: mass lost {100 * fractions[0]:.1f} to "
                  f"{100 * fractions[-1]:.1f} % of the projectile (median "
                  f"{100 * fractions[len(fractions) // 2]:.1f} %)."]
    if exponents is not None:
        n, slopes = exponents
        lines += ["", f"Velocity exponent d ln P / d ln V0 within groups of one reference, "
                  f"projectile and f_c ({n} shots in groups of 2 or more): "
                  + ", ".join(f"{c} {v:.2f}" for c, v in slopes.items()) + "."]
    return "\n".join(lines) + "\n"


def main(argv=None):
    from cavex.verification.validation.shots import read_shots

    parser = argparse.ArgumentParser(prog="python -m cavex.verification.studies.erosion_study",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--shots", default=str(DEFAULT_SHOTS))
    parser.add_argument("--out", default=str(DEFAULT_OUT))
    args = parser.parse_args(argv)
    shots = [s for s in read_shots(args.shots).shots if s.V0 > FASTER_THAN]
    rows = shot_rows(shots)
    statistics = band_statistics(rows)
    exponents = within_group_exponents(rows, {s.id: s for s in shots})
    folder = Path(args.out)
    folder.mkdir(parents=True, exist_ok=True)
    write_text_atomic(folder / "erosion_bias.csv", study_csv(rows))
    report = report_md(rows, statistics, Path(args.shots).name, exponents)
    write_text_atomic(folder / "erosion_bias.md", report)
    print(report, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
