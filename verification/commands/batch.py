"""``cavex batch``: a sweep of FE cases (TOML) run into one Dataset, resumable
(:mod:`cavex.verification.fedata.batch`; the sweep writes its own files as it goes)."""

import json
import os
import sys
import time

from cavex.verification.commands.shared_options import add_parallel_options, scheduler_of

HELP = "run a sweep of FE cases (TOML) into one Dataset"


def add_arguments(parser):
    """The options of ``cavex batch``."""
    parser.add_argument("sweep", help="sweep TOML file; its [target] section names the target")
    parser.add_argument("--out", help="output folder (default results/batch/<sweep name>)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    add_parallel_options(parser)
    parser.add_argument("--allow-large", action="store_true",
                        help="run a sweep of more than 20000 FE cases")
    parser.add_argument("--allow-file-scheduler", action="store_true",
                        help="connect to the sweep file's [sweep] scheduler (without it the key "
                        "is refused: a scheduler runs code on this machine; --scheduler always "
                        "counts)")


def run(args, target, projectile):
    """Run the sweep (:func:`job`); returns its result."""
    return job(args.sweep, args.out, scheduler=scheduler_of(args), workers=args.workers,
               progress=args.progress, allow_large=args.allow_large,
               allow_file_scheduler=args.allow_file_scheduler)


def job(path, out_dir=None, *, scheduler=None, workers=None, progress=None, allow_large=False,
        allow_file_scheduler=False):
    """Check, then run the sweep ``path`` into ``out_dir`` (default
    ``results/batch/<sweep name>``): ``{"dataset", "out_dir", "loaded", "seconds"}``.

    The size and an estimate of the run time go to stderr first; more than
    :data:`cavex.verification.fedata.cases.LARGE_RUN` cases need ``allow_large``.
    """
    from cavex.verification.fedata.batch import (
        STORE_DIR,
        file_scheduler,
        parse_sweep,
        run_sweep,
        sweep_cases,
    )
    from cavex.verification.fedata.cases import check_run_size
    from cavex.verification.fedata.runner import check_execution, check_store, read_store
    from cavex.verification.output.paths import check_output_dir

    sweep = parse_sweep(path)
    out_dir = os.fspath(out_dir) if out_dir is not None else os.path.join("results", "batch",
                                                                          sweep.name)
    cases = sweep_cases(sweep)
    check_output_dir(out_dir, "out")
    scheduler = scheduler if scheduler is not None else file_scheduler(sweep,
                                                                        allow_file_scheduler)
    workers = workers if workers is not None else sweep.workers
    check_execution(workers, scheduler)
    estimate = check_run_size(len(cases), workers or os.cpu_count() or 1, allow_large)
    check_store(os.path.join(out_dir, STORE_DIR), cases)
    print(f"sweep '{sweep.name}': {estimate}", file=sys.stderr)
    ids = {case["id"] for case in cases}
    loaded = len(ids & set(read_store(os.path.join(out_dir, STORE_DIR))))
    start = time.perf_counter()
    dataset = run_sweep(path, out_dir, scheduler=scheduler, workers=workers, progress=progress,
                        allow_file_scheduler=allow_file_scheduler)
    return {"dataset": dataset, "out_dir": out_dir, "loaded": loaded,
            "seconds": time.perf_counter() - start}


def summary(job):
    """What ``cavex batch --json`` prints: the sweep's name, its cases (run now, loaded from
    the store, failed, with the reasons), the Dataset's dimensions, the wall time and the
    files written."""
    from cavex.verification.fedata.batch import RESULTS_FILE, STORE_DIR

    dataset, out_dir = job["dataset"], job["out_dir"]
    cases = int(dataset.attrs["cases"])
    reasons = json.loads(dataset.attrs["failure_reasons"])
    return {"sweep": dataset.attrs["sweep"], "cases": cases, "run": cases - job["loaded"],
            "loaded": job["loaded"], "failed": len(reasons), "failure_reasons": reasons,
            "dimension_sizes": dict(dataset.sizes), "wall_time_s": float(job["seconds"]),
            "output": os.path.join(out_dir, RESULTS_FILE),
            "store": os.path.join(out_dir, STORE_DIR)}


def text(job):
    """Cases run, loaded and failed (the first ten reasons), dimensions, files."""
    s = summary(job)
    sizes = ", ".join(f"{name}={size}" for name, size in s["dimension_sizes"].items())
    reasons = s["failure_reasons"]
    lines = [f"sweep '{s['sweep']}': {s['cases']} cases ({s['run']} run, "
             f"{s['loaded']} loaded from the store), {s['failed']} failed, "
             f"{s['wall_time_s']:.1f} s",
             f"dimensions: {sizes}"]
    lines += [f"  failed {case_id}: {reason}" for case_id, reason in list(reasons.items())[:10]]
    if len(reasons) > 10:
        lines.append(f"  ... and {len(reasons) - 10} more (attribute failure_reasons)")
    lines.append(f"wrote {s['output']} (cases in {s['store']}/)")
    return "\n".join(lines)
