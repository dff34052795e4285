r"""One Newton iteration for every case of a stack: generalized-alpha step equations, per-case
convergence, and the line-searched last attempt.

The semi-discrete equations in radial dof order are ``M a + f_int(u) = r`` with ``r`` the
reaction at the prescribed dofs (the cavity wall under displacement control, the outer boundary
when fixed) or the follower wall load ``p 4 pi r_wall^2`` under pressure control. One step
``n -> n+1`` solves, on the free dofs,

.. math:: M[(1-\alpha_m) a_{n+1} + \alpha_m a_n] + (1-\alpha_f) f(u_{n+1}) + \alpha_f f(u_n) = 0,

with the Newmark updates
``a_{n+1} = (u_{n+1} - u_n - dt v_n)/(beta dt^2) - (1/(2 beta) - 1) a_n``,
``v_{n+1} = v_n + dt[(1 - gamma) a_n + gamma a_{n+1}]`` and
``alpha_m = (2 rho_inf - 1)/(rho_inf + 1)``, ``alpha_f = rho_inf/(rho_inf + 1)``,
``gamma = 1/2 - alpha_m + alpha_f``, ``beta = (1 - alpha_m + alpha_f)^2/4`` (Chung-Hulbert,
second order; ``rho_inf`` is the spectral radius at infinite frequency). The plastic state is
return-mapped at ``u_{n+1}`` (backward Euler), so ``f(u_n)`` is the converged force of the
previous step. The Newton matrix is ``(1-alpha_m)/(beta dt^2) M + (1-alpha_f) K_T``; without
inertia (quasi-static load stepping) it is ``K_T`` and the residual ``f(u_{n+1})``.

Convergence, the force yardstick and failures (folded element, non-finite value, singular
tangent, a stall, no convergence) are decided per case (:func:`newton`); a converged case is
frozen and a failed one drops out. A *stall* fails an attempt early: its relative residual
``max |r_free| / scale`` has not reached a new low (the predictor's residual not counted) in
``STALL_ITERATIONS`` = 4 iterations. Measured on the 105 cases of the issue grid and their
companions without the rule: the rule fires on every one of the 763 attempts that did not
converge in 30 iterations, at iteration 7 (median; 90 % by 12), and on 0.7 % of the 17812
attempts that converged (those are cut back instead, like a failure); 3 iterations would fire
on 3 % and cut back undamped runs (``rho_inf = 1``) often enough to excite their spurious
modes (docs/fem.md, "Time-step policy").

The iteration of a stack runs compiled (:func:`iterate`: kernel, step equations, rules, banded
solve and update in one call), so a Newton iteration costs the kernels' work and no
interpreter time per iteration; a case that is done is skipped by the kernels, so one hard case
costs its own work only. Every case gets the same bits alone and inside any stack.
:func:`newton_line_search` is the last attempt of a step that fails at the deepest cut-back
(:mod:`cavex.fem.solver`).
"""

import math

import numpy as np
from numba import njit

from cavex.fem.banded import solve_blocks
from cavex.fem.element import assemble_cases
from cavex.fem.records import (
    Assembly,
    Convergence,
    Equations,
    Layout,
    PointResponse,
    Progress,
    Scheme,
    StepStart,
)

MAX_ITERATIONS = 30     # Newton iterations per attempt
STALL_ITERATIONS = 4    # an attempt fails once its residual has not reached a new low in this many
LINE_SEARCH_EVALUATIONS = 20  # residual evaluations per line search (Illinois steps)
LINE_SEARCH_TOLERANCE = 0.5   # accept s once |G(s)| <= this * |G(0)|


class StepFailure(Exception):
    """A Newton iteration that did not converge (internal: triggers a cut-back)."""


def converged(iteration, r_max, scale, tol):
    """The convergence rule of every Newton iteration here: ``max |r_free| <= tol * scale``
    (``r_max`` NaN never converges), from the second iteration on (the first residual is the
    predictor's). Scalars or arrays per case."""
    return (iteration > 1) & (r_max <= tol * scale)


# why a case's attempt failed, by the status code of :func:`iterate` (0: iterating, 1: converged)
FAILURES = {
    2: "non-positive stretch",
    3: "non-finite residual",
    4: f"Newton stalled: no new low of the residual in {STALL_ITERATIONS} iterations",
    5: "singular tangent",
    6: "non-finite increment",
    7: f"Newton did not converge in {MAX_ITERATIONS} iterations",
}


def newton(stack, w, scheme, tol):
    """Generalized-alpha Newton iteration of every case of ``stack`` with ``w.active`` (a
    :class:`~cavex.fem.records.StepStart`), from the predictor (:func:`predict`), in the time
    scheme ``scheme`` (:class:`~cavex.fem.records.Scheme`).

    The iteration runs compiled (:func:`iterate`), every case with its own convergence
    (:func:`converged`), stall and failure, a case that is done skipped by the kernels.
    Returns ``(u, a, f, response, iterations, reasons, evaluations)``; ``reasons[c]`` is None
    for a converged case, else why it failed; ``evaluations[c]`` counts the case's residual
    evaluations (kernel passes). Inactive cases come back as converged (their values are not
    to be used).
    """
    k = stack.n_cases
    u, assembly, response, equations = newton_buffers(stack)
    progress = Progress(status=np.where(w.active, 0, 1).astype(np.int64),
                        iterations=np.zeros(k, dtype=np.int64),
                        evaluations=np.zeros(k, dtype=np.int64))
    convergence = Convergence(tol, MAX_ITERATIONS, STALL_ITERATIONS)
    iterate(u, tuple(w), tuple(stack.layout), stack.material, tuple(scheme), tuple(convergence),
            tuple(assembly), tuple(response), tuple(equations), tuple(progress))
    status, iterations = progress.status, progress.iterations
    reasons = [FAILURES.get(code) for code in status.tolist()]
    iterations[status != 1] = 0
    return u, equations.a, assembly.f, response, iterations, reasons, progress.evaluations


def newton_buffers(stack):
    """The arrays :func:`newton` works in, made once per stack and reused by every call on it
    (every value a call returns is written by that call; the solver copies what it keeps
    before the next call): ``(u, assembly, response, equations)``
    (:class:`~cavex.fem.records.Assembly`, :class:`~cavex.fem.records.PointResponse`,
    :class:`~cavex.fem.records.Equations`)."""
    if not hasattr(stack, "_newton_buffers"):
        assembly, response = stack.new_buffers()
        stack._newton_buffers = (np.zeros(stack.ndof), assembly, response, Equations(
            a=np.zeros(stack.ndof), r_free=np.zeros(stack.ndof),
            jac=np.zeros_like(assembly.band), scale=np.zeros(stack.n_cases),
            r_max=np.zeros(stack.n_cases)))
    return stack._newton_buffers


@njit(cache=True, error_model="numpy")
def stalls(relative, best, stalled, c, limit):
    """The stall rule for case ``c`` at a relative residual ``relative`` (from the second
    iteration on): a new low resets the count (``best[c]``, ``stalled[c]``, updated in place);
    True once ``limit`` iterations in a row brought none."""
    if relative < best[c]:
        best[c] = relative
        stalled[c] = 0
        return False
    stalled[c] += 1
    return stalled[c] >= limit


@njit(cache=True, error_model="numpy")
def iterate(u, w, layout, material, scheme, convergence, assembly, response, equations,
            progress):
    """Compiled body of :func:`newton`: the iterations of every case with ``progress.status``
    0 from the predictor (:func:`predict_cases`, written into ``u``, which is then updated in
    place, as every output: ``assembly``, ``response``, ``equations``, ``progress``). ``w`` is
    the :class:`~cavex.fem.records.StepStart`, ``layout`` the stack's
    :class:`~cavex.fem.records.Layout`, ``material`` its record per element; the records come
    as plain tuples (:mod:`cavex.fem.records`, the boundary rule). Per iteration: the
    kernel (:func:`cavex.fem.element.assemble_cases`), the step equations
    (:func:`step_equations`), the rules (folded, non-finite, :func:`converged`, stall), the
    banded solve (:func:`cavex.fem.banded.solve_blocks`, fixed dofs as identity rows) and the
    update. ``status`` per case on return: 1 converged (``iterations`` = Newton solves), else
    the failure code of :data:`FAILURES`; ``evaluations`` is incremented per kernel pass."""
    w, layout, scheme = StepStart(*w), Layout(*layout), Scheme(*scheme)
    convergence, assembly, response = Convergence(*convergence), Assembly(*assembly), \
        PointResponse(*response)
    equations, progress = Equations(*equations), Progress(*progress)
    status, iterations, evaluations = progress.status, progress.iterations, progress.evaluations
    dof_start, dof_count, free = layout.dof_start, layout.dof_count, layout.free
    f, band, folded = assembly.f, assembly.band, assembly.folded
    r_free, jac, scale, r_max = equations.r_free, equations.jac, equations.scale, equations.r_max
    tol = convergence.tol
    k = dof_start.size
    predict_cases(u, w, status == 0, layout, scheme.dynamic)
    done = status != 0
    best = np.full(k, np.inf)
    stalled = np.zeros(k, dtype=np.int64)
    flat = jac.reshape(-1)
    rhs = np.zeros(u.size)
    du = np.zeros(u.size)
    singular = np.zeros(k, dtype=np.bool_)
    for iteration in range(1, convergence.max_iterations + 1):
        skip = done.copy()
        for c in range(k):
            if not skip[c]:
                evaluations[c] += 1
                s0, m = dof_start[c], dof_count[c]
                f[s0:s0 + m] = 0.0
                band[:, s0:s0 + m] = 0.0
        assemble_cases(u, layout, material, w.theta_p, w.gamma_p, skip, assembly, response)
        for c in range(k):
            if not done[c] and folded[c]:
                status[c] = 2
                done[c] = True
        step_equations(u, w, layout, scheme, assembly, done, equations)
        for c in range(k):
            if done[c]:
                continue
            if np.isnan(r_max[c]):
                status[c] = 3
                done[c] = True
            elif iteration > 1 and r_max[c] <= tol * scale[c]:  # converged()
                status[c] = 1
                iterations[c] = iteration - 1
                done[c] = True
            elif iteration > 1 and stalls(r_max[c] / scale[c], best, stalled, c,
                                          convergence.stall_iterations):
                status[c] = 4
                done[c] = True
        if done.all():
            return
        flat[layout.fixed_entries] = 0.0
        flat[layout.fixed_diagonal] = 1.0
        for i in range(u.size):
            rhs[i] = r_free[i] if free[i] else 0.0
            du[i] = 0.0
        singular[:] = False
        solve_blocks(jac, rhs, layout.degree, dof_start, dof_count, ~done, du, singular)
        for c in range(k):
            if done[c]:
                continue
            if singular[c]:
                status[c] = 5
                done[c] = True
                continue
            s0, m = dof_start[c], dof_count[c]
            for i in range(s0, s0 + m):
                if not np.isfinite(du[i]):
                    status[c] = 6
                    done[c] = True
                    break
            if not done[c]:
                for i in range(s0, s0 + m):
                    if free[i]:
                        u[i] = u[i] - du[i]
    for c in range(k):
        if not done[c]:
            status[c] = 7


def predict(stack, w, dynamic):
    """First Newton iterate of every active case (:func:`predict_cases`), a new array."""
    u = np.empty(stack.ndof)
    predict_cases(u, tuple(w), w.active, tuple(stack.layout), dynamic)
    return u


@njit(cache=True, error_model="numpy")
def predict_cases(u, w, active, layout, dynamic):
    """First Newton iterate of every active case; the wall at its prescribed displacement
    under displacement control.

    The last step's increment scaled to this step: by ``dt / dt_old`` dynamic (and under
    pressure control), and quasi-static by the ratio of this step's prescribed wall increment
    to the last one; at the first step ``u0 + dt v0`` dynamic and ``u0`` quasi-static.
    Quasi-static pseudo-time steps are all 1 while the wall increments grow 3 % a step: scaled
    by ``dt / dt_old`` the predictor lags, and on the issue grid's quasi-static cases the wall
    ratio saves 41 % of the residual evaluations and three quarters of the cut-backs
    (docs/fem.md, "Time-step policy"). Dynamic, ``u0 + dt v0`` would save 8 % but excites the
    spurious modes of an undamped run (``rho_inf = 1``).

    Written into ``u``; the prescribed dofs (and every dof of an inactive case) keep ``u0``,
    the wall its prescribed displacement ``load`` under displacement control."""
    w, layout = StepStart(*w), Layout(*layout)
    u0, v0, du_prev, load, dt = w.u0, w.v0, w.du_prev, w.load, w.dt
    dof_start, dof_count, free, pressure = (layout.dof_start, layout.dof_count, layout.free,
                                            layout.pressure)
    for c in range(dof_start.size):
        s0, m = dof_start[c], dof_count[c]
        if dynamic or pressure:
            ratio = dt[c] / w.dt_old[c]
        else:
            ratio = (load[c] - u0[s0]) / du_prev[s0]
            if not np.isfinite(ratio):
                ratio = 1.0
        for i in range(s0, s0 + m):
            if free[i] and active[c]:
                if w.has_prev[c]:
                    u[i] = u0[i] + ratio * du_prev[i]
                elif dynamic:
                    u[i] = u0[i] + dt[c] * v0[i]
                else:
                    u[i] = u0[i]
            elif i == s0 and not pressure:
                u[i] = load[c]
            else:
                u[i] = u0[i]


def equations(stack, w, scheme, u, assembly, skip=None, out=None):
    """The :class:`~cavex.fem.records.Equations` ``(a, r_free, jac, scale, r_max)`` of the
    step's equations at the iterate ``u`` with the element kernel's ``assembly`` (stack layout;
    ``r_free`` is zero at the prescribed dofs; per case ``scale``, the largest of the point
    force yardstick, the reactions and the wall load, and ``r_max = max |r_free|``, NaN where
    the residual is not finite). ``jac`` is a buffer that :meth:`Stack.solve` may overwrite.
    Cases with ``skip`` keep their values in ``out`` (the previous call's result, reused in
    place)."""
    k = stack.n_cases
    if out is None:
        out = Equations(a=np.zeros(stack.ndof), r_free=np.zeros(stack.ndof),
                        jac=np.zeros_like(assembly.band), scale=np.zeros(k), r_max=np.zeros(k))
    if skip is None:
        skip = np.zeros(k, dtype=bool)
    step_equations(u, tuple(w), tuple(stack.layout), tuple(scheme), tuple(assembly), skip,
                   tuple(out))
    return out


@njit(cache=True, error_model="numpy")
def step_equations(u, w, layout, scheme, assembly, skip, out):
    """Compiled body of :func:`equations` (module docstring: the generalized-alpha residual
    and Newton matrix; the inertia from the banded mass matrix)."""
    w, layout, scheme = StepStart(*w), Layout(*layout), Scheme(*scheme)
    assembly, out = Assembly(*assembly), Equations(*out)
    u0, v0, a0, f0, dt, load = w.u0, w.v0, w.a0, w.f0, w.dt, w.load
    f, band, force_scale = assembly.f, assembly.band, assembly.force_scale
    a, r_free, jac, scale, r_max = out.a, out.r_free, out.jac, out.scale, out.r_max
    mass_band, dof_start, dof_count, free = (layout.mass_band, layout.dof_start,
                                             layout.dof_count, layout.free)
    p, pressure, R_dofs = layout.degree, layout.pressure, layout.R_dofs
    alpha_m, alpha_f, beta, dynamic = scheme.alpha_m, scheme.alpha_f, scheme.beta, scheme.dynamic
    for c in range(dof_start.size):
        if skip[c]:
            continue
        s0, m = dof_start[c], dof_count[c]
        h = dt[c]
        c_m = (1.0 - alpha_m) / (beta * h * h)
        for i in range(s0, s0 + m):
            if dynamic:
                a[i] = (u[i] - u0[i] - h * v0[i]) / (beta * h * h) - (0.5 / beta - 1.0) * a0[i]
            else:
                a[i] = 0.0
        biggest = 0.0
        finite = True
        reaction = 0.0
        for i in range(s0, s0 + m):
            if dynamic:
                inertia = 0.0
                for j in range(max(s0, i - p), min(s0 + m, i + p + 1)):
                    inertia += mass_band[p + i - j, j] * ((1.0 - alpha_m) * a[j]
                                                          + alpha_m * a0[j])
                residual = inertia + (1.0 - alpha_f) * f[i] + alpha_f * f0[i]
                for r in range(2 * p + 1):
                    jac[r, i] = (1.0 - alpha_f) * band[r, i] + c_m * mass_band[r, i]
            else:
                residual = f[i]
                for r in range(2 * p + 1):
                    jac[r, i] = band[r, i]
            if pressure and i == s0:
                r_wall = R_dofs[i] + u[i]
                residual -= load[c] * 4.0 * np.pi * r_wall * r_wall
                jac[p, i] -= load[c] * 8.0 * np.pi * r_wall
            if free[i]:
                r_free[i] = residual
                finite = finite and np.isfinite(residual)
                biggest = max(biggest, abs(residual))
            else:
                r_free[i] = 0.0
                reaction = max(reaction, abs(residual))
        r_max[c] = biggest if finite else np.nan
        sc = max(force_scale[c], 1e-300, reaction)
        if pressure:
            sc = max(sc, abs(load[c]) * 4.0 * np.pi * R_dofs[s0] * R_dofs[s0])
        scale[c] = sc


def replace_points(response, where, other):
    """Overwrite the point arrays of ``response`` at ``where`` (elements) by ``other``'s."""
    for value, replacement in zip(response, other, strict=True):
        value[where] = replacement


# ------------------------------------------------------------------------- the line search
def _dot(x, y):
    """``x . y`` correctly rounded (``math.fsum``): the same bits whatever the array layout."""
    return math.fsum(x * y)


def line_search_newton(evaluate, solve, x, tol, max_iterations):
    """Newton iteration with an energy line search; the last resort of a failing step.

    ``evaluate(x)`` returns a tuple starting with the free-dof residual ``r`` and the force
    yardstick ``scale`` at the free-dof iterate ``x`` (it raises :class:`StepFailure` where the
    equations cannot be evaluated); ``solve(out, r)`` returns the Newton increment ``J^-1 r``
    for the tangent of ``out``. Converged: :func:`converged`, as in :func:`newton`. Returns
    ``(x, out, iterations)``.

    The full step ``d = -J^-1 r`` is taken unless it increases ``max |r|``; then ``s`` in
    ``(0, 1)`` is sought with ``G(s) = d . r(x + s d) = 0`` (the energy along the step is
    stationary; ``G(0) = -r^T J^-1 r < 0``), by regula falsi with the Illinois modification
    on the bracket ``[0, 1]`` when ``G(1) > 0``, until ``|G(s)| <= 0.5 |G(0)|``. This reaches
    the narrow set of states in which a point lies on the Mohr-Coulomb face next to the apex
    of the cone, which plain Newton steps over in both directions (a two-cycle between an
    elastic and an apex state; docs/fem.md) and which halving the step on the residual norm
    does not find.
    """
    out = evaluate(x)
    for iteration in range(1, max_iterations + 1):
        r, scale = out[0], out[1]
        norm = np.max(np.abs(r))
        if converged(iteration, norm, scale, tol):
            return x, out, iteration - 1
        d = -solve(out, r)
        if not np.all(np.isfinite(d)):
            raise StepFailure("non-finite increment")
        trial = evaluate(x + d)
        s = 1.0
        if np.max(np.abs(trial[0])) > norm:
            s, trial = _illinois(evaluate, x, d, _dot(d, r), _dot(d, trial[0]), trial)
        x = x + s * d
        out = trial
    raise StepFailure(f"Newton with line search did not converge in {max_iterations} "
                      "iterations")


def _illinois(evaluate, x, d, g0, g1, out1):
    """``(s, evaluate(x + s d))`` with ``|G(s)| <= 0.5 |G(0)|`` (see :func:`line_search_newton`);
    the full step when ``[0, 1]`` does not bracket a root of ``G``."""
    if not g0 < 0.0 < g1:
        return 1.0, out1
    lo, g_lo, hi, g_hi = 0.0, g0, 1.0, g1
    side = 0
    s, out = 1.0, out1
    for _ in range(LINE_SEARCH_EVALUATIONS):
        s = hi - g_hi * (hi - lo) / (g_hi - g_lo)
        out = evaluate(x + s * d)
        g = _dot(d, out[0])
        if abs(g) <= LINE_SEARCH_TOLERANCE * abs(g0):
            break
        if g > 0.0:
            hi, g_hi = s, g
            if side > 0:
                g_lo *= 0.5
            side = 1
        else:
            lo, g_lo = s, g
            if side < 0:
                g_hi *= 0.5
            side = -1
    return s, out


def newton_line_search(stack, w, scheme, tol):
    """The Newton iteration of the one case of ``stack`` with the line search of
    :func:`line_search_newton`. Returns ``(u, a, f, response, iterations, reason)`` (reason
    None when converged)."""
    start = predict(stack, w, scheme.dynamic)
    free = stack.free

    def evaluate(x):
        u = start.copy()
        u[free] = x
        assembly, response = stack.assemble(u, w.theta_p, w.gamma_p)
        if assembly.folded[0]:
            raise StepFailure("non-positive stretch")
        a, r_free, jac, scale, r_max = equations(stack, w, scheme, u, assembly)
        if np.isnan(r_max[0]):
            raise StepFailure("non-finite residual")
        return r_free[free], scale[0], jac, u, a, assembly.f, response

    def solve(out, r):
        rhs = np.zeros(stack.ndof)
        rhs[free] = r
        du, singular = stack.solve(out[2].copy(), rhs, np.zeros(1, dtype=bool))
        if singular[0]:
            raise StepFailure("singular tangent")
        return du[free]

    try:
        _, out, iterations = line_search_newton(evaluate, solve, start[free], tol,
                                                MAX_ITERATIONS)
    except StepFailure as exc:
        return start, np.zeros_like(start), np.zeros_like(start), None, 0, str(exc)
    _, _, _, u, a, f, resp = out
    return u, a, f, resp, iterations, None
