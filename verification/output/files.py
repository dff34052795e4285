"""Files every command writes: atomically (a temporary file, then ``os.replace``), so that a
killed run never leaves a partial file: text, CSV columns of numbers, matplotlib figures, copies.

Every temporary file is created exclusively in the destination folder
(:func:`exclusive_temporary`: ``tempfile.mkstemp``, ``O_CREAT | O_EXCL | O_NOFOLLOW`` under a
random name), so a symlink planted at a temporary name is never written through; the final
``os.replace`` replaces a symlink planted at the final name (the link, not its target).
"""

import csv
import gc
import io
import os
import sys
import tempfile
from contextlib import contextmanager

#: the process's umask (read once): a temporary file gets the mode ``open()`` would give
_UMASK = os.umask(0)
os.umask(_UMASK)
#: every temporary file's name ends so (the FE-table cache counts and removes stale ones)
TMP_SUFFIX = ".tmp"


def temporary_prefix(path):
    """``.<name>.<pid>.``: the hidden prefix of ``path``'s temporary files (the process id
    tells a stale one, :func:`stale_temporary`)."""
    return f".{os.path.basename(os.fspath(path))}.{os.getpid()}."


def exclusive_temporary(path, suffix=TMP_SUFFIX):
    """A new file beside ``path``, created exclusively (``tempfile.mkstemp``: ``O_CREAT |
    O_EXCL | O_NOFOLLOW``, random name :func:`temporary_prefix` ``...suffix``) with the mode
    ``open()`` would give; returns ``(descriptor, path)``."""
    folder = os.path.dirname(os.fspath(path)) or "."
    handle, tmp = tempfile.mkstemp(dir=folder, prefix=temporary_prefix(path), suffix=suffix)
    try:
        os.fchmod(handle, 0o666 & ~_UMASK)
    except OSError:
        pass
    return handle, tmp


def stale_temporary(name):
    """Whether the temporary file named ``name`` (:func:`temporary_prefix`, then mkstemp's
    8 random characters) belongs to no running process of this host (a killed writer's); a
    name without a process id (an older cavex's) is stale."""
    import re

    found = re.findall(r"\.(\d+)\.[a-z0-9_]{8}(?=\.|$)", name)
    if not found:
        return True
    return not process_alive(int(found[-1]))


def process_alive(pid):
    """Whether process ``pid`` exists on this host (this process, or another user's, counts
    as alive; an id no process can have does not)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except (ProcessLookupError, OverflowError):
        return False
    except PermissionError:  # another user's process
        return True
    return True


def write_text_atomic(path, text, durable=True):
    """Write ``text`` so that no reader (or a run resumed after ``kill -9``) sees a partial file.

    The text goes to a new temporary file beside ``path`` (:func:`exclusive_temporary`), is
    flushed (and, ``durable``, fsynced: on disk before it replaces ``path``, so that an
    operating-system crash or a power cut leaves the old file or the new one), then
    ``os.replace``-d onto ``path``. A killed process loses nothing it wrote
    either way (the data is in the operating system's cache); ``durable=False`` is for files
    whose reader checks them and can recompute them (the case store: an fsync costs 1-4 ms here,
    ~0.2 s of a 100-case ``cavex table``)."""
    handle, tmp = exclusive_temporary(path)
    try:
        with os.fdopen(handle, "w", encoding="utf-8", newline="") as stream:
            stream.write(text)
            stream.flush()
            if durable:
                os.fsync(stream.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.lexists(tmp):
            os.remove(tmp)


def run_stem(name):
    """A run's name in file names (``trajectory_<stem>.csv``, ``history_<stem>.csv``,
    ``phases_<stem>.csv``): the whole target's run, ``"runway"`` in the commands' JSON (kept
    for scripts that read it), is ``target``, whatever the target (a user's own is no runway);
    another run its own name, spaces as ``_`` (``first_layer_only``)."""
    return "target" if name == "runway" else name.replace(" ", "_")


def write_columns_csv(path, columns, quanta=None):
    """``columns`` (name -> sequence) as CSV, atomically, every number through
    :func:`~cavex.verification.output.number_format.format_number`, with the rule
    ``quanta[name]`` where given (a ``Decimals``: the absolute quantum; an int: that many
    significant digits); returns ``path``."""
    from cavex.verification.output.number_format import TRAJECTORY_DIGITS, Decimals, format_number

    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(columns)
    rules = [(quanta or {}).get(name) for name in columns]
    rules = [(q, TRAJECTORY_DIGITS) if isinstance(q, Decimals) or q is None else (None, q)
             for q in rules]
    writer.writerows([format_number(x, digits, quantum) for x, (quantum, digits)
                      in zip(row, rules, strict=True)]
                     for row in zip(*columns.values(), strict=True))
    write_text_atomic(path, text.getvalue())
    return path


@contextmanager
def replaced_atomically(path, suffix=".tmp"):
    """Yield the path of a new, empty temporary file beside ``path``, created exclusively
    (:func:`exclusive_temporary`), for the caller to write; on success it is
    ``os.replace``-d onto ``path``, on an exception removed: a killed or failed run never
    leaves a partial file."""
    handle, tmp = exclusive_temporary(path, suffix)
    os.close(handle)
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if os.path.lexists(tmp):
            os.remove(tmp)


def save_figure(fig, path, **savefig):
    """Save a matplotlib figure atomically (:func:`replaced_atomically`) and close it; returns
    ``path``. A figure made without pyplot (:func:`agg_figure`) has nothing to close: pyplot
    is then not imported for it."""
    try:
        with replaced_atomically(path, ".tmp.png") as tmp:
            fig.savefig(tmp, **savefig)
    finally:
        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close(fig)
    return path


def agg_figure(**figure):
    """A matplotlib ``Figure(**figure)`` on an Agg canvas, made without pyplot (its import and
    figure manager cost a tenth of a second a command and nothing here shows a window)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**figure)
    FigureCanvasAgg(fig)
    return fig


@contextmanager
def collector_paused():
    """Python's cyclic garbage collector off for the block, back on after. Drawing allocates
    many small objects; in a process that holds numba's and scipy's (over 10^5 tracked
    objects), each automatic full collection walks them all: a third of the figure time,
    measured (benchmarks/commands.py). The figures' cycles are collected when it is back on."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def copy_atomic(source, path):
    """Copy the file ``source`` to ``path`` (:func:`replaced_atomically`); returns ``path``."""
    import shutil

    os.makedirs(os.path.dirname(os.fspath(path)) or ".", exist_ok=True)
    with replaced_atomically(path) as tmp:
        shutil.copyfile(source, tmp)
    return path
