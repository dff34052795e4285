"""``cavex fem``: the FE wall stress against both closed-form conventions at one nose depth."""

import json


def run(args, target, projectile):
    """The comparison as text or JSON; ``--fields`` also writes the FE fields."""
    document = summary(job(target, projectile, args.depth, args.velocity, nu=args.nu,
                           fields=args.fields))
    return json.dumps(document, indent=2) if args.json else text(document)


def job(target, projectile, depth, velocity, *, nu=None, fields=None):
    """:func:`cavex.verification.fedata.comparison.compare_at_depth` (JSON-able)."""
    from cavex.verification.fedata.comparison import compare_at_depth

    return compare_at_depth(target, projectile, depth, velocity, nu=nu, fields=fields)


def summary(job):
    """What ``cavex fem --json`` prints: the comparison as it is."""
    return job


def text(summary):
    """The problem, the FE and analytic wall stresses with their differences, the estimate."""
    s = summary
    fe, analytic = s["fe_sigma_r_Pa"], s["analytic_sigma_r_Pa"]
    lines = [f"nose depth {s['depth_m']} m, V = {s['velocity_m_s']} m/s, cavity "
             f"radius {s['cavity_radius_m']} m, layers {', '.join(s['layers'])}",
             f"interfaces (m): requested {s['interface_radii_m']}, FE final "
             f"{s['interface_radii_final_m']}",
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
        lines.append(f"wrote   {s['fields']} (+ history CSV)")
    return "\n".join(lines)
