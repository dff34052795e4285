"""``cavex trajectory``: one oblique shot through the layered target (docs/oblique.md).

The job runs :func:`cavex.analytic.penetration.oblique.fly` for the runway (and, with
``compare_homogeneous``, for the first layer alone, as the paper does), writes the histories as
CSV (9 significant digits) and the figures (:mod:`cavex.verification.report.trajectory_figures`):
side view to scale with the projectile outline at intervals, pitch against time, axial and
lateral overload against time and depth with the interfaces marked, a 3-D view of the path in
the layered block to scale (matplotlib's mplot3d).
"""

import argparse
import json
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from cavex.analytic.models import get
from cavex.analytic.models.plain_law import law_echo
from cavex.analytic.penetration.strike import Strike
from cavex.config import load_config
from cavex.errors import CavexInputError, CavexNumericalError, is_finite_number, require
from cavex.verification.commands.options import (
    FLOWN_3D,
    add_interface_option,
    add_resistance_options,
    interface_target,
    law_settings,
    resistance_settings,
)
from cavex.verification.commands.shared_options import add_config_option, add_figures_option
from cavex.verification.fedata.runner import show_progress
from cavex.verification.output.files import run_stem, write_columns_csv, write_text_atomic
from cavex.verification.output.json_document import json_text
from cavex.verification.output.paths import check_output_dir, write_staged
from cavex.verification.report.trajectory_figures import figures, run_label, shot_title

HELP = ("oblique shot with attitude: the rigid projectile in 3-D through the layers "
        "(docs/oblique.md)")
DEFAULT_DIR = "results/trajectory"
# m/s: below it the damping Jacobian frozen over a ROS2 step misjudges the switching contact
# and the steps explode (1e-4 m/s: 14 894 steps against 298 at 1e-3, docs/oblique.md)
MIN_CONTACT_RAMP = 0.001
# m/s: up to it the final depth is within the stated 0.1 % of its V_r -> 0 limit (docs/oblique.md
# convergence table: +1.3e-4 at 0.03, +4.0e-4 at 0.1, +1.3e-3 at 0.3; 100 m/s gave 3x the depth;
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


def add_arguments(parser):
    """The options of ``cavex trajectory``."""
    add_config_option(parser)
    parser.add_argument("--velocity", type=float, help="striking speed (m/s; default: the "
                        f"projectile's V0, {load_config()[1].V0:g} m/s for the paper's Table 1)")
    parser.add_argument("--obliquity", type=float, default=0.0,
                        help="angle of the velocity from the target normal (deg)")
    parser.add_argument("--attack", type=float, default=0.0,
                        help="angle of attack, axis from velocity (deg)")
    parser.add_argument("--attack-plane", type=float, default=0.0, help="plane of the angle of "
                        "attack about the velocity (deg; 0: in the plane of obliquity, nose "
                        "toward the surface, +x, or -x for a negative obliquity, the mirror "
                        "shot; 90: toward +y)")
    parser.add_argument("--spin", type=float, default=0.0, help="spin about the axis (rad/s)")
    add_resistance_options(parser, FLOWN_3D)
    add_interface_option(parser)
    parser.add_argument("--contact-ramp", type=float, help="contact regularisation: the stress "
                        "rises linearly over 0 < V_n < this (m/s; default 0.01; docs/oblique.md)")
    parser.add_argument("--contact-hold", type=float, help="held contact instead of the ramp: "
                        "each element's load rises over this push into its wall, then it cuts "
                        "(m in [1e-7, 1e-5]; not with --contact-ramp or --tangency-psi; default: "
                        "off, the velocity ramp; docs/oblique.md)")
    parser.add_argument("--estimate", action="store_true",
                        help="fly each run again with every discretisation parameter refined and "
                        "report the change of each reported quantity as its estimate "
                        "(summary.json 'estimate'; docs/oblique.md)")
    parser.add_argument("--tunnel-wall", type=float, help="factor in [0, 1] on the shank's load "
                        "in every layer (a sensitivity setting, uncalibrated; default: each "
                        "layer's tunnel_wall key, else 1; docs/oblique.md)")
    parser.add_argument("--tangency-psi", type=float, default=0.0, help="OFPM's attenuation: an "
                        "element's load falls linearly within this angle of tangency to its "
                        "velocity (deg in [0, 30]; default 0: none; docs/oblique.md)")
    parser.add_argument("--entry-crater", action="store_true", help="the shank carries no load "
                        "in the entry crater, nose-tip depth 0 to 4.5 r + l (the 1-D crater "
                        "depth; default: off, the tunnel wall from the surface; docs/oblique.md)")
    parser.add_argument("--crater", choices=("nose-base", "nose-tip"), help="where the crater "
                        "depth 4.5 r of the entry and interface craters is measured from (with "
                        "--entry-crater or debonded interfaces; default nose-base, as penetrate)")
    parser.add_argument("--no-free-surface", action="store_true",
                        help="no free-surface reduction of the derived law")
    parser.add_argument("--compare-homogeneous", action="store_true",
                        help="also the same shot into the first layer alone")
    parser.add_argument("--json", action="store_true", help="print JSON")
    add_figures_option(parser, "the CSV histories and summary.json")
    parser.add_argument("--progress", action=argparse.BooleanOptionalAction, help="progress bar "
                        "of integrator steps on stderr (default: when stderr is a terminal)")
    parser.add_argument("--out", default=DEFAULT_DIR,
                        help="output folder (default results/trajectory)")


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
    from cavex.analytic.models import fly
    from cavex.analytic.penetration.oblique import CONTACT_RAMP

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
    runs["runway"].check_answered("runway")
    if compare_homogeneous and len(target.layers) > 1:
        single = target.single(0)
        resistance_single = get(resistance).first_layer or resistance
        if resistance_single != resistance:  # the table belongs to the runway
            options = {**options, "table": None}
        with _steps("first layer only", progress) as step:
            runs["first layer only"] = fly(single, projectile, strike, resistance_single,
                                           progress=step, **options)
        runs["first layer only"].check_answered("first layer only")
    settings = {"speed_m_s": strike.speed, "obliquity_deg": strike.obliquity,
                "attack_deg": strike.attack, "attack_plane_deg": strike.attack_plane,
                "spin_rad_s": strike.spin, "resistance": resistance, "boundary": boundary,
                "epsilon": epsilon,
                # whether the free-surface reduction applied (a law without one: False)
                "free_surface": bool(free_surface and get(resistance).free_surface_option),
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
    if get(resistance).takes_law:
        settings["law"] = law_echo(target, law_A, law_B)
    paper = target.with_interfaces("bonded") == load_config()[0]
    return {"runs": runs, "settings": settings, "target": target,
            "labels": {} if paper else {"runway": "layered target"}}


@contextmanager
def _steps(name, enabled):
    """``callable(t, y)`` counting integrator steps (a numerical failure past
    :data:`MAX_STEPS`) and, when ``enabled``, advancing a tqdm bar of them."""
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


def summary(job):
    """What ``cavex trajectory --json`` prints: the runway's end and phases, the settings,
    :func:`run_summary` of every run and (once written, ``job["outputs"]``) the files written;
    a number that is not finite (a repeated time sample gives an infinite rate) is a numerical
    failure."""
    runs = {name: run_summary(result) for name, result in job["runs"].items()}
    try:
        json.dumps(runs, allow_nan=False)
    except ValueError:
        raise CavexNumericalError("the trajectory summary is not finite (peaks, pitch "
                                  "rate)") from None
    main = runs["runway"]
    document = {"end": main["end"], "phases": main["phases"], "settings": job["settings"],
                "runs": runs, **({"estimate": job["estimate"]} if "estimate" in job else {})}
    return document if "outputs" not in job else {**document, "outputs": job["outputs"]}


def write_outputs(job, out, draw=True):
    """CSV histories, ``summary.json`` (the settings and :func:`run_summary` of each run) and,
    if ``draw``, the figures into ``out``; returns the paths written."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    written = [str(write_columns_csv(folder / f"history_{run_stem(name)}.csv",
                                     result.history))
               for name, result in job["runs"].items()]
    path = folder / "summary.json"
    document = summary(job)
    text = json_text({k: document[k] for k in ("settings", "runs", "estimate") if k in document})
    write_text_atomic(path, text + "\n")
    written.append(str(path))
    if draw:
        written += figures(job, folder)
    return written


def run(args, target, projectile):
    """``cavex trajectory``: checks, runs, writes (every file or none, also on Ctrl-C or
    kill); returns the job with the files written (``outputs``)."""
    settings = resistance_settings(args, FLOWN_3D)
    target = interface_target(args, target, settings["resistance"])
    if args.tunnel_wall is not None:
        require(is_finite_number(args.tunnel_wall) and 0.0 <= args.tunnel_wall <= 1.0,
                "tunnel-wall", "in [0, 1]", args.tunnel_wall)
        target = target.with_tunnel_wall(args.tunnel_wall)
    require(is_finite_number(args.tangency_psi) and 0.0 <= args.tangency_psi <= 30.0,
            "tangency-psi", "in [0, 30] degrees", args.tangency_psi)
    laws = law_settings(args, target)
    if args.no_free_surface and not get(args.resistance).free_surface_option:
        raise CavexInputError(f"option '--no-free-surface' goes with '--resistance derived'; "
                              f"'--resistance {args.resistance}' has no free-surface reduction")
    if (args.boundary is not None and get(args.resistance).first_layer
            and not args.compare_homogeneous):
        raise CavexInputError(f"option '--boundary' with '--resistance {args.resistance}' is the "
                              "convention of the first layer alone's closed form: it goes with "
                              "'--compare-homogeneous'")
    if args.compare_homogeneous and len(target.layers) < 2:
        raise CavexInputError("option '--compare-homogeneous' needs a target of two or more "
                              "layers (this one is its first layer alone already)")
    if args.crater is not None and not (args.entry_crater or target.debonded):
        raise CavexInputError("option '--crater nose-base|nose-tip' goes with '--entry-crater' "
                              "or '--interfaces debonded' (it sets their crater depth)")
    folder = check_output_dir(args.out, "out")
    speed = projectile.V0 if args.velocity is None else args.velocity  # Strike checks it
    strike = Strike(speed, args.obliquity, args.attack, args.attack_plane, args.spin)
    # rifling turns the shank's surface at 0.1-0.5 of the speed; each turn costs ~170 steps
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
    job["outputs"] = write_staged(folder,
                                  lambda stage: write_outputs(job, stage, draw=args.figures),
                                  replaces=OUTPUTS)
    return job


#: every file ``cavex trajectory`` can write (a rerun into the folder replaces them all)
OUTPUTS = ("history_*.csv", "summary.json", "path_side.png", "pitch_time.png", "overload.png",
           "path_3d.png")


def degrees(angle):
    """An angle (deg) to 2 decimals, without the sign of a zero (-0.001 is "0.00")."""
    words = f"{angle:.2f}"
    return "0.00" if words == "-0.00" else words


def text(job):
    """The settings, each run's phase table, end state and peaks, the files written."""
    document = summary(job)
    lines = [shot_title(document)]
    for name, s in document["runs"].items():
        e = s["end"]
        lines += ["", f"{run_label(job, name)}:",
                  f"{'phase':<10} {'ends at t (ms)':>14} {'tip z (m)':>10} {'pitch':>8} "
                  f"{'speed':>8}  because"]
        lines += [f"{p['label']:<10} {p['end_time_s'] * 1e3:14.4f} "
                  f"{p['end_nose_tip_m'][2]:10.4f} {degrees(p['end_pitch_deg']):>8} "
                  f"{p['end_speed_m_s']:8.2f}  {p['end_reason']}" for p in s["phases"]]
        tip = ", ".join(f"{c:.4f}".replace("-0.0000", "0.0000") for c in e["nose_tip_m"])
        lines.append(f"end: {e['state']}, nose tip ({tip}) m, pitch "
                     f"{degrees(e['pitch_deg'])} deg; peaks: axial {s['max_axial_g']:.0f} g, "
                     f"lateral {s['max_lateral_g']:.0f} g")
    if "estimate" in document:
        from cavex.analytic.penetration.refinement import verdict
        lines += ["", *verdict(document["estimate"])]
    lines += ["", "wrote: " + ", ".join(document["outputs"])]
    return "\n".join(lines)
