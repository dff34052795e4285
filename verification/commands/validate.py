"""``cavex validate``: predictions against measurements, written as JSON, CSV, a
markdown report and figures.

Files (in ``--out``, default ``results/validation``): ``validation.json`` (what ``--json``
prints), ``predictions.csv``, ``report.md`` (:mod:`cavex.verification.report.validation_markdown`),
``predicted_vs_measured.png``, ``ratio_vs_velocity.png``, ``by_regime.png``, ``residuals.png``
(:mod:`cavex.verification.report.validation_figures`) and ``tables/`` (a copy of the FE tables
the run used, one per distinct target; they are built once into the shared cache,
:mod:`cavex.verification.fedata.table_cache`, and reused by every later run into any folder).
Depths and statistics carry 6 significant digits (``validation.DEPTH_DIGITS``); the statistics
are computed from the written depths, so every printed number is a function of the stored ones,
and no wall time is written, so a rerun gives the same files.
"""

import csv
import io
import os
import shlex
import sys
import time

from cavex.analytic.models import labels
from cavex.errors import CavexInputError
from cavex.verification.commands.options import add_erosion_option
from cavex.verification.commands.shared_options import (
    add_figures_option,
    add_parallel_options,
    scheduler_of,
)
from cavex.verification.fedata.runner import check_execution
from cavex.verification.output.files import write_text_atomic
from cavex.verification.output.json_document import json_text
from cavex.verification.output.paths import check_output_dir, write_staged
from cavex.verification.report.validation_markdown import (
    cross_validation_lines,
    number_or_na,
    ranking,
    report_markdown,
    verdict,
)
from cavex.verification.validation.predict import (
    FE_MODEL,
    FE_PARTNER,
    TableCache,
    add_statistics,
    predictions,
    validate,
)
from cavex.verification.validation.shots import read_shots

HELP = "predicted against measured penetration depths (docs/validation.md)"
DEFAULT_OUT = "results/validation"
COMPRESSIBILITY_COLUMN = f"{FE_MODEL}, {FE_PARTNER} calibration"
#: the run's bookkeeping in the result, not in ``validation.json`` (:func:`summary`): the FE
#: tables built or reused, the wall time (s), the files written
BOOKKEEPING = ("tables", "seconds", "outputs")


def add_arguments(parser):
    """The options of ``cavex validate``."""
    parser.add_argument("--shots", required=True, help="shot file (CSV)")
    parser.add_argument("--calibration", nargs="+", action="extend",
                        help="calibration TOML file(s) from `cavex calibrate` (default: "
                        "none, the uncalibrated models only)")
    parser.add_argument("--models", nargs="+", action="extend", metavar="NAME",
                        help="run only these models: " + ", ".join(labels(predicts_shots=True))
                        + " (default: all; calibrations add their columns)")
    add_erosion_option(parser)
    parser.add_argument("--cross-validate", nargs="*", metavar="FOLD",
                        help="also predict each fold with the choices its models make on the "
                        "other shots (options, splits, calibrations): FOLD of reference (each "
                        "reference, column source, left out), calibre (<= 13 mm), yield "
                        "(projectile yield < 1 GPa), velocity (V0 > 1000 m/s); given without FOLD: "
                        "all; default: no cross-validation (docs/validation.md "
                        "\"Cross-validation\")")
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.add_argument("--out", help="output folder (default results/validation)")
    add_figures_option(parser, "validation.json, predictions.csv and report.md")
    add_parallel_options(parser)


def run(args, target, projectile):
    """Check every input, run :func:`job`, write the files (every file or none, also on Ctrl-C
    or kill); return the result with the wall time (``seconds``) and the files written
    (``outputs``)."""
    from cavex.verification.validation.calibration import read_calibration

    shots_path, calibration_paths = args.shots, args.calibration
    workers, scheduler = args.workers, scheduler_of(args)
    models = check_models(args.models)
    shot_file = read_shots(shots_path)
    folds = None
    if args.cross_validate is not None:
        from cavex.verification.validation.cross_validation import check_folds

        folds = check_folds(args.cross_validate, shot_file.shots)
    calibrations = [read_calibration(p) for p in calibration_paths or ()]
    columns = [c.column for c in calibrations]
    repeated = sorted({c for c in columns if columns.count(c) > 1})
    if repeated:
        raise CavexInputError(f"two calibrations of the same model ({', '.join(repeated)}); "
                              "give one per model")
    out = check_output_dir(DEFAULT_OUT if args.out is None else args.out, "out")
    check_execution(workers, scheduler)
    from cavex.verification.fedata.runner import show_progress

    # one cache for the estimate and the run: the entries the estimate checked are not read
    # again; the tables go into --out/tables/ with the other files, in the staged write
    tables = TableCache(workers=workers, scheduler=scheduler,
                        progress=show_progress(args.progress))
    size = estimate(shot_file.shots, calibrations, tables, workers, models, args.erosion,
                    folds)
    print(f"cavex: validate {size}", file=sys.stderr, flush=True)
    began = time.monotonic()
    result = job(shot_file, calibrations, workers=workers, scheduler=scheduler,
                 progress=args.progress, models=models, tables=tables, erosion=args.erosion,
                 cross_validate=folds)
    seconds = time.monotonic() - began
    result["command"] = command_line(shots_path, calibration_paths, out, args.models,
                                     args.erosion, args.cross_validate)
    written = write_staged(out, lambda stage: write_outputs(result, stage, draw=args.figures),
                           replaces=outputs())
    result["seconds"], result["outputs"] = seconds, written
    return result


def check_models(models):
    """The ``--models`` labels (None: all), checked
    (:func:`cavex.verification.validation.predict.check_models`)."""
    from cavex.verification.validation.predict import check_models as check

    return check(models)


def columns_of(calibrations, models=None):
    """Every column :func:`job` fills: the models (default all), the calibrated ones and, with
    a derived-dynamic calibration and the FE-table model among the models run,
    :data:`COMPRESSIBILITY_COLUMN`."""
    from cavex.verification.validation.predict import validation_columns

    columns = validation_columns(calibrations, models=models)
    dynamic = compressibility_calibrations(calibrations, models)
    if dynamic:
        columns[COMPRESSIBILITY_COLUMN] = (FE_MODEL, dynamic[0].mapping)
    return columns


def compressibility_calibrations(calibrations, models=None):
    """The derived-dynamic calibrations whose mapping :data:`COMPRESSIBILITY_COLUMN` flies the
    FE tables with: none where ``--models`` leaves the FE-table model out (the column built
    17 FE tables for a run of derived-dynamic alone)."""
    if models is not None and FE_MODEL not in models:
        return []
    return [c for c in calibrations if c.model == FE_PARTNER]


def estimate(shots, calibrations, tables, workers, models=None, erosion="none",
             cross_validate=None):
    """The run's size and time, measured by a short probe on ``shots``
    (:func:`cavex.verification.validation.run_estimate.run_estimate`); ``tables``: a
    :class:`TableCache` (None: a new one); ``erosion``: the name of the run's erosion law;
    ``cross_validate``: the fold families (every option of the concrete model is then run)."""
    from cavex.analytic.penetration.erosion import law_named
    from cavex.verification.validation.run_estimate import run_estimate

    workers = workers or os.cpu_count() or 1
    return run_estimate(shots, columns_of(calibrations, models),
                        TableCache() if tables is None else tables, workers, law_named(erosion),
                        every_option=cross_validate is not None)


def job(shot_file, calibrations=(), *, tables_dir=None, workers=None, scheduler=None,
        progress=None, models=None, tables=None, erosion="none", cross_validate=None):
    """:func:`cavex.verification.validation.predict.validate` plus the compressibility column and
    the shots file's description; ``tables``: the :class:`TableCache` to use (default a new
    one copying its tables into ``tables_dir``); ``erosion``: a name of
    :data:`cavex.analytic.penetration.erosion.CHOICES` ("none": rigid); ``cross_validate``:
    the fold families, checked (:func:`cavex.verification.validation.cross_validation.
    check_folds`; None: no cross-validation)."""
    from cavex.analytic.penetration.erosion import law_named
    from cavex.verification.fedata.runner import show_progress
    from cavex.verification.validation.cross_validation import fold_validator

    law = law_named(erosion)
    if tables is None:
        tables = TableCache(tables_dir, workers=workers, scheduler=scheduler,
                            progress=show_progress(progress))
    folds = None if cross_validate is None else fold_validator(cross_validate, law)
    result = validate(shot_file.shots, calibrations=calibrations, tables=tables,
                      progress=progress, models=models, erosion=law, cross_validate=folds)
    dynamic = compressibility_calibrations(calibrations, models)
    if dynamic:
        columns = {COMPRESSIBILITY_COLUMN: (FE_MODEL, dynamic[0].mapping)}
        depths, failures = predictions(shot_file.shots, columns, tables, progress, law)
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
    # ``cache``: the run's tables, written by :func:`write_outputs` into ``tables/``
    result["tables"] = {"built": tables.built, "reused": tables.reused, "cache": tables}
    return result


def summary(result):
    """The JSON document (``validation.json``, ``--json``): everything but the run's
    :data:`BOOKKEEPING` (tables built or reused, wall time, files written)."""
    return {k: v for k, v in result.items() if k not in BOOKKEEPING}


# --- files ------------------------------------------------------------------------------------

def outputs():
    """Every file ``cavex validate`` can write at the top of ``--out`` (a rerun replaces them
    all; ``tables/`` holds FE tables by their keys and is merged)."""
    from cavex.verification.report.validation_figures import (
        CROSS_VALIDATION_FIGURE,
        FIGURES,
        REGIME_FIGURES,
    )

    return ("validation.json", "predictions.csv", "report.md", *FIGURES, *REGIME_FIGURES,
            CROSS_VALIDATION_FIGURE)


def write_outputs(result, out, draw=True):
    """Write the JSON, CSV, report, (if ``draw``) the figures and the FE tables the run used
    (``tables/``) into ``out``; return the paths."""
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, content in (("validation.json", json_text(summary(result)) + "\n"),
                          ("predictions.csv", predictions_csv(result)),
                          ("report.md", report_markdown(result, figures=draw))):
        write_text_atomic(out / name, content)
        written.append(out / name)
    if draw:
        from cavex.verification.report.validation_figures import write_figures

        written += write_figures(result, out)
    cache = result.get("tables", {}).get("cache")
    if cache is not None:
        written += cache.write_used(out / "tables")
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


def text(result):
    """What ``cavex validate`` prints without ``--json``: the statistics on the held-out
    shots, all shots and without the outliers, the verdict, the failures, the files written
    (``result["outputs"]``) and the wall time (``result["seconds"]``)."""
    lines = [f"{result['shots_file']['n']} shots from {result['shots_file']['path']}; "
             f"FE tables built {result['tables']['built']}, reused "
             f"{result['tables']['reused']}; {result['seconds']:.1f} s", ""]
    if result.get("erosion"):
        lines[-1:-1] = [f"nose erosion: {result['erosion']} in every model that flies the "
                        "integrator (the empirical formulas are rigid; docs/erosion.md)"]
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
            lines.append(f"{m:<40} {s['n']:>3} {number_or_na(s['mean_ratio'], '10.3f')} "
                         f"{number_or_na(s['std_ratio'], '7.3f')} "
                         f"{number_or_na(s['mean_abs_log_ratio'], '10.4f')}")
        lines.append("")
    sentence = verdict(result.get("held_out_summary", {}), result["calibrations"])
    if sentence:
        lines += [f"held-out: {sentence}", ""]
    if result.get("cross_validation"):
        lines += cross_validation_lines(result["cross_validation"]) + [""]
    if result["failures"]:
        count = sum(len(v) for v in result["failures"].values())
        lines += [f"{count} prediction(s) failed (see report.md)", ""]
    lines.append("wrote   " + ", ".join(result["outputs"]))
    return "\n".join(lines)


def command_line(shots_path, calibration_paths, out_dir, models=None, erosion="none",
                 cross_validate=None):
    """The ``cavex validate`` command that makes these outputs (the report's provenance)."""
    words = ["cavex", "validate", "--shots", str(shots_path)]
    if models:
        words += ["--models", *models]
    if erosion != "none":
        words += ["--erosion", erosion]
    if cross_validate is not None:
        words += ["--cross-validate", *cross_validate]
    if calibration_paths:
        words += ["--calibration", *map(str, calibration_paths)]
    return " ".join(shlex.quote(w) for w in [*words, "--out", str(out_dir)])
