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
                        "(default: local processes, --workers); a scheduler runs code on "
                        "this machine and this machine's on its workers: connect only to "
                        "one you trust (docs/verification.md)")
    parser.add_argument("--scheduler-tls-ca", metavar="FILE", help="TLS: the certificate "
                        "authority the tls:// scheduler's certificate is checked against "
                        "(default: none, no TLS)")
    parser.add_argument("--scheduler-tls-cert", metavar="FILE", help="TLS: this client's "
                        "certificate (with --scheduler-tls-key; default: none)")
    parser.add_argument("--scheduler-tls-key", metavar="FILE", help="TLS: this client's key "
                        "(default: none)")
    parser.add_argument("--workers", type=int, help="local worker processes (default: CPUs)")
    parser.add_argument("--progress", action=argparse.BooleanOptionalAction,
                        help="progress bar on stderr (default: when stderr is a terminal)")


def scheduler_of(args):
    """``--scheduler`` with its TLS files (``--scheduler-tls-*``), checked
    (:func:`cavex.verification.fedata.runner.scheduler_with_tls`)."""
    from cavex.verification.fedata.runner import scheduler_with_tls

    return scheduler_with_tls(args.scheduler, args.scheduler_tls_ca, args.scheduler_tls_cert,
                              args.scheduler_tls_key)


def add_figures_option(parser, files):
    """``--figures/--no-figures``: draw the PNG figures (default), or write only ``files`` (for
    scripted runs: no matplotlib)."""
    parser.add_argument("--figures", action=argparse.BooleanOptionalAction, default=True,
                        help=f"draw the figures (default; --no-figures: {files} only, for "
                        "scripted runs)")
