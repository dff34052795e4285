"""Numbers of the verification report: closed forms against the FE grid, cell by cell.

Everything the report states is computed here from the grid Dataset (the FE table of
:func:`cavex.verification.fedata.table.build_table`) and stored back into it, so that ``grid.nc``
holds every number the report prints.

Conventions: the relative error of a closed form is ``(analytic - FE) / FE``; ``S`` is
``sigma_r`` over ``tau`` of the layer at the cavity wall (the FE table's ``wall_layer``, the
derived model's ``"cavity"`` switch) for every model, so that the curves are comparable.

The FE and closed-form values are rounded to the digits the numerics support
(:func:`cavex.verification.output.number_format.round_dataset`) before the errors are computed, so
that every derived number is a function of the numbers ``grid.nc`` stores and comes out the
same on every CPU.
"""

import math

import numpy as np
import xarray as xr

from cavex.analytic.cavity import cavity_solution
from cavex.analytic.geometry import spherical_problem
from cavex.analytic.paper_model import paper_stress
from cavex.errors import CavexInputError
from cavex.verification.output.cf_metadata import decode_flags, flag_attrs
from cavex.verification.output.number_format import round_dataset

# (key, label, sigma_r variable) of each closed form, in report order.
MODELS = (("dynamic", "derived-dynamic", "sigma_r_dynamic"),
          ("quasi_static", "derived-quasi-static", "sigma_r_quasi_static"),
          ("paper", "paper (She 2020)", "sigma_r_paper"))
TOLERANCES = (0.01, 0.05)
# validity codes: within 1 %, within 5 %, beyond 5 %, FE cell failed
VALIDITY_LABELS = {0: "within 1 %", 1: "within 5 %", 2: "beyond 5 %", -1: "FE failed"}
# a difference is "resolved" when the FE error estimate is below this fraction of it
RESOLVED_FRACTION = 1.0 / 3.0
# named parts of (paper - FE)/FE: printed formulas, boundary convention, idealisation
ERROR_PARTS = (("formulas", "paper's printed formulas vs the derived quasi-static solution"),
               ("convention", "quasi-static vs dynamic elastic-plastic boundary"),
               ("idealisation", "incompressible small-strain closed form vs the compressible "
                                "finite-strain FE"))
# the parts that make up each closed form's (model - FE)/FE, exactly, cell by cell
MODEL_PARTS = {"dynamic": ("idealisation",), "quasi_static": ("convention", "idealisation"),
               "paper": ("formulas", "convention", "idealisation")}


def analytic_cells(target, projectile, depths, velocities):
    """Closed-form quantities on the grid, ``cells[i][j]`` a plain dict at ``velocities[i]``
    (m/s) and ``depths[j]`` (m), computed through the array form: one derived call per group
    of depths with the same layers around the cavity and per convention (every velocity at
    once); the paper's coefficients once per depth."""
    velocities = np.asarray(velocities, dtype=float)
    cells = [[{} for _ in depths] for _ in velocities]
    groups = {}  # layers around the cavity -> (depth columns, their interface radii)
    for j, depth in enumerate(depths):
        layers, interfaces = spherical_problem(target, projectile, float(depth))
        columns, radii = groups.setdefault(tuple(layers), ([], []))
        columns.append(j)
        radii.append(interfaces)
    for key, boundary in (("dynamic", "dynamic"), ("quasi_static", "quasi-static")):
        for layers, (columns, radii) in groups.items():
            interfaces = np.array(radii, dtype=float).reshape(len(columns), len(layers) - 1)
            state = cavity_solution(layers, interfaces,
                                    velocities[:, None], projectile.r, boundary=boundary)
            for i in range(len(velocities)):
                for k, j in enumerate(columns):
                    cells[i][j][f"state_{key}"] = str(state.state[i, k])
                    cells[i][j][f"b_{key}"] = float(state.plastic_radius[i, k])
    for j, depth in enumerate(depths):
        try:
            paper = paper_stress(target, projectile, float(depth), velocities)
        except CavexInputError:
            paper = np.full(len(velocities), math.nan)
        for i in range(len(velocities)):
            cells[i][j]["sigma_r_paper"] = float(paper[i])
    return cells


def add_analytic(grid, target, projectile):
    """Add ``sigma_r_paper``, ``state_*`` and ``b_*`` (derived dynamic and quasi-static).

    The response states are stored coded (``int8``, one code list for both conventions, in
    label order) with CF ``flag_values``/``flag_meanings``; :func:`state_labels` decodes them.
    """
    cells = analytic_cells(target, projectile, grid.depth.values, grid.velocity.values)
    dims = ("velocity", "depth")
    out = grid.copy()
    for key in cells[0][0]:
        if not key.startswith("state_"):
            out[key] = (dims, np.array([[c[key] for c in row] for row in cells], dtype=float))
    out["sigma_r_paper"].attrs.update(units="Pa", long_name="paper's wall stress, Eqs. 19-29")
    labels = {key: np.array([[c[f"state_{key}"] for c in row] for row in cells], dtype=str)
              for key in ("dynamic", "quasi_static")}
    vocabulary = sorted({str(x) for values in labels.values() for x in np.unique(values)},
                        key=lambda label: (len(label.split("+")[0]) > 1, label))  # letters first
    index = {label: i for i, label in enumerate(vocabulary)}
    for key in ("dynamic", "quasi_static"):
        out[f"b_{key}"].attrs.update(units="m", long_name=f"derived {key} plastic radius b")
        codes = np.vectorize(index.__getitem__, otypes=[np.int8])(labels[key])
        out[f"state_{key}"] = (dims, codes, flag_attrs(
            range(len(vocabulary)), vocabulary,
            f"derived {key.replace('_', '-')} response state (paper's Fig. 2, a-h)"))
    return out


def state_labels(grid, key):
    """Response-state labels (``"a"``, ``"c+island"``, ...) of ``state_<key>``, as strings."""
    return decode_flags(grid[f"state_{key}"])


def add_errors(grid):
    """Add ``rel_err_*``, ``validity_*`` and ``resolved_*`` for every closed form."""
    out = grid.copy()
    failed = out["failed"].astype(bool)
    fe = out["sigma_r"].where(~failed)
    for key, label, var in MODELS:
        rel = (out[var] - fe) / fe
        out[f"rel_err_{key}"] = rel.assign_attrs(units="1", long_name=f"({label} - FE) / FE")
        out[f"validity_{key}"] = validity_codes(rel, failed)
        resolved = out["error_estimate"] < RESOLVED_FRACTION * abs(rel)
        out[f"resolved_{key}"] = xr.where(failed, -1, resolved.astype(np.int8)).astype(
            np.int8).assign_attrs(flag_attrs(
                [-1, 0, 1], ["FE_failed", "not_resolved", "resolved"],
                f"FE error estimate < {RESOLVED_FRACTION:.3g} |rel_err_{key}|: resolved (1), "
                "not (0), FE failed (-1)"))
    return out


def validity_codes(rel, failed):
    """0 within 1 %, 1 within 5 %, 2 beyond, -1 failed (``int8``)."""
    mag = abs(rel)
    codes = xr.where(mag <= TOLERANCES[0], 0, xr.where(mag <= TOLERANCES[1], 1, 2))
    codes = xr.where(failed | rel.isnull(), -1, codes).astype(np.int8)
    values = sorted(VALIDITY_LABELS)
    return codes.assign_attrs(flag_attrs(
        values, [VALIDITY_LABELS[v].replace(" %", "_percent") for v in values],
        "closed form against FE: " + "; ".join(f"{k}: {v}" for k, v in
                                               VALIDITY_LABELS.items())))


def add_S(grid, target):
    """Add ``S_<model>`` = analytic ``sigma_r`` over the wall layer's ``tau``."""
    out = grid.copy()
    taus = np.array([m.tau for m in target.layers])
    tau = xr.DataArray(taus[out["wall_layer"].values.astype(int)], dims=out["wall_layer"].dims)
    for key, _, var in MODELS:
        out[f"S_{key}"] = (out[var] / tau).assign_attrs(units="1",
                                                         long_name=f"{var} / tau of wall layer")
    return out


def add_error_parts(grid):
    """Split ``rel_err_paper`` into formulas + convention + idealisation (exactly additive)."""
    out = grid.copy()
    fe = out["sigma_r"].where(~out["failed"].astype(bool))
    parts = {"formulas": out["sigma_r_paper"] - out["sigma_r_quasi_static"],
             "convention": out["sigma_r_quasi_static"] - out["sigma_r_dynamic"],
             "idealisation": out["sigma_r_dynamic"] - fe}
    for name, text in ERROR_PARTS:
        out[f"part_{name}"] = (parts[name] / fe).assign_attrs(units="1",
                                                              long_name=text + " (over FE)")
    return out


def analyse(grid, target, projectile):
    """The FE grid with every analytic and derived report quantity added (the FE and
    closed-form values rounded first, see the module docstring)."""
    coords = {name: dict(grid[name].attrs) for name in grid.coords}
    grid = round_dataset(add_analytic(grid.transpose("velocity", "depth", ...), target,
                                      projectile))
    out = add_error_parts(add_S(add_errors(grid), target))
    for name, attrs in coords.items():  # xr.where drops the coordinates' units and long_name
        out[name].attrs = attrs
    return out


def layer_mask(grid, index):
    """Cells (velocity x depth) whose wall layer is ``index`` (FE table's ``wall_layer``)."""
    return (grid["wall_layer"] == index).broadcast_like(grid["sigma_r"])


def layer_stats(grid, key, index):
    """Statistics of one closed form's error over the cells with wall layer ``index``.

    Returns
    -------
    dict
        ``cells``, ``failed``, ``median``, ``max_abs`` (signed value of the largest
        magnitude), ``at`` ((V, L) of it), ``within`` (fractions for 1 % and 5 %),
        ``unresolved`` (cells whose FE error estimate is not small against the difference),
        ``v_within`` (largest V up to which every cell is within each tolerance, or None).
    """
    mask = layer_mask(grid, index)
    rel = grid[f"rel_err_{key}"].where(mask)
    ok = rel.notnull()
    n_ok = int(ok.sum())
    stats = {"cells": int(mask.sum()), "failed": int((mask & (grid["failed"] != 0)).sum())}
    if n_ok == 0:
        return {**stats, "median": math.nan, "max_abs": math.nan, "at": None,
                "within": (math.nan, math.nan), "unresolved": 0, "v_within": (None, None)}
    flat = rel.stack(cell=("velocity", "depth")).dropna("cell")
    worst = flat.isel(cell=int(np.argmax(np.abs(flat.values))))
    return {**stats, "median": float(flat.median()), "max_abs": float(worst),
            "at": (float(worst.velocity), float(worst.depth)),
            "within": tuple(float((abs(flat) <= t).mean()) for t in TOLERANCES),
            "unresolved": int(((grid[f"resolved_{key}"] == 0) & mask).sum()),
            "v_within": tuple(velocity_limit(rel, t) for t in TOLERANCES)}


def velocity_limit(rel, tolerance):
    """Largest V such that every cell with velocity <= V is within ``tolerance`` (or None)."""
    limit = None
    for V in rel.velocity.values:
        row = rel.sel(velocity=V)
        if not bool(row.notnull().any()):
            continue
        if bool((abs(row) > tolerance).any()):
            break
        limit = float(V)
    return limit


def all_stats(grid, target):
    """``{model key: {layer index: layer_stats}}`` for the layers present at the wall."""
    present = sorted({int(i) for i in np.unique(grid["wall_layer"].values)})
    return {key: {i: layer_stats(grid, key, i) for i in present} for key, _, _ in MODELS}


#: the model label (README "One resistance vocabulary") of each closed form's key
MODEL_LABEL = {"dynamic": "derived-dynamic", "quasi_static": "derived-quasi-static",
               "paper": "paper"}


def accuracy_records(grid, target, stats):
    """The report's conclusions as numbers (``cavex verify --json``): one record per closed
    form and wall layer, from :func:`layer_stats` and :func:`attribution`.

    Each record: ``model`` (label), ``wall_layer``, ``closest`` (the closed form with the
    smallest ``|median|`` in that layer), ``cells``, ``fe_failed``,
    ``median_relative_difference`` and ``worst_relative_difference`` (``closed form / FE - 1``;
    None without an FE result), ``worst_at_velocity_m_s``, ``worst_at_depth_m``,
    ``within_1_percent_ratio`` and ``within_5_percent_ratio`` (fractions of the cells),
    ``all_within_1_percent_up_to_m_s`` and ``all_within_5_percent_up_to_m_s`` (None: not even
    at the lowest velocity), ``unresolved_cells`` (the FE estimate does not resolve the
    difference), ``parts_median_relative_difference`` ({part: median}, the parts of
    :data:`MODEL_PARTS`) and ``parts_worst_relative_difference`` (at the worst cell)."""
    names = target.layer_names()

    def number(x):
        return None if x is None or not math.isfinite(x) else float(x)

    records = []
    for index in sorted(next(iter(stats.values()))):
        medians = {key: abs(stats[key][index]["median"]) for key in stats}
        closest = min(medians, key=lambda k: medians[k] if math.isfinite(medians[k])
                      else math.inf)
        for key, s in ((k, stats[k][index]) for k in stats):
            found = math.isfinite(s["median"])
            parts = attribution(grid, key, index, s["at"]) if found else None
            records.append({
                "model": MODEL_LABEL[key], "wall_layer": names[index],
                "closest": key == closest, "cells": s["cells"], "fe_failed": s["failed"],
                "median_relative_difference": number(s["median"]),
                "worst_relative_difference": number(s["max_abs"]),
                "worst_at_velocity_m_s": s["at"][0] if found else None,
                "worst_at_depth_m": s["at"][1] if found else None,
                "within_1_percent_ratio": number(s["within"][0]),
                "within_5_percent_ratio": number(s["within"][1]),
                "all_within_1_percent_up_to_m_s": s["v_within"][0],
                "all_within_5_percent_up_to_m_s": s["v_within"][1],
                "unresolved_cells": s["unresolved"],
                "parts_median_relative_difference": parts and parts["medians"],
                "parts_worst_relative_difference": parts and parts["worst"]})
    return records


def part_medians(grid, index):
    """Median of each error part of the paper model over wall layer ``index``."""
    mask = layer_mask(grid, index)
    return {name: float(grid[f"part_{name}"].where(mask).median()) for name, _ in ERROR_PARTS}


def attribution(grid, key, index, at):
    """Where the error of closed form ``key`` over wall layer ``index`` comes from.

    The parts of :data:`MODEL_PARTS` add up exactly, per cell, to ``rel_err_<key>``; their
    medians (over the cells of the layer where the model's error is defined) do not add up.

    Returns
    -------
    dict
        ``medians`` ({part: median}), ``median_part`` (largest ``|median|``), ``worst``
        ({part: value} at the cell ``at`` = (V, L), the model's worst cell) and ``worst_part``
        (largest ``|value|`` there).
    """
    parts = MODEL_PARTS[key]
    mask = layer_mask(grid, index) & grid[f"rel_err_{key}"].notnull()
    medians = {p: float(grid[f"part_{p}"].where(mask).median()) for p in parts}
    cell = grid.sel(velocity=at[0], depth=at[1])
    worst = {p: float(cell[f"part_{p}"]) for p in parts}
    return {"medians": medians, "worst": worst,
            "median_part": max(parts, key=lambda p: abs(medians[p])),
            "worst_part": max(parts, key=lambda p: abs(worst[p]))}
