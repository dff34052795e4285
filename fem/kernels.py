"""Compiled (numba) point and element kernels of a stack of cases: one pass per Newton iteration.

:func:`assemble_stack` computes, case by case, what :meth:`cavex.fem.batch.Stack.respond` and
:meth:`~cavex.fem.discretisation.FastAssembly.assemble_response` compute with numpy from the
displacement gradients: the Hencky/Mohr-Coulomb return map of :mod:`cavex.fem.constitutive`
(the Mohr-Coulomb-only closed form, or the multi-surface one for every point of a case in which
some point needs it, as the numpy code decides per case), the internal force, the banded
consistent tangent, the force yardstick and the folded-element flag. Every formula is written
in the order of the numpy expression it replaces, which makes the results bit-for-bit those of
the numpy kernels (measured on whole runs, benchmarks/table.py; tests/test_throughput.py checks
1e-10). Only the quantities the batch needs are returned (no energies or dissipation).
"""

import math

import numpy as np
from numba import njit

TWO_THIRDS = 2.0 / 3.0


@njit(cache=True, error_model="numpy", inline="always")
def _finish_point(P, Q, T00, T01, T10, T11, lam, tau, J, out):
    """Stresses, tangent (into ``out[0..5]``) and yield ratio (``out[6]``) of one point."""
    out[0] = -(P + 2.0 * Q / 3.0)
    out[1] = -(P - Q / 3.0)
    a_t = -T00 - TWO_THIRDS * T10
    a_g = -T01 - TWO_THIRDS * T11
    b_t = -T00 + T10 / 3.0
    b_g = -T01 + T11 / 3.0
    out[2] = a_t + a_g
    out[3] = 2.0 * a_t - a_g
    out[4] = b_t + b_g
    out[5] = 2.0 * b_t - b_g
    c = 1.0 if Q >= 0.0 else (3.0 + lam) / 3.0
    strength = lam * P + tau * J
    out[6] = c * abs(Q) / strength if strength > 0.0 else 1.0


@njit(cache=True, error_model="numpy")
def _mc_point(theta, gamma, J, theta_p, gamma_p, K, G, lam, tau, lam_psi, tension, out):
    """Mohr-Coulomb-only return of one point; returns ``(plastic, needs_general)``; writes
    stresses, tangent, yield ratio and the new ``theta_p``, ``gamma_p`` (``out[7]``, ``out[8]``)."""
    P = -K * (theta - theta_p)
    Q = -2.0 * G * (gamma - gamma_p)
    positive = Q >= 0.0
    sign = 1.0 if positive else -1.0
    c_mc = 1.0 if positive else 1.0 + lam / 3.0
    tol = 1e-12 * tau * J
    f_mc = c_mc * sign * Q - lam * P - tau * J
    sigma_3 = P - Q / 3.0 if positive else P + 2.0 * Q / 3.0
    f_tc = -sigma_3 - tension * J
    plastic = (f_mc > tol) or (f_tc > tol)
    general = f_tc > tol
    c_psi = 1.0 if positive else 1.0 + lam_psi / 3.0
    d_P = -K * lam_psi
    d_Q = 3.0 * G * c_psi * sign
    g = -lam * d_P + c_mc * sign * d_Q
    dl = f_mc / g if plastic else 0.0
    P_new = P - dl * d_P
    Q_new = Q - dl * d_Q
    s3 = P_new - Q_new / 3.0 if Q_new >= 0.0 else P_new + 2.0 * Q_new / 3.0
    if plastic and not (-s3 - tension * J <= 1e-12 * tau * J):
        general = True
    out[7] = theta_p + dl * lam_psi
    out[8] = gamma_p - dl * 1.5 * c_psi * sign
    pl = (1.0 if plastic else 0.0) / g
    row_t = (lam * K - tau * J) * pl
    row_g = (-2.0 * G * c_mc * sign) * pl
    T00 = -K - d_P * row_t
    T01 = -d_P * row_g
    T10 = -d_Q * row_t
    T11 = -2.0 * G - d_Q * row_g
    _finish_point(P_new, Q_new, T00, T01, T10, T11, lam, tau, J, out)
    return plastic, general


@njit(cache=True, error_model="numpy")
def _general_point(theta, gamma, J, theta_p, gamma_p, K, G, lam, tau, lam_psi, tension, out):
    """Multi-surface return (Mohr-Coulomb, tension cut-off or their corner) of one point;
    returns ``plastic``; writes as :func:`_mc_point`."""
    P_tr = -K * (theta - theta_p)
    Q_tr = -2.0 * G * (gamma - gamma_p)
    sign = 1.0 if Q_tr >= 0.0 else -1.0
    pos = sign > 0
    c_mc = 1.0 if pos else (3.0 + lam) / 3.0
    c_psi = 1.0 if pos else (3.0 + lam_psi) / 3.0
    a10, a11 = -lam, c_mc * sign
    g10, g11_ = lam_psi, -1.5 * c_psi * sign
    a20, a21 = -1.0, (1.0 / 3.0 if pos else -2.0 / 3.0)
    g20, g21_ = 1.0, (-0.5 if pos else 1.0)
    d10, d11 = -K * g10, -2.0 * G * g11_
    d20, d21 = -K * g20, -2.0 * G * g21_
    f1 = (a10 * P_tr + a11 * Q_tr) - tau * J
    f2 = (a20 * P_tr + a21 * Q_tr) - tension * J
    g11 = a10 * d10 + a11 * d11
    g12 = a10 * d20 + a11 * d21
    g21 = a20 * d10 + a21 * d11
    g22 = a20 * d20 + a21 * d21
    tol = 1e-12 * tau * J
    dl1 = f1 / g11
    ok1 = (dl1 > 0) and (f2 - g21 * dl1 <= tol)
    dl2 = f2 / g22
    ok2 = (dl2 > 0) and (f1 - g12 * dl2 <= tol)
    det = g11 * g22 - g12 * g21
    c1 = (g22 * f1 - g12 * f2) / det
    c2 = (g11 * f2 - g21 * f1) / det
    elastic = (f1 <= tol) and (f2 <= tol)
    use1 = (not elastic) and ok1
    use2 = (not elastic) and (not use1) and ok2
    use3 = (not elastic) and (not use1) and (not use2)
    m1 = dl1 if use1 else (c1 if use3 else 0.0)
    m2 = dl2 if use2 else (c2 if use3 else 0.0)
    P = P_tr - m1 * d10 - m2 * d20
    Q = Q_tr - m1 * d11 - m2 * d21
    out[7] = theta_p + m1 * g10 + m2 * g20
    out[8] = gamma_p + m1 * g11_ + m2 * g21_
    E00, E11 = -K, -2.0 * G
    T00, T01, T10, T11 = E00, 0.0, 0.0, E11
    if use1 or use2:
        if use1:
            r0, r1, d0, d1, gg = a10 * E00 - tau * J, a11 * E11, d10, d11, g11
        else:
            r0, r1, d0, d1, gg = a20 * E00 - tension * J, a21 * E11, d20, d21, g22
        T00 = E00 - d0 * r0 / gg
        T01 = 0.0 - d0 * r1 / gg
        T10 = 0.0 - d1 * r0 / gg
        T11 = E11 - d1 * r1 / gg
    elif use3:
        i00, i01, i10, i11 = g22 / det, -g12 / det, -g21 / det, g11 / det
        A00, A01 = a10 * E00 - tau * J, a11 * E11
        A10, A11 = a20 * E00 - tension * J, a21 * E11
        # corr_ij = sum_kl D_ik inv_kl A_lj in numpy.einsum's order, D = [[d10, d20], [d11, d21]]
        T00 = E00 - (d10 * i00 * A00 + d10 * i01 * A10 + d20 * i10 * A00 + d20 * i11 * A10)
        T01 = 0.0 - (d10 * i00 * A01 + d10 * i01 * A11 + d20 * i10 * A01 + d20 * i11 * A11)
        T10 = 0.0 - (d11 * i00 * A00 + d11 * i01 * A10 + d21 * i10 * A00 + d21 * i11 * A10)
        T11 = E11 - (d11 * i00 * A01 + d11 * i01 * A11 + d21 * i10 * A01 + d21 * i11 * A11)
    _finish_point(P, Q, T00, T01, T10, T11, lam, tau, J, out)
    return not elastic


@njit(cache=True, error_model="numpy")
def assemble_stack(Gr, Gt, element_dofs, dNdR, N, R_points, weights, force_weights, K, G, lam,
                   tau, lam_psi, tension, theta_p, gamma_p, el_start, el_count, skip, p, f, band,
                   tau_r, tau_t, th_p_new, ga_p_new, plastic, yield_ratio, folded, force_scale):
    """Response, internal force and banded tangent of every case ``c`` with ``not skip[c]``.

    ``Gr``, ``Gt`` are the displacement gradients ``du/dR``, ``u/R`` at the points (from
    :meth:`~cavex.fem.discretisation.FastAssembly.displacement_gradients`; those of folded
    cases are overwritten by zero).

    Outputs (``f``, ``band`` zeroed by the caller; per point ``tau_r`` ... ``yield_ratio``; per
    case ``folded`` and ``force_scale``) are filled in place. Tangent components are not kept
    per point: they only enter the band.
    """
    nb = element_dofs.shape[1]
    nq = R_points.shape[1]
    out = np.empty(9)
    C = np.empty((4,) + R_points.shape)
    Br = np.empty((nb, nq))
    Bt = np.empty((nb, nq))
    X = np.empty((nb, nq))
    Y = np.empty((nb, nq))
    for c in range(el_start.size):
        if skip[c]:
            continue
        e0, e1 = el_start[c], el_start[c] + el_count[c]
        # a folded element makes the whole case evaluate at zero strain
        bad = False
        for e in range(e0, e1):
            for q in range(nq):
                if not (Gr[e, q] > -1.0 and Gt[e, q] > -1.0):
                    bad = True
        folded[c] = bad
        if bad:
            Gr[e0:e1] = 0.0
            Gt[e0:e1] = 0.0
        # return map: Mohr-Coulomb only, or multi-surface at every point of the case
        general = False
        for sweep in range(2):
            for e in range(e0, e1):
                for q in range(nq):
                    er = math.log1p(Gr[e, q])
                    et = math.log1p(Gt[e, q])
                    theta = er + 2.0 * et
                    gamma = er - et
                    J = math.exp(theta)
                    if sweep == 0:
                        pl, gen = _mc_point(theta, gamma, J, theta_p[e, q], gamma_p[e, q],
                                            K[e, q], G[e, q], lam[e, q], tau[e, q],
                                            lam_psi[e, q], tension[e, q], out)
                        general = general or gen
                    else:
                        pl = _general_point(theta, gamma, J, theta_p[e, q], gamma_p[e, q],
                                            K[e, q], G[e, q], lam[e, q], tau[e, q],
                                            lam_psi[e, q], tension[e, q], out)
                    tau_r[e, q] = out[0]
                    tau_t[e, q] = out[1]
                    for i in range(4):
                        C[i, e, q] = out[2 + i]
                    yield_ratio[e, q] = out[6]
                    th_p_new[e, q] = out[7]
                    ga_p_new[e, q] = out[8]
                    plastic[e, q] = pl
            if not general:
                break
        scale = 0.0
        for e in range(e0, e1):
            for q in range(nq):
                s = (abs(tau_r[e, q]) + 2.0 * abs(tau_t[e, q])) * force_weights[e, q]
                if s > scale or s != s:
                    scale = s
            _element(e, Gr, Gt, C, tau_r, tau_t, element_dofs, dNdR, N, R_points, weights, p,
                     Br, Bt, X, Y, f, band)
        force_scale[c] = scale


@njit(cache=True, error_model="numpy", inline="always")
def _element(e, Gr, Gt, C, tau_r, tau_t, element_dofs, dNdR, N, R_points, weights, p, Br, Bt,
             X, Y, f, band):
    """Add element ``e``'s internal force and tangent (numpy path's formulas) to ``f``, ``band``."""
    nb, nq = Br.shape
    for b in range(nb):
        for q in range(nq):
            lam_r = 1.0 + Gr[e, q]
            lam_t = 1.0 + Gt[e, q]
            Br[b, q] = dNdR[e, b, q] / lam_r
            Bt[b, q] = N[b, q] / (R_points[e, q] * lam_t)
    for b in range(nb):
        for q in range(nq):
            X[b, q] = C[0, e, q] * Br[b, q] + C[1, e, q] * Bt[b, q] - tau_r[e, q] * Br[b, q]
            Y[b, q] = C[2, e, q] * Br[b, q] + C[3, e, q] * Bt[b, q] - tau_t[e, q] * Bt[b, q]
    for a in range(nb):
        fe = 0.0
        for q in range(nq):
            W = weights[e, q]
            fe += (W * tau_r[e, q]) * Br[a, q] + (2.0 * W * tau_t[e, q]) * Bt[a, q]
        f[element_dofs[e, a]] += fe
    for a in range(nb):
        row = element_dofs[e, a]
        for b in range(nb):
            col = element_dofs[e, b]
            k1 = 0.0
            k2 = 0.0
            for q in range(nq):
                W = weights[e, q]
                k1 += (Br[a, q] * W) * X[b, q]
                k2 += (Bt[a, q] * (2.0 * W)) * Y[b, q]
            band[p + row - col, col] += k1 + k2
