r"""Compiled linearly implicit integrator of the rigid projectile, with event location.

The sliding shank makes the equations of motion stiff: on the contact ramp
``0 < V_n < V_r`` every element is a damper of rate ``kappa / m ~ sigma_n A / (m V_r)``, about
10^7 1/s for the default projectile, so an explicit method needs steps of ~0.5 us whatever the
accuracy asked (the step count grows as ``1/V_r``). The W-method ROS2 (Verwer, Spee, Blom and
Hundsdorfer, SIAM J. Sci. Comput. 20 (1999) 1456) treats that damping implicitly:

.. math::
    (I - \gamma h J)\,k_1 = f(y_n), \qquad
    (I - \gamma h J)\,k_2 = f(y_n + h k_1) - 2 k_1, \qquad
    y_{n+1} = y_n + \tfrac32 h k_1 + \tfrac12 h k_2,

``gamma = 1 + 1/sqrt(2)``. It is of order 2 for *any* matrix ``J`` and L-stable when ``J``
holds the stiff part of the Jacobian; here ``J`` is zero except for the contact damping block
``D = d(dv/dt, d omega/dt)/d(v, omega)`` of
:func:`cavex.analytic.penetration.surface_force.derivative`,
so each stage solves one 6 x 6 system. Without contact damping (``D = 0``) the scheme is
Heun's method.

Step control: the embedded first-order solution ``y_n + h k_1`` gives the estimate
``e = h (k_1 + k_2) / 2``; a step is accepted when
``||e_i / (atol_i + rtol max(|y_n,i|, |y_n+1,i|))||_rms <= 1`` over the 14 rigid-body
components (``atol_i``: each component's absolute tolerance, in its own unit; the caller's,
:meth:`cavex.analytic.penetration.oblique.ObliqueModel.absolute_tolerances`) and the next step is
``h min(5, max(0.2, 0.9 err^(-1/2)))`` (at most ``h`` after a rejection). A step whose
stage state has non-finite equations of motion (a stiff contact overshot by too long a step)
is rejected with the largest shrink, not fatal.

Events: the functions of :func:`event_values` (nose tip at each interface, deepest and
shallowest point of the body, the axis's ``z`` component, transverse kinetic energy) are
checked after every accepted step with the sign rules of ``scipy.integrate.solve_ivp``
(``direction`` > 0: from below to above zero, < 0: from above, 0: either). A root is first
located by bisection on the cubic Hermite interpolant of the step (``y`` and ``f`` at both
ends; also the dense output of the trajectory), then landed on with a step of the method
itself, its length found by secant iteration to 4 ulp of ``t``: an interpolated state's
lateral velocity is off the stiff contact's slow manifold by the interpolation error, which
the damper turns into a spurious side force (a 95 000 g spike at an interface crossing, and a
kick into the next phase). Every event is terminal: integration stops at the earliest root of
the step.

One call advances at most ``max_steps`` accepted steps and returns, so that the caller can
report progress and resume (:func:`integrate`).
"""

import math

import numpy as np
from numba import njit

from cavex.analytic.penetration.stress_laws import NOT_FINITE, OK
from cavex.analytic.penetration.surface_force import derivative, rotation_matrix

GAMMA = 1.0 + 1.0 / math.sqrt(2.0)
SAFETY, SHRINK, GROW = 0.9, 0.2, 5.0
REJECTED = 1e6  # the scaled error of a step whose stage is not finite: shrinks it by SHRINK
EPS = 2.220446049250313e-16
# statuses of integrate() beside the stress-law statuses (OK, WALK_FAILED, ..., NOT_FINITE)
RUNNING, EVENT, END_TIME, STEP_TOO_SMALL = 10, 11, 12, 13


@njit(cache=True, error_model="numpy")
def event_values(y, mass, inertia, event_args, out):
    """Event functions of the state ``y`` into ``out`` (``event_args = (tip, points, depths,
    bottom, energy_stop)``, body frame): ``tip_z - H_j`` for every interface,
    then the deepest point of the body (ricochet when it rises through 0), the shallowest
    minus the bottom (perforation; 0 without a bottom), the axis's ``z`` component (axis
    parallel to the surface) and the kinetic energy without spin minus ``energy_stop``."""
    tip, points, depths, bottom, energy_stop = event_args
    rot = rotation_matrix(y[3:7])
    down0, down1, down2 = rot[2, 0], rot[2, 1], rot[2, 2]  # target z in body coordinates
    tip_z = y[2] + (down0 * tip[0] + down1 * tip[1] + down2 * tip[2])
    deepest = shallowest = tip_z
    for i in range(points.shape[0]):
        z = y[2] + (down0 * points[i, 0] + down1 * points[i, 1] + down2 * points[i, 2])
        deepest = max(deepest, z)
        shallowest = min(shallowest, z)
    n = depths.shape[0]
    for j in range(n):
        out[j] = tip_z - depths[j]
    out[n] = deepest
    out[n + 1] = shallowest - bottom if bottom < np.inf else 1.0
    out[n + 2] = down0
    energy = 0.5 * mass * (y[7] * y[7] + y[8] * y[8] + y[9] * y[9]) + 0.5 * (
        inertia[1] * y[11] * y[11] + inertia[2] * y[12] * y[12])
    out[n + 3] = energy - energy_stop
    return out


@njit(cache=True, error_model="numpy")
def scaled_rms(x, y0, y1, rtol, atol):
    """``||x_i / (atol_i + rtol max(|y0_i|, |y1_i|))||_rms`` over the 14 rigid-body state
    components (``atol``: an array of absolute tolerances, one per state component in its
    unit, of which the first 14 are read; a held contact's load fractions are left out). The
    quaternion's four terms are summed as ``(q_0^2 + q_1^2) + (q_2^2 + q_3^2)`` after the
    others, so that the mirror shot (which permutes them, :func:`cavex.analytic.
    surface_force.mirror_state`) gets the same bits."""
    e = np.empty(14)
    for k in range(14):
        e[k] = x[k] / (atol[k] + rtol * max(abs(y0[k]), abs(y1[k])))
    total = 0.0
    for k in range(14):
        if k < 3 or k > 6:
            total += e[k] * e[k]
    total += (e[3] * e[3] + e[4] * e[4]) + (e[5] * e[5] + e[6] * e[6])
    return math.sqrt(total / 14.0)


@njit(cache=True, error_model="numpy")
def initial_step(y, f, rtol, atol, largest):
    """First step: ``0.01 ||y|| / ||f||`` in the scaled norm (Hairer, Norsett and Wanner's
    first guess), ``1e-6`` when either is tiny, at most ``largest``."""
    d0 = scaled_rms(y, y, y, rtol, atol)
    d1 = scaled_rms(f, y, y, rtol, atol)
    if d0 < 1e-5 or d1 < 1e-5:
        return min(largest, 1e-6)
    return min(largest, 0.01 * d0 / d1)


@njit(cache=True, error_model="numpy", inline="always")
def hermite(s, h, y0, f0, y1, f1, out):
    """Cubic Hermite interpolant of a step of length ``h`` at the fraction ``s``."""
    s2, s3 = s * s, s * s * s
    a0 = 2.0 * s3 - 3.0 * s2 + 1.0
    b0 = (s3 - 2.0 * s2 + s) * h
    a1 = -2.0 * s3 + 3.0 * s2
    b1 = (s3 - s2) * h
    for k in range(y0.shape[0]):
        out[k] = a0 * y0[k] + b0 * f0[k] + a1 * y1[k] + b1 * f1[k]
    return out


@njit(cache=True, error_model="numpy")
def _solve6(matrix, rhs):
    """``matrix^-1 rhs`` (6 x 6, Gaussian elimination with partial pivoting; a pivot chosen by
    magnitude, so that a sign-mirrored system gives the sign-mirrored solution exactly)."""
    a = matrix.copy()
    x = rhs.copy()
    for col in range(6):
        pivot = col
        for r in range(col + 1, 6):
            if abs(a[r, col]) > abs(a[pivot, col]):
                pivot = r
        if pivot != col:
            for c in range(6):
                a[col, c], a[pivot, c] = a[pivot, c], a[col, c]
            x[col], x[pivot] = x[pivot], x[col]
        for r in range(col + 1, 6):
            factor = a[r, col] / a[col, col]
            for c in range(col, 6):
                a[r, c] -= factor * a[col, c]
            x[r] -= factor * x[col]
    for r in range(5, -1, -1):
        total = x[r]
        for c in range(r + 1, 6):
            total -= a[r, c] * x[c]
        x[r] = total / a[r, r]
    return x


@njit(cache=True, error_model="numpy", inline="always")
def _stage(matrix, f, out):
    """``(I - gamma h J)^-1 f`` for ``J`` zero but the ``(v, omega)`` block (``y[7:13]``)."""
    out[:] = f
    out[7:13] = _solve6(matrix, f[7:13])
    return out


@njit(cache=True, error_model="numpy")
def _held_stage(matrix, jac, gh, partners, f, out):
    """``(I - gamma h J)^-1 f`` with the held contact: ``J`` has the blocks ``D`` (the
    dashpot's damping, ``jac[0:6]``), ``B_i`` (the ``(v, omega)`` rates by the fraction
    ``phi_i``), ``C_i`` (its rate by ``(v, omega)``) and ``E_i`` (by itself) of
    :func:`cavex.analytic.penetration.surface_force.derivative`; eliminating
    ``k_phi_i = (f_phi_i + gamma h C_i k_v) / (1 - gamma h E_i)`` leaves
    ``(I - gamma h D - (gamma h)^2 sum B_i C_i^T / (1 - gamma h E_i)) k_v
    = f_v + gamma h sum B_i f_phi_i / (1 - gamma h E_i)``, ``matrix`` its left side
    (:func:`_held_matrix`). The sums over the elements are taken in mirror pairs
    (``partners``), as the loads are."""
    n = partners.shape[0]
    out[:] = f
    rhs = np.zeros(6)
    one = np.empty(6)
    for i in range(n):
        j = partners[i]
        if j < i:
            continue
        w = f[14 + i] / (1.0 - gh * jac[6 + 2 * n + i, 0])
        for r in range(6):
            one[r] = jac[6 + i, r] * w
        if j != i:
            w = f[14 + j] / (1.0 - gh * jac[6 + 2 * n + j, 0])
            for r in range(6):
                one[r] += jac[6 + j, r] * w
        rhs += one
    for r in range(6):
        rhs[r] = f[7 + r] + gh * rhs[r]
    kv = _solve6(matrix, rhs)
    out[7:13] = kv
    for i in range(n):
        coupling = 0.0
        for r in range(6):
            coupling += jac[6 + n + i, r] * kv[r]
        out[14 + i] = (f[14 + i] + gh * coupling) / (1.0 - gh * jac[6 + 2 * n + i, 0])
    return out


@njit(cache=True, error_model="numpy")
def _held_matrix(jac, gh, partners):
    """The left side of :func:`_held_stage`'s ``(v, omega)`` system (pairs summed first)."""
    n = partners.shape[0]
    total = np.zeros((6, 6))
    one = np.empty((6, 6))
    for i in range(n):
        j = partners[i]
        if j < i:
            continue
        for second in range(2 if j != i else 1):
            k = j if second else i
            w = gh * gh / (1.0 - gh * jac[6 + 2 * n + k, 0])
            for r in range(6):
                wb = w * jac[6 + k, r]
                for c in range(6):
                    if second:
                        one[r, c] += wb * jac[6 + n + k, c]
                    else:
                        one[r, c] = wb * jac[6 + n + k, c]
        total += one
    matrix = np.empty((6, 6))
    for r in range(6):
        for c in range(6):
            matrix[r, c] = (1.0 if r == c else 0.0) - gh * jac[r, c] - total[r, c]
    return matrix


@njit(cache=True, error_model="numpy")
def ros2_step(y, f, jac, h, rtol, atol, mass, inertia, surface, y1):
    """One ROS2 step of length ``h`` from ``y`` (``f = f(y)``, ``jac`` its damping block)
    into ``y1``; returns ``(scaled error, status, V_n)`` (module docstring). With the held
    contact (``jac`` taller than 6 rows) the stages are :func:`_held_stage`, the load
    fractions of ``y1`` are clipped to ``[0, 1]`` (round-off) and left out of the error norm
    (their error acts through the velocities, which are in it)."""
    if jac.shape[0] > 6:
        return _held_step(y, f, jac, h, rtol, atol, mass, inertia, surface, y1)
    matrix = np.empty((6, 6))
    for r in range(6):
        for c in range(6):
            matrix[r, c] = (1.0 if r == c else 0.0) - GAMMA * h * jac[r, c]
    k1 = _stage(matrix, f, np.empty(14))
    stage = np.empty(14)
    for k in range(14):
        stage[k] = y[k] + h * k1[k]
    fstage, _, status, vn = derivative(stage, mass, inertia, *surface)
    if status == NOT_FINITE:  # the stage overshot: a rejected step (the largest shrink)
        return REJECTED, OK, vn
    if status != OK:
        return np.inf, status, vn
    for k in range(14):
        stage[k] = fstage[k] - 2.0 * k1[k]
    k2 = _stage(matrix, stage, np.empty(14))
    for k in range(14):
        y1[k] = y[k] + h * (1.5 * k1[k] + 0.5 * k2[k])
        stage[k] = 0.5 * h * (k1[k] + k2[k])
    estimate = _stage(matrix, stage, np.empty(14))  # filtered: (I - gamma h J)^-1 e
    return scaled_rms(estimate, y, y1, rtol, atol), OK, 0.0


@njit(cache=True, error_model="numpy")
def _held_step(y, f, jac, h, rtol, atol, mass, inertia, surface, y1):
    """:func:`ros2_step` with the held contact."""
    size = y.shape[0]
    partners = surface[4]
    gh = GAMMA * h
    matrix = _held_matrix(jac, gh, partners)
    k1 = _held_stage(matrix, jac, gh, partners, f, np.empty(size))
    stage = np.empty(size)
    for k in range(size):
        stage[k] = y[k] + h * k1[k]
    fstage, _, status, vn = derivative(stage, mass, inertia, *surface)
    if status != OK:
        return np.inf, status, vn
    for k in range(size):
        stage[k] = fstage[k] - 2.0 * k1[k]
    k2 = _held_stage(matrix, jac, gh, partners, stage, np.empty(size))
    for k in range(size):
        y1[k] = y[k] + h * (1.5 * k1[k] + 0.5 * k2[k])
        stage[k] = 0.5 * h * (k1[k] + k2[k])
    for k in range(14, size):
        y1[k] = min(max(y1[k], 0.0), 1.0)
    estimate = _held_stage(matrix, jac, gh, partners, stage, np.empty(size))
    return scaled_rms(estimate, y, y1, rtol, atol), OK, 0.0


@njit(cache=True, error_model="numpy")
def _fires(g0, g1, direction):
    """``solve_ivp``'s rule: does an event with these values at the ends of a step fire?"""
    up = g0 <= 0.0 and g1 >= 0.0
    down = g0 >= 0.0 and g1 <= 0.0
    return ((up and direction > 0.0) or (down and direction < 0.0)
            or ((up or down) and direction == 0.0))


@njit(cache=True, error_model="numpy", inline="always")
def _time_resolution(t, h):
    """4 ulp of the times of a step from ``t`` to ``t + h``: where a root is resolved."""
    return 4.0 * EPS * max(abs(t), abs(t + h))


@njit(cache=True, error_model="numpy")
def _hermite_root(e, g_start, t, h, y, f, y1, f1, mass, inertia, event_args, gs, probe):
    """Fraction of the step at which event ``e`` changes sign on the cubic Hermite
    interpolant (bisection to 4 ulp of ``t``; the returned end is on the far side)."""
    lo, hi = 0.0, 1.0
    while (hi - lo) * h > _time_resolution(t, h) and hi - lo > EPS:
        mid = 0.5 * (lo + hi)
        hermite(mid, h, y, f, y1, f1, probe)
        event_values(probe, mass, inertia, event_args, gs)
        if (gs[e] >= 0.0) == (g_start >= 0.0) and gs[e] != 0.0:
            lo = mid
        else:
            hi = mid
    return hi


@njit(cache=True, error_model="numpy")
def _land(e, fraction, t, h, y, f, jac, rtol, atol, mass, inertia, surface, event_args, gs,
          out):
    """The state at the root of event ``e`` reached by a ROS2 step from ``(t, y)`` (not by the
    interpolant, whose lateral velocity is off the contact's slow manifold by up to the
    interpolation error and would carry a spurious damper force): secant iteration on the step
    length, from the interpolant's root, to 4 ulp of ``t``. Returns ``(fraction, status,
    V_n, steps taken)`` with the state in ``out``."""
    tolerance = _time_resolution(t, h) / h
    s_prev, s = fraction, fraction * (1.0 - 1e-6)
    _, status, vn = ros2_step(y, f, jac, s_prev * h, rtol, atol, mass, inertia, surface, out)
    calls = 1
    if status != OK:
        return s_prev, status, vn, calls
    g_prev = event_values(out, mass, inertia, event_args, gs)[e]
    for _ in range(50):
        _, status, vn = ros2_step(y, f, jac, s * h, rtol, atol, mass, inertia, surface, out)
        calls += 1
        if status != OK:
            return s, status, vn, calls
        g = event_values(out, mass, inertia, event_args, gs)[e]
        if g == 0.0 or g == g_prev:
            return s, OK, 0.0, calls
        s_new = min(max(s - g * (s - s_prev) / (g - g_prev), 0.0), 1.0)
        s_prev, g_prev, s = s, g, s_new
        if abs(s - s_prev) <= tolerance:
            break
    _, status, vn = ros2_step(y, f, jac, s * h, rtol, atol, mass, inertia, surface, out)
    return s, status, vn, calls + 1


@njit(cache=True, error_model="numpy")
def integrate(t, y, f, jac, h, t_end, min_step, rtol, atol, max_steps, directions, event_args,
              ts, ys, fs, mass, inertia, surface):
    """Advance from ``(t, y)`` (``f = f(y)``, ``jac`` its damping block, overwritten with that
    of the last accepted state, from which a RUNNING integration resumes) by at most
    ``max_steps`` accepted steps of initial size ``h`` (none below ``min_step``: the step size
    has collapsed, STEP_TOO_SMALL), writing the accepted points into
    ``ts[1:], ys[1:], fs[1:]`` (row 0 is the start). Returns ``(status, steps, h_next,
    evaluations, event, V_n)``: ``status`` RUNNING (``max_steps`` taken), EVENT (the last row
    is the root of event ``event``), END_TIME, STEP_TOO_SMALL or a failed stress-law status of
    the right-hand side (``V_n`` of the failed element). ``event_args`` are the ``event_args``
    of :func:`event_values`, ``surface`` those of
    :func:`cavex.analytic.penetration.surface_force.derivative` after ``inertia``."""
    y = y.copy()
    n_events = directions.shape[0]
    g0 = event_values(y, mass, inertia, event_args, np.empty(n_events))
    g1 = np.empty(n_events)
    gs = np.empty(n_events)
    y1 = np.empty(y.shape[0])
    probe = np.empty(y.shape[0])
    ts[0] = t
    ys[0] = y
    fs[0] = f
    steps = 0
    evaluations = 0
    while steps < max_steps:
        if t >= t_end:
            return END_TIME, steps, h, evaluations, -1, 0.0
        if h < min_step:
            return STEP_TOO_SMALL, steps, h, evaluations, -1, 0.0
        h = min(h, t_end - t)
        err, status, vn = ros2_step(y, f, jac, h, rtol, atol, mass, inertia, surface, y1)
        evaluations += 1
        if status != OK:
            return status, steps, h, evaluations, -1, vn
        if not math.isfinite(err):
            return STEP_TOO_SMALL, steps, h, evaluations, -1, 0.0
        if err > 1.0:
            h *= max(SHRINK, SAFETY / math.sqrt(err))
            continue
        f1, jac1, status, vn = derivative(y1, mass, inertia, *surface)
        evaluations += 1
        if status != OK:
            return status, steps, h, evaluations, -1, vn
        event_values(y1, mass, inertia, event_args, g1)
        # the earliest root among the events that fire in this step, on the interpolant
        first, root = -1, np.inf
        for e in range(n_events):
            if _fires(g0[e], g1[e], directions[e]):
                fraction = _hermite_root(e, g0[e], t, h, y, f, y1, f1, mass, inertia,
                                         event_args, gs, probe)
                if fraction < root:
                    first, root = e, fraction
        if first >= 0:  # land on it with a step of the method
            root, status, vn, calls = _land(first, root, t, h, y, f, jac, rtol, atol, mass,
                                            inertia, surface, event_args, gs, probe)
            evaluations += calls
            if status == OK:
                f_root, _, status, vn = derivative(probe, mass, inertia, *surface)
                evaluations += 1
            if status != OK:
                return status, steps, h, evaluations, -1, vn
            steps += 1
            ts[steps] = t + root * h
            ys[steps] = probe
            fs[steps] = f_root
            return EVENT, steps, h, evaluations, first, 0.0
        steps += 1
        t = t + h
        y[:] = y1
        f = f1
        jac[:, :] = jac1
        g0[:] = g1
        ts[steps] = t
        ys[steps] = y
        fs[steps] = f
        h *= min(GROW, max(SHRINK, SAFETY / math.sqrt(max(err, 1e-10))))
    return RUNNING, steps, h, evaluations, -1, 0.0
