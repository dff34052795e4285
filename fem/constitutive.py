r"""Hencky elasticity with Mohr-Coulomb perfect plasticity, a Tresca cap and a tension cut-off.

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
  The default ``T = tau/lam`` puts it through the cone's apex (no cut-off for Tresca);
  a layer's ``tensile_strength`` (concrete's ``f_t``) replaces it in that layer;
- Tresca cap (concrete, Forrestal and Tzou 1997) on the principal stress difference,
  ``f_cap = |Q| - tau_max J`` (``c = 1`` on both sides), associated (``g_cap = (0, -3/2 s)``:
  volume-preserving, along ``Q`` at fixed ``P``), so that the strength is
  ``|sigma_r - sigma_theta| <= min(lam sigma + tau, tau_max)``; ``tau_max = inf`` (the default)
  is no cap.

Compaction (a layer's hydrostat, :data:`cavex.materials.HYDROSTAT`; Holmquist, Johnson and
Cook 1993, "HJC", in the kernel's measures): with the log volumetric strain ``e = -theta``
(compression positive) the Kirchhoff pressure on loading is the piecewise-linear curve

.. math:: H(e) = K e \ (e \le e_0 = P_c/K), \qquad
          P_c + K_c (e - e_0) \ (e_0 \le e \le e_l), \qquad
          P_l + K_l (e - e_l) \ (e \ge e_l),

``K_c = (P_l - P_c)/(e_l - e_0) < K``: elastic to the crush pressure ``P_c``, compaction to the
lock point ``(e_l, P_l)``, then locked (``K_l``); continuous at the crush and lock points.
Compaction is irreversible, written as volumetric plasticity whose hardening variable is the
plastic volumetric strain ``theta_p`` (the cap models' rule): ``e_c = -theta_p`` is the net
compaction, the elastic strain ``x = e - e_c = theta_p - theta`` gives ``P = K x``, and the crush
surface ``P <= P_c + h max(e_c, 0)``, ``h = K K_c/(K - K_c)``, is the loading curve seen from
the elastic line (a point unloaded from ``H(e_max)`` unloads and reloads elastically with ``K``
and crushes again on ``H`` at ``e_max``). Return (:func:`hydrostat`), for ``P_tr = K x_tr > `` the
crush surface: a crack opening ``theta_p > 0`` (left by the tension cut-off) first closes at the
crush pressure (``P = P_c``, tangent 0, while ``P_tr - K theta_p <= P_c``: on loading ``P =
H(e)`` again once it is closed, whatever the opening was); then ``dl = theta_p^+ + (P_tr - K
theta_p^+ - P_c - h max(e_c, 0))/(K + h)``, ``theta_p -= dl``, ``P = P_tr - K dl = H(e)``
(tangent ``K_c``); past full compaction ``e_c^l = e_l - P_l/K`` the point is locked: ``theta_p =
-e_c^l`` and ``P = P_l + K_l (x - P_l/K)`` for ``x > P_l/K`` (tangent ``K_l``), elastic ``K x``
below (the locked branch is reversible). The deviatoric returns below then act at the
hydrostat's pressure and tangent (``P_tr``, ``K`` replaced by ``K_t``): exact where no volume
flows plastically through them (dilatancy 0 and the cut-off inactive: every point of the
cavity's comminuted zone); where the cut-off or dilatancy moves ``theta_p`` the volumetric
correction runs along that piece's modulus (an operator split). Without a hydrostat (``crush
= inf``) the pressure is ``-K (theta - theta_p)``, the same arithmetic as before.

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

Implementation: one compiled (numba) kernel per point, :func:`return_point`, used by the element
loop of :mod:`cavex.fem.element` for every case, with the element's material record
(:mod:`cavex.fem.material_records`). It tries the Mohr-Coulomb-only return first (one
multiplier, the common case) and falls back, for that point only, to the multi-surface return
when the trial state or the Mohr-Coulomb-returned one violates the tension cut-off. With a
finite cap, a point whose trial or returned deviator exceeds ``tau_max J`` is returned again
from its trial state by the three-surface return :func:`_capped_point` (the active set, one
surface or a corner of two, the first of MC, cap, TC, MC+cap, MC+TC, cap+TC with positive
multipliers that violates no other surface; the same closed-form solve and tangent). Without a
cap (``inf``) those tests are false and every point takes the code path above, bit for bit.
An independent numpy implementation of the same equations (the hydrostat written from its
loading curve in the total strain) is kept in ``tests/oracles.py`` and compared with this
kernel point by point (``tests/test_fem_kernels.py``, which also drives a point along
hydrostatic and uniaxial-strain paths against the exact hydrostat).
"""


import math

import numpy as np
from numba import njit

TWO_THIRDS = 2.0 / 3.0
NO_OUTPUTS = (0.0,) * 9  # the outputs of a return that hands over to another
#: Per-point outputs of :func:`return_point`, in order (``out[i]``).
OUTPUTS = ("tau_r", "tau_t", "C_rr", "C_rt", "C_tr", "C_tt", "yield_ratio", "theta_p",
           "gamma_p")


@njit(cache=True, error_model="numpy", inline="always")
def _finish_point(P, Q, T00, T01, T10, T11, lam, tau, J, theta_p, gamma_p):
    """The point's :data:`OUTPUTS`: Kirchhoff stresses ``tau_r, tau_t`` (tension positive),
    the tangent ``d tau_i / d eps_j`` (from ``T = d(P, Q)/d(theta, gamma)``), the yield ratio
    (deviator over strength) and the plastic strains ``theta_p, gamma_p`` (given)."""
    a_t = -T00 - TWO_THIRDS * T10
    a_g = -T01 - TWO_THIRDS * T11
    b_t = -T00 + T10 / 3.0
    b_g = -T01 + T11 / 3.0
    c = 1.0 if Q >= 0.0 else (3.0 + lam) / 3.0
    strength = lam * P + tau * J
    return (-(P + 2.0 * Q / 3.0), -(P - Q / 3.0), a_t + a_g, 2.0 * a_t - a_g, b_t + b_g,
            2.0 * b_t - b_g, c * abs(Q) / strength if strength > 0.0 else 1.0, theta_p,
            gamma_p)


@njit(cache=True, error_model="numpy", inline="always")
def _mohr_coulomb_point(P_tr, gamma, J, theta_p, gamma_p, K, G, lam, tau, lam_psi, tension):
    """Mohr-Coulomb-only return from the trial pressure ``P_tr`` (:func:`hydrostat`; ``K`` its
    tangent); returns ``(plastic, needs_multi_surface, outputs)`` (:data:`OUTPUTS`; not to be
    used when the multi-surface return is needed)."""
    P = P_tr
    Q = -2.0 * G * (gamma - gamma_p)
    positive = Q >= 0.0
    sign = 1.0 if positive else -1.0
    c_mc = 1.0 if positive else 1.0 + lam / 3.0
    tol = 1e-12 * tau * J
    f_mc = c_mc * sign * Q - lam * P - tau * J
    sigma_3 = P - Q / 3.0 if positive else P + 2.0 * Q / 3.0
    f_tc = -sigma_3 - tension * J
    plastic = (f_mc > tol) or (f_tc > tol)
    if f_tc > tol:
        return plastic, True, NO_OUTPUTS
    c_psi = 1.0 if positive else 1.0 + lam_psi / 3.0
    d_P = -K * lam_psi                      # stress correction direction d = (d_P, d_Q)
    d_Q = 3.0 * G * c_psi * sign
    g = -lam * d_P + c_mc * sign * d_Q      # a . d
    dl = f_mc / g if plastic else 0.0
    P_new = P - dl * d_P
    Q_new = Q - dl * d_Q
    s3 = P_new - Q_new / 3.0 if Q_new >= 0.0 else P_new + 2.0 * Q_new / 3.0
    if plastic and not (-s3 - tension * J <= 1e-12 * tau * J):
        return plastic, True, NO_OUTPUTS
    # tangent d(P, Q)/d(theta, gamma) = E - d (a^T E - k J e_theta^T) / g on plastic points
    pl = (1.0 if plastic else 0.0) / g
    row_t = (lam * K - tau * J) * pl
    row_g = (-2.0 * G * c_mc * sign) * pl
    return plastic, False, _finish_point(P_new, Q_new, -K - d_P * row_t, -d_P * row_g,
                                         -d_Q * row_t, -2.0 * G - d_Q * row_g, lam, tau, J,
                                         theta_p + dl * lam_psi,
                                         gamma_p - dl * 1.5 * c_psi * sign)


@njit(cache=True, error_model="numpy")
def _trial(P_tr, gamma, gamma_p, G, lam, lam_psi):
    """The trial state ``(P, Q)`` (``P_tr`` given: :func:`hydrostat`) and the side of the
    Mohr-Coulomb pyramid it lies on:
    ``pos`` (``Q >= 0``: compression-dominated branch), its ``sign`` and the yield and flow
    coefficients ``c_mc``, ``c_psi`` of that side (shared by every return)."""
    Q_tr = -2.0 * G * (gamma - gamma_p)
    pos = Q_tr >= 0.0
    sign = 1.0 if pos else -1.0
    c_mc = 1.0 if pos else (3.0 + lam) / 3.0
    c_psi = 1.0 if pos else (3.0 + lam_psi) / 3.0
    return P_tr, Q_tr, pos, sign, c_mc, c_psi


@njit(cache=True, error_model="numpy")
def _multi_surface_point(P_tr, gamma, J, theta_p, gamma_p, K, G, lam, tau, lam_psi, tension):
    """Multi-surface return (Mohr-Coulomb, tension cut-off or their corner); returns
    ``(plastic, outputs)``."""
    P_tr, Q_tr, pos, sign, c_mc, c_psi = _trial(P_tr, gamma, gamma_p, G, lam, lam_psi)
    # surface normals a_k, flow vectors g_k and stress corrections d_k = E g_k
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
    elastic = (f1 <= tol) and (f2 <= tol)
    m1 = m2 = 0.0
    E00, E11 = -K, -2.0 * G
    T00, T01, T10, T11 = E00, 0.0, 0.0, E11
    dl1 = f1 / g11
    dl2 = f2 / g22
    if not elastic and dl1 > 0 and f2 - g21 * dl1 <= tol:          # Mohr-Coulomb alone
        m1 = dl1
        r0, r1 = a10 * E00 - tau * J, a11 * E11
        T00, T01, T10, T11 = E00 - d10 * r0 / g11, -d10 * r1 / g11, -d11 * r0 / g11, \
            E11 - d11 * r1 / g11
    elif not elastic and dl2 > 0 and f1 - g12 * dl2 <= tol:        # tension cut-off alone
        m2 = dl2
        r0, r1 = a20 * E00 - tension * J, a21 * E11
        T00, T01, T10, T11 = E00 - d20 * r0 / g22, -d20 * r1 / g22, -d21 * r0 / g22, \
            E11 - d21 * r1 / g22
    elif not elastic:                                                # the corner
        det = g11 * g22 - g12 * g21
        m1 = (g22 * f1 - g12 * f2) / det
        m2 = (g11 * f2 - g21 * f1) / det
        i00, i01, i10, i11 = g22 / det, -g12 / det, -g21 / det, g11 / det
        A00, A01 = a10 * E00 - tau * J, a11 * E11
        A10, A11 = a20 * E00 - tension * J, a21 * E11
        # T = E - D G^-1 A with D = [[d10, d20], [d11, d21]]
        T00 = E00 - (d10 * (i00 * A00 + i01 * A10) + d20 * (i10 * A00 + i11 * A10))
        T01 = -(d10 * (i00 * A01 + i01 * A11) + d20 * (i10 * A01 + i11 * A11))
        T10 = -(d11 * (i00 * A00 + i01 * A10) + d21 * (i10 * A00 + i11 * A10))
        T11 = E11 - (d11 * (i00 * A01 + i01 * A11) + d21 * (i10 * A01 + i11 * A11))
    return not elastic, _finish_point(P_tr - m1 * d10 - m2 * d20, Q_tr - m1 * d11 - m2 * d21,
                                      T00, T01, T10, T11, lam, tau, J,
                                      theta_p + m1 * g10 + m2 * g20,
                                      gamma_p + m1 * g11_ + m2 * g21_)


@njit(cache=True, error_model="numpy")
def _capped_point(P_tr, gamma, J, theta_p, gamma_p, K, G, lam, tau, lam_psi, tension, cap):
    """Three-surface return (Mohr-Coulomb, Tresca cap, tension cut-off; one surface or a
    corner of two) from the trial state; returns ``(plastic, outputs)``.

    The active set is the first of MC, cap, TC, MC+cap, MC+TC, cap+TC (single surfaces only
    where the trial state violates them) whose multipliers are positive and whose returned
    state violates no other surface (within ``1e-12 tau J``); if round-off leaves none
    admissible, the one with the smallest violation.
    """
    P_tr, Q_tr, pos, sign, c_mc, c_psi = _trial(P_tr, gamma, gamma_p, G, lam, lam_psi)
    # surfaces k = 0 (MC), 1 (cap), 2 (TC): f_k = a0[k] P + a1[k] Q - k_k J, flow g_k
    a0 = (-lam, 0.0, -1.0)
    a1 = (c_mc * sign, sign, 1.0 / 3.0 if pos else -2.0 / 3.0)
    kJ = (tau * J, cap * J, tension * J)
    g0 = (lam_psi, 0.0, 1.0)
    g1 = (-1.5 * c_psi * sign, -1.5 * sign, -0.5 if pos else 1.0)
    d0 = (-K * g0[0], -K * g0[1], -K * g0[2])
    d1 = (-2.0 * G * g1[0], -2.0 * G * g1[1], -2.0 * G * g1[2])
    f = (a0[0] * P_tr + a1[0] * Q_tr - kJ[0], a0[1] * P_tr + a1[1] * Q_tr - kJ[1],
         a0[2] * P_tr + a1[2] * Q_tr - kJ[2])
    tol = 1e-12 * tau * J
    E00, E11 = -K, -2.0 * G
    T00, T01, T10, T11 = E00, 0.0, 0.0, E11
    m = (0.0, 0.0, 0.0)
    elastic = f[0] <= tol and f[1] <= tol and f[2] <= tol
    if not elastic:
        best = np.inf
        for s in range(6):
            i = s if s < 3 else (0 if s < 5 else 1)
            j = -1 if s < 3 else (1 if s == 3 else 2)
            if j < 0 and not f[i] > tol:
                continue
            Gii = a0[i] * d0[i] + a1[i] * d1[i]
            if j < 0:
                li, lj = f[i] / Gii, 0.0
                j = i  # no second surface: its multiplier is zero
            else:
                Gij = a0[i] * d0[j] + a1[i] * d1[j]
                Gji = a0[j] * d0[i] + a1[j] * d1[i]
                Gjj = a0[j] * d0[j] + a1[j] * d1[j]
                det = Gii * Gjj - Gij * Gji
                li = (Gjj * f[i] - Gij * f[j]) / det
                lj = (Gii * f[j] - Gji * f[i]) / det
            dP = li * d0[i] + lj * d0[j] if j != i else li * d0[i]
            dQ = li * d1[i] + lj * d1[j] if j != i else li * d1[i]
            P = P_tr - dP
            Q = Q_tr - dQ
            worst = max(-li, -lj)
            for k in range(3):
                worst = max(worst, a0[k] * P + a1[k] * Q - kJ[k])
            if not worst < best:          # NaN (a singular corner) or no better
                continue
            best = worst
            second = lj if j != i else 0.0
            m = ((li if i == 0 else 0.0) + (second if j == 0 else 0.0),
                 (li if i == 1 else 0.0) + (second if j == 1 else 0.0),
                 (li if i == 2 else 0.0) + (second if j == 2 else 0.0))
            # tangent T = E - D G^-1 (A E - k J e_theta^T) over the active set
            r_i0, r_i1 = a0[i] * E00 - kJ[i], a1[i] * E11
            if j == i:
                T00 = E00 - d0[i] * r_i0 / Gii
                T01 = -d0[i] * r_i1 / Gii
                T10 = -d1[i] * r_i0 / Gii
                T11 = E11 - d1[i] * r_i1 / Gii
            else:
                r_j0, r_j1 = a0[j] * E00 - kJ[j], a1[j] * E11
                i00, i01, i10, i11 = Gjj / det, -Gij / det, -Gji / det, Gii / det
                x0, x1 = i00 * r_i0 + i01 * r_j0, i00 * r_i1 + i01 * r_j1
                y0, y1 = i10 * r_i0 + i11 * r_j0, i10 * r_i1 + i11 * r_j1
                T00 = E00 - (d0[i] * x0 + d0[j] * y0)
                T01 = -(d0[i] * x1 + d0[j] * y1)
                T10 = -(d1[i] * x0 + d1[j] * y0)
                T11 = E11 - (d1[i] * x1 + d1[j] * y1)
            if worst <= tol:
                break
    return not elastic, _finish_point(P_tr - m[0] * d0[0] - m[1] * d0[1] - m[2] * d0[2],
                                      Q_tr - m[0] * d1[0] - m[1] * d1[1] - m[2] * d1[2],
                                      T00, T01, T10, T11, lam, tau, J,
                                      theta_p + m[0] * g0[0] + m[1] * g0[1] + m[2] * g0[2],
                                      gamma_p + m[0] * g1[0] + m[1] * g1[1] + m[2] * g1[2])


@njit(cache=True, error_model="numpy")
def hydrostat(theta, theta_p, K, crush, lock_pressure, lock_strain, locked_modulus):
    """The compaction hydrostat at the point (module docstring, "Compaction"): the trial
    Kirchhoff pressure ``P_tr``, its tangent ``K_t = dP/de`` and the plastic volumetric strain
    ``theta_p`` after compaction."""
    x = theta_p - theta                     # elastic volumetric strain e - e_c
    e_c = -theta_p                          # net plastic compaction
    x_lock = lock_pressure / K
    e_c_lock = lock_strain - x_lock
    if e_c >= e_c_lock:                     # fully compacted: elastic, then locked
        if x > x_lock:
            return lock_pressure + locked_modulus * (x - x_lock), locked_modulus, theta_p
        return K * x, K, theta_p
    K_c = (lock_pressure - crush) / (lock_strain - crush / K)
    h = K * K_c / (K - K_c)
    P_tr = K * x
    opened = max(theta_p, 0.0)
    crush_now = crush + h * max(e_c, 0.0)
    if not P_tr > crush_now:                # elastic
        return P_tr, K, theta_p
    if P_tr - K * opened <= crush:          # closing opened volume at the crush pressure
        return crush, 0.0, theta_p - (P_tr - crush) / K
    dl = opened + (P_tr - K * opened - crush_now) / (K + h)
    if e_c + dl < e_c_lock:                 # compaction
        return P_tr - K * dl, K_c, theta_p - dl
    return (lock_pressure + locked_modulus * (x - (e_c_lock - e_c) - x_lock), locked_modulus,
            -e_c_lock)                      # compacted through the locking strain


@njit(cache=True, error_model="numpy", inline="always")
def return_point(eps_r, eps_t, theta_p, gamma_p, material):
    """Return map of one point from its total log strains: ``(plastic, outputs)``, whether the
    point is plastic in this step and the tuple of its :data:`OUTPUTS`.

    ``material`` is the point's record of :data:`cavex.fem.material_records.MATERIAL`; the
    only place where the kernels read its constitutive fields. Its ``cap`` is the Tresca cap
    ``tau_max`` (Pa) on ``|sigma_r - sigma_theta|``; ``inf`` (no cap) takes exactly the
    Mohr-Coulomb/tension code path (the cap tests are false). Its ``crush`` is the hydrostat's
    crush pressure (Pa); ``inf`` (no compaction) is the linear ``P = -K (theta - theta_p)``,
    the same arithmetic as without the hydrostat. A point that compacts in this step is
    plastic."""
    K, G, lam, tau = material.K, material.G, material.lam, material.tau
    lam_psi, tension, cap = material.lam_psi, material.tension, material.cap
    theta = eps_r + 2.0 * eps_t
    gamma = eps_r - eps_t
    J = math.exp(theta)
    compacted = False
    if material.crush < np.inf:
        P_tr, K, th_p = hydrostat(theta, theta_p, K, material.crush, material.lock_pressure,
                                  material.lock_strain, material.locked_modulus)
        compacted = th_p != theta_p
        theta_p = th_p
    else:
        P_tr = -K * (theta - theta_p)
    plastic, multi, out = _mohr_coulomb_point(P_tr, gamma, J, theta_p, gamma_p, K, G, lam,
                                              tau, lam_psi, tension)
    if multi:
        plastic, out = _multi_surface_point(P_tr, gamma, J, theta_p, gamma_p, K, G, lam, tau,
                                            lam_psi, tension)
    if cap < np.inf:
        capJ = cap * J
        tol = 1e-12 * tau * J
        trial_deviator = 2.0 * G * abs(gamma - gamma_p)
        if trial_deviator - capJ > tol or abs(out[1] - out[0]) - capJ > tol:
            plastic, out = _capped_point(P_tr, gamma, J, theta_p, gamma_p, K, G, lam, tau,
                                         lam_psi, tension, cap)
        out = out[:6] + (max(out[6], abs(out[1] - out[0]) / capJ),) + out[7:]
    return plastic or compacted, out
