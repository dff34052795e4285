"""Whether this process is the cavex program, whose command ends when its outputs are moved in.

A separate module of no imports, so that the program (:func:`cavex.verification.cli.console`)
says so at start-up without loading :mod:`cavex.verification.output.paths` (socket, threading
and the output files: about 8 ms of a command that writes nothing, such as ``cavex config`` or
``--help``), which reads it at the commit of a staged write.
"""

#: Set by :func:`program_ends_at_commit`; empty in a library caller (the tests' ``main``).
_ENDS_AT_COMMIT = []


def program_ends_at_commit():
    """Called by the cavex program before its command runs. Every command's staged write is the
    last of its work (what follows prints its summary), so once
    :func:`~cavex.verification.output.paths.staged_output` has moved the files in, SIGINT and
    SIGTERM are ignored for the rest of the process, and one that arrived during the moves is
    discarded: the exit code then says what ``--out`` holds, 0 every new file, 130 (or death by
    the signal) none of them. Without this call (a library caller, the tests' in-process
    ``main``) an interrupt during the moves is raised as :class:`KeyboardInterrupt` once they
    are done, and handlers are restored."""
    _ENDS_AT_COMMIT.append(True)


def ends_at_commit():
    """Whether :func:`program_ends_at_commit` was called in this process."""
    return bool(_ENDS_AT_COMMIT)
