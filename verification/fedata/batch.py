"""Batch sweeps: a TOML file -> validated FE cases -> :func:`run_cases` -> one xarray Dataset.

The schema is documented in ``docs/verification.md`` ("Batch sweeps"). Every listed value is an
axis of the Cartesian product; a scalar is a fixed setting. Everything is validated (unknown
keys, types, ranges, by constructing the same ``Material``/``Numerics`` objects the FE run
will) before the first case runs.

Files in ``out_dir``: ``sweep.json`` (the axes and case ids), ``cases/<id>.json`` (one per
finished case, the resumable store) and ``results.nc`` (the Dataset, netCDF3 via scipy).
"""

import itertools
import json
import os
import re
from dataclasses import dataclass, field

import numpy as np

from cavex.config import parse_projectile, parse_target
from cavex.errors import CavexInputError, check_keys, is_finite_number, prefixed, require
from cavex.fem.settings import make_numerics
from cavex.input_files import in_file, read_toml
from cavex.materials import MAX_VELOCITY, material_parameters
from cavex.verification.fedata.cases import (
    CaseBuilder,
    config_tables,
    fe_case_id,
    fe_cases,
    numerics_names,
)
from cavex.verification.fedata.runner import check_execution, check_store, read_store, run_cases
from cavex.verification.fedata.table import MAX_DEPTH
from cavex.verification.output.cf_metadata import CONVENTIONS, boolean_attrs
from cavex.verification.output.files import replaced_atomically, write_text_atomic
from cavex.verification.output.paths import check_output_dir

SECTIONS = ("sweep", "target", "grid", "numerics", "materials")
SWEEP_KEYS = ("name", "scheduler", "workers")
TARGET_KEYS = ("config", "layers", "projectile")
GRID_KEYS = ("velocities", "depths", "nu")
#: a layer's sweepable properties and their units: its thickness and the material's parameters
PROPERTY_UNITS = {"thickness": "m", **material_parameters()}
MATERIAL_PROPERTIES = tuple(PROPERTY_UNITS)
NUMERICS_UNITS = {"seed_radius": "m", "tension_cutoff": "Pa", "dilatancy_deg": "degree"}
SWEEP_FILE, STORE_DIR, RESULTS_FILE = "sweep.json", "cases", "results.nc"

VARIABLES = {  # name: (path in the comparison record of a case, units, long name)
    "fe_sigma_r": (("fe_sigma_r_Pa",), "Pa", "FE radial stress at the cavity wall"),
    "S": (("S",), "1", "FE wall stress over the wall layer's tau"),
    "error_estimate": (("error_estimate",), "1",
                       "FE relative discretisation error estimate (NaN: not estimated)"),
    "analytic_sigma_r_dynamic": (("analytic_sigma_r_Pa", "dynamic"), "Pa",
                                 "closed-form wall stress, dynamic boundary convention"),
    "analytic_sigma_r_quasi_static": (("analytic_sigma_r_Pa", "quasi-static"), "Pa",
                                      "closed-form wall stress, quasi-static convention"),
    "relative_difference_dynamic": (("relative_difference", "dynamic"), "1",
                                    "fe_sigma_r / analytic_sigma_r_dynamic - 1"),
    "relative_difference_quasi_static": (("relative_difference", "quasi-static"), "1",
                                         "fe_sigma_r / analytic_sigma_r_quasi_static - 1"),
    "fe_plastic_radius": (("fe_plastic_radius_m",), "m", "FE elastic-plastic boundary radius"),
    "analytic_plastic_radius_dynamic": (("analytic_plastic_radius_m", "dynamic"), "m",
                                        "closed-form plastic radius, dynamic convention"),
    "analytic_plastic_radius_quasi_static": (("analytic_plastic_radius_m", "quasi-static"), "m",
                                             "closed-form plastic radius, quasi-static"),
    "wall_time": (("wall_time_s",), "s", "FE run time (not reproducible)"),
}


@dataclass(frozen=True)
class Axis:
    """One swept key: a Dataset dimension."""

    name: str
    kind: str  # "grid", "material" or "numerics"
    key: tuple  # ("velocity",), ("layer", index, property) or ("numerics", setting)
    values: tuple
    units: str
    long_name: str


@dataclass
class Sweep:
    """A validated sweep: base tables, fixed settings and the axes of the product."""

    name: str
    scheduler: str | None
    workers: int | None
    layers: list
    projectile: dict
    axes: list
    nu: float | None = None
    numerics: dict = field(default_factory=dict)


# --- reading and validating ---------------------------------------------------------------------

def parse_sweep(path_or_dict):
    """Validate a sweep (a TOML path or an already parsed mapping) into a :class:`Sweep`.

    Raises
    ------
    CavexInputError
        Unreadable TOML, unknown keys, wrong types or out-of-range values, naming the key; from
        a file ``'<path>': <where> <what>`` (:mod:`cavex.input_files`).
    """
    if isinstance(path_or_dict, dict):
        return _sweep(path_or_dict, os.getcwd(), "sweep")
    path = os.fspath(path_or_dict)
    data = read_toml(path)
    stem = re.sub(r"[^A-Za-z0-9._-]", "_", os.path.splitext(os.path.basename(path))[0])
    return in_file(path, _sweep, data, os.path.dirname(os.path.abspath(path)),
                   stem.lstrip("._-") or "sweep")


def _sweep(data, base_dir, default_name):
    _check_table(data, "", SECTIONS, required=("grid",))
    meta = _sweep_section(data.get("sweep", {}), default_name)
    layers, projectile = _target_section(data.get("target", {}), base_dir)
    axes, nu = _grid_section(data["grid"])
    numerics, numerics_axes = _numerics_section(data.get("numerics", {}))
    layers, material_axes = _materials_section(data.get("materials", []), layers,
                                               "nu" in data["grid"])
    refuse_debonded_layers(layers)
    axes += material_axes + numerics_axes
    names = [axis.name for axis in axes]
    duplicated = sorted({n for n in names if names.count(n) > 1})
    if duplicated:
        raise CavexInputError(f"two swept keys share the dimension name '{duplicated[0]}'")
    return Sweep(meta["name"], meta["scheduler"], meta["workers"], layers, projectile, axes,
                 nu, numerics)


def refuse_debonded_layers(layers):
    """Refuse a debonded interface (``bottom = "debonded"``), as ``stress``, ``fem``,
    ``table`` and ``verify`` do (:func:`cavex.verification.commands.options.refuse_debonded`):
    the FE cases solve the bonded spherical problem only."""
    for j, layer in enumerate(layers):
        if layer.get("bottom") == "debonded":
            raise CavexInputError("is \"debonded\", which `cavex batch` does not model (the "
                                  "spherical problem is one bonded continuum): remove the key",
                                  f"target.layers[{j}].bottom")


def _check_table(table, where, allowed, required=()):
    require(isinstance(table, dict), where.rstrip(".") or "sweep file", "a table", table)
    check_keys(table, allowed, where, required)


def _sweep_section(table, default_name):
    _check_table(table, "sweep.", SWEEP_KEYS)
    name = table.get("name", default_name)
    require(isinstance(name, str) and re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}", name)
            is not None, "sweep.name", "a plain folder name (letters, digits, '.', '_', '-'; "
            "no path)", name)
    scheduler = table.get("scheduler")
    require(scheduler is None or (isinstance(scheduler, str) and scheduler), "sweep.scheduler",
            "an address string such as 'tcp://127.0.0.1:8786'", scheduler)
    workers = table.get("workers")
    require(workers is None or (_is_int(workers) and workers >= 1), "sweep.workers",
            "an integer >= 1", workers)
    return {"name": name, "scheduler": scheduler, "workers": workers}


def _target_section(table, base_dir):
    _check_table(table, "target.", TARGET_KEYS)
    if "config" in table:
        if len(table) > 1:
            raise CavexInputError("excludes target.layers and target.projectile (give a file "
                                  "or inline tables)", "target.config")
        path = table["config"]
        require(isinstance(path, str) and path, "target.config", "a path string", path)
        try:
            return config_tables(os.path.join(base_dir, path))
        except CavexInputError as exc:
            raise CavexInputError(f"names a bad target file: {exc}", "target.config") from None
    layers, projectile = config_tables()
    if "layers" in table:
        prefixed(parse_target, "target.", table["layers"])
        layers = [dict(t) for t in table["layers"]]
    if "projectile" in table:
        prefixed(parse_projectile, "target.", table["projectile"])
        projectile = {k: float(v) for k, v in table["projectile"].items()}
    return layers, projectile


def _grid_section(table):
    _check_table(table, "grid.", GRID_KEYS, required=("velocities", "depths"))
    velocities = _number_list(table["velocities"], "grid.velocities", lambda v: v > 0, "> 0")
    depths = _number_list(table["depths"], "grid.depths", lambda v: v >= 0, ">= 0")
    for where, values, top, unit in (("grid.velocities", velocities, MAX_VELOCITY, "m/s"),
                                     ("grid.depths", depths, MAX_DEPTH, "m")):
        for i, value in enumerate(values):  # as `cavex table`; the case ids stay file names
            require(value <= top, f"{where}[{i}]", f"<= {top:g} {unit}", value)
    axes = [Axis("velocity", "grid", ("velocity",), velocities, "m s-1",
                 "cavity expansion velocity V"),
            Axis("depth", "grid", ("depth",), depths, "m", "nose-tip depth L")]
    nu = table.get("nu")
    if isinstance(nu, list):
        values = _number_list(nu, "grid.nu", lambda v: -1 < v < 0.5, "in (-1, 0.5)")
        axes.append(Axis("nu", "grid", ("nu",), values, "1", "Poisson's ratio of every layer"))
        return axes, None
    if nu is not None:
        require(is_finite_number(nu) and -1 < nu < 0.5, "grid.nu", "in (-1, 0.5)", nu)
        nu = float(nu)
    return axes, nu


def _numerics_section(table):
    _check_table(table, "numerics.", numerics_names())
    fixed, axes = {}, []
    for key, value in table.items():
        where = "numerics." + key
        if isinstance(value, list):
            values = _value_list(value, where)
            axes.append(Axis(key, "numerics", ("numerics", key), values,
                             NUMERICS_UNITS.get(key, "1"), f"FE setting {key}"))
        else:
            fixed[key] = value
    for combination in _combinations(axes):
        settings = {**fixed, **{a.key[1]: v for a, v in zip(axes, combination, strict=True)}}
        prefixed(make_numerics, "numerics.", **settings)
    return fixed, axes


def _materials_section(entries, layers, grid_sets_nu):
    require(isinstance(entries, list), "materials", "an array of tables ([[materials]])",
            entries)
    layers = [dict(t) for t in layers]
    axes, seen = [], set()
    for i, entry in enumerate(entries):
        where = f"materials[{i}]."
        _check_table(entry, where, ("layer", *MATERIAL_PROPERTIES), required=("layer",))
        index = _layer_index(entry["layer"], layers, where + "layer")
        for prop, value in entry.items():
            if prop == "layer":
                continue
            if prop == "nu" and grid_sets_nu:
                raise CavexInputError("conflicts with grid.nu (which sets every layer's nu)",
                                      f"{where}nu")
            strength = "tau" if prop == "sigma_c" else prop  # each replaces the other
            if (index, strength) in seen:
                raise CavexInputError("varies a property already given"
                                      + (" (tau and sigma_c replace each other: give one)"
                                         if strength == "tau" else ""), f"{where}{prop}")
            seen.add((index, strength))
            if isinstance(value, list):
                values = _value_list(value, where + prop)
                for j, item in enumerate(values):
                    _check_property(layers, index, prop, item, f"{where}{prop}[{j}]")
                axes.append(Axis(f"{_layer_label(layers, index)}_{prop}", "material",
                                 ("layer", index, prop), values, PROPERTY_UNITS[prop],
                                 f"{prop} of layer {_layer_label(layers, index)}"))
            else:
                _check_property(layers, index, prop, value, where + prop)
                _set_property(layers[index], prop, value)
    for combination in _combinations(axes):
        prefixed(parse_target, "target.", _apply_materials(layers, axes, combination))
    return layers, axes


def _check_property(layers, index, prop, value, where):
    """Validate one property value alone (the layer as given otherwise), naming ``where``."""
    changed = [dict(t) for t in layers]
    _set_property(changed[index], prop, value)
    try:
        parse_target(changed)
    except CavexInputError as exc:
        same = exc.where == f"layers[{index}].{prop}"  # else a check of the layer it changed
        raise CavexInputError(exc.problem if same else f"is refused ({exc})", where) from None


def _layer_index(layer, layers, where):
    if _is_int(layer):
        require(0 <= layer < len(layers), where, f"a layer index in [0, {len(layers)})", layer)
        return layer
    names = [t.get("name") for t in layers]
    require(isinstance(layer, str) and layer in names, where,
            "a layer name (" + ", ".join(map(repr, names)) + ") or index", layer)
    return names.index(layer)


def _layer_label(layers, index):
    name = re.sub(r"\W+", "_", str(layers[index].get("name", ""))).strip("_")
    return name or f"layer{index}"


def _set_property(table, prop, value):
    """Set a layer property; ``tau`` and ``sigma_c`` replace each other."""
    other = {"tau": "sigma_c", "sigma_c": "tau"}.get(prop)
    if other:
        table.pop(other, None)
    table[prop] = value


def _apply_materials(layers, axes, combination):
    layers = [dict(t) for t in layers]
    for axis, value in zip(axes, combination, strict=True):
        _set_property(layers[axis.key[1]], axis.key[2], value)
    return layers


def _number_list(values, where, condition, accepted):
    require(isinstance(values, list) and values, where, "a non-empty array of numbers", values)
    for i, value in enumerate(values):
        require(is_finite_number(value) and condition(value), f"{where}[{i}]",
                f"a finite number {accepted}", value)
    return _unique(tuple(float(v) for v in values), where)


def _value_list(values, where):
    require(values and len({type(v) for v in values}) == 1, where,
            "a non-empty array of values of one type", values)
    require(not isinstance(values[0], (list, dict)), where, "an array of scalars", values)
    return _unique(tuple(values), where)


def _unique(values, where):
    require(len(set(values)) == len(values), where, "without repeated values", list(values))
    return values


def _combinations(axes):
    return itertools.product(*(axis.values for axis in axes))


def _is_int(value):
    return isinstance(value, int) and not isinstance(value, bool)


# --- cases --------------------------------------------------------------------------------------

def sweep_cases(sweep):
    """The FE cases of a sweep (:class:`~cavex.verification.fedata.cases.FECase`, each distinct
    target and numerics parsed once), in the C order of its axes (the last axis varies
    fastest)."""
    cases = [_case(sweep, combination) for combination in _combinations(sweep.axes)]
    ids = [case["id"] for case in cases]
    if len(set(ids)) != len(ids):
        raise CavexInputError("two cases of the sweep get the same id: swept values too close "
                              "to tell apart (velocity to 1e-3 m/s, depth to 1e-5 m)")
    build = CaseBuilder()
    return [build(case) for case in cases]


def _case(sweep, combination):
    values = dict(zip((axis.name for axis in sweep.axes), combination, strict=True))
    numerics = dict(sweep.numerics)
    material_axes, material_values = [], []
    suffix = ""
    for axis, value in zip(sweep.axes, combination, strict=True):
        if axis.name not in ("velocity", "depth"):
            suffix += f"_{axis.name}{_id_text(value)}"
        if axis.kind == "numerics":
            numerics[axis.key[1]] = value
        elif axis.kind == "material":
            material_axes.append(axis)
            material_values.append(value)
    case = {"id": fe_case_id(values["velocity"], values["depth"]) + suffix,
            "velocity": values["velocity"], "depth": values["depth"]}
    nu = values.get("nu", sweep.nu)
    if nu is not None:
        case["nu"] = nu
    if numerics:
        case["numerics"] = numerics
    case["target"] = _apply_materials(sweep.layers, material_axes, material_values)
    case["projectile"] = dict(sweep.projectile)
    return case


def _id_text(value):
    if isinstance(value, float):
        return f"{value:.10g}"
    return str(value).lower() if isinstance(value, bool) else str(value)


# --- running and loading ------------------------------------------------------------------------

def file_scheduler(sweep, allowed):
    """The sweep file's ``scheduler`` if ``allowed`` (``--allow-file-scheduler``), None if it
    has none; else refused: a Dask scheduler runs code on the machine that connects to it, so a
    sweep file from someone else must not choose one (docs/verification.md)."""
    if sweep.scheduler is None or allowed:
        return sweep.scheduler
    raise CavexInputError(f"is used only with --allow-file-scheduler (got "
                          f"{sweep.scheduler!r}; a scheduler can run code on this machine): "
                          "give --scheduler, or remove the key", "sweep.scheduler")


def run_sweep(path_or_dict, out_dir, scheduler=None, workers=None, progress=None,
              chunk_size=None, allow_file_scheduler=False):
    """Validate, run (resuming from ``out_dir``) and return the sweep as one Dataset.

    Parameters
    ----------
    path_or_dict : str, os.PathLike or dict
        The sweep TOML file, or its parsed mapping (relative paths then from the cwd).
    out_dir : str or os.PathLike
        Output folder: ``sweep.json``, ``cases/<id>.json`` and ``results.nc``.
    scheduler : str or dask.distributed.Client, optional
        Overrides ``sweep.scheduler``; see :func:`cavex.verification.fedata.runner.run_cases`.
        The file's ``sweep.scheduler`` is used only with ``allow_file_scheduler``
        (:func:`file_scheduler`).
    workers : int, optional
        Overrides ``sweep.workers`` (local processes).
    progress : bool, optional
        Progress bar on stderr (None: when stderr is a terminal).
    chunk_size : int, optional
        Cases per work unit (default: one chunk per worker, at most
        :data:`cavex.verification.fedata.runner.MAX_CHUNK`); a run killed and resumed recomputes the
        cases of the chunks that had not finished.

    Returns
    -------
    xarray.Dataset
        One dimension per swept key; see :func:`load_sweep`.
    """
    sweep = parse_sweep(path_or_dict)
    cases = sweep_cases(sweep)
    out_dir = os.fspath(check_output_dir(out_dir, "out"))
    scheduler = scheduler if scheduler is not None else file_scheduler(sweep,
                                                                        allow_file_scheduler)
    workers = workers if workers is not None else sweep.workers
    check_execution(workers, scheduler)
    check_store(os.path.join(out_dir, STORE_DIR), cases)  # before sweep.json is rewritten
    # scikit-fem and numba, after the checks (bad input is refused without them) and before the
    # workers are forked (they inherit them)
    from cavex.verification.fedata.comparison import with_closed_forms

    os.makedirs(out_dir, exist_ok=True)
    description = _description(sweep, cases)
    write_text_atomic(os.path.join(out_dir, SWEEP_FILE), json.dumps(description, indent=1))
    results = run_cases(fe_cases, cases, store=os.path.join(out_dir, STORE_DIR),
                        scheduler=scheduler, workers=workers, progress=progress,
                        chunk_size=chunk_size)
    results = with_closed_forms(results, {case["id"]: case.problem for case in cases})
    dataset = _dataset(description, {r["id"]: r for r in results})
    write_sweep(dataset, os.path.join(out_dir, RESULTS_FILE))
    return dataset


def write_sweep(dataset, path):
    """Write the sweep's Dataset as netCDF-3, atomically, exactly as computed: the file
    mirrors the case store (it loads back identical to :func:`load_sweep`) and holds the wall
    times, so it is not a reproducible result file anyway. xarray's own writer: the sweep has
    text variables, which :mod:`cavex.netcdf3` does not encode."""
    with replaced_atomically(path) as tmp:
        dataset.to_netcdf(tmp, engine="scipy")
    return path


def load_sweep(out_dir):
    """The sweep in ``out_dir`` as one Dataset, from its stored cases (a partial run too); the
    closed forms are evaluated from the stored case descriptions.

    Returns
    -------
    xarray.Dataset
        Dimensions: the swept keys in file order (``velocity``, ``depth``, ``nu``,
        ``<layer>_<property>``, numerics setting names); coordinates with ``units``. Data
        variables (``units`` and ``long_name`` attributes): ``fe_sigma_r``, ``S``,
        ``error_estimate``, ``analytic_sigma_r_dynamic``, ``analytic_sigma_r_quasi_static``,
        ``relative_difference_dynamic``, ``relative_difference_quasi_static``,
        ``fe_plastic_radius``, ``analytic_plastic_radius_dynamic``,
        ``analytic_plastic_radius_quasi_static``, ``wall_time``, ``status`` ("ok", "failed",
        "missing"), ``failed`` (bool; failed or missing cells are NaN) and ``case_id``.
        Attributes: ``sweep`` (name), ``failure_reasons`` (JSON ``{id: reason}``),
        ``cases``, ``failed_cases``, ``missing_cases`` and ``fixed`` (JSON of the settings
        that are not swept).
    """
    from cavex.verification.fedata.comparison import with_closed_forms

    out_dir = os.fspath(out_dir)
    path = os.path.join(out_dir, SWEEP_FILE)
    if not os.path.exists(path):
        raise CavexInputError(f"'{out_dir}' holds no sweep (no {SWEEP_FILE})")
    with open(path, encoding="utf-8") as handle:
        description = json.load(handle)
    stored = read_store(os.path.join(out_dir, STORE_DIR))
    build = CaseBuilder()
    problems = {k: build(entry["case"]).problem for k, entry in stored.items()
                if entry["result"]["status"] == "ok"}
    results = with_closed_forms([entry["result"] for entry in stored.values()], problems)
    return _dataset(description, {r["id"]: r for r in results})


def _description(sweep, cases):
    axes = [{"name": a.name, "kind": a.kind, "values": list(a.values), "units": a.units,
             "long_name": a.long_name} for a in sweep.axes]
    fixed = {"nu": sweep.nu, "numerics": sweep.numerics, "target": sweep.layers,
             "projectile": sweep.projectile}
    return {"name": sweep.name, "axes": axes, "fixed": fixed,
            "case_ids": [case["id"] for case in cases]}


def _dataset(description, results):
    import xarray as xr

    axes = description["axes"]
    shape = tuple(len(axis["values"]) for axis in axes)
    dims = [axis["name"] for axis in axes]
    ids = description["case_ids"]
    ordered = [results.get(case_id) for case_id in ids]
    data_vars = {name: (dims, _values(ordered, path).reshape(shape),
                        {"units": units, "long_name": long_name})
                 for name, (path, units, long_name) in VARIABLES.items()}
    status = [r["status"] if r else "missing" for r in ordered]
    # text variables: a long_name, no units (CF: units belong to numbers)
    data_vars["status"] = (dims, np.array(status, dtype=str).reshape(shape),
                           {"long_name": "ok, failed (see failure_reasons) or missing"})
    data_vars["failed"] = (dims, np.array([s != "ok" for s in status]).reshape(shape),
                           boolean_attrs("the case failed or was not run; its values are NaN",
                                         "ok", "failed_or_missing"))
    data_vars["case_id"] = (dims, np.array(ids, dtype=str).reshape(shape),
                            {"long_name": "case id (file cases/<id>.json)"})
    coords = {axis["name"]: (axis["name"], np.asarray(axis["values"]), _axis_attrs(axis))
              for axis in axes}
    reasons = {r["id"]: r["reason"] for r in ordered if r and r["status"] == "failed"}
    attrs = {"Conventions": CONVENTIONS, "title": f"cavex batch sweep {description['name']}",
             "sweep": description["name"], "failure_reasons": json.dumps(reasons),
             "cases": len(ids), "failed_cases": len(reasons),
             "missing_cases": status.count("missing"),
             "fixed": json.dumps(description["fixed"])}
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def _axis_attrs(axis):
    """CF attributes of a swept coordinate: numbers with units, booleans as flags (stored as
    int8), text with a long_name only."""
    values = np.asarray(axis["values"])
    if values.dtype.kind == "b":
        return boolean_attrs(axis["long_name"], "false", "true")
    if values.dtype.kind in "US":
        return {"long_name": axis["long_name"]}
    return {"units": axis["units"], "long_name": axis["long_name"]}


def _values(results, path):
    out = np.full(len(results), np.nan)
    for i, result in enumerate(results):
        if result and result["status"] == "ok":
            value = result
            for key in path:
                value = value[key]
            out[i] = np.nan if value is None else value
    return out
