"""The ``cavex`` command line: argument parsing and printing only; the work lives in the parts."""

import argparse
import json
import os
import re
import sys

from cavex import __version__
from cavex.analytic.paper_model import EPSILON_READINGS
from cavex.config import load_config
from cavex.errors import CavexInputError, CavexNumericalError
from cavex.verification.output.paths import check_output_dir, write_staged

DEFAULT_PENETRATION_DIR = "results/penetration"


class _Help(argparse.ArgumentDefaultsHelpFormatter):
    """Every option's help shows its default, unless the help already says it."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text or action.default in (None, False, argparse.SUPPRESS):
            return text
        return super()._get_help_string(action)


class _Parser(argparse.ArgumentParser):
    """Argument errors as one line on stderr and exit code 2; help shows the defaults."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", _Help)
        super().__init__(*args, **kwargs)
        # a value such as -1e3 or -inf, not an unknown option (argparse < 3.13 takes only
        # -123 and -1.5 for numbers: `--spin -1e3` was "expected one argument")
        self._negative_number_matcher = re.compile(
            r"^-(\d+\.?\d*|\.\d+)(e[-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)

    def error(self, message):
        raise CavexInputError(message)


DESCRIPTION = ("cavex: layered spherical cavity-expansion resistance, checked against a finite-"
               "element solution, and the rigid projectile through a layered target (an airport "
               "runway). SI units, compression positive. Bad input: one line on stderr, exit "
               "code 2; a numerical failure: exit code 1.")


def build_parser():
    parser = _Parser(prog="cavex", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"cavex {__version__}")
    commands = parser.add_subparsers(dest="command", parser_class=_Parser, metavar="COMMAND")
    penetrate = commands.add_parser("penetrate", help="integrate the projectile through the target")
    _common(penetrate)
    penetrate.add_argument("--out", default=DEFAULT_PENETRATION_DIR, help="output folder")
    penetrate.add_argument("--crater", choices=("nose-base", "nose-tip"), default="nose-base",
                           help="where the crater depth 4.5 r is measured from")
    penetrate.add_argument("--resistance", choices=("closed-form", "table"),
                           default="closed-form", help="closed form (--model) or an FE table")
    penetrate.add_argument("--table", help="NetCDF table from `cavex table` (--resistance table)")
    stress = commands.add_parser("stress", help="cavity-wall stress at a nose depth")
    _common(stress)
    stress.add_argument("--velocity", type=float, required=True, help="expansion velocity V (m/s)")
    stress.add_argument("--depth", type=float, required=True, help="nose-tip depth L (m)")
    fem = commands.add_parser("fem", help="FE against analytic wall stress at a nose depth")
    fem.add_argument("--config", help="target TOML file (default: the paper's Table 1)")
    fem.add_argument("--velocity", type=float, required=True, help="expansion velocity V (m/s)")
    fem.add_argument("--depth", type=float, required=True, help="nose-tip depth L (m)")
    fem.add_argument("--nu", type=float, help="Poisson's ratio for every layer (default: file's)")
    fem.add_argument("--json", action="store_true", help="print JSON")
    fem.add_argument("--fields", help="folder for the FE fields (XDMF time series for ParaView "
                     "and meshio, history CSV)")
    table = commands.add_parser("table", help="FE-tabulated sigma_r(V, L) for the target")
    table.add_argument("--config", help="target TOML file (default: the paper's Table 1)")
    table.add_argument("--velocities", nargs="+", type=float,
                       help="m/s (default 0, 100, ..., 1200)")
    table.add_argument("--depths", nargs="+", type=float, help="nose depths, m")
    table.add_argument("-o", "--out", default="results/table.nc", help="NetCDF file to write")
    table.add_argument("--nu", type=float, help="Poisson's ratio for every layer")
    table.add_argument("--json", action="store_true", help="print JSON")
    _parallel(table)
    verify = commands.add_parser("verify", help="analytic against FE report for the target")
    verify.add_argument("--config", help="target TOML file (default: the paper's Table 1)")
    verify.add_argument("--quick", action="store_true", help="small grid (under a minute)")
    verify.add_argument("--out", help="report folder (default results/verification)")
    verify.add_argument("--json", action="store_true", help="print JSON")
    _parallel(verify)
    batch = commands.add_parser("batch", help="run a sweep of FE cases (TOML) into one Dataset")
    batch.add_argument("sweep", help="sweep TOML file; its [target] section names the target")
    batch.add_argument("--out", help="output folder (default results/batch/<sweep name>)")
    batch.add_argument("--json", action="store_true", help="print JSON")
    _parallel(batch)
    batch.add_argument("--allow-large", action="store_true",
                       help="run a sweep of more than 20000 FE cases")
    calibrate = commands.add_parser("calibrate", help="fit material parameters to measured "
                                    "penetration depths (docs/validation.md)")
    calibrate.add_argument("--shots", required=True, help="shot file (CSV)")
    calibrate.add_argument("--out", required=True, help="calibration TOML file to write")
    calibrate.add_argument("--params", nargs="+", help="free parameters: lam, strength_factor, "
                           "modulus_factor (default: lam strength_factor)")
    calibrate.add_argument("--model", default="derived-dynamic",
                           help="derived-dynamic (default), derived-quasi-static, paper or "
                                "fe-table")
    calibrate.add_argument("--ids", nargs="+", help="fit only these shots (default: all)")
    calibrate.add_argument("--json", action="store_true", help="print JSON")
    _parallel(calibrate)
    validate = commands.add_parser("validate", help="predicted against measured penetration "
                                   "depths (docs/validation.md)")
    validate.add_argument("--shots", required=True, help="shot file (CSV)")
    validate.add_argument("--calibration", nargs="+", action="extend",
                          help="calibration TOML file(s) from `cavex calibrate`")
    validate.add_argument("--json", action="store_true", help="print JSON")
    validate.add_argument("--out", help="output folder (default results/validation)")
    _parallel(validate)
    trajectory = commands.add_parser("trajectory", help="oblique shot with attitude: the rigid "
                                     "projectile in 3-D through the layers (docs/oblique.md)")
    trajectory.add_argument("--config", help="target TOML file (default: the paper's Table 1)")
    trajectory.add_argument("--velocity", type=float, help="striking speed (m/s; default V0)")
    trajectory.add_argument("--obliquity", type=float, default=0.0,
                            help="angle of the velocity from the target normal (deg)")
    trajectory.add_argument("--attack", type=float, default=0.0,
                            help="angle of attack, axis from velocity (deg)")
    trajectory.add_argument("--attack-plane", type=float, default=0.0,
                            help="plane of the angle of attack about the velocity (deg; 0: "
                            "in the plane of obliquity toward +x)")
    trajectory.add_argument("--spin", type=float, default=0.0, help="spin about the axis (rad/s)")
    trajectory.add_argument("--resistance", choices=("derived", "paper", "table", "law"),
                            default="derived", help="surface stress law")
    trajectory.add_argument("--boundary", choices=("dynamic", "quasi-static"),
                            default="dynamic", help="convention of the derived law")
    trajectory.add_argument("--contact-ramp", dest="contact_ramp", type=float, default=None,
                            help="contact regularisation: the stress rises linearly over "
                            "0 < V_n < this (m/s; default 0.01; docs/oblique.md)")
    trajectory.add_argument("--table", help="NetCDF table from `cavex table` (--resistance table)")
    trajectory.add_argument("--law-A", dest="law_A", type=float, help="A of sigma_n = A + B "
                            "V_n^2 (Pa)")
    trajectory.add_argument("--law-B", dest="law_B", type=float, help="B (kg/m^3)")
    trajectory.add_argument("--no-free-surface", action="store_true",
                            help="no free-surface reduction of the derived law")
    trajectory.add_argument("--compare-homogeneous", action="store_true",
                            help="also the same shot into the first layer alone")
    trajectory.add_argument("--json", action="store_true", help="print JSON")
    trajectory.add_argument("--figures", action=argparse.BooleanOptionalAction, default=True,
                            help="draw the figures (default; --no-figures: the CSV histories "
                            "and summary.json only, for scripted runs)")
    trajectory.add_argument("--progress", action=argparse.BooleanOptionalAction,
                            help="progress bar of integrator steps on stderr (default: when "
                            "stderr is a terminal)")
    trajectory.add_argument("--out", default="results/trajectory",
                            help="output folder (default results/trajectory)")
    _describe(commands)
    return parser


def _describe(commands):
    """Each subcommand's ``--help`` opens with its one-line summary."""
    for action in commands._choices_actions:  # argparse keeps the summaries only here
        sub = commands.choices[action.dest]
        if sub.description is None:
            sub.description = action.help


def _parallel(command):
    command.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://127.0.0.1:8786")
    command.add_argument("--workers", type=int, help="local worker processes (default: CPUs)")
    command.add_argument("--progress", action=argparse.BooleanOptionalAction,
                         help="progress bar on stderr (default: when stderr is a terminal)")


def _common(command):
    command.add_argument("--config", help="target TOML file (default: the paper's Table 1)")
    command.add_argument("--model", choices=("derived", "paper"), default="derived")
    command.add_argument("--boundary", choices=("quasi-static", "dynamic"),
                         help="yield-at-boundary convention of the derived model (default: "
                         "dynamic; the paper model has its own, quasi-static)")
    command.add_argument("--epsilon", choices=EPSILON_READINGS, default="quasi-static",
                         help="the paper model's reading of epsilon (docs/table2.md)")
    command.add_argument("--json", action="store_true", help="print JSON")


def main(argv=None):
    """Entry point; returns the exit code (0 ok, 1 numerical failure, 2 bad input)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if args.command is None:  # bare `cavex`: what it can do
            parser.print_help()
            return 0
        target, projectile = load_config(args.config) if "config" in args else (None, None)
        text = COMMANDS[args.command](args, target, projectile)
    except CavexInputError as exc:
        print(f"cavex: error: {exc}", file=sys.stderr)
        return 2
    except CavexNumericalError as exc:
        print(f"cavex: numerical failure: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:  # the file system refused (disk full, a file changed under us)
        where = f"'{exc.filename}': " if exc.filename else ""
        print(f"cavex: error: cannot read or write {where}{exc.strerror or exc}",
              file=sys.stderr)
        return 2
    except (KeyboardInterrupt, SystemError) as exc:  # Ctrl-C (numba: a SystemError around it)
        if isinstance(exc, SystemError) and not isinstance(exc.__context__, KeyboardInterrupt):
            raise
        print("cavex: interrupted", file=sys.stderr)
        return 130
    try:
        print(text)
        sys.stdout.flush()
    except BrokenPipeError:  # the reader (e.g. `| head`) stopped: not an error of cavex
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return 0


def _penetrate(args, target, projectile):
    from cavex.verification.commands.penetrate import (
        penetration_job,
        phases_as_dicts,
        write_outputs,
    )

    if (args.resistance == "table") != (args.table is not None):
        raise CavexInputError("option '--table FILE' goes with '--resistance table' (both or "
                              "neither)")
    folder = check_output_dir(args.out, "out")
    job = penetration_job(target, projectile, model=args.model, boundary=args.boundary,
                          epsilon=args.epsilon, crater=args.crater, table_path=args.table)
    # every file or none, also on Ctrl-C or kill
    written = write_staged(folder, lambda stage: write_outputs(job, stage))
    phases = phases_as_dicts(job["runs"]["runway"])
    if args.json:
        settings = {k: job[k] for k in ("model", "boundary", "epsilon", "crater",
                                        "target_label", "notes")}
        return json.dumps({**settings, "phases": phases, "table2": job["table2"],
                           "outputs": written}, indent=2)
    return _penetration_text(job, phases, written)


def _penetration_text(job, phases, written):
    settings = (f"epsilon {job['epsilon']}" if job["model"] == "paper"
                else f"boundary {job['boundary']}")
    lines = [f"model {job['model']}, {settings}, crater from {job['crater']}"]
    lines += [f"note: {note}" for note in job["notes"]]
    lines += ["", f"phases ({job['target_label']}):",
             f"{'#':>2} {'label':<24} {'L (m)':>8} {'V (m/s)':>9} {'t (ms)':>8}  ends because"]
    lines += [f"{p['phase']:>2} {p['label']:<24} {p['end_depth_m']:8.4f} "
              f"{p['end_velocity_m_s']:9.2f} {p['end_time_s'] * 1e3:8.3f}  {p['end_reason']}"
              for p in phases]
    if job["table2"] is not None:
        lines += ["", "beside the paper's Table 2:",
                  f"{'row':<32} {'L ours':>7} {'paper':>6} {'V ours':>8} {'paper':>7} "
                  f"{'t ours':>7} {'paper':>6}"]
    for row in job["table2"] or []:
        ours, paper = row["ours"], row["paper"]
        mine = ("{:7.3f} {:>6} {:8.1f} {:>7} {:7.2f} {:>6.2f}".format(
            ours["depth_m"], paper["depth_m"], ours["velocity_m_s"], paper["velocity_m_s"],
            ours["time_s"] * 1e3, paper["time_s"] * 1e3) if ours else "(phase not reached)")
        lines.append(f"{row['phase']} {row['name']:<30} {mine}")
    lines += ["", "wrote: " + ", ".join(written)]
    return "\n".join(lines)


def _stress(args, target, projectile):
    from cavex.verification.commands.stress import stress_at_depth

    result = stress_at_depth(target, projectile, args.depth, args.velocity, model=args.model,
                             boundary=args.boundary, epsilon=args.epsilon)
    if args.json:
        return json.dumps(result, indent=2)
    return "\n".join(f"{key:<22} {value}" for key, value in result.items())


def _fem(args, target, projectile):
    from cavex.verification.fedata.comparison import compare_at_depth

    result = compare_at_depth(target, projectile, args.depth, args.velocity, nu=args.nu,
                              fields=args.fields)
    if args.json:
        return json.dumps(result, indent=2)
    fe, analytic = result["fe_sigma_r_Pa"], result["analytic_sigma_r_Pa"]
    lines = [f"nose depth {result['depth_m']} m, V = {result['velocity_m_s']} m/s, cavity "
             f"radius {result['cavity_radius_m']} m, layers {', '.join(result['layers'])}",
             f"interfaces (m): requested {result['interface_radii_m']}, FE final "
             f"{result['interface_radii_final_m']}",
             f"{'':<26} {'sigma_r (MPa)':>14} {'FE/analytic - 1':>16} {'b (m)':>10}",
             f"{'FE':<26} {fe / 1e6:14.3f} {'':>16} {result['fe_plastic_radius_m']:10.5f}"]
    for boundary, stress in analytic.items():
        lines.append(f"{'analytic ' + boundary:<26} {stress / 1e6:14.3f} "
                     f"{result['relative_difference'][boundary]:16.4%} "
                     f"{result['analytic_plastic_radius_m'][boundary]:10.5f}")
    estimate = result["error_estimate"]
    lines.append("FE estimated discretisation error: "
                 + ("not estimated" if estimate is None else f"{estimate:.3%}")
                 + f" ({result['refinements']} refinement(s) of the default resolution)")
    if "fields" in result:
        lines.append(f"wrote   {result['fields']} (+ history CSV)")
    return "\n".join(lines)


def _table(args, target, projectile):
    from cavex.verification.fedata.table import table_main

    return table_main(args.config, args.velocities, args.depths, args.out, args.nu,
                      args.workers, args.scheduler, progress=args.progress, as_json=args.json)


def _verify(args, target, projectile):
    from cavex.verification.report.build import verify_main

    return verify_main(args.config, args.quick, args.out, args.scheduler, args.workers,
                       progress=args.progress, as_json=args.json)


def _batch(args, target, projectile):
    from cavex.verification.fedata.batch import batch_main

    return batch_main(args.sweep, args.out, args.scheduler, args.workers,
                      progress=args.progress, allow_large=args.allow_large, as_json=args.json)


def _calibrate(args, target, projectile):
    from cavex.verification.validation.calibration import calibrate_main

    return calibrate_main(args.shots, args.out, args.params, args.model, args.ids,
                          args.workers, args.scheduler, progress=args.progress, as_json=args.json)


def _validate(args, target, projectile):
    from cavex.verification.commands.validate import validate_main

    return validate_main(args.shots, args.calibration, args.out, args.json, args.workers,
                         args.scheduler, progress=args.progress)


def _trajectory(args, target, projectile):
    from cavex.verification.commands.trajectory import trajectory_main

    return trajectory_main(args, target, projectile)


COMMANDS = {"penetrate": _penetrate, "stress": _stress, "fem": _fem, "table": _table,
            "verify": _verify, "batch": _batch, "calibrate": _calibrate, "validate": _validate,
            "trajectory": _trajectory}

if __name__ == "__main__":
    sys.exit(main())
