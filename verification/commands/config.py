"""``cavex config``: the configuration the other commands use, as TOML text: the embedded
default (the paper's Table 1, ``--default``), to copy and edit, or ``--config FILE`` once read
and checked (every key in docs/config.md)."""

from pathlib import Path

from cavex.config import default_config_text


def run(args, target, projectile):
    """The TOML text: ``FILE`` (already read and checked by the command line, which refuses a
    bad file with one line and exit code 2) or the embedded default."""
    if args.config is None:
        return default_config_text().rstrip("\n")
    return Path(args.config).read_text(encoding="utf-8").rstrip("\n")
