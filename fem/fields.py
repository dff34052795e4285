"""Post-processing: current radii, Cauchy stresses, wall stress and the plastic radius."""

import numpy as np


def current_point_radii(disc, u):
    """Current radius ``r = R lambda_t`` of every quadrature point, shape (nel, nq)."""
    _, g_t = disc.displacement_gradients(u)
    return disc.R_points * (1.0 + g_t)


def cauchy_stresses(disc, u, response):
    """``(sigma_r, sigma_theta)`` at the points, Pa, compression positive (``-tau/J``)."""
    g_r, g_t = disc.displacement_gradients(u)
    J = (1.0 + g_r) * (1.0 + g_t) ** 2
    return -response.tau_r / J, -response.tau_t / J


def wall_stress(disc, u, wall_force):
    """Cavity-wall ``sigma_r`` (Pa, compression positive) from the consistent nodal reaction.

    ``wall_force`` is the wall row of ``f_int + M a``; divided by the current wall area.
    """
    a = disc.R_dofs[0] + u[0]
    return wall_force / (4.0 * np.pi * a * a)


def plastic_radius(disc, u, response, state):
    """Current radius of the outermost yielded material (m); the wall radius if none yielded.

    Points that have yielded carry plastic strain. Beyond the last one, the elastic deviator of
    an expanding sphere falls off as ``r^-3`` (exact for the Lame/Hill and incompressible fields),
    so the boundary is placed from the first elastic point ``r_e`` with yield ratio ``f_e``
    (deviator over strength) at ``b = r_e f_e^(1/3)``, between that point and the last yielded one.
    """
    r = current_point_radii(disc, u).ravel()
    yielded = (state["eq_p"].ravel() > 0.0) | response.plastic.ravel()
    a = disc.R_dofs[0] + u[0]
    if not np.any(yielded):
        return float(a)
    last = int(np.flatnonzero(yielded)[-1])
    if last + 1 >= r.size:
        return float(r[last])
    ratio = response.yield_ratio.ravel()[last + 1]
    b = r[last + 1] * min(max(ratio, 0.0), 1.0) ** (1.0 / 3.0)
    return float(min(max(b, r[last]), r[last + 1]))
