r"""Axial force on a rigid ogive nose from the cavity-wall stress (paper Eqs. 3-14).

A tangent ogive of shank radius ``r`` and ogive radius ``R`` is parametrised by the angle
``phi`` from ``phi_0 = asin((R - r)/R)`` at the tip to ``pi/2`` at the shank. The normal stress
on the nose is the cavity-wall stress at the normal expansion velocity ``V cos(phi)``, so

.. math:: F(V) = 2\pi R^2 \int_{\phi_0}^{\pi/2}
          \Big[\sin\phi - \frac{R - r}{R}\Big] \cos\phi \; \sigma_r(V\cos\phi)\, d\phi .

For ``sigma_r = tau A + B rho V^2`` this is ``F = C_A + C_B V^2`` with ``C_A = pi r^2 tau A``
and ``C_B = pi r^2 rho B (8 psi - 1)/(24 psi^2)``, ``psi = R/(2r)`` (Eqs. 12-14). For any other
``sigma_r(V)`` the integral is evaluated by Gauss-Legendre quadrature in ``phi``. Where the
response state does not change over ``[0, V]`` the integrand is smooth and the rule converges
exponentially (``test_nose`` measures 1e-13 at 8 points); where it changes, ``sigma_r(V)`` has a
kink and the error is algebraic (measured 6e-6 relative at 8 points, dynamic convention, 0.62 m).
"""

import math
from functools import lru_cache

import numpy as np

QUADRATURE_POINTS = 8


def ogive_coefficients(projectile, A, B, tau, rho):
    """``(C_A, C_B)`` of Eqs. 13-14 for ``S = A + B rho V^2 / tau``."""
    psi = projectile.psi
    area = math.pi * projectile.r ** 2
    return area * tau * A, area * rho * B * (8.0 * psi - 1.0) / (24.0 * psi ** 2)


def nose_rule(projectile, points=QUADRATURE_POINTS):
    """Quadrature ``(cos(phi_k), w_k)`` with ``F(V) = sum_k w_k sigma_r(V cos(phi_k))``
    (read-only arrays, computed once per ogive and number of points)."""
    return _rule(float(projectile.R), float(projectile.r), points)


@lru_cache(maxsize=64)
def angle_rule(R, r, points=QUADRATURE_POINTS):
    r"""Gauss-Legendre rule in the angle ``phi`` of the ogive's normal over ``[phi_0, pi/2]``,
    ``phi_0 = asin((R - r)/R)``: ``int f(phi) dphi ~ sum_k f(phi_k) g_k J``.

    Returns ``(phi_k, g_k, J)``: the nodes, the Legendre weights on ``[-1, 1]`` and the
    Jacobian ``J = (pi/2 - phi_0)/2`` (read-only arrays). The nose force
    (:func:`nose_rule`) and the 3-D body's surface elements
    (:func:`cavex.analytic.penetration.body.build_body`) both use it.
    """
    phi0 = math.asin((R - r) / R)
    nodes, weights = np.polynomial.legendre.leggauss(points)
    phi = phi0 + (0.5 * math.pi - phi0) * 0.5 * (nodes + 1.0)
    for array in (phi, weights):
        array.setflags(write=False)
    return phi, weights, 0.5 * (0.5 * math.pi - phi0)


@lru_cache(maxsize=64)
def _rule(R, r, points):
    s0 = (R - r) / R
    phi, weights, jacobian = angle_rule(R, r, points)
    w = 2.0 * math.pi * R ** 2 * (np.sin(phi) - s0) * np.cos(phi) * weights * jacobian
    cosines = np.cos(phi)
    cosines.setflags(write=False)
    w.setflags(write=False)
    return cosines, w


def nose_force(projectile, wall_stress, velocity, points=QUADRATURE_POINTS):
    """Axial nose force (N) for a cavity-wall stress law ``wall_stress(V) -> Pa``, by quadrature.

    ``wall_stress`` is called once, with the array of the nodes' velocities ``V cos(phi_k)``.
    """
    cosines, weights = nose_rule(projectile, points)
    return float(np.sum(weights * wall_stress(velocity * cosines)))
