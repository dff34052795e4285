"""``cavex fem``: the FE wall stress against both closed-form conventions at one nose depth."""

import sys

from cavex.verification.commands.shared_options import add_config_option

HELP = "FE against analytic wall stress at a nose depth"

#: m/s: the upper end of the model's range (docs/fem.md "Range"): the velocities the FE is
#: verified over (cavex.verification.fedata.table.DEFAULT_VELOCITIES, 0-1200 m/s), a little
#: above the speeds the rigid-projectile model is used at (the paper's V0 = 1000 m/s, the
#: validation shots to 800 m/s); beyond it the wall stress leaves the constitutive law (no
#: equation of state) and a real projectile deforms.
RANGE_VELOCITY = 1200.0


def add_arguments(parser):
    """The options of ``cavex fem``."""
    add_config_option(parser)
    parser.add_argument("--velocity", type=float, required=True, help="expansion velocity V (m/s)")
    parser.add_argument("--depth", type=float, required=True, help="nose-tip depth L (m)")
    parser.add_argument("--nu", type=float, help="Poisson's ratio for every layer (default: "
                        "file's)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.add_argument("--fields", help="folder for the FE fields (XDMF time series for "
                        "ParaView and meshio, history CSV; default: none written)")


def run(args, target, projectile):
    """The comparison (:func:`job`); ``--fields`` also writes the FE fields. A velocity beyond
    :data:`RANGE_VELOCITY`, or a layer with FE-only keys, is computed, with one warning line
    each on stderr."""
    from cavex.verification.commands.options import refuse_debonded

    refuse_debonded(target, "fem")
    result = job(target, projectile, args.depth, args.velocity, nu=args.nu, fields=args.fields)
    for warning in result["warnings"]:
        print(f"cavex fem: warning: {warning}", file=sys.stderr)
    return result


def range_warnings(velocity, wall_stress):
    """What to say about ``velocity`` (m/s) with the FE ``wall_stress`` (Pa): a sentence if it
    is beyond :data:`RANGE_VELOCITY`, else nothing."""
    if velocity <= RANGE_VELOCITY:
        return []
    return [f"V = {velocity:g} m/s is beyond {RANGE_VELOCITY:g} m/s, the model's range (the "
            f"incompressible rigid-projectile regime, docs/fem.md 'Range'): a real projectile "
            f"deforms, and the wall stress ({wall_stress / 1e9:.3g} GPa) is beyond the "
            "constitutive law"]


def estimate_warnings(result):
    """A sentence if the FE's estimated error is still above the target the commands promise
    (:data:`cavex.fem.estimate.DEFAULT_ERROR_TARGET`) after the refinements allowed."""
    from cavex.fem.estimate import DEFAULT_ERROR_TARGET

    estimate = result["error_estimate"]
    if estimate is None or estimate <= DEFAULT_ERROR_TARGET:
        return []
    return [f"the FE's estimated error {estimate:.3%} is above the {DEFAULT_ERROR_TARGET:.1%} "
            f"target after {result['refinements']} refinement(s), the most allowed: the wall "
            "stress is resolved only to that estimate"]


def material_warnings(target):
    """A sentence if a layer has FE-only keys (``tau_max``, ``tensile_strength``): the closed
    forms ignore them, so the comparison is between different materials."""
    from cavex.verification.commands.options import fe_only_layers

    named = fe_only_layers(target)
    if not named:
        return []
    return ["FE-only keys in " + "; ".join(named) + ": the closed forms ignore them, so "
            "FE/analytic - 1 compares different materials (docs/fem.md 'Concrete')"]


def job(target, projectile, depth, velocity, *, nu=None, fields=None):
    """:func:`cavex.verification.fedata.comparison.compare_at_depth` (JSON-able) with
    ``warnings``: the velocity beyond the model's range (:func:`range_warnings`) and the
    FE-only keys (:func:`material_warnings`). The problem is checked first, before the FE
    solver is loaded: bad input answers at once."""
    from cavex.analytic.geometry import spherical_problem
    from cavex.problem import SphericalProblem

    SphericalProblem(*spherical_problem(target, projectile, depth), velocity, projectile.r)
    from cavex.verification.fedata.comparison import compare_at_depth

    result = compare_at_depth(target, projectile, depth, velocity, nu=nu, fields=fields)
    return {**result, "warnings": range_warnings(result["velocity_m_s"], result["fe_sigma_r_Pa"])
            + material_warnings(target) + estimate_warnings(result)}


def summary(result):
    """What ``cavex fem --json`` prints: the comparison as it is, with its ``warnings``."""
    return result


def text(result):
    """The problem, the FE and analytic wall stresses with their differences, the estimate."""
    s = result
    fe, analytic = s["fe_sigma_r_Pa"], s["analytic_sigma_r_Pa"]
    lines = [f"nose depth {s['depth_m']:.6g} m, V = {s['velocity_m_s']:.6g} m/s, cavity "
             f"radius {s['cavity_radius_m']:.6g} m, layers {', '.join(s['layers'])}",
             f"interfaces (m): requested {_radii(s['interface_radii_m'])}, FE final "
             f"{_radii(s['interface_radii_final_m'])}",
             f"{'':<26} {'sigma_r (MPa)':>14} {'FE/analytic - 1':>16} {'b (m)':>10}",
             f"{'FE':<26} {fe / 1e6:14.3f} {'':>16} {s['fe_plastic_radius_m']:10.5f}"]
    for boundary, stress in analytic.items():
        lines.append(f"{'analytic ' + boundary:<26} {stress / 1e6:14.3f} "
                     f"{s['relative_difference'][boundary]:16.4%} "
                     f"{s['analytic_plastic_radius_m'][boundary]:10.5f}")
    estimate = s["error_estimate"]
    lines.append("FE estimated discretisation error: "
                 + ("not estimated" if estimate is None else f"{estimate:.3%}")
                 + f" ({s['refinements']} refinement(s) of the default resolution)")
    if "fields" in s:
        lines.append(f"wrote   {s['fields']} (time series: meshio.xdmf.TimeSeriesReader), "
                     "fem_final.vtu (meshio.read), fem_history.csv")
    return "\n".join(lines)


def _radii(radii):
    """Interface radii (m) to 6 significant digits, or "none"."""
    return ", ".join(f"{r:.6g}" for r in radii) or "none"
