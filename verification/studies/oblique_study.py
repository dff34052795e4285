"""The oblique-penetration study (docs/oblique.md, results/oblique): does cavex reproduce the
paper's two 3-D findings?

(i) the layer interfaces accelerate the change of the projectile's attitude, the more so the
lower the striking velocity; (ii) the overload history has a peak at each interface.

Every shot of the grid (obliquities x striking velocities, zero angle of attack, derived
dynamic resistance with the free surface, the default contact regularisation) is flown into
the runway and into its first layer alone (the paper's comparison). Per shot: end state,
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
from cavex.analytic.penetration.oblique import CONTACT_RAMP, Strike, overload_peaks, peaks
from cavex.config import load_config
from cavex.verification.fedata.runner import run_cases
from cavex.verification.output.files import save_figure, write_text_atomic
from cavex.verification.output.number_format import format_number
from cavex.verification.output.paths import check_output_dir

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
# every shot at the default contact regularisation and at three times it: the attitude change
# at the interfaces is first order in the ramp, and is extrapolated to ramp -> 0
RAMPS = (CONTACT_RAMP, 3.0 * CONTACT_RAMP)
# run-to-run spread of the added change (layered - concrete, twice the measured 8.5e-6 deg of
# each, see DECIMALS) and of its linear extrapolation 1.5 fine - 0.5 coarse: an extrapolated
# value counts as non-zero only beyond its estimate plus this spread
ADDED_SPREAD_DEG = 2.0 * 8.5e-6
EXTRAPOLATION_SPREAD_DEG = ADDED_SPREAD_DEG * (1.0 + 2.0 * RAMPS[0] / (RAMPS[1] - RAMPS[0]))
DEFAULT_DIR = "results/oblique"


def study_cases(obliquities=OBLIQUITIES, velocities=VELOCITIES, ramps=RAMPS,
                interfaces="bonded"):
    """The shots of the grid; ``interfaces``: the runway's interfaces, all bonded or all
    debonded (docs/oblique.md "Debonded interfaces")."""
    cases = [{"id": f"{'layered' if t == 'runway' else 'homogeneous'}_{o:g}deg_{v:g}_{r:g}",
              "target": t, "obliquity_deg": o, "speed_m_s": v, "contact_ramp_m_s": r,
              "interfaces": interfaces}
             for o in obliquities for v in velocities for t in TARGETS for r in ramps]
    if interfaces == "debonded":  # each runway shot again one ulp faster: does its row hold?
        cases += [{**c, "id": c["id"] + "_ulp", "ulp": True} for c in cases
                  if c["target"] == "runway"]
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
            out.append(shot_summary(fly(t, projectile, strike,
                                        contact_ramp=case["contact_ramp_m_s"]), approach,
                                    nose_length(projectile)))
        except Exception as exc:  # noqa: BLE001 (reported per case)
            out.append(exc)
    return out


def _pairs(results, ramp=CONTACT_RAMP):
    """``(obliquity, V, layered, concrete only)`` of every shot at contact ramp ``ramp``."""
    by = {(r["obliquity_deg"], r["speed_m_s"], r["target"]): r for r in results
          if r["contact_ramp_m_s"] == ramp}
    keys = sorted({(r["obliquity_deg"], r["speed_m_s"]) for r in results})
    return [(o, v, by[(o, v, "runway")], by[(o, v, "first layer only")]) for o, v in keys]


def _added(results, ramp):
    """Added pitch change near the interfaces (layered - concrete, deg) of every oblique shot
    that reaches the approach depth in both targets, at contact ramp ``ramp``."""
    return {(o, v): lay["pitch_change_deep_deg"] - hom["pitch_change_deep_deg"]
            for o, v, lay, hom in _pairs(results, ramp)
            if o > 0.0 and lay["pitch_change_deep_deg"] is not None
            and hom["pitch_change_deep_deg"] is not None}


def extrapolated_added(results):
    """``{(obliquity, V): (added change at V_r -> 0, its estimate)}``: linear (first-order)
    extrapolation from the default contact ramp and three times it (the added change is
    first order in the ramp, docs/oblique.md); the estimate is the distance of the default's
    value from the extrapolated one."""
    fine, coarse = _added(results, RAMPS[0]), _added(results, RAMPS[1])
    out = {}
    for key in fine.keys() & coarse.keys():
        limit = fine[key] - (coarse[key] - fine[key]) * RAMPS[0] / (RAMPS[1] - RAMPS[0])
        out[key] = (limit, abs(fine[key] - limit))
    return out


def faster_results(results, faster):
    """``results`` with every runway row replaced by the one flown one ulp faster."""
    return [faster[(r["obliquity_deg"], r["speed_m_s"], r["contact_ramp_m_s"])]
            if r["target"] == "runway" else r for r in results]


def findings(results, interfaces, faster=None):
    """Answers to (i) and (ii) computed from the shots (dict of numbers); with ``faster``
    (:func:`split_ulp`) an extrapolated added change counts as resolved only beyond its
    estimate plus the larger of the bonded spread and its own change one ulp faster."""
    # (i): attitude change from the approach depth on, layered against concrete alone, in the
    # oblique shots whose nose reaches that depth in both targets; at the default ramp and
    # extrapolated to ramp -> 0
    added = _added(results, CONTACT_RAMP)
    limits = extrapolated_added(results)
    stops_before = sorted({(o, v) for o, v, lay, _ in _pairs(results)
                           if o > 0.0 and lay["pitch_change_deep_deg"] is None})
    spread = dict.fromkeys(limits, EXTRAPOLATION_SPREAD_DEG)
    if faster:
        for key, (x, _) in extrapolated_added(faster_results(results, faster)).items():
            if key in spread:
                spread[key] = max(spread[key], abs(x - limits[key][0]))
    resolved = {k: x for k, (x, e) in limits.items() if abs(x) > e + spread[k]}
    # (ii): an overload peak near each interface the nose tip crossed
    crossed = peaked = 0
    for _, _, lay, _ in _pairs(results):
        for H in interfaces:
            if lay["tip_z_m"] > H:
                crossed += 1
                if any(H - PEAK_WINDOW[0] <= z <= H + PEAK_WINDOW[1]
                       for z, _ in lay["overload_peaks"]):
                    peaked += 1
    def span(values):
        return [min(values), max(values)] if values else None

    return {"shots_reaching_the_interface": len(added),
            "stop_before_the_interface": [f"{o:g} deg {v:g} m/s" for o, v in stops_before],
            "added_change_range_deg": span(list(added.values())),
            "toward_the_normal": sum(1 for x in added.values() if x < 0.0),
            "extrapolated_added_change_range_deg": span([x for x, _ in limits.values()]),
            "largest_extrapolation_estimate_deg": max((e for _, e in limits.values()),
                                                      default=None),
            "resolved_nonzero_after_extrapolation": len(resolved),
            "largest_spread_deg": max(spread.values(), default=None),
            "interfaces_crossed": crossed, "interfaces_with_a_peak": peaked,
            "added_change_deg": {f"{o:g} deg, {v:g} m/s": x
                                 for (o, v), x in sorted(added.items())}}


# --- output -----------------------------------------------------------------------------------

INPUTS = ("obliquity_deg", "speed_m_s", "contact_ramp_m_s")  # written as given
COLUMNS = ("obliquity_deg", "speed_m_s", "contact_ramp_m_s", "target", "state", "tip_x_m",
           "tip_z_m", "pitch_deg", "pitch_change_deg", "pitch_change_deep_deg",
           "max_pitch_rate_deg_s", "max_axial_g", "max_lateral_g")
# the debonded study's further columns (issue 20; the bonded study.csv keeps its bytes): the
# lateral overload averaged over one nose length of travel (:func:`low_pass`), whose peak is
# steadier than the raw samples', which switch with the shank's contact
DEBONDED_COLUMNS = ("max_lateral_low_pass_g",)


def _row(r, columns=COLUMNS):
    peaks = " ".join(_g(z, "_m") for z, _ in r["overload_peaks"])
    return (",".join(f"{r[c]:g}" if c in INPUTS else _g(r[c], c) for c in columns)
            + f",{peaks}")


def split_ulp(results):
    """``(results, {(obliquity, V, ramp): the row one ulp faster})``: the debonded study flies
    every runway shot again at the next larger striking speed (:func:`study_cases`)."""
    faster = {(r["obliquity_deg"], r["speed_m_s"], r["contact_ramp_m_s"]): r
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
                                            r["contact_ramp_m_s"], r["target"])):
        line = _row(r, columns)
        if faster:
            key = (r["obliquity_deg"], r["speed_m_s"], r["contact_ramp_m_s"])
            line += ("," + ("yes" if _row(faster[key], columns) == line else "no")
                     if r["target"] == "runway" else ",")
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


def report_md(results, answers, interfaces, faster=None):
    lines = ["# Oblique penetration study (generated by `python -m "
             "cavex.verification.studies.oblique_study`)", "",
             f"Default runway (the paper's Table 1) with {results[0].get('interfaces', 'bonded')} "
             "interfaces (docs/oblique.md), zero angle of attack, derived dynamic "
             f"resistance with the free surface, contact ramp {_g(RAMPS[0])} m/s (the default; "
             f"every shot is also run at {_g(RAMPS[1])} m/s for the extrapolation); layered "
             "against the first layer (concrete) alone. Depths are nose-tip depths; pitch is the "
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
             + "layered overload peaks at tip depth (m) | "
             "added pitch change at the interfaces, contact ramp -> 0 (deg) |",
             "|---|---|---|---|---|---|---|---|---|---|---|" + ("---|" if faster else "")]
    quantities = ("tip_z_m", "pitch_deg", "pitch_change_deg", "pitch_change_deep_deg",
                  "max_pitch_rate_deg_s", "max_axial_g", "max_lateral_g",
                  *(DEBONDED_COLUMNS if faster else ()))
    limits = extrapolated_added(results)
    for o, v, lay, hom in _pairs(results):
        peaks = ", ".join(_g(z, "_m") for z, _ in lay["overload_peaks"]) or "-"
        limit = (f"{_g(limits[(o, v)][0], '_deg')} +- {_g(limits[(o, v)][1], '_deg')}"
                 if (o, v) in limits else "-")
        lines.append(
            f"| {o:g} | {v:g} | " + " | ".join(
                f"{_g(lay[c], c)} / {_g(hom[c], c)}" for c in quantities)
            + f" | {peaks} | {limit} |")
    a = answers
    lines += ["", "## Answers computed from the table", "",
              f"- (i) attitude: {a['shots_reaching_the_interface']} oblique shots reach "
              f"{_g(APPROACH)} m above the first interface (the others stop in concrete: "
              f"{', '.join(a['stop_before_the_interface']) or 'none'}). From there on, at the "
              f"default contact ramp ({_g(RAMPS[0])} m/s), the layered runway changes the pitch "
              "by " + _span(a["added_change_range_deg"]) + " deg more than concrete alone "
              "(the integrator's run-to-run spread of this difference is up to "
              + (f"{ADDED_SPREAD_DEG:.1e} deg). " if not faster else
                 f"{ADDED_SPREAD_DEG:.1e} deg bonded; debonded, see Reproducibility). ")
              + "This added change is first order in the "
              f"contact ramp: extrapolated to ramp -> 0 from {_g(RAMPS[0])} and "
              f"{_g(RAMPS[1])} m/s it is " + _span(a["extrapolated_added_change_range_deg"])
              + " deg (largest estimate " + _g(a["largest_extrapolation_estimate_deg"], "_deg")
              + " deg), non-zero beyond its estimate plus the spread "
              + (f"({EXTRAPOLATION_SPREAD_DEG:.1e} deg) in " if not faster else
                 "(each shot's own: the change of its extrapolated value one ulp faster, "
                 f"at least {EXTRAPOLATION_SPREAD_DEG:.1e} deg; largest "
                 f"{_g(a['largest_spread_deg'], '_deg')} deg) in ")
              + f"{a['resolved_nonzero_after_extrapolation']} of "
              f"{a['shots_reaching_the_interface']} shots.",
              f"- (ii) overload: of {a['interfaces_crossed']} interface crossings by the nose tip "
              f"(interfaces at {', '.join(_g(H) for H in interfaces)} m), "
              f"{a['interfaces_with_a_peak']} have an axial overload peak at nose-tip depths from "
              f"{_g(PEAK_WINDOW[0])} m before to {_g(PEAK_WINDOW[1])} m past the interface.",
              ""]
    if faster:
        runway = {(r["obliquity_deg"], r["speed_m_s"], r["contact_ramp_m_s"]): r
                  for r in results if r["target"] == "runway"}
        moved = [f"{o:g} deg {v:g} m/s (ramp {ramp:g} m/s)"
                 for (o, v, ramp), r in sorted(faster.items())
                 if _row(runway[(o, v, ramp)]) != _row(r)]
        lines += ["## Reproducibility", "",
                  "Every runway shot was flown again one ulp faster (`one_ulp_stable` in "
                  "study.csv). Rows whose written digits change under that change of the "
                  "striking speed do not reproduce to those digits on another CPU (open "
                  "interfaces leave the body unsupported, and its turn amplifies the "
                  "integrator's step decisions): "
                  + (", ".join(moved) if moved else "none") + ".", ""]
    return "\n".join(lines)


def figures(results, folder, interfaces, runs):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written = []
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for k, o in enumerate(sorted({r["obliquity_deg"] for r in results} - {0.0})):
        pairs = [p for p in _pairs(results) if p[0] == o]
        v = [p[1] for p in pairs]
        axes[0].plot(v, [p[2]["pitch_change_deg"] for p in pairs], "o-", color=f"C{k}",
                     label=f"{o:g} deg layered")
        axes[0].plot(v, [p[3]["pitch_change_deg"] for p in pairs], "s--", color=f"C{k}",
                     mfc="none", label=f"{o:g} deg concrete only")
        for ramp, style in zip(RAMPS, ("o-", "^:"), strict=True):
            added = _added(results, ramp)
            rows = sorted((v, x) for (q, v), x in added.items() if q == o)
            if rows:
                axes[1].plot(*zip(*rows, strict=True), style, color=f"C{k}",
                             label=f"{o:g} deg, ramp {ramp:g} m/s")
        limits = sorted((v, x) for (q, v), (x, _) in extrapolated_added(results).items()
                        if q == o)
        if limits:
            axes[1].plot(*zip(*limits, strict=True), "s--", color=f"C{k}", mfc="none",
                         label=f"{o:g} deg, ramp -> 0")
    axes[0].set_ylabel("final pitch - initial pitch (deg)")
    axes[0].set_title("whole path: layered (solid) against concrete alone (dashed)",
                      fontsize=9)
    axes[1].set_ylabel("added pitch change, layered - concrete (deg)")
    axes[1].set_title(f"from {APPROACH:g} m above the first interface on (shots that get "
                      "there), by contact ramp", fontsize=9)
    for a in axes:
        a.set_xlabel("striking velocity (m/s)")
        a.legend(fontsize=7, ncol=2)
        a.grid(alpha=0.3)
    written.append(save_figure(fig, folder / "pitch_change.png", dpi=120,
                               bbox_inches="tight"))
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


def turn_after_interface(result, interface=1):
    """Pitch at the end of the phase after the nose tip first crosses ``interface`` minus the
    pitch at the crossing (deg); None when it does not cross."""
    k = next((i for i, p in enumerate(result.phases) if p["end_reason"].startswith(
        f"nose tip crossed interface {interface}")), None)
    if k is None or k + 1 >= len(result.phases):
        return None
    return result.phases[k + 1]["end_pitch_deg"] - result.phases[k]["end_pitch_deg"]


def low_pass(history, length):
    """Lateral overload averaged over the time the body takes to travel ``length`` (the nose
    length) around each sample (trapezoidal mean over ``[t - T/2, t + T/2]``, ``T = length /
    speed``): the raw samples switch with the shank's contact."""
    t, g, v = history["t_s"], history["lateral_g"], history["speed_m_s"]
    out = np.empty_like(g)
    for i in range(t.size):
        half = 0.5 * length / max(v[i], 1e-9)
        lo, hi = t[i] - half, t[i] + half
        grid = np.concatenate([[max(lo, t[0])], t[(t > lo) & (t < hi)], [min(hi, t[-1])]])
        values = np.interp(grid, t, g)
        span = grid[-1] - grid[0]
        area = float(np.sum(0.5 * (values[1:] + values[:-1]) * np.diff(grid)))
        out[i] = area / span if span > 0 else g[i]
    return out


SHOT = Strike(600.0, obliquity=20.0)  # the paper's shot that reaches the first interface
SCAB_CALIBRES = (1.5, 2.12, 2.5, 3.0, 3.5)
WALL_FACTORS = (0.25, 0.5, 0.75, 1.0)


def interface_figures(folder, target, projectile):
    """Figures of the debonded study (issue 20): the 600 m/s, 20 deg shot's pitch and
    overloads against nose-tip depth (bonded, debonded, concrete alone; the open zones
    shaded), and the sensitivity of its added turn at the first interface to the rear-zone
    depth, the crater depth and the tunnel-wall factor. Returns the files and the numbers."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cavex.analytic.models import make_law
    from cavex.analytic.penetration.oblique import ObliqueModel
    from cavex.analytic.penetration.zones import open_zones
    from cavex.materials import Target

    bonded = target.with_interfaces("bonded")
    debonded = target.with_interfaces("debonded")
    runs = {"bonded": fly(bonded, projectile, SHOT), "debonded": fly(debonded, projectile, SHOT),
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

    def added(runway, *, crater="nose-base"):
        turns = []
        for t in (runway.with_interfaces("bonded"), runway):
            model = ObliqueModel(t, projectile, make_law(t, projectile), crater=crater)
            turns.append(turn_after_interface(model.run(SHOT)))
        return None if None in turns else turns[1] - turns[0]

    numbers = {"scab_calibres": {}, "tunnel_wall": {}, "crater": {}}
    n = len(target.thicknesses)
    for c in SCAB_CALIBRES:
        scabbed = Target(target.layers, target.thicknesses, ("debonded",) * n,
                         (c * 2.0 * projectile.r,) * n)
        numbers["scab_calibres"][c] = added(scabbed)
    for f in WALL_FACTORS:
        numbers["tunnel_wall"][f] = added(debonded.with_tunnel_wall(f))
    for crater in ("nose-tip", "nose-base"):
        numbers["crater"][crater] = added(debonded, crater=crater)
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.0), layout="constrained")
    for a, (key, label) in zip(axes, (("scab_calibres", "rear-zone depth (calibres)"),
                                      ("tunnel_wall", "tunnel-wall factor"),
                                      ("crater", "crater depth rule (4.5 r from ...)")),
                               strict=True):
        items = [(k, v) for k, v in numbers[key].items() if v is not None]
        x = list(range(len(items))) if key == "crater" else [k for k, _ in items]
        a.plot(x, [v for _, v in items], "o" if key == "crater" else "o-")
        for xi, (_, v) in zip(x, items, strict=True):
            a.annotate(f"{v:+.2f}", (xi, v), textcoords="offset points", xytext=(4, 4),
                       fontsize=7)
        if key == "crater":
            a.set_xticks(x, [k for k, _ in items])
            a.set_xlim(-0.5, len(items) - 0.5)
        if key == "scab_calibres":  # a body that turns over: tens of degrees
            a.set_yscale("symlog", linthresh=1.0)
        a.set_xlabel(label)
        a.grid(alpha=0.3)
    axes[0].set_ylabel("added turn at interface 1 (deg; symlog, linear within +-1)")
    axes[1].set_ylabel("added turn at interface 1 (deg)")
    fig.suptitle(f"Sensitivity of the added turn (debonded - bonded), {SHOT.speed:g} m/s at "
                 f"{SHOT.obliquity:g} deg (uncalibrated settings)", fontsize=10)
    written.append(save_figure(fig, folder / "interface_sensitivity.png", dpi=120,
                               bbox_inches="tight"))
    return [str(p) for p in written], numbers


def crossing_figure(results, folder):
    """The added turn (layered - concrete, from the approach depth on, at the default ramp and
    extrapolated to ramp -> 0) against the speed at which the nose tip crosses the first
    interface, one line per obliquity (10-45 deg): does a slower crossing turn more?"""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    added, limits = _added(results, CONTACT_RAMP), extrapolated_added(results)
    speed = {(o, v): lay["crossing_speed_m_s"] for o, v, lay, _ in _pairs(results)}
    fig, ax = plt.subplots(figsize=(6.5, 4.2), layout="constrained")
    for k, o in enumerate(sorted({o for o, _ in added if 0.0 < o <= 45.0})):
        rows = sorted((speed[(q, v)], x, limits[(q, v)][0]) for (q, v), x in added.items()
                      if q == o and speed[(q, v)] is not None)
        if rows:
            s_, x, lim = zip(*rows, strict=True)
            ax.plot(s_, x, "o-", color=f"C{k}", label=f"{o:g} deg, ramp {CONTACT_RAMP:g} m/s")
            ax.plot(s_, lim, "s--", color=f"C{k}", mfc="none", label=f"{o:g} deg, ramp -> 0")
    ax.set_yscale("symlog", linthresh=1.0)
    ax.set_xlabel("speed at the first interface (m/s)")
    ax.set_ylabel("added turn, layered - concrete (deg; symlog, linear within +-1)")
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
    folder = check_output_dir(args.out, "out")
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
    write_text_atomic(folder / "study.csv", table_csv(results, faster))
    write_text_atomic(folder / "report.md", report_md(results, answers, interfaces, faster))
    figures(results, folder, interfaces, runs)
    if args.interfaces == "debonded":
        crossing_figure(results, folder)
        _, numbers = interface_figures(folder, target, projectile)
        print(json.dumps({"sensitivity_added_turn_deg": numbers}, indent=1))
    print(json.dumps({k: v for k, v in answers.items() if k != "added_change_deg"}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
