"""The ``cavex`` program: its console script and ``python -m cavex``.

:func:`console` runs :func:`cavex.verification.cli.console` (the command line) after the one
setting that has to precede numpy's import: OpenBLAS's thread pool, ``OPENBLAS_NUM_THREADS``,
1 unless the user set it. The program computes in processes of its own (the FE workers of
``table``, ``verify`` and ``batch``) and solves its systems with its own compiled banded
solver; the threads OpenBLAS starts when numpy and scipy load it (a pool per library and
process) only spin beside the work. Measured on 2 cores (benchmarks/commands.md): 22 % of the
CPU of ``cavex penetrate --no-figures`` and 10 % of a ``cavex table`` run, 5 % and 3 % of their
wall time; the results are the same bytes.
"""

import os
import sys


def console():
    """The ``cavex`` program; returns its exit code."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # read by OpenBLAS when it loads
    from cavex.verification.cli import console as command_line

    return command_line()


if __name__ == "__main__":
    sys.exit(console())
