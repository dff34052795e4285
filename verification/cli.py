"""The ``cavex`` command line: the parser, the configuration, dispatch to the command's module
(:mod:`cavex.verification.commands`, one per command: ``run(args, target, projectile)`` returns
the text to print) and exit codes."""

import argparse
import gc
import importlib
import os
import re
import signal
import sys

from cavex import __version__
from cavex.analytic.penetration.labels import VALIDATION_LABELS
from cavex.config import load_config
from cavex.errors import CavexInputError, CavexNumericalError
from cavex.verification.commands.options import add_interface_option, add_resistance_options

DEFAULT_PENETRATION_DIR = "results/penetration"


class _Help(argparse.ArgumentDefaultsHelpFormatter):
    """Every option's help shows its default (or that it is required), unless the help already
    says it; a flag (off unless given) shows none."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text or "required" in text:
            return text
        if action.required or not action.option_strings:
            return text + " (required)"
        if action.default is None or action.default is False or action.nargs == 0:
            return text
        return text + " (default: %(default)s)"


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
    _config(penetrate)
    add_resistance_options(penetrate, ("derived", "paper", "table", "law"))
    add_interface_option(penetrate)
    penetrate.add_argument("--json", action="store_true", help="print JSON")
    penetrate.add_argument("--out", default=DEFAULT_PENETRATION_DIR, help="output folder")
    _figures(penetrate, "the CSV trajectories and phase table")
    penetrate.add_argument("--crater", choices=("nose-base", "nose-tip"), default="nose-base",
                           help="where the crater depth 4.5 r is measured from")
    stress = commands.add_parser("stress", help="cavity-wall stress at a nose depth")
    _config(stress)
    add_resistance_options(stress, ("derived", "paper"), table=False)
    stress.add_argument("--json", action="store_true", help="print JSON")
    stress.add_argument("--velocity", type=float, required=True, help="expansion velocity V (m/s)")
    stress.add_argument("--depth", type=float, required=True, help="nose-tip depth L (m)")
    fem = commands.add_parser("fem", help="FE against analytic wall stress at a nose depth")
    _config(fem)
    fem.add_argument("--velocity", type=float, required=True, help="expansion velocity V (m/s)")
    fem.add_argument("--depth", type=float, required=True, help="nose-tip depth L (m)")
    fem.add_argument("--nu", type=float, help="Poisson's ratio for every layer (default: file's)")
    fem.add_argument("--json", action="store_true", help="print JSON")
    fem.add_argument("--fields", help="folder for the FE fields (XDMF time series for ParaView "
                     "and meshio, history CSV; default: none written)")
    table = commands.add_parser("table", help="FE-tabulated sigma_r(V, L) for the target")
    _config(table)
    table.add_argument("--velocities", nargs="+", type=float,
                       help="m/s (default 0, 100, ..., 1200)")
    table.add_argument("--depths", nargs="+", type=float, help="nose depths, m (default: the "
                       "target's default grid; the layer switch and refinement depths are "
                       "added, and the run states the grid)")
    table.add_argument("-o", "--out", default="results/table.nc", help="NetCDF file to write")
    table.add_argument("--nu", type=float, help="Poisson's ratio for every layer (default: "
                       "file's)")
    table.add_argument("--json", action="store_true", help="print JSON")
    _parallel(table)
    verify = commands.add_parser("verify", help="analytic against FE report for the target")
    _config(verify)
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
    add_resistance_options(calibrate, table=False, epsilon=False)
    calibrate.add_argument("--ids", nargs="+", help="fit only these shots (default: all)")
    calibrate.add_argument("--json", action="store_true", help="print JSON")
    _parallel(calibrate)
    validate = commands.add_parser("validate", help="predicted against measured penetration "
                                   "depths (docs/validation.md)")
    validate.add_argument("--shots", required=True, help="shot file (CSV)")
    validate.add_argument("--calibration", nargs="+", action="extend",
                          help="calibration TOML file(s) from `cavex calibrate` (default: "
                          "none, the uncalibrated models only)")
    validate.add_argument("--models", nargs="+", action="extend", metavar="NAME",
                          help="run only these models: " + ", ".join(VALIDATION_LABELS)
                          + " (default: all; calibrations add their columns)")
    validate.add_argument("--json", action="store_true", help="print JSON")
    validate.add_argument("--out", help="output folder (default results/validation)")
    _figures(validate, "validation.json, predictions.csv and report.md")
    _parallel(validate)
    trajectory = commands.add_parser("trajectory", help="oblique shot with attitude: the rigid "
                                     "projectile in 3-D through the layers (docs/oblique.md)")
    _config(trajectory)
    trajectory.add_argument("--velocity", type=float, help="striking speed (m/s; default V0)")
    trajectory.add_argument("--obliquity", type=float, default=0.0,
                            help="angle of the velocity from the target normal (deg)")
    trajectory.add_argument("--attack", type=float, default=0.0,
                            help="angle of attack, axis from velocity (deg)")
    trajectory.add_argument("--attack-plane", type=float, default=0.0,
                            help="plane of the angle of attack about the velocity (deg; 0: "
                            "in the plane of obliquity toward +x)")
    trajectory.add_argument("--spin", type=float, default=0.0, help="spin about the axis (rad/s)")
    add_resistance_options(trajectory, ("derived", "paper", "table", "law"))
    add_interface_option(trajectory)
    trajectory.add_argument("--contact-ramp", dest="contact_ramp", type=float, default=None,
                            help="contact regularisation: the stress rises linearly over "
                            "0 < V_n < this (m/s; default 0.01; docs/oblique.md)")
    trajectory.add_argument("--contact-hold", dest="contact_hold", type=float, default=None,
                            help="held contact instead of the ramp: each element's load rises "
                            "over this push into its wall, then it cuts (m in [1e-7, 1e-5]; "
                            "not with --contact-ramp or --tangency-psi; default: off, the "
                            "velocity ramp; docs/oblique.md)")
    trajectory.add_argument("--estimate", action="store_true",
                            help="fly each run again with every discretisation parameter "
                            "refined and report the change of each reported quantity as its "
                            "estimate (summary.json 'estimate'; docs/oblique.md)")
    trajectory.add_argument("--tunnel-wall", dest="tunnel_wall", type=float, default=None,
                            help="factor in [0, 1] on the shank's load in every layer (a "
                            "sensitivity setting, uncalibrated; default: each layer's "
                            "tunnel_wall key, else 1; docs/oblique.md)")
    trajectory.add_argument("--tangency-psi", dest="tangency_psi", type=float, default=0.0,
                            help="OFPM's attenuation: an element's load falls linearly within "
                            "this angle of tangency to its velocity (deg in [0, 30]; default "
                            "0: none; docs/oblique.md)")
    trajectory.add_argument("--entry-crater", dest="entry_crater", action="store_true",
                            help="the shank carries no load in the entry crater, nose-tip "
                            "depth 0 to 4.5 r + l (the 1-D crater depth; default: off, the "
                            "tunnel wall from the surface; docs/oblique.md)")
    trajectory.add_argument("--crater", choices=("nose-base", "nose-tip"), default=None,
                            help="where the crater depth 4.5 r of the entry and interface "
                            "craters is measured from (with --entry-crater or debonded "
                            "interfaces; default nose-base, as penetrate)")
    trajectory.add_argument("--no-free-surface", action="store_true",
                            help="no free-surface reduction of the derived law")
    trajectory.add_argument("--compare-homogeneous", action="store_true",
                            help="also the same shot into the first layer alone")
    trajectory.add_argument("--json", action="store_true", help="print JSON")
    _figures(trajectory, "the CSV histories and summary.json")
    trajectory.add_argument("--progress", action=argparse.BooleanOptionalAction,
                            help="progress bar of integrator steps on stderr (default: when "
                            "stderr is a terminal)")
    trajectory.add_argument("--out", default="results/trajectory",
                            help="output folder (default results/trajectory)")
    config = commands.add_parser("config", help="print the configuration as TOML: the embedded "
                                 "default (Table 1) to copy and edit, or a checked --config FILE")
    _config(config)
    config.add_argument("--default", action="store_true", help="the embedded default (also "
                        "without --config)")
    _describe(commands)
    return parser


def _describe(commands):
    """Each subcommand's ``--help`` opens with its one-line summary."""
    for action in commands._choices_actions:  # argparse keeps the summaries only here
        sub = commands.choices[action.dest]
        if sub.description is None:
            sub.description = action.help


def _parallel(command):
    command.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://127.0.0.1:8786 "
                         "(default: local processes, --workers)")
    command.add_argument("--workers", type=int, help="local worker processes (default: CPUs)")
    command.add_argument("--progress", action=argparse.BooleanOptionalAction,
                         help="progress bar on stderr (default: when stderr is a terminal)")


def _figures(command, files):
    """``--figures/--no-figures``: draw the PNG figures (default), or write only ``files`` (for
    scripted runs: no matplotlib)."""
    command.add_argument("--figures", action=argparse.BooleanOptionalAction, default=True,
                         help=f"draw the figures (default; --no-figures: {files} only, for "
                         "scripted runs)")


def _config(command):
    command.add_argument("--config", help="target TOML file (default: the paper's Table 1)")


COMPILING = ("cavex: compiling the numerical kernels (first run after installing or updating; "
             "cached for later runs)")


def announce_compiling(stream):
    """Write :data:`COMPILING` to ``stream`` once, when numba starts compiling a kernel (its
    ``numba:compile`` event fires on a cache miss only: a kernel loaded from numba's cache says
    nothing). Returns the listener (registered for the rest of the process)."""
    from numba.core import event

    class Notice(event.Listener):
        said = False

        def on_start(self, _event):
            if not Notice.said:
                Notice.said = True
                print(COMPILING, file=stream, flush=True)

        def on_end(self, _event):
            pass

    listener = Notice()
    event.register("numba:compile", listener)
    return listener


_ANNOUNCED = []  # the listener of this process, once registered


def _announce_on_terminal(command):
    """The compile notice on stderr when it is a terminal (as the progress bars), once per
    process; ``cavex config`` compiles nothing."""
    if command != "config" and not _ANNOUNCED and sys.stderr.isatty():
        _ANNOUNCED.append(announce_compiling(sys.stderr))


INTERRUPTED = 130  # the exit code of a Ctrl-C (128 + SIGINT)


def interrupted(exc):
    """Whether ``exc`` comes of a Ctrl-C: a KeyboardInterrupt, or an exception that one
    caused or arose while one was handled (numba wraps an interrupt that arrives inside a
    compiled call, or inside the unpickling of one of its constants, in one or more
    SystemErrors; Python wraps one raised inside ``__set_name__`` in a RuntimeError)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def main(argv=None):
    """Entry point; returns the exit code (0 ok, 1 numerical failure, 2 bad input)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if args.command is None:  # bare `cavex`: what it can do
            parser.print_help()
            return 0
        if args.command == "config" and args.default and args.config is not None:
            raise CavexInputError("options --default and --config FILE exclude each other")
        target, projectile = load_config(args.config) if "config" in args else (None, None)
        _announce_on_terminal(args.command)
        command = importlib.import_module(f"cavex.verification.commands.{args.command}")
        text = command.run(args, target, projectile)
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
    except (KeyboardInterrupt, Exception) as exc:  # Ctrl-C, also wrapped (interrupted)
        if not interrupted(exc):
            raise
        print("cavex: interrupted", file=sys.stderr)
        return INTERRUPTED
    try:
        print(text)
        sys.stdout.flush()
    except BrokenPipeError:  # the reader (e.g. `| head`) stopped: not an error of cavex
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return 0


#: The cyclic garbage collector's thresholds while the program runs: the youngest generation
#: collected every 70 000 net container allocations instead of Python's 700. Importing numba,
#: scipy and scikit-fem makes about a million long-lived objects, and at the default
#: thresholds the collector walks them again and again while they are made: 0.15-0.2 s of
#: CPU per command (benchmarks/commands.md). Cycles are still collected; 70 000 young objects
#: are a few MB.
GC_THRESHOLDS = (70_000, 10, 10)


def console():
    """The ``cavex`` program (its console script and ``python -m cavex`` run it through
    :func:`cavex.__main__.console`, which first sets OpenBLAS's threads): :func:`main`; returns
    its exit code.

    The collector runs at :data:`GC_THRESHOLDS` (worker processes forked by a command inherit
    them). What the command leaves lives until the process ends: it is moved out of the cyclic
    garbage collector's reach (``gc.freeze``) before the interpreter exits, whose final
    collections would walk every object numba and scipy made (0.3-0.5 s of a ``cavex penetrate
    --no-figures``, benchmarks/commands.md). Functions registered with ``atexit`` or
    ``weakref.finalize`` still run, except after an interrupt (exit code 130), where the
    process ends at once (``os._exit``) once the command has cleaned up; the tests call
    :func:`main`, which leaves the collector as it is."""
    gc.set_threshold(*GC_THRESHOLDS)
    try:
        code = main()
    except KeyboardInterrupt:  # raised again after main's report: reported once
        code = INTERRUPTED
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the work is done: the exit is not cut short
    if code == INTERRUPTED:
        # the interrupt may have cut short objects being built (llvmlite's), whose finalisers
        # then fail as the interpreter ends, and Python may have flagged it as unhandled and
        # end by SIGINT instead (measured: 2-7 in 80 runs interrupted while writing): the
        # command has cleaned up its outputs, so the process ends here, with 130
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(INTERRUPTED)
    gc.freeze()
    return code


if __name__ == "__main__":
    sys.exit(console())
