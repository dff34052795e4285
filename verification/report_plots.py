"""PNG figures of the verification report (matplotlib, Agg): maps over (V, L) and curves."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import BoundaryNorm, ListedColormap, TwoSlopeNorm  # noqa: E402

from cavex.verification.report_analysis import MODELS, TOLERANCES, layer_names  # noqa: E402
from cavex.verification.runner import save_figure  # noqa: E402

VALIDITY_COLOURS = ("#1a9850", "#fee08b", "#d73027", "#7f7f7f")  # 1 %, 5 %, beyond, failed


def _depth_limit(ax, grid, target):
    """Curves end shortly below the last interface (deeper, the wall layer is alone)."""
    deepest = max(target.interface_depths, default=float(grid.depth.max()))
    ax.set_xlim(float(grid.depth.min()) - 0.02, min(float(grid.depth.max()), deepest + 0.25))


def _save(fig, path):
    return save_figure(fig, path, dpi=110, bbox_inches="tight")


def _cell_xy(grid):
    """Map coordinates of the cell centres: velocity index and depth index (ij layout)."""
    return np.meshgrid(np.arange(grid.sizes["velocity"]), np.arange(grid.sizes["depth"]),
                       indexing="ij")


def _frame(ax, grid, target, title):
    """Axes of a (V, L) map, one row per depth and one column per velocity (the depth grid is
    not uniform), depth downwards, interface depths dashed, failed cells crossed."""
    depths, velocities = grid.depth.values, grid.velocity.values
    for H in target.interface_depths:
        ax.axhline(np.interp(H, depths, np.arange(depths.size)), color="k", lw=0.8, ls="--")
    failed = grid["failed"].values.astype(bool)
    X, Y = _cell_xy(grid)
    if failed.any():
        ax.plot(X[failed], Y[failed], "kx", ms=7, mew=1.5, label="FE failed")
        ax.legend(loc="lower right", fontsize=7)
    step = max(1, depths.size // 12)
    ax.set_yticks(np.arange(0, depths.size, step), [f"{d:.4g}" for d in depths[::step]])
    ax.set_xticks(np.arange(velocities.size), [f"{v:g}" for v in velocities], rotation=90)
    ax.set(xlabel="V (m/s)", ylabel="nose depth L (m)", title=title)
    ax.set_ylim(depths.size - 0.5, -0.5)


def _mesh(ax, grid, values, **kwargs):
    return ax.pcolormesh(np.arange(grid.sizes["velocity"] + 1) - 0.5,
                         np.arange(grid.sizes["depth"] + 1) - 0.5,
                         np.asarray(values, dtype=float).T, shading="flat", **kwargs)


def error_maps(grid, target, out):
    """One heat map of ``(analytic - FE)/FE`` (%) per closed form; dots: not resolved by FE."""
    paths = []
    X, Y = _cell_xy(grid)
    for key, label, _ in MODELS:
        rel = 100 * grid[f"rel_err_{key}"].values
        finite = rel[np.isfinite(rel)]
        lim = max(float(np.abs(finite).max()) if finite.size else 1.0, 1.0)
        fig, ax = plt.subplots(figsize=(6.5, 5))
        mesh = _mesh(ax, grid, rel, cmap="RdBu_r", norm=TwoSlopeNorm(0.0, -lim, lim))
        fig.colorbar(mesh, ax=ax, label="(analytic - FE) / FE (%)")
        unresolved = grid[f"resolved_{key}"].values == 0
        ax.plot(X[unresolved], Y[unresolved], "k.", ms=3, label="FE error not small")
        _frame(ax, grid, target, f"{label} vs FE")
        paths.append(_save(fig, out / f"error_{key}.png"))
    return paths


def validity_map(grid, target, out):
    """Where each closed form is within 1 % and 5 % of FE (three panels)."""
    cmap = ListedColormap(VALIDITY_COLOURS)
    norm = BoundaryNorm([-0.5, 0.5, 1.5, 2.5, 3.5], cmap.N)
    fig, axes = plt.subplots(1, len(MODELS), figsize=(5 * len(MODELS), 4.8), sharey=True)
    for ax, (key, label, _) in zip(axes, MODELS, strict=True):
        codes = grid[f"validity_{key}"].values.astype(float)
        codes[codes < 0] = 3
        mesh = _mesh(ax, grid, codes, cmap=cmap, norm=norm)
        _frame(ax, grid, target, label)
    bar = fig.colorbar(mesh, ax=axes, ticks=[0, 1, 2, 3])
    bar.ax.set_yticklabels([f"<= {TOLERANCES[0]:.0%}", f"<= {TOLERANCES[1]:.0%}",
                            f"> {TOLERANCES[1]:.0%}", "FE failed"])
    return _save(fig, out / "validity.png")


def s_curves(grid, target, out, velocities):
    """``S`` against nose depth at a few velocities: FE points, closed forms as lines."""
    fig, ax = plt.subplots(figsize=(7, 5))
    styles = {"dynamic": "-", "quasi_static": "--", "paper": ":"}
    for i, V in enumerate(velocities):
        row = grid.sel(velocity=V)
        colour = f"C{i}"
        ok = row["failed"].values == 0
        ax.plot(row.depth.values[ok], row["S"].values[ok], "o", color=colour, ms=4,
                label=f"FE, V = {V:g} m/s")
        for key, label, _ in MODELS:
            ax.plot(row.depth.values, row[f"S_{key}"].values, styles[key], color=colour, lw=1,
                    label=label if i == 0 else None)
    for H in target.interface_depths:
        ax.axvline(H, color="k", lw=0.8, ls="--")
    _depth_limit(ax, grid, target)
    ax.set(xlabel="nose depth L (m)", ylabel="S = sigma_r / tau (wall layer)", yscale="log",
           title="S against depth (lines: closed forms, points: FE)")
    ax.legend(fontsize=7, ncol=2)
    return _save(fig, out / "S_depth.png")


def state_map(grid, target, out):
    """Categorical map of the derived dynamic and quasi-static response states."""
    keys = ("dynamic", "quasi_static")
    labels = sorted({str(s) for k in keys for s in np.unique(grid[f"state_{k}"].values)})
    cmap = ListedColormap([plt.get_cmap("tab20")(i % 20) for i in range(len(labels))])
    norm = BoundaryNorm(np.arange(len(labels) + 1) - 0.5, cmap.N)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.8), sharey=True)
    for ax, key in zip(axes, keys, strict=True):
        codes = np.vectorize(labels.index)(grid[f"state_{key}"].values.astype(str))
        mesh = _mesh(ax, grid, codes, cmap=cmap, norm=norm)
        _frame(ax, grid, target, f"derived {key.replace('_', '-')} state")
    bar = fig.colorbar(mesh, ax=axes, ticks=range(len(labels)))
    bar.ax.set_yticklabels(labels)
    return _save(fig, out / "states.png")


def plastic_radius_plot(grid, target, out, velocities):
    """FE plastic radius against the derived ``b`` (both conventions) over depth."""
    fig, ax = plt.subplots(figsize=(7, 5))
    for i, V in enumerate(velocities):
        row, colour = grid.sel(velocity=V), f"C{i}"
        ok = row["failed"].values == 0
        ax.plot(row.depth.values[ok], row["plastic_radius"].values[ok], "o", color=colour, ms=4,
                label=f"FE, V = {V:g} m/s")
        ax.plot(row.depth.values, row["b_dynamic"].values, "-", color=colour, lw=1,
                label="derived dynamic" if i == 0 else None)
        ax.plot(row.depth.values, row["b_quasi_static"].values, "--", color=colour, lw=1,
                label="derived quasi-static" if i == 0 else None)
    names = layer_names(target)
    _depth_limit(ax, grid, target)
    for k, H in enumerate(target.interface_depths):
        ax.axvline(H, color="k", lw=0.8, ls="--")
        ax.text(H, ax.get_ylim()[1], f" {names[k]}|{names[k + 1]}", fontsize=7, va="top")
    ax.set(xlabel="nose depth L (m)", ylabel="plastic radius b (m)",
           title="Elastic-plastic boundary: FE against closed forms")
    ax.legend(fontsize=7)
    return _save(fig, out / "plastic_radius.png")


def error_estimate_map(grid, target, out):
    """FE error estimate (log10 of the relative estimate) of every cell."""
    est = grid["error_estimate"].where(grid["failed"] == 0).values
    fig, ax = plt.subplots(figsize=(6.5, 5))
    with np.errstate(divide="ignore"):
        mesh = _mesh(ax, grid, np.log10(np.maximum(est, 1e-12)), cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="log10(FE relative error estimate)")
    _frame(ax, grid, target, "FE error estimate (Richardson)")
    return _save(fig, out / "error_estimate.png")
