r"""A trajectory's own error estimate: one refined rerun (``cavex trajectory --estimate``).

The run is flown again with every discretisation parameter refined at once
(:func:`refined_model`): twice the nose points, azimuths and shank rings of the surface rule
(:func:`cavex.analytic.penetration.body.build_body`), the integrator tolerances ``rtol`` and
``atol`` divided by :data:`RTOL_FACTOR`, the contact regularisation (``contact_ramp``, or the
held contact's depth) divided by :data:`RAMP_FACTOR`. The estimate of a reported quantity
``q`` is ``|q - q_refined|`` and the quantity counts as resolved when its estimate is within
the tolerance (:data:`DEPTH_TOLERANCE`, :func:`angle_tolerance`, :data:`PEAK_TOLERANCE`):

- final nose-tip depth: 0.1 % of it;
- final pitch, each phase's pitch change: ``max(0.01 deg, 3 %)``;
- the largest axial and lateral overload: 3 %;
- each overload peak (:func:`cavex.analytic.penetration.oblique.overload_peaks`): it survives
  the refinement when the refined run has a peak within one nose length (``PEAK_SPAN``) of its
  depth, and is resolved when, in addition, the two values agree within 3 %.

An estimate never certifies an unresolved run: ``resolved`` is false as soon as one estimate
exceeds its tolerance (or the refined run ends otherwise or has other phases). docs/oblique.md
"Convergence" measures how far one refinement is from the converged value.
"""

from cavex.analytic.penetration.body import AZIMUTHS, NOSE_POINTS, SHANK_RINGS, build_body
from cavex.analytic.penetration.oblique import (
    ATOL,
    CONTACT_RAMP,
    PEAK_SPAN,
    RTOL,
    ObliqueModel,
    overload_peaks,
    peaks,
)

RTOL_FACTOR = 3.0  # rtol and atol of the refined run: the run's / this
RAMP_FACTOR = 2.0  # contact ramp (or held contact's depth) of the refined run: the run's / this
DEPTH_TOLERANCE = 1e-3  # relative
ANGLE_TOLERANCE_DEG, ANGLE_TOLERANCE_RELATIVE = 0.01, 0.03
PEAK_TOLERANCE = 0.03  # relative


def angle_tolerance(value):
    """Tolerance (deg) of an angle or angle change: ``max(0.01 deg, 3 % of |value|)``."""
    return max(ANGLE_TOLERANCE_DEG, ANGLE_TOLERANCE_RELATIVE * abs(value))


def settings(model):
    """The discretisation of ``model`` (JSON-ready)."""
    nose_points, azimuths, shank_rings = model.body.shape
    out = {"nose_points": nose_points, "azimuths": azimuths, "shank_rings": shank_rings,
           "rtol": model.rtol, "atol": model.atol}
    if model.contact_hold:
        out["contact_hold_m"] = model.contact_hold
    else:
        out["contact_ramp_m_s"] = model.contact_ramp
    return out


def refined_model(model):
    """A model like ``model`` with every discretisation parameter refined (module
    docstring)."""
    n, a, s = model.body.shape
    return ObliqueModel(
        model.target, model.projectile, model.law,
        body=build_body(model.projectile, 2 * n, 2 * a, 2 * s), bottom=model.bottom,
        rtol=model.rtol / RTOL_FACTOR, atol=model.atol / RTOL_FACTOR, method=model.method,
        contact_ramp=model.contact_ramp / RAMP_FACTOR, crater=model.crater,
        tangency_psi=model.tangency_psi, entry_crater=model.entry_crater,
        contact_hold=model.contact_hold / RAMP_FACTOR, hold_time=model.hold_time,
        crater_ratio=model.crater_ratio)


def refined_options(projectile):
    """The refined rerun's discretisation as keywords of
    :func:`cavex.analytic.penetration.oblique.fly` (from the defaults)."""
    return {"body": build_body(projectile, 2 * NOSE_POINTS, 2 * AZIMUTHS, 2 * SHANK_RINGS),
            "rtol": RTOL / RTOL_FACTOR, "atol": ATOL / RTOL_FACTOR,
            "contact_ramp": CONTACT_RAMP / RAMP_FACTOR}


def reported(result):
    """The reported quantities of a run: final depth and pitch, each phase's pitch change,
    the largest overloads and the overload peaks."""
    return {"tip_depth_m": result.end["nose_tip_m"][2], "pitch_deg": result.end["pitch_deg"],
            "phases": [(p["end_reason"], p["pitch_change_deg"]) for p in result.phases],
            **{k: v for k, v in peaks(result.history).items() if k.endswith("_g")},
            "overload_peaks": overload_peaks(result.history)}


def _entry(value, refined, tolerance):
    estimate = abs(value - refined)
    return {"value": value, "refined": refined, "estimate": estimate, "tolerance": tolerance,
            "resolved": bool(estimate <= tolerance)}


def matched_peaks(found, refined, span=PEAK_SPAN):
    """Each peak ``(z, g)`` of ``found`` with the nearest peak of ``refined`` within ``span``
    of its depth (None: it does not survive the refinement)."""
    out = []
    for z, g in found:
        near = [p for p in refined if abs(p[0] - z) <= span]
        out.append(((z, g), min(near, key=lambda p: abs(p[0] - z)) if near else None))
    return out


def compare(run, fine):
    """Estimates of the quantities ``run`` (:func:`reported`) against the refined ``fine``
    (module docstring): ``{"resolved", "quantities", "phases", "overload_peaks",
    "unresolved"}``; ``overload_peaks`` lists the peaks that survive the refinement (with
    their estimates), ``not_surviving`` the others (not reported as peaks)."""
    quantities = {
        "tip_depth_m": _entry(run["tip_depth_m"], fine["tip_depth_m"],
                              DEPTH_TOLERANCE * abs(fine["tip_depth_m"])),
        "pitch_deg": _entry(run["pitch_deg"], fine["pitch_deg"],
                            angle_tolerance(fine["pitch_deg"])),
        **{k: _entry(run[k], fine[k], PEAK_TOLERANCE * abs(fine[k]))
           for k in ("max_axial_g", "max_lateral_g")}}
    same_phases = [r for r, _ in run["phases"]] == [r for r, _ in fine["phases"]]
    phases = ([{"end_reason": r, **_entry(x, y, angle_tolerance(y))}
               for (r, x), (_, y) in zip(run["phases"], fine["phases"], strict=True)]
              if same_phases else [])
    surviving, lost = [], []
    for (z, g), match in matched_peaks(run["overload_peaks"], fine["overload_peaks"]):
        if match is None:
            lost.append({"tip_depth_m": z, "axial_g": g})
        else:
            surviving.append({"tip_depth_m": z, **_entry(g, match[1], PEAK_TOLERANCE * match[1]),
                              "refined_tip_depth_m": match[0]})
    unresolved = [k for k, e in quantities.items() if not e["resolved"]]
    unresolved += [f"phase {i + 1} pitch change" for i, e in enumerate(phases)
                   if not e["resolved"]]
    unresolved += [f"overload peak at {p['tip_depth_m']:.3f} m" for p in surviving
                   if not p["resolved"]]
    if not same_phases:
        unresolved.append("phases (the refined run has other events)")
    if lost or len(surviving) != len(fine["overload_peaks"]):
        unresolved.append("overload peaks (not the same peaks in the refined run)")
    return {"resolved": not unresolved, "unresolved": unresolved, "quantities": quantities,
            "phases": phases, "overload_peaks": surviving, "not_surviving": lost}


def estimate(result):
    """One refined rerun of ``result`` (a :class:`~cavex.analytic.penetration.oblique.Result`)
    and :func:`compare` of the two, with the settings of both runs (JSON-ready)."""
    fine_model = refined_model(result.model)
    fine = fine_model.run(result.strike)
    return {"settings": settings(result.model), "refined_settings": settings(fine_model),
            **compare(reported(result), reported(fine))}


def estimate_runs(runs):
    """:func:`estimate` of every run of a trajectory job (``{name: Result}``)."""
    return {name: estimate(result) for name, result in runs.items()}


def verdict(estimates):
    """One line per run: resolved within the tolerances, or which quantities are not."""
    return [f"estimate ({name}, one refined rerun): " + (
        "every reported quantity within its tolerance" if e["resolved"] else
        "NOT resolved within the tolerance: " + ", ".join(e["unresolved"]))
        for name, e in estimates.items()]
