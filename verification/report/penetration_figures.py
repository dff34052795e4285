"""The figures of ``cavex penetrate``: velocity against time and deceleration against nose-tip
depth, the runway beside its first layer alone (the paper's Fig. 4 pair), drawn without pyplot.

Each takes the command's job (:func:`cavex.verification.commands.penetrate.penetration_job`:
its ``runs``, ``title``, ``layer_names``, ``interface_depths``, ``table``, ``debonded``); the
panels are drawn by functions of a matplotlib ``Axes`` and the job (:func:`draw_velocity`,
:func:`draw_deceleration`), so that the Python API draws the same.
"""

import textwrap

from cavex.verification.output.files import agg_figure, collector_paused, save_figure


def figures(job, out):
    """The two figures into the folder ``out``, made without pyplot and drawn with the garbage
    collector paused (:func:`~cavex.verification.output.files.collector_paused`); returns their
    paths."""
    with collector_paused():
        fig = agg_figure(figsize=(6.4, 4.8))
        draw_velocity(fig.add_subplot(), job)
        velocity_png = _save(fig, out / "velocity_time.png")
        fig = agg_figure(figsize=(6.4, 4.8))
        draw_deceleration(fig.add_subplot(), job)
        return [velocity_png, _save(fig, out / "deceleration_depth.png")]


def _labels(job):
    """The legend's words for the target (the paper's: "runway"; another: "layered target")
    and for its first layer alone."""
    names = job.get("layer_names", [])
    paper = job.get("target_label", "runway").startswith("runway")
    whole, kind = ("runway", "layered, ") if paper else ("layered target", "")
    if job.get("debonded"):
        label = f"{whole} ({kind}debonded interfaces)"
    elif job.get("table") is not None:
        label = f"{whole} ({kind}FE table)"
    else:
        label = f"{whole} (layered)" if paper else whole
    return label, f"{names[0] if names else 'first layer'} alone"


def subtitle(job):
    """The resistance in words (``job["title"]``), with ", debonded interfaces" where the
    target has any, wrapped to 70 characters."""
    words = job["title"] + (", debonded interfaces" if job.get("debonded") else "")
    return textwrap.fill(words, 70)


#: The two runs' curves are called identical when their depths at every common time differ by
#: less than this fraction of the final depth: far below a pixel (1/600 of an axis), far
#: above the interpolation between the runs' own samples (measured: 2.2e-6 for the global
#: plain law, whose runs are the same; 6.8e-2 for the default derived runs, which differ).
SAME_CURVES = 1e-4


def same_curves(job):
    """Whether the layered run and its first layer alone coincide (:data:`SAME_CURVES`):
    the layered target's resistance does not depend on the layer (``--resistance law`` with
    the global ``--law-A/--law-B``: one law everywhere). The first layer alone's depth is
    interpolated at the layered run's times by the cubic Hermite of its depths and
    velocities (``dL/dt = V``)."""
    import numpy as np
    from scipy.interpolate import CubicHermiteSpline

    runway, single = job["runs"]["runway"], job["runs"]["first_layer_only"]
    end = max(float(runway.depth[-1]), float(single.depth[-1]))
    if abs(float(runway.depth[-1]) - float(single.depth[-1])) > SAME_CURVES * end:
        return False
    t, k = np.unique(single.t, return_index=True)  # a phase end is sampled twice
    depth = CubicHermiteSpline(t, single.depth[k], single.velocity[k])
    inside = runway.t <= t[-1]
    gap = np.abs(depth(runway.t[inside]) - runway.depth[inside])
    return bool(np.max(gap, initial=0.0) <= SAME_CURVES * end)


def note_same_curves(ax, job):
    """Where the two runs coincide (:func:`same_curves`), say so inside ``ax``: otherwise
    the dashed curve of the first layer alone hides the layered one without a word."""
    if not same_curves(job):
        return
    runway_label, single_label = _labels(job)
    why = (" (the global --law-A/--law-B is one law in every layer)"
           if isinstance(job.get("law"), dict) else "")
    ax.text(0.98, 0.97, textwrap.fill(f"{runway_label} and {single_label}: one curve, "
                                      f"drawn on each other{why}", 42),
            transform=ax.transAxes, ha="right", va="top", multialignment="left",
            fontsize=8.5, color="0.2",
            bbox={"boxstyle": "round", "facecolor": "white", "edgecolor": "0.6"})


def draw_velocity(ax, job):
    """On ``ax``: velocity against time of the runway and of its first layer alone (dashed),
    titled with the resistance (``job["title"]``), the legend below the axes."""
    runway, single = job["runs"]["runway"], job["runs"]["first_layer_only"]
    runway_label, single_label = _labels(job)
    ax.plot(runway.t * 1e3, runway.velocity, label=runway_label)
    ax.plot(single.t * 1e3, single.velocity, "--", label=single_label)
    ax.set(xlabel="time (ms)", ylabel="velocity (m/s)")
    note_same_curves(ax, job)
    ax.set_title(f"Velocity against time\n{subtitle(job)}", fontsize=10)
    legend_below(ax)


def draw_deceleration(ax, job):
    """On ``ax``: deceleration (10^3 g) against nose-tip depth of the runway and of its first
    layer alone (dashed), the interfaces dotted and the layers named above the axes
    (:func:`layer_names`), the legend below the axes."""
    runway, single = job["runs"]["runway"], job["runs"]["first_layer_only"]
    runway_label, single_label = _labels(job)
    ax.plot(runway.depth, runway.deceleration / 9.81 / 1e3, label=runway_label)
    ax.plot(single.depth, single.deceleration / 9.81 / 1e3, "--", label=single_label)
    left, right = ax.get_xlim()
    bounds = [left, *job["interface_depths"], right]
    for depth in job["interface_depths"]:
        ax.axvline(depth, color="grey", linewidth=0.8, linestyle=":")
    ax.set_xlim(left, right)
    rows = layer_names(ax, job.get("layer_names", []), bounds)
    ax.set(xlabel="nose-tip depth (m)", ylabel=r"deceleration ($10^3$ g)")
    note_same_curves(ax, job)
    ax.set_title(f"Deceleration against depth\n{subtitle(job)}", fontsize=10,
                 pad=14 + NAME_ROW_PT * (rows - 1))
    legend_below(ax)


NAME_ROW_PT = 10  # the height of a row of layer names above the axes (points)


def layer_names(ax, names, bounds):
    """Every layer's name above the axes: a layer in view centred on the part of its depth
    range ``bounds[k]`` to ``bounds[k + 1]`` in view, a layer below the view at the right
    edge ("below: name"); a name that would stick out of the axes is moved in to its edge,
    one that would overlap a name already placed goes up a row (extents measured, not
    guessed). Returns the number of rows used (1 when every name fits in one)."""
    from matplotlib.transforms import offset_copy

    left, right = ax.get_xlim()
    renderer = ax.figure.canvas.get_renderer()
    frame, placed = ax.get_window_extent(renderer), []
    for k, name in enumerate(names[:len(bounds) - 1]):
        lo, hi = max(bounds[k], left), min(bounds[k + 1], right)
        if hi <= lo and bounds[k] < right:  # above the view (none: the view starts at 0)
            continue
        for row in range(len(names)):
            where = offset_copy(ax.get_xaxis_transform(), fig=ax.figure, y=NAME_ROW_PT * row,
                                units="points") if row else ax.get_xaxis_transform()
            if hi > lo:
                text = ax.text(0.5 * (lo + hi), 1.0, name, ha="center", va="bottom",
                               fontsize=8, style="italic", transform=where)
            else:
                text = ax.text(right, 1.0, f"below: {name}", ha="right", va="bottom",
                               fontsize=8, style="italic", transform=where)
            box = text.get_window_extent(renderer)
            if box.x0 < frame.x0 or box.x1 > frame.x1:  # moved in to the edge it crosses
                text.set(x=left if box.x0 < frame.x0 else right,
                         ha="left" if box.x0 < frame.x0 else "right")
                box = text.get_window_extent(renderer)
            if any(box.x0 < other.x1 and other.x0 < box.x1 and row == other_row
                   for other, other_row in placed):
                text.remove()
                continue
            placed.append((box, row))
            break
    return 1 + max((row for _, row in placed), default=0)


def legend_below(ax):
    """The legend below the axes, off the data."""
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, frameon=False,
              fontsize=9)


def _save(fig, path):
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)
