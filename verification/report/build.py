"""The verification report: closed forms against the FE over a (V, L) grid, for one target.

:func:`verify` builds the FE table (:func:`cavex.verification.fedata.table.build_table`, run by the
shared case runner), adds the closed forms (derived dynamic, derived quasi-static, the paper's
printed model), and writes ``report.md``, ``report.html`` (self-contained: the figures are
embedded), PNG figures (matplotlib; among them the FE stresses around the cavity at one
(V, L) and the trajectories of the closed forms against the FE table) and ``grid.nc`` (every
number the report prints) into ``out_dir``.
:mod:`cavex.verification.commands.verify` is the ``cavex verify`` command.

The written files are reproducible: the FE table is rounded to the digits the numerics support
(:mod:`cavex.verification.output.number_format`) before anything is computed from it, the trajectory
numbers in ``grid.nc`` carry the integrator's digits, and wall times and the table's creation
time are only in the returned summary (printed by ``cavex verify``), not in the files.
"""

import json
import math
import time
from pathlib import Path

import numpy as np

from cavex.analytic.models import the
from cavex.errors import CavexInputError
from cavex.fem.estimate import DEFAULT_ERROR_TARGET
from cavex.verification.fedata.table import build_table, write_table
from cavex.verification.output.number_format import TRAJECTORY_DIGITS, round_dataset, round_nested
from cavex.verification.report import plots, text
from cavex.verification.report.analysis import (
    RESOLVED_FRACTION,
    TOLERANCES,
    accuracy_records,
    all_stats,
    analyse,
)
from cavex.verification.report.html import markdown_to_html, slug

DEFAULT_VELOCITIES = (0.0, 50.0, 100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 800.0, 1000.0,
                      1200.0)
# 31 depths through concrete and macadam into the soil (every 0.04 m), then the soil alone
# (single layer: sigma_r no longer depends on L) down to where the trajectories stop.
DEFAULT_DEPTHS = tuple(np.round(np.linspace(0.10, 1.30, 31), 6)) + (1.6, 2.0, 2.6, 3.4, 4.0)
# quick: five velocities (fractions of the striking velocity V0: 0, 100, 300, 600, 1000 m/s for
# Table 1; the nose sees V cos(phi) <= 0.54 V, and sigma_r bends most at low V: with 0, 600 and
# 1000 m/s alone the table's shot stopped 0.49 m (15 %) deeper than the default grid's,
# docs/verification.md "Interpolation error") and four depths from the crater's end (where the
# trajectories start) to past the last wall-layer switch (the last layer alone: the table
# answers for every deeper L), so that the quick report is complete, trajectory comparison
# included
QUICK_VELOCITY_FRACTIONS = (0.0, 0.1, 0.3, 0.6, 1.0)
QUICK_DEPTH_COUNT = 4
QUICK_DEPTH_MARGIN = 0.15  # m past the last switch depth
# quick: half the FE resolution in space and time (the error estimate says what that costs)
QUICK_NUMERICS = {"elements_per_decade": 15.0, "growth_per_step": 0.06}
PICTURE_VELOCITY = 600.0
CURVE_VELOCITIES = (200.0, 600.0, 1000.0)


def quick_axes(target, projectile):
    """``(velocities, depths)`` of the quick grid for ``target`` and ``projectile``.

    Velocities: :data:`QUICK_VELOCITY_FRACTIONS` of ``V0`` (the table must reach ``V0`` for the
    crater stage). Depths: :data:`QUICK_DEPTH_COUNT` from the nose-tip depth at the crater's end
    (rounded down to the centimetre) to :data:`QUICK_DEPTH_MARGIN` past the last wall-layer
    switch depth (one metre deep for a single layer), rounded to the centimetre.
    """
    from cavex.analytic.geometry import switch_depths
    from cavex.analytic.penetration.integrator import crater_depth

    velocities = tuple(float(f"{f * projectile.V0:.6g}") for f in QUICK_VELOCITY_FRACTIONS)
    start = math.floor(100.0 * crater_depth(projectile) + 1e-9) / 100.0
    switches = switch_depths(target, projectile)
    end = (switches[-1] if switches else start + 1.0 - QUICK_DEPTH_MARGIN) + QUICK_DEPTH_MARGIN
    depths = np.unique(np.round(np.linspace(start, max(end, start + 0.1), QUICK_DEPTH_COUNT), 2))
    return velocities, tuple(float(x) for x in depths)


def grid_axes(quick, velocities=None, depths=None, target=None, projectile=None):
    """``(velocities, depths)`` of the report grid (explicit values win over the presets; the
    quick preset needs ``target`` and ``projectile``, see :func:`quick_axes`)."""
    if quick and (velocities is None or depths is None):
        qv, qd = quick_axes(target, projectile)
        velocities = qv if velocities is None else velocities
        depths = qd if depths is None else depths
    v = DEFAULT_VELOCITIES if velocities is None else velocities
    d = DEFAULT_DEPTHS if depths is None else depths
    return tuple(float(x) for x in v), tuple(float(x) for x in d)


def trajectories(target, projectile, table):
    """:func:`compare_trajectories` on the FE table and the trajectories themselves
    (``{name: Trajectory}``), or a one-line reason why not and ``{}``."""
    from cavex.analytic.models.comparison import comparison_runs
    from cavex.analytic.penetration.tabulated import trajectory_summary

    try:
        runs = comparison_runs(target, projectile, table)
    except CavexInputError as exc:
        return f"Trajectory comparison not possible: {exc}", {}
    return {name: trajectory_summary(run, target) for name, run in runs.items()}, runs


def table_interpolation_error(target, projectile, table, runs):
    """The FE-table shot's interpolation-error estimate
    (:func:`cavex.analytic.penetration.table_error.interpolation_error`: the table with every
    other node in V and in L), None without a table shot."""
    from cavex.analytic.penetration.table_error import interpolation_error

    run = runs.get(the(takes_table=True).name)
    if run is None:
        return None
    reference = {"final_depth_m": float(run.depth[-1]),
                 "phase_end_velocities_m_s": [float(p.end_velocity) for p in run.phases],
                 "phase_labels": [p.label for p in run.phases]}
    try:
        return interpolation_error(target, projectile, table, reference=reference)
    except CavexInputError:  # a coarsened table the shot cannot fly: no estimate
        return None


def picture(target, projectile, grid, out, nu, numerics):
    """The stress figure at ``PICTURE_VELOCITY`` (nearest grid velocity); path and message."""
    from cavex.verification.report import picture as report_picture

    v = grid.velocity.values
    velocity = float(v[np.argmin(np.abs(v - PICTURE_VELOCITY))])
    depth = report_picture.picture_depth(target, projectile, velocity, grid.depth.values)
    try:
        path, message = report_picture.make_picture(target, projectile, velocity, depth,
                                                    out / report_picture.FILE_NAME, numerics,
                                                    nu)
    except Exception as exc:  # noqa: BLE001 - the FE run of the figure failed
        path, message = None, ("stress figure not drawn (FE run failed: "
                               f"{report_picture.first_line(exc)})")
    return {"path": path, "message": message, "velocity": velocity, "depth": depth}


def curve_velocities(grid):
    """Velocities of the S(L) and b(L) curves: the preset ones present, else three spread."""
    v = [float(x) for x in grid.velocity.values]
    chosen = [x for x in CURVE_VELOCITIES if x in v]
    return chosen or [v[i] for i in sorted({len(v) // 4, len(v) // 2, len(v) - 1})]


#: the report's figures but the trajectories (with the FE-table shots) and the stresses
FIGURES = ("error_maps", "validity", "S_depth", "states", "plastic_radius", "error_estimate")


def figures(grid, target, out, runs=None):
    """Write every matplotlib figure (:data:`FIGURES`, and the trajectories when ``runs`` are
    given); returns ``{name: path}``."""
    curves = curve_velocities(grid)
    paths = dict(zip(FIGURES, (plots.error_maps(grid, target, out),
                               plots.validity_map(grid, target, out),
                               plots.s_curves(grid, target, out, curves),
                               plots.state_map(grid, target, out),
                               plots.plastic_radius_plot(grid, target, out, curves),
                               plots.error_estimate_map(grid, target, out)), strict=True))
    if runs:
        paths["trajectories"] = plots.trajectory_plot(runs, target, out)
    return paths


REPORT_FILES = ("report.md", "report.html", "grid.nc", "target.toml", "stresses.png",
                "error_maps.png", "validity.png", "S_depth.png", "states.png",
                "plastic_radius.png", "error_estimate.png", "trajectories.png")
# written by earlier versions of the report; removed so that they never mix with a new one
OLD_REPORT_FILES = ("sphere.png", "error_dynamic.png", "error_quasi_static.png",
                    "error_paper.png")


def remove_report_files(out):
    """Delete the files a report writes (and nothing else) from ``out``."""
    for name in REPORT_FILES + OLD_REPORT_FILES:
        (Path(out) / name).unlink(missing_ok=True)


def write_grid(grid, path, extra):
    """``grid.nc`` (netCDF3, scipy engine) with the report's extra attributes as JSON.

    Through :func:`~cavex.verification.fedata.table.write_table`: rounded, without the creation
    time. """
    ds = grid.copy()
    for key, value in extra.items():
        ds.attrs[key] = value if isinstance(value, str) else json.dumps(value)
    return write_table(ds, path)


def verify(target, projectile, *, quick=False, out_dir, scheduler=None, workers=None,
           config_text=None, velocities=None, depths=None, nu=None, numerics=None,
           error_target=DEFAULT_ERROR_TARGET, store=None, progress=None, draw=True):
    """Write the verification report of ``target`` into ``out_dir``; return its summary.

    Parameters
    ----------
    target, projectile : Target, Projectile
    quick : bool
        A small grid (5 velocities x 4 depths from the crater's end to past the last switch
        depth, :func:`quick_axes`, plus the table's switch depths) at half the FE resolution and
        without refinement, instead of the default (11 velocities 0-1200 m/s x 36 depths, plus
        the switch depths); its first conclusion line names its FE-table shot as the quick
        one, with the table's interpolation-error estimate (:func:`table_interpolation_error`).
    out_dir : str or path
        Output folder (created).
    scheduler, workers
        Passed to the case runner (Dask scheduler address, local processes).
    config_text : str, optional
        TOML text of the configuration; copied to ``out_dir/target.toml``.
    velocities, depths : sequence of float, optional
        Override the grid (velocities must include 0 and reach ``V0`` for the trajectories).
    nu : float, optional
        Poisson's ratio for every layer in the FE (default: each layer's own).
    numerics : dict, optional
        :class:`cavex.fem.Numerics` settings.
    error_target : float or None
        Refine the FE cells estimated above it (see :func:`build_table`); the quick report
        does not refine.
    store : str or path, optional
        Case store of the runner (resumable); default: none (nothing kept on disk).
    progress : bool, optional
        Runner progress bar.
    draw : bool
        Draw the PNG figures (default); False (``--no-figures``): none, and the report's
        sections say where a figure was left out.

    Returns
    -------
    dict
        ``out_dir``, ``files``, ``quick``, ``cells``, ``failed``, ``wall_time_s``,
        ``table_wall_time_s``, ``created`` (the FE table's creation time), ``conclusions``
        (list of str), ``picture`` (message), ``stats``, ``table_interpolation_error`` (the
        FE-table shot's estimate, :func:`table_interpolation_error`; None without that shot).
        The wall times and the creation time are not written into any file (they would differ
        on every run).
    """
    started = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    remove_report_files(out)  # an old report never mixes with this one
    v, d = grid_axes(quick, velocities, depths, target, projectile)
    if numerics is None and quick:
        numerics, error_target = dict(QUICK_NUMERICS), None
    fe = build_table(target, projectile, v, d, nu=nu, numerics=numerics,
                     error_target=error_target, scheduler=scheduler, workers=workers,
                     store=store, progress=progress)
    created = fe.attrs.get("created")
    fe = round_dataset(fe)  # the numbers grid.nc stores: everything below derives from them
    table_seconds = time.perf_counter() - started
    grid = analyse(fe, target, projectile)
    trajectory, runs = trajectories(target, projectile, fe)
    interpolation = table_interpolation_error(target, projectile, fe, runs)
    if draw:
        pic = picture(target, projectile, grid, out, nu, numerics)
        paths = figures(grid, target, out, runs)
    else:  # the same keys, no file
        pic = {"path": None, "message": NOT_DRAWN}
        paths = dict.fromkeys((*FIGURES, *(("trajectories",) if runs else ())))
    stats = all_stats(grid, target)
    lines = text.conclusions(grid, target, stats)
    if quick:  # the quick table's shot is no reference: say so, with its error estimate
        lines = [text.quick_reference_line(interpolation), *lines]
    info = {"quick": quick, "cells": int(grid["failed"].size), "failed": int(grid["failed"].sum()),
            "picture": pic["message"]}
    files = {**{k: str(p) for k, p in paths.items() if p is not None},
             "grid": str(write_grid(grid, out / "grid.nc",
                                    {"report": info,
                                     "trajectories": round_nested(trajectory, TRAJECTORY_DIGITS),
                                     "conclusions": lines}))}
    if pic["path"] is not None:
        files["stresses"] = str(pic["path"])
    if config_text is not None:
        (out / "target.toml").write_text(config_text, encoding="utf-8")
        files["config"] = str(out / "target.toml")
    markdown = report_markdown(grid, target, stats, lines, trajectory, pic, paths, info)
    (out / "report.md").write_text(markdown, encoding="utf-8")
    (out / "report.html").write_text(
        markdown_to_html(markdown, "cavex verification report", base_dir=out), encoding="utf-8")
    files.update(report=str(out / "report.md"), html=str(out / "report.html"))
    return {"out_dir": str(out), "files": files, "conclusions": lines, "stats": stats, **info,
            "accuracy": accuracy_records(grid, target, stats),
            "table_interpolation_error": interpolation,
            "wall_time_s": time.perf_counter() - started, "table_wall_time_s": table_seconds,
            "created": created}


def _settings_lines(grid, info):
    v, d = grid.velocity.values, grid.depth.values
    settings = json.loads(grid.attrs.get("solver_settings", "{}"))
    return [
        f"- grid: {v.size} velocities ({', '.join(f'{x:g}' for x in v)} m/s) x {d.size} nose "
        f"depths ({d[0]:.4g} to {d[-1]:.4g} m, including the wall-layer switch depths) = "
        f"{info['cells']} FE cells, {info['failed']} failed; "
        f"{'quick' if info['quick'] else 'default'} settings",
        f"- FE: Poisson's ratio {settings.get('nu') or 'of each layer'}, numerics "
        f"`{json.dumps(settings.get('numerics', {}), sort_keys=True)}`",
        f"- target fingerprint `{grid.attrs.get('fingerprint', '?')}`; versions "
        f"`{grid.attrs.get('versions', '?')}`; every number below is in `grid.nc`",
        "- relative error = (analytic - FE) / FE; S = sigma_r / tau of the layer at the cavity "
        "wall (the derived model's cavity switch) for every model",
    ]


NOT_DRAWN = "(figure not drawn: --no-figures)"


def _image(paths, key):
    """The markdown lines of figure ``key``, or a line saying it was not drawn."""
    if paths[key] is None:
        return [NOT_DRAWN, ""]
    return [f"![{key}]({Path(paths[key]).name})", ""]


def report_sections(grid, target, stats, lines, trajectory, pic, paths, info):
    """The report's sections, in order: ``[(heading, lines)]``; the first figure and the first
    table lead, the prose follows."""
    depth_break = len(plots.depth_parts(grid, target)) == 2
    one, five = (f"{100 * t:g} %" for t in TOLERANCES)
    error_caption = (
        "(analytic - FE) / FE of each closed form at every grid cell (V, L), on one colour "
        f"scale for all three: white is within {one}, the thin and thick lines are the {one} "
        f"and {five} contours (outlining the cells within). Dots: the FE error estimate is "
        f"not below {RESOLVED_FRACTION:.2g} of the difference (not resolved); crosses: FE "
        "failed; dashed: interface depths H (the layer at the cavity wall changes a little "
        "deeper, at L = H + l - r, where the interface comes within the shank radius r of the "
        "cavity centre). Cells are centred on the grid points (minor ticks)"
        + ("; the depth axis is broken below the layers, where the last layer alone is at "
           "the wall and nothing depends on L any more." if depth_break else "."))
    sections = [
        ("Where each closed form agrees with FE", [*_image(paths, "error_maps"), error_caption]),
        ("Accuracy by closed form and wall layer", [text.accuracy_table(stats, target)]),
        ("Conclusion", [f"- {line}" for line in lines]),
        ("Settings", _settings_lines(grid, info)),
        ("Validity (within 1 % and 5 % of FE)", [
            *_image(paths, "validity"),
            "The classes of the maps above, per cell (colour-blind-safe palette)."]),
        ("S against depth", _image(paths, "S_depth")),
        ("Response states and plastic radius", [
            *_image(paths, "states"), text.states_text(grid, target), "",
            *_image(paths, "plastic_radius")]),
        ("Stresses around the cavity",
         [*_image({"stresses": pic["path"]}, "stresses"), pic["message"] + "."]
         if pic["path"] is not None else [pic["message"]]),
        ("Trajectories: closed forms against the FE table",
         ([*_image(paths, "trajectories")] if "trajectories" in paths else [])
         + [text.trajectory_section(trajectory)]),
        ("FE error estimate", [text.resolution_text(grid, stats), "",
                               *_image(paths, "error_estimate")]),
        ("Failed FE cells", [text.failed_table(grid)]),
        ("Where the paper's error comes from", [
            "Per cell, (paper - FE)/FE = formulas + convention + idealisation exactly; medians:",
            "", text.parts_table(grid, target)]),
        ("Appendix: every cell", [text.table(text.CELL_HEADER, text.cell_rows(grid, target))]),
    ]
    return sections


def report_markdown(grid, target, stats, lines, trajectory, pic, paths, info):
    """The whole ``report.md`` text: title, one line on the target, contents, sections."""
    names = target.layer_names()
    sections = report_sections(grid, target, stats, lines, trajectory, pic, paths, info)
    contents = " · ".join(f"[{heading}](#{slug(heading)})" for heading, _ in sections)
    md = ["# cavex verification report: closed forms against FE", "",
          f"Target: {', '.join(names)} (interfaces at "
          f"{', '.join(f'{H:g}' for H in target.interface_depths)} m); {info['cells']} FE "
          f"cells, {info['failed']} failed; {'quick' if info['quick'] else 'default'} "
          "settings.", "", f"Contents: {contents}", ""]
    for heading, body in sections:
        md += [f"## {heading}", "", *body, ""]
    return "\n".join(md)


__all__ = ["verify", "DEFAULT_VELOCITIES", "DEFAULT_DEPTHS"]
