"""``cavex calibrate``: fit a model's free material parameters to measured depths, written as a
calibration file (:mod:`cavex.verification.validation.calibration`, docs/validation.md)."""

import shlex
import sys
import time
from pathlib import Path

from cavex.verification.commands.options import add_resistance_options
from cavex.verification.commands.shared_options import add_parallel_options, scheduler_of

HELP = "fit material parameters to measured penetration depths (docs/validation.md)"


def add_arguments(parser):
    """The options of ``cavex calibrate``."""
    parser.add_argument("--shots", required=True, help="shot file (CSV)")
    parser.add_argument("--out", required=True, help="calibration TOML file to write")
    parser.add_argument("--params", nargs="+", help="free parameters: lam, strength_factor, "
                        "modulus_factor (default: lam strength_factor)")
    add_resistance_options(parser, table=False, epsilon=False)
    parser.add_argument("--ids", nargs="+", help="fit only these shots (default: all)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    add_parallel_options(parser)


def run(args, target, projectile):
    """Check everything, fit, write ``--out``; returns the result (:func:`job`) with the shots
    file, the reference shot and the command line the file records and the file written
    (``outputs``). Nothing is written when an input is refused or the fit fails."""
    from cavex.verification.commands.options import resistance_settings
    from cavex.verification.output.paths import check_output_file
    from cavex.verification.validation.calibration import check_parameters
    from cavex.verification.validation.shots import read_shots

    settings = resistance_settings(args)
    shot_file = read_shots(args.shots)
    shots = shot_file.by_id(args.ids) if args.ids else shot_file.shots
    params = check_parameters(args.params)
    out = check_output_file(args.out, "out")
    result = job(shots, resistance=settings["resistance"], boundary=settings["boundary"],
                 params=params, workers=args.workers, scheduler=scheduler_of(args),
                 progress=args.progress, out=out)
    calibration = result["calibration"]
    result["command"] = command_line(args.shots, args.out, calibration.model, params, args.ids)
    warning = all_fitted_warning(shots, len(shot_file.shots))
    if warning:
        print(f"cavex calibrate: warning: {warning}", file=sys.stderr)
    result["shots_path"] = args.shots
    result["reference"] = next(s for s in shots if s.id in calibration.shots)  # first fitted
    result["outputs"] = write_outputs(result, out)
    return result


def job(shots, *, resistance="derived", boundary=None, params=None, workers=None,
        scheduler=None, progress=None, out=None):
    """Fit (:func:`cavex.verification.validation.calibration.fit`) after checking the execution
    settings and that ``out`` (if given) ends in .toml: ``{"calibration", "seconds",
    "output"}`` (``output``: ``out``, the file to write)."""
    from cavex.errors import require
    from cavex.verification.fedata.runner import check_execution, show_progress
    from cavex.verification.validation.calibration import fit
    from cavex.verification.validation.predict import TableCache

    check_execution(workers, scheduler)
    require(out is None or Path(out).suffix == ".toml", "out", "a path ending in .toml",
            str(out))
    show = show_progress(progress)
    tables = TableCache(workers=workers, scheduler=scheduler, progress=show)
    began = time.monotonic()
    calibration = fit(shots, resistance, params, tables=tables, progress=show,
                      boundary=boundary)
    return {"calibration": calibration, "seconds": time.monotonic() - began, "output": out}


def command_line(shots_path, out_path, model, params, ids=None):
    """The ``cavex calibrate`` command that writes this file (its comment)."""
    from cavex.analytic.models import label_options

    words = ["cavex", "calibrate", "--shots", str(shots_path), "--out", str(out_path),
             *label_options(model).split(), "--params", *params,
             *(["--ids", *ids] if ids else [])]
    return " ".join(shlex.quote(w) for w in words)


def write_outputs(job, out):
    """Write the calibration file ``out``, recording the job's ``shots_path``, ``reference``
    shot and ``command``; return the paths written."""
    from cavex.verification.output.files import write_text_atomic
    from cavex.verification.output.paths import output_refusals
    from cavex.verification.validation.calibration import calibration_text

    out = Path(out)
    text = calibration_text(job["calibration"], job["shots_path"], job["reference"],
                            job["command"])
    with output_refusals("out", out):  # a full disk: one line naming --out, no file
        if out.parent != Path(""):
            out.parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(out, text)
    return [str(out)]


def _outlier_lines(s):
    """The fitted shots the model misses by more than the factor, and the fit without them."""
    if not s["outliers"]:
        return []
    w = s["without_outliers"]
    fit = ("no shot left" if w["n"] == 0 else
           f"mean |ln(predicted/measured)| {w['mean_abs_log_ratio']:.4f}, rms "
           f"{w['rms_log_ratio']:.4f} over {w['n']} shots")
    return [f"outliers {len(s['outliers'])} shot(s) off by more than a factor "
            f"{s['outlier_factor']:g} at the fit (flagged, still fitted): "
            f"{', '.join(s['outliers'])}", f"without  {fit}"]


def summary(job):
    """What ``cavex calibrate --json`` prints: the model, the fitted parameters (all
    dimensionless), the mapping, the shots fitted, the fit statistics, the shots skipped, the
    outliers and the statistics without them, the wall time and the file written."""
    from cavex.verification.validation.predict import OUTLIER_FACTOR

    calibration = job["calibration"]
    return {"model": calibration.model, "params": list(calibration.params),
            "fitted": {p: getattr(calibration.mapping, p) for p in calibration.params},
            "standard_errors": dict(calibration.standard_errors),
            "mapping": calibration.mapping.as_dict(), "shots": list(calibration.shots),
            **dict(calibration.statistics),
            "skipped": {shot: reason for shot, reason in calibration.skipped},
            "outlier_factor": OUTLIER_FACTOR, "outliers": list(calibration.outliers),
            "without_outliers": dict(calibration.without_outliers),
            "wall_time_s": float(job["seconds"]),
            "output": str(job["output"])}


def text(job):
    """The model and its shots, the fitted values, the fit, the shots the model could not
    predict (left out of the fit), the file."""
    s = summary(job)
    errors = s["standard_errors"]
    why = ("as many shots as parameters" if len(s["shots"]) <= len(s["fitted"])
           else "the shots do not determine it")
    values = ", ".join(f"{p} = {v:.6g}" + _error(errors.get(p), bound_words(p, v) or why)
                       for p, v in s["fitted"].items())
    return "\n".join([
        f"model   {s['model']}, {len(s['shots'])} shots: {', '.join(s['shots'])}",
        f"fitted  {values}",
        f"fit     mean |ln(predicted/measured)| {s['mean_abs_log_ratio']:.4f}, rms "
        f"{s['rms_log_ratio']:.4f}, {s['evaluations']} evaluations, "
        f"{s['wall_time_s']:.1f} s",
        *(f"skipped {shot}: {reason}" for shot, reason in s["skipped"].items()),
        *_outlier_lines(s),
        f"wrote   {s['output']}",
    ])


def bound_words(param, value):
    """Why a parameter fitted onto its bound has no standard error (None: not on one)."""
    from cavex.verification.validation.calibration import BOUNDS, at_bound

    side = at_bound(param, value)
    if side is None:
        return None
    bound = BOUNDS[param][0 if side == "lower" else 1]
    return (f"at its {side} bound {bound:g}: the shots want it beyond, so they determine "
            "neither it nor its error")


def _error(se, why):
    """`` +- se`` (the fit's standard error, 2 significant digits), or ``why`` there is none."""
    if se is None:
        return f" (no standard error: {why})"
    return f" +- {se:.2g}"


def all_fitted_warning(fitted, available):
    """The warning when the fit used every shot of the file (None otherwise): ``cavex
    validate`` then has no held-out shot to judge the calibration on."""
    if len(fitted) < available:
        return None
    return (f"every shot of the file ({available}) was fitted: `cavex validate` has no "
            "held-out shot to judge this calibration on (fit a subset with --ids)")
