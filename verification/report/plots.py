"""PNG figures of the verification report (matplotlib, Agg): maps over (V, L) and curves.

Maps are drawn on the true velocity and depth coordinates: each grid point is the centre of a
cell whose edges lie half-way to its neighbours (grid points are the minor ticks). Where the
depth grid reaches far below the last interface (the last layer alone at the wall, where
``sigma_r`` no longer depends on ``L``), the depth axis is broken: the layers at full scale
above, the rest below, each part to its own linear scale. Depth increases downwards.

Colours: the three relative-error maps share one diverging scale (:data:`ERROR_BOUNDS`, %),
with 1 % and 5 % contour lines; the validity classes use the Okabe-Ito colour-blind-safe
palette; the error estimate is in % on a log scale (cividis).
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator  # noqa: E402

from cavex.analytic.models import line_style  # noqa: E402
from cavex.analytic.states import STATE_GROUPS, state_meaning  # noqa: E402
from cavex.verification.output.files import save_figure  # noqa: E402
from cavex.verification.output.number_format import ESTIMATE_DECIMALS  # noqa: E402
from cavex.verification.report.analysis import (  # noqa: E402
    MODEL_LABEL,
    MODELS,
    RESOLVED_FRACTION,
    TOLERANCES,
)

# Okabe-Ito: within 1 % (blue), within 5 % (sky blue), beyond 5 % (orange), FE failed (grey)
VALIDITY_COLOURS = ("#0072B2", "#56B4E9", "#E69F00", "#BBBBBB")
# one diverging scale for every closed form: (analytic - FE) / FE in %, symmetric bins
ERROR_BOUNDS = (-200.0, -100.0, -50.0, -20.0, -10.0, -5.0, -2.0, -1.0,
                1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0)
ERROR_CMAP = "RdBu_r"
# the depth axis is broken when the grid reaches this far below the last interface (m) ...
BREAK_BELOW_INTERFACE = 0.3
# ... and the part below would take more than this fraction of the part above
BREAK_FRACTION = 0.5
# Okabe-Ito (colour-blind-safe) for the response states, grey instead of black
STATE_COLOURS = ("#0072B2", "#E69F00", "#009E73", "#F0E442", "#56B4E9", "#D55E00", "#CC79A7",
                 "#999999")


def _pct(fraction):
    """``0.01`` -> ``"1 %"`` (the report's spelling)."""
    return f"{100 * fraction:g} %"


def _save(fig, path):
    return save_figure(fig, path, dpi=110, bbox_inches="tight")


def _depth_limit(ax, grid, target):
    """Curves end shortly below the last interface (deeper, the wall layer is alone)."""
    deepest = max(target.interface_depths, default=float(grid.depth.max()))
    ax.set_xlim(float(grid.depth.min()) - 0.02, min(float(grid.depth.max()), deepest + 0.25))


def _interfaces_v(ax, target):
    """Vertical dashed lines at the interface depths; each layer named above its depth band
    (call after the x limits are set)."""
    left, right = ax.get_xlim()
    bounds = [-np.inf, *target.interface_depths, np.inf]
    for H in target.interface_depths:
        ax.axvline(H, color="k", lw=0.8, ls="--")
    for k, name in enumerate(target.layer_names()):
        lo, hi = max(bounds[k], left), min(bounds[k + 1], right)
        if hi - lo > 0.06 * (right - left):
            ax.text(0.5 * (lo + hi), 1.0, name, fontsize=8, style="italic", va="bottom",
                    ha="center", transform=ax.get_xaxis_transform())


# --- maps over (V, L) -------------------------------------------------------------------------

def edges(x, lower=None):
    """Cell edges around the points ``x``: half-way between neighbours, the ends mirrored
    (and not below ``lower``)."""
    x = np.asarray(x, dtype=float)
    if x.size == 1:
        half = max(abs(x[0]) * 0.05, 0.5)
        out = np.array([x[0] - half, x[0] + half])
    else:
        mid = 0.5 * (x[1:] + x[:-1])
        out = np.concatenate([[2 * x[0] - mid[0]], mid, [2 * x[-1] - mid[-1]]])
    if lower is not None:
        out[0] = max(out[0], lower)
    return out


def depth_parts(grid, target):
    """Depth ranges ``(top, bottom)`` (m) of a map's axes: one, or two for a broken axis."""
    d = grid.depth.values
    e = edges(d, lower=0.0)
    deepest = max(target.interface_depths, default=float(d[-1]))
    k = int(np.sum(d <= deepest + BREAK_BELOW_INTERFACE))
    if 2 <= k < d.size and (e[-1] - e[k]) > BREAK_FRACTION * (e[k] - e[0]):
        return [(e[0], e[k]), (e[k], e[-1])]
    return [(e[0], e[-1])]


def map_figure(grid, target, titles, panel_width=4.3):
    """Figure with one column of map axes per title; returns ``(fig, columns)``, each column
    the list of its axes (two for a broken depth axis)."""
    parts = depth_parts(grid, target)
    heights = [4.0] if len(parts) == 1 else [4.0, 1.1]
    fig = plt.figure(figsize=(panel_width * len(titles) + 1.6, 1.7 + sum(heights)),
                     layout="constrained")
    axes = fig.subplots(len(parts), len(titles), sharex="col", sharey="row",
                        height_ratios=heights, squeeze=False)
    if len(parts) == 2:
        fig.get_layout_engine().set(h_pad=0.02, hspace=0.0)
    columns = [list(axes[:, c]) for c in range(len(titles))]
    for column, title in zip(columns, titles, strict=True):
        column[0].set_title(title)
        for ax, (top, bottom) in zip(column, parts, strict=True):
            ax.set_ylim(bottom, top)
        if len(column) == 2:
            _break_marks(*column)
    return fig, columns


def _break_marks(upper, lower):
    """Hide the spines at a broken depth axis and draw the usual diagonal marks."""
    upper.spines["bottom"].set_visible(False)
    lower.spines["top"].set_visible(False)
    upper.tick_params(axis="x", which="both", bottom=False)
    kwargs = {"marker": [(-1, -0.5), (1, 0.5)], "markersize": 9, "linestyle": "none",
              "color": "k", "mec": "k", "mew": 1, "clip_on": False}
    upper.plot([0, 1], [0, 0], transform=upper.transAxes, **kwargs)
    lower.plot([0, 1], [1, 1], transform=lower.transAxes, **kwargs)


def mesh(ax, grid, values, **kwargs):
    """``values`` (velocity x depth) as cells on the true coordinates."""
    return ax.pcolormesh(edges(grid.velocity.values, lower=0.0),
                         edges(grid.depth.values, lower=0.0),
                         np.asarray(values, dtype=float).T, shading="flat", **kwargs)


def frame(columns, grid, target, names_on=0):
    """Axes decoration of every map: limits, grid points as minor ticks, interfaces (dashed,
    named on column ``names_on``), failed cells crossed, labels."""
    v, d = grid.velocity.values, grid.depth.values
    failed = grid["failed"].values.astype(bool)
    V, L = np.meshgrid(v, d, indexing="ij")
    names = target.layer_names()
    for c, column in enumerate(columns):
        for ax in column:
            limits = ax.get_ylim()  # set_yticks widens the view to every tick: restored
            ax.set_xticks(v, minor=True)
            ax.set_yticks(d, minor=True)
            ax.set_xlim(edges(v, lower=0.0)[[0, -1]])
            ax.set_ylim(limits)
            ax.tick_params(which="minor", length=2.5)
            for H in target.interface_depths:
                ax.axhline(H, color="k", lw=1.0, ls="--")
            if failed.any():
                ax.plot(V[failed], L[failed], "kx", ms=7, mew=1.5)
        column[-1].set_xlabel("expansion velocity V (m/s)")
        if c == 0:
            column[0].set_ylabel("nose-tip depth L (m)")
        if names_on is not None and c == names_on:
            _layer_names(column, target, names)


def _layer_names(column, target, names):
    """Each layer's name at the left edge, in the middle of its depth band."""
    bounds = [0.0, *target.interface_depths, np.inf]
    for ax in column:
        bottom, top = ax.get_ylim()
        for k, name in enumerate(names):
            lo, hi = max(bounds[k], top), min(bounds[k + 1], bottom)
            if hi - lo > 0.08 * (bottom - top):
                ax.text(0.02, 0.5 * (lo + hi), name, fontsize=8, style="italic", va="center",
                        transform=ax.get_yaxis_transform(),
                        bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                              "alpha": 0.75})


def _marker_legend(fig, extra=(), failed=False):
    """The meaning of the lines and markers, inside the image, below the panels."""
    handles = list(extra) + [Line2D([], [], color="k", lw=1.0, ls="--",
                                    label="interface depth H")]
    if failed:
        handles.append(Line2D([], [], color="k", marker="x", ls="none", mew=1.5,
                              label="FE failed (no value)"))
    fig.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 3),
               fontsize=8, frameon=False)


def error_maps(grid, target, out):
    """``(analytic - FE)/FE`` (%) of the three closed forms on one diverging colour scale.

    Thin and thick contour lines: 1 % and 5 %; dots: the FE error estimate is not below
    ``RESOLVED_FRACTION`` of the difference (the difference is not resolved by the FE).
    """
    fig, columns = map_figure(grid, target, [f"{label} vs FE" for _, label, _ in MODELS])
    cmap = plt.get_cmap(ERROR_CMAP, len(ERROR_BOUNDS) + 1)
    norm = BoundaryNorm(ERROR_BOUNDS, cmap.N, extend="both")
    V, L = np.meshgrid(grid.velocity.values, grid.depth.values, indexing="ij")
    for column, (key, _, _) in zip(columns, MODELS, strict=True):
        rel = 100 * grid[f"rel_err_{key}"].values
        unresolved = grid[f"resolved_{key}"].values == 0
        for ax in column:
            quad = mesh(ax, grid, rel, cmap=cmap, norm=norm)
            _contours(ax, grid, np.abs(rel))
            ax.plot(V[unresolved], L[unresolved], "k.", ms=2.5)
    frame(columns, grid, target)
    bar = fig.colorbar(quad, ax=[ax for column in columns for ax in column], shrink=0.9,
                       spacing="uniform", ticks=ERROR_BOUNDS, aspect=30)
    bar.set_label("(analytic - FE) / FE (%)")
    bar.ax.yaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:+g}"))
    _marker_legend(fig, [
        Line2D([], [], color="0.25", lw=0.8, label=f"|error| = {_pct(TOLERANCES[0])} contour"),
        Line2D([], [], color="k", lw=2.0, label=f"|error| = {_pct(TOLERANCES[1])} contour"),
        Line2D([], [], color="k", marker=".", ls="none",
               label=f"not resolved: FE error estimate >= {RESOLVED_FRACTION:.2g} x |error|"),
    ], failed=bool(grid["failed"].values.any()))
    return _save(fig, out / "error_maps.png")


def _contours(ax, grid, magnitude):
    """1 % (thin) and 5 % (thick) lines of ``|error|`` (%): the outlines of the cells within
    them, drawn along the cell edges (no interpolation between grid points)."""
    if not np.isfinite(magnitude).any():
        return
    x, y, z = _stepped(edges(grid.velocity.values, lower=0.0),
                       edges(grid.depth.values, lower=0.0), magnitude)
    z = np.ma.masked_invalid(z)
    for level, colour, width in ((100 * TOLERANCES[0], "0.25", 0.9),
                                 (100 * TOLERANCES[1], "k", 2.0)):
        if z.min() < level < z.max():
            ax.contour(x, y, z.T, levels=[level], colors=colour, linewidths=width)


def _stepped(x_edges, y_edges, values):
    """Each cell's value at two points just inside its edges, so that a contour of the
    result runs along the cell edges."""
    def doubled(e):
        inset = 1e-6 * np.diff(e)
        return np.column_stack([e[:-1] + inset, e[1:] - inset]).ravel()

    z = np.repeat(np.repeat(np.asarray(values, dtype=float), 2, axis=0), 2, axis=1)
    return doubled(x_edges), doubled(y_edges), z


def validity_map(grid, target, out):
    """Where each closed form is within 1 % and 5 % of FE (three panels)."""
    cmap = ListedColormap(VALIDITY_COLOURS)
    norm = BoundaryNorm([-0.5, 0.5, 1.5, 2.5, 3.5], cmap.N)
    fig, columns = map_figure(grid, target, [label for _, label, _ in MODELS], panel_width=3.8)
    for column, (key, _, _) in zip(columns, MODELS, strict=True):
        codes = grid[f"validity_{key}"].values.astype(float)
        codes[codes < 0] = 3
        for ax in column:
            mesh(ax, grid, codes, cmap=cmap, norm=norm)
    frame(columns, grid, target)
    classes = [f"within {_pct(TOLERANCES[0])} of FE", f"within {_pct(TOLERANCES[1])}",
               f"beyond {_pct(TOLERANCES[1])}", "FE failed"]
    _marker_legend(fig, [Patch(fc=c, ec="none", label=t)
                         for c, t in zip(VALIDITY_COLOURS, classes, strict=True)],
                   failed=bool(grid["failed"].values.any()))
    return _save(fig, out / "validity.png")


def state_map(grid, target, out):
    """Categorical map of the derived dynamic and quasi-static response states, explained
    (legend) and labelled on the map."""
    keys = ("dynamic", "quasi_static")
    labels = grid["state_dynamic"].attrs["flag_meanings"].split()
    colours = STATE_COLOURS if len(labels) <= len(STATE_COLOURS) else \
        [plt.get_cmap("tab20")(i % 20) for i in range(len(labels))]
    cmap = ListedColormap(colours[:len(labels)])
    norm = BoundaryNorm(np.arange(len(labels) + 1) - 0.5, cmap.N)
    fig, columns = map_figure(grid, target, [f"{k.replace('_', '-')} convention"
                                             for k in keys], panel_width=4.6)
    for column, key in zip(columns, keys, strict=True):
        codes = grid[f"state_{key}"].values
        for ax in column:
            mesh(ax, grid, codes, cmap=cmap, norm=norm)
    frame(columns, grid, target, names_on=None)
    for column, key in zip(columns, keys, strict=True):
        for ax in column:
            _label_cells(ax, grid, grid[f"state_{key}"].values, labels)
    names = target.layer_names()
    groups = [f"{letters}: {n} layers around the cavity ({', '.join(names[-n:])})"
              for n, letters in STATE_GROUPS.items() if len(names) >= n]
    handles = [Patch(fc=cmap(i), ec="none", label=f"{label}: {state_meaning(label, names, True)}")
               for i, label in enumerate(labels)]
    handles.append(Line2D([], [], color="k", lw=1.0, ls="--", label="interface depth H"))
    if grid["failed"].values.any():
        handles.append(Line2D([], [], color="k", marker="x", ls="none", mew=1.5,
                              label="FE failed (no value)"))
    fig.legend(handles=handles, loc="outside lower center", fontsize=8, frameon=False,
               ncols=2, title_fontsize=8, title="  ·  ".join(
                   [*groups, f"single: {names[-1]} alone"]))
    fig.suptitle("Response state of the derived closed form (the paper's Fig. 2): where the "
                 "plastic zone ends", fontsize=10)
    return _save(fig, out / "states.png")


def _label_cells(ax, grid, codes, labels):
    """Write each state's label once per axes, in the middle of its largest visible block (a
    run of cells down one velocity column), if that is large enough to hold it."""
    x, y = edges(grid.velocity.values, lower=0.0), edges(grid.depth.values, lower=0.0)
    bottom, top = ax.get_ylim()
    lo, hi = np.maximum(y[:-1], top), np.minimum(y[1:], bottom)
    visible = hi > lo
    best = {}
    for i in range(codes.shape[0]):
        j = 0
        while j < codes.shape[1]:
            k = j
            while k + 1 < codes.shape[1] and codes[i, k + 1] == codes[i, j]:
                k += 1
            if visible[j:k + 1].any():
                first = j + int(np.argmax(visible[j:k + 1]))
                last = k - int(np.argmax(visible[j:k + 1][::-1]))
                size = ((x[i + 1] - x[i]) / (x[-1] - x[0]), (hi[last] - lo[first]) / (bottom - top))
                if size[0] * size[1] > best.get(codes[i, j], (0.0,))[0]:
                    best[codes[i, j]] = (size[0] * size[1], size, i, lo[first], hi[last])
            j = k + 1
    for code, (_, size, i, y0, y1) in best.items():
        if size[0] >= 0.06 and size[1] >= 0.05:
            ax.text(0.5 * (x[i] + x[i + 1]), 0.5 * (y0 + y1), labels[int(code)],
                    ha="center", va="center", fontsize=9, fontweight="bold",
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none",
                          "alpha": 0.8})


def error_estimate_map(grid, target, out):
    """FE relative error estimate of every cell, in %, on a log scale. Estimates are stored to
    a quantum of 1e-5 (:data:`~cavex.verification.output.number_format.ESTIMATE_DECIMALS`);
    one stored as 0 (below half the quantum) is drawn at half the quantum, the bottom of the
    scale, not left blank."""
    est = 100 * grid["error_estimate"].where(grid["failed"] == 0).values
    positive = np.where(est > 0, est, np.where(est == 0, 50 * 10.0 ** -ESTIMATE_DECIMALS,
                                               np.nan))
    fig, columns = map_figure(grid, target, ["FE error estimate (Richardson)"], panel_width=5.0)
    finite = positive[np.isfinite(positive)]
    norm = LogNorm(finite.min(), finite.max()) if finite.size and finite.min() < finite.max() \
        else None
    for ax in columns[0]:
        quad = mesh(ax, grid, positive, cmap="cividis", norm=norm)
    frame(columns, grid, target)
    bar = fig.colorbar(quad, ax=columns[0], shrink=0.9, aspect=30)
    bar.set_label("FE relative error estimate (%)")
    if norm is not None:
        bar.ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    bar.ax.yaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:.3g} %"))
    bar.ax.yaxis.set_minor_formatter(FuncFormatter(lambda x, _: ""))
    _marker_legend(fig, failed=bool(grid["failed"].values.any()))
    return _save(fig, out / "error_estimate.png")


# --- curves -----------------------------------------------------------------------------------

def s_curves(grid, target, out, velocities):
    """``S`` against nose depth at a few velocities: FE points, closed forms as lines."""
    fig, ax = plt.subplots(figsize=(7, 5))
    for i, V in enumerate(velocities):
        row = grid.sel(velocity=V)
        colour = f"C{i}"
        ok = row["failed"].values == 0
        ax.plot(row.depth.values[ok], row["S"].values[ok], "o", color=colour, ms=4,
                label=f"FE, V = {V:g} m/s")
        for key, label, _ in MODELS:
            ax.plot(row.depth.values, row[f"S_{key}"].values, line_style(MODEL_LABEL[key])[1],
                    color=colour, lw=1, label=label if i == 0 else None)
    _depth_limit(ax, grid, target)
    _interfaces_v(ax, target)
    ax.set(xlabel="nose-tip depth L (m)", ylabel="S = sigma_r / tau of the wall layer",
           yscale="log")
    ax.set_title("S against depth (lines: closed forms, points: FE)", pad=14)
    ax.legend(fontsize=7, ncol=2)
    return _save(fig, out / "S_depth.png")


def plastic_radius_plot(grid, target, out, velocities):
    """FE plastic radius against the derived ``b`` (both conventions) over depth."""
    fig, ax = plt.subplots(figsize=(7, 5))
    for i, V in enumerate(velocities):
        row, colour = grid.sel(velocity=V), f"C{i}"
        ok = row["failed"].values == 0
        ax.plot(row.depth.values[ok], 1e3 * row["plastic_radius"].values[ok], "o", color=colour,
                ms=4, label=f"FE, V = {V:g} m/s")
        ax.plot(row.depth.values, 1e3 * row["b_dynamic"].values, "-", color=colour, lw=1,
                label="derived-dynamic" if i == 0 else None)
        ax.plot(row.depth.values, 1e3 * row["b_quasi_static"].values, "--", color=colour, lw=1,
                label="derived-quasi-static" if i == 0 else None)
    _depth_limit(ax, grid, target)
    _interfaces_v(ax, target)
    ax.set(xlabel="nose-tip depth L (m)", ylabel="plastic radius b (mm)")
    ax.set_title("Elastic-plastic boundary: FE against closed forms", pad=14)
    ax.legend(fontsize=7)
    return _save(fig, out / "plastic_radius.png")


def trajectory_plot(runs, target, out):
    """Velocity against nose-tip depth of the closed forms and the FE table (``runs``:
    ``{name: Trajectory}``), the stops marked."""
    fig, ax = plt.subplots(figsize=(7, 4.6))
    for name, run in runs.items():
        colour, style, lw = line_style(name)
        ax.plot(run.depth, run.velocity, style, color=colour, lw=lw,
                label=f"{name} (stops at {run.depth[-1]:.2f} m)")
        ax.plot(run.depth[-1], 0.0, "o", color=colour, ms=5)
    ax.set_xlim(0.0, None)
    ax.set_ylim(0.0, None)
    _interfaces_v(ax, target)
    ax.set(xlabel="nose-tip depth L (m)", ylabel="projectile velocity V (m/s)")
    ax.set_title("Trajectories: closed-form resistances against the FE table", pad=14)
    ax.legend(fontsize=8)
    return _save(fig, out / "trajectories.png")
