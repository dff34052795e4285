r"""The compiled element kernel: internal force, consistent tangent and point response of a stack.

Reference radius ``R``, displacement ``u(R)``, current radius ``r = R + u``. Principal stretches
``lambda_r = 1 + du/dR`` and ``lambda_t = 1 + u/R``, log strains ``eps = ln lambda`` (formed as
``log1p`` of the displacement gradients, which keeps full relative precision at tiny strains).
With Kirchhoff stresses ``tau_r``, ``tau_t`` (tension positive) and ``dV = 4 pi R^2 dR``, the
virtual work of the internal forces is

.. math:: \delta W_{int} = \int (\tau_r\, \delta\varepsilon_r + 2\tau_t\, \delta\varepsilon_t)\,dV,
          \quad \delta\varepsilon_r = \frac{\delta u'}{\lambda_r},\quad
          \delta\varepsilon_t = \frac{\delta u}{R\lambda_t},

and its linearisation (``C_ij = d tau_i / d eps_j`` from the return map,
:func:`cavex.fem.constitutive.return_point`) is

.. math:: \int \Big[\delta\varepsilon_r (C_{rr}\Delta\varepsilon_r + C_{rt}\Delta\varepsilon_t)
          + 2\delta\varepsilon_t (C_{tr}\Delta\varepsilon_r + C_{tt}\Delta\varepsilon_t)
          - \tau_r \frac{\delta u'\,\Delta u'}{\lambda_r^2}
          - 2\tau_t \frac{\delta u\,\Delta u}{R^2\lambda_t^2}\Big]\,dV .

Both are integrated with the reduced Gauss rule of :mod:`cavex.fem.discretisation` (``degree``
points per element, the locking-free rule) and scattered in *radial* dof order into LAPACK band
storage (``p`` sub- and super-diagonals). The inertia ``int rho_0 u'' du dV`` is the scikit-fem
mass form of :mod:`cavex.fem.forms`, assembled once.

:func:`assemble_cases` runs over a stack of disconnected cases (:class:`cavex.fem.stack.Stack`),
skipping the cases flagged ``skip`` (their outputs are left as they are); it takes the
stack's records (:mod:`cavex.fem.records`) and one material record per element
(:mod:`cavex.fem.material_records`), which it hands to the point kernel unread. A case in which some
point has a non-positive stretch is *folded*: it is flagged and evaluated at zero strain (its
Newton iteration is then abandoned by the caller). The scikit-fem forms of the same weak form
are kept in ``tests/oracles.py`` and compared with this kernel in ``tests/test_fem_kernels.py``.
"""

import math

import numpy as np
from numba import njit

from cavex.fem.constitutive import return_point
from cavex.fem.records import Assembly, Layout, PointResponse


@njit(cache=True, error_model="numpy")
def assemble_cases(u, layout, material, theta_p, gamma_p, skip, out, resp):
    """Response, internal force and banded tangent at the radial dofs ``u`` of every case ``c``
    with ``not skip[c]``, into the :class:`~cavex.fem.records.Assembly` ``out`` and the
    :class:`~cavex.fem.records.PointResponse` ``resp``.

    ``layout`` is the stack's :class:`~cavex.fem.records.Layout`, ``material`` its
    :data:`~cavex.fem.material_records.MATERIAL` record per element, ``theta_p, gamma_p`` the
    start-of-step plastic strains per point. ``out.Gr``, ``out.Gt`` (element, point) receive
    the displacement gradients ``du/dR``, ``u/R`` (zero in a folded case). ``out.f`` and
    ``out.band`` must be zero on the cases evaluated; the point response and per-case
    ``folded`` and ``force_scale`` (the largest nodal force one point contributes: Newton's
    yardstick) are written in place. Records come named or as plain tuples
    (:mod:`cavex.fem.records`, the boundary rule).
    """
    layout, out, resp = Layout(*layout), Assembly(*out), PointResponse(*resp)
    element_dofs, dNdR, N = layout.element_dofs, layout.dNdR, layout.N
    R_points, force_weights = layout.R_points, layout.force_weights
    el_start, el_count = layout.el_start, layout.el_count
    Gr, Gt = out.Gr, out.Gt
    tau_r, tau_t, plastic, yield_ratio = resp.tau_r, resp.tau_t, resp.plastic, resp.yield_ratio
    th_p_new, ga_p_new = resp.theta_p, resp.gamma_p
    folded, force_scale = out.folded, out.force_scale
    nb = element_dofs.shape[1]
    nq = R_points.shape[1]
    C = np.empty((4, nq))
    Br = np.empty((nb, nq))
    Bt = np.empty((nb, nq))
    X = np.empty((nb, nq))
    Y = np.empty((nb, nq))
    for c in range(el_start.size):
        if skip[c]:
            continue
        e0, e1 = el_start[c], el_start[c] + el_count[c]
        bad = False
        for e in range(e0, e1):
            for q in range(nq):
                g_r = 0.0
                g_t = 0.0
                for b in range(nb):
                    g_r += u[element_dofs[e, b]] * dNdR[e, b, q]
                    g_t += u[element_dofs[e, b]] * N[b, q]
                Gr[e, q] = g_r
                Gt[e, q] = g_t / R_points[e, q]
                if not (Gr[e, q] > -1.0 and Gt[e, q] > -1.0):
                    bad = True
        folded[c] = bad
        if bad:
            Gr[e0:e1] = 0.0
            Gt[e0:e1] = 0.0
        scale = 0.0
        for e in range(e0, e1):
            for q in range(nq):
                plastic[e, q], point = return_point(
                    math.log1p(Gr[e, q]), math.log1p(Gt[e, q]), theta_p[e, q], gamma_p[e, q],
                    material[e])
                tau_r[e, q] = point[0]
                tau_t[e, q] = point[1]
                C[0, q], C[1, q], C[2, q], C[3, q] = point[2], point[3], point[4], point[5]
                yield_ratio[e, q] = point[6]
                th_p_new[e, q] = point[7]
                ga_p_new[e, q] = point[8]
                s = (abs(point[0]) + 2.0 * abs(point[1])) * force_weights[e, q]
                if s > scale or s != s:
                    scale = s
            _element(e, Gr, Gt, C, tau_r, tau_t, element_dofs, dNdR, N, R_points,
                     layout.weights, layout.degree, Br, Bt, X, Y, out.f, out.band)
        force_scale[c] = scale


@njit(cache=True, error_model="numpy", inline="always")
def _element(e, Gr, Gt, C, tau_r, tau_t, element_dofs, dNdR, N, R_points, weights, p, Br, Bt,
             X, Y, f, band):
    """Add element ``e``'s internal force and tangent (module docstring) to ``f``, ``band``."""
    nb, nq = Br.shape
    for q in range(nq):
        W = weights[e, q]
        inv_r = 1.0 / (1.0 + Gr[e, q])
        inv_t = 1.0 / (R_points[e, q] * (1.0 + Gt[e, q]))
        c_rr = C[0, q] - tau_r[e, q]
        c_rt = C[1, q]
        c_tr = C[2, q]
        c_tt = C[3, q] - tau_t[e, q]
        W2 = 2.0 * W
        for b in range(nb):
            br = dNdR[e, b, q] * inv_r                     # d eps_r / d u_b
            bt = N[b, q] * inv_t                           # d eps_t / d u_b
            Br[b, q] = br
            Bt[b, q] = bt
            X[b, q] = W * (c_rr * br + c_rt * bt)
            Y[b, q] = W2 * (c_tr * br + c_tt * bt)
    for a in range(nb):
        row = element_dofs[e, a]
        fe = 0.0
        for q in range(nq):
            fe += weights[e, q] * (tau_r[e, q] * Br[a, q] + 2.0 * tau_t[e, q] * Bt[a, q])
        f[row] += fe
        for b in range(nb):
            col = element_dofs[e, b]
            k = 0.0
            for q in range(nq):
                k += Br[a, q] * X[b, q] + Bt[a, q] * Y[b, q]
            band[p + row - col, col] += k
