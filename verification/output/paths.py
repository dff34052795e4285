"""Output locations, checked before any work is done.

A command that writes refuses at once, with one line naming its option and the reason, when it
could not write where it is asked to (a parent that is a file, a read-only or immutable folder,
a pseudo file system such as ``/proc``, an empty path), instead of failing after the
computation and losing it. Nothing is created by the check: the folder is made when the command
writes.
"""

import errno
import os
import shutil
import signal
import socket
import sys
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path

from cavex.errors import CavexInputError, require
from cavex.verification.output.files import process_alive
from cavex.verification.output.program import ends_at_commit


def check_output_dir(path, option, shown=None):
    """The folder ``path`` as a :class:`~pathlib.Path` if it exists as a writable folder or can
    be created as one; else :class:`CavexInputError` naming ``option`` (and ``shown``, the path
    the user gave, when it differs)."""
    text = os.fspath(path)
    require(text.strip() != "", option, "a non-empty path", text)
    folder = Path(text)
    existing = folder
    while not existing.exists():
        if existing.parent == existing:
            break
        existing = existing.parent
    shown = text if shown is None else shown
    if existing != folder:
        require(existing.is_dir(), option, f"a path whose existing part '{existing}' is a folder",
                shown)
    else:
        require(folder.is_dir(), option, f"a path in a folder ('{folder}' is a file)", shown)
    _check_writable(existing, option, shown)
    return folder


def check_output_file(path, option):
    """The file ``path`` as a :class:`~pathlib.Path` if its folder is writable (or can be
    created) and it is not a folder; else :class:`CavexInputError` naming ``option``."""
    text = os.fspath(path)
    require(text.strip() != "", option, "a non-empty path", text)
    file = Path(text)
    require(not file.is_dir(), option, "a file path (it is a folder)", text)
    check_output_dir(file.parent if str(file.parent) else Path("."), option, shown=text)
    return file


def _check_writable(folder, option, text):
    """Create and remove a temporary file in ``folder`` (the only test that also catches
    immutable folders, pseudo file systems and root's read-only mounts)."""
    try:
        handle, name = tempfile.mkstemp(dir=folder, prefix=".cavex-check-")
        os.close(handle)
        os.remove(name)
    except OSError as exc:
        raise CavexInputError(f"parameter '{option}' must be a writable location (got "
                              f"{text!r}: {exc.strerror or exc})") from None


#: what an ``OSError`` while writing the stage says about the output folder: full, over
#: quota, read-only, not permitted
FOLDER_ERRORS = (errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM)
STAGE_PREFIX = ".cavex-partial-"  # then host, process id and a random part
STALE_SECONDS = 86400.0  # a stage of no known process (an older cavex, another host) after


def remove_stale_stages(folder):
    """Remove the hidden stages a killed run (``kill -9``, power loss: no clean-up ran) left in
    ``folder``: those of this host whose process is gone, and any untouched for
    :data:`STALE_SECONDS` (older cavex names no process; another host's cannot be asked)."""
    import time

    host = socket.gethostname()
    for stage in folder.glob(STAGE_PREFIX + "*"):
        owner = stage.name[len(STAGE_PREFIX):].rsplit("-", 2)
        try:
            mine = len(owner) == 3 and owner[0] == host
            dead = mine and not process_alive(int(owner[1]))
            old = time.time() - stage.stat().st_mtime > STALE_SECONDS
        except (ValueError, OSError):
            continue
        if stage.is_dir() and (dead or (old and not mine)):
            shutil.rmtree(stage, ignore_errors=True)


@contextmanager
def staged_output(folder, option="out", replaces=()):
    """Write a command's files into a hidden folder inside ``folder`` (the ``with`` target);
    when the block ends normally, move them into ``folder`` (``os.replace``, with SIGINT and
    SIGTERM held back for the moves), so that ``folder`` gets either every new file or none.

    ``replaces``: glob patterns of every file the command can write. A file of ``folder`` that
    matches one and that this run did not write (an earlier run's figures before a
    ``--no-figures`` run, its first-layer history before a run without
    ``--compare-homogeneous``) is removed with the moves, so ``folder`` never holds two runs'
    files side by side.

    An exception or an interrupt (SIGINT or SIGTERM: :class:`KeyboardInterrupt`, also when the
    exception was swallowed on its way, e.g. in a garbage-collector callback) removes the hidden
    folder, and ``folder`` too if this created it and it is empty: Ctrl-C or ``kill`` in the
    middle of writing leaves no partial set of outputs. ``kill -9`` runs no clean-up: its stage
    (named by host and process id) is removed by the next staged write into ``folder``
    (:func:`remove_stale_stages`).

    The moves are the commit. Blocking the signals holds back only those delivered to the main
    thread: a signal another thread (numba's, dask's) receives still runs Python's handler in
    the main thread, so the handler only records a signal once the commit (or the clean-up)
    has begun, and neither is cut short midway. What happens to such a signal after the moves:
    :func:`cavex.verification.output.program.program_ends_at_commit`.

    A clash (a staged file whose name is a folder in ``folder``, a staged folder whose name
    is a file or a symlink) is found before anything is moved (:func:`planned_moves`): the
    run is refused (:class:`CavexInputError` naming ``option``) and ``folder`` is left as it
    was. Staged folders (``validate``'s ``tables/``) are merged into existing ones.
    """
    folder = Path(folder)
    created = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    remove_stale_stages(folder)
    stage = Path(tempfile.mkdtemp(prefix=f"{STAGE_PREFIX}{socket.gethostname()}-{os.getpid()}-",
                                  dir=folder))
    received, record_only = [], []

    def interrupt(signum, frame):
        received.append(signum)
        if not record_only:
            raise KeyboardInterrupt(f"signal {signum}")

    caught = ()  # handlers are set in the main thread only; an ignored signal stays ignored
    if threading.current_thread() is threading.main_thread():
        caught = [s for s in (signal.SIGINT, signal.SIGTERM)
                  if signal.getsignal(s) is not signal.SIG_IGN]
    previous = [signal.signal(s, interrupt) for s in caught]
    # an interrupt raised inside a finaliser or a garbage-collector callback is "unraisable":
    # Python would print it as a multi-line "Exception ignored in ..." report; it is recorded
    # in ``received`` and raised below instead
    unraisable = sys.unraisablehook

    def quiet(report):
        if not (received and issubclass(report.exc_type, KeyboardInterrupt)):
            unraisable(report)

    sys.unraisablehook = quiet
    committed = False
    try:
        with output_refusals(option, folder):
            yield stage
        record_only.append(True)  # the commit begins
        held = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
        try:
            if received:  # interrupted before the commit (the exception swallowed on its way)
                raise KeyboardInterrupt(f"signal {received[0]}")
            moves = planned_moves(stage, folder, option)
            for source, destination in moves:
                os.replace(source, destination)
            remove_earlier_outputs(folder, replaces,
                                   {Path(d).relative_to(folder).parts[0] for _, d in moves})
            committed = True
            if ends_at_commit():  # ignoring a blocked signal discards it if pending (POSIX)
                previous = [signal.SIG_IGN] * len(caught)
                for s in caught:
                    signal.signal(s, signal.SIG_IGN)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, held)
    finally:
        record_only.append(True)  # the clean-up is not cut short either
        sys.unraisablehook = unraisable
        for s, handler in zip(caught, previous, strict=True):
            signal.signal(s, signal.SIG_DFL if handler is None else handler)
        shutil.rmtree(stage, ignore_errors=True)
        if created:
            try:
                folder.rmdir()  # only if empty: nothing was moved in
            except OSError:
                pass
    if committed and received and not ends_at_commit():  # every file is in: then the interrupt
        raise KeyboardInterrupt(f"signal {received[0]}")


def remove_earlier_outputs(folder, patterns, written):
    """Remove the files (or links) of ``folder`` matching ``patterns`` whose names are not in
    ``written`` (:func:`staged_output`'s ``replaces``)."""
    for pattern in patterns:
        for path in Path(folder).glob(pattern):
            if path.name not in written and (path.is_symlink() or path.is_file()):
                try:
                    path.unlink(missing_ok=True)
                except OSError:  # the moves are done: a file that stays is no reason to fail
                    pass


@contextmanager
def output_refusals(option, where):
    """Turn an ``OSError`` that says the output location cannot take the files (full, over
    quota, read-only, not permitted: :data:`FOLDER_ERRORS`) into one line naming ``option``
    and ``where`` (:class:`CavexInputError`, exit 2); other errors pass."""
    try:
        yield
    except OSError as exc:
        if exc.errno not in FOLDER_ERRORS:
            raise
        raise CavexInputError(f"parameter '{option}' must be a location the outputs can be "
                              f"written to (got '{where}': {exc.strerror or exc}; nothing "
                              "was written)") from None


def planned_moves(stage, folder, option="out"):
    """The ``(source, destination)`` renames that put every entry of ``stage`` into
    ``folder``: a file or a folder new to ``folder`` is moved whole, a staged folder whose
    name is a folder of ``folder`` is merged into it (its entries planned the same way).
    Every destination is checked before anything is moved: a file onto a folder, or a folder
    onto a file or a symlink (never followed), is refused with :class:`CavexInputError`.
    A symlink at a file's name is replaced (the link, not what it points to)."""
    moves = []
    for source in sorted(Path(stage).iterdir()):
        destination = Path(folder) / source.name
        real_folder = destination.is_dir() and not destination.is_symlink()
        if source.is_dir() and real_folder:
            moves += planned_moves(source, destination, option)
            continue
        if source.is_dir() and os.path.lexists(destination):
            raise CavexInputError(f"parameter '{option}' must be a folder where '{source.name}'"
                                  f" can be written as a folder (got '{destination}': a file "
                                  "or a symlink; nothing was written)")
        if real_folder:
            raise CavexInputError(f"parameter '{option}' must be a folder where '{source.name}'"
                                  f" can be written (got '{destination}': a folder; nothing "
                                  "was written)")
        moves.append((source, destination))
    return moves


def write_staged(folder, write, replaces=()):
    """``write(stage)`` (writes a command's files into ``stage``, returns their paths) inside
    :func:`staged_output` of ``folder`` (``replaces``: the patterns of every file the command
    can write); returns the paths the files have in ``folder``."""
    folder = Path(folder)
    with staged_output(folder, replaces=replaces) as stage:
        written = write(stage)
    return [str(folder / Path(path).relative_to(stage)) for path in written]
