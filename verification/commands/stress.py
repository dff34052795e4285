"""``cavex stress``: S, sigma_r, response state and b at one nose depth and velocity."""

import math

from cavex.analytic.geometry import spherical_problem
from cavex.analytic.models import get, names
from cavex.errors import CavexNumericalError, require
from cavex.materials import MAX_VELOCITY
from cavex.verification.commands.options import (
    CLOSED_FORMS,
    add_resistance_options,
    fe_only_layers,
    refuse_debonded,
    resistance_settings,
)
from cavex.verification.commands.shared_options import add_config_option

HELP = "cavity-wall stress at a nose depth"


def add_arguments(parser):
    """The options of ``cavex stress``."""
    add_config_option(parser)
    add_resistance_options(parser, CLOSED_FORMS, table=False)
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.add_argument("--velocity", type=float, required=True, help="expansion velocity V (m/s)")
    parser.add_argument("--depth", type=float, required=True, help="nose-tip depth L (m)")


def run(args, target, projectile):
    """The closed form's wall stress (:func:`stress_at_depth`; a table is no closed form:
    refused)."""
    refuse_debonded(target, "stress")
    settings = resistance_settings(args, CLOSED_FORMS)
    result = stress_at_depth(target, projectile, args.depth, args.velocity,
                             resistance=settings["resistance"], boundary=settings["boundary"],
                             epsilon=settings["epsilon"])
    named = fe_only_layers(target)
    if named:  # the realistic concrete: the closed form answers for another material
        result["notes"] = [f"the closed form ignores the FE-only keys of {'; '.join(named)}: "
                           "the wall stress of another material than the FE's (`cavex fem` "
                           "carries them; docs/fem.md 'Concrete')"]
    return result


def stress_at_depth(target, projectile, depth, velocity, *, resistance="derived", boundary=None,
                    epsilon="quasi-static"):
    """JSON-able description of the cavity-wall stress at nose depth ``depth`` (m) of the
    closed form ``resistance`` (a model of the registry with ``closed_form``); ``boundary``
    None is the model's default (:meth:`cavex.analytic.models.registry.Model.boundary`)."""
    require(math.isfinite(velocity) and 0.0 <= velocity <= MAX_VELOCITY, "velocity",
            f"in [0, {MAX_VELOCITY:g}] m/s", velocity)
    model = get(resistance, offered=names(closed_form=True))
    model.check(boundary)
    spherical_problem(target, projectile, depth)  # checks the depth
    return _finite(model.wall_stress(target, projectile, depth, velocity,
                                     boundary=model.boundary(boundary), epsilon=epsilon))


def summary(result):
    """What ``cavex stress --json`` prints: the result's description as it is (JSON-able)."""
    return result


DIGITS = 4  # significant digits of the text table (the JSON keeps every digit)


def text(result):
    """A table of quantity, value (:data:`DIGITS` significant digits) and unit: stresses in
    MPa, lengths in mm, the response state spelled out (:func:`state_meaning`)."""
    s = summary(result)
    g = _digits
    model = s["model"] + (f", epsilon {s['epsilon']}" if "epsilon" in s
                          else f" ({s['boundary']} boundary)")
    rows = [("model", model, ""), ("nose-tip depth L", g(s["depth_m"]), "m"),
            ("expansion velocity V", g(s["velocity_m_s"]), "m/s")]
    if "wall_layer" in s:
        rows.append(("layer at the wall", s["wall_layer"], ""))
    rows += [("sigma_r at the wall", g(s["sigma_r_Pa"] / 1e6), "MPa"),
             ("S = sigma_r / tau", g(s["S"]), f"(tau = {g(s['tau_Pa'] / 1e6)} MPa, "
              f"{s['S_normalised_by']})")]
    if "equation" in s:  # the paper's printed coefficients
        rows += [("A, B (S = A + B rho V^2/tau)", f"{g(s['A'])}, {g(s['B'])}",
                  f"(Eq. {s['equation']})")]
    rows.append(("response state", f"{s['response_state']}:", s["response_state_meaning"]))
    if "plastic_radius_m" in s:
        rows.append(("plastic radius b", g(s["plastic_radius_m"] * 1e3), "mm"))
        radii = ", ".join(g(r * 1e3) for r in s["interface_radii_m"])
        rows.append(("interface radii", f"{radii} mm from the cavity centre" if radii
                     else "none (one layer around the cavity)", ""))
        zones = "; ".join(f"{z['layer']} {g(z['r_inner_m'] * 1e3)}-{g(z['r_outer_m'] * 1e3)}"
                          for z in s["plastic_zones"]) or "none"
        rows.append(("plastic zones", zones, "mm" if s["plastic_zones"] else ""))
    width = max(len(name) for name, _, _ in rows)
    return "\n".join([f"{name:<{width}}  {value}" + (f" {unit}" if unit else "")
                      for name, value, unit in rows]
                     + [f"note: {note}" for note in s.get("notes", ())])


def _digits(x):
    """``x`` with :data:`DIGITS` significant digits."""
    return format(x, f".{DIGITS}g")


def _finite(result):
    """``result`` unless a number in it is not finite (then a numerical failure, never printed
    as a number)."""
    for key, value in result.items():
        if isinstance(value, float) and not math.isfinite(value):
            raise CavexNumericalError(f"the {result['model']} model gives {key} = {value} at "
                                      f"V = {result['velocity_m_s']:g} m/s, "
                                      f"L = {result['depth_m']:g} m")
    return result
