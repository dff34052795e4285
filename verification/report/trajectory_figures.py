"""The figures of ``cavex trajectory`` (docs/oblique.md): the side view to scale with the
projectile's outline at intervals, pitch against time, axial and lateral overload against time
and nose-tip depth with the interfaces marked, and a 3-D view of the path in the layered block
to scale (matplotlib's mplot3d), all drawn without pyplot.

Each takes the command's job (``{"runs": {name: Result}, "settings": {...}, "target":
Target}``, :func:`cavex.verification.commands.trajectory.trajectory_job`); the panels are drawn
by functions of a matplotlib ``Axes`` and the job (:func:`draw_side_view`, :func:`draw_pitch`,
:func:`draw_overload_row`, :func:`draw_view_3d`), so that the Python API draws the same.
"""

import math
import textwrap

import numpy as np

from cavex.analytic.models import get
from cavex.verification.output.files import agg_figure, collector_paused, save_figure


def figures(job, folder):
    """The four figures into ``folder``, drawn without pyplot and with the garbage collector
    paused (:func:`collector_paused`); returns their paths."""
    with collector_paused():
        written = [side_view(job, folder / "path_side.png"),
                   pitch_time(job, folder / "pitch_time.png"),
                   overloads(job, folder / "overload.png"),
                   view_3d(job, folder / "path_3d.png")]
    return [str(path) for path in written]


def _interfaces(ax, target, vertical=True, deepest=math.inf):
    """The interfaces down to ``deepest`` (m) as dashed lines (an interface the shot never
    reaches would stretch the axis away from what moves)."""
    for H in target.interface_depths:
        if H <= deepest:
            (ax.axhline if vertical else ax.axvline)(H, color="0.5", lw=0.8, ls="--")


#: A pitch (deg) or lateral overload (fraction of the axial peak) below this is round-off (a
#: shot in the plane of symmetry: normal incidence without attack): noted, not plotted.
PITCH_ROUNDOFF_DEG = 1e-6
LATERAL_ROUNDOFF = 1e-9
SIDE_WIDTH_IN = 7.5  # side view: width (in); its height follows the picture's aspect


def margins(fig, left, right, top, bottom, **space):
    """Place the axes of ``fig`` with fixed margins (in) around them: no layout engine, so a
    figure is drawn once when saved (a layout engine or ``bbox_inches="tight"`` draws it twice
    and lays out its text each time: most of the figure time, benchmarks/commands.py)."""
    width, height = fig.get_size_inches()
    fig.subplots_adjust(left=left / width, right=1.0 - right / width, top=1.0 - top / height,
                        bottom=bottom / height, **space)


def _layer_names(ax, target, only=None):
    """Each layer's name at the right edge of a side view, in the middle of the part of its
    depth range that is in view (only the layers in view); ``only``: the words of the run the
    layers below the first belong to (a homogeneous run beside it flies through the first
    layer's material there: "macadam (runway only)")."""
    tops = [0.0, *target.interface_depths, math.inf]
    deep, shallow = ax.get_ylim()  # the axis is inverted: ylim = (deepest, shallowest)
    for k, name in enumerate(target.layer_names()):
        low, high = max(tops[k], shallow, 0.0), min(tops[k + 1], deep)
        if k > 0 and only:
            name = f"{name} ({only} only)"
        if high > low:
            fit_right(ax.text(1.01, 0.5 * (low + high), name,
                              transform=ax.get_yaxis_transform(), va="center", fontsize=8,
                              color="0.3"))


def fit_right(text, narrowest=6):
    """Wrap ``text`` (a name right of the axes) onto more lines until it ends inside the
    figure (its extent measured), down to ``narrowest`` characters a line: a long layer
    name is not cropped at the figure's edge."""
    figure = text.figure
    renderer = figure.canvas.get_renderer()
    edge, words = figure.bbox.x1, text.get_text()
    for width in range(len(words), narrowest - 1, -1):
        if text.get_window_extent(renderer).x1 <= edge:
            return text
        text.set_text(textwrap.fill(words, width))
    return text


def outline_points(result, y):
    """Closed outline of the projectile (x, z) in the plane of obliquity at state ``y``: the
    outline of :func:`body_outline_3d` (in the plane that contains the axis and the body e2
    axis, the plane of obliquity for in-plane shots)."""
    world = body_outline_3d(result, y)
    return world[:, 0], world[:, 2]


def side_limits(xs, zs, target, min_ratio=0.3):
    """``(x limits, z limits)`` of a side view drawn to scale around what moves: the extent of
    ``xs``, ``zs`` (outlines and path) and the surface, with a margin; the narrower extent is
    widened to at least ``min_ratio`` of the wider (a straight shot is not a hairline), and
    the interfaces the picture reaches are in it."""
    x0, x1 = float(np.min(xs)), float(np.max(xs))
    z0, z1 = min(float(np.min(zs)), 0.0), max(float(np.max(zs)), 0.0)
    span = max(x1 - x0, z1 - z0)
    margin = 0.08 * span
    x0, x1, z0, z1 = x0 - margin, x1 + margin, z0 - margin, z1 + margin
    width, depth = x1 - x0, z1 - z0
    if width < min_ratio * depth:
        middle, half = 0.5 * (x0 + x1), 0.5 * min_ratio * depth
        x0, x1 = middle - half, middle + half
    elif depth < min_ratio * width:
        grow = min_ratio * width - depth
        z0, z1 = z0 - 0.25 * grow, z1 + 0.75 * grow  # mostly below: the target
    return (x0, x1), (z0, z1)


def side_view_curves(job):
    """``(curves, (x limits, z limits))`` of the side view: per run ``(name, colour, history,
    outlines)``, the outlines ``(x, z)`` at 9 equal time intervals, and the limits around them
    and the centre of mass's path (:func:`side_limits`)."""
    curves, xs, zs = [], [], []
    for k, (name, result) in enumerate(job["runs"].items()):
        h = result.history
        outlines = [outline_points(result, result.state(t))
                    for t in np.linspace(0.0, h["t_s"][-1], 9)]
        curves.append((name, f"C{k}", h, outlines))
        xs += [h["cg_x_m"], *(o[0] for o in outlines)]
        zs += [h["cg_z_m"], *(o[1] for o in outlines)]
    return curves, side_limits(np.concatenate(xs), np.concatenate(zs), job["target"])


def draw_side_view(ax, job, curves=None):
    """On ``ax``: the path in the plane of obliquity to scale (equal axes) around what moves:
    the centre of mass and the outline at 9 equal time intervals, the surface, the interfaces
    in view and the layers named. ``curves``: :func:`side_view_curves` of ``job`` (None: made
    here)."""
    target = job["target"]
    curves, ((x0, x1), (z0, z1)) = side_view_curves(job) if curves is None else curves
    for name, color, h, outlines in curves:
        label = legend_label(job, name)
        ax.plot(h["cg_x_m"], h["cg_z_m"], color=color, lw=1.3, ls=(0, (5, 2, 1, 2)),
                label=f"{label}: centre of mass")
        for k, (ox, oz) in enumerate(outlines):
            ax.plot(ox, oz, color=color, lw=0.8,
                    label=f"{label}: outline at 9 equal time intervals" if k == 0
                    else None)
    for depth in target.interface_depths:
        if z0 < depth < z1:
            ax.axhline(depth, color="0.5", lw=0.8, ls="--")
    ax.axhline(0.0, color="k", lw=1)
    ax.set_xlim(x0, x1)
    ax.set_ylim(z1, z0)  # depth downward
    ax.set_aspect("equal")
    _layer_names(ax, target, run_label(job, "runway") if HOMOGENEOUS in job["runs"] else None)
    ax.set_xlabel("x (m, horizontal, plane of obliquity)")
    ax.set_ylabel("z (m, depth)")


def side_view(job, path):
    """The side view (:func:`draw_side_view`) in a figure sized to its scale, the title above
    the axes and the legend below them."""
    curves = side_view_curves(job)
    (x0, x1), (z0, z1) = curves[1]
    # the axes box to scale: 5.75 in wide, or narrower where 8 in high would not hold it (the
    # figure then narrower too, at least 5.5 in for the title and the legend)
    box_w = min(SIDE_WIDTH_IN - 1.75, 8.0 * (x1 - x0) / (z1 - z0))
    box_h = box_w * (z1 - z0) / (x1 - x0)
    rows = 2 * len(curves[0])  # legend rows: centre of mass and outline of each run
    bottom, top = 0.6 + 0.2 * rows, 0.55
    fig = agg_figure(figsize=(max(box_w + 1.75, 5.5), box_h + bottom + top))
    ax = fig.subplots()
    margins(fig, left=0.75, right=1.0, top=top, bottom=bottom)
    draw_side_view(ax, job, curves)
    # the title (wrapped to the narrow figure) above the axes, the legend below: off the data
    fig.suptitle(textwrap.fill(shot_title(job), 64), fontsize=9, va="top",
                 y=1.0 - 0.05 / fig.get_size_inches()[1])
    fig.legend(*ax.get_legend_handles_labels(), fontsize=8, loc="lower center",
               bbox_to_anchor=(0.5, 0.0), frameon=False)
    return save_figure(fig, path, dpi=120)


HOMOGENEOUS = "first layer only"  # the run of --compare-homogeneous


def legend_label(job, name):
    """The run's words in a figure's legend (:func:`run_label`); the homogeneous run of
    ``--compare-homogeneous`` says that its target is the first layer throughout, so that its
    curve drawn past an interface of the layered target is not read as flying through the next
    layer."""
    label = run_label(job, name)
    if name == HOMOGENEOUS:
        label += f" ({job['target'].layer_names()[0]} throughout)"
    return label


def run_label(job, name):
    """The words for the run ``name`` of ``job`` in legends and text: its ``labels`` entry
    (a target other than the paper's: "layered target" for "runway"), else the name."""
    return job.get("labels", {}).get(name, name)


def shot_title(job):
    """One line of the shot's settings (``job`` or its summary: its ``settings``): speed,
    obliquity, attack, resistance, the contact, the entry crater and debonded interfaces."""
    s = job["settings"]
    law = get(s["resistance"]).label(s["boundary"])
    return (f"V0 = {s['speed_m_s']:g} m/s, obliquity {s['obliquity_deg']:g} deg, attack "
            f"{s['attack_deg']:g} deg; resistance {law}, "
            + (f"contact ramp {s['contact_ramp_m_s']:g} m/s" if "contact_ramp_m_s" in s
               else f"held contact {s['contact_hold_m']:g} m")
            + (f"; entry crater to {s['entry_crater_m'][1]:.3g} m" if "entry_crater_m" in s
               else "")
            + ("; debonded interfaces" if "debonded" in s.get("interfaces", ()) else ""))


def _note(ax, text):
    """``text`` in the middle of an empty axes (instead of a curve of round-off)."""
    ax.set_xticks([])
    ax.set_yticks([])
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", fontsize=9,
            wrap=True, color="0.25")


def turning_runs(job):
    """``[(k, name, result)]`` of the runs whose pitch reaches :data:`PITCH_ROUNDOFF_DEG`
    (``k``: the run's colour index)."""
    return [(k, name, result) for k, (name, result) in enumerate(job["runs"].items())
            if np.max(np.abs(result.history["pitch_deg"])) >= PITCH_ROUNDOFF_DEG]


def pitch_time(job, path):
    """Pitch against time (:func:`draw_pitch`), with room on the right for the legend."""
    fig = agg_figure(figsize=(8, 4.5))
    ax = fig.subplots()
    # room on the right for the legend (off the data) only where there are curves
    margins(fig, left=0.8, right=1.6 if turning_runs(job) else 0.8, top=0.75, bottom=0.55)
    draw_pitch(ax, job)
    return save_figure(fig, path, dpi=120)


def draw_pitch(ax, job):
    """On ``ax``: pitch against time with the phase ends dotted, the legend right of the axes;
    a note instead of a curve where the pitch stays below :data:`PITCH_ROUNDOFF_DEG`
    (round-off)."""
    runs = job["runs"].items()
    moving = turning_runs(job)
    for k, name, result in moving:
        h = result.history
        ax.plot(h["t_s"] * 1e3, h["pitch_deg"], color=f"C{k}",
                label=textwrap.fill(legend_label(job, name), 18))  # the right margin's width
        for ph in result.phases[:-1]:
            ax.axvline(ph["end_time_s"] * 1e3, color=f"C{k}", lw=0.6, ls=":")
    if moving:
        ax.set_xlabel("t (ms)")
        ax.set_ylabel("pitch (deg, axis from +z toward +x)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    still = [run_label(job, name) for name, _ in runs if name not in {m[1] for m in moving}]
    if still:
        note = (f"pitch of {', '.join(still)} stays 0 (below {PITCH_ROUNDOFF_DEG:g} deg: "
                "round-off; a shot in its plane of symmetry does not turn)")
        if moving:
            ax.text(0.01, 0.02, note, transform=ax.transAxes, fontsize=8, color="0.25")
        else:
            _note(ax, note.replace(" (", "\n("))
    ax.set_title(shot_title(job).replace("; ", "\n")
                 + ("; dotted: phase ends (nose tip crosses an interface, ...)"
                    if moving else ""), fontsize=9)


def overloads(job, path):
    """Axial (top row) and lateral (bottom row) overload against time and nose-tip depth
    (:func:`draw_overload_row`), one legend below the panels."""
    fig = agg_figure(figsize=(10, 7))
    axes = fig.subplots(2, 2)
    margins(fig, left=0.75, right=0.2, top=0.55, bottom=0.55 + 0.25 * (len(job["runs"]) > 1),
            hspace=0.3, wspace=0.22)
    runs = list(job["runs"].items())
    for row, key in enumerate(("axial_g", "lateral_g")):
        draw_overload_row(axes[row, 0], axes[row, 1], job, key)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.suptitle(shot_title(job), fontsize=10)
    if len(runs) > 1:
        fig.legend(handles, labels, loc="lower center", ncol=len(runs), fontsize=8,
                   frameon=False, bbox_to_anchor=(0.5, 0.0))
    return save_figure(fig, path, dpi=120)


#: The nose tip rising again by more than this fraction of its depth range (a ricochet): the
#: overloads are drawn against the nose tip's path length, on which a curve does not fold back.
TURN_BACK = 0.02


def depth_turns_back(history):
    """Whether the nose-tip depth falls back from its running maximum by more than
    :data:`TURN_BACK` of its range."""
    z = np.asarray(history["tip_z_m"])
    return float(np.max(np.maximum.accumulate(z) - z)) > TURN_BACK * max(float(np.ptp(z)), 1e-12)


def path_length(history):
    """The nose tip's path length ``s_i = sum_{j <= i} |x_tip,j - x_tip,j-1|`` (m)."""
    tip = np.stack([history[f"tip_{c}_m"] for c in "xyz"], axis=-1)
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(tip, axis=0), axis=-1))])


def zone_spans(x, depth, zones):
    """``[(x0, x1)]``: the stretches of ``x`` (time, depth or path length, one value a sample)
    where the nose-tip ``depth`` lies in one of ``zones`` (``(top, bottom)`` depths, m)."""
    spans = []
    for top, bottom in zones:
        inside = np.flatnonzero((depth >= top) & (depth <= bottom))
        if inside.size:
            runs = np.split(inside, np.flatnonzero(np.diff(inside) > 1) + 1)
            spans += [(float(x[r[0]]), float(x[r[-1]])) for r in runs if r[-1] > r[0]]
    return spans


def open_zones_of(job):
    """The layered run's zones (debonded interfaces' craters and rear zones, the entry crater;
    none for a bonded target): ``model.zones``, ``(top, bottom)`` depths (m)."""
    return [tuple(z) for z in getattr(job["runs"]["runway"].model, "zones", [])]


def draw_overload_row(ax_time, ax_depth, job, key):
    """The overload ``key`` ("axial_g" or "lateral_g") of every run against time on
    ``ax_time`` and against nose-tip depth on ``ax_depth`` (the interfaces dashed; against the
    nose tip's path length when the tip rises again, :func:`depth_turns_back`: against depth
    the curve would fold back), the open zones of the layered run shaded; the lateral
    overload as its samples (thin) and their mean over one nose length (thick,
    :func:`~cavex.analytic.penetration.low_pass.low_pass`): the samples step where discrete
    surface points enter and leave contact. A note instead of the lateral curves where they
    stay below :data:`LATERAL_ROUNDOFF` of the axial peak."""
    from matplotlib.ticker import MaxNLocator

    from cavex.analytic.penetration.low_pass import low_pass

    runs = list(job["runs"].items())
    along_path = any(depth_turns_back(r.history) for _, r in runs)
    shown = 0
    for k, (name, result) in enumerate(runs):
        h = result.history
        peak = np.max(np.abs(h["axial_g"]))
        if key == "lateral_g" and np.max(np.abs(h[key])) < LATERAL_ROUNDOFF * peak:
            continue
        shown += 1
        x = path_length(h) if along_path else h["tip_z_m"]
        label = legend_label(job, name)
        if key == "lateral_g":
            mean = low_pass(h, result.model.body.nose_length)
            for a, abscissa in ((ax_time, h["t_s"] * 1e3), (ax_depth, x)):
                a.plot(abscissa, h[key] / 1e3, color=f"C{k}", lw=0.6, alpha=0.45)
                a.plot(abscissa, mean / 1e3, color=f"C{k}", lw=1.6, label=label)
        else:
            ax_time.plot(h["t_s"] * 1e3, h[key] / 1e3, color=f"C{k}", label=label)
            ax_depth.plot(x, h[key] / 1e3, color=f"C{k}", label=label)
    word = key.split("_")[0]
    if not shown:
        for a in (ax_time, ax_depth):
            _note(a, f"lateral overload 0\n(below {LATERAL_ROUNDOFF:g} of the axial peak: "
                  "round-off;\na shot in its plane of symmetry\nhas no lateral force)")
        return
    zones = open_zones_of(job)
    h = job["runs"]["runway"].history
    x = path_length(h) if along_path else h["tip_z_m"]
    for a, abscissa in ((ax_time, h["t_s"] * 1e3), (ax_depth, x)):
        for x0, x1 in zone_spans(abscissa, h["tip_z_m"], zones):
            a.axvspan(x0, x1, color="0.88", lw=0, zorder=0)
    shaded = "; shaded: open zones" if zones else ""
    ax_time.set_ylabel(f"{word} overload (thousands of g)")
    ax_time.set_xlabel("t (ms)" + shaded)
    if along_path:
        ax_depth.set_xlabel("nose-tip path length (m; the tip rises again)" + shaded)
    else:
        ax_depth.set_xlabel("nose-tip depth (m); dashed: interfaces" + shaded)
        deepest = max(float(np.max(r.history["tip_z_m"])) for _, r in runs)
        _interfaces(ax_depth, job["target"], vertical=False, deepest=deepest)
    if key == "lateral_g":
        nose = job["runs"]["runway"].model.body.nose_length
        ax_time.text(0.0, 1.03, "thin: samples (they step as surface points enter and leave "
                     "contact, in the model's force too); thick: mean over one nose length "
                     f"({nose * 1e3:.3g} mm)", transform=ax_time.transAxes, fontsize=8,
                     va="bottom")
    for a in (ax_time, ax_depth):
        a.grid(alpha=0.3)
        a.xaxis.set_major_locator(MaxNLocator(6))  # no overprinted ticks (mm depths)


LAYER_COLOURS = ("#bbbbbb", "#c8a27a", "#9cbf5a", "#8c8c8c")  # the 3-D view's layers, top down
VIEW_3D_SIZE_IN = (7.5, 6.5)  # the 3-D view: width, height (in)


def block_limits(result, target, min_ratio=0.4):
    """``(x limits, y limits, depth limits)`` (m) of the 3-D view's block: around the path and
    the body (tip and centre of mass) with a margin, from above the surface (the body at the
    strike) to below the path, so that the block is to the scale of the shot (a ricochet's
    few centimetres are not drawn in a block of the whole target's depth; the layers below it
    are named in the legend, :func:`draw_view_3d`); each
    horizontal extent at least ``min_ratio`` of the largest extent (no hairline axis, room for
    readable ticks); ``y`` covers the half ``y >= 0`` behind the plane of obliquity and any
    lateral motion."""
    h = result.history
    x = np.concatenate([h["tip_x_m"], h["cg_x_m"]])
    y = np.concatenate([h["tip_y_m"], h["cg_y_m"]])
    z = np.concatenate([h["tip_z_m"], h["cg_z_m"]])
    length = result.model.body.length
    top = min(float(z.min()), 0.0) - 0.5 * length
    deepest = max(float(z.max()), 0.0)
    span = max(float(np.ptp(x)), deepest - top, length)
    margin = 0.1 * span
    bottom = deepest + margin
    x0, x1 = float(x.min()) - margin, float(x.max()) + margin
    depth = bottom - top
    if x1 - x0 < min_ratio * depth:
        middle, half = 0.5 * (x0 + x1), 0.5 * min_ratio * depth
        x0, x1 = middle - half, middle + half
    y0 = min(float(y.min()), 0.0) - 0.5 * margin
    y1 = max(float(y.max()), 0.0, y0 + min_ratio * max(depth, x1 - x0))
    return (x0, x1), (y0, y1), (top, bottom)


def body_outline_3d(result, y):
    """Closed outline of the body in the plane of its axis and its e2 axis, as world points
    ``(n, 3)`` (m; z depth) at state ``y``."""
    from cavex.analytic.penetration.surface_force import rotation_matrix

    body = result.model.body
    ax, rad = body.outline[:, 0], body.outline[:, 1]
    top = np.stack([ax, rad, np.zeros_like(ax)], -1)
    bottom = np.stack([ax[::-1], -rad[::-1], np.zeros_like(ax)], -1)
    pts = np.concatenate([top, bottom, top[:1]])
    return y[0:3] + pts @ rotation_matrix(y[3:7]).T


def view_3d(job, path):
    """The 3-D view (:func:`draw_view_3d`) with the title above and the legend below the axes
    (off the data)."""
    fig = agg_figure(figsize=VIEW_3D_SIZE_IN)
    # the drawing order is set by draw_view_3d (walls, outlines, path, body): everything drawn
    # is either on the block's back walls or in front of them, so no depth sorting is needed
    ax = fig.add_axes((0.0, 0.12, 1.0, 0.78), projection="3d", computed_zorder=False)
    handles = draw_view_3d(ax, job)
    rows = math.ceil(len(handles) / 2)  # the legend's rows below the axes (0.19 in each)
    bottom = (0.45 + 0.19 * rows) / VIEW_3D_SIZE_IN[1]  # and the x label above it
    ax.set_position((0.0, bottom, 1.0, 0.9 - bottom))
    fig.suptitle(shot_title(job).replace("; ", "\n") + "\nx: horizontal in the plane of obliquity; "
                 "the block cut open along it", fontsize=9, y=0.985)
    fig.legend(handles=handles, fontsize=8, loc="lower center", ncol=min(len(handles), 2),
               frameon=False, bbox_to_anchor=(0.5, 0.0))
    return save_figure(fig, path, dpi=120)


def draw_view_3d(ax, job):
    """On the 3-D ``ax`` (``computed_zorder=False``): the target's path in the layered block,
    drawn to scale (equal axes, ticks in m): the block is cut open along the plane of obliquity
    (its half ``y >= 0``, behind the path as seen), each layer a coloured band on the block's
    back walls and floor, the surface and the interfaces outlined, the centre of mass's path
    and the body's outline at 6 equal time intervals drawn over them. Returns the legend's
    handles."""
    from matplotlib.patches import Patch
    from matplotlib.ticker import MaxNLocator
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    target = job["target"]
    result = job["runs"]["runway"]
    h = result.history
    (x0, x1), (y0, y1), (top, bottom) = block_limits(result, target)
    ax.view_init(elev=22, azim=-58)
    planes = [0.0, *(H for H in target.interface_depths if H < bottom), bottom]
    names = target.layer_names()
    handles = [Patch(facecolor="none", edgecolor="none",
                     label=f"below the block: {names[k + 1]} from {H:.3g} m")
               for k, H in enumerate(target.interface_depths) if H >= bottom]
    for k in range(len(planes) - 1):
        a, b = planes[k], planes[k + 1]
        colour = LAYER_COLOURS[k % len(LAYER_COLOURS)]
        walls = [[(x0, y1, a), (x1, y1, a), (x1, y1, b), (x0, y1, b)],  # back wall
                 [(x0, y0, a), (x0, y1, a), (x0, y1, b), (x0, y0, b)]]  # left wall
        if k == len(planes) - 2:  # the floor: under the last layer
            walls.append([(x0, y0, b), (x1, y0, b), (x1, y1, b), (x0, y1, b)])
        ax.add_collection3d(Poly3DCollection(walls, facecolor=colour, alpha=0.45,
                                             edgecolor="none", zorder=1))
        handles.insert(k, Patch(facecolor=colour, alpha=0.6, label=names[k]))
    for k, depth in enumerate(planes[:-1]):  # the surface (solid) and the interfaces (dashed)
        ax.plot([x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0], [depth] * 5, zorder=2,
                color="k" if k == 0 else "0.35", lw=1.0 if k == 0 else 0.8,
                ls="-" if k == 0 else "--")
    path_line, = ax.plot(h["cg_x_m"], h["cg_y_m"], h["cg_z_m"], color="red", lw=1.2, zorder=5,
                         label="centre of mass")
    handles.insert(0, path_line)
    for t in np.linspace(0.0, h["t_s"][-1], 6):
        pts = body_outline_3d(result, result.state(t))
        ax.add_collection3d(Poly3DCollection([pts], facecolor="navy", edgecolor="navy",
                                             lw=0.6, zorder=4))
    handles.insert(1, Patch(facecolor="navy", label="body at 6 equal time intervals"))
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_zlim(bottom, top)  # depth downward
    ax.set_box_aspect((x1 - x0, y1 - y0, bottom - top), zoom=0.95)  # to scale
    extents = (x1 - x0, y1 - y0, bottom - top)
    for axis, extent in zip((ax.xaxis, ax.yaxis, ax.zaxis), extents, strict=True):
        # ticks in proportion to the axis's drawn length: a short axis gets 2-3 (no crowding)
        axis.set_major_locator(MaxNLocator(nbins=max(2, round(5 * extent / max(extents))),
                                           steps=[1, 2, 2.5, 5, 10]))
        axis.set_pane_color((1.0, 1.0, 1.0, 0.0))
    ax.grid(False)
    ax.tick_params(labelsize=8, pad=1)
    ax.set_xlabel("x (m)", fontsize=8, labelpad=6)
    ax.set_ylabel("y (m)", fontsize=8, labelpad=4)
    ax.set_zlabel("depth z (m)", fontsize=8, labelpad=9)
    return handles
