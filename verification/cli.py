"""The ``cavex`` command line: the parser (each command's module adds its own options), the
configuration, dispatch to the command's module (:mod:`cavex.verification.commands`, one per
command: ``run(args, target, projectile)`` returns the result, printed as ``summary`` JSON with
``--json``, opened by ``cavex_version``, else as ``text``) and exit codes."""

import argparse
import gc
import importlib
import importlib.abc
import importlib.util
import os
import re
import signal
import sys

from cavex import __version__
from cavex.config import load_config
from cavex.errors import CavexInputError, CavexNumericalError
from cavex.verification.output.json_document import json_text

#: The commands, in the order ``cavex --help`` lists them; each is the module
#: ``cavex.verification.commands.<name>``.
COMMANDS = ("penetrate", "stress", "fem", "table", "verify", "batch", "calibrate", "validate",
            "trajectory", "view", "config")


class _Help(argparse.ArgumentDefaultsHelpFormatter):
    """Every option's help shows its default (or that it is required), unless the help already
    says it; a flag (off unless given) shows none, nor does a command in ``cavex --help``'s
    list (an entry of the optional COMMAND: bare ``cavex`` prints the help)."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text or "required" in text:
            return text
        if action.required:  # a required option or positional; not a command of the list
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


def command_module(name):
    """The module of the command ``name`` (:data:`COMMANDS`)."""
    return importlib.import_module(f"cavex.verification.commands.{name}")


def build_parser(command=None):
    """The ``cavex`` parser: one subparser per command of :data:`COMMANDS`, with the command's
    one-line ``HELP`` and the options its ``add_arguments`` adds. ``command``: only that
    command's module is imported and its subparser filled (the others are there by name), which
    is all ``cavex COMMAND ...`` parses, so a command's start costs the import of its own module
    only; None: every command (``cavex --help``)."""
    parser = _Parser(prog="cavex", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"cavex {__version__}")
    commands = parser.add_subparsers(dest="command", parser_class=_Parser, metavar="COMMAND")
    for name in COMMANDS:
        if command is None or name == command:
            module = command_module(name)
            module.add_arguments(commands.add_parser(name, help=module.HELP))
        else:
            commands.add_parser(name)
    _describe(commands)
    return parser


def named_command(argv):
    """The command ``argv`` names (its first word that is no option; ``cavex`` has no option
    that takes a value), or None when it names none of :data:`COMMANDS`."""
    word = next((str(a) for a in argv if not str(a).startswith("-")), None)
    return word if word in COMMANDS else None


def _describe(commands):
    """Each subcommand's ``--help`` opens with its one-line summary."""
    for action in commands._choices_actions:  # argparse keeps the summaries only here
        sub = commands.choices[action.dest]
        if sub.description is None:
            sub.description = action.help


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


class _AfterImport(importlib.abc.MetaPathFinder):
    """Calls ``then()`` once the module ``name`` has been imported (a post-import hook): the
    first import of ``name`` is found by the other finders and run by their loader, then
    ``then`` runs. The finder removes itself at that first import."""

    def __init__(self, name, then):
        self.name, self.then = name, then

    def find_spec(self, fullname, path=None, target=None):
        if fullname != self.name:
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(fullname)
        if spec is None or spec.loader is None:
            return spec
        loader, then = spec.loader, self.then

        class Loader(importlib.abc.Loader):
            def create_module(self, spec):
                return loader.create_module(spec)

            def exec_module(self, module):
                loader.exec_module(module)
                then()

        spec.loader = Loader()
        return spec


def announce_in_the_program(argv, stream=None):
    """The installed program (:func:`console`) says that it compiles on ``stream`` (stderr)
    also where it is no terminal (a pipe, a log, CI: the first ``trajectory`` compiled for
    about 2 min in silence there, issue 33). The listener is registered once numba is
    imported, by the command's computation (a hook on numba's import): a refused input
    still loads no numerical library (``commands/__init__.py``). ``main`` called from Python
    (the tests, the API) says it on a terminal only (:func:`_announce_on_terminal`)."""
    command = named_command(argv)
    if command in (None, "config") or _ANNOUNCED:
        return

    def register():
        if not _ANNOUNCED:
            _ANNOUNCED.append(announce_compiling(stream or sys.stderr))

    if "numba" in sys.modules:
        register()
    else:
        sys.meta_path.insert(0, _AfterImport("numba", register))


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
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(named_command(argv))
    try:
        args = parser.parse_args(argv)
        if args.command is None:  # bare `cavex`: what it can do
            parser.print_help()
            return 0
        if args.command == "config" and args.default and args.config is not None:
            raise CavexInputError("options --default and --config FILE exclude each other")
        target, projectile = load_config(args.config) if "config" in args else (None, None)
        _announce_on_terminal(args.command)
        command = command_module(args.command)
        result = command.run(args, target, projectile)
        text = (json_text(command.summary(result)) if getattr(args, "json", False)
                else command.text(result))
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
    except OSError as exc:  # standard output refused (a full disk, /dev/full): one line
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        print(f"cavex: error: cannot write the standard output: {exc.strerror or exc}",
              file=sys.stderr)
        return 2
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
    :func:`main`, which leaves the collector as it is.

    A command's outputs are its last work: once they are moved into ``--out``, SIGINT and
    SIGTERM are ignored (:func:`cavex.verification.output.program.program_ends_at_commit`), so
    exit code 0 means every new file is there and 130 (or death by SIGTERM) that none is."""
    from cavex.verification.output.program import program_ends_at_commit

    gc.set_threshold(*GC_THRESHOLDS)
    announce_in_the_program(sys.argv[1:])
    program_ends_at_commit()
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
