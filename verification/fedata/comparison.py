"""FE and closed-form cavity-wall stress side by side for a target's spherical problem at depth L.

The FE side runs on the one solver of :mod:`cavex.fem` (all problems of a call in stacks), with
the default error target: a problem whose estimated discretisation error exceeds
:data:`cavex.fem.estimate.DEFAULT_ERROR_TARGET` is refined (up to twice) until it does not.
Its record (:func:`cavex.verification.fedata.fe_record.fe_record`) is what an FE case returns.

The closed-form side (:func:`closed_forms`) is evaluated once per problem and convention
through the array form of :func:`cavex.analytic.cavity.cavity_solution`, for all problems of a
call together, where the numbers are kept (the FE table, the batch Dataset, ``cavex fem``);
:func:`comparison_record` puts both sides in one record.
"""

import numpy as np

from cavex.analytic.cavity import cavity_solution
from cavex.fem.estimate import DEFAULT_ERROR_TARGET, MAX_REFINEMENTS
from cavex.fem.expansion import expand_problems
from cavex.fem.output import write_result
from cavex.fem.settings import make_numerics
from cavex.problem import BOUNDARIES
from cavex.verification.fedata.cases import fe_problem
from cavex.verification.fedata.fe_record import fe_record
from cavex.verification.output.number_format import FE_DIGITS
from cavex.verification.output.paths import check_output_dir

#: Keys of a comparison record, in order (the FE record's and the closed forms')
COMPARISON_KEYS = ("depth_m", "velocity_m_s", "cavity_radius_m", "layers", "interface_radii_m",
                   "interface_radii_final_m", "fe_sigma_r_Pa", "S", "analytic_sigma_r_Pa",
                   "relative_difference", "error_estimate", "refinements",
                   "fe_plastic_radius_m", "analytic_plastic_radius_m", "numerics",
                   "wall_time_s")


def closed_forms(problems, boundaries=BOUNDARIES):
    """Closed-form wall stress and plastic radius of every problem, evaluated once each.

    Parameters
    ----------
    problems : sequence of tuple
        ``(layers, interfaces, velocity, radius)`` each (checked by the evaluation).
    boundaries : sequence of str
        Conventions (:data:`cavex.problem.BOUNDARIES`).

    Returns
    -------
    dict
        ``{boundary: (stress, plastic_radius)}``, float arrays in the order of ``problems``:
        one :func:`~cavex.analytic.cavity.cavity_solution` call per convention and group of
        problems with the same layers (interfaces, velocities and radii as arrays; the same
        bits as one call per problem).
    """
    groups = {}
    for i, (layers, *_) in enumerate(problems):
        groups.setdefault(tuple(layers), []).append(i)
    out = {b: (np.full(len(problems), np.nan), np.full(len(problems), np.nan))
           for b in boundaries}
    for layers, members in groups.items():
        interfaces = np.array([problems[i][1] for i in members], dtype=float).reshape(
            len(members), len(layers) - 1)
        velocity = np.array([problems[i][2] for i in members], dtype=float)
        radius = np.array([problems[i][3] for i in members], dtype=float)
        for b in boundaries:
            state = cavity_solution(layers, interfaces, velocity, radius, boundary=b)
            out[b][0][members] = state.stress
            out[b][1][members] = state.plastic_radius
    return out


def comparison_record(record, closed, i):
    """An FE ``record`` (:func:`fe_record`) with problem ``i`` of ``closed``
    (:func:`closed_forms`) beside it: ``analytic_sigma_r_Pa``, ``relative_difference``
    (``fe/analytic - 1``) and ``analytic_plastic_radius_m``, each keyed by convention; keys in
    the order :data:`COMPARISON_KEYS`, then any others of ``record``."""
    fe = record["fe_sigma_r_Pa"]
    stress = {b: float(s[i]) for b, (s, _) in closed.items()}
    merged = {**record, "analytic_sigma_r_Pa": stress,
              "relative_difference": {b: float(fe / s - 1.0) for b, s in stress.items()},
              "analytic_plastic_radius_m": {b: float(r[i]) for b, (_, r) in closed.items()}}
    return {**{k: merged[k] for k in COMPARISON_KEYS if k in merged},
            **{k: v for k, v in merged.items() if k not in COMPARISON_KEYS}}


def with_closed_forms(records, problems):
    """``records`` (dicts with ``"status"``) where the ``"ok"`` ones get the closed forms of
    ``problems[record["id"]]`` (:func:`comparison_record`; one :func:`closed_forms` for all);
    the others as they are."""
    ok = [r for r in records if r.get("status") == "ok"]
    closed = closed_forms([problems[r["id"]].as_tuple() for r in ok])
    done = {id(r): comparison_record(r, closed, i) for i, r in enumerate(ok)}
    return [done.get(id(r), r) for r in records]


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
        ``fem_final.vtu`` (the last snapshot, for ``meshio.read``) and ``fem_history.csv``
        (:func:`cavex.fem.write_result`, :data:`FE_DIGITS` digits); checked before the run.
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
    problem = fe_problem(target, projectile, depth, velocity, nu)
    result, = expand_problems([problem], make_numerics(**numerics), error_target=error_target,
                              max_refinements=MAX_REFINEMENTS, record=fields is not None)
    if not result.ok:
        raise result.error
    out = comparison_record(fe_record(depth, problem, result),
                            closed_forms([problem.as_tuple()]), 0)
    if fields is not None:
        out["fields"] = str(write_result(result, fields / "fem", digits=FE_DIGITS))
    return out
