"""FE and analytic cavity-wall stress side by side for the target's spherical problem at depth L."""

from dataclasses import replace

from cavex.analytic.cavity import cavity_solution
from cavex.analytic.geometry import spherical_problem
from cavex.fem.expansion import expand_cavity


def compare_at_depth(target, projectile, depth, velocity, nu=None, **numerics):
    """FE ``sigma_r`` at the cavity wall next to both analytic conventions, as a plain dict.

    Parameters
    ----------
    target : Target
    projectile : Projectile
    depth : float
        Nose-tip depth ``L`` (m); the spherical problem comes from
        :func:`cavex.analytic.geometry.spherical_problem` (cavity radius = shank radius).
    velocity : float
        Cavity expansion velocity ``V`` (m/s).
    nu : float, optional
        Poisson's ratio given to every layer (default: each layer's own ``nu``).
    **numerics
        Settings of :class:`cavex.fem.settings.Numerics`.

    Returns
    -------
    dict
        ``fe_sigma_r``; ``analytic_sigma_r`` and ``relative_difference`` (``fe/analytic - 1``),
        each a dict keyed ``"dynamic"`` and ``"quasi-static"``; ``error_estimate``;
        ``fe_plastic_radius`` and ``analytic_plastic_radius`` (dict); ``S`` (FE wall stress over
        the wall layer's tau); the problem (``depth``, ``velocity``, ``radius``, ``layers``,
        ``interfaces``, ``interfaces_final``) and ``settings`` (the numerics used).
    """
    layers, interfaces = spherical_problem(target, projectile, depth)
    if nu is not None:
        layers = [replace(m, nu=nu) for m in layers]
    radius = projectile.r
    result = expand_cavity(layers, interfaces, velocity, radius, **numerics)
    analytic = {b: cavity_solution(layers, interfaces, velocity, radius, boundary=b)
                for b in ("dynamic", "quasi-static")}
    fe = result.cavity_stress
    return {
        "depth": float(depth), "velocity": float(velocity), "radius": float(radius),
        "layers": [m.name or f"layer {i}" for i, m in enumerate(layers)],
        "interfaces": [float(h) for h in interfaces],
        "interfaces_final": [float(h) for h in result.interfaces_final],
        "fe_sigma_r": float(fe),
        "S": float(fe / layers[0].tau),
        "analytic_sigma_r": {b: float(s.stress) for b, s in analytic.items()},
        "relative_difference": {b: float(fe / s.stress - 1.0) for b, s in analytic.items()},
        "error_estimate": None if result.error_estimate is None else float(result.error_estimate),
        "fe_plastic_radius": float(result.plastic_radius),
        "analytic_plastic_radius": {b: float(s.plastic_radius) for b, s in analytic.items()},
        "settings": result.settings["numerics"],
        "seconds": float(result.stats["seconds"]),
    }
