"""The FE-table cache shared by every command and run (``cavex validate``, ``cavex calibrate
--resistance table``).

A table is a pure function of its target and projectile (:func:`cavex.config.fingerprint`), its
velocity and depth grid and the solver settings
(:func:`cavex.verification.fedata.table.settings_json`); the entry's key is the first 16 hex
digits of ``sha256(json([fingerprint, velocities, depths, settings]))`` and its file
``<folder>/table_<key>.nc`` (:func:`cavex.verification.fedata.table.write_table`: a temporary
file of the writing process, then ``os.replace``, so concurrent runs never see half a file).

The folder is ``$CAVEX_CACHE_DIR``, else ``$XDG_CACHE_HOME/cavex/tables``, else
``~/.cache/cavex/tables``. An entry is never trusted: one that cannot be read, was built for
another target, has another velocity grid or another solver setting, or was made by another
cavex version is rebuilt and replaced.

Size: the folder is kept under ``$CAVEX_CACHE_MAX_MB`` megabytes (default 500; a number > 0):
after each store the least recently used entries (oldest modification time; a reused entry is
touched) are deleted until the rest fit, never the entry just stored.
"""

import hashlib
import json
import os
from pathlib import Path

import numpy as np

from cavex.errors import CavexInputError

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
    time first) until the folder's tables take at most ``limit`` bytes; ``keep`` (a path) is
    never deleted. Returns the deleted paths."""
    entries = []
    for path in Path(directory).glob("table_*.nc"):
        try:
            status = path.stat()
        except OSError:  # removed by a concurrent run
            continue
        entries.append((status.st_mtime, path, status.st_size))
    total = sum(size for _, _, size in entries)
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
    """The cached table at ``path``, or None when it is missing or cannot be trusted (unreadable,
    another target, another velocity grid, other solver settings, another cavex version)."""
    from cavex.analytic.penetration.tabulated import check_fingerprint, load_table
    from cavex.verification.fedata.table import settings_json

    if not Path(path).exists():
        return None
    try:
        table = load_table(path)
        check_fingerprint(table, target, projectile, str(path))
    except CavexInputError:
        return None
    grid = np.asarray(table["velocity"].values, dtype=float)
    if grid.shape != (len(velocities),) or not np.allclose(grid, velocities, rtol=1e-9):
        return None
    if table.attrs.get("solver_settings") != settings_json(None, numerics):
        return None
    if json.loads(table.attrs.get("versions", "{}")).get("cavex") != _cavex_version():
        return None
    try:
        os.utime(path)  # used now: the last to go when the cache is pruned
    except OSError:
        pass
    return table


def store(table, path):
    """Write ``table`` to ``path`` atomically and return it as read back (rounded as stored)."""
    from cavex.analytic.penetration.tabulated import load_table
    from cavex.verification.fedata.table import write_table

    write_table(table, path)
    prune(Path(path).parent, path, max_bytes())
    return load_table(path)


def _cavex_version():
    from cavex.verification.fedata.table import _version

    return _version("cavex")
