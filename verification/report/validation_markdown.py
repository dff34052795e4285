"""The markdown report of ``cavex validate`` (``report.md``) and the sentences it shares with the
command's text: the models ranked by mean ``|ln(predicted/measured)|``, the verdict on the
held-out shots, the recommendation, the regimes, the outliers, the compressibility spread
(FE over derived-dynamic depth) and every shot's predictions. Every number is read from the
validation's result (:func:`cavex.verification.validation.predict.validate`), never recomputed
from the shots."""

import numpy as np

from cavex.analytic.models import get, models
from cavex.verification.validation.predict import EMPIRICAL, FE_MODEL, FE_PARTNER
from cavex.verification.validation.regimes import NON_RIGID, REGIME_TITLES


def number_or_na(value, spec):
    """``value`` formatted by ``spec``, or "n/a" when there is none."""
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


def model_lines(mapping):
    """The report's list of the models, in the registry's words (``report_words``; the models
    that share words share a line; ``nu``: the mapping's Poisson's ratio)."""
    groups = []  # [labels, words, recommended]
    for model in models(predicts_shots=True):
        words = (model.report_words or model.help or "a registered model").format(
            nu=mapping["nu"], option=model.option)
        if groups and groups[-1][1] == words:
            groups[-1][0].extend(model.labels())
        else:
            groups.append([list(model.labels()), words, model.recommended])
    return [f"- {', '.join(f'`{label}`' for label in labels)}"
            + (" (recommended)" if recommended else "") + f": {words};"
            for labels, words, recommended in groups]


def recommendation(model, summary):
    """One sentence: why ``model`` (the recommended one) is recommended and how it does on
    ``summary``'s shots against :data:`EMPIRICAL` (None when it was not run)."""
    ours = summary.get(model, {}).get("mean_abs_log_ratio")
    if ours is None:
        return None
    why = get(model).recommendation_reason
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
        lines.append(f"| {m} | {s['n']} | {number_or_na(s['mean_ratio'], '.3f')} | "
                     f"{number_or_na(s['std_ratio'], '.3f')} | "
                     f"{number_or_na(s['mean_abs_log_ratio'], '.4f')} |")
    return lines


def compressibility(result, column):
    """FE over derived-dynamic depth per shot, same material: ``(min, median, max)`` or None.

    ``column`` is the FE column; its closed-form partner is ``derived-dynamic`` (uncalibrated
    mapping) or ``derived-dynamic calibrated`` (the compressibility column)."""
    partner = FE_PARTNER if column == FE_MODEL else f"{FE_PARTNER} calibrated"
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
              *model_lines(mapping),
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
                         f"{number_or_na(c.get('mean_abs_log_ratio'), '.4f')} |")
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
    lines += cross_validation_section(result)
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
              "", *(["![cross-validated mean |ln ratio| and bias by regime and per fold left "
                     "out](cross_validation.png)", ""] if result.get("cross_validation")
                    else [])] if figures \
        else ["", "(figures not drawn: `--no-figures`)", ""]
    if result["failures"]:
        lines += ["## Failures", ""]
        for model, items in result["failures"].items():
            lines += [f"- {model}, shot {i}: {reason}" for i, reason in items.items()]
        lines.append("")
    return "\n".join(lines)


def _regime_header(regimes, names, first):
    """The two header lines of a table of models by regime: each regime's title with the
    number of shots of the model ``first`` in it."""
    return ["| model | " + " | ".join(f"{REGIME_TITLES[n]} ({regimes[n][first]['n']})"
                                     for n in names) + " |",
            "|---|" + "---:|" * len(names)]


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
             *_regime_header(regimes, names, first)]
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


def _cell(stats, plain=None):
    """``mean |ln| / bias`` of ``stats`` (``n/a`` without shots), with ``(plain ...)``."""
    if stats is None or stats["mean_abs_log_ratio"] is None:
        return "n/a"
    text = f"{stats['mean_abs_log_ratio']:.3f} / {stats['mean_log_ratio']:+.3f}"
    if plain is not None and plain.get("mean_abs_log_ratio") is not None:
        text += f" ({plain['mean_abs_log_ratio']:.3f})"
    return text


def cross_validation_section(result):
    """The report's "Cross-validation" section (docs/validation.md): what each model chooses
    on shots, the reference folds by regime beside the plain scores, the kinds of shot left
    out by regime, each reference left out and each fold's choices."""
    cv = result.get("cross_validation")
    if not cv:
        return []
    columns = result["models"]
    chosen = cv["chosen_on_shots"]
    lines = ["## Cross-validation", "",
             "Each choice a model makes on shots is made again without each fold (on the other "
             "shots given) and the fold is predicted with it (`--cross-validate "
             + " ".join(cv["families"]) + "`; docs/validation.md \"Cross-validation\"). "
             "Mean |ln(predicted/measured)| / bias over the shots left out.", ""]
    for column in columns:
        what = chosen[column]
        lines.append(f"- `{column}`: " + (f"chooses {what}" + (
            f"; on all these shots: '{cv['choice_on_all_shots'][column]}'"
            if column in cv["choice_on_all_shots"] else "") if what else
            "nothing chosen on shots: predicted as it is, its cross-validated score equals "
            "its plain score"))
    lines.append("")
    plain = result["regimes"]
    if "regimes" in cv:
        names = list(cv["regimes"])
        first = columns[0]
        lines += ["### Leaving out one reference at a time, by regime", "",
                  "Every shot predicted by the choices made without its reference; in "
                  "brackets the plain mean |ln ratio| (each model as it runs, its choices "
                  "those of the registry).", "",
                  *_regime_header(cv["regimes"], names, first)]
        for m in columns:
            lines.append(f"| {m} | " + " | ".join(
                _cell(cv["regimes"][n][m], plain.get(n, {}).get(m)) for n in names) + " |")
        lines.append("")
    kinds = {f["name"]: f for f in cv["folds"] if f["family"] != "reference"}
    if kinds:
        lines += ["### Leaving out one kind of shot, by regime", "",
                  "| kind left out | regime (n) | " + " | ".join(columns) + " |",
                  "|---|---|" + "---:|" * len(columns)]
        for name, fold in kinds.items():
            for regime, stats in fold["regimes"].items():
                n = stats[columns[0]]["n"] if stats else 0
                lines.append(f"| {table_cell(name)} | {REGIME_TITLES[regime]} ({n}) | "
                             + " | ".join(_cell(stats[m]) for m in columns) + " |")
        lines.append("")
    refs = {f["name"]: f for f in cv["folds"] if f["family"] == "reference"}
    if refs:
        lines += ["### Each reference left out", "",
                  "| reference left out | n | " + " | ".join(columns) + " |",
                  "|---|---:|" + "---:|" * len(columns)]
        for name, fold in refs.items():
            lines.append(f"| {table_cell(name.removeprefix('reference '))} | {fold['n']} | "
                         + " | ".join(_cell(fold["models"][m]) for m in columns) + " |")
        lines.append("")
    choosing = [c for c in columns if chosen[c]]
    if choosing:
        lines += ["### The choice made without each fold", "",
                  "| fold left out | " + " | ".join(choosing) + " |",
                  "|---|" + "---|" * len(choosing)]
        for fold in cv["folds"]:
            lines.append(f"| {table_cell(fold['name'])} | " + " | ".join(
                table_cell(fold["models"][c]["choice"]) for c in choosing) + " |")
        lines.append("")
    return lines


def cross_validation_lines(cv):
    """The command's text: the cross-validated mean |ln ratio| / bias per model, over the
    reference folds by regime and over each kind of shot left out."""
    lines = ["cross-validated (" + " ".join(cv["families"]) + "), mean |ln r| / bias:"]
    if "regimes" in cv:
        names = list(cv["regimes"])
        lines.append("leaving out each reference: " + ", ".join(REGIME_TITLES[n]
                                                                 for n in names))
        for m, _ in cv["regimes"][names[0]].items():
            lines.append(f"  {m:<38} " + "  ".join(f"{_cell(cv['regimes'][n][m]):>16}"
                                                   for n in names))
    for fold in cv["folds"]:
        if fold["family"] == "reference":
            continue
        lines.append(f"leaving out {fold['name']} ({fold['n']} shots):")
        for m, stats in fold["models"].items():
            lines.append(f"  {m:<38} {_cell(stats):>16}"
                         + (f"  chose {stats['choice']}" if stats["choice"] else ""))
    return lines
