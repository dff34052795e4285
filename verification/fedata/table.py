"""FE-tabulated cavity-wall stress ``sigma_r(V, L)`` for one target and projectile.

The table holds the FE cavity-wall radial stress of the spherical problem at nose-tip depth
``L`` (:func:`cavex.analytic.geometry.spherical_problem`, ``switch="cavity"``) for expansion
velocity ``V``, on a grid, as a :class:`cavex.netcdf3.PlainDataset` (:func:`tabulate`, what
``cavex table`` writes without importing xarray) or an :class:`xarray.Dataset`
(:func:`build_table`), with:

- coordinates ``velocity`` (m/s; must start at 0, see ``docs/verification.md``) and ``depth``
  (nose-tip depth, m); the depth grid always contains the wall-layer switch depths
  ``H_i + l - r`` inside its range, where ``sigma_r`` is continuous but its slope is not;
- ``sigma_r``, ``S``, ``error_estimate``, ``plastic_radius`` (FE elastic-plastic boundary),
  ``failed`` on ``(velocity, depth)`` (failed cells NaN), ``wall_layer`` on ``depth``, the
  analytic ``sigma_r_dynamic`` and ``sigma_r_quasi_static`` for reference, and
  ``sigma_r_first_layer`` / ``failed_first_layer`` on ``velocity``: the first layer alone,
  semi-infinite, for the crater stage;
- attributes: the TOML text of the target and projectile, their fingerprint, the solver
  settings (JSON), package versions and the creation time; ``Conventions = "CF-1.10"``: every
  variable and coordinate has ``units`` (UDUNITS spelling,
  :mod:`cavex.verification.output.cf_metadata`)
  and ``long_name``, and ``failed``, ``failed_first_layer`` and ``wall_layer`` carry
  ``flag_values`` / ``flag_meanings``.

The FE cells are run with the shared case runner (:mod:`cavex.verification.fedata.runner`) on cases
from :func:`cavex.verification.fedata.cases.make_fe_cases`.
"""

import json
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path

import numpy as np

from cavex.analytic.geometry import spherical_problem, switch_depths, wall_layer
from cavex.config import config_text, fingerprint, fingerprint_data, projectile_table, target_table
from cavex.errors import require, require_choice
from cavex.fem.estimate import DEFAULT_ERROR_TARGET
from cavex.materials import MAX_VELOCITY
from cavex.netcdf3 import PlainDataset, write_netcdf3
from cavex.problem import BOUNDARIES
from cavex.verification.fedata.cases import CaseBuilder, fe_cases, make_fe_cases
from cavex.verification.fedata.runner import run_cases
from cavex.verification.output.cf_metadata import CONVENTIONS, UNITS, boolean_attrs, flag_attrs
from cavex.verification.output.files import replaced_atomically
from cavex.verification.output.number_format import round_variable

DEFAULT_VELOCITIES = tuple(np.linspace(0.0, 1200.0, 13))
DEFAULT_DEPTHS = tuple(np.round(np.linspace(0.10, 1.30, 31), 6))
FINGERPRINT_SCOPE = "layers (all keys) and projectile r, l: what sigma_r(V, L) depends on"
VERSIONED = ("cavex", "numpy", "scipy", "scikit-fem", "xarray")
SWITCH_REFINEMENT = (2.0, 1.0, 0.5, 0.25, 0.125)  # depths L_s - f r added above each switch
SWITCH_OFFSET = 1e-9  # m: the switch node sits this far below the switch depth
FIRST_LAYER_DEPTH = 0.0  # the single first-layer problem has no interfaces; any depth will do

#: Deepest nose depth of a table (m): far below any rigid penetration; the grid's depths are
#: rounded to 1e-12 m, which overflows beyond ~1e296 m.
MAX_DEPTH = 1e3


# --- target and projectile as TOML-schema data ------------------------------------------------

# --- the grid ---------------------------------------------------------------------------------

def switch_nodes(target, projectile):
    """Grid depths standing for the switch depths: ``L_s + SWITCH_OFFSET``.

    At ``L_s`` itself rounding may keep a zero-thickness shell of the upper layer (the FE mesh
    then degenerates); ``SWITCH_OFFSET`` past it the upper layer is surely gone. ``sigma_r`` is
    continuous there, so the node serves both segments.
    """
    return tuple(s + SWITCH_OFFSET for s in switch_depths(target, projectile))


def grid_depths(depths, target, projectile, refine=SWITCH_REFINEMENT):
    """Sorted unique ``depths`` plus, for each switch depth ``L_s`` inside their range, its
    node (:func:`switch_nodes`) and the refinement depths ``L_s - f r`` (``f`` in ``refine``).

    Just above a switch the upper layer is a shell of thickness ``delta = L_s - L`` around the
    cavity, and ``sigma_r`` changes over ``delta ~ r/4`` (it decays with distance from the wall
    like the cavity field, on the cavity radius), so the grid is refined there.
    """
    d = np.unique(np.asarray(depths, dtype=float))
    extra = []
    for s, node in zip(switch_depths(target, projectile), switch_nodes(target, projectile),
                       strict=True):
        if d[0] < s < d[-1]:
            extra += [node] + [s - f * projectile.r for f in refine
                               if s - f * projectile.r > d[0]]
    d = d[~np.any(np.abs(d[:, None] - np.asarray(extra)[None, :]) < 1e-6, axis=1)] if extra else d
    return np.unique(np.round(np.concatenate([d, extra]), 12))


def check_grid(velocities, depths):
    """Raise :class:`CavexInputError` unless the grid can be tabulated and interpolated."""
    v = np.asarray(velocities, dtype=float)
    d = np.asarray(depths, dtype=float)
    shown_v, shown_d = [float(x) for x in v.ravel()], [float(x) for x in d.ravel()]
    require(v.ndim == 1 and np.all(np.isfinite(v)) and np.all(v >= 0.0)
            and np.all(v <= MAX_VELOCITY), "velocities", f"values in [0, {MAX_VELOCITY:g}] m/s",
            shown_v)
    require(np.unique(v).size >= 2, "velocities", "at least two different values", shown_v)
    require(v.min() == 0.0, "velocities",
            "a grid that includes V = 0 (the nose tip sees V cos(phi) -> 0)", shown_v)
    require(d.ndim == 1 and np.all(np.isfinite(d)) and np.all(d >= 0.0)
            and np.all(d <= MAX_DEPTH), "depths", f"values in [0, {MAX_DEPTH:g}] m", shown_d)
    require(np.unique(d).size >= 2, "depths", "at least two different values", shown_d)


# --- building ---------------------------------------------------------------------------------

def build_table(target, projectile, velocities, depths, **options):
    """:func:`tabulate`'s table as an :class:`xarray.Dataset` (xarray loaded while the FE
    workers compute: :func:`load_table_dataset`)."""
    return tabulate(target, projectile, velocities, depths, while_running=load_table_dataset,
                    **options).dataset()


def tabulate(target, projectile, velocities, depths, *, nu=None, numerics=None,
             error_target=DEFAULT_ERROR_TARGET, scheduler=None, workers=None, store=None,
             progress=None, refine=SWITCH_REFINEMENT, while_running=None):
    """FE cavity-wall stress on the ``(velocity, depth)`` grid, as a
    :class:`cavex.netcdf3.PlainDataset` (plain arrays: no xarray).

    Parameters
    ----------
    target, projectile : Target, Projectile
    velocities : sequence of float
        Expansion velocities (m/s); must include 0. Sorted and made unique.
    depths : sequence of float
        Nose-tip depths (m); the wall-layer switch depths inside their range are added.
    nu : float, optional
        Poisson's ratio for every layer (default: each layer's own).
    numerics : dict, optional
        Settings of :class:`cavex.fem.Numerics`.
    error_target : float or None
        A cell whose estimated FE error exceeds this is refined (twice the space and time
        resolution, at most twice; default 0.5 %); None: every cell at ``numerics``.
    scheduler, workers, store, progress
        Passed to :func:`cavex.verification.fedata.runner.run_cases`.
    refine : sequence of float
        Depths ``L_s - f r`` added above each switch depth (see :func:`grid_depths`).
    while_running : callable, optional
        Passed to :func:`~cavex.verification.fedata.runner.run_cases`: what to load while the
        FE workers compute (default :func:`load_table_writer`, what :func:`write_table` needs).

    Returns
    -------
    cavex.netcdf3.PlainDataset
        See the module docstring; failed cells are NaN with ``failed`` True and their reasons
        in the ``failures`` attribute (JSON).
    """
    check_grid(velocities, depths)
    v = np.unique(np.asarray(velocities, dtype=float))
    d = grid_depths(depths, target, projectile, refine)
    grid = table_cases(target, projectile, v, d, nu, numerics, error_target)
    first = [case.renamed(f"first-layer-{case['id']}") for case in
             table_cases(target.single(0), projectile, v, [FIRST_LAYER_DEPTH], nu, numerics,
                         error_target)]
    # the closed forms first: they load numba's compiled-code machinery once in this process,
    # before the worker processes are forked from it, so that they inherit it (measured on the
    # issue grid: ~0.4 s of CPU less per worker)
    reference = analytic_grid(target, projectile, v, d)
    results = run_cases(fe_cases, grid + first, store=store, scheduler=scheduler,
                        workers=workers, progress=progress,
                        while_running=while_running or load_table_writer)
    cells = _cells(results[:len(grid)], grid, v, d)
    crater = _cells(results[len(grid):], first, v, [FIRST_LAYER_DEPTH])
    return assemble_table(target, projectile, v, d, cells, crater,
                          settings_json(nu, numerics, error_target), reference)


def load_table_writer():
    """Import what :func:`write_table` writes with (:mod:`scipy.io`, which loads all its
    formats: ~0.1-0.2 s of CPU), done by :func:`tabulate` while the FE workers compute
    (``run_cases(while_running=...)``)."""
    import scipy.io  # noqa: F401


def load_table_dataset():
    """Import xarray and what it loads on the first dataset (dask, probed for chunked arrays):
    ~0.5 s of CPU, which :func:`build_table` spends while the FE workers compute."""
    import xarray as xr

    xr.Dataset({"warm": ("n", np.zeros(1))})


def table_cases(target, projectile, velocities, depths, nu, numerics,
                error_target=DEFAULT_ERROR_TARGET):
    """FE cases in the order velocity-major, depth-minor (``V = 0`` is a quasi-static run)."""
    return make_fe_cases(target_table(target), projectile_table(projectile), velocities,
                         depths, nu=nu, numerics=numerics, error_target=error_target,
                         build=CaseBuilder(target, projectile))


def _cells(results, cases, velocities, depths):
    """Grid arrays ``sigma_r``, ``S``, ``error_estimate``, ``plastic_radius``, ``failed`` and the
    failure list."""
    shape = (len(velocities), len(depths))
    out = {k: np.full(shape, np.nan) for k in ("sigma_r", "S", "error_estimate",
                                                "plastic_radius")}
    failed = np.zeros(shape, dtype=bool)
    failures = []
    for case, result in zip(cases, results, strict=True):
        i = int(np.searchsorted(velocities, case["velocity"]))
        j = int(np.searchsorted(depths, case["depth"]))
        if result.get("status") != "ok":
            failed[i, j] = True
            failures.append({"velocity": float(case["velocity"]), "depth": float(case["depth"]),
                             "reason": str(result.get("reason", ""))})
            continue
        out["sigma_r"][i, j] = result["fe_sigma_r_Pa"]
        out["S"][i, j] = result["S"]
        out["plastic_radius"][i, j] = result["fe_plastic_radius_m"]
        estimate = result.get("error_estimate")
        out["error_estimate"][i, j] = np.nan if estimate is None else estimate
    return {**out, "failed": failed, "failures": failures}


def settings_json(nu, numerics, error_target=DEFAULT_ERROR_TARGET):
    """Solver settings (``nu``, every :class:`~cavex.fem.Numerics` value and the error target)
    as JSON."""
    from cavex.fem.settings import make_numerics

    return json.dumps({"nu": nu, "numerics": make_numerics(**(numerics or {})).as_dict(),
                       "error_target": error_target, "switch": "cavity"}, sort_keys=True)


def analytic_table(target, projectile, velocities, depths, boundary="dynamic",
                   refine=SWITCH_REFINEMENT):
    """A table filled from the closed form instead of the FE (for tests and comparisons).

    ``sigma_r`` and ``plastic_radius`` are the closed form's (:func:`cavex.analytic.cavity_solution`
    with ``boundary``); the grid is built as :func:`build_table` builds it.
    """
    check_grid(velocities, depths)
    require_choice(boundary, BOUNDARIES, "boundary")
    v = np.unique(np.asarray(velocities, dtype=float))
    d = grid_depths(depths, target, projectile, refine)

    def cells(tgt, ds, closed):
        sigma, b = closed[boundary]
        tau = np.array([tgt.layers[wall_layer(tgt, projectile, L)].tau for L in ds])
        return {"sigma_r": sigma, "S": sigma / tau, "error_estimate": np.zeros_like(sigma),
                "plastic_radius": b,
                "failed": np.zeros(sigma.shape, dtype=bool), "failures": []}

    reference = analytic_grid(target, projectile, v, d)
    first = target.single(0)
    return assemble_table(target, projectile, v, d, cells(target, d, reference),
                          cells(first, [FIRST_LAYER_DEPTH],
                                analytic_grid(first, projectile, v, [FIRST_LAYER_DEPTH],
                                              (boundary,))),
                          json.dumps({"analytic": boundary, "switch": "cavity"}),
                          reference).dataset()


def analytic_grid(target, projectile, velocities, depths, boundaries=BOUNDARIES):
    """The closed forms on the grid, each cell once
    (:func:`cavex.verification.fedata.comparison.closed_forms`): ``{boundary: (sigma_r,
    plastic_radius)}``, arrays of shape ``(velocities, depths)``."""
    from cavex.verification.fedata.comparison import closed_forms  # scikit-fem: not at the top

    columns = [spherical_problem(target, projectile, float(L)) for L in depths]
    problems = [(layers, interfaces, float(V), projectile.r)
                for V in velocities for layers, interfaces in columns]
    shape = (len(velocities), len(depths))
    return {b: (stress.reshape(shape), radius.reshape(shape))
            for b, (stress, radius) in closed_forms(problems, boundaries).items()}


def assemble_table(target, projectile, velocities, depths, cells, crater, settings, reference):
    """The table (a :class:`cavex.netcdf3.PlainDataset`) from grid arrays (see
    :func:`tabulate`); ``reference`` holds the closed forms on the grid (:func:`analytic_grid`)."""
    v, d = np.asarray(velocities, dtype=float), np.asarray(depths, dtype=float)
    grid = ("velocity", "depth")
    names = target.layer_names()
    data = {
        "sigma_r": (grid, cells["sigma_r"], _attrs("Pa", "FE cavity-wall radial stress, "
                                                   "compression positive")),
        "S": (grid, cells["S"], _attrs("1", "sigma_r / tau of the wall layer")),
        "error_estimate": (grid, cells["error_estimate"],
                           _attrs("1", "FE relative discretisation error (Richardson)")),
        "plastic_radius": (grid, cells["plastic_radius"],
                           _attrs("m", "FE elastic-plastic boundary radius b")),
        "failed": (grid, cells["failed"],
                   boolean_attrs("FE run failed (cell is NaN)", "ok", "failed")),
        "wall_layer": ("depth", np.array([wall_layer(target, projectile, L) for L in d],
                                         dtype=np.int32),
                       flag_attrs(range(len(names)), names, "index of the layer at the cavity "
                                  "wall; names in attribute layer_names", np.int32)),
        "sigma_r_first_layer": ("velocity", cells_first(crater, "sigma_r"),
                                _attrs("Pa", "FE cavity-wall stress, first layer alone "
                                             "(crater stage)")),
        "failed_first_layer": ("velocity", cells_first(crater, "failed"),
                               boolean_attrs("FE first-layer run failed", "ok", "failed")),
    }
    for boundary in BOUNDARIES:
        data["sigma_r_" + boundary.replace("-", "_")] = (
            grid, reference[boundary][0],
            _attrs("Pa", f"analytic cavity-wall stress, {boundary} boundary (reference)"))
    coords = {"velocity": ("velocity", v, _attrs(UNITS["velocity"],
                                                 "cavity expansion velocity V")),
              "depth": ("depth", d, _attrs(UNITS["length"], "nose-tip depth L"))}
    attrs = {**table_attrs(target, projectile, settings), "layer_names": json.dumps(names),
             "failures": json.dumps(cells["failures"] + crater["failures"])}
    return PlainDataset(data, coords, attrs)


def cells_first(crater, key):
    """The single-depth column of the first-layer cells."""
    return crater[key][:, 0]


def _attrs(units, long_name):
    return {"units": units, "long_name": long_name}


def table_attrs(target, projectile, settings):
    """Global attributes: TOML text, fingerprint, settings, versions, creation time."""
    return {
        "Conventions": CONVENTIONS,
        "title": "cavex FE-tabulated cavity-wall stress sigma_r(V, L)",
        "target": config_text(target, projectile),
        "fingerprint": fingerprint(target, projectile),
        "fingerprint_scope": FINGERPRINT_SCOPE,
        "fingerprint_data": json.dumps(fingerprint_data(target, projectile), sort_keys=True),
        "solver_settings": settings,
        "versions": json.dumps({name: _version(name) for name in VERSIONED}),
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
    }


def _version(name):
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "unknown"


# --- files ------------------------------------------------------------------------------------

# attributes that would make the same table a different file: when it was made, where it was read
UNREPRODUCIBLE_ATTRS = ("created", "source")


def reproducible_table(table):
    """``table`` (a :class:`~cavex.netcdf3.PlainDataset`) as :func:`write_table` writes it by
    default: float data variables rounded to
    :func:`~cavex.verification.output.number_format.variable_digits`, without the attributes
    of :data:`UNREPRODUCIBLE_ATTRS`."""
    data = {name: (dims, round_variable(name, values), attrs)
            for name, (dims, values, attrs) in table.data.items()}
    return PlainDataset(data, table.coords, {k: v for k, v in table.attrs.items()
                                             if k not in UNREPRODUCIBLE_ATTRS}, table.order)


def write_table(table, path, *, reproducible=True):
    """Write ``table`` (a :class:`~cavex.netcdf3.PlainDataset` or an :class:`xarray.Dataset`)
    as netCDF-3 (:func:`cavex.netcdf3.write_netcdf3`: the file xarray's scipy engine writes,
    without importing xarray), atomically (a temporary file, then ``os.replace``); returns
    ``path``.

    ``reproducible`` (default): the same table computed on another CPU gives the same file
    (:func:`reproducible_table`: float data variables rounded to the significant digits the
    numerics support, the attributes in :data:`UNREPRODUCIBLE_ATTRS` left out). ``table``
    itself is not changed. False: written exactly as it is.
    """
    table = table if isinstance(table, PlainDataset) else PlainDataset.from_dataset(table)
    if reproducible:
        table = reproducible_table(table)
    path = Path(path)
    if path.parent != Path(""):
        path.parent.mkdir(parents=True, exist_ok=True)
    with replaced_atomically(path) as tmp:
        write_netcdf3(tmp, table.variables(), table.attrs)
    return path
