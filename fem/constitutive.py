r"""Hencky elasticity with Mohr-Coulomb perfect plasticity and a tension cut-off.

Spherical symmetry keeps the principal axes fixed (``r``, ``theta = phi``), so the finite-strain
return map is exact in principal logarithmic strains. Per quadrature point the total log strains
``eps_r = ln lambda_r`` and ``eps_t = ln lambda_t`` are written as

.. math:: \theta = \varepsilon_r + 2\varepsilon_t \quad(\ln J), \qquad
          \gamma = \varepsilon_r - \varepsilon_t ,

with plastic parts ``theta_p``, ``gamma_p``. The Hencky energy per reference volume is
``psi = K theta_e^2 / 2 + (2/3) G gamma_e^2`` and, compression positive, the Kirchhoff mean and
deviator are

.. math:: P = -K(\theta - \theta_p), \qquad Q = \tau_r^c - \tau_\theta^c = -2G(\gamma - \gamma_p).

Yield is written on the Cauchy stress ``sigma = tau/J`` (``J = exp(theta)``), i.e. on
Kirchhoff stress with the intercepts scaled by ``J``. With ``s = sign(Q)``:

- Mohr-Coulomb, the paper's ``sigma_r - sigma_theta = lam sigma + tau`` for ``s > 0`` and the
  same Mohr-Coulomb cone (``sigma_1 = N_phi sigma_3 + sigma_c``) on the extension side,
  ``f_MC = c_s |Q| - lam P - tau J`` with ``c_+ = 1``, ``c_- = (3 + lam)/3``;
- tension cut-off on the least compressive principal stress ``sigma_3 >= -T``:
  ``f_TC = -sigma_3 - T J`` with ``sigma_3 = P - Q/3`` (``s > 0``) or ``P + 2Q/3`` (``s < 0``).
  The default ``T = tau/lam`` puts it through the cone's apex (no cut-off for Tresca).

Flow: Mohr-Coulomb is non-associated with plastic potential ``g = c_s(psi)|Q| - lam_psi P``
(``lam_psi = 6 sin psi / (3 - sin psi)`` from the dilatancy angle ``psi``; zero by default, i.e.
volume-preserving plastic strain); the cut-off is associated (Rankine). With multipliers
``dl_k >= 0`` the plastic strain increments are ``(d theta_p, d gamma_p) = sum_k dl_k g_k`` with
``g_MC = (lam_psi, -3/2 c_s(psi) s)``, ``g_TC = (1, -1/2)`` (``s > 0``) or ``(1, 1)`` (``s < 0``).
Because elasticity is linear in log strain and the surfaces are linear in ``(P, Q)``, the
backward-Euler return solves, for the active set ``A`` (one surface or the corner),

.. math:: \sigma = \sigma^{tr} - \sum_{l\in A} \Delta\lambda_l\, d_l, \qquad
          f_k(\sigma) = f_k(\sigma^{tr}) - \sum_{l\in A} (a_k\cdot d_l)\,\Delta\lambda_l = 0,
          \quad k \in A,

with ``sigma = (P, Q)``, ``f_k = a_k . sigma - k_k J``, ``d_l = (-K g_l[0], -2G g_l[1])``. It is
linear, so solved in closed form; the consistent tangent is its exact derivative
``d sigma / d(theta, gamma) = E - D G^{-1} (A E - k J e_theta^T)``, ``E = diag(-K, -2G)``.
"""

from dataclasses import dataclass

import numpy as np

# (theta, gamma) = TO_INVARIANTS @ (eps_r, eps_t)
TO_INVARIANTS = np.array([[1.0, 2.0], [1.0, -1.0]])


@dataclass
class PointMaterial:
    """Material constants broadcast to the quadrature points (arrays of one shape)."""

    K: np.ndarray
    G: np.ndarray
    lam: np.ndarray
    tau: np.ndarray
    lam_psi: np.ndarray
    tension: np.ndarray

    @classmethod
    def from_layers(cls, layers, layer_of_point, dilatancy_deg=0.0, tension_cutoff=None):
        """Constants at points whose layer index is ``layer_of_point`` (int array).

        ``tension_cutoff`` is ``None`` (through the apex, ``tau/lam``), a number (Pa) applied to
        every layer, or a sequence with one value per layer.
        """
        pick = np.asarray(layer_of_point)

        def per_layer(values):
            return np.asarray(values, dtype=float)[pick]

        if tension_cutoff is None:
            cut = [m.tau / m.lam if m.lam > 0 else np.inf for m in layers]
        elif np.ndim(tension_cutoff) == 0:
            cut = [float(tension_cutoff)] * len(layers)
        else:
            cut = list(tension_cutoff)
        sin_psi = np.sin(np.radians(dilatancy_deg))
        lam_psi = 6.0 * sin_psi / (3.0 - sin_psi)
        return cls(K=per_layer([m.bulk_modulus for m in layers]),
                   G=per_layer([m.shear_modulus for m in layers]),
                   lam=per_layer([m.lam for m in layers]),
                   tau=per_layer([m.tau for m in layers]),
                   lam_psi=np.full(pick.shape, lam_psi),
                   tension=per_layer(cut))

    def take(self, index):
        """The constants at ``index`` (anything that indexes the point arrays)."""
        return PointMaterial(**{name: value[index] for name, value in vars(self).items()})


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


def hencky_mohr_coulomb(eps_r, eps_t, theta_p, gamma_p, mat, groups=None):
    """Return-map the trial state; see the module docstring for the equations solved.

    Parameters
    ----------
    eps_r, eps_t : ndarray
        Total logarithmic strains at the points.
    theta_p, gamma_p : ndarray
        Plastic volumetric and deviatoric log strains at the start of the step.
    mat : PointMaterial
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
    K, G = mat.K, mat.G
    P = -K * (theta - theta_p)
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
        return _general_return(theta, gamma, J, theta_p, gamma_p, mat)
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
        return _general_return(theta, gamma, J, theta_p, gamma_p, mat)
    th_p = theta_p + dl * mat.lam_psi
    ga_p = gamma_p - dl * 1.5 * c_psi * sign
    # tangent d(P, Q)/d(theta, gamma): E - d (a^T E - k J e_theta^T) / g on plastic points
    pl = plastic / g
    row_t = (mat.lam * K - mat.tau * J) * pl
    row_g = (-2.0 * G * c_mc * sign) * pl
    T = np.array([[-K - d_P * row_t, -d_P * row_g], [-d_Q * row_t, -2.0 * G - d_Q * row_g]])
    response = _finish(theta, gamma, theta_p, gamma_p, th_p, ga_p, P_new, Q_new, T, plastic, J,
                       mat)
    if groups is not None and np.any(general):
        redo = np.isin(groups, np.unique(groups[general]))
        replace_points(response, redo, _general_return(theta[redo], gamma[redo], J[redo],
                                                       theta_p[redo], gamma_p[redo],
                                                       mat.take(redo)))
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


def _general_return(theta, gamma, J, theta_p, gamma_p, mat):
    """Multi-surface return (Mohr-Coulomb, tension cut-off, or their corner)."""
    K, G = mat.K, mat.G
    P_tr = -K * (theta - theta_p)
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
    return _finish(theta, gamma, theta_p, gamma_p, th_p, ga_p, P, Q, T, ~elastic, J, mat)


def equivalent_plastic_strain(gamma_p, theta_p):
    """``sqrt(2/3 eps_p : eps_p)`` of the plastic log strain (deviatoric and volumetric parts)."""
    return np.sqrt((2.0 / 3.0) * ((2.0 / 3.0) * gamma_p ** 2 + theta_p ** 2 / 3.0))
