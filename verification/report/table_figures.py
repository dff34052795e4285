"""The figure of ``cavex table``: the tabulated ``S(V, L) = sigma_r / tau`` against the cavity
expansion velocity V, one line per nose depth L, drawn without pyplot.

The lines are coloured by depth (the colour bar, depth downward) and styled by the layer at
the cavity wall (the legend names each layer and its depth range); the depths where the wall
layer switches (the table's ``wall_layer`` changes: the layer interfaces as the cavity meets
them) are marked on the colour bar and named in the legend. ``S`` jumps there: ``tau`` is the
wall layer's. The panel is drawn by :func:`draw_table` on a matplotlib ``Axes`` from a table
(a :class:`cavex.netcdf3.PlainDataset` or an :class:`xarray.Dataset`: its ``S``,
``velocity``, ``depth``, ``wall_layer`` and the attribute ``layer_names``), so that the
Python API draws the same.
"""

import json

import numpy as np

from cavex.verification.output.files import agg_figure, collector_paused, save_figure

#: line styles of the wall layers, in order (a fifth layer takes the first again)
LAYER_STYLES = ("-", "--", ":", "-.")
SWITCH_COLOUR = "red"  # the switch depths across the colour bar


def figure_path(out):
    """The figure's path beside the table ``out``: ``<stem>_S.png``."""
    return out.with_name(out.stem + "_S.png")


def figure(table, path):
    """The figure of :func:`draw_table` into ``path`` (drawn with the collector paused);
    returns ``path``."""
    with collector_paused():
        fig = agg_figure(figsize=(8.0, 5.2))
        ax = fig.add_subplot()
        draw_table(ax, table)
        fig.tight_layout()
        return save_figure(fig, path, dpi=120)


def layer_names(table):
    """The layer names of ``table`` (its attribute ``layer_names``, JSON), a name missing or
    empty read as ``layer k``."""
    names = json.loads(table.attrs.get("layer_names", "[]"))
    count = int(np.max(np.asarray(table["wall_layer"]))) + 1
    names = list(names) + [""] * max(0, count - len(names))
    return [name or f"layer {k + 1}" for k, name in enumerate(names)]


def wall_segments(table):
    """``[(layer index, first depth, last depth)]``: the runs of consecutive depths with the
    same layer at the cavity wall, in depth order."""
    depth = np.asarray(table["depth"], dtype=float)
    wall = np.asarray(table["wall_layer"], dtype=int)
    segments = []
    for L, k in zip(depth, wall, strict=True):
        if segments and segments[-1][0] == k:
            segments[-1][2] = float(L)
        else:
            segments.append([int(k), float(L), float(L)])
    return [tuple(s) for s in segments]


def switch_depths(table):
    """The depths (m) where the wall layer switches: the first depth of each segment but the
    first (the table's switch node, 1e-9 m below the switch itself)."""
    return [first for _, first, _ in wall_segments(table)[1:]]


def counted(n, word, plural=None):
    """``n word`` or ``n words`` (``plural``: the plural where it is not word + s)."""
    return f"{n} {word if n == 1 else plural or word + 's'}"


def depth_range(first, last):
    """``first-last`` (m, 3 digits), or one depth."""
    return f"{first:.3g}" if f"{first:.3g}" == f"{last:.3g}" else f"{first:.3g}-{last:.3g}"


def draw_table(ax, table, cmap="viridis"):
    """On ``ax``: ``S`` against V (m/s), one line per depth coloured by depth (colour bar
    beside ``ax``, depth downward, the switch depths as red lines across it) and styled by
    the wall layer; the legend names each wall layer with its depth range and the switch
    depths. A failed cell (NaN) leaves a gap in its line. Returns the colour bar."""
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D

    velocity = np.asarray(table["velocity"], dtype=float)
    depth = np.asarray(table["depth"], dtype=float)
    S = np.asarray(table["S"], dtype=float)
    wall = np.asarray(table["wall_layer"], dtype=int)
    names = layer_names(table)
    low, high = float(depth.min()), float(depth.max())
    if high <= low:  # one depth: a colour bar of some width around it
        low, high = low - 0.05, high + 0.05
    norm, colours = Normalize(low, high), colormaps[cmap]
    for j, L in enumerate(depth):
        ax.plot(velocity, S[:, j], color=colours(norm(L)), lw=1.0,
                ls=LAYER_STYLES[wall[j] % len(LAYER_STYLES)], marker="o" if velocity.size < 4
                else None, ms=3)
    ax.set_xlim(float(velocity.min()), float(velocity.max()))
    ax.set_xlabel("cavity expansion velocity V (m/s)")
    ax.set_ylabel(r"S = $\sigma_r$ / $\tau$ of the wall layer")
    ax.set_title(f"Tabulated S(V, L): {counted(velocity.size, 'velocity', 'velocities')} x "
                 f"{counted(depth.size, 'depth')}, {counted(len(names), 'layer')}", fontsize=10)
    bar = ax.figure.colorbar(ScalarMappable(norm, colours), ax=ax)
    bar.set_label("nose-tip depth L (m)")
    bar.ax.invert_yaxis()  # depth downward
    switches = switch_depths(table)
    for L in switches:
        bar.ax.axhline(L, color=SWITCH_COLOUR, lw=2.0)
    handles = [Line2D([], [], color="0.2", ls=LAYER_STYLES[k % len(LAYER_STYLES)],
                      label=f"wall in {names[k]}: L {depth_range(first, last)} m")
               for k, first, last in wall_segments(table)]
    if switches:
        handles.append(Line2D([], [], color=SWITCH_COLOUR, lw=2.0, label="wall layer switches "
                              "(colour bar): L = " + ", ".join(f"{L:.4g}" for L in switches)
                              + " m"))
    ax.legend(handles=handles, fontsize=8, loc="best")
    return bar
