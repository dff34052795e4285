"""FE and closed-form cavity-wall stress side by side for a target's spherical problem at depth L.

The FE side runs on the one solver of :mod:`cavex.fem` (all problems of a call in stacks), with
the default error target: a problem whose estimated discretisation error exceeds
:data:`cavex.fem.estimate.DEFAULT_ERROR_TARGET` is refined (up to twice) until it does not.
"""

from dataclasses import replace

from cavex.analytic.cavity import cavity_solution
from cavex.analytic.geometry import spherical_problem
from cavex.fem.estimate import DEFAULT_ERROR_TARGET, MAX_REFINEMENTS
from cavex.fem.expansion import expand_cavities
from cavex.fem.output import write_result
from cavex.problem import BOUNDARIES, check_problem
from cavex.verification.output.paths import check_output_dir

#: Numerics settings renamed in JSON output (their unit appended)
NUMERICS_JSON_KEYS = {"seed_radius": "seed_radius_m", "tension_cutoff": "tension_cutoff_Pa"}


def fe_problem(target, projectile, depth, velocity, nu=None):
    """``(layers, interfaces, velocity, radius)`` of the FE problem at nose-tip depth ``depth``
    (:func:`cavex.analytic.geometry.spherical_problem`; cavity radius = shank radius), with
    Poisson's ratio ``nu`` for every layer when given."""
    layers, interfaces = spherical_problem(target, projectile, depth)
    if nu is not None:
        layers = [replace(m, nu=nu) for m in layers]
    return list(layers), list(interfaces), float(velocity), float(projectile.r)


def compare_many(requests, error_target=DEFAULT_ERROR_TARGET, max_refinements=MAX_REFINEMENTS,
                 **numerics):
    """FE against closed form for many ``(target, projectile, depth, velocity, nu)`` requests,
    with shared numerics; a list of dicts (see :func:`compare_at_depth`), or of the
    :class:`~cavex.errors.CavexNumericalError` of a failed FE run."""
    return [comparison(request[2], problem, result) if result.ok else result.error
            for request, problem, result in zip(requests, *_run(requests, error_target,
                                                                max_refinements, False,
                                                                **numerics), strict=True)]


def _run(requests, error_target, max_refinements, record, **numerics):
    problems = [fe_problem(*request) for request in requests]
    return problems, expand_cavities(problems, error_target=error_target,
                                     max_refinements=max_refinements, record=record, **numerics)


def comparison(depth, problem, result):
    """The JSON-able comparison of one FE result with both closed-form conventions."""
    layers, interfaces, velocity, radius = problem
    analytic = {b: cavity_solution(layers, interfaces, velocity, radius, boundary=b)
                for b in BOUNDARIES}
    fe = result.cavity_stress
    return {
        "depth_m": float(depth), "velocity_m_s": float(velocity),
        "cavity_radius_m": float(radius),
        "layers": [m.name or f"layer {i}" for i, m in enumerate(layers)],
        "interface_radii_m": [float(h) for h in interfaces],
        "interface_radii_final_m": [float(h) for h in result.interfaces_final],
        "fe_sigma_r_Pa": float(fe),
        "S": float(fe / layers[0].tau),
        "analytic_sigma_r_Pa": {b: float(s.stress) for b, s in analytic.items()},
        "relative_difference": {b: float(fe / s.stress - 1.0) for b, s in analytic.items()},
        "error_estimate": None if result.error_estimate is None else float(result.error_estimate),
        "refinements": int(result.stats["refinements"]),
        "fe_plastic_radius_m": float(result.plastic_radius),
        "analytic_plastic_radius_m": {b: float(s.plastic_radius) for b, s in analytic.items()},
        "numerics": numerics_json(result.numerics),
        "wall_time_s": float(result.stats["seconds"]),
    }


def numerics_json(numerics):
    """:class:`cavex.fem.Numerics` settings (a dict) with the JSON key convention: the
    dimensional ones carry their unit (``seed_radius_m``, ``tension_cutoff_Pa``; README
    "Commands"), the others are dimensionless (``dilatancy_deg`` already names its unit)."""
    return {NUMERICS_JSON_KEYS.get(k, k): v for k, v in numerics.items()}


def compare_at_depth(target, projectile, depth, velocity, nu=None,
                     error_target=DEFAULT_ERROR_TARGET, fields=None, **numerics):
    """FE ``sigma_r`` at the cavity wall next to both analytic conventions, as a plain dict.

    Parameters
    ----------
    target : Target
    projectile : Projectile
    depth : float
        Nose-tip depth ``L`` (m).
    velocity : float
        Cavity expansion velocity ``V`` (m/s).
    nu : float, optional
        Poisson's ratio given to every layer (default: each layer's own ``nu``).
    error_target : float or None
        Refine the FE run while its estimated error exceeds this (None: never).
    fields : str or path, optional
        Folder for the FE fields of the run reported: ``fem.xdmf`` (time series) and
        ``fem_history.csv`` (:func:`cavex.fem.write_result`); checked before the run.
    **numerics
        Settings of :class:`cavex.fem.Numerics`.

    Returns
    -------
    dict
        ``fe_sigma_r_Pa``; ``analytic_sigma_r_Pa`` and ``relative_difference``
        (``fe/analytic - 1``), each a dict keyed ``"dynamic"`` and ``"quasi-static"``;
        ``error_estimate``, ``refinements``; ``fe_plastic_radius_m`` and
        ``analytic_plastic_radius_m`` (dict); ``S`` (FE wall stress over the wall layer's
        tau); the problem (``depth_m``, ``velocity_m_s``, ``cavity_radius_m``, ``layers``,
        ``interface_radii_m``, ``interface_radii_final_m``), ``numerics`` (the settings of
        the run reported, :func:`numerics_json`) and ``wall_time_s``. Keys follow the JSON
        convention of README "Commands" (SI unit suffix on every dimensional quantity).

    Raises
    ------
    CavexNumericalError
        The FE run failed.
    """
    if fields is not None:
        fields = check_output_dir(fields, "fields")
    request = (target, projectile, depth, velocity, nu)
    check_problem(*fe_problem(*request), "dynamic")  # named without the batch's index
    (problem,), (result,) = _run([request], error_target, MAX_REFINEMENTS, fields is not None,
                                 **numerics)
    if not result.ok:
        raise result.error
    out = comparison(depth, problem, result)
    if fields is not None:
        out["fields"] = str(write_result(result, fields / "fem"))
    return out
