"""The command-line inputs the studies share: ``--out`` (and a shot study's ``--shots``),
checked before any work is done; a bad one is one line on stderr, and the study exits 2
writing nothing."""

import sys

from cavex.errors import CavexInputError
from cavex.verification.output.paths import check_output_dir
from cavex.verification.validation.shots import read_shots


def _checked(read):
    """``read()``, or None after its :class:`CavexInputError` on one line of stderr."""
    try:
        return read()
    except CavexInputError as exc:
        print(f"cavex: {exc}", file=sys.stderr)
        return None


def output_folder(args):
    """The folder of a study's ``--out`` (:func:`~cavex.verification.output.paths.
    check_output_dir`); None, with one line on stderr, when it is bad."""
    return _checked(lambda: check_output_dir(args.out, "out"))


def study_inputs(args):
    """``(output folder, shots)`` from a shot study's ``--out`` and ``--shots``; None, with
    one line on stderr, when either is bad."""
    return _checked(lambda: (check_output_dir(args.out, "out"), read_shots(args.shots).shots))
