"""``cavex config``: the configuration the other commands use, as TOML text: the embedded
default (the paper's Table 1, ``--default``), to copy and edit, or ``--config FILE`` once read
and checked (every key in docs/config.md)."""

from pathlib import Path

from cavex.config import default_config_text
from cavex.verification.commands.shared_options import add_config_option

HELP = ("print the configuration as TOML: the embedded default (Table 1) to copy and edit, or a "
        "checked --config FILE")


def add_arguments(parser):
    """The options of ``cavex config``."""
    add_config_option(parser)
    parser.add_argument("--default", action="store_true", help="the embedded default (also "
                        "without --config)")


def run(args, target, projectile):
    """The TOML text: ``FILE`` (already read and checked by the command line, which refuses a
    bad file with one line and exit code 2) or the embedded default."""
    if args.config is None:
        return default_config_text().rstrip("\n")
    return Path(args.config).read_text(encoding="utf-8").rstrip("\n")


def text(result):
    """The TOML text as it is (``cavex config`` has no ``--json``)."""
    return result
