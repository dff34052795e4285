"""``cavex validate``: predictions against measurements, written as JSON, CSV, a
markdown report and two figures.

Files (in ``--out``, default ``results/validation``): ``validation.json`` (what ``--json``
prints), ``predictions.csv``, ``report.md``, ``predicted_vs_measured.png``,
``ratio_vs_velocity.png`` and ``tables/`` (a copy of the FE tables the run used, one per
distinct target; they are built once into the shared cache,
:mod:`cavex.verification.fedata.table_cache`, and reused by every later run into any folder).
Depths and statistics carry 6 significant digits (``validation.DEPTH_DIGITS``); the statistics
are computed from the written depths, so every printed number is a function of the stored ones,
and no wall time is written, so a rerun gives the same files.
"""

import csv
import io
import json
import math
import os
import shlex
import sys
import time

import numpy as np

from cavex.errors import CavexInputError
from cavex.verification.fedata.runner import check_execution
from cavex.verification.output.files import save_figure, write_text_atomic
from cavex.verification.output.paths import check_output_dir, write_staged
from cavex.verification.validation.predict import (
    CONCRETE,
    EMPIRICAL,
    FE_MODEL,
    LI_CHEN,
    MODELS,
    SPLIT,
    TableCache,
    add_statistics,
    predictions,
    validate,
)
from cavex.verification.validation.regimes import NON_RIGID, REGIME_TITLES, REGIMES
from cavex.verification.validation.shots import read_shots

DEFAULT_OUT = "results/validation"
COMPRESSIBILITY_COLUMN = f"{FE_MODEL}, derived-dynamic calibration"
BAND = 0.2  # +-20 % band on the predicted-against-measured figure


def run(args, target, projectile):
    """Check every input, run :func:`job`, write the files (every file or none, also on Ctrl-C
    or kill); return the text or JSON to print."""
    from cavex.verification.validation.calibration import read_calibration

    shots_path, calibration_paths = args.shots, args.calibration
    workers, scheduler = args.workers, args.scheduler
    models = check_models(args.models)
    shot_file = read_shots(shots_path)
    calibrations = [read_calibration(p) for p in calibration_paths or ()]
    columns = [c.column for c in calibrations]
    repeated = sorted({c for c in columns if columns.count(c) > 1})
    if repeated:
        raise CavexInputError(f"two calibrations of the same model ({', '.join(repeated)}); "
                              "give one per model")
    out = check_output_dir(DEFAULT_OUT if args.out is None else args.out, "out")
    check_execution(workers, scheduler)
    size = estimate(shot_file.shots, calibrations, out / "tables", workers, models)
    print(f"cavex: validate {size}", file=sys.stderr, flush=True)
    began = time.monotonic()
    result = job(shot_file, calibrations, tables_dir=out / "tables", workers=workers,
                 scheduler=scheduler, progress=args.progress, models=models)
    seconds = time.monotonic() - began
    result["command"] = command_line(shots_path, calibration_paths, out, args.models)
    written = write_staged(out, lambda stage: write_outputs(result, stage, draw=args.figures))
    if args.json:
        return json.dumps(summary(result), indent=2)
    return text(result, seconds, written)


def check_models(models):
    """The ``--models`` labels (None: all), checked
    (:func:`cavex.verification.validation.predict.check_models`)."""
    from cavex.verification.validation.predict import check_models as check

    return check(models)


def columns_of(calibrations, models=None):
    """Every column :func:`job` fills: the models (default all), the calibrated ones and, with
    a derived-dynamic calibration, :data:`COMPRESSIBILITY_COLUMN`."""
    from cavex.verification.validation.predict import validation_columns

    columns = validation_columns(calibrations, models=models)
    dynamic = [c for c in calibrations if c.model == "derived-dynamic"]
    if dynamic:
        columns[COMPRESSIBILITY_COLUMN] = (FE_MODEL, dynamic[0].mapping)
    return columns


def estimate(shots, calibrations, tables_dir, workers, models=None):
    """The run's size and time (:func:`cavex.verification.validation.predict.run_estimate`)."""
    from cavex.verification.validation.predict import run_estimate

    workers = workers or os.cpu_count() or 1
    return run_estimate(shots, columns_of(calibrations, models), TableCache(tables_dir),
                        workers)


def job(shot_file, calibrations=(), *, tables_dir=None, workers=None, scheduler=None,
        progress=None, models=None):
    """:func:`cavex.verification.validation.predict.validate` plus the compressibility column and
    the shots file's description."""
    from cavex.verification.fedata.runner import show_progress

    tables = TableCache(tables_dir, workers=workers, scheduler=scheduler,
                        progress=show_progress(progress))
    result = validate(shot_file.shots, calibrations=calibrations, tables=tables,
                      progress=progress, models=models)
    if any(c.model == "derived-dynamic" for c in calibrations):
        columns = {COMPRESSIBILITY_COLUMN: columns_of(calibrations)[COMPRESSIBILITY_COLUMN]}
        depths, failures = predictions(shot_file.shots, columns, tables, progress)
        for row, depth in zip(result["shots"], depths[COMPRESSIBILITY_COLUMN], strict=True):
            row["predicted_m"][COMPRESSIBILITY_COLUMN] = depth
            row["ratio"][COMPRESSIBILITY_COLUMN] = None if depth is None else \
                depth / row["measured_m"]
        result["failures"].update(failures)
        result["compressibility_column"] = COMPRESSIBILITY_COLUMN
        result["models"].append(COMPRESSIBILITY_COLUMN)
        add_statistics(result)
    result["shots_file"] = {"path": shot_file.path, "comments": list(shot_file.comments),
                            "n": len(shot_file.shots)}
    result["tables"] = {"built": tables.built, "reused": tables.reused}
    return result


def summary(result):
    """The JSON document (``validation.json``, ``--json``): everything but the run's
    bookkeeping (tables built or reused)."""
    return {k: v for k, v in result.items() if k != "tables"}


# --- files ------------------------------------------------------------------------------------

def write_outputs(result, out, draw=True):
    """Write the JSON, CSV, report and (if ``draw``) the figures into ``out``; return the
    paths."""
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, content in (("validation.json", json.dumps(summary(result), indent=2) + "\n"),
                          ("predictions.csv", predictions_csv(result)),
                          ("report.md", report_markdown(result, figures=draw))):
        write_text_atomic(out / name, content)
        written.append(out / name)
    if draw:
        written += write_figures(result, out)
    return [str(p) for p in written]


def slug(name):
    return "".join(ch if ch.isalnum() else "_" for ch in name.lower()).strip("_")


def predictions_csv(result):
    """One row per shot: inputs, measured depth, every model's depth and ratio."""
    text = io.StringIO(newline="")
    writer = csv.writer(text, lineterminator="\n")
    models = result["models"]
    writer.writerow(["id", "V0_m_s", "fc_Pa", "rho_kg_m3", "measured_m", "flag"]
                    + [f"{slug(m)}_m" for m in models] + [f"{slug(m)}_ratio" for m in models])
    for row in result["shots"]:
        writer.writerow([row["id"], _g(row["V0_m_s"]), _g(row["fc_Pa"]), _g(row["rho_kg_m3"]),
                         _g(row["measured_m"]), row.get("flag") or ""]
                        + [_g(row["predicted_m"][m]) for m in models]
                        + [_g(row["ratio"][m]) for m in models])
    return text.getvalue()


def _g(value, digits=6):
    return "" if value is None else format(float(value), f".{digits}g")


def _f(value, spec):
    return "n/a" if value is None else format(value, spec)


def ranking(summary):
    """Model names by mean |ln ratio| (models without shots last)."""
    return sorted(summary, key=lambda m: (summary[m]["mean_abs_log_ratio"] is None,
                                          summary[m]["mean_abs_log_ratio"] or 0.0))


def verdict(summary, calibrations):
    """One sentence: the best calibrated cavex model against the empirical one on
    ``summary``."""
    calibrated = [c["column"] for c in calibrations
                  if summary.get(c["column"], {}).get("mean_abs_log_ratio") is not None]
    empirical = summary.get(EMPIRICAL, {}).get("mean_abs_log_ratio")
    if not calibrated or empirical is None:
        return None
    best = min(calibrated, key=lambda m: summary[m]["mean_abs_log_ratio"])
    ours = summary[best]["mean_abs_log_ratio"]
    relation = "no larger than" if ours <= empirical else "LARGER than"
    return (f"best calibrated cavex model: {best}, mean |ln ratio| {ours:.4f}, {relation} "
            f"{EMPIRICAL}'s {empirical:.4f}")


#: why a model is recommended, in words (:func:`recommendation`)
RECOMMENDATION_REASONS = {
    SPLIT: f"`{LI_CHEN}` at normal strength, f_c <= 100 MPa, `{CONCRETE}` above, each where "
           "it is the better on the development shots; no constant fitted by cavex",
    CONCRETE: "uncalibrated, every constant published, none fitted to shots"}


def recommendation(model, summary):
    """One sentence: why ``model`` (the recommended one) is recommended and how it does on
    ``summary``'s shots against :data:`EMPIRICAL` (None when it was not run)."""
    ours = summary.get(model, {}).get("mean_abs_log_ratio")
    if ours is None:
        return None
    why = RECOMMENDATION_REASONS.get(model, "uncalibrated, no constant fitted to the shots")
    sentence = (f"Recommended model: `{model}` ({why}; docs/validation.md); on these "
                f"{summary[model]['n']} shots its mean abs ln ratio is {ours:.4f}")
    empirical = summary.get(EMPIRICAL, {}).get("mean_abs_log_ratio")
    if empirical is not None:
        relation = "no larger than" if ours <= empirical else "LARGER than"
        sentence += (f", {relation} {EMPIRICAL}'s {empirical:.4f} (a formula fitted by its "
                     "authors to their own shots)")
    return sentence + "."


def _summary_table(summary):
    lines = ["| model | n | mean ratio | std ratio | mean abs ln ratio |",
             "|---|---:|---:|---:|---:|"]
    for m in ranking(summary):
        s = summary[m]
        lines.append(f"| {m} | {s['n']} | {_f(s['mean_ratio'], '.3f')} | "
                     f"{_f(s['std_ratio'], '.3f')} | {_f(s['mean_abs_log_ratio'], '.4f')} |")
    return lines


def compressibility(result, column):
    """FE over derived-dynamic depth per shot, same material: ``(min, median, max)`` or None.

    ``column`` is the FE column; its closed-form partner is ``derived-dynamic`` (uncalibrated
    mapping) or ``derived-dynamic calibrated`` (the compressibility column)."""
    partner = "derived-dynamic" if column == FE_MODEL else "derived-dynamic calibrated"
    ratios = [row["predicted_m"][column] / row["predicted_m"][partner]
              for row in result["shots"]
              if row["predicted_m"].get(column) and row["predicted_m"].get(partner)]
    if not ratios:
        return None
    return float(np.min(ratios)), float(np.median(ratios)), float(np.max(ratios))


def report_markdown(result, figures=True):
    """The validation report (markdown); every number is from ``result``; ``figures``: the
    figures were drawn (else the report says they were not)."""
    models, shots = result["models"], result["shots"]
    info = result["shots_file"]
    mapping = result["mapping"]
    lines = ["# Validation against measured penetration depths", ""]
    if result.get("command"):
        lines += [f"Generated by `{result['command']}`.", ""]
    lines += [f"Shots: `{info['path']}`, {info['n']} shots. Its header:", ""]
    lines += [f"> {c}" for c in info["comments"]] + [""]
    lines += ["## Models", "",
              "- `derived-quasi-static`, `derived-dynamic`, `paper`: cavex's incompressible "
              "closed forms with the penetration integrator (crater 4.5 r from the nose base);",
              f"- `{FE_MODEL}`: the FE-tabulated resistance, compressible (nu = "
              f"{mapping['nu']:g}) and finite-strain, one FE table per distinct target;",
              f"- `{CONCRETE}`: the concrete cavity-expansion model (docs/concrete.md): "
              "Mohr-Coulomb capped at 7 f_c, radial cracking, compaction to lock-up, every "
              "constant published (none fitted to shots), its own crater (Li and Chen 2003); "
              "it does not use the mapping below;",
              f"- `{LI_CHEN}`: S = 72 f_c^-0.5 (f_c in MPa), crater 0.707 + h/d calibres "
              "(Li and Chen 2003, fitted by them to published shots);",
              f"- `{SPLIT}` (recommended): `{LI_CHEN}` for f_c <= 100 MPa, `{CONCRETE}` "
              "above (no constant fitted; the split chosen on the development shots, "
              "docs/validation.md);",
              f"- `{EMPIRICAL}`: S = 82.6 f_c^-0.544 (f_c in MPa), crater of two calibres "
              "(Forrestal et al. 1994). Forrestal et al. fitted S to their own shots, so on "
              "their data it is not an out-of-sample prediction;",
              "- `<model> calibrated`: the model with the fitted mapping of a calibration file.",
              "",
              "Uncalibrated mapping (docs/validation.md): lam = "
              f"{mapping['lam']:.6g}, sigma_c = {mapping['strength_factor']:.6g} f_c, E = "
              f"{mapping['modulus_factor']:.6g} x ACI 318, nu = {mapping['nu']:g}.", ""]
    if result["calibrations"]:
        lines += ["## Calibrations", "",
                  "| column | file | fitted | lam | sigma_c / f_c | E / E_ACI | fitted on | "
                  "fit mean abs ln ratio |", "|---|---|---|---:|---:|---:|---|---:|"]
        for c in result["calibrations"]:
            m = c["mapping"]
            lines.append(f"| {c['column']} | `{c['file']}` | {', '.join(c['params'])} | "
                         f"{m['lam']:.6g} | {m['strength_factor']:.6g} | "
                         f"{m['modulus_factor']:.6g} | {len(c['shots'])} shots: "
                         f"{', '.join(c['shots'])} | "
                         f"{_f(c.get('mean_abs_log_ratio'), '.4f')} |")
        lines += ["", f"Held out (in no calibration's fit): {len(result['held_out'])} shots: "
                  f"{', '.join(result['held_out'])}.", "",
                  "## How each model does on the held-out shots", ""]
        lines += _summary_table(result["held_out_summary"]) + [""]
        sentence = verdict(result["held_out_summary"], result["calibrations"])
        if sentence:
            lines += [f"On the held-out shots the {sentence}.", ""]
    lines += ["## How each model does on all shots", ""]
    lines += _summary_table(result["summary"]) + [""]
    sentence = recommendation(result["recommended_model"], result["summary"])
    if sentence:
        lines += [sentence, ""]
    lines += ["Ratio = predicted / measured depth; std is the sample standard deviation; "
              "mean abs ln ratio is the mean of |ln(predicted/measured)|.", ""]
    lines += _regime_section(result)
    lines += _outlier_section(result)
    lines += ["## Compressibility: the FE table against the incompressible closed forms", ""]
    for column, what in ((FE_MODEL, "uncalibrated mapping"),
                         (result.get("compressibility_column"),
                          "the derived-dynamic calibration's mapping")):
        spread = compressibility(result, column) if column else None
        if spread:
            lines.append(f"- {what}: {FE_MODEL} depth / derived-dynamic depth, same material, "
                         f"min {spread[0]:.3f}, median {spread[1]:.3f}, max {spread[2]:.3f}.")
    lines += ["", "Same E, lam, tau and rho: the FE differs from the derived-dynamic closed form "
              "only by compressibility (nu) and finite strain (docs/validation.md).", ""]
    lines += ["## Per shot: predicted depth (mm) and predicted / measured", "",
              "| shot | V0 (m/s) | f_c (MPa) | measured (mm) | "
              + " | ".join(models) + " |",
              "|---|---:|---:|---:|" + "---:|" * len(models)]
    for row in shots:
        cells = [f"{row['predicted_m'][m] * 1e3:.1f} ({row['ratio'][m]:.3f})"
                 if row["predicted_m"][m] is not None else "failed" for m in models]
        lines.append(f"| {table_cell(row['id'])} | {row['V0_m_s']:g} | {row['fc_Pa'] / 1e6:g} | "
                     f"{row['measured_m'] * 1e3:g} | " + " | ".join(cells) + " |")
    lines += ["", "![predicted against measured (small multiples: the uncalibrated models and "
              "the empirical formula, then each calibrated model with its fitted shots filled "
              "and its held-out shots open)](predicted_vs_measured.png)", "",
              "![ratio against striking velocity](ratio_vs_velocity.png)", "",
              "![the recommended model, the concrete model and the empirical formulas, "
              "predicted against measured by regime (open: flagged non-rigid)](by_regime.png)",
              "",
              "![ln(predicted/measured) against striking velocity and f_c](residuals.png)",
              ""] if figures \
        else ["", "(figures not drawn: `--no-figures`)", ""]
    if result["failures"]:
        lines += ["## Failures", ""]
        for model, items in result["failures"].items():
            lines += [f"- {model}, shot {i}: {reason}" for i, reason in items.items()]
        lines.append("")
    return "\n".join(lines)


def _regime_section(result):
    """Mean |ln ratio| / bias per regime (docs/validation.md, "Regimes")."""
    regimes = result.get("regimes", {})
    if not regimes:
        return []
    flags = [row.get("flag") for row in result["shots"]]
    names = list(regimes)
    first = result["models"][0]
    lines = ["## By regime", "",
             "Mean |ln(predicted/measured)| / bias (mean ln ratio; positive: too deep), n shots "
             "per regime. A shot's regime follows from its inputs "
             "(`cavex.verification.validation.regimes`).", "",
             "| model | " + " | ".join(f"{REGIME_TITLES[n]} ({regimes[n][first]['n']})"
                                       for n in names) + " |",
             "|---|" + "---:|" * len(names)]
    for m in result["models"]:
        cells = []
        for n in names:
            s = regimes[n][m]
            cells.append("n/a" if s["mean_abs_log_ratio"] is None else
                         f"{s['mean_abs_log_ratio']:.3f} / {s['mean_log_ratio']:+.3f}"
                         + (f" ({s['n']})" if s["n"] != regimes[n][first]["n"] else ""))
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    flagged = sum(1 for f in flags if f == NON_RIGID)
    if any(f is not None for f in flags):
        lines += ["", f"Flagged non-rigid: {flagged} of {len(flags)} shots (the concrete model's "
                  "mean nose pressure at impact above the projectile's listed yield strength; "
                  "kept in every table)."]
    return lines + [""]


def table_cell(text):
    """``text`` as one markdown table cell: ``|`` escaped, line breaks and other control
    characters as spaces (a shot id may hold any character)."""
    return "".join(" " if ch.isspace() or not ch.isprintable() else ch
                   for ch in str(text)).replace("|", "\\|")


def _outlier_section(result):
    """Report lines: the flagged shots (every model off by more than the factor), each with
    its measured depth and the range of the models' ratios, and the statistics without them."""
    flagged, factor = result["outliers"]["shots"], result["outliers"]["factor"]
    lines = ["## Outliers: shots every model misses by more than a factor "
             f"{factor:g}", ""]
    if not flagged:
        return lines + ["None.", ""]
    rows = {row["id"]: row for row in result["shots"]}
    lines += [f"{len(flagged)} shot(s), kept in every statistic above (flagged, not dropped):",
              "", "| shot | V0 (m/s) | measured (mm) | predicted / measured, every model |",
              "|---|---:|---:|---|"]
    for shot in flagged:
        ratios = [r for r in rows[shot]["ratio"].values() if r is not None]
        lines.append(f"| {table_cell(shot)} | {rows[shot]['V0_m_s']:g} | "
                     f"{rows[shot]['measured_m'] * 1e3:g} | {min(ratios):.3g} to "
                     f"{max(ratios):.3g} |")
    lines += ["", "Without them:", ""] + _summary_table(result["summary_without_outliers"])
    return lines + [""]


FIGURES = ("predicted_vs_measured.png", "ratio_vs_velocity.png")
REGIME_FIGURES = ("by_regime.png", "residuals.png")


def write_figures(result, out):
    """Predicted against measured (log-log, 1:1, +-20 %) and ratio against striking velocity,
    each as small multiples (:func:`_panels`): the cavex models as they are beside the
    empirical formula, then one panel per calibrated model with its fitted shots filled and
    its held-out shots open. One legend below the panels, off the data."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = _panels(result)
    measured = np.array([row["measured_m"] for row in result["shots"]])
    velocity = np.array([row["V0_m_s"] for row in result["shots"]])
    columns = min(3, len(panels))
    rows = -(-len(panels) // columns)
    written = []
    for name, title in zip(FIGURES, ("Predicted against measured penetration depth",
                                     "Ratio predicted / measured against striking velocity"),
                           strict=True):
        predicted = name.startswith("predicted")
        fig, axes = plt.subplots(rows, columns, figsize=(max(4.6 * columns, 8.0), 4.2 * rows + 1.2),
                                 squeeze=False, sharex=True, sharey=True)
        for ax, (heading, models) in zip(axes.flat, panels, strict=False):
            for model in models:
                _draw_model(ax, result, model, measured, None if predicted else velocity)
            _frame(ax, measured, predicted)
            ax.set_title(heading, fontsize=9)
        for ax in list(axes.flat)[len(panels):]:
            ax.set_visible(False)
        handles, labels = axes.flat[0].get_legend_handles_labels()
        if len(panels) > 1:
            handles += _fitted_keys()
            labels += ["calibrated: fitted shot", "calibrated: held-out shot"]
        fig.suptitle(title, fontsize=11)
        fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
        fig.tight_layout(rect=(0, 0.1 if rows == 1 else 0.06, 1, 0.97))
        written.append(save_figure(fig, out / name, dpi=110))
    return written + write_regime_figures(result, out, plt)


def regime_models(result):
    """The models of the regime figures: the concrete model, the empirical formulas and, drawn
    last (on top of the one it equals in a regime), the recommended one (those that ran, each
    once)."""
    chosen = (CONCRETE, LI_CHEN, EMPIRICAL, result["recommended_model"])
    return [m for k, m in enumerate(chosen) if m in result["models"] and m not in chosen[k + 1:]]


def write_regime_figures(result, out, plt):
    """``by_regime.png``: predicted against measured (log-log, 1:1, +-20 %) for the
    :func:`regime_models`, one panel per regime other than ``all``, shots flagged non-rigid
    open; ``residuals.png``: ``ln(predicted/measured)`` against ``V0`` and ``f_c``. One legend
    below the panels."""
    models = regime_models(result)
    rows = result["shots"]
    if not models or not rows:
        return []
    measured = np.array([row["measured_m"] for row in rows])
    velocity = np.array([row["V0_m_s"] for row in rows])
    strength = np.array([row["fc_Pa"] for row in rows]) / 1e6
    flagged = np.array([row.get("flag") == NON_RIGID for row in rows])
    names = [n for n in REGIMES if n != "all"]
    member = {n: np.array([REGIMES[n](r["fc_Pa"], r["V0_m_s"], r.get("flag")) for r in rows])
              for n in names}
    names = [n for n in names if member[n].any()]

    def depths(model):
        return np.array([np.nan if row["predicted_m"][model] is None
                         else row["predicted_m"][model] for row in rows])

    written = []
    fig, axes = plt.subplots(1, len(names), figsize=(4.4 * len(names), 5.0), squeeze=False)
    for ax, name in zip(axes.flat, names, strict=True):
        chosen = member[name]
        for model in models:
            _scatter(ax, measured[chosen] * 1e3, depths(model)[chosen] * 1e3, flagged[chosen],
                     model)
        _frame(ax, measured[chosen], True)
        ax.set_title(f"{REGIME_TITLES[name]} ({int(chosen.sum())} shots)", fontsize=9)
    _legend_below(fig, axes.flat[0], flagged.any())
    fig.suptitle("Predicted against measured depth, by regime", fontsize=11)
    fig.tight_layout(rect=(0, 0.12, 1, 0.95))
    written.append(save_figure(fig, out / REGIME_FIGURES[0], dpi=110))

    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.8), sharey=True)
    for ax, x, label, scale in ((axes[0], velocity, "striking velocity V0 (m/s)", "linear"),
                                (axes[1], strength, "f_c (MPa)", "log")):
        for model in models:
            _scatter(ax, x, np.log(depths(model) / measured), flagged, model)
        ax.axhline(0.0, color="k", linewidth=1)
        ax.axhspan(math.log(1 - BAND), math.log(1 + BAND), color="grey", alpha=0.2,
                   label="+-20 %")
        ax.set(xlabel=label, xscale=scale)
        ax.autoscale_view()
        if scale == "log":
            _plain_log_ticks(ax.xaxis)
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("ln(predicted / measured)")
    _legend_below(fig, axes[0], flagged.any())
    fig.suptitle("Residuals against striking velocity and concrete strength", fontsize=11)
    fig.tight_layout(rect=(0, 0.12, 1, 0.95))
    written.append(save_figure(fig, out / REGIME_FIGURES[1], dpi=110))
    return written


def _plain_log_ticks(axis):
    """Ticks of a log axis written as plain numbers: decades (1, 10, 100), and 2 and 5 times
    them where the axis spans less than two decades; minor ticks unlabelled (their default
    labels overprint)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    lo, hi = sorted(axis.get_view_interval())
    if lo > 0.0 and hi / lo < 100.0:
        axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    axis.set_minor_formatter(NullFormatter())


def _scatter(ax, x, y, flagged, model):
    """One model's points, the shots flagged non-rigid open."""
    base = next(b for b in MODELS if model.startswith(b))
    style = {"marker": MARKERS[base], "color": COLOURS[base], "linestyle": "none",
             "markersize": 5, "alpha": 0.8}
    ax.plot(x[~flagged], y[~flagged], label=model, **style)
    ax.plot(x[flagged], y[flagged], markerfacecolor="white", **style)


def _legend_below(fig, ax, flagged):
    handles, labels = ax.get_legend_handles_labels()
    if flagged:
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], marker="o", color="0.3", markerfacecolor="white",
                              linestyle="none"))
        labels.append("open: flagged non-rigid")
    fig.legend(handles, labels, loc="lower center", ncol=min(6, len(labels)), fontsize=8,
               frameon=False)


def _fitted_keys():
    """Legend keys for a calibrated model's fitted (filled) and held-out (open) shots."""
    from matplotlib.lines import Line2D

    style = {"marker": "o", "color": "0.3", "linestyle": "none", "markersize": 7}
    return [Line2D([], [], **style),
            Line2D([], [], markerfacecolor="white", markeredgewidth=1.5, **style)]


def _panels(result):
    """``[(title, models)]``: the cavex models as they are with the empirical formula, then
    one panel per calibrated model."""
    plain = [m for m in result["models"] if m in MODELS]
    return [("cavex models (uncalibrated), empirical formula", plain),
            *((m, [m]) for m in result["models"] if m not in MODELS)]


def fitted_ids(result, model):
    """The ids of the shots ``model`` (a calibrated column) was fitted to (the compressibility
    column uses the derived-dynamic calibration's mapping, hence its shots)."""
    for calibration in result["calibrations"]:
        if calibration["column"] == model or (
                model == result.get("compressibility_column")
                and calibration["model"] == "derived-dynamic"):
            return set(calibration["shots"])
    return set()


MARKERS = dict(zip(MODELS, ["o", "s", "^", "D", "v", "X", "h", "*"], strict=True))
COLOURS = dict(zip(MODELS, ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple",
                            "tab:brown", "tab:pink", "black"], strict=True))


def _draw_model(ax, result, model, measured, velocity):
    """One model's points: predicted depth (mm) against measured (``velocity`` None), else the
    ratio predicted/measured against ``velocity``; a calibrated model's fitted shots filled
    and its held-out shots open."""
    base = next(b for b in MODELS if model.startswith(b))
    y = np.array([np.nan if row["predicted_m"][model] is None else row["predicted_m"][model]
                  for row in result["shots"]])
    x = measured * 1e3 if velocity is None else velocity
    y = y * 1e3 if velocity is None else y / measured
    marker = "P" if model == COMPRESSIBILITY_COLUMN else MARKERS[base]
    style = {"marker": marker, "color": COLOURS[base], "linestyle": "none",
             "markersize": 10 if base == EMPIRICAL else 7}
    if model in MODELS:
        ax.plot(x, y, label=model, markerfacecolor=COLOURS[base], **style)
        return
    fitted = np.array([row["id"] in fitted_ids(result, model) for row in result["shots"]])
    ax.plot(x[fitted], y[fitted], **style)
    ax.plot(x[~fitted], y[~fitted], markerfacecolor="white", markeredgewidth=1.5, **style)


def _frame(ax, measured, predicted):
    """The 1:1 line and +-20 % band, scales and labels of one panel."""
    if predicted:
        lo, hi = 0.5 * measured.min() * 1e3, 2.0 * measured.max() * 1e3
        line = np.array([lo, hi])
        ax.plot(line, line, "k-", linewidth=1, label="1:1")
        ax.fill_between(line, line * (1 - BAND), line * (1 + BAND), color="grey", alpha=0.2,
                        label="+-20 %")
        ax.set(xscale="log", yscale="log", xlim=(lo, hi), ylim=(lo / 2, hi * 1.5),
               xlabel="measured depth (mm)", ylabel="predicted depth (mm)")
        _plain_log_ticks(ax.xaxis)
        _plain_log_ticks(ax.yaxis)
    else:
        ax.axhline(1.0, color="k", linewidth=1)
        ax.axhspan(1 - BAND, 1 + BAND, color="grey", alpha=0.2, label="+-20 %")
        ax.set(xlabel="striking velocity (m/s)", ylabel="predicted / measured depth")
    ax.grid(alpha=0.3, which="both")


def _save(fig, path, plt):
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)


def text(result, seconds, written):
    """What ``cavex validate`` prints without ``--json``."""
    lines = [f"{result['shots_file']['n']} shots from {result['shots_file']['path']}; "
             f"FE tables built {result['tables']['built']}, reused "
             f"{result['tables']['reused']}; {seconds:.1f} s", ""]
    fitted = bool(result["calibrations"])
    parts = [("all shots" + (" (calibrated models: in-sample on their fitted shots)" if fitted
                             else ""), result["summary"])]
    flagged = result["outliers"]["shots"]
    if flagged:
        shown = ", ".join(flagged[:10]) + (", ..." if len(flagged) > 10 else "")
        parts.append((f"without the {len(flagged)} outlier(s), every model off by more than a "
                      f"factor {result['outliers']['factor']:g} ({shown}; see report.md)",
                      result["summary_without_outliers"]))
    if result.get("held_out"):
        parts.insert(0, (f"held-out shots ({len(result['held_out'])})",
                         result["held_out_summary"]))
    elif fitted:
        lines += ["no held-out shot: every shot was fitted by the calibration(s), so their rows "
                  "below are in-sample (calibrate on a subset with --ids)", ""]
    for title, summary in parts:
        lines += [f"{title}:", f"{'model':<40} {'n':>3} {'mean ratio':>10} {'std':>7} "
                  f"{'mean|ln r|':>10}"]
        for m in ranking(summary):
            s = summary[m]
            lines.append(f"{m:<40} {s['n']:>3} {_f(s['mean_ratio'], '10.3f')} "
                         f"{_f(s['std_ratio'], '7.3f')} {_f(s['mean_abs_log_ratio'], '10.4f')}")
        lines.append("")
    sentence = verdict(result.get("held_out_summary", {}), result["calibrations"])
    if sentence:
        lines += [f"held-out: {sentence}", ""]
    if result["failures"]:
        count = sum(len(v) for v in result["failures"].values())
        lines += [f"{count} prediction(s) failed (see report.md)", ""]
    lines.append("wrote   " + ", ".join(written))
    return "\n".join(lines)


def command_line(shots_path, calibration_paths, out_dir, models=None):
    """The ``cavex validate`` command that makes these outputs (the report's provenance)."""
    words = ["cavex", "validate", "--shots", str(shots_path)]
    if models:
        words += ["--models", *models]
    if calibration_paths:
        words += ["--calibration", *map(str, calibration_paths)]
    return " ".join(shlex.quote(w) for w in [*words, "--out", str(out_dir)])

