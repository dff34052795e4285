"""The FE side of a case: the JSON-able record of one FE run of the one solver (what an FE case
returns, :func:`cavex.verification.fedata.cases.fe_cases`; the closed-form side is added
where the numbers are kept, :mod:`cavex.verification.fedata.comparison`)."""

from cavex.fem.estimate import DEFAULT_ERROR_TARGET, MAX_REFINEMENTS
from cavex.fem.expansion import expand_problems

#: Numerics settings renamed in JSON output (their unit appended)
NUMERICS_JSON_KEYS = {"seed_radius": "seed_radius_m", "tension_cutoff": "tension_cutoff_Pa"}
def fe_records(depths, problems, numerics, error_target=DEFAULT_ERROR_TARGET):
    """FE runs of checked ``problems`` (nose-tip ``depths``) with one
    :class:`~cavex.fem.Numerics`: per problem its :func:`fe_record`, or the
    :class:`~cavex.errors.CavexNumericalError` of a failed FE run."""
    results = expand_problems(problems, numerics, error_target=error_target,
                              max_refinements=MAX_REFINEMENTS)
    return [fe_record(depth, problem, result) if result.ok else result.error
            for depth, problem, result in zip(depths, problems, results, strict=True)]


def fe_record(depth, problem, result):
    """The JSON-able record of one FE result (the FE side of :func:`compare_at_depth`)."""
    layers, interfaces, velocity, radius = problem.as_tuple()
    fe = result.cavity_stress
    return {
        "depth_m": float(depth), "velocity_m_s": float(velocity),
        "cavity_radius_m": float(radius),
        "layers": [m.name or f"layer {i}" for i, m in enumerate(layers)],
        "interface_radii_m": [float(h) for h in interfaces],
        "interface_radii_final_m": [float(h) for h in result.interfaces_final],
        "fe_sigma_r_Pa": float(fe),
        "S": float(fe / layers[0].tau),
        "error_estimate": None if result.error_estimate is None else float(result.error_estimate),
        "refinements": int(result.stats["refinements"]),
        "fe_plastic_radius_m": float(result.plastic_radius),
        "numerics": numerics_json(result.numerics),
        "wall_time_s": float(result.stats["seconds"]),
    }


def numerics_json(numerics):
    """:class:`cavex.fem.Numerics` settings (a dict) with the JSON key convention: the
    dimensional ones carry their unit (``seed_radius_m``, ``tension_cutoff_Pa``; README
    "Commands"), the others are dimensionless (``dilatancy_deg`` already names its unit)."""
    return {NUMERICS_JSON_KEYS.get(k, k): v for k, v in numerics.items()}
