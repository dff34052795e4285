"""``cavex verify``: the analytic-against-FE report of the target
(:mod:`cavex.verification.report`).

The report is written into a hidden folder and moved in complete: Ctrl-C or kill leaves the
previous report as it was, or (if that was removed) no report, never a partial one.
"""

from pathlib import Path

from cavex.verification.commands.shared_options import (
    add_config_option,
    add_figures_option,
    add_parallel_options,
    scheduler_of,
)

HELP = "analytic against FE report for the target"
DEFAULT_OUT = "results/verification"


def add_arguments(parser):
    """The options of ``cavex verify``."""
    add_config_option(parser)
    parser.add_argument("--quick", action="store_true", help="small grid (under a minute)")
    parser.add_argument("--out", help="report folder (default results/verification)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    add_figures_option(parser, "report.md, report.html, grid.nc and target.toml")
    add_parallel_options(parser)


def run(args, target, projectile):
    """Write the report (:func:`job`); returns its result."""
    from cavex.verification.commands.options import refuse_debonded

    refuse_debonded(target, "verify")
    return job(target, projectile, config_path=args.config, quick=args.quick,
               out_dir=args.out, scheduler=scheduler_of(args), workers=args.workers,
               progress=args.progress, draw=args.figures)


def job(target, projectile, *, config_path=None, quick=False, out_dir=None, scheduler=None,
        workers=None, progress=None, draw=True):
    """Check the output folder and the execution settings, build and write the report
    (:func:`cavex.verification.report.build.verify`, staged); return its result with the
    paths of the folder it was moved to. ``config_path``: the file the target was read from
    (None: the default target), whose text the report quotes; ``draw``: the PNG figures."""
    from cavex.config import default_config_text
    from cavex.verification.fedata.runner import check_execution
    from cavex.verification.output.paths import check_output_dir, staged_output

    config = default_config_text() if config_path is None else Path(config_path).read_text(
        encoding="utf-8")
    out_dir = check_output_dir(DEFAULT_OUT if out_dir is None else out_dir, "out")
    check_execution(workers, scheduler)
    from cavex.verification.report import build  # the numerical libraries, after the checks

    # an old report never mixes with this one: its files are replaced at the commit
    with staged_output(out_dir, replaces=build.REPORT_FILES + build.OLD_REPORT_FILES) as stage:
        result = build.verify(target, projectile, quick=quick, out_dir=stage,
                              scheduler=scheduler, workers=workers, config_text=config,
                              progress=progress, draw=draw)
    return _moved(result, stage, out_dir)


def _moved(result, stage, out_dir):
    """``result`` with the paths of the staged files in ``stage`` moved to ``out_dir``."""
    files = {k: str(Path(out_dir) / Path(v).relative_to(stage))
             for k, v in result["files"].items()}
    return {**result, "out_dir": str(out_dir), "files": files}


def summary(job):
    """What ``cavex verify --json`` prints: the report's result, its conclusions both as the
    report's sentences and as numbers (``accuracy``: one record per closed form and wall layer,
    :func:`cavex.verification.report.analysis.accuracy_records`)."""
    return {k: job[k] for k in ("out_dir", "files", "quick", "cells", "failed", "picture",
                                "accuracy", "conclusions", "wall_time_s", "table_wall_time_s",
                                "created", "table_interpolation_error")}


def text(summary):
    """Cells, times, the picture's cell, the conclusions and where the report is (of the job's
    result or its :func:`summary`: the same keys)."""
    return "\n".join([
        f"cells   {summary['cells']} ({summary['failed']} failed)",
        f"time    {summary['wall_time_s']:.1f} s (FE table {summary['table_wall_time_s']:.1f} s, "
        f"created {summary.get('created') or '?'})",
        f"figure  {summary['picture']}",
        *(f"- {line}" for line in summary["conclusions"]),
        f"wrote   {summary['files']['report']} (+ html, "
        f"{'PNGs, ' if 'error_maps' in summary['files'] else ''}grid.nc) in {summary['out_dir']}",
    ])
