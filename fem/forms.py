r"""The weak form in the reference configuration, as scikit-fem forms (the reference path).

Reference radius ``R``, displacement ``u(R)``, current radius ``r = R + u``. Principal stretches
``lambda_r = 1 + du/dR`` and ``lambda_t = 1 + u/R``, log strains ``eps = ln lambda``. With
Kirchhoff stresses ``tau_r``, ``tau_t`` (tension positive) and ``dV = 4 pi R^2 dR``, the virtual
work of the internal forces is

.. math:: \delta W_{int} = \int (\tau_r\, \delta\varepsilon_r + 2\tau_t\, \delta\varepsilon_t)\,dV,
          \quad \delta\varepsilon_r = \frac{\delta u'}{\lambda_r},\quad
          \delta\varepsilon_t = \frac{\delta u}{R\lambda_t},

its linearisation (``C_ij = d tau_i / d eps_j`` from the return map) is

.. math:: \int \Big[\delta\varepsilon_r (C_{rr}\Delta\varepsilon_r + C_{rt}\Delta\varepsilon_t)
          + 2\delta\varepsilon_t (C_{tr}\Delta\varepsilon_r + C_{tt}\Delta\varepsilon_t)
          - \tau_r \frac{\delta u'\,\Delta u'}{\lambda_r^2}
          - 2\tau_t \frac{\delta u\,\Delta u}{R^2\lambda_t^2}\Big]\,dV ,

and the inertia is ``int rho_0 u'' du dV``. The internal-force and tangent forms are integrated
with the reduced (Gauss, ``degree`` points) rule of :mod:`cavex.fem.discretisation`, the mass with
a full rule.
"""

import numpy as np
from skfem import BilinearForm, LinearForm

FOUR_PI = 4.0 * np.pi


def _d_eps(v, w):
    """Variations ``(d eps_r, d eps_t)`` of the log strains for the test/trial function ``v``."""
    return v.grad[0] / w.lam_r, v / (w.x[0] * w.lam_t)


@LinearForm
def internal_force(v, w):
    """``(tau_r d eps_r + 2 tau_t d eps_t) 4 pi R^2``."""
    de_r, de_t = _d_eps(v, w)
    return (w.tau_r * de_r + 2.0 * w.tau_t * de_t) * FOUR_PI * w.x[0] ** 2


@BilinearForm
def tangent(u, v, w):
    """Consistent linearisation of :func:`internal_force` (material plus geometric part)."""
    du_r, du_t = _d_eps(u, w)
    dv_r, dv_t = _d_eps(v, w)
    material = (dv_r * (w.C_rr * du_r + w.C_rt * du_t)
                + 2.0 * dv_t * (w.C_tr * du_r + w.C_tt * du_t))
    geometric = -w.tau_r * du_r * dv_r - 2.0 * w.tau_t * du_t * dv_t
    return (material + geometric) * FOUR_PI * w.x[0] ** 2


@BilinearForm
def mass(u, v, w):
    """``rho_0 u v 4 pi R^2`` (reference density)."""
    return w.rho * u * v * FOUR_PI * w.x[0] ** 2
