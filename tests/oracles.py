"""Independent implementations kept only as test oracles for the compiled kernels of cavex.fem.

- :func:`hencky_mohr_coulomb`: the Hencky/Mohr-Coulomb return map of
  :mod:`cavex.fem.constitutive`, vectorised in numpy (masks over all points; the multi-surface
  return for every point of a group in which some point needs it), with the compaction
  hydrostat written as its loading curve in the total volumetric strain
  (:func:`compaction_hydrostat`);
- :func:`assemble_forms`: the internal force and tangent of :mod:`cavex.fem.element` assembled
  from scikit-fem ``LinearForm``/``BilinearForm``s written like the weak form, with this numpy
  return map.

Neither is used by the product; ``tests/test_fem_kernels.py`` compares them with the compiled
kernels point by point and element by element.
"""

from dataclasses import dataclass

import numpy as np
from fem_helpers import take_points, to_skfem
from skfem import BilinearForm, LinearForm, asm

from cavex.fem.discretisation import to_banded
from cavex.fem.forms import FOUR_PI


@dataclass
class PointResponse:
    """Stress, tangent and updated internal variables at the quadrature points.

    ``tau_r``, ``tau_t`` are Kirchhoff stresses, tension positive; ``tangent[i, j]`` is
    ``d tau_i / d eps_j`` for ``i, j`` in ``(r, t)``.
    """

    tau_r: np.ndarray
    tau_t: np.ndarray
    tangent: np.ndarray
    theta_p: np.ndarray
    gamma_p: np.ndarray
    plastic: np.ndarray
    dissipation: np.ndarray
    energy: np.ndarray
    yield_ratio: np.ndarray


def _surfaces(sign, mat):
    """Normals ``a``, intercepts ``k`` and flow vectors ``g`` of (MC, TC), each shape (2, ...)."""
    pos = sign > 0
    c_mc = np.where(pos, 1.0, (3.0 + mat.lam) / 3.0)
    c_psi = np.where(pos, 1.0, (3.0 + mat.lam_psi) / 3.0)
    a_mc = np.array([-mat.lam, c_mc * sign])
    g_mc = np.array([mat.lam_psi, -1.5 * c_psi * sign])
    a_tc = np.array([-np.ones_like(sign), np.where(pos, 1.0 / 3.0, -2.0 / 3.0)])
    g_tc = np.array([np.ones_like(sign), np.where(pos, -0.5, 1.0)])
    return (a_mc, mat.tau, g_mc), (a_tc, mat.tension, g_tc)


def compaction_hydrostat(theta, theta_p, mat):
    """``(P, K_t, theta_p)``: the trial Kirchhoff pressure, its tangent ``dP/de`` and the
    plastic volumetric strain after compaction, written from the loading curve.

    With ``e = -theta`` (log volumetric strain, compression positive), ``e_c = -theta_p`` and
    the crush strain ``e_0 = P_c/K``, the loading curve is ``H(e) = P_c + K_c (e - e_0)``,
    ``K_c = (P_l - P_c)/(e_l - e_0)``, up to ``e_l``, then ``P_l + K_l (e - e_l)``. A point
    unloaded to ``e_c`` crushes again where the elastic line ``K (e - e_c)`` meets ``H``
    (``e_c <= 0``: at ``P_c``, the opened volume ``-e_c`` closing at the crush pressure while
    ``e <= e_0``). Fully compacted (``e_c >= e_l - P_l/K``): elastic ``K x``, ``x = e - e_c``,
    up to ``x_l = P_l/K``, then ``P_l + K_l (x - x_l)``. No hydrostat (``crush = inf``): the
    linear ``K (e - e_c)``.
    """
    K = mat.K
    e, e_c = -theta, -theta_p
    x = e - e_c
    linear = K * x
    has = np.isfinite(mat.crush)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        P_c, P_l, e_l, K_l = mat.crush, mat.lock_pressure, mat.lock_strain, mat.locked_modulus
        e_0 = P_c / K
        K_c = (P_l - P_c) / (e_l - e_0)
        x_l = P_l / K
        e_c_lock = e_l - x_l
        full = has & (e_c >= e_c_lock)
        # where the elastic line of e_c meets the loading curve (the crush point now)
        e_meet = e_0 + np.maximum(e_c, 0.0) * K / (K - K_c)
        crushes = has & ~full & (linear > P_c + K_c * (e_meet - e_0))
        plateau = crushes & (e <= e_0)
        locks = crushes & ~plateau & (e >= e_l)
        compacts = crushes & ~plateau & ~locks
        P = np.where(full & (x > x_l), P_l + K_l * (x - x_l), linear)
        K_t = np.where(full & (x > x_l), K_l, K)
        P = np.where(plateau, P_c, P)
        P = np.where(compacts, P_c + K_c * (e - e_0), P)
        P = np.where(locks, P_l + K_l * (e - e_l), P)
        K_t = np.where(plateau, 0.0, np.where(compacts, K_c, np.where(locks, K_l, K_t)))
        new_e_c = np.where(plateau, e - e_0, np.where(compacts, e - P / K,
                                                      np.where(locks, e_c_lock, e_c)))
    return P, K_t, -new_e_c


def hencky_mohr_coulomb(eps_r, eps_t, theta_p, gamma_p, mat, groups=None):
    """Return-map the trial state; see the module docstring for the equations solved.

    Parameters
    ----------
    eps_r, eps_t : ndarray
        Total logarithmic strains at the points.
    theta_p, gamma_p : ndarray
        Plastic volumetric and deviatoric log strains at the start of the step.
    mat : record array of :data:`cavex.fem.material_records.MATERIAL`
        Broadcast to the points, with attribute access (``mat.K``).
    groups : ndarray of int, optional
        Group (independent model, e.g. one case of a batch) of every point. The Mohr-Coulomb-
        only return is used for all points unless some point needs the multi-surface one;
        that choice is made per group, so each group gets exactly the arithmetic it would get
        if it were return-mapped alone. None: all points form one group.

    Returns
    -------
    PointResponse
    """
    theta = eps_r + 2.0 * eps_t
    gamma = eps_r - eps_t
    J = np.exp(theta)
    G = mat.G
    P, K, compacted_theta_p = compaction_hydrostat(theta, theta_p, mat)
    compacted = compacted_theta_p != theta_p
    theta_p = compacted_theta_p
    Q = -2.0 * G * (gamma - gamma_p)
    positive = Q >= 0.0
    sign = np.where(positive, 1.0, -1.0)
    c_mc = np.where(positive, 1.0, 1.0 + mat.lam / 3.0)
    tol = 1e-12 * mat.tau * J
    f_mc = c_mc * sign * Q - mat.lam * P - mat.tau * J
    with np.errstate(invalid="ignore"):
        sigma_3 = np.where(positive, P - Q / 3.0, P + 2.0 * Q / 3.0)
        f_tc = -sigma_3 - mat.tension * J
    plastic = (f_mc > tol) | (f_tc > tol)
    general = f_tc > tol
    if groups is None and np.any(general):
        return _general_return(P, K, gamma, J, theta_p, gamma_p, mat, compacted)
    # Mohr-Coulomb alone (tension cut-off inactive everywhere): one multiplier per point
    c_psi = np.where(positive, 1.0, 1.0 + mat.lam_psi / 3.0)
    d_P, d_Q = -K * mat.lam_psi, 3.0 * G * c_psi * sign          # stress correction direction
    g = -mat.lam * d_P + c_mc * sign * d_Q                       # a . d
    dl = np.where(plastic, f_mc / g, 0.0)
    P_new = P - dl * d_P
    Q_new = Q - dl * d_Q
    trial_ok = _tension_ok(P_new, Q_new, J, mat)
    general |= plastic & ~trial_ok
    if groups is None and np.any(general):
        return _general_return(P, K, gamma, J, theta_p, gamma_p, mat, compacted)
    th_p = theta_p + dl * mat.lam_psi
    ga_p = gamma_p - dl * 1.5 * c_psi * sign
    # tangent d(P, Q)/d(theta, gamma): E - d (a^T E - k J e_theta^T) / g on plastic points
    pl = plastic / g
    row_t = (mat.lam * K - mat.tau * J) * pl
    row_g = (-2.0 * G * c_mc * sign) * pl
    T = np.array([[-K - d_P * row_t, -d_P * row_g], [-d_Q * row_t, -2.0 * G - d_Q * row_g]])
    response = _finish(theta, gamma, theta_p, gamma_p, th_p, ga_p, P_new, Q_new, T,
                       plastic | compacted, J, mat)
    if groups is not None and np.any(general):
        redo = np.isin(groups, np.unique(groups[general]))
        replace_points(response, redo, _general_return(P[redo], K[redo], gamma[redo], J[redo],
                                                       theta_p[redo], gamma_p[redo],
                                                       take_points(mat, redo),
                                                       compacted[redo]))
    return response


def replace_points(response, where, other):
    """Overwrite ``response`` at the points ``where`` (boolean or indices) by ``other``."""
    for name, value in vars(response).items():
        if name == "tangent":
            value[:, :, where] = other.tangent
        else:
            value[where] = getattr(other, name)


def _tension_ok(P, Q, J, mat):
    with np.errstate(invalid="ignore"):
        sigma_3 = np.where(Q >= 0.0, P - Q / 3.0, P + 2.0 * Q / 3.0)
        return -sigma_3 - mat.tension * J <= 1e-12 * mat.tau * J


def _finish(theta, gamma, theta_p, gamma_p, th_p, ga_p, P, Q, T, plastic, J, mat):
    """Principal Kirchhoff stresses, tangent in (eps_r, eps_t), energies, yield ratio."""
    K, G = mat.K, mat.G
    tau_r = -(P + 2.0 * Q / 3.0)
    tau_t = -(P - Q / 3.0)
    # d tau / d eps = TO_TAU . T . TO_INVARIANTS, written out
    a_t = -T[0, 0] - (2.0 / 3.0) * T[1, 0]
    a_g = -T[0, 1] - (2.0 / 3.0) * T[1, 1]
    b_t = -T[0, 0] + T[1, 0] / 3.0
    b_g = -T[0, 1] + T[1, 1] / 3.0
    tangent = np.array([[a_t + a_g, 2.0 * a_t - a_g], [b_t + b_g, 2.0 * b_t - b_g]])
    dissipation = -P * (th_p - theta_p) - (2.0 / 3.0) * Q * (ga_p - gamma_p)
    energy = 0.5 * K * (theta - th_p) ** 2 + (2.0 / 3.0) * G * (gamma - ga_p) ** 2
    c_mc = np.where(Q >= 0.0, 1.0, (3.0 + mat.lam) / 3.0)
    strength = mat.lam * P + mat.tau * J
    with np.errstate(divide="ignore", invalid="ignore"):
        yield_ratio = np.where(strength > 0.0, c_mc * np.abs(Q) / strength, 1.0)
    return PointResponse(tau_r=tau_r, tau_t=tau_t, tangent=tangent, theta_p=th_p,
                         gamma_p=ga_p, plastic=plastic, dissipation=dissipation,
                         energy=energy, yield_ratio=yield_ratio)


def _general_return(P_tr, K, gamma, J, theta_p, gamma_p, mat, compacted):
    """Multi-surface return (Mohr-Coulomb, tension cut-off, or their corner) from the trial
    pressure ``P_tr`` (tangent ``K``)."""
    G = mat.G
    theta = np.log(J)
    Q_tr = -2.0 * G * (gamma - gamma_p)
    sign = np.where(Q_tr >= 0.0, 1.0, -1.0)
    (a1, k1, g1), (a2, k2, g2) = _surfaces(sign, mat)
    d1 = np.array([-K * g1[0], -2.0 * G * g1[1]])
    d2 = np.array([-K * g2[0], -2.0 * G * g2[1]])
    s_tr = np.array([P_tr, Q_tr])
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        f1 = (a1 * s_tr).sum(0) - k1 * J
        f2 = (a2 * s_tr).sum(0) - k2 * J
        g11, g12 = (a1 * d1).sum(0), (a1 * d2).sum(0)
        g21, g22 = (a2 * d1).sum(0), (a2 * d2).sum(0)
        tol = 1e-12 * mat.tau * J
        dl1 = f1 / g11
        ok1 = (dl1 > 0) & (f2 - g21 * dl1 <= tol)
        dl2 = f2 / g22
        ok2 = (dl2 > 0) & (f1 - g12 * dl2 <= tol)
        det = g11 * g22 - g12 * g21
        c1 = (g22 * f1 - g12 * f2) / det
        c2 = (g11 * f2 - g21 * f1) / det
    elastic = (f1 <= tol) & (f2 <= tol)
    use1 = ~elastic & ok1
    use2 = ~elastic & ~use1 & ok2
    use3 = ~elastic & ~use1 & ~use2
    z = np.zeros_like(theta)
    m1 = np.where(use1, dl1, np.where(use3, c1, z))
    m2 = np.where(use2, dl2, np.where(use3, c2, z))
    P = P_tr - m1 * d1[0] - m2 * d2[0]
    Q = Q_tr - m1 * d1[1] - m2 * d2[1]
    th_p = theta_p + m1 * g1[0] + m2 * g2[0]
    ga_p = gamma_p + m1 * g1[1] + m2 * g2[1]
    E = np.array([[-K, z], [z, -2.0 * G]])
    T = E.copy()
    for mask, a, k, d, g in ((use1, a1, k1, d1, g11), (use2, a2, k2, d2, g22)):
        row = np.array([a[0] * E[0, 0] - k * J, a[1] * E[1, 1]])
        with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
            corr = d[:, None] * row[None, :] / g
        T = np.where(mask, E - corr, T)
    if np.any(use3):
        with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
            inv = np.array([[g22, -g12], [-g21, g11]]) / det
            A = np.array([[a1[0] * E[0, 0] - k1 * J, a1[1] * E[1, 1]],
                          [a2[0] * E[0, 0] - k2 * J, a2[1] * E[1, 1]]])
            D = np.array([[d1[0], d2[0]], [d1[1], d2[1]]])
            corr = np.einsum("ik...,kl...,lj...->ij...", D, inv, A)
        T = np.where(use3, E - corr, T)
    return _finish(theta, gamma, theta_p, gamma_p, th_p, ga_p, P, Q, T, ~elastic | compacted, J,
                   mat)


# ----------------------------------------------------------------------------- the weak form
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


def assemble_forms(disc, u, theta_p, gamma_p):
    """``(f, band, response)`` at the radial dofs ``u`` from the scikit-fem forms and the
    numpy return map (radial dof order, LAPACK band storage)."""
    field = disc.basis.interpolate(to_skfem(disc, u))
    g_r, g_t = field.grad[0], np.asarray(field) / disc.R_points
    # one material record per element, at every point
    points = np.broadcast_to(disc.material[:, None], g_r.shape).view(np.recarray)
    resp = hencky_mohr_coulomb(np.log1p(g_r), np.log1p(g_t), theta_p, gamma_p, points)
    fields = {"lam_r": 1.0 + g_r, "lam_t": 1.0 + g_t, "tau_r": resp.tau_r, "tau_t": resp.tau_t}
    f = np.empty(disc.ndof)
    f[disc.radial] = asm(internal_force, disc.basis, **fields)
    C = resp.tangent
    K = asm(tangent, disc.basis, C_rr=C[0, 0], C_rt=C[0, 1], C_tr=C[1, 0], C_tt=C[1, 1],
            **fields)
    order = np.argsort(disc.radial)
    return f, to_banded(K[order][:, order], disc.degree), resp
