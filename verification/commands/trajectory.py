"""``cavex trajectory``: one oblique shot through the layered target (docs/oblique.md).

The job runs :func:`cavex.analytic.penetration.oblique.fly` for the runway (and, with
``compare_homogeneous``, for the first layer alone, as the paper does), writes the histories as
CSV (9 significant digits) and the figures: side view to scale with the projectile outline at
intervals, pitch against time, axial and lateral overload against time and depth with the
interfaces marked, a 3-D view of the path in the layered block to scale (matplotlib's mplot3d).
"""

import json
import math
import sys
import textwrap
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from cavex.analytic.penetration.strike import Strike
from cavex.errors import is_finite_number, require
from cavex.verification.fedata.runner import show_progress
from cavex.verification.output.files import (
    agg_figure,
    collector_paused,
    save_figure,
    write_columns_csv,
    write_text_atomic,
)
from cavex.verification.output.paths import check_output_dir, write_staged

DEFAULT_DIR = "results/trajectory"
# m/s: below it the damping Jacobian frozen over a ROS2 step misjudges the switching contact
# and the steps explode (1e-4 m/s: 241 823 steps against 419 at 1e-3, docs/oblique.md)
MIN_CONTACT_RAMP = 0.001
# m/s: up to it the final depth is within the stated 0.1 % of its V_r -> 0 limit (docs/oblique.md
# convergence table: +1.3e-4 at 0.03, +1.0e-3 at 0.1, +1.7e-3 at 0.3; 100 m/s gave 3x the depth;
# tests/test_edges.py measures 0.03 against 0.001)
MAX_CONTACT_RAMP = 0.03
# m: the held contact's depth (--contact-hold, docs/oblique.md "Held contact"): over it the
# added turn at the paper's debonded interface converges (0.354, 0.337, 0.329, 0.327 deg at
# 3e-6, 1e-6, 3e-7, 1e-7 m, rtol 1e-4; 0.387 deg at 1e-5, rtol 1e-3); its steps measured
# there, not below
MIN_CONTACT_HOLD, MAX_CONTACT_HOLD = 1e-7, 1e-5
# integrator steps per run before it is stopped as a numerical failure: measured shots take
# 300-7 000 (docs/oblique.md); the largest spin once accepted took 599 113 steps (272 s)
MAX_STEPS = 100_000


def trajectory_job(target, projectile, strike, resistance="derived", *, boundary="dynamic",
                   epsilon="quasi-static", free_surface=True, table=None, law_A=None,
                   law_B=None, compare_homogeneous=False, contact_ramp=None, progress=False,
                   tangency_psi=0.0, entry_crater=False, crater=None, contact_hold=None):
    """``{"runs": {"runway": Result, ["first layer only": Result]}, "settings": {...}}``;
    ``progress``: a tqdm bar per run on stderr (steps, simulated time, speed);
    ``contact_ramp`` None: the model's default
    (:data:`~cavex.analytic.penetration.oblique.CONTACT_RAMP`); ``contact_hold`` (m): the held
    contact instead of the ramp (not with ``contact_ramp`` or ``tangency_psi``)."""
    # the command keeps the regularisation on: without it (or far below the default) an
    # oblique shot's sliding shank needs millions of steps (docs/oblique.md); above
    # MAX_CONTACT_RAMP the depth leaves the stated accuracy
    require(contact_ramp is None or (is_finite_number(contact_ramp)
            and MIN_CONTACT_RAMP <= contact_ramp <= MAX_CONTACT_RAMP), "contact_ramp",
            f"in [{MIN_CONTACT_RAMP:g}, {MAX_CONTACT_RAMP:g}] m/s (final depth within 0.1 % "
            "of the V_r -> 0 limit)", contact_ramp)
    require(contact_hold is None or (is_finite_number(contact_hold)
            and MIN_CONTACT_HOLD <= contact_hold <= MAX_CONTACT_HOLD), "contact_hold",
            f"in [{MIN_CONTACT_HOLD:g}, {MAX_CONTACT_HOLD:g}] m (the held contact's depth; the "
            "added turn at a debonded interface converges there)", contact_hold)
    require(contact_hold is None or (contact_ramp is None and not tangency_psi),
            "contact_hold", "given without contact_ramp and tangency_psi (it replaces the "
            "velocity ramp)", contact_hold)
    from cavex.analytic.penetration.oblique import CONTACT_RAMP, fly

    contact_ramp = CONTACT_RAMP if contact_ramp is None else contact_ramp
    options = {"boundary": boundary, "epsilon": epsilon, "free_surface": free_surface,
               "table": table, "law_A": law_A, "law_B": law_B, "contact_ramp": contact_ramp,
               "tangency_psi": tangency_psi, "entry_crater": entry_crater,
               "crater": crater or "nose-base"}
    if contact_hold is not None:
        options["contact_hold"] = contact_hold
    if table is not None:
        from cavex.analytic.penetration.tabulated import read_table
        options["table"] = read_table(table)
    with _steps("runway", progress) as step:
        runs = {"runway": fly(target, projectile, strike, resistance, progress=step, **options)}
    check_answered("runway", runs["runway"])
    if compare_homogeneous and len(target.layers) > 1:
        single = target.single(0)
        if resistance == "table":  # the table belongs to the runway; first layer by closed form
            options = {**options, "table": None}
            resistance_single = "derived"
        else:
            resistance_single = resistance
        with _steps("first layer only", progress) as step:
            runs["first layer only"] = fly(single, projectile, strike, resistance_single,
                                           progress=step, **options)
        check_answered("first layer only", runs["first layer only"])
    settings = {"speed_m_s": strike.speed, "obliquity_deg": strike.obliquity,
                "attack_deg": strike.attack, "attack_plane_deg": strike.attack_plane,
                "spin_rad_s": strike.spin, "resistance": resistance, "boundary": boundary,
                "epsilon": epsilon, "free_surface": free_surface,
                "contact_ramp_m_s": contact_ramp}
    if target.debonded:  # a bonded target's settings (and committed results) are unchanged
        settings["interfaces"] = list(target.bottoms)
    if any(w != 1.0 for w in target.tunnel_walls):  # the default's settings are unchanged
        settings["tunnel_walls"] = list(target.tunnel_walls)
    if tangency_psi:
        settings["tangency_psi_deg"] = tangency_psi
    if contact_hold is not None:  # the ramp is not used; the default's settings are unchanged
        settings["contact_hold_m"] = contact_hold
        del settings["contact_ramp_m_s"]
    if entry_crater:  # the runway's entry crater [top, bottom] (m); the default's settings
        settings["entry_crater_m"] = list(runs["runway"].model.zones[0])  # are unchanged
    if crater is not None:
        settings["crater"] = crater
    if resistance == "law":
        from cavex.verification.commands.options import law_echo

        settings["law"] = law_echo(target, law_A, law_B)
    return {"runs": runs, "settings": settings, "target": target}


def check_answered(name, result):
    """A run that reached the 1 s time limit still moving is no answer (numerical failure):
    either the body has turned tail-first and slides through the target, which resists only
    surfaces moving into it and has no tail face to plough (a large attack, or one against the
    obliquity, gets there), or it is too heavy for the target to stop within the time limit."""
    from cavex.errors import CavexNumericalError

    end = result.end
    if end["state"] != "time limit":
        return
    y = result.solutions[-1].y[:, -1]
    where = (f"to the {end['time_s']:g} s time limit ({end['speed_m_s']:.3g} m/s, nose tip "
             f"{end['nose_tip_m'][2]:.3g} m deep)")
    if float(np.dot(result.model.axis(y), y[7:10])) < 0.0:
        why = ("the body turned tail-first and slid " + where + "; the model loads only "
               "surfaces moving into the target (no tail face): use a smaller --attack or one "
               "toward the obliquity")
    else:
        why = (f"the body was still moving nose-first {where}: a body this heavy for the target "
               "is beyond the model's time")
    raise CavexNumericalError(f"the {name} trajectory did not end: {why}")


@contextmanager
def _steps(name, enabled):
    """``callable(t, y)`` counting integrator steps (a numerical failure past
    :data:`MAX_STEPS`) and, when ``enabled``, advancing a tqdm bar of them."""
    from cavex.errors import CavexNumericalError

    count = [0]

    def budget(t, y):
        count[0] += 1
        if count[0] > MAX_STEPS:
            raise CavexNumericalError(
                f"the {name} trajectory needed more than {MAX_STEPS} integrator steps (stopped "
                f"at t = {t * 1e3:.4g} ms): a spin, attack or contact ramp at the edge of its "
                "range; measured shots take under 10 000 (docs/oblique.md)")

    if not enabled:
        yield budget
        return
    from tqdm.auto import tqdm

    bar = tqdm(desc=name, unit=" steps", file=sys.stderr, dynamic_ncols=True, leave=False)

    def step(t, y):
        budget(t, y)
        bar.update()
        bar.set_postfix_str(f"t = {t * 1e3:.3f} ms, {float(np.linalg.norm(y[7:10])):.1f} m/s",
                            refresh=False)

    try:
        yield step
    finally:
        bar.close()


def run_summary(result):
    """End state and phases of one run (JSON-ready; each phase with its ``pitch_change_deg``),
    the largest pitch rate and overloads, and the axial overload's peaks
    (:func:`~cavex.analytic.penetration.oblique.overload_peaks`) as ``overload_peaks``
    ``[{"tip_depth_m", "axial_g"}]``."""
    from cavex.analytic.penetration.oblique import overload_peaks, peaks

    return {"end": result.end, "phases": result.phases, **peaks(result.history),
            "overload_peaks": [{"tip_depth_m": z, "axial_g": g}
                               for z, g in overload_peaks(result.history)]}


def summary(job, written=None):
    """What ``cavex trajectory --json`` prints: the runway's end and phases, the settings,
    :func:`run_summary` of every run and (``written``) the files written; a number that is not
    finite (a repeated time sample gives an infinite rate) is a numerical failure."""
    from cavex.errors import CavexNumericalError

    runs = {name: run_summary(result) for name, result in job["runs"].items()}
    try:
        json.dumps(runs, allow_nan=False)
    except ValueError:
        raise CavexNumericalError("the trajectory summary is not finite (peaks, pitch "
                                  "rate)") from None
    main = runs["runway"]
    document = {"end": main["end"], "phases": main["phases"], "settings": job["settings"],
                "runs": runs, **({"estimate": job["estimate"]} if "estimate" in job else {})}
    return document if written is None else {**document, "outputs": written}


def write_outputs(job, out, draw=True):
    """CSV histories, ``summary.json`` (the settings and :func:`run_summary` of each run) and,
    if ``draw``, the figures into ``out``; returns the paths written."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    written = [str(write_columns_csv(folder / f"history_{name.replace(' ', '_')}.csv",
                                     result.history))
               for name, result in job["runs"].items()]
    path = folder / "summary.json"
    document = summary(job)
    text = json.dumps({k: document[k] for k in ("settings", "runs", "estimate") if k in document},
                      indent=2)
    write_text_atomic(path, text + "\n")
    written.append(str(path))
    if draw:
        written += figures(job, folder)
    return written


# --- figures ----------------------------------------------------------------------------------

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


def _layer_names(ax, target):
    """Each layer's name at the right edge of a side view, in the middle of the part of its
    depth range that is in view (only the layers in view)."""
    tops = [0.0, *target.interface_depths, math.inf]
    deep, shallow = ax.get_ylim()  # the axis is inverted: ylim = (deepest, shallowest)
    for k, name in enumerate(target.layer_names()):
        low, high = max(tops[k], shallow, 0.0), min(tops[k + 1], deep)
        if high > low:
            ax.text(1.01, 0.5 * (low + high), name, transform=ax.get_yaxis_transform(),
                    va="center", fontsize=8, color="0.3")


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


def side_view(job, path):
    """The path in the plane of obliquity to scale (equal axes) around what moves
    (:func:`side_limits`): the centre of mass and the outline at 9 equal time intervals, the
    surface, the interfaces in view and the layers named; the legend below the axes."""
    target = job["target"]
    curves, xs, zs = [], [], []
    for k, (name, result) in enumerate(job["runs"].items()):
        h = result.history
        outlines = [outline_points(result, result.state(t))
                    for t in np.linspace(0.0, h["t_s"][-1], 9)]
        curves.append((name, f"C{k}", h, outlines))
        xs += [h["cg_x_m"], *(o[0] for o in outlines)]
        zs += [h["cg_z_m"], *(o[1] for o in outlines)]
    (x0, x1), (z0, z1) = side_limits(np.concatenate(xs), np.concatenate(zs), target)
    # the axes box to scale: 5.75 in wide, or narrower where 8 in high would not hold it (the
    # figure then narrower too, at least 5.5 in for the title and the legend)
    box_w = min(SIDE_WIDTH_IN - 1.75, 8.0 * (x1 - x0) / (z1 - z0))
    box_h = box_w * (z1 - z0) / (x1 - x0)
    rows = 2 * len(curves)  # legend rows: centre of mass and outline of each run
    bottom, top = 0.6 + 0.2 * rows, 0.55
    fig = agg_figure(figsize=(max(box_w + 1.75, 5.5), box_h + bottom + top))
    ax = fig.subplots()
    margins(fig, left=0.75, right=1.0, top=top, bottom=bottom)
    for name, color, h, outlines in curves:
        ax.plot(h["cg_x_m"], h["cg_z_m"], color=color, lw=1, label=f"{name}: centre of mass")
        for k, (ox, oz) in enumerate(outlines):
            ax.plot(ox, oz, color=color, lw=0.8,
                    label=f"{name}: outline at 9 equal time intervals" if k == 0 else None)
    for depth in target.interface_depths:
        if z0 < depth < z1:
            ax.axhline(depth, color="0.5", lw=0.8, ls="--")
    ax.axhline(0.0, color="k", lw=1)
    ax.set_xlim(x0, x1)
    ax.set_ylim(z1, z0)  # depth downward
    ax.set_aspect("equal")
    _layer_names(ax, target)
    ax.set_xlabel("x (m, horizontal, plane of obliquity)")
    ax.set_ylabel("z (m, depth)")
    # the title (wrapped to the narrow figure) above the axes, the legend below: off the data
    fig.suptitle(textwrap.fill(_title(job), 64), fontsize=9, va="top",
                 y=1.0 - 0.05 / fig.get_size_inches()[1])
    fig.legend(*ax.get_legend_handles_labels(), fontsize=8, loc="lower center",
               bbox_to_anchor=(0.5, 0.0), frameon=False)
    return save_figure(fig, path, dpi=120)


def _title(job):
    s = job["settings"]
    law = s["resistance"] + (f"-{s['boundary']}" if s["resistance"] == "derived" else "")
    return (f"V0 = {s['speed_m_s']:g} m/s, obliquity {s['obliquity_deg']:g} deg, attack "
            f"{s['attack_deg']:g} deg; resistance {law}, "
            + (f"contact ramp {s['contact_ramp_m_s']:g} m/s" if "contact_ramp_m_s" in s
               else f"held contact {s['contact_hold_m']:g} m")
            + (f"; entry crater to {s['entry_crater_m'][1]:.3g} m" if "entry_crater_m" in s
               else ""))


def _note(ax, text):
    """``text`` in the middle of an empty axes (instead of a curve of round-off)."""
    ax.set_xticks([])
    ax.set_yticks([])
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", fontsize=9,
            wrap=True, color="0.25")


def pitch_time(job, path):
    """Pitch against time with the phase ends dotted; a note instead of a curve where the
    pitch stays below :data:`PITCH_ROUNDOFF_DEG` (round-off)."""
    fig = agg_figure(figsize=(8, 4.5))
    ax = fig.subplots()
    runs = job["runs"].items()
    moving = [(k, name, result) for k, (name, result) in enumerate(runs)
              if np.max(np.abs(result.history["pitch_deg"])) >= PITCH_ROUNDOFF_DEG]
    for k, name, result in moving:
        h = result.history
        ax.plot(h["t_s"] * 1e3, h["pitch_deg"], color=f"C{k}", label=name)
        for ph in result.phases[:-1]:
            ax.axvline(ph["end_time_s"] * 1e3, color=f"C{k}", lw=0.6, ls=":")
    # room on the right for the legend (off the data) only where there are curves
    margins(fig, left=0.8, right=1.6 if moving else 0.8, top=0.75, bottom=0.55)
    if moving:
        ax.set_xlabel("t (ms)")
        ax.set_ylabel("pitch (deg, axis from +z toward +x)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    still = [name for name, _ in runs if name not in {m[1] for m in moving}]
    if still:
        note = (f"pitch of {', '.join(still)} stays 0 (below {PITCH_ROUNDOFF_DEG:g} deg: "
                "round-off; a shot in its plane of symmetry does not turn)")
        if moving:
            ax.text(0.01, 0.02, note, transform=ax.transAxes, fontsize=8, color="0.25")
        else:
            _note(ax, note.replace(" (", "\n("))
    ax.set_title(_title(job).replace("; ", "\n")
                 + ("; dotted: phase ends (nose tip crosses an interface, ...)"
                    if moving else ""), fontsize=9)
    return save_figure(fig, path, dpi=120)


def overloads(job, path):
    """Axial and lateral overload against time and nose-tip depth; a note instead of the
    lateral curves where they stay below :data:`LATERAL_ROUNDOFF` of the axial peak."""
    from matplotlib.ticker import MaxNLocator

    fig = agg_figure(figsize=(10, 7))
    axes = fig.subplots(2, 2)
    margins(fig, left=0.75, right=0.2, top=0.55, bottom=0.55 + 0.25 * (len(job["runs"]) > 1),
            hspace=0.3, wspace=0.22)
    runs = list(job["runs"].items())
    for row, key in enumerate(("axial_g", "lateral_g")):
        shown = 0
        for k, (name, result) in enumerate(runs):
            h = result.history
            peak = np.max(np.abs(h["axial_g"]))
            if key == "lateral_g" and np.max(np.abs(h[key])) < LATERAL_ROUNDOFF * peak:
                continue
            shown += 1
            axes[row, 0].plot(h["t_s"] * 1e3, h[key] / 1e3, color=f"C{k}", label=name)
            axes[row, 1].plot(h["tip_z_m"], h[key] / 1e3, color=f"C{k}", label=name)
        word = key.split("_")[0]
        if not shown:
            for a in axes[row]:
                _note(a, f"lateral overload 0\n(below {LATERAL_ROUNDOFF:g} of the axial peak: "
                      "round-off;\na shot in its plane of symmetry\nhas no lateral force)")
            continue
        axes[row, 0].set_ylabel(f"{word} overload (thousands of g)")
        axes[row, 0].set_xlabel("t (ms)")
        axes[row, 1].set_xlabel("nose-tip depth (m); dashed: interfaces")
        deepest = max(float(np.max(r.history["tip_z_m"])) for _, r in runs)
        _interfaces(axes[row, 1], job["target"], vertical=False, deepest=deepest)
        for a in axes[row]:
            a.grid(alpha=0.3)
            a.xaxis.set_major_locator(MaxNLocator(6))  # no overprinted ticks (mm depths)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.suptitle(_title(job), fontsize=10)
    if len(runs) > 1:
        fig.legend(handles, labels, loc="lower center", ncol=len(runs), fontsize=8,
                   frameon=False, bbox_to_anchor=(0.5, 0.0))
    return save_figure(fig, path, dpi=120)


LAYER_COLOURS = ("#bbbbbb", "#c8a27a", "#9cbf5a", "#8c8c8c")  # the 3-D view's layers, top down
VIEW_3D_SIZE_IN = (7.5, 6.5)  # the 3-D view: width, height (in)


def block_limits(result, target, min_ratio=0.4):
    """``(x limits, y limits, depth limits)`` (m) of the 3-D view's block: around the path and
    the body (tip and centre of mass) with a margin, from above the surface (the body at the
    strike) to below the deepest interface and the path, so that every layer is in it; each
    horizontal extent at least ``min_ratio`` of the largest extent (no hairline axis, room for
    readable ticks); ``y`` covers the half ``y >= 0`` behind the plane of obliquity and any
    lateral motion."""
    h = result.history
    x = np.concatenate([h["tip_x_m"], h["cg_x_m"]])
    y = np.concatenate([h["tip_y_m"], h["cg_y_m"]])
    z = np.concatenate([h["tip_z_m"], h["cg_z_m"]])
    length = result.model.body.length
    interfaces = target.interface_depths or (0.0,)
    top = min(float(z.min()), 0.0) - 0.5 * length
    deepest = max(float(z.max()), interfaces[-1])
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
    """The path in the layered block, drawn to scale (equal axes, ticks in m) with matplotlib's
    mplot3d: the block is cut open along the plane of obliquity (its half ``y >= 0``, behind the
    path as seen), each layer a coloured band on the block's back walls and floor, the surface
    and the interfaces outlined, the centre of mass's path and the body's outline at 6 equal
    time intervals drawn over them; the legend below the axes (off the data)."""
    from matplotlib.patches import Patch
    from matplotlib.ticker import MaxNLocator
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    target = job["target"]
    result = job["runs"]["runway"]
    h = result.history
    (x0, x1), (y0, y1), (top, bottom) = block_limits(result, target)
    fig = agg_figure(figsize=VIEW_3D_SIZE_IN)
    # the drawing order is set here (walls, outlines, path, body): everything drawn is either
    # on the block's back walls or in front of them, so no depth sorting is needed
    ax = fig.add_axes((0.0, 0.12, 1.0, 0.78), projection="3d", computed_zorder=False)
    ax.view_init(elev=22, azim=-58)
    planes = [0.0, *target.interface_depths, bottom]
    names = target.layer_names()
    handles = []
    for k in range(len(planes) - 1):
        a, b = planes[k], planes[k + 1]
        colour = LAYER_COLOURS[k % len(LAYER_COLOURS)]
        walls = [[(x0, y1, a), (x1, y1, a), (x1, y1, b), (x0, y1, b)],  # back wall
                 [(x0, y0, a), (x0, y1, a), (x0, y1, b), (x0, y0, b)]]  # left wall
        if k == len(planes) - 2:  # the floor: under the last layer
            walls.append([(x0, y0, b), (x1, y0, b), (x1, y1, b), (x0, y1, b)])
        ax.add_collection3d(Poly3DCollection(walls, facecolor=colour, alpha=0.45,
                                             edgecolor="none", zorder=1))
        handles.append(Patch(facecolor=colour, alpha=0.6, label=names[k]))
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
    ax.set_zlabel("depth z (m)", fontsize=8, labelpad=6)
    fig.suptitle(_title(job).replace("; ", "\n") + "\nx: horizontal in the plane of obliquity; "
                 "the block cut open along it", fontsize=9, y=0.985)
    fig.legend(handles=handles, fontsize=8, loc="lower center", ncol=min(len(handles), 3),
               frameon=False, bbox_to_anchor=(0.5, 0.0))
    return save_figure(fig, path, dpi=120)


# --- the command -----------------------------------------------------------------------------

def run(args, target, projectile):
    """``cavex trajectory``: checks, runs, writes (every file or none, also on Ctrl-C or
    kill), returns the text or JSON to print."""
    from cavex.analytic.penetration.labels import FLIGHT_RESISTANCES
    from cavex.errors import CavexInputError, CavexNumericalError
    from cavex.verification.commands.options import (
        interface_target,
        law_settings,
        resistance_settings,
    )

    settings = resistance_settings(args, FLIGHT_RESISTANCES)
    target = interface_target(args, target, settings["resistance"])
    if args.tunnel_wall is not None:
        require(is_finite_number(args.tunnel_wall) and 0.0 <= args.tunnel_wall <= 1.0,
                "tunnel-wall", "in [0, 1]", args.tunnel_wall)
        target = target.with_tunnel_wall(args.tunnel_wall)
    require(is_finite_number(args.tangency_psi) and 0.0 <= args.tangency_psi <= 30.0,
            "tangency-psi", "in [0, 30] degrees", args.tangency_psi)
    laws = law_settings(args, target)
    if args.no_free_surface and args.resistance in ("law", "paper"):
        raise CavexInputError(f"option '--no-free-surface' goes with '--resistance derived' (or "
                              f"table); '--resistance {args.resistance}' has no free-surface "
                              "reduction")
    if args.compare_homogeneous and len(target.layers) < 2:
        raise CavexInputError("option '--compare-homogeneous' needs a target of two or more "
                              "layers (this one is its first layer alone already)")
    if args.crater is not None and not (args.entry_crater or target.debonded):
        raise CavexInputError("option '--crater nose-base|nose-tip' goes with '--entry-crater' "
                              "or '--interfaces debonded' (it sets their crater depth)")
    folder = check_output_dir(args.out, "out")
    speed = projectile.V0 if args.velocity is None else args.velocity  # Strike checks it
    strike = Strike(speed, args.obliquity, args.attack, args.attack_plane, args.spin)
    # rifling turns the shank's surface at 0.1-0.5 of the speed; each turn costs ~1 600 steps
    top = strike.speed / projectile.r  # the shank's surface speed <= the striking speed
    require(abs(strike.spin) <= top, "spin",
            f"in [-{top:.6g}, {top:.6g}] rad/s (shank surface speed |spin| r <= the striking "
            f"speed {strike.speed:g} m/s)", strike.spin)
    projectile.body_length  # noqa: B018 (a projectile without a length refuses here)
    try:  # forces beyond the body's mass and inertia overflow (warnings, then a bogus end)
        with np.errstate(over="raise", invalid="raise"):
            job = trajectory_job(target, projectile, strike, settings["resistance"],
                                 boundary=settings["boundary"], epsilon=settings["epsilon"],
                                 free_surface=not args.no_free_surface,
                                 table=settings["table"], **laws,
                                 compare_homogeneous=args.compare_homogeneous,
                                 contact_ramp=args.contact_ramp,
                                 contact_hold=args.contact_hold,
                                 tangency_psi=args.tangency_psi,
                                 entry_crater=args.entry_crater, crater=args.crater,
                                 progress=show_progress(args.progress))
    except FloatingPointError as exc:
        raise CavexNumericalError(f"the trajectory overflowed ({exc}): forces far beyond the "
                                  "projectile's mass and inertia") from None
    for name, result in job["runs"].items():  # nothing but finite numbers is written
        finite = all(np.all(np.isfinite(v)) for v in result.history.values())
        if not finite or result.phases[-1]["end_time_s"] <= 0.0:
            raise CavexNumericalError(
                f"the {name} trajectory " + ("is not finite" if not finite else
                "ended at t = 0 s: the integrator could not advance (a shot too slow, or "
                "forces far beyond the projectile's mass and inertia)"))
    if getattr(args, "estimate", False):  # one refined rerun (analytic/penetration/refinement)
        from cavex.analytic.penetration.refinement import estimate_runs
        job["estimate"] = estimate_runs(job["runs"])
    summary(job)  # the peaks and rates are finite too, before anything is written
    written = write_staged(folder, lambda stage: write_outputs(job, stage, draw=args.figures))
    document = summary(job, written)
    return json.dumps(document, indent=2) if args.json else text(document)


def text(summary):
    """The settings, each run's phase table, end state and peaks, the files written."""
    lines = [_title(summary)]
    for name, s in summary["runs"].items():
        e = s["end"]
        lines += ["", f"{name}:",
                  f"{'phase':<10} {'ends at t (ms)':>14} {'tip z (m)':>10} {'pitch':>8} "
                  f"{'speed':>8}  because"]
        lines += [f"{p['label']:<10} {p['end_time_s'] * 1e3:14.4f} "
                  f"{p['end_nose_tip_m'][2]:10.4f} {p['end_pitch_deg']:8.2f} "
                  f"{p['end_speed_m_s']:8.2f}  {p['end_reason']}" for p in s["phases"]]
        tip = ", ".join(f"{c:.4f}".replace("-0.0000", "0.0000") for c in e["nose_tip_m"])
        lines.append(f"end: {e['state']}, nose tip ({tip}) m, pitch "
                     f"{e['pitch_deg']:.2f} deg; peaks: axial {s['max_axial_g']:.0f} g, "
                     f"lateral {s['max_lateral_g']:.0f} g")
    if "estimate" in summary:
        from cavex.analytic.penetration.refinement import verdict
        lines += ["", *verdict(summary["estimate"])]
    lines += ["", "wrote: " + ", ".join(summary["outputs"])]
    return "\n".join(lines)
