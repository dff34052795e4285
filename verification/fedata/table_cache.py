"""The FE-table cache shared by every command and run (``cavex validate``, ``cavex calibrate
--resistance table``).

A table is a pure function of its target and projectile (:func:`cavex.config.fingerprint`), its
velocity and depth grid and the solver settings
(:func:`cavex.verification.fedata.table.settings_json`); the entry's key is the first 16 hex
digits of ``sha256(json([fingerprint, velocities, depths, settings]))`` and its file
``<folder>/table_<key>.nc`` (:func:`cavex.verification.fedata.table.write_table`: a temporary
file of the writing process, then ``os.replace``, so concurrent runs never see half a file).

The folder is ``$CAVEX_CACHE_DIR``, else ``$XDG_CACHE_HOME/cavex/tables``, else
``~/.cache/cavex/tables``. An entry is never trusted (:func:`entry_problem`): one that cannot be
read, whose attributes do not parse, was built for another target, has another velocity grid or
another solver setting, was made by another cavex version, holds failed FE cells, or holds a
stress that is not finite and positive (or above :data:`STRESS_LIMIT_PA`) is rebuilt and
replaced, with one line on stderr naming it and the reason.

An unusable folder (read-only, a file where the folder should be, a symlink loop) is found
before any FE work (:func:`folder_problem`); a store that fails (a full disk) is found when
it fails: either way the run goes on without the cache after one warning line.

Concurrent runs: a table is claimed (:func:`claimed`: an exclusive ``flock`` on
``table_<key>.nc.lock``, released by the kernel when its holder ends, also on ``kill -9``):
one run builds it, the others wait, then read it.

Size: the folder is kept under ``$CAVEX_CACHE_MAX_MB`` megabytes (default 500; a number > 0):
after each store the least recently used entries (oldest modification time; a reused entry is
touched) are deleted until the rest fit, never the entry just stored. Temporary files count:
a killed writer's (:func:`cavex.verification.output.files.stale_temporary`) is removed, a live
writer's is counted.
"""

import functools
import hashlib
import json
import os
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from cavex.errors import CavexInputError

#: no cached cavity-wall stress is trusted above this (Pa): 10 TPa, over ten times the
#: stagnation pressure rho V^2 of steel (7850 kg/m^3) at 10 km/s (7.9e11 Pa)
STRESS_LIMIT_PA = 1e13
#: the stress variables of a table checked when read (finite, > 0, <= STRESS_LIMIT_PA
#: where the cell did not fail)
STRESS_VARIABLES = ("sigma_r", "sigma_r_first_layer")
_warned = set()  # the folders already warned about in this process (one line each)

CACHE_ENV = "CAVEX_CACHE_DIR"
SIZE_ENV = "CAVEX_CACHE_MAX_MB"
DEFAULT_MAX_MB = 500.0


def max_bytes(environ=None):
    """The cache's size limit in bytes: ``$CAVEX_CACHE_MAX_MB`` megabytes (a finite number
    > 0), default :data:`DEFAULT_MAX_MB`."""
    environ = os.environ if environ is None else environ
    text = environ.get(SIZE_ENV, "")
    if not text:
        return DEFAULT_MAX_MB * 1e6
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value > 0.0 and value != float("inf")):
        raise CavexInputError(f"parameter '{SIZE_ENV}' (environment) must be a finite number "
                              f"of megabytes > 0, got {text!r}", SIZE_ENV)
    return value * 1e6


def prune(directory, keep, limit):
    """Delete the least recently used ``table_*.nc`` of ``directory`` (oldest modification
    time first) until the folder's tables and live temporary files take at most ``limit``
    bytes (stale temporary files are removed first); ``keep`` (a path) is never deleted.
    Returns the deleted paths."""
    entries = []
    total = remove_stale_temporaries(directory)
    for path in Path(directory).glob("table_*.nc"):
        try:
            status = path.stat()
        except OSError:  # removed by a concurrent run
            continue
        entries.append((status.st_mtime, path, status.st_size))
    total += sum(size for _, _, size in entries)
    deleted = []
    for _, path, size in sorted(entries):
        if total <= limit:
            break
        if Path(path) == Path(keep):
            continue
        try:
            path.unlink()
        except OSError:
            continue
        total -= size
        deleted.append(path)
    return deleted


def is_temporary(name):
    """Whether ``name`` is a temporary file of a table being written (this cavex's
    ``.table_<key>.nc.<pid>.<random>.tmp`` or an older ``table_<key>.nc.<pid>.tmp``)."""
    return name.endswith(".tmp") and (name.startswith(".table_") or name.startswith("table_"))


def remove_stale_temporaries(directory):
    """Remove the temporary files of killed writers in ``directory``; returns the bytes the
    live ones (being written now) take."""
    from cavex.verification.output.files import stale_temporary

    live = 0
    try:
        names = os.listdir(directory)
    except OSError:
        return 0
    for name in names:
        if not is_temporary(name):
            continue
        path = os.path.join(directory, name)
        try:
            if stale_temporary(name):
                os.remove(path)
            else:
                live += os.lstat(path).st_size
        except OSError:  # finished or removed meanwhile
            continue
    return live


def folder_problem(directory):
    """None if ``directory`` can hold the cache, else the reason in words: it is a folder in
    which a file can be created and removed, or its nearest existing parent is (nothing is
    created: the folder is made by the first store)."""
    from cavex.verification.output.files import exclusive_temporary

    existing = Path(directory)
    while not existing.exists() and not existing.is_symlink() and existing.parent != existing:
        existing = existing.parent
    if not existing.is_dir():
        return f"'{existing}' is not a folder"
    try:
        handle, name = exclusive_temporary(existing / "table_check")
        os.close(handle)
        os.remove(name)
    except OSError as exc:
        return exc.strerror or str(exc)
    if existing == Path(directory):
        remove_stale_temporaries(directory)
    return None


def warn(directory, reason):
    """One line on stderr (once per folder and process): the cache is not used."""
    key = os.fspath(directory)
    if key not in _warned:
        _warned.add(key)
        print(f"cavex: warning: FE-table cache folder '{key}' is unusable ({reason}); going on "
              f"without the cache (set {CACHE_ENV} to a writable folder)", file=sys.stderr,
              flush=True)


@contextmanager
def claimed(path):
    """Hold an exclusive claim on the entry ``path`` (``flock`` on ``<path>.lock``, opened
    with ``O_NOFOLLOW``) for the block: another run claiming it waits (one line on stderr)
    until this one has stored it. A lock that cannot be made (a planted symlink, a read-only
    folder) claims nothing: the block runs unclaimed."""
    import fcntl

    lock = os.fspath(path) + ".lock"
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)  # the first claim makes the folder
        handle = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o666)
    except OSError:
        yield
        return
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            print(f"cavex: waiting for another run building '{path}'", file=sys.stderr,
                  flush=True)
            fcntl.flock(handle, fcntl.LOCK_EX)
        yield
    finally:
        os.close(handle)  # releases the lock


def cache_dir(environ=None):
    """The cache folder: ``$CAVEX_CACHE_DIR``, ``$XDG_CACHE_HOME/cavex/tables`` or
    ``~/.cache/cavex/tables`` (the first set and non-empty)."""
    environ = os.environ if environ is None else environ
    if environ.get(CACHE_ENV):
        return Path(environ[CACHE_ENV]).expanduser()
    base = environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base).expanduser() / "cavex" / "tables"


def table_key(target, projectile, velocities, depths, numerics=None):
    """16 hex digits identifying a table: fingerprint, grid and solver settings."""
    from cavex.config import fingerprint
    from cavex.verification.fedata.table import settings_json

    text = json.dumps([fingerprint(target, projectile), list(velocities), list(depths),
                       settings_json(None, numerics)])
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def entry_path(key, directory=None):
    """``<folder>/table_<key>.nc`` (folder: :func:`cache_dir` unless given)."""
    return Path(cache_dir() if directory is None else directory) / f"table_{key}.nc"


def load_entry(path, target, projectile, velocities, numerics=None):
    """The cached table at ``path``, or None when it is missing or cannot be trusted
    (:func:`read_entry`)."""
    return read_entry(path, target, projectile, velocities, numerics)[0]


def read_entry(path, target, projectile, velocities, numerics=None):
    """``(table, None)`` for a trusted entry at ``path`` (touched: the last to go when the
    cache is pruned); ``(None, None)`` when there is none; ``(None, reason)`` when the entry
    cannot be trusted (:func:`entry_problem`)."""
    from cavex.analytic.penetration.tabulated import load_table

    if not os.path.lexists(path):
        return None, None
    if os.path.islink(path) or not os.path.isfile(path):
        return None, "not a regular file"
    try:
        table = load_table(path)
    except CavexInputError as exc:
        return None, str(exc)
    except Exception as exc:  # a damaged file fails in many ways inside the reader
        return None, f"{type(exc).__name__}: {exc}"
    reason = entry_problem(table, target, projectile, velocities, numerics, str(path))
    if reason is not None:
        return None, reason
    try:
        os.utime(path)  # used now: the last to go when the cache is pruned
    except OSError:
        pass
    return table, None


def entry_problem(table, target, projectile, velocities, numerics=None, name="entry"):
    """None if ``table`` is the table of this target, projectile, velocity grid, solver
    settings and cavex version, without failed cells and with finite, positive stresses
    (at most :data:`STRESS_LIMIT_PA`); else the reason in words."""
    from cavex.analytic.penetration.tabulated import check_fingerprint
    from cavex.verification.fedata.table import settings_json

    try:
        check_fingerprint(table, target, projectile, name)
        versions = json.loads(table.attrs.get("versions", "{}"))
    except CavexInputError as exc:
        return str(exc)
    except (ValueError, TypeError):
        return "its attributes do not parse"
    if not isinstance(versions, dict) or versions.get("cavex") != _cavex_version():
        return "made by another cavex version"
    if table.attrs.get("solver_settings") != settings_json(None, numerics):
        return "other solver settings"
    grid = np.asarray(table["velocity"].values, dtype=float)
    if grid.shape != (len(velocities),) or not np.allclose(grid, velocities, rtol=1e-9):
        return "another velocity grid"
    failed = np.asarray(table["failed"].values, dtype=bool)
    failed_first = np.asarray(table["failed_first_layer"].values, dtype=bool)
    if failed.any() or failed_first.any():
        return "it holds failed FE cells"
    for name_ in STRESS_VARIABLES:
        values = np.asarray(table[name_].values, dtype=float)
        if not (np.isfinite(values).all() and (values > 0.0).all()
                and (values <= STRESS_LIMIT_PA).all()):
            return f"'{name_}' holds values that are not finite, positive and <= " \
                f"{STRESS_LIMIT_PA:g} Pa"
    return None


def store(table, path):
    """Write ``table`` to ``path`` atomically and return it as read back (rounded as stored);
    an ``OSError`` (a full disk) leaves no file and is the caller's to handle."""
    from cavex.analytic.penetration.tabulated import load_table
    from cavex.verification.fedata.table import write_table

    write_table(table, path)
    prune(Path(path).parent, path, max_bytes())
    return load_table(path)


@functools.lru_cache(maxsize=1)
def _cavex_version():
    from cavex.verification.fedata.table import _version

    return _version("cavex")
