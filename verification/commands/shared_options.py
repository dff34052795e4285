"""The options several commands share: ``--config``, the execution options (``--scheduler``,
``--workers``, ``--progress``) and ``--figures/--no-figures``; the resistance options are in
:mod:`cavex.verification.commands.options`."""

import argparse


def add_config_option(parser):
    """``--config FILE``: the target TOML file (default: the paper's Table 1)."""
    parser.add_argument("--config", help="target TOML file (default: the paper's Table 1)")


def add_parallel_options(parser):
    """``--scheduler``, ``--workers`` and ``--progress/--no-progress`` of a command that runs FE
    cases (locally or on Dask)."""
    parser.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://127.0.0.1:8786 "
                        "(default: local processes, --workers)")
    parser.add_argument("--workers", type=int, help="local worker processes (default: CPUs)")
    parser.add_argument("--progress", action=argparse.BooleanOptionalAction,
                        help="progress bar on stderr (default: when stderr is a terminal)")


def add_figures_option(parser, files):
    """``--figures/--no-figures``: draw the PNG figures (default), or write only ``files`` (for
    scripted runs: no matplotlib)."""
    parser.add_argument("--figures", action=argparse.BooleanOptionalAction, default=True,
                        help=f"draw the figures (default; --no-figures: {files} only, for "
                        "scripted runs)")
