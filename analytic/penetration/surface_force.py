r"""Differential-area force law and the rigid body's equations of motion (compiled).

State ``y`` (14): centre of mass ``x`` (target frame), unit quaternion ``q = (w, x, y, z)``
(body to target), velocity ``v``, body-frame angular velocity ``omega``, work ``W`` of the
surface forces. For surface element ``i`` (body-frame centroid ``p_i``, outward normal
``n_i``, area ``A_i``, spans ``(dn_a, dp_a, dn_b, dp_b)``: the changes of the normal and the
position across the element in its two surface directions) with ``R = R(q)``:

.. math::
    \mathbf p = R \mathbf p_i, \quad \mathbf n = R \mathbf n_i, \quad
    \mathbf u = \mathbf v + (R \boldsymbol\omega) \times \mathbf p, \quad
    V_n = \mathbf u \cdot \mathbf n, \quad z = x_3 + p_3.

Fractions. An element is a small parallelogram over which ``z`` and ``V_n`` vary linearly:
``z + s dz_a + t dz_b`` and ``V_n + s dV_a + t dV_b`` with ``|s|, |t| <= 1/2``,
``dz = (R dp) . e_3`` and ``dV = u . (R dn) + ((R omega) x (R dp)) . n``. The part of it on
which a linear function ``x + s w_1 + t w_2`` is positive is the distribution function of the
sum of two uniform variables of widths ``w_1 >= w_2`` (:func:`wetted_fraction`; a trapezoid's
integral, exact for the linear function), so every step of the force law across the surface
(the free surface, a finite bottom, an open zone's edges, an interface where the stress law
jumps, the line where the contact opens) is integrated over the element's area instead of
switching at its centroid; the surface rule then converges at second order in the element
size at a fixed state (docs/oblique.md "Convergence"). With ``G(x) = wetted_fraction(x, dz)``:

- embedded fraction ``w = G(z)`` (the part below ``z = 0``), at a finite bottom ``z_b`` less
  ``1 - G(z_b - z)``; for a shank element less its part ``G(z_b - z) - G(z_t - z)`` in each
  open zone ``[z_t, z_b]`` (:func:`cavex.analytic.penetration.zones.open_zones`, opened by the
  integrator's events: no tunnel wall in a crater or a scabbed rear zone); times the
  tunnel-wall factor ``walls[k]`` of its layer ``k`` (none: 1);
- an element straddling an interface ``H`` carries ``G(z - H) sigma_n(max(z, H)) +
  (1 - G(z - H)) sigma_n(min(z, H^-))``, each side's stress at the centroid's depth clamped
  to that side (:func:`_split_stress`);
- wetted fraction ``c = wetted_fraction(V_n - V_r/2, max(w_1, V_r), w_2)`` of the normal
  velocity's widths: the contact regularisation ``V_r`` = ``contact_ramp`` (0: none) is a ramp
  ``clip(V_n/V_r, 0, 1)`` for an element over which ``V_n`` hardly varies and the element's
  part in contact otherwise; with OFPM's tangency attenuation ``tangency = sin psi`` > 0,
  ``V_r = max(contact_ramp, |u| sin psi)`` (the load falls linearly within ``psi`` of
  tangency). ``V_n`` within ``10^-9 (|v| + L |omega|)`` of zero counts as zero, and so does
  its change across an element (round-off).

An element with ``w c > 0`` carries the load ``P = A_i w c sigma_n(z, n_3, max(V_n, 0))``,
force

.. math:: \mathbf f = -P (\mathbf n + \mu \mathbf t), \quad
          \mathbf t = \mathbf u_t / |\mathbf u_t|, \quad
          \mathbf u_t = \mathbf u - V_n \mathbf n.

Sums: ``F = sum f``, ``M = R^T sum p x f`` (body frame), power ``sum f . u``.

Contact damping (the stiff part of the Jacobian, for the linearly implicit integrator of
:mod:`cavex.analytic.penetration.rosenbrock`): the load grows with ``V_n`` at the rate
``kappa = A_i w sigma_n dc/dV_n`` (at most ``A_i w sigma_n / V_r``: large for a small ramp,
a sliding shank is a stiff damper). With ``u = v - [p]_x omega_t`` its contribution to
``d(F, sum p x f)/d(v, omega_t)`` is ``-kappa b a^T``, ``a = (n, p x n)``,
``b = (d, p x d)``, ``d = n + mu t``; the kernel returns
``D = d(dv/dt, d omega/dt)/d(v, omega)`` in the state's frames (body-frame ``omega``),

.. math:: D = -\mathrm{diag}(1/m, I^{-1})\,\mathrm{diag}(1, R^T)
          \Big(\sum \kappa\, \mathbf b \mathbf a^T\Big)\,\mathrm{diag}(1, R),

without the slow parts (``d sigma_n / d V_n``, the turning of ``t``, the gyroscopic term).

Held contact (``hold`` = ``delta_r`` > 0, docs/oblique.md "Held contact"): instead of the
ramp, each element carries an elastic fraction ``phi_i = y[14 + i]`` in ``[0, 1]`` with
``dphi_i/dt = V_n / delta_r`` (``|V_n|`` less the round-off guard; 0 where ``V_n`` pushes it
out of ``[0, 1]``: plastic beyond 1) and the load
``P = A_i w sigma_n(z, n_3, max(V_n, 0)) clip(phi_i + tau dphi_i/dt, 0, 1)`` (``tau`` =
``hold_time``, a dashpot in parallel): a held element keeps its load at ``V_n = 0``. The
Jacobian rows of the elastic elements (:func:`derivative`) replace the damping block.

Motion:

.. math:: \dot{\mathbf x} = \mathbf v, \quad
          \dot q = \tfrac12 q \otimes (0, \boldsymbol\omega), \quad
          m \dot{\mathbf v} = \mathbf F, \quad
          I \dot{\boldsymbol\omega} = \mathbf M - \boldsymbol\omega \times I \boldsymbol\omega,
          \quad \dot W = \sum \mathbf f \cdot \mathbf u,

``I = diag(I_a, I_t, I_t)``. ``sigma_n`` is
:func:`cavex.analytic.penetration.stress_laws.element_stress`.
"""

import math

import numpy as np
from numba import njit

from cavex.analytic.penetration.stress_laws import (
    BEYOND_TABLE,
    NOT_FINITE,
    OK,
    WALK_FAILED,
    element_stress,
)

ROUND_OFF = 1e-9  # normal velocities below this x the body's velocity scale count as zero
_NO_ZONES = np.empty((0, 2))


@njit(cache=True, error_model="numpy")
def rotation_matrix(q):
    """Rotation matrix (body to target) of the quaternion ``q`` (any norm).

    Written with grouped sums (``(w^2 + x^2) - (y^2 + z^2)``, ...) so that the mirror map of
    :func:`mirror_state` changes its entries by exact sign flips."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    ww, xx, yy, zz = w * w, x * x, y * y, z * z
    s = 1.0 / ((ww + xx) + (yy + zz))
    rot = np.empty((3, 3))
    rot[0, 0] = s * ((ww + xx) - (yy + zz))
    rot[1, 1] = s * ((ww + yy) - (xx + zz))
    rot[2, 2] = s * ((ww + zz) - (xx + yy))
    rot[0, 1] = 2.0 * s * (x * y - w * z)
    rot[1, 0] = 2.0 * s * (x * y + w * z)
    rot[0, 2] = 2.0 * s * (x * z + w * y)
    rot[2, 0] = 2.0 * s * (x * z - w * y)
    rot[1, 2] = 2.0 * s * (y * z - w * x)
    rot[2, 1] = 2.0 * s * (y * z + w * x)
    return rot


@njit(cache=True, error_model="numpy", inline="always")
def _sum3(a, b, c):
    """``a + b + c`` added in order of increasing magnitude: the same bits for any order of
    the terms and the negated sum for the negated terms."""
    if abs(a) > abs(b):
        a, b = b, a
    if abs(b) > abs(c):
        b, c = c, b
    if abs(a) > abs(b):
        a, b = b, a
    return (a + b) + c


def mirror_state(y, partners=None):
    """The state of the mirror-image shot (``x -> -x``): with the body mirror
    ``theta -> -theta`` the rotation becomes ``S R D`` (``S = diag(-1, 1, 1)``,
    ``D = diag(1, 1, -1)``), i.e. ``q -> (-q_2, -q_3, -q_0, -q_1)``, and the body angular
    velocity (a pseudovector) ``omega -> (-omega_1, -omega_2, omega_3)``. The held contact's
    load fractions (``y[14:]``) are exchanged between mirror partners (``partners``, the
    body's ``partners``; needed when ``y`` has them)."""
    m = np.array(y, dtype=float)
    m[0], m[7] = -y[0], -y[7]
    m[3:7] = -y[5], -y[6], -y[3], -y[4]
    m[10], m[11] = -y[10], -y[11]
    if m.shape[0] > 14:
        m[14:] = np.asarray(y)[14:][np.asarray(partners)]
    return m


@njit(cache=True, error_model="numpy", inline="always")
def wetted_fraction(x, wide, narrow):
    """``(fraction, d fraction / dx)`` of the unit square ``|s|, |t| <= 1/2`` on which
    ``x + wide s + narrow t > 0`` (``wide >= narrow >= 0``; "Wetted fraction" in the module
    docstring): the distribution function of the sum of two uniform variables of widths
    ``wide`` and ``narrow`` at ``x``, a trapezoid's integral. ``wide = 0``: the step at 0."""
    if wide <= 0.0:
        return (1.0 if x > 0.0 else 0.0), 0.0
    outer = 0.5 * (wide + narrow)
    inner = 0.5 * (wide - narrow)
    if x <= -outer:
        return 0.0, 0.0
    if x >= outer:
        return 1.0, 0.0
    if x < -inner:
        return (x + outer) ** 2 / (2.0 * wide * narrow), (x + outer) / (wide * narrow)
    if x > inner:
        return 1.0 - (outer - x) ** 2 / (2.0 * wide * narrow), (outer - x) / (wide * narrow)
    return 0.5 + x / wide, 1.0 / wide


@njit(cache=True, error_model="numpy", inline="always")
def _near_edge(z, reach, bottom, open_zones, interfaces):
    """Whether an edge of the force law (the free surface, the bottom, an open zone's top or
    bottom, an interface) lies within ``reach`` (the element's largest half extent) of the
    depth ``z``: only then do the element's fractions need its spans."""
    if abs(z) < reach or abs(bottom - z) < reach:
        return True
    for k in range(open_zones.shape[0]):
        if abs(open_zones[k, 0] - z) < reach or abs(open_zones[k, 1] - z) < reach:
            return True
    for k in range(interfaces.shape[0]):
        if abs(interfaces[k] - z) < reach:
            return True
    return False


@njit(cache=True, error_model="numpy", inline="always")
def _depth_spread(i, rot, spans):
    """``(shift, wide, narrow)``: the depth of element ``i``'s centre less its node's,
    ``e dz_a``, and the larger and the smaller change of the depth across it in its two
    surface directions, ``|dz| = |(R dp) . e_3|`` (module docstring, "Fractions")."""
    first = (rot[2, 0] * spans[i, 1, 0] + rot[2, 1] * spans[i, 1, 1]
             + rot[2, 2] * spans[i, 1, 2])
    second = abs(rot[2, 0] * spans[i, 3, 0] + rot[2, 1] * spans[i, 3, 1]
                 + rot[2, 2] * spans[i, 3, 2])
    return spans[i, 4, 2] * first, max(abs(first), second), min(abs(first), second)


@njit(cache=True, error_model="numpy", inline="always")
def _span_change(i, k, rot, omega, u0, u1, u2, n0, n1, n2, spans):
    """``u . (R dn) + ((R omega) x (R dp)) . n`` for the spans ``dn = spans[i, k]``,
    ``dp = spans[i, k + 1]`` (``omega`` already in the target frame)."""
    a0, a1, a2 = spans[i, k, 0], spans[i, k, 1], spans[i, k, 2]
    b0, b1, b2 = spans[i, k + 1, 0], spans[i, k + 1, 1], spans[i, k + 1, 2]
    dn0 = rot[0, 0] * a0 + rot[0, 1] * a1 + rot[0, 2] * a2
    dn1 = rot[1, 0] * a0 + rot[1, 1] * a1 + rot[1, 2] * a2
    dn2 = rot[2, 0] * a0 + rot[2, 1] * a1 + rot[2, 2] * a2
    dp0 = rot[0, 0] * b0 + rot[0, 1] * b1 + rot[0, 2] * b2
    dp1 = rot[1, 0] * b0 + rot[1, 1] * b1 + rot[1, 2] * b2
    dp2 = rot[2, 0] * b0 + rot[2, 1] * b1 + rot[2, 2] * b2
    c0 = omega[1] * dp2 - omega[2] * dp1
    c1 = omega[2] * dp0 - omega[0] * dp2
    c2 = omega[0] * dp1 - omega[1] * dp0
    return (u0 * dn0 + u1 * dn1 + u2 * dn2) + (c0 * n0 + c1 * n1 + c2 * n2)


@njit(cache=True, error_model="numpy", inline="always")
def _velocity_spread(i, rot, omega, u0, u1, u2, n0, n1, n2, spans):
    """``(shift, wide, narrow)``: the normal velocity at element ``i``'s centre less its
    node's, ``e dV_a``, and the larger and the smaller change of the normal velocity across
    it in its two surface directions, ``|dV| = |u . dn + (omega x dp) . n|`` with the
    element's ``spans`` turned to the target frame (module docstring, "Fractions")."""
    first = _span_change(i, 0, rot, omega, u0, u1, u2, n0, n1, n2, spans)
    second = abs(_span_change(i, 2, rot, omega, u0, u1, u2, n0, n1, n2, spans))
    return spans[i, 4, 2] * first, max(abs(first), second), min(abs(first), second)


@njit(cache=True, error_model="numpy", inline="always")
def _split_stress(kind, scalars, values, tables, counts, depths, z, middle, wide, narrow, nz, vn,
                  radii, zones):
    """``(sigma_n, status)`` of an element with its node at depth ``z`` whose depths span
    ``middle`` plus the sum of two uniform offsets of widths ``wide >= narrow``: where the
    element straddles an interface ``H`` (a jump of the law), the parts below and above it,
    each at the node's depth clamped to its side (module docstring, "Fractions"); else the
    law at ``z``."""
    for j in range(depths.shape[0]):
        H = depths[j]
        if abs(middle - H) < 0.5 * (wide + narrow):
            below = wetted_fraction(middle - H, wide, narrow)[0]
            low, status = element_stress(kind, scalars, values, tables, counts, depths,
                                         max(z, H), nz, vn, radii, zones)
            if status == WALK_FAILED or below >= 1.0:
                return low, status
            high, other = element_stress(kind, scalars, values, tables, counts, depths,
                                         max(min(z, np.nextafter(H, -np.inf)), 1e-12), nz, vn,
                                         radii, zones)
            if other == WALK_FAILED:
                return high, other
            return below * low + (1.0 - below) * high, max(status, other)
    return element_stress(kind, scalars, values, tables, counts, depths, max(z, 1e-12), nz, vn,
                          radii, zones)


@njit(cache=True, error_model="numpy", inline="always")
def _held_fraction(phi, vn, scale, hold, hold_time):
    """``(dphi/dt, load fraction, elastic)`` of an element under the held contact (module
    docstring, "Held contact"). Its elastic fraction ``phi`` moves at ``V_n / hold`` within
    ``[0, 1]`` (not at all where ``V_n`` pushes out of them; ``|V_n|`` less the round-off
    guard ``scale``): an elastic spring of ``hold`` up to the element's capacity, then plastic
    flow (the wall is cut). With the dashpot of time constant ``hold_time`` its load fraction
    is ``clip(phi + hold_time dphi/dt, 0, 1)``; elastic: neither the rate nor the fraction
    clipped."""
    rate = 0.0
    if abs(vn) > scale and not ((phi >= 1.0 and vn > 0.0) or (phi <= 0.0 and vn < 0.0)):
        rate = (vn - scale if vn > 0.0 else vn + scale) / hold  # continuous at the guard
    raw = phi + hold_time * rate
    fraction = min(max(raw, 0.0), 1.0)
    elastic = rate != 0.0 and 0.0 < raw < 1.0
    return rate, fraction, elastic


@njit(cache=True, error_model="numpy", inline="always")
def _held_load(i, rate, fraction, elastic, frac, p0, p1, p2, n0, n1, n2, u0, u1, u2, vn, z,
               middle, z_wide, z_narrow, areas, mu, hold, hold_time, law, radii, zones, out,
               damping, extra):
    """Element ``i`` under the held contact (module docstring, "Held contact"), a loaded one
    (its ``rate``, ``fraction`` and whether it is ``elastic``: :func:`_held_fraction`).
    The load is ``A_i w sigma_n(z, n_3, max(V_n, 0)) fraction``. Writes the force, moment
    and power into ``out``, ``extra = (dphi/dt, capacity b (6), a / hold (6), 0)`` (target
    frame; rows zero unless the element is elastic: neither its rate nor its fraction
    clipped) and the dashpot's damping ``capacity hold_time / hold b a^T`` into
    ``damping``."""
    extra[:] = 0.0
    extra[0] = rate
    kind, scalars, values, tables, counts, depths = law
    sigma, status = _split_stress(kind, scalars, values, tables, counts, depths, z, middle,
                                  z_wide, z_narrow, n2, max(vn, 0.0), radii, zones)
    if status == WALK_FAILED:
        return status, vn
    capacity = sigma * areas[i] * frac
    d0, d1, d2 = n0, n1, n2  # the force's direction per unit load: n + mu t
    if mu > 0.0:
        t0, t1, t2 = u0 - vn * n0, u1 - vn * n1, u2 - vn * n2
        tangential = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        if tangential > 1e-12:
            d0, d1, d2 = (d0 + mu * t0 / tangential, d1 + mu * t1 / tangential,
                          d2 + mu * t2 / tangential)
    load = capacity * fraction
    f0, f1, f2 = -load * d0, -load * d1, -load * d2
    out[0], out[1], out[2] = f0, f1, f2
    out[3] = p1 * f2 - p2 * f1
    out[4] = p2 * f0 - p0 * f2
    out[5] = p0 * f1 - p1 * f0
    out[6] = f0 * u0 + f1 * u1 + f2 * u2
    a = (n0, n1, n2, p1 * n2 - p2 * n1, p2 * n0 - p0 * n2, p0 * n1 - p1 * n0)
    b = (d0, d1, d2, p1 * d2 - p2 * d1, p2 * d0 - p0 * d2, p0 * d1 - p1 * d0)
    if elastic:
        kappa = capacity * hold_time / hold
        for r in range(6):
            extra[1 + r] = capacity * b[r]
            extra[7 + r] = a[r] / hold
            kb = kappa * b[r]
            for c in range(6):
                damping[r, c] = kb * a[c]
    return status, vn


@njit(cache=True, error_model="numpy")
def surface_loads(y, points, normals, areas, spans, partners, length, mu, contact_ramp, bottom,
                  nose, open_zones, walls, wall_depths, tangency, hold, hold_time, kind, scalars,
                  values, tables, counts, depths):
    """``(F (3, target frame), M (3, body frame), power, status, V_n of a failed element,
    C, H)`` of the surface forces in state ``y`` (module docstring; the law arrays are
    ``law.data``; ``C = diag(1, R^T) (sum kappa b a^T) diag(1, R)``, the contact damping
    on ``(v, omega)``, with the held contact (``hold`` > 0) the same sum of the stiffnesses
    ``(capacity / hold) b a^T``; ``H`` (N, 13), empty without the held contact: each
    element's ``dphi/dt``, ``capacity diag(1, R^T) b`` and ``diag(1, R^T) a / hold``, the
    rows of the Jacobian in the state's frames). Each element is added
    together with its mirror image ``partners[i]`` (``theta -> -theta``) first, so that a
    shot and its mirror shot sum the same numbers in the same order: the mirrored trajectory
    is mirrored to the last bit."""
    rot = rotation_matrix(y[3:7])
    omega = np.empty(3)
    for r in range(3):
        omega[r] = rot[r, 0] * y[10] + rot[r, 1] * y[11] + rot[r, 2] * y[12]
    speed = math.sqrt(y[7] * y[7] + y[8] * y[8] + y[9] * y[9])
    scale = ROUND_OFF * (speed + length * math.sqrt(omega @ omega))
    turning = math.sqrt(omega[0] * omega[0] + omega[1] * omega[1] + omega[2] * omega[2])
    total = np.zeros(7)  # force, moment (target frame), power
    radii = np.empty((1, max(depths.shape[0], 1)))
    zones = np.empty((0, 1, 2))
    one = np.empty(7)
    other = np.empty(7)
    damping = np.zeros((6, 6))
    one_damping = np.empty((6, 6))
    other_damping = np.empty((6, 6))
    held = np.zeros((areas.shape[0] if hold > 0.0 else 0, 14))
    extra = np.empty(14)
    beyond = 0.0  # largest normal velocity beyond a table's range (0: none)
    law = (kind, scalars, values, tables, counts, depths)
    for i in range(areas.shape[0]):
        j = partners[i]
        if j < i:
            continue
        for second in range(2 if j != i else 1):
            # element k's force, moment about the centre of mass (target frame) and power
            # into out[0:7], its contact damping kappa b a^T (module docstring, target frame)
            # into out_damping, with the held contact its rate and Jacobian rows into extra
            # (_held_load). Written out here, not called: numba binds a called function's
            # twenty arrays anew for every element, reference counted, which took 60 % of a
            # derivative call (issue 30). ``break`` ends the element.
            k = j if second else i
            out = other if second else one
            out_damping = other_damping if second else one_damping
            status, vn = OK, 0.0
            for _ in range(1):
                for r in range(7):
                    out[r] = 0.0
                for r in range(6):
                    for c in range(6):
                        out_damping[r, c] = 0.0
                x0, x1, x2 = points[k, 0], points[k, 1], points[k, 2]
                p0 = rot[0, 0] * x0 + rot[0, 1] * x1 + rot[0, 2] * x2
                p1 = rot[1, 0] * x0 + rot[1, 1] * x1 + rot[1, 2] * x2
                p2 = rot[2, 0] * x0 + rot[2, 1] * x1 + rot[2, 2] * x2
                z = y[2] + p2
                middle, z_wide, z_narrow = z, 0.0, 0.0  # far from every edge: steps, exact
                if _near_edge(z, spans[k, 4, 1], bottom,
                              open_zones if not nose[k] else _NO_ZONES, depths):
                    shift, z_wide, z_narrow = _depth_spread(k, rot, spans)
                    middle = z + shift
                # the part below the free surface
                frac = wetted_fraction(middle, z_wide, z_narrow)[0]
                if bottom < np.inf:  # and above the bottom
                    frac = max(frac - (1.0 - wetted_fraction(bottom - middle, z_wide,
                                                             z_narrow)[0]), 0.0)
                if not nose[k] and open_zones.shape[0] > 0:  # the shank carries no load in
                    # an open zone (crater, scabbed rear zone); the zones are disjoint (merged
                    # where they touch), so the element's part inside their union is the sum
                    # of its parts in each
                    inside = 0.0
                    for zone in range(open_zones.shape[0]):
                        inside += (wetted_fraction(open_zones[zone, 1] - middle, z_wide,
                                                   z_narrow)[0]
                                   - wetted_fraction(open_zones[zone, 0] - middle, z_wide,
                                                     z_narrow)[0])
                    frac = max(frac - inside, 0.0)
                if not nose[k] and walls.shape[0] > 0:  # the tunnel-wall factor of its layer
                    frac *= walls[np.searchsorted(wall_depths, z, side="right")]
                if frac <= 0.0 and hold <= 0.0:  # (a held element's fraction moves outside)
                    break
                x0, x1, x2 = normals[k, 0], normals[k, 1], normals[k, 2]
                n0 = rot[0, 0] * x0 + rot[0, 1] * x1 + rot[0, 2] * x2
                n1 = rot[1, 0] * x0 + rot[1, 1] * x1 + rot[1, 2] * x2
                n2 = rot[2, 0] * x0 + rot[2, 1] * x1 + rot[2, 2] * x2
                u0 = y[7] + omega[1] * p2 - omega[2] * p1
                u1 = y[8] + omega[2] * p0 - omega[0] * p2
                u2 = y[9] + omega[0] * p1 - omega[1] * p0
                vn = u0 * n0 + u1 * n1 + u2 * n2
                if hold > 0.0:
                    rate, fraction, elastic = _held_fraction(y[14 + k], vn, scale, hold,
                                                             hold_time)
                    if frac <= 0.0 or not (fraction > 0.0 or elastic):  # carries nothing
                        for r in range(14):
                            extra[r] = 0.0
                        extra[0] = rate
                        vn = 0.0
                        break
                    status, vn = _held_load(k, rate, fraction, elastic, frac, p0, p1, p2, n0,
                                            n1, n2, u0, u1, u2, vn, z, middle, z_wide,
                                            z_narrow, areas, mu, hold, hold_time, law, radii,
                                            zones, out, out_damping, extra)
                    break
                if abs(vn) <= scale:
                    vn = 0.0
                ramp = contact_ramp
                if tangency > 0.0:  # OFPM's attenuation: load x angle / psi within psi of
                    # tangency
                    ramp = max(ramp, tangency * math.sqrt(u0 * u0 + u1 * u1 + u2 * u2))
                shift = wide = narrow = 0.0
                speed = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
                if abs(vn - 0.5 * ramp) < (0.5 * ramp + speed * spans[k, 4, 0]
                                           + turning * spans[k, 4, 1]):
                    shift, wide, narrow = _velocity_spread(k, rot, omega, u0, u1, u2, n0, n1,
                                                           n2, spans)
                    if wide <= scale:  # round-off: V_n does not vary across the element
                        shift = wide = narrow = 0.0
                wetted, slope = wetted_fraction(vn + shift - 0.5 * ramp, max(wide, ramp),
                                                narrow)
                if wetted <= 0.0:
                    break
                sigma, status = _split_stress(kind, scalars, values, tables, counts, depths, z,
                                              middle, z_wide, z_narrow, n2, max(vn, 0.0),
                                              radii, zones)
                if status == WALK_FAILED:
                    break
                capacity = sigma * areas[k] * frac
                load = capacity * wetted
                f0, f1, f2 = -load * n0, -load * n1, -load * n2
                if mu > 0.0:
                    t0, t1, t2 = u0 - vn * n0, u1 - vn * n1, u2 - vn * n2
                    tangential = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
                    if tangential > 1e-12:
                        friction = mu * load / tangential
                        f0, f1, f2 = f0 - friction * t0, f1 - friction * t1, f2 - friction * t2
                out[0], out[1], out[2] = f0, f1, f2
                out[3] = p1 * f2 - p2 * f1
                out[4] = p2 * f0 - p0 * f2
                out[5] = p0 * f1 - p1 * f0
                out[6] = f0 * u0 + f1 * u1 + f2 * u2
                if slope > 0.0 and load > 0.0:
                    kappa = capacity * slope  # d load / d V_n = A_i w sigma_n d(wetted)/dV_n
                    a = (n0, n1, n2, p1 * n2 - p2 * n1, p2 * n0 - p0 * n2, p0 * n1 - p1 * n0)
                    b = (-f0 / load, -f1 / load, -f2 / load, -out[3] / load, -out[4] / load,
                         -out[5] / load)
                    for r in range(6):
                        kb = kappa * b[r]
                        for c in range(6):
                            out_damping[r, c] = kb * a[c]
            if hold > 0.0:  # the rate and the Jacobian rows, turned to the state's frames
                for r in range(14):
                    held[k, r] = extra[r]
                for r in range(3):
                    held[k, 4 + r] = (rot[0, r] * extra[4] + rot[1, r] * extra[5]
                                      + rot[2, r] * extra[6])
                    held[k, 10 + r] = (rot[0, r] * extra[10] + rot[1, r] * extra[11]
                                       + rot[2, r] * extra[12])
            if status == BEYOND_TABLE:
                beyond = max(beyond, vn)
            elif status != OK:
                return total[0:3], total[3:6], total[6], status, vn, damping, held
        if j != i:
            for r in range(7):
                one[r] += other[r]
            for r in range(6):
                for c in range(6):
                    one_damping[r, c] += other_damping[r, c]
        for r in range(7):
            total[r] += one[r]
        for r in range(6):
            for c in range(6):
                damping[r, c] += one_damping[r, c]
    moment = rot.T @ total[3:6]
    # to the state's frames: omega_t = R omega, body moment R^T M
    turned = damping.copy()
    for r in range(6):
        for c in range(3):
            turned[r, 3 + c] = (damping[r, 3] * rot[0, c] + damping[r, 4] * rot[1, c]
                                + damping[r, 5] * rot[2, c])
    for c in range(6):
        for r in range(3):
            damping[3 + r, c] = (rot[0, r] * turned[3, c] + rot[1, r] * turned[4, c]
                                 + rot[2, r] * turned[5, c])
        for r in range(3):
            damping[r, c] = turned[r, c]
    if beyond > 0.0:
        return total[0:3], moment, total[6], BEYOND_TABLE, beyond, damping, held
    return total[0:3], moment, total[6], OK, 0.0, damping, held


@njit(cache=True, error_model="numpy")
def derivative(y, mass, inertia, points, normals, areas, spans, partners, length, mu,
               contact_ramp, bottom, nose, open_zones, walls, wall_depths, tangency, hold,
               hold_time, kind, scalars, values, tables, counts, depths):
    """``(dy/dt, D, status, V_n of a failed element)`` (module docstring; ``D`` the 6 x 6
    contact damping block of the Jacobian; with the held contact, ``hold`` > 0, ``D`` is
    ``(6 + 2 N) x 6``: rows 0-5 the product ``S = B C`` of the two blocks, rows ``6 + i``
    the column ``B_i = d(dv/dt, d omega/dt)/d phi_i``, rows ``6 + N + i`` the row
    ``C_i = d(dphi_i/dt)/d(v, omega)``)."""
    force, moment, power, status, vn, damping, held = surface_loads(
        y, points, normals, areas, spans, partners, length, mu, contact_ramp, bottom,
        nose, open_zones, walls, wall_depths, tangency, hold, hold_time, kind, scalars, values,
        tables, counts, depths)
    size = y.shape[0]
    dy = np.empty(size)
    q0, q1, q2, q3 = y[3], y[4], y[5], y[6]
    w0, w1, w2 = y[10], y[11], y[12]
    dy[0:3] = y[7:10]
    dy[3] = 0.5 * _sum3(-q1 * w0, -q2 * w1, -q3 * w2)
    dy[4] = 0.5 * _sum3(q0 * w0, q2 * w2, -q3 * w1)
    dy[5] = 0.5 * _sum3(q0 * w1, -q1 * w2, q3 * w0)
    dy[6] = 0.5 * _sum3(q0 * w2, q1 * w1, -q2 * w0)
    dy[7:10] = force / mass
    i0, i1, i2 = inertia[0], inertia[1], inertia[2]
    dy[10] = (moment[0] - (w1 * i2 * w2 - w2 * i1 * w1)) / i0
    dy[11] = (moment[1] - (w2 * i0 * w0 - w0 * i2 * w2)) / i1
    dy[12] = (moment[2] - (w0 * i1 * w1 - w1 * i0 * w0)) / i2
    dy[13] = power
    n_held = held.shape[0]
    jac = np.zeros((6 + 3 * n_held, 6)) if n_held else np.empty((6, 6))
    for r in range(6):
        scale = -1.0 / (mass if r < 3 else inertia[r - 3])
        for c in range(6):
            jac[r, c] = scale * damping[r, c]
    for k in range(n_held):
        dy[14 + k] = held[k, 0]
        for r in range(6):
            jac[6 + k, r] = -held[k, 1 + r] / (mass if r < 3 else inertia[r - 3])
            jac[6 + n_held + k, r] = held[k, 7 + r]
        jac[6 + 2 * n_held + k, 0] = held[k, 13]
    # an integrator stage may try a state whose normal velocities exceed a table's (stiff
    # contact): it gets the table's largest velocity; the accepted states are checked when the
    # history is sampled (surface_loads reports BEYOND_TABLE there)
    if status == BEYOND_TABLE:
        status = OK
    if status == OK:
        for k in range(size):
            if not math.isfinite(dy[k]):
                return dy, jac, NOT_FINITE, vn
    return dy, jac, status, vn
