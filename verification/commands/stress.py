"""``cavex stress``: S, sigma_r, response state and b at one nose depth and velocity."""

import json
import math

from cavex.analytic.cavity import cavity_solution
from cavex.analytic.geometry import spherical_problem, wall_layer
from cavex.analytic.paper_model import paper_coefficients
from cavex.analytic.penetration.resistance import check_model, model_boundary, model_label
from cavex.errors import CavexNumericalError, require
from cavex.materials import MAX_VELOCITY


def run(args, target, projectile):
    """The closed form's wall stress as text or JSON (a table is no closed form: refused)."""
    from cavex.verification.commands.options import CLOSED_FORMS, resistance_settings

    settings = resistance_settings(args, CLOSED_FORMS)
    document = summary(stress_at_depth(target, projectile, args.depth, args.velocity,
                                       resistance=settings["resistance"],
                                       boundary=settings["boundary"],
                                       epsilon=settings["epsilon"]))
    return json.dumps(document, indent=2) if args.json else text(document)


def stress_at_depth(target, projectile, depth, velocity, *, resistance="derived", boundary=None,
                    epsilon="quasi-static"):
    """JSON-able description of the cavity-wall stress at nose depth ``depth`` (m) of the
    closed form ``resistance`` ("derived" or "paper"); ``boundary`` None is the default
    (dynamic for the derived model, see
    :func:`cavex.analytic.penetration.resistance.model_boundary`)."""
    require(math.isfinite(velocity) and 0.0 <= velocity <= MAX_VELOCITY, "velocity",
            f"in [0, {MAX_VELOCITY:g}] m/s", velocity)
    check_model(resistance, boundary)
    boundary = model_boundary(resistance, boundary)
    if resistance == "paper":
        return _finite(_paper(target, projectile, depth, velocity, epsilon))
    layers, interfaces = spherical_problem(target, projectile, depth)
    state = cavity_solution(layers, interfaces, velocity, projectile.r, boundary=boundary)
    index = wall_layer(target, projectile, depth)
    return _finite({"model": model_label(resistance, boundary), "resistance": resistance,
            "boundary": boundary, "depth_m": depth,
            "velocity_m_s": velocity, "sigma_r_Pa": state.stress, "S": state.S,
            "S_normalised_by": f"tau of {target.layer_name(index)} ({layers[0].tau} Pa)",
            "response_state": state.state, "plastic_radius_m": state.plastic_radius,
            "wall_layer": target.layer_name(index), "interface_radii_m": list(interfaces),
            "plastic_zones": [{"layer": target.layer_name(index + i), "r_inner_m": r0,
                               "r_outer_m": r1} for i, r0, r1 in state.plastic_zones]})


def summary(job):
    """What ``cavex stress --json`` prints: the job's description as it is (JSON-able)."""
    return job


def text(summary):
    """One ``key value`` line per item."""
    return "\n".join(f"{key:<22} {value}" for key, value in summary.items())


def _finite(result):
    """``result`` unless a number in it is not finite (then a numerical failure, never printed
    as a number)."""
    for key, value in result.items():
        if isinstance(value, float) and not math.isfinite(value):
            raise CavexNumericalError(f"the {result['model']} model gives {key} = {value} at "
                                      f"V = {result['velocity_m_s']:g} m/s, "
                                      f"L = {result['depth_m']:g} m")
    return result


def _paper(target, projectile, depth, velocity, epsilon):
    c = paper_coefficients(target, projectile, depth, epsilon=epsilon)
    return {"model": "paper", "resistance": "paper", "epsilon": epsilon, "depth_m": depth,
            "velocity_m_s": velocity,
            "sigma_r_Pa": c.stress(velocity), "S": c.S(velocity),
            "S_normalised_by": f"tau = {c.tau} Pa (as the paper's Eq. {c.equation})",
            "A": c.A, "B": c.B, "equation": c.equation, "response_state": c.state}
