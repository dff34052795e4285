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
"""

import hashlib
import json
import os
from pathlib import Path

import numpy as np

from cavex.errors import CavexInputError

CACHE_ENV = "CAVEX_CACHE_DIR"


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
    return table


def store(table, path):
    """Write ``table`` to ``path`` atomically and return it as read back (rounded as stored)."""
    from cavex.analytic.penetration.tabulated import load_table
    from cavex.verification.fedata.table import write_table

    write_table(table, path)
    return load_table(path)


def _cavex_version():
    from cavex.verification.fedata.table import _version

    return _version("cavex")
