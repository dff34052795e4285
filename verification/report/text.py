"""The report's markdown: conclusions, tables and figure references, all from the grid numbers.

Number formats (the tests parse them back): relative errors in percent with three decimals
(``+1.234 %``), stresses in MPa with four significant decimals, radii in mm with two decimals.
"""

import json
import math

import numpy as np

from cavex.analytic.models import the
from cavex.analytic.states import state_meaning
from cavex.verification.report.analysis import (
    ERROR_PARTS,
    MODELS,
    RESOLVED_FRACTION,
    TOLERANCES,
    attribution,
    part_medians,
    state_labels,
)

LABELS = {key: label for key, label, _ in MODELS}
PART_REASONS = {
    "formulas": "the paper's printed equations and its nose-tip layer switch differ from the "
                "derived quasi-static solution (docs/paper_model.md lists each kept error and "
                "choice)",
    "convention": "the quasi-static convention freezes the elastic-plastic boundary at "
                  "eps^3 = 3 tau/(2E) while the FE boundary moves with V",
    "idealisation": "the closed form is incompressible and small-strain in its elastic zone, "
                    "the FE solid is compressible (finite wave speed) and finite-strain",
}


def pct(x, digits=3):
    """``+1.234 %`` (or ``n/a`` for NaN/None)."""
    if x is None or not math.isfinite(x):
        return "n/a"
    return f"{100 * x:+.{digits}f} %"


def table(header, rows):
    """Markdown pipe table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


PART_NAMES = {"formulas": "printed formulas/switch", "convention": "boundary convention",
              "idealisation": "idealisation"}


def _within_text(limit, vmax, vmin, fraction, tolerance):
    """Where the closed form is within ``tolerance`` of FE, plainly."""
    t = f"{100 * tolerance:g} % of FE"
    if limit is None:
        if fraction == 0.0:
            return f"never within {t}"
        return (f"within {t} in only {100 * fraction:.1f} % of its cells (some depths are "
                f"beyond even at V = {vmin:g} m/s)")
    if limit >= vmax:
        return f"within {t} in every cell (V up to {vmax:g} m/s)"
    if limit == 0.0:
        return f"within {t} at every depth only at V = 0 (quasi-static)"
    return f"within {t} at every depth only for V <= {limit:g} m/s"


def conclusions(grid, target, stats):
    """Plain-language conclusion lines generated from the statistics.

    Per closed form and wall layer: the velocities up to which every depth is within 1 % and
    5 % of FE, the worst cell, and the attribution of the error to the parts of
    :data:`~cavex.verification.report.analysis.MODEL_PARTS` (their medians, the part dominating
    the median and the part dominating the worst cell).
    """
    names = target.layer_names()
    vmax, vmin = float(grid.velocity.max()), float(grid.velocity.min())
    lines = []
    for index in sorted(next(iter(stats.values()))):
        ranked = [k for k in stats if math.isfinite(stats[k][index]["median"])]
        if not ranked:  # every FE cell of this wall layer failed: nothing to rank
            lines.append(f"**{names[index]} at the wall**: no FE result (every cell failed), "
                         "so no closed form is ranked there.")
            continue
        best = min(ranked, key=lambda k: abs(stats[k][index]["median"]))
        lines.append(f"**{names[index]} at the wall**: the closest closed form is "
                     f"{LABELS[best]} (median error {pct(stats[best][index]['median'])}).")
        for key, s in ((k, stats[k][index]) for k in stats):
            if not math.isfinite(s["median"]):
                lines.append(f"{LABELS[key]}: no FE result in {names[index]}.")
                continue
            within = [_within_text(s["v_within"][i], vmax, vmin, s["within"][i], t)
                      for i, t in enumerate(TOLERANCES)]
            lines.append(
                f"{LABELS[key]}, {names[index]} at the wall: {within[0]}; {within[1]}; worst "
                f"{pct(s['max_abs'])} at V = {s['at'][0]:g} m/s, L = {s['at'][1]:.4g} m. "
                f"{_attribution_text(attribution(grid, key, index, s['at']), s['median'])}")
    return lines


def _attribution_text(a, median):
    """The parts of the error: medians, and which part dominates the median and the worst cell."""
    medians, worst = a["medians"], a["worst"]
    if len(medians) == 1:
        (part,) = medians
        return (f"Its error is the {PART_NAMES[part]} part alone (median {pct(medians[part])}): "
                f"{PART_REASONS[part]}.")
    listed = ", ".join(f"{PART_NAMES[p]} {pct(m)}" for p, m in medians.items())
    there = ", ".join(f"{PART_NAMES[p]} {pct(w)}" for p, w in worst.items())
    m, w = a["median_part"], a["worst_part"]
    out = f"Medians of its error parts: {listed} (median error {pct(median)}). "
    if m == w:
        return (out + f"The {PART_NAMES[m]} part dominates both the median and the worst cell "
                f"(there: {there}): {PART_REASONS[m]}.")
    return (out + f"The {PART_NAMES[m]} part dominates the median: {PART_REASONS[m]}. At the "
            f"worst cell the {PART_NAMES[w]} part dominates (there: {there}): "
            f"{PART_REASONS[w]}.")


def accuracy_table(stats, target):
    """Per closed form and wall layer: median, worst, fractions within 1 % and 5 %, limits."""
    names = target.layer_names()
    rows = []
    for key, s_by_layer in stats.items():
        for index, s in s_by_layer.items():
            at = "n/a" if s["at"] is None else f"{s['at'][0]:g} / {s['at'][1]:.4g}"
            rows.append([LABELS[key], names[index], s["cells"], s["failed"], pct(s["median"]),
                         pct(s["max_abs"]), at, _frac(s["within"][0]), _frac(s["within"][1]),
                         _v(s["v_within"][0]), _v(s["v_within"][1]), s["unresolved"]])
    return table(["closed form", "wall layer", "cells", "FE failed", "median error",
                  "worst error", "worst at V (m/s) / L (m)", "within 1 %", "within 5 %",
                  "all within 1 % up to V (m/s)", "all within 5 % up to V (m/s)",
                  "differences not resolved by FE"], rows)


def _frac(x):
    return "n/a" if not math.isfinite(x) else f"{100 * x:.1f} %"


def _v(v):
    return "none" if v is None else f"{v:g}"


def parts_table(grid, target):
    """Median of each part of the paper's error, per wall layer (exactly additive per cell)."""
    names = target.layer_names()
    rows = []
    for index in sorted({int(i) for i in np.unique(grid["wall_layer"].values)}):
        parts = part_medians(grid, index)
        mask = (grid["wall_layer"] == index).broadcast_like(grid["sigma_r"])
        total = float(grid["rel_err_paper"].where(mask).median())
        rows.append([names[index], *(pct(parts[p]) for p, _ in ERROR_PARTS), pct(total)])
    return table(["wall layer", *(f"{p}: {text}" for p, text in ERROR_PARTS),
                  "paper total (median)"], rows)


def failed_table(grid):
    """Failed FE cells with the runner's one-line reason."""
    failures = json.loads(grid.attrs.get("failures", "[]"))
    if not failures:
        return "No FE cell failed."
    return table(["V (m/s)", "L (m)", "reason"],
                 [[f"{f['velocity']:g}", f"{f['depth']:.5g}", f["reason"] or "?"]
                  for f in failures])


def cell_rows(grid, target):
    """One row per (V, L) cell: the grid numbers as printed in the appendix."""
    names = target.layer_names()
    states = {key: state_labels(grid, key) for key in ("dynamic", "quasi_static")}
    rows = []
    for i, V in enumerate(grid.velocity.values):
        for j, L in enumerate(grid.depth.values):
            c = grid.sel(velocity=V, depth=L)
            failed = bool(c["failed"])
            flags = ["FE FAILED"] if failed else [
                f"{k} unresolved" for k, _, _ in MODELS if int(c[f"resolved_{k}"]) == 0]
            rows.append([f"{V:g}", f"{L:.5g}", names[int(c["wall_layer"])],
                         "n/a" if failed else f"{float(c['sigma_r']) / 1e6:.4f}",
                         "n/a" if failed else f"{float(c['error_estimate']):.3e}",
                         *(pct(float(c[f"rel_err_{k}"])) for k, _, _ in MODELS),
                         states["dynamic"][i, j], states["quasi_static"][i, j],
                         _mm(c["plastic_radius"]), _mm(c["b_dynamic"]),
                         _mm(c["b_quasi_static"]), ", ".join(flags) or "-"])
    return rows


def _mm(value):
    x = float(value)
    return "n/a" if not math.isfinite(x) else f"{1e3 * x:.2f}"


CELL_HEADER = ["V (m/s)", "L (m)", "wall layer", "FE sigma_r (MPa)", "FE error estimate",
               "derived-dynamic error", "derived-quasi-static error", "paper error",
               "state (dynamic)", "state (quasi-static)", "FE b (mm)", "dynamic b (mm)",
               "quasi-static b (mm)", "flags"]


def quick_reference_line(estimate):
    """The quick report's warning: its FE-table shot is on the quick grid, with the table's
    interpolation-error estimate (:func:`~cavex.verification.report.build.
    table_interpolation_error`), and the full ``cavex verify`` is the reference."""
    if estimate is None or estimate["estimate_m"] is None:
        error = "no interpolation-error estimate (the table cannot be coarsened)"
    else:
        parts = ", ".join(f"{axis} {estimate[axis]['difference_m']:+.4f} m"
                          for axis in ("velocity", "depth") if estimate[axis] is not None)
        error = (f"final depth {estimate['final_depth_m']:.4f} m with an interpolation-error "
                 f"estimate of {estimate['estimate_m']:.4f} m (the table with every other "
                 f"node: {parts})")
    return ("**Quick report**: its FE table is the quick grid, and so is the FE-table shot "
            f"compared with the closed forms: {error}; the full `cavex verify` is the "
            "reference.")


def trajectory_section(trajectories):
    """Summary and phase tables of :func:`compare_trajectories`, or its one-line failure."""
    if isinstance(trajectories, str):
        return trajectories
    rows = []
    fe_label = the(takes_table=True).name  # the FE table, the others' reference
    fe = trajectories.get(fe_label)
    for name, t in trajectories.items():
        h1 = t["at_H1"]
        v1 = "stops before" if h1 is None else f"{h1['velocity_m_s']:.2f}"
        dv = ("n/a" if h1 is None or fe is None or fe["at_H1"] is None or name == fe_label
              else f"{h1['velocity_m_s'] - fe['at_H1']['velocity_m_s']:+.2f}")
        rows.append([name, f"{t['phases'][0]['end_velocity_m_s']:.2f}", v1, dv,
                     "n/a" if h1 is None else f"{1e3 * h1['time_s']:.4f}",
                     f"{t['final_depth_m']:.4f}", f"{1e3 * t['final_time_s']:.4f}"])
    out = [table(["resistance", "V after crater (m/s)", "V when the nose tip reaches H1 "
                  "(residual after the concrete, m/s)", "minus FE table (m/s)",
                  "t at H1 (ms)", "final depth (m)", "final time (ms)"], rows), ""]
    for name, t in trajectories.items():
        out += [f"Phase ends, {name}:", "",
                table(["phase", "end L (m)", "end V (m/s)", "end t (ms)", "ends because"],
                      [[p["label"], f"{p['end_depth_m']:.4f}", f"{p['end_velocity_m_s']:.2f}",
                        f"{1e3 * p['end_time_s']:.4f}", p["end_reason"]]
                       for p in t["phases"]]), ""]
    return "\n".join(out)


def resolution_text(grid, stats):
    """How many differences the FE error estimate resolves, per closed form."""
    est = grid["error_estimate"].where(grid["failed"] == 0)
    lines = [f"FE relative error estimate (Richardson, half resolution): median "
             f"{float(est.median()):.3e}, largest {float(est.max()):.3e}."
             if bool(est.notnull().any()) else "No FE error estimate available."]
    for key, s_by_layer in stats.items():
        n = sum(s["unresolved"] for s in s_by_layer.values())
        total = sum(s["cells"] - s["failed"] for s in s_by_layer.values())
        lines.append(f"- {LABELS[key]}: {n} of {total} cells have an FE error estimate not "
                     f"below {RESOLVED_FRACTION:.3g} of |analytic - FE|/FE; their differences "
                     "are not resolved by the FE (dots on the error maps, 'unresolved' in the "
                     "cell table).")
    return "\n".join(lines)


def states_text(grid, target):
    """What the response-state labels of the state map mean (those present in the grid)."""
    names = target.layer_names()
    used = {int(x) for key in ("dynamic", "quasi_static")
            for x in np.unique(grid[f"state_{key}"].values)}
    present = [label for code, label in enumerate(
        grid["state_dynamic"].attrs["flag_meanings"].split()) if code in used]
    return "\n".join(
        ["Response states (the paper's Fig. 2): the letter says how many layers still "
         "surround the cavity at that nose depth (a-e: three, f-h: two, `single`: one; a layer "
         "stops surrounding it once its interface comes within the shank radius r of the "
         "cavity centre) and where the elastic-plastic boundary b lies among them:", ""]
        + [f"- `{label}`: {state_meaning(label, names)}" for label in present])
