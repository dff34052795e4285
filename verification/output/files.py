"""Files every command writes: atomically (a temporary file, then ``os.replace``), so that a
killed run never leaves a partial file: text, CSV columns of numbers, matplotlib figures, copies."""

import csv
import gc
import io
import os
import sys
from contextlib import contextmanager


def write_text_atomic(path, text, durable=True):
    """Write ``text`` so that no reader (or a run resumed after ``kill -9``) sees a partial file.

    The text goes to ``<path>.tmp``, is flushed (and, ``durable``, fsynced: on disk before it
    replaces ``path``, so that an operating-system crash or a power cut leaves the old file or
    the new one), then ``os.replace``-d onto ``path``. A killed process loses nothing it wrote
    either way (the data is in the operating system's cache); ``durable=False`` is for files
    whose reader checks them and can recompute them (the case store: an fsync costs 1-4 ms here,
    ~0.2 s of a 100-case ``cavex table``)."""
    tmp = os.fspath(path) + ".tmp"
    with open(tmp, "w", encoding="utf-8", newline="") as handle:
        handle.write(text)
        handle.flush()
        if durable:
            os.fsync(handle.fileno())
    os.replace(tmp, path)


def write_columns_csv(path, columns, quanta=None):
    """``columns`` (name -> sequence) as CSV, atomically, every number through
    :func:`~cavex.verification.output.number_format.format_number`, with the absolute quantum
    ``quanta[name]`` where given; returns ``path``."""
    from cavex.verification.output.number_format import format_number

    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(columns)
    column_quanta = [(quanta or {}).get(name) for name in columns]
    writer.writerows([format_number(x, quantum=q) for x, q in zip(row, column_quanta, strict=True)]
                     for row in zip(*columns.values(), strict=True))
    write_text_atomic(path, text.getvalue())
    return path


@contextmanager
def replaced_atomically(path, suffix=".tmp"):
    """Yield a temporary path beside ``path`` (``<path>.<pid><suffix>``) for the caller to
    write; on success it is ``os.replace``-d onto ``path``, on an exception removed: a killed
    or failed run never leaves a partial file."""
    tmp = os.fspath(path) + f".{os.getpid()}{suffix}"
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
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
    """Copy the file ``source`` to ``path`` (a temporary file of this process, then
    ``os.replace``); returns ``path``."""
    import shutil

    os.makedirs(os.path.dirname(os.fspath(path)) or ".", exist_ok=True)
    tmp = os.fspath(path) + f".{os.getpid()}.tmp"
    try:
        shutil.copyfile(source, tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    return path
