"""The oblique-penetration study (docs/oblique.md, results/oblique): does cavex reproduce the
paper's two 3-D findings?

(i) the layer interfaces accelerate the change of the projectile's attitude, the more so the
lower the striking velocity; (ii) the overload history has a peak at each interface.

Every shot of the grid (obliquities x striking velocities, zero angle of attack, derived
dynamic resistance with the free surface, the default discretisation) is flown into
the runway and into its first layer alone (the paper's comparison), and again refined (every
discretisation parameter at once, :mod:`cavex.analytic.penetration.refinement`): each number
is reported with its estimate, the change under that refinement, and an overload peak only
if it survives it. Per shot: end state,
final nose tip, final pitch, pitch change, largest pitch rate, overload peaks (local maxima of
the axial overload that rise above the dip before them by 5 % of their value,
:func:`cavex.analytic.penetration.oblique.overload_peaks`) and their nose-tip depths.
``--interfaces debonded`` flies the runway with every interface debonded (docs/oblique.md).
The answers are computed from the table, not written by hand.

Run: ``python -m cavex.verification.studies.oblique_study [--out results/oblique] [--workers N]``.
Digits: a last-bit change of the striking speed moves the results through the integrator's
step decisions (measured over the whole grid, see :data:`DECIMALS`), so each quantity is
written with a rounding unit well above its own spread.
"""

import argparse
import json
import math
import sys

import numpy as np

from cavex.analytic.models import fly
from cavex.analytic.penetration.low_pass import low_pass
from cavex.analytic.penetration.oblique import PEAK_SPAN, Strike, overload_peaks, peaks
from cavex.analytic.penetration.refinement import (
    PEAK_TOLERANCE,
    angle_tolerance,
    matched_peaks,
    refined_options,
)
from cavex.config import load_config
from cavex.verification.fedata.runner import run_cases
from cavex.verification.output.files import save_figure, write_text_atomic
from cavex.verification.output.number_format import format_number
from cavex.verification.studies.inputs import output_folder
from cavex.verification.studies.study_axes import broken_axes, symlog_axis

OBLIQUITIES = (0.0, 10.0, 20.0, 30.0, 45.0, 60.0)
VELOCITIES = (400.0, 600.0, 800.0, 1000.0)
TARGETS = ("runway", "first layer only")
DIGITS = 3
# "a peak at an interface": nose-tip depth from 0.1 m before it (the plastic zone ahead of the
# nose reaches an interface 4-8 shank radii ahead) to past the next layer's crater stage, as in
# issue 20: the crater depth (4.5 r from the nose base, zones.crater_depth: 0.116 m for Table 1)
# plus 0.05 m
PEAK_WINDOW = (0.1, 0.166)
# the attitude change "at the interfaces" is counted from a nose-tip depth this far above the
# first interface (the same window): before it, layered and concrete-only shots are alike
APPROACH = PEAK_WINDOW[0]
# every shot at the default discretisation and refined (refinement.refined_options)
LEVELS = ("default", "refined")
# run-to-run spread of the added change (layered - concrete, twice the measured 8.5e-6 deg of
# each, see DECIMALS): an added change counts as non-zero only beyond its estimate plus this
ADDED_SPREAD_DEG = 2.0 * 8.5e-6
DEFAULT_DIR = "results/oblique"


def study_cases(obliquities=OBLIQUITIES, velocities=VELOCITIES, interfaces="bonded"):
    """The shots of the grid, each at the default discretisation and refined; ``interfaces``:
    the runway's interfaces, all bonded or all debonded (docs/oblique.md "Debonded
    interfaces")."""
    cases = [{"id": f"{'layered' if t == 'runway' else 'homogeneous'}_{o:g}deg_{v:g}_{d}",
              "target": t, "obliquity_deg": o, "speed_m_s": v, "discretisation": d,
              "interfaces": interfaces}
             for o in obliquities for v in velocities for t in TARGETS for d in LEVELS]
    if interfaces == "debonded":  # each default runway shot again one ulp faster
        cases += [{**c, "id": c["id"] + "_ulp", "ulp": True} for c in cases
                  if c["target"] == "runway" and c["discretisation"] == "default"]
    return cases


def nose_length(projectile):
    """Length ``sqrt(2 R r - r^2)`` of the projectile's tangent ogive nose (m)."""
    return math.sqrt(2.0 * projectile.R * projectile.r - projectile.r ** 2)


def shot_summary(result, approach_depth, low_pass_length):
    """Numbers of one shot; ``approach_depth``: nose-tip depth from which the attitude change
    near the first interface is counted (the same depth for the shot into concrete alone);
    ``low_pass_length``: the travel over which :func:`low_pass` averages the lateral
    overload for its peak ``max_lateral_low_pass_g``."""
    h = result.history
    near = np.flatnonzero(h["tip_z_m"] >= approach_depth)
    return {"state": result.end["state"], "time_s": result.end["time_s"],
            "tip_x_m": result.end["nose_tip_m"][0], "tip_z_m": result.end["nose_tip_m"][2],
            "pitch_deg": result.end["pitch_deg"],
            "pitch_change_deg": result.end["pitch_deg"] - float(h["pitch_deg"][0]),
            "pitch_change_deep_deg": (result.end["pitch_deg"] - float(h["pitch_deg"][near[0]])
                                      if near.size else None),
            **peaks(h), "overload_peaks": overload_peaks(h),
            "max_lateral_low_pass_g": float(np.max(low_pass(h, low_pass_length))),
            "crossing_speed_m_s": next((p["end_speed_m_s"] for p in result.phases
                                        if p["end_reason"].startswith(
                                            "nose tip crossed interface 1")), None)}


def study_chunk(chunk):
    """Work unit for :func:`cavex.verification.fedata.runner.run_cases`."""
    target, projectile = load_config()
    approach = target.interface_depths[0] - APPROACH
    out = []
    for case in chunk:
        try:
            runway = target.with_interfaces(case.get("interfaces", "bonded"))
            t = runway if case["target"] == "runway" else target.single(0)
            speed = case["speed_m_s"]
            if case.get("ulp"):
                speed = float(np.nextafter(speed, np.inf))
            strike = Strike(speed, obliquity=case["obliquity_deg"])
            options = (refined_options(projectile) if case["discretisation"] == "refined"
                       else {})
            out.append(shot_summary(fly(t, projectile, strike, **options), approach,
                                    nose_length(projectile)))
        except Exception as exc:  # noqa: BLE001 (reported per case)
            out.append(exc)
    return out


def _pairs(results, level="default"):
    """``(obliquity, V, layered, concrete only)`` of every shot at discretisation ``level``."""
    by = {(r["obliquity_deg"], r["speed_m_s"], r["target"]): r for r in results
          if r["discretisation"] == level}
    keys = sorted({(r["obliquity_deg"], r["speed_m_s"]) for r in results})
    return [(o, v, by[(o, v, "runway")], by[(o, v, "first layer only")]) for o, v in keys]


def _added(results, level):
    """Added pitch change near the interfaces (layered - concrete, deg) of every oblique shot
    that reaches the approach depth in both targets, at discretisation ``level``."""
    return {(o, v): lay["pitch_change_deep_deg"] - hom["pitch_change_deep_deg"]
            for o, v, lay, hom in _pairs(results, level)
            if o > 0.0 and lay["pitch_change_deep_deg"] is not None
            and hom["pitch_change_deep_deg"] is not None}


def estimated_added(results):
    """``{(obliquity, V): (added change at the default discretisation, its estimate)}``: the
    estimate is the change under the refinement (refinement.refined_options)."""
    default, fine = _added(results, "default"), _added(results, "refined")
    return {key: (default[key], abs(default[key] - fine[key]))
            for key in default.keys() & fine.keys()}


def surviving_peaks(lay, fine):
    """The overload peaks of the default run ``lay`` that survive the refinement (a peak of
    the refined run ``fine`` within one nose length): ``[(z, g, estimate)]``, and the others
    ``[(z, g)]``."""
    kept, lost = [], []
    for (z, g), match in matched_peaks(lay["overload_peaks"], fine["overload_peaks"]):
        if match is None:
            lost.append((z, g))
        else:
            kept.append((z, g, abs(g - match[1])))
    return kept, lost


def faster_results(results, faster):
    """``results`` with every default runway row replaced by the one flown one ulp faster."""
    return [faster[(r["obliquity_deg"], r["speed_m_s"], r["discretisation"])]
            if r["target"] == "runway" and r["discretisation"] == "default" else r
            for r in results]


def findings(results, interfaces, faster=None):
    """Answers to (i) and (ii) computed from the shots (dict of numbers). (i): an added change
    counts as resolved when it exceeds its estimate (the change under the refinement) plus its
    run-to-run spread (with ``faster``, :func:`split_ulp`, the larger of the bonded spread and
    its own change one ulp faster). (ii): a crossing has a peak when the default run has one
    in the window that survives the refinement (:func:`surviving_peaks`); resolved when its
    estimate is within 3 %."""
    estimated = estimated_added(results)
    added = {k: x for k, (x, _) in estimated.items()}
    stops_before = sorted({(o, v) for o, v, lay, _ in _pairs(results)
                           if o > 0.0 and lay["pitch_change_deep_deg"] is None})
    spread = dict.fromkeys(estimated, ADDED_SPREAD_DEG)
    if faster:
        for key, x in _added(faster_results(results, faster), "default").items():
            if key in spread:
                spread[key] = max(spread[key], abs(x - added[key]))
    resolved = {k: x for k, (x, e) in estimated.items() if abs(x) > e + spread[k]}
    within = {k for k, (x, e) in estimated.items() if e <= angle_tolerance(x)}
    fine = {(o, v): lay for o, v, lay, _ in _pairs(results, "refined")}
    crossed = peaked = lost = resolved_peaks = 0
    for o, v, lay, _ in _pairs(results):
        kept, gone = surviving_peaks(lay, fine[(o, v)])
        for H in interfaces:
            if lay["tip_z_m"] > H:
                crossed += 1
                near = [(z, g, e) for z, g, e in kept
                        if H - PEAK_WINDOW[0] <= z <= H + PEAK_WINDOW[1]]
                peaked += bool(near)
                resolved_peaks += bool(near) and all(e <= PEAK_TOLERANCE * g
                                                      for _, g, e in near)
                lost += any(H - PEAK_WINDOW[0] <= z <= H + PEAK_WINDOW[1] for z, _ in gone)

    def span(values):
        return [min(values), max(values)] if values else None

    return {"shots_reaching_the_interface": len(added),
            "stop_before_the_interface": [f"{o:g} deg {v:g} m/s" for o, v in stops_before],
            "added_change_range_deg": span(list(added.values())),
            "toward_the_normal": sum(1 for x in added.values() if x < 0.0),
            "largest_estimate_deg": max((e for _, e in estimated.values()), default=None),
            "within_tolerance": len(within),
            "resolved_nonzero": len(resolved),
            "largest_spread_deg": max(spread.values(), default=None),
            "interfaces_crossed": crossed, "interfaces_with_a_peak": peaked,
            "interface_peaks_resolved": resolved_peaks,
            "interface_peaks_not_surviving": lost,
            "added_change_deg": {f"{o:g} deg, {v:g} m/s": [x, e]
                                 for (o, v), (x, e) in sorted(estimated.items())}}


# --- output -----------------------------------------------------------------------------------

INPUTS = ("obliquity_deg", "speed_m_s", "discretisation")  # written as given
COLUMNS = ("obliquity_deg", "speed_m_s", "discretisation", "target", "state", "tip_x_m",
           "tip_z_m", "pitch_deg", "pitch_change_deg", "pitch_change_deep_deg",
           "max_pitch_rate_deg_s", "max_axial_g", "max_lateral_g")
# the debonded study's further columns (issue 20; the bonded study.csv keeps its bytes): the
# lateral overload averaged over one nose length of travel (:func:`low_pass`), whose peak is
# steadier than the raw samples', which switch with the shank's contact
DEBONDED_COLUMNS = ("max_lateral_low_pass_g",)


def _row(r, columns=COLUMNS):
    peaks = " ".join(_g(z, "_m") for z, _ in r["overload_peaks"])
    return (",".join(f"{r[c]}" if c == "discretisation" else f"{r[c]:g}" if c in INPUTS
                     else _g(r[c], c) for c in columns)
            + f",{peaks}")


def split_ulp(results):
    """``(results, {(obliquity, V, ramp): the row one ulp faster})``: the debonded study flies
    every runway shot again at the next larger striking speed (:func:`study_cases`)."""
    faster = {(r["obliquity_deg"], r["speed_m_s"], r["discretisation"]): r
              for r in results if r.get("ulp")}
    return [r for r in results if not r.get("ulp")], faster


def table_csv(results, faster=None):
    """The CSV of every shot; with ``faster`` (:func:`split_ulp`, debonded) the
    :data:`DEBONDED_COLUMNS` and a last column ``one_ulp_stable``: whether the runway row
    reads the same one ulp faster."""
    columns = COLUMNS + DEBONDED_COLUMNS if faster else COLUMNS
    lines = [",".join(columns) + ",overload_peak_depths_m"
             + (",one_ulp_stable" if faster else "")]
    for r in sorted(results, key=lambda r: (r["obliquity_deg"], r["speed_m_s"],
                                            r["discretisation"], r["target"])):
        line = _row(r, columns)
        if faster:
            key = (r["obliquity_deg"], r["speed_m_s"], r["discretisation"])
            line += ("," + ("yes" if _row(faster[key], columns) == line else "no")
                     if key in faster and r["target"] == "runway" else ",")
        lines.append(line)
    return "\n".join(lines) + "\n"


# How each quantity is written, so that it reads the same on every machine. Measured largest
# spread over the grid (both ramps) under a one-ulp change of the striking speed: tip depth and
# tip x 1.4e-5 m; final pitch and pitch change 1.3e-5 deg; pitch change from the approach depth
# 8.5e-6 deg (so 1.7e-5 deg for the layered - concrete difference, 3.4e-5 deg for its linear
# extrapolation in the ramp); axial overload peak 1.1e-7, lateral 2.5e-7, pitch-rate peak
# 5e-12 relative. Each is written with a rounding unit >= 29x its spread: depths and positions
# to 1 mm, angles and angle changes to 0.001 deg (decimals), the peaks to 3 significant digits.
DECIMALS = {"pitch_deg": 3, "pitch_change_deg": 3, "pitch_change_deep_deg": 3, "_deg": 3,
            "tip_x_m": 3, "tip_z_m": 3, "_m": 3}
SIGNIFICANT = {}
# below these a value is integration round-off (normal incidence: pitch rate 1e-5 deg/s,
# lateral overload 1e-5 g, tip x 1e-15 m) and is written as 0
NOISE = {"_deg_s": 1e-3, "_g": 1.0, "_m": 1e-9}


def _floor(column, value):
    if isinstance(value, float):
        for suffix, floor in NOISE.items():
            if column.endswith(suffix) and abs(value) < floor:
                return 0.0
    return value


def _text(value, column):
    """``value`` of quantity ``column`` as written (see :data:`DECIMALS`)."""
    value = _floor(column, value)
    if column in DECIMALS:
        text = f"{value:.{DECIMALS[column]}f}"
        return text[1:] if text.startswith("-") and float(text) == 0.0 else text
    return format_number(value, SIGNIFICANT.get(column, DIGITS))


def _g(x, column=""):
    return "-" if x is None else _text(x, column)


def _span(values):
    return "-" if values is None else " to ".join(_g(x, "_deg") for x in values)


def _pm(value, fine, column):
    """``value +- |value - fine|`` as written (the estimate to the value's digits)."""
    if value is None:
        return "-"
    if fine is None:
        return _g(value, column) + " +- ?"
    return f"{_g(value, column)} +- {_g(abs(value - fine), column)}"


def report_md(results, answers, interfaces, faster=None, sensitivity=None):
    fine = {(o, v): (lay, hom) for o, v, lay, hom in _pairs(results, "refined")}
    lines = ["# Oblique penetration study (generated by `python -m "
             "cavex.verification.studies.oblique_study`)", "",
             f"Default runway (the paper's Table 1) with {results[0].get('interfaces', 'bonded')} "
             "interfaces (docs/oblique.md), zero angle of attack, derived dynamic "
             "resistance with the free surface, the default discretisation (16 nose points, 16 "
             "azimuths, 16 shank rings, rtol 1e-3, contact ramp 0.01 m/s); layered against the "
             "first layer (concrete) alone. Every shot was flown again refined (32 / 32 / 32, "
             "rtol 3.3e-4, ramp 0.005 m/s; `cavex trajectory --estimate`): each number is "
             "written `value +- estimate`, the estimate being its change under that "
             "refinement, and an overload peak is listed only if the refined run has one within "
             "a nose length of it (docs/oblique.md \"Convergence\" measures how far one "
             "refinement is from the converged value). Depths are nose-tip depths; pitch is the "
             "axis angle from the target normal, positive toward the striking direction. "
             "Digits: each quantity is rounded well above its measured run-to-run spread "
             "(`DECIMALS`, `SIGNIFICANT` in verification/studies/oblique_study.py).", "",
             "| obliquity (deg) | V0 (m/s) | final tip depth layered / concrete (m) | final pitch "
             "layered / concrete (deg) | pitch change layered / concrete (deg) | pitch change "
             f"from {_g(APPROACH)} m above the first interface layered / concrete (deg) | "
             "largest pitch rate layered / concrete (deg/s) | axial peak layered / concrete (g) "
             "| lateral peak layered / concrete (g) | "
             + ("lateral peak over one nose length of travel layered / concrete (g) | "
                if faster else "")
             + "layered overload peaks (tip depth m: g), surviving the refinement | "
             "added pitch change at the interfaces (deg) |",
             "|---|---|---|---|---|---|---|---|---|---|---|" + ("---|" if faster else "")]
    quantities = ("tip_z_m", "pitch_deg", "pitch_change_deg", "pitch_change_deep_deg",
                  "max_pitch_rate_deg_s", "max_axial_g", "max_lateral_g",
                  *(DEBONDED_COLUMNS if faster else ()))
    estimated = estimated_added(results)
    for o, v, lay, hom in _pairs(results):
        flay, fhom = fine[(o, v)]
        kept, lost = surviving_peaks(lay, flay)
        peaks = ", ".join(f"{_g(z, '_m')}: {_g(g, '_g')} +- {_g(e, '_g')}"
                          for z, g, e in kept) or "-"
        if lost:
            peaks += " (not surviving: " + ", ".join(_g(z, "_m") for z, _ in lost) + ")"
        added = (f"{_g(estimated[(o, v)][0], '_deg')} +- {_g(estimated[(o, v)][1], '_deg')}"
                 if (o, v) in estimated else "-")
        lines.append(
            f"| {o:g} | {v:g} | " + " | ".join(
                f"{_pm(lay[c], flay[c], c)} / {_pm(hom[c], fhom[c], c)}" for c in quantities)
            + f" | {peaks} | {added} |")
    a = answers
    lines += ["", "## Answers computed from the table", "",
              f"- (i) attitude: {a['shots_reaching_the_interface']} oblique shots reach "
              f"{_g(APPROACH)} m above the first interface (the others stop in concrete: "
              f"{', '.join(a['stop_before_the_interface']) or 'none'}). From there on the "
              "layered runway changes the pitch by " + _span(a["added_change_range_deg"])
              + " deg more than concrete alone (largest estimate "
              + _g(a["largest_estimate_deg"], "_deg") + " deg; within the tolerance "
              f"max(0.01 deg, 3 %) in {a['within_tolerance']} of "
              f"{a['shots_reaching_the_interface']}); non-zero beyond its estimate plus the "
              "run-to-run spread "
              + (f"({ADDED_SPREAD_DEG:.1e} deg) " if not faster else
                 "(each shot's own: its change one ulp faster, at least "
                 f"{ADDED_SPREAD_DEG:.1e} deg; largest {_g(a['largest_spread_deg'], '_deg')} "
                 "deg) ")
              + f"in {a['resolved_nonzero']} of {a['shots_reaching_the_interface']} shots.",
              f"- (ii) overload: of {a['interfaces_crossed']} interface crossings by the nose tip "
              f"(interfaces at {', '.join(_g(H) for H in interfaces)} m), "
              f"{a['interfaces_with_a_peak']} have an axial overload peak that survives the "
              f"refinement at nose-tip depths from {_g(PEAK_WINDOW[0])} m before to "
              f"{_g(PEAK_WINDOW[1])} m past the interface ({a['interface_peaks_resolved']} of "
              "them with an estimate within 3 %); "
              f"{a['interface_peaks_not_surviving']} crossings have a peak there that does not "
              "survive the refinement (not counted).", ""]
    if sensitivity:
        lines += sensitivity_md(sensitivity)
    if faster:
        runway = {(r["obliquity_deg"], r["speed_m_s"], r["discretisation"]): r
                  for r in results if r["target"] == "runway"}
        moved = [f"{o:g} deg {v:g} m/s"
                 for (o, v, level), r in sorted(faster.items())
                 if _row(runway[(o, v, level)]) != _row(r)]
        lines += ["## Reproducibility", "",
                  "Every default runway shot was flown again one ulp faster (`one_ulp_stable` "
                  "in study.csv). Rows whose written digits change under that change of the "
                  "striking speed do not reproduce to those digits on another CPU (open "
                  "interfaces leave the body unsupported, and its turn amplifies the "
                  "integrator's step decisions): "
                  + (", ".join(moved) if moved else "none") + ".", ""]
    return "\n".join(lines)


def figures(results, folder, interfaces, runs):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written = [pitch_change_figure(results, folder, plt)]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for k, (label, result) in enumerate(runs.items()):
        h = result.history
        style = "-" if label.startswith("runway") else "--"
        axes[0].plot(h["t_s"] * 1e3, h["pitch_deg"], style, color=f"C{k // 2}", label=label)
        axes[1].plot(h["tip_z_m"], h["axial_g"] / 1e3, style, color=f"C{k // 2}", label=label)
    for H in interfaces:
        axes[1].axvline(H, color="0.5", lw=0.8, ls=":")
    axes[0].set_xlabel("t (ms)")
    axes[0].set_ylabel("pitch (deg)")
    axes[1].set_xlabel("nose-tip depth (m); dotted: interfaces")
    axes[1].set_ylabel("axial overload (thousands of g)")
    for a in axes:
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.suptitle("The paper's shots: 20 deg obliquity, layered (solid) against concrete alone "
                 "(dashed)", fontsize=10)
    written.append(save_figure(fig, folder / "paper_shots.png", dpi=120, bbox_inches="tight"))
    return [str(p) for p in written]


def pitch_change_figure(results, folder, plt):
    """``pitch_change.png``: the whole path's pitch change (layered and concrete alone) and
    the added pitch change from the approach depth on (default and refined), each against the
    striking velocity, one colour per obliquity; a panel whose few large values (a turn-over)
    would squash the rest gets them in a panel of their own above it
    (:func:`~cavex.verification.studies.study_axes.broken_axes`). Returns the file."""
    fig = plt.figure(figsize=(12, 6.2), layout="constrained")
    cells = fig.add_gridspec(1, 2, wspace=0.08)
    obliquities = sorted({r["obliquity_deg"] for r in results} - {0.0})
    curves = ([], [])  # per panel: (x, y, style, colour, open marker, label)
    for k, o in enumerate(obliquities):
        pairs = [p for p in _pairs(results) if p[0] == o]
        v = [p[1] for p in pairs]
        curves[0].append((v, [p[2]["pitch_change_deg"] for p in pairs], "o-", f"C{k}", False,
                          f"{o:g} deg layered"))
        curves[0].append((v, [p[3]["pitch_change_deg"] for p in pairs], "s--", f"C{k}", True,
                          f"{o:g} deg concrete only"))
        for level, style in zip(LEVELS, ("o-", "s--"), strict=True):
            rows = sorted((v, x) for (q, v), x in _added(results, level).items() if q == o)
            if rows:
                x, y = zip(*rows, strict=True)
                curves[1].append((x, y, style, f"C{k}", level == "refined",
                                  f"{o:g} deg, {level}"))
    titles = ("Whole path: final - initial pitch,\nlayered (solid) against concrete alone "
              "(dashed)",
              f"Added pitch change (layered - concrete) from {APPROACH:g} m above the first "
              "interface on,\nshots that get there: default (solid) and refined (dashed) "
              "discretisation")
    labels = ("pitch change (deg)", "added pitch change (deg)")
    for cell, panel, title, label in zip(cells, curves, titles, labels, strict=True):
        upper, lower = broken_axes(fig, cell, [y for c in panel for y in c[1]])
        for ax in (upper, lower):
            if ax is None:
                continue
            for x, y, style, colour, hollow, name in panel:
                ax.plot(x, y, style, color=colour, mfc="none" if hollow else None,
                        label=name)
            ax.grid(alpha=0.3)
        (upper or lower).set_title(title, fontsize=9)
        lower.set_ylabel(label)
        if upper is not None:
            upper.set_ylabel("large turns\n(deg; own scale)", fontsize=8)
        lower.set_xlabel("striking velocity (m/s)")
        lower.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.16),
                     frameon=False)
    return save_figure(fig, folder / "pitch_change.png", dpi=120, bbox_inches="tight")


def turn_after_interface(result, interface=1):
    """Pitch at the end of the phase after the nose tip first crosses ``interface`` minus the
    pitch at the crossing (deg); None when it does not cross."""
    k = next((i for i, p in enumerate(result.phases) if p["end_reason"].startswith(
        f"nose tip crossed interface {interface}")), None)
    if k is None or k + 1 >= len(result.phases):
        return None
    return result.phases[k + 1]["end_pitch_deg"] - result.phases[k]["end_pitch_deg"]


SHOT = Strike(600.0, obliquity=20.0)  # the paper's shot that reaches the first interface
# the uncalibrated zone sizes across their ranges (docs/oblique.md "Convergence"): the rear
# zone in calibres (the modified NDRC constant 2.12, zones.SCAB_CALIBRES) and the crater depth
# in shank radii (the paper's 4.5; Forrestal et al. 1994: 2 d = 4 r; Li and Chen 2003:
# (0.707 + l_n / d) d = 4.7 r for this nose)
SCAB_CALIBRES = (1.5, 2.12, 2.5, 3.0, 3.5)
CRATER_RATIOS = (3.0, 4.0, 4.5, 5.0, 6.0)


def interface_peak(result_peaks, H):
    """The largest overload peak ``(z, g)`` within the window of interface ``H``, or None."""
    near = [(z, g) for z, g in result_peaks if H - PEAK_WINDOW[0] <= z <= H + PEAK_WINDOW[1]]
    return max(near, key=lambda p: p[1]) if near else None


def zone_sensitivity(target, projectile):
    """The 600 m/s, 20 deg shot's answers to (i) and (ii) against the zone sizes, default and
    refined: ``{(setting, value): {"added": (default, refined), "peak": (default (z, g) or
    None, refined)}}``; (i) the added turn at the first interface (debonded - bonded,
    :func:`turn_after_interface`), (ii) the axial overload peak at it."""
    from cavex.analytic.models import make_law
    from cavex.analytic.penetration.oblique import ObliqueModel
    from cavex.materials import Target

    H = target.interface_depths[0]
    levels = ({}, refined_options(projectile))
    bonded = target.with_interfaces("bonded")
    base = [turn_after_interface(fly(bonded, projectile, SHOT, **o)) for o in levels]
    n = len(target.thicknesses)
    out = {}
    for key, values in (("rear zone (calibres)", SCAB_CALIBRES),
                        ("crater (shank radii)", CRATER_RATIOS)):
        for value in values:
            scab = value if key.startswith("rear") else 2.12
            ratio = value if key.startswith("crater") else 4.5
            runway = Target(target.layers, target.thicknesses, ("debonded",) * n,
                            (scab * 2.0 * projectile.r,) * n)
            turns, found = [], []
            for options, turn0 in zip(levels, base, strict=True):
                model = ObliqueModel(runway, projectile, make_law(runway, projectile),
                                     crater_ratio=ratio, **options)
                result = model.run(SHOT)
                turn = turn_after_interface(result)
                turns.append(None if turn is None or turn0 is None else turn - turn0)
                found.append(interface_peak(overload_peaks(result.history), H))
            out[(key, value)] = {"added": tuple(turns), "peak": tuple(found)}
    return out


def sensitivity_md(numbers):
    """The table of :func:`zone_sensitivity` (report.md)."""
    lines = ["## How the answers move with the uncalibrated zone sizes", "",
             f"{SHOT.speed:g} m/s at {SHOT.obliquity:g} deg, debonded, each zone size varied "
             "with the other at its default (rear zone 2.12 calibres, crater 4.5 r from the nose "
             "base): (i) the added turn at the first interface (debonded - bonded, the phase "
             "after the crossing) and (ii) the largest axial overload peak within the window of "
             "the first interface, each `default +- estimate` (the change under the "
             "refinement); a peak is listed only if the refined run has one within a nose "
             "length.", "",
             "| zone | size | (i) added turn (deg) | (ii) interface peak: tip depth (m), g |",
             "|---|---|---|---|"]
    for (key, value), entry in numbers.items():
        a, fine = entry["added"]
        peak, fine_peak = entry["peak"]
        if peak is None:
            text = "none" + ("" if fine_peak is None else
                             f" (refined: {_g(fine_peak[1], '_g')} g at "
                             f"{_g(fine_peak[0], '_m')} m)")
        elif fine_peak is None or abs(fine_peak[0] - peak[0]) > PEAK_SPAN:
            text = f"none surviving ({_g(peak[1], '_g')} g at {_g(peak[0], '_m')} m)"
        else:
            text = (f"{_g(peak[0], '_m')}, {_g(peak[1], '_g')} +- "
                    f"{_g(abs(peak[1] - fine_peak[1]), '_g')}")
        lines.append(f"| {key} | {value:g} | {_pm(a, fine, '_deg')} | {text} |")
    return lines + [""]


def interface_figures(folder, target, projectile, numbers):
    """Figures of the debonded study: the 600 m/s, 20 deg shot's pitch and overloads against
    nose-tip depth (bonded, debonded, concrete alone; the open zones shaded), and the answers
    of :func:`zone_sensitivity` (``numbers``) against the zone sizes. Returns the files."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cavex.analytic.penetration.zones import open_zones

    debonded = target.with_interfaces("debonded")
    runs = {"bonded": fly(target.with_interfaces("bonded"), projectile, SHOT),
            "debonded": fly(debonded, projectile, SHOT),
            "concrete alone": fly(target.single(0), projectile, SHOT)}
    length = nose_length(projectile)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.4), layout="constrained")
    for k, (label, result) in enumerate(runs.items()):
        h, color = result.history, f"C{k}"
        axes[0].plot(h["tip_z_m"], h["pitch_deg"], "--" if k == 2 else "-", color=color,
                     label=label)
        if label != "concrete alone":
            axes[1].plot(h["tip_z_m"], h["axial_g"] / 1e3, color=color, label=label)
            axes[2].plot(h["tip_z_m"], h["lateral_g"] / 1e3, lw=0.5, alpha=0.4, color=color,
                         label=f"{label}, raw samples")
            axes[2].plot(h["tip_z_m"], low_pass(h, length) / 1e3, lw=1.6, color=color,
                         label=f"{label}, mean over one nose length")
    for a in axes:
        for top, bottom in open_zones(debonded, projectile):
            a.axvspan(top, bottom, color="0.85", lw=0)
        for H in target.interface_depths:
            a.axvline(H, color="0.5", lw=0.8, ls=":")
        a.set_xlabel("nose-tip depth (m); shaded: open zones (debonded)")
        a.set_xlim(0.0, max(r.end["nose_tip_m"][2] for r in runs.values()) + 0.02)
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    axes[0].set_ylabel("pitch (deg)")
    axes[1].set_ylabel("axial overload (thousands of g)")
    axes[2].set_ylabel("lateral overload (thousands of g)")
    fig.suptitle(f"{SHOT.speed:g} m/s at {SHOT.obliquity:g} deg: bonded and debonded "
                 "interfaces, and the concrete alone", fontsize=10)
    written = [save_figure(fig, folder / "interface_shot.png", dpi=120, bbox_inches="tight")]
    written.append(sensitivity_figure(folder, numbers, plt))
    return [str(p) for p in written]


#: The rows of ``interface_sensitivity.png``: the answer, its axis label, its panel title.
SENSITIVITY_ROWS = (
    ("added", "added turn (deg)",
     "(i) added turn at interface 1 (debonded - bonded)"),
    ("peak", "axial peak (thousands of g)",
     "(ii) largest axial overload peak within the window of interface 1"))


def sensitivity_figure(folder, numbers, plt):
    """``interface_sensitivity.png``: the answers of :func:`zone_sensitivity` (``numbers``)
    against each zone size (columns), default and refined; the answer named in each panel's
    title and a short axis label (the long labels of two rows overlapped), a symmetric-log
    axis labelled on both sides of zero where the added turn spans decades, and a note
    instead of an empty panel where no size gives an interface peak."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.4), layout="constrained", sharex="col")
    keys = ("rear zone (calibres)", "crater (shank radii)")
    for col, key in enumerate(keys):
        items = [(v, e) for (k, v), e in numbers.items() if k == key]
        for row, (what, label, title) in enumerate(SENSITIVITY_ROWS):
            a = axes[row, col]
            drawn = []
            for level, style in ((0, "o-"), (1, "s--")):
                xs, ys = [], []
                for v, e in items:
                    y = e[what][level]
                    if what == "peak":
                        y = None if y is None else y[1] / 1e3
                    if y is not None:
                        xs.append(v)
                        ys.append(y)
                if xs:
                    a.plot(xs, ys, style, mfc="none" if level else None,
                           label="default" if level == 0 else "refined")
                drawn += ys
            default = 2.12 if col == 0 else 4.5
            a.axvline(default, color="0.6", lw=0.8, ls=":")
            a.grid(alpha=0.3)
            a.set_title(title, fontsize=9)
            a.set_ylabel(label)
            if not drawn:
                a.set_yticks([])
                a.text(0.5, 0.5, "no axial peak within the window of interface 1 at any "
                       f"{key.split(' (')[0]} size,\ndefault or refined (report.md)",
                       transform=a.transAxes, ha="center", va="center", fontsize=9,
                       color="0.25")
                continue
            a.legend(fontsize=7)
            if what == "added" and any(abs(y) > 2.0 for y in drawn):
                symlog_axis(a, drawn, linthresh=1.0)
                a.set_ylabel(label + "\n(symmetric log: linear within +-1)")
        axes[1, col].set_xlabel(key + "; dotted: default")
        axes[1, col].tick_params(axis="x", labelbottom=True)
    fig.suptitle(f"The answers against the uncalibrated zone sizes, {SHOT.speed:g} m/s at "
                 f"{SHOT.obliquity:g} deg, debonded", fontsize=10)
    return save_figure(fig, folder / "interface_sensitivity.png", dpi=120,
                       bbox_inches="tight")


def crossing_figure(results, folder):
    """The added turn (layered - concrete, from the approach depth on, at the default and the
    refined discretisation) against the speed at which the nose tip crosses the first
    interface, one line per obliquity (10-45 deg): does a slower crossing turn more?"""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    added, fine = _added(results, "default"), _added(results, "refined")
    speed = {(o, v): lay["crossing_speed_m_s"] for o, v, lay, _ in _pairs(results)}
    fig, ax = plt.subplots(figsize=(6.5, 4.2), layout="constrained")
    drawn = []
    for k, o in enumerate(sorted({o for o, _ in added if 0.0 < o <= 45.0})):
        rows = sorted((speed[(q, v)], x, fine[(q, v)]) for (q, v), x in added.items()
                      if q == o and speed[(q, v)] is not None and (q, v) in fine)
        if rows:
            s_, x, refined = zip(*rows, strict=True)
            ax.plot(s_, x, "o-", color=f"C{k}", label=f"{o:g} deg, default")
            ax.plot(s_, refined, "s--", color=f"C{k}", mfc="none", label=f"{o:g} deg, refined")
            drawn += [*x, *refined]
    symlog_axis(ax, drawn or [0.0], linthresh=1.0)
    ax.set_xlabel("speed at the first interface (m/s)")
    ax.set_ylabel("added turn, layered - concrete (deg)\n(symmetric log: linear within +-1)")
    ax.set_title(f"{results[0].get('interfaces', 'bonded')} interfaces: the turn from "
                 f"{APPROACH:g} m above the first interface on", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    return str(save_figure(fig, folder / "added_turn_crossing.png", dpi=120,
                           bbox_inches="tight"))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=DEFAULT_DIR)
    parser.add_argument("--workers", type=int)
    parser.add_argument("--no-progress", action="store_true")
    parser.add_argument("--quick", action="store_true", help="2 x 2 shots (a check)")
    parser.add_argument("--interfaces", choices=("bonded", "debonded"), default="bonded",
                        help="the runway's interfaces (docs/oblique.md)")
    parser.add_argument("--store", help="folder keeping every finished shot (resumable)")
    args = parser.parse_args(argv)
    grid = ((0.0, 20.0), (400.0, 800.0)) if args.quick else (OBLIQUITIES, VELOCITIES)
    folder = output_folder(args)
    if folder is None:
        return 2
    folder.mkdir(parents=True, exist_ok=True)
    cases = study_cases(*grid, interfaces=args.interfaces)
    results = run_cases(study_chunk, cases, workers=args.workers, store=args.store,
                        progress=not args.no_progress)
    failed = [r for r in results if r["status"] != "ok"]
    if failed:
        print(f"{len(failed)} shot(s) failed, first: {failed[0]['id']}: {failed[0]['reason']}",
              file=sys.stderr)
        return 1
    cases = {c["id"]: c for c in cases}
    results, faster = split_ulp([{**cases[r["id"]], **r} for r in results])
    target, projectile = load_config()
    target = target.with_interfaces(args.interfaces)
    interfaces = list(target.interface_depths)
    answers = findings(results, interfaces, faster)
    runs = {}
    for v in (400.0, 600.0):  # the paper's two shots (its Figs. 8 and 9)
        strike = Strike(v, obliquity=20.0)
        runs[f"runway {v:g} m/s"] = fly(target, projectile, strike)
        runs[f"concrete only {v:g} m/s"] = fly(target.single(0), projectile, strike)
    numbers = (zone_sensitivity(target, projectile) if args.interfaces == "debonded"
               and not args.quick else None)
    write_text_atomic(folder / "study.csv", table_csv(results, faster))
    write_text_atomic(folder / "report.md", report_md(results, answers, interfaces, faster,
                                                      numbers))
    figures(results, folder, interfaces, runs)
    if args.interfaces == "debonded":
        crossing_figure(results, folder)
        if numbers:
            interface_figures(folder, target, projectile, numbers)
    print(json.dumps({k: v for k, v in answers.items() if k != "added_change_deg"}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
