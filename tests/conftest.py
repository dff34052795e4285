"""Shared fixtures for the cavex tests.

The numbers here are typed in from the paper's Table 1 (She 2020; docs/problem.md section 3),
not read from ``core/data/runway.toml``, so that the embedded default can be checked against
them.

Every test runs with its own FE-table cache (``CAVEX_CACHE_DIR`` in its temporary folder, also
for the commands it starts), so the suite never reads or writes the user's cache; a session-wide
temporary cache covers the fixtures of wider scope.
"""

import os
import shutil
import signal
import tempfile

import pytest

from cavex.verification.fedata.table_cache import CACHE_ENV

_SESSION_CACHE = tempfile.mkdtemp(prefix="cavex-test-cache-")
os.environ[CACHE_ENV] = _SESSION_CACHE


def pytest_unconfigure(config):
    """Remove the session-wide table cache."""
    shutil.rmtree(_SESSION_CACHE, ignore_errors=True)


# The modules with the largest summed durations (measured 2026-11-27, fourth session, warm
# caches, largest first: the concrete solver's 10 100-point sweep about 120 s, the held
# contact's added-turn series about 35 s, the signal faults about 45 s in 13 runs, the edge
# cases, the documentation site with its notebooks, the 3-D integrator's checks). They run
# first, so that on two workers (pyproject addopts: each module on one worker, taken in
# collection order, --no-loadscope-reorder) no long module starts last while the other worker
# idles. The held contact comes second, so that the 3-D kernel is compiled by one worker (46 s
# of CPU on a cold numba cache, measured) while the other runs the sweep.
HEAVY_FIRST = ("test_concrete_cavity_sweep.py", "test_contact_hold.py",
               "test_faults_signals.py", "test_edges.py", "test_docs_site.py",
               "test_oblique.py", "test_plain_law_1d.py", "test_validation.py",
               "test_notebooks.py", "test_interfaces.py", "test_adversarial.py",
               "test_contact_hold_balances.py", "test_entry_crater.py",
               "test_command_figures.py")


def pytest_collection_modifyitems(items):
    """Put the modules of :data:`HEAVY_FIRST` first, in that order (a stable sort: the order
    within a module and of the other modules is kept)."""
    rank = {name: k for k, name in enumerate(HEAVY_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))


@pytest.fixture(autouse=True, scope="session")
def interruptible():
    """Ctrl-C reaches the suite's processes as it reaches a user's. A suite started where SIGINT
    is ignored (a background job of a shell without job control) passes the ignore on to every
    process it starts, and cavex keeps an ignored signal ignored (``staged_output``), so the
    tests that interrupt a run could not: the default handler is restored (its children then
    start with SIGINT at its default)."""
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    yield


@pytest.fixture(autouse=True)
def table_cache_dir(tmp_path, monkeypatch):
    """This test's FE-table cache folder (``$CAVEX_CACHE_DIR``)."""
    folder = tmp_path / "cavex-table-cache"
    monkeypatch.setenv(CACHE_ENV, str(folder))
    return folder

TABLE1_PROJECTILE = {"r": 0.0125, "l": 0.06, "R": 0.075, "m": 0.505, "V0": 1000.0}

TABLE1_LAYERS = (
    {"name": "concrete", "rho": 2500.0, "E": 25e9, "tau": 25e6, "lam": 0.15},
    {"name": "macadam", "rho": 1800.0, "E": 10e9, "tau": 10e6, "lam": 0.35},
    {"name": "soil", "rho": 1600.0, "E": 0.12e9, "tau": 6e6, "lam": 0.50},
)

TABLE1_INTERFACE_DEPTHS = (0.65, 1.1)


@pytest.fixture
def table1():
    """The paper's Table 1: projectile, layer properties and interface depths ``H1, H2`` (m).

    Returns
    -------
    dict
        ``{"projectile": {...}, "layers": (dict, dict, dict), "interface_depths": (H1, H2)}``.
    """
    return {
        "projectile": dict(TABLE1_PROJECTILE),
        "layers": tuple(dict(layer) for layer in TABLE1_LAYERS),
        "interface_depths": TABLE1_INTERFACE_DEPTHS,
    }
