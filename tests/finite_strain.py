r"""Incompressible cavity expansion with a finite-strain (Hencky) elastic zone, by quadrature.

The analytic model (``cavex.analytic.cavity``) takes the elastic deviator in small strain,
``sigma_r - sigma_theta = (2E/3) y^3`` with ``y = a/r``. For a cavity opened from zero radius in
incompressible material the exact stretches are ``lambda_t = r/R = (1 - y^3)^(-1/3)``,
``lambda_r = lambda_t^-2``, so the Hencky deviator is

.. math:: D_e = -2G \ln(1 - y^3), \qquad G = E/3,

which reduces to the small-strain one as ``y^3 -> 0`` but is larger where ``y^3`` is not small
(soft layers: ``E/tau = 20`` gives ``y^3 ~ 0.075`` at the elastic-plastic boundary). With the
same momentum balance ``d sigma_r/dy = 2D/y + 2 rho V^2 (1 - y^3)``, the plastic deviator
``D = alpha sigma_r + k`` and the dynamic yield condition at ``b`` (``D_e = alpha sigma_r + k``),
the single-layer wall stress is integrated here numerically. It is the reference the FE solver
is compared with where the small-strain closed form is not the same problem.
"""

import math

from scipy.integrate import solve_ivp


def finite_strain_cavity_stress(material, velocity, rtol=1e-10):
    """Wall ``sigma_r`` (Pa) of one incompressible Hencky/Mohr-Coulomb layer (dynamic yield)."""
    G = material.E / 3.0
    alpha, k = material.alpha, material.yield_intercept
    rho_v2 = material.rho * velocity ** 2

    def elastic(y, s):
        return [2.0 * (-2.0 * G * math.log1p(-y ** 3)) / y + 2.0 * rho_v2 * (1.0 - y ** 3)]

    def plastic(y, s):
        return [2.0 * (alpha * s[0] + k) / y + 2.0 * rho_v2 * (1.0 - y ** 3)]

    def yields(y, s):
        return -2.0 * G * math.log1p(-y ** 3) - alpha * s[0] - k

    yields.terminal = True
    yields.direction = 1
    y0 = 1e-6
    s0 = (4.0 * material.E / 9.0) * y0 ** 3 + 2.0 * rho_v2 * y0  # series start, y -> 0
    out = solve_ivp(elastic, (y0, 1.0 - 1e-12), [s0], events=yields, rtol=rtol, atol=1e-6)
    if out.t_events[0].size == 0:
        return float(out.y[0, -1])
    yb, sb = out.t_events[0][0], out.y_events[0][0][0]
    out = solve_ivp(plastic, (yb, 1.0), [sb], rtol=rtol, atol=1e-6)
    return float(out.y[0, -1])
