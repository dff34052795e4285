r"""Many cavity expansions advanced together: one block-diagonal system per Newton iteration.

:func:`expand_cavities` runs a list of problems (layers, interfaces, velocity, radius) with shared
numerical settings and returns, for each, what a table needs (:class:`CaseResult`: wall stress,
error estimate, plastic radius). It computes exactly what :func:`cavex.fem.expand_cavity` computes
case by case (measured: identical to 1e-10 relative, in practice to the last bit), only faster:

- *One model of disconnected copies.* The cases of a batch are concatenated, element by element
  and dof by dof, into one stack (:class:`Stack`); the vectorised kernels of
  :class:`~cavex.fem.discretisation.FastAssembly` and the return map then run once per Newton
  iteration over all (case, element, point) triples. The global tangent is block diagonal with
  the bandwidth of one case, so the whole batch is one ``scipy.linalg.solve_banded`` call; the
  prescribed dofs (wall, outer boundary) become identity rows and columns. Partial pivoting never
  leaves a block (the entries coupling two blocks are exact zeros), so every block is factorised
  with the same operations as alone.
- *Per-case Newton.* Convergence, the force yardstick and failures (folded element, non-finite
  value, no convergence) are decided per case; a converged case is frozen (its re-assembled
  values do not change) and a failed one is replaced by an identity block. When few cases are
  left iterating, they continue on a smaller stack, so one hard case does not make the whole
  batch iterate.
- *Per-case stepping.* Every case follows its own step list (the geometric radius schedule, and
  the times ``t_k = (a_k - a0)/V`` of its velocity) and its own recursive step halving; a round
  advances every unfinished case by one (sub-)step, so cases whose cut-backs differ stay
  independent. The return-map branch (Mohr-Coulomb only, or multi-surface) is chosen per case.
  A case whose step still fails at the deepest cut-back gets the one-case path's last attempt,
  Newton with a line search (:func:`cavex.fem.solver.line_search_newton`), on a one-case stack.

Energies, field snapshots and histories are not kept; use :func:`cavex.fem.expand_cavity` (the
one-case path, also the debugging path) for those.
"""

import math
import time
from dataclasses import dataclass, field, replace
from types import SimpleNamespace

import numpy as np
from cavex.analytic.cavity import check_problem
from cavex.fem.constitutive import PointMaterial, hencky_mohr_coulomb, replace_points
from cavex.fem.discretisation import FastAssembly
from cavex.fem.expansion import (
    build_model,
    expand_cavity,
    radius_schedule,
    richardson_error,
    richardson_error_from_finer,
    wall_times,
)
from cavex.fem.fields import plastic_radius
from cavex.fem.settings import make_numerics
from cavex.fem.solver import Newmark, StepFailure, failure_message, line_search_newton
from scipy.linalg import LinAlgError, solve_banded
from scipy.sparse import csr_matrix

from cavex.errors import CavexInputError, CavexNumericalError, require

try:  # the compiled kernels; without numba the numpy kernels of the one-case path are used
    from cavex.fem import kernels
except ImportError:  # pragma: no cover - exercised only without numba
    kernels = None

MAX_ITERATIONS = 30     # Newton iterations per attempt, as RadialSolver's default
DEFAULT_BATCH = 200     # cases per stack (measured optimum on a 2-core machine: 100-400)
SHRINK_FRACTION = 0.25  # continue on a smaller stack when at most this fraction still iterates
MIN_SHRINK = 8          # ... and the stack has at least this many cases
ON_ERROR = ("return", "raise")
DISC_CACHE = 1024       # discretisations kept per process (a table has 2 per depth)
_DISCS = {}             # (layers, interfaces, radius, numerics) -> Discretisation


@dataclass
class CaseResult:
    """Outcome of one case of :func:`expand_cavities`.

    ``cavity_stress`` (Pa, compression positive), ``error_estimate`` (relative, None when not
    requested), ``plastic_radius`` (m) and the final nodal displacements ``u`` (radial dof order,
    m) are those :func:`cavex.fem.expand_cavity` returns; NaN (``u`` None) when the case failed,
    and ``error`` then holds the :class:`~cavex.errors.CavexNumericalError` (naming V, the step's
    cavity radius and the wall radius). ``stats``: ``elements``, ``dofs``, ``steps``,
    ``newton_iterations``, ``cutbacks`` of the main run, ``error_companion`` (``"coarse"``, or
    ``"finer"`` where the 2x coarser run failed) and its ``coarse_cavity_stress`` or
    ``finer_cavity_stress``, and ``refinements`` (see ``error_target``). ``numerics``: the
    settings of the run (those given, or refined ones), with which
    :func:`cavex.fem.expand_cavity` reproduces it.
    """

    velocity: float
    radius: float
    cavity_stress: float
    error_estimate: float | None
    plastic_radius: float
    u: np.ndarray | None
    stats: dict = field(default_factory=dict)
    error: CavexNumericalError | None = None
    numerics: dict = field(default_factory=dict)

    @property
    def ok(self):
        return self.error is None


# ---------------------------------------------------------------------------------- the stack
def _ranges(starts, counts):
    """Concatenated ``arange(s, s + c)`` for every pair (vectorised)."""
    counts = np.asarray(counts)
    total = int(counts.sum())
    if total == 0:
        return np.zeros(0, dtype=int)
    first = np.repeat(np.asarray(starts) - np.concatenate([[0], np.cumsum(counts)[:-1]]), counts)
    return first + np.arange(total)


def _starts(counts):
    return np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(int)


class Stack(FastAssembly):
    """Discretisations of several cases concatenated into one model of disconnected copies.

    Case ``c`` owns dofs ``dof_start[c] : dof_start[c] + dof_count[c]`` (its radial order) and
    elements ``el_start[c] : el_start[c] + el_count[c]``.
    """

    def __init__(self, discs, outer_fixed=True):
        d0 = discs[0]
        self.discs = list(discs)
        self.degree = p = d0.degree
        self.N = d0.N
        self.n_cases = k = len(discs)
        self.dof_count = np.array([d.ndof for d in discs])
        self.el_count = np.array([d.n_elements for d in discs])
        self.dof_start = _starts(self.dof_count)
        self.el_start = _starts(self.el_count)
        self.ndof = n = int(self.dof_count.sum())
        self.element_dofs = np.concatenate([d.element_dofs + o
                                            for d, o in zip(discs, self.dof_start, strict=True)])
        for name in ("dNdR", "R_points", "weights", "force_weights", "R_dofs", "mass_band"):
            setattr(self, name, np.concatenate([getattr(d, name) for d in discs],
                                               axis=1 if name == "mass_band" else 0))
        self.material = PointMaterial(**{name: np.concatenate([getattr(d.material, name)
                                                               for d in discs])
                                         for name in vars(d0.material)})
        self.element_case = np.repeat(np.arange(k), self.el_count)
        self.point_case = np.repeat(self.element_case[:, None], self.R_points.shape[1], axis=1)
        self.dof_case = np.repeat(np.arange(k), self.dof_count)
        nnz = np.array([d.mass.nnz for d in discs])
        indptr = np.concatenate([d.mass.indptr[:-1] + o for d, o in zip(discs, _starts(nnz),
                                                                         strict=True)]
                                + [[nnz.sum()]])
        self.mass = csr_matrix((np.concatenate([d.mass.data for d in discs]),
                                np.concatenate([d.mass.indices + o for d, o in
                                                zip(discs, self.dof_start, strict=True)]),
                                indptr), shape=(n, n))
        self.wall = self.dof_start
        self.outer_fixed = outer_fixed
        self.outer = self.dof_start + self.dof_count - 1
        fixed = np.concatenate([self.wall, self.outer]) if outer_fixed else self.wall
        self.free = np.ones(n, dtype=bool)
        self.free[fixed] = False
        # band entries of the fixed dofs' rows and columns (cleared, then a unit diagonal)
        rows = np.arange(2 * p + 1)
        col_entries = (rows[:, None] * n + fixed[None, :]).ravel()
        j = fixed[None, :] + np.arange(-p, p + 1)[:, None]
        row_entries = ((p + fixed[None, :] - j) * n + j)[(j >= 0) & (j < n)]
        self.fixed_entries = np.concatenate([col_entries, row_entries])
        self.fixed_diagonal = p * n + fixed

    def subset(self, cases):
        """``(stack, dof_map, element_map)`` of the cases ``cases`` (indices into this stack)."""
        cases = np.asarray(cases)
        sub = Stack([self.discs[c] for c in cases], outer_fixed=self.outer_fixed)
        return (sub, _ranges(self.dof_start[cases], self.dof_count[cases]),
                _ranges(self.el_start[cases], self.el_count[cases]))

    def respond(self, u, theta_p, gamma_p):
        """``(lambda_r, lambda_t, response, folded)``; ``folded`` flags cases with a
        non-positive stretch (their points are evaluated at zero strain instead)."""
        g_r, g_t = self.displacement_gradients(u)
        ok = (g_r > -1.0).all(axis=1) & (g_t > -1.0).all(axis=1)
        folded = ~np.logical_and.reduceat(ok, self.el_start)
        if folded.any():
            bad = folded[self.element_case][:, None]
            g_r, g_t = np.where(bad, 0.0, g_r), np.where(bad, 0.0, g_t)
        response = hencky_mohr_coulomb(np.log1p(g_r), np.log1p(g_t), theta_p, gamma_p,
                                       self.material, groups=self.point_case)
        return 1.0 + g_r, 1.0 + g_t, response, folded

    def assemble(self, u, theta_p, gamma_p, skip, out=None):
        """``(f, band, response, folded, force_scale)`` at ``u``; cases with ``skip`` set keep
        the values they have in ``out`` (the previous call's result, reused in place).

        Uses the compiled kernel of :mod:`cavex.fem.kernels` when numba is installed, else the
        numpy kernels of the one-case path (which then evaluate every case).
        """
        if kernels is None:
            lam_r, lam_t, resp, folded = self.respond(u, theta_p, gamma_p)
            f, band, resp = self.assemble_response(lam_r, lam_t, resp)
            return f, band, resp, folded, self.force_scale(resp)
        if out is None:
            shape = self.R_points.shape
            out = (np.zeros(self.ndof), np.zeros((2 * self.degree + 1, self.ndof)),
                   SimpleNamespace(tau_r=np.zeros(shape), tau_t=np.zeros(shape),
                                   theta_p=np.zeros(shape), gamma_p=np.zeros(shape),
                                   plastic=np.zeros(shape, dtype=bool),
                                   yield_ratio=np.zeros(shape)),
                   np.zeros(self.n_cases, dtype=bool), np.zeros(self.n_cases))
        f, band, resp, folded, scale = out
        if skip.any():
            keep = ~skip[self.dof_case]
            f[keep] = 0.0
            band[:, keep] = 0.0
        else:
            f[:] = 0.0
            band[:] = 0.0
        m = self.material
        g_r, g_t = self.displacement_gradients(u)
        kernels.assemble_stack(g_r, g_t, self.element_dofs, self.dNdR, self.N, self.R_points,
                               self.weights, self.force_weights, m.K, m.G, m.lam, m.tau,
                               m.lam_psi, m.tension, theta_p, gamma_p, self.el_start,
                               self.el_count, skip, self.degree, f, band, resp.tau_r,
                               resp.tau_t, resp.theta_p, resp.gamma_p, resp.plastic,
                               resp.yield_ratio, folded, scale)
        return out

    def force_scale(self, response):
        """Per case: the largest nodal force one point contributes (Newton's yardstick)."""
        per_element = ((np.abs(response.tau_r) + 2.0 * np.abs(response.tau_t))
                       * self.force_weights).max(axis=1)
        return np.maximum.reduceat(per_element, self.el_start)

    def per_case_max(self, dof_values):
        return np.maximum.reduceat(dof_values, self.dof_start)

    def per_case_all(self, dof_flags):
        return np.logical_and.reduceat(dof_flags, self.dof_start)

    def solve(self, band, rhs, skip):
        """Solve the block-diagonal banded system for the cases without ``skip`` (bool per
        case; their increment is zero); fixed dofs get identity rows. Returns the increment and
        the cases whose block is singular.

        Only the blocks solved are passed to LAPACK (gathered when some are skipped): partial
        pivoting never leaves a block, so each is factorised exactly as it would be alone.
        """
        p = self.degree
        flat = band.reshape(-1)  # band is the caller's scratch copy
        flat[self.fixed_entries] = 0.0
        flat[self.fixed_diagonal] = 1.0
        rhs = np.where(self.free, rhs, 0.0)
        du = np.zeros_like(rhs)
        singular = np.zeros(self.n_cases, dtype=bool)
        solve = np.flatnonzero(~skip)
        if solve.size == 0:
            return du, singular
        if solve.size < self.n_cases:
            cols = _ranges(self.dof_start[solve], self.dof_count[solve])
            band, rhs = band[:, cols], rhs[cols]
        else:
            cols = slice(None)
        try:
            du[cols] = solve_banded((p, p), band, rhs, check_finite=False)
        except (LinAlgError, ValueError):
            starts = _starts(self.dof_count[solve])
            for c, start in zip(solve, starts, strict=True):
                s = slice(start, start + self.dof_count[c])
                try:
                    part = solve_banded((p, p), band[:, s], rhs[s], check_finite=False)
                except (LinAlgError, ValueError):
                    singular[c] = True
                    continue
                d = self.dof_start[c]
                du[d:d + self.dof_count[c]] = part
        return du, singular


# ---------------------------------------------------------------------------------- Newton
def _newton(stack, w, params, dynamic, tol, first_iteration=1):
    """Generalized-alpha Newton iteration of every case of ``stack`` with ``w["active"]``.

    ``w`` holds the start-of-step state in stack layout (``u0, v0, a0, f0, du_prev`` per dof,
    ``theta_p, gamma_p`` per point, ``load, dt, dt_old, has_prev, active`` per case; ``u`` the
    current iterate when continuing at ``first_iteration > 1``). Returns ``(u, a, f, response,
    iterations, reasons)``; ``reasons[c]`` is None for a converged case, else why it failed.
    Inactive cases come back as converged (their values are not to be used).
    """
    k = stack.n_cases
    dof_case = stack.dof_case
    u = _predict(stack, w, dynamic) if first_iteration == 1 else w["u"]
    done = ~w["active"]
    reasons = np.full(k, None, dtype=object)
    iterations = np.zeros(k, dtype=int)
    buffers = None
    for iteration in range(first_iteration, MAX_ITERATIONS + 1):
        buffers = stack.assemble(u, w["theta_p"], w["gamma_p"], done, buffers)
        f, band, resp, folded, force_scale = buffers
        _fail(reasons, done, folded, "non-positive stretch")
        a, r_free, jac, scale = _equations(stack, w, params, dynamic, u, f, band, force_scale)
        _fail(reasons, done, ~stack.per_case_all(np.isfinite(r_free)), "non-finite residual")
        with np.errstate(invalid="ignore"):
            converged = stack.per_case_max(np.abs(r_free)) <= tol * scale
        if iteration > 1:
            newly = converged & ~done
            iterations[newly] = iteration - 1
            done |= newly
        if done.all():
            return u, a, f, resp, iterations, reasons
        remaining = np.flatnonzero(~done)
        if k >= MIN_SHRINK and remaining.size <= SHRINK_FRACTION * k:
            return _continue_on_subset(stack, w, params, dynamic, tol, iteration, remaining,
                                       u, a, f, resp, iterations, reasons)
        failed = np.array([r is not None for r in reasons])
        du, singular = stack.solve(jac, r_free, failed | done)
        _fail(reasons, done, singular, "singular tangent")
        _fail(reasons, done, ~stack.per_case_all(np.isfinite(du)), "non-finite increment")
        u = np.where(stack.free & (~done)[dof_case], u - du, u)
    for c in np.flatnonzero(~done):
        reasons[c] = f"Newton did not converge in {MAX_ITERATIONS} iterations"
    return u, a, f, resp, iterations, reasons


def _predict(stack, w, dynamic):
    """First Newton iterate of every active case (the predictor, as the one-case path)."""
    dof_case = stack.dof_case
    dt_d = w["dt"][dof_case]
    u0 = w["u0"]
    u = u0.copy()
    u[stack.wall] = w["load"]
    if dynamic:
        guess = u0 + dt_d * w["v0"]
    else:
        guess = u0
    ratio = (w["dt"] / w["dt_old"])[dof_case]
    predicted = np.where(w["has_prev"][dof_case], u0 + ratio * w["du_prev"], guess)
    return np.where(stack.free & w["active"][dof_case], predicted, u)


def _equations(stack, w, params, dynamic, u, f, band, force_scale):
    """``(a, r_free, jac, scale)`` of the step's equations at the iterate ``u`` (stack layout;
    ``r_free`` is zero at the prescribed dofs, ``scale`` per case)."""
    p = params
    if dynamic:
        dt_d = w["dt"][stack.dof_case]
        c_m = ((1.0 - p.alpha_m) / (p.beta * w["dt"] * w["dt"]))[stack.dof_case]
        a = ((u - w["u0"] - dt_d * w["v0"]) / (p.beta * dt_d * dt_d)
             - (0.5 / p.beta - 1.0) * w["a0"])
        inertia = stack.mass @ ((1.0 - p.alpha_m) * a + p.alpha_m * w["a0"])
        residual = inertia + (1.0 - p.alpha_f) * f + p.alpha_f * w["f0"]
        jac = (1.0 - p.alpha_f) * band + c_m[None, :] * stack.mass_band
    else:
        a = np.zeros_like(u)
        residual = f
        jac = band.copy()
    r_free = np.where(stack.free, residual, 0.0)
    with np.errstate(invalid="ignore"):
        fixed = np.abs(residual[stack.wall])
        if stack.outer_fixed:
            fixed = np.maximum(fixed, np.abs(residual[stack.outer]))
        scale = np.maximum(np.maximum(force_scale, fixed), 1e-300)
    return a, r_free, jac, scale


def _newton_line_search(stack, w, params, dynamic, tol):
    """The Newton iteration of the one case of ``stack`` with the line search of
    :func:`cavex.fem.solver.line_search_newton`, as :meth:`RadialSolver.advance` does it at the
    deepest cut-back. Returns ``(u, a, f, response, iteration count, reason)`` (reason None
    when converged)."""
    start = _predict(stack, w, dynamic)
    free = stack.free
    no_skip = np.zeros(1, dtype=bool)

    def evaluate(x):
        u = start.copy()
        u[free] = x
        f, band, resp, folded, force_scale = stack.assemble(u, w["theta_p"], w["gamma_p"],
                                                             no_skip)
        if folded[0]:
            raise StepFailure("non-positive stretch")
        a, r_free, jac, scale = _equations(stack, w, params, dynamic, u, f, band, force_scale)
        r = r_free[free]
        if not np.all(np.isfinite(r)):
            raise StepFailure("non-finite residual")
        return r, scale[0], jac, u, a, f, resp

    def solve(out, r):
        rhs = np.zeros(stack.ndof)
        rhs[free] = r
        du, singular = stack.solve(out[2], rhs, no_skip)
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


def _fail(reasons, done, flags, why):
    """Mark the not-yet-done cases among ``flags`` failed with ``why``."""
    if not flags.any():
        return
    new = flags & ~done
    for c in np.flatnonzero(new):
        reasons[c] = why
    done |= new


def _continue_on_subset(stack, w, params, dynamic, tol, iteration, cases, u, a, f, resp,
                        iterations, reasons):
    """Continue the Newton iteration of ``cases`` on a smaller stack, from ``iteration``."""
    sub, dofs, elements = stack.subset(cases)
    sw = {name: w[name][dofs] for name in ("u0", "v0", "a0", "f0", "du_prev")}
    sw.update({name: w[name][elements] for name in ("theta_p", "gamma_p")})
    sw.update({name: w[name][cases] for name in ("load", "dt", "dt_old", "has_prev")})
    sw["active"] = np.ones(cases.size, dtype=bool)
    sw["u"] = u[dofs]
    su, sa, sf, sresp, sit, sreasons = _newton(sub, sw, params, dynamic, tol, iteration)
    u, a, f = u.copy(), a.copy(), f.copy()
    u[dofs], a[dofs], f[dofs] = su, sa, sf
    resp = SimpleNamespace(**{name: value.copy() for name, value in vars(resp).items()})
    replace_points(resp, elements, sresp)
    iterations[cases] = sit
    reasons[cases] = sreasons
    return u, a, f, resp, iterations, reasons


# ---------------------------------------------------------------------------------- one batch
DOF_STATE = ("u", "v", "a", "f", "du_prev")
POINT_STATE = ("theta_p", "gamma_p", "eq_p", "plastic", "yield_ratio")


def _run_batch(models, numerics):
    """Run every case of ``models`` (``(disc, velocity, radius)``, all dynamic or all not)."""
    k = len(models)
    discs = [m[0] for m in models]
    velocity = np.array([m[1] for m in models], dtype=float)
    dynamic = numerics.dynamic and bool(velocity[0] > 0.0)
    params = Newmark.from_rho_inf(numerics.rho_inf)
    root = Stack(discs, outer_fixed=numerics.outer == "fixed")
    seeds = root.R_dofs[root.wall]
    radii = [radius_schedule(m[2], s, numerics.growth_per_step) for m, s in zip(models, seeds,
                                                                              strict=True)]
    times = [wall_times(r, s, v, numerics.start_ramp) if dynamic else None
             for r, s, v in zip(radii, seeds, velocity, strict=True)]
    n_steps = np.array([len(r) for r in radii])
    state = {name: np.zeros(root.ndof) for name in DOF_STATE}
    if dynamic and numerics.start_ramp == 0:
        state["v"][root.wall] = velocity
    shape = root.R_points.shape
    state.update({name: np.zeros(shape) for name in POINT_STATE})
    state["plastic"] = np.zeros(shape, dtype=bool)
    _, _, resp0, _ = root.respond(state["u"], state["theta_p"], state["gamma_p"])
    state["f"] = root.assemble_response(np.ones(shape), np.ones(shape), resp0, tangent=False)[0]
    state["yield_ratio"] = resp0.yield_ratio
    t = np.zeros(k)
    load = np.zeros(k)
    dt_old = np.ones(k)
    has_prev = np.zeros(k, dtype=bool)
    wall_force = np.zeros(k)
    steps = np.zeros(k, dtype=int)
    iterations = np.zeros(k, dtype=int)
    cutbacks = np.zeros(k, dtype=int)
    next_step = np.zeros(k, dtype=int)
    pending = [[] for _ in range(k)]
    finished = np.zeros(k, dtype=bool)
    errors = [None] * k
    task_load, task_dt, task_depth = np.zeros(k), np.zeros(k), np.zeros(k, dtype=int)
    task_search = np.zeros(k, dtype=bool)   # the task is the line-searched last attempt
    plain_reason = [None] * k               # why its plain Newton attempt failed
    stack, cases, dofs, elements = root, np.arange(k), np.arange(root.ndof), \
        np.arange(root.el_count.sum())
    while True:
        # next (sub-)step of every unfinished case
        for c in np.flatnonzero(~finished):
            if pending[c]:
                task_load[c], task_dt[c], task_depth[c], task_search[c] = pending[c].pop()
            elif next_step[c] == n_steps[c]:
                finished[c] = True
            else:
                s = next_step[c]
                task_load[c] = radii[c][s] - seeds[c]
                task_dt[c] = times[c][s] - t[c] if dynamic else 1.0
                task_depth[c] = 0
                task_search[c] = False
                next_step[c] += 1
        if finished.all():
            break
        active = ~finished[cases]
        if active.sum() < 0.5 * stack.n_cases:
            cases = np.flatnonzero(~finished)
            stack, dofs, elements = root.subset(cases)
            active = np.ones(cases.size, dtype=bool)
        w = {"u0": state["u"][dofs], "v0": state["v"][dofs], "a0": state["a"][dofs],
             "f0": state["f"][dofs], "du_prev": state["du_prev"][dofs],
             "theta_p": state["theta_p"][elements], "gamma_p": state["gamma_p"][elements],
             "load": task_load[cases], "dt": task_dt[cases], "dt_old": dt_old[cases],
             "has_prev": has_prev[cases], "active": active}
        search = active & task_search[cases]
        if search.any():
            w["active"] = active & ~search
        u, a, f, resp, its, reasons = _newton(stack, w, params, dynamic, numerics.newton_tol)
        if search.any():  # the line-searched last attempts, case by case
            w["active"] = active
            u, a, f = u.copy(), a.copy(), f.copy()
            resp = SimpleNamespace(**{name: value.copy() for name, value in vars(resp).items()})
            for i in np.flatnonzero(search):
                sub, sdofs, selements = stack.subset([i])
                sw = {name: w[name][sdofs] for name in ("u0", "v0", "a0", "f0", "du_prev")}
                sw.update({name: w[name][selements] for name in ("theta_p", "gamma_p")})
                sw.update({name: w[name][[i]] for name in ("load", "dt", "dt_old", "has_prev",
                                                           "active")})
                su, sa, sf, sresp, its[i], reasons[i] = _newton_line_search(
                    sub, sw, params, dynamic, numerics.newton_tol)
                if reasons[i] is None:
                    u[sdofs], a[sdofs], f[sdofs] = su, sa, sf
                    replace_points(resp, selements, sresp)
        ok = active & np.array([r is None for r in reasons])
        # commit the converged cases
        if dynamic:
            dt_d = w["dt"][stack.dof_case]
            v = w["v0"] + dt_d * ((1.0 - params.gamma) * w["a0"] + params.gamma * a)
            end_force = f[stack.wall] + (stack.mass @ a)[stack.wall]
        else:
            v = np.zeros_like(u)
            end_force = f[stack.wall]
        ok_dofs, ok_elements = ok[stack.dof_case], ok[stack.element_case]
        new = {"u": u, "v": v, "a": a, "f": f, "du_prev": u - w["u0"]}
        for name in DOF_STATE:
            state[name][dofs[ok_dofs]] = new[name][ok_dofs]
        eq_p = state["eq_p"][elements] + np.abs(resp.gamma_p - w["gamma_p"]) * (2.0 / 3.0)
        new = {"theta_p": resp.theta_p, "gamma_p": resp.gamma_p, "eq_p": eq_p,
               "plastic": resp.plastic, "yield_ratio": resp.yield_ratio}
        for name in POINT_STATE:
            state[name][elements[ok_elements]] = new[name][ok_elements]
        done = cases[ok]
        dt_old[done] = task_dt[done]
        has_prev[done] = True
        wall_force[done] = end_force[ok]
        load[done] = task_load[done]
        t[done] += task_dt[done]
        steps[done] += 1
        iterations[done] += its[ok]
        # cut back (or give up on) the failed ones
        for i in np.flatnonzero(active & ~ok):
            c = cases[i]
            depth = task_depth[c]
            if depth >= numerics.max_cutbacks and not task_search[c]:
                # last resort, as RadialSolver.advance: the same task with the line search
                plain_reason[c] = reasons[i]
                pending[c].append((task_load[c], task_dt[c], depth, True))
                continue
            if depth >= numerics.max_cutbacks:
                wall = seeds[c] + state["u"][root.wall[c]]
                errors[c] = CavexNumericalError(
                    f"V = {velocity[c]:g} m/s, step to cavity radius "
                    f"{radii[c][next_step[c] - 1]:.6g} m: "
                    + failure_message(depth, t[c], wall, task_load[c], task_dt[c],
                                      plain_reason[c], reasons[i]))
                finished[c] = True
                continue
            cutbacks[c] += 1
            half = 0.5 * task_dt[c]
            pending[c].append((task_load[c], half, depth + 1, False))
            pending[c].append((0.5 * (load[c] + task_load[c]), half, depth + 1, False))
    out = []
    for c, disc in enumerate(discs):
        stats = {"elements": disc.n_elements, "dofs": disc.ndof, "steps": int(steps[c]),
                 "newton_iterations": int(iterations[c]), "cutbacks": int(cutbacks[c])}
        if errors[c] is not None:
            out.append({"cavity_stress": math.nan, "plastic_radius": math.nan, "u": None,
                        "stats": stats, "error": errors[c]})
            continue
        d = slice(root.dof_start[c], root.dof_start[c] + root.dof_count[c])
        e = slice(root.el_start[c], root.el_start[c] + root.el_count[c])
        u = state["u"][d].copy()
        a_wall = disc.R_dofs[0] + u[0]
        response = SimpleNamespace(plastic=state["plastic"][e],
                                   yield_ratio=state["yield_ratio"][e])
        out.append({"cavity_stress": float(wall_force[c] / (4.0 * np.pi * a_wall * a_wall)),
                    "plastic_radius": plastic_radius(disc, u, response,
                                                     {"eq_p": state["eq_p"][e]}),
                    "u": u, "stats": stats, "error": None})
    return out


# ---------------------------------------------------------------------------------- public API
def _problem(i, problem):
    """``(layers, interfaces, velocity, radius)`` of one entry, checked."""
    if isinstance(problem, dict):
        unknown = set(problem) - {"layers", "interfaces", "velocity", "radius"}
        require(not unknown, f"problems[{i}]", "a dict with keys layers, interfaces, velocity, "
                "radius", sorted(unknown))
        problem = (problem.get("layers"), problem.get("interfaces", ()),
                   problem.get("velocity"), problem.get("radius"))
    require(isinstance(problem, (tuple, list)) and len(problem) == 4, f"problems[{i}]",
            "(layers, interfaces, velocity, radius) or a dict of those", problem)
    layers, interfaces, velocity, radius = problem
    try:
        require(isinstance(velocity, (int, float)) and not isinstance(velocity, bool),
                "velocity", "a number", velocity)
        require(isinstance(radius, (int, float)) and not isinstance(radius, bool),
                "radius", "a number", radius)
        layers = tuple(layers)
        interfaces = tuple(float(h) for h in interfaces)
        check_problem(layers, interfaces, float(velocity), float(radius), "dynamic")
    except (CavexInputError, TypeError) as exc:
        raise CavexInputError(f"problems[{i}]: {exc}") from None
    return layers, interfaces, float(velocity), float(radius)


def expand_cavities(problems, *, batch_size=DEFAULT_BATCH, on_error="return", error_target=None,
                    max_refinements=2, **numerics):
    """Expand many spherical cavities with shared settings; the batched :func:`expand_cavity`.

    Parameters
    ----------
    problems : sequence
        Each ``(layers, interfaces, velocity, radius)`` as :func:`cavex.fem.expand_cavity` takes
        them (or a dict with those keys).
    batch_size : int
        Cases advanced together in one stack (memory grows linearly with it), >= 1.
    on_error : {"return", "raise"}
        A case whose Newton iteration fails after the cut-backs comes back with ``error`` set
        (the others are unaffected), or, with ``"raise"``, the first such error is raised after
        the whole list has run.
    error_target : float, optional
        With the error estimate on, a case whose estimate exceeds this relative error is run
        again at twice the space and time resolution (``elements_per_decade * 2``,
        ``growth_per_step / 2``; the estimate then comes from that run and its half-resolution
        run), up to ``max_refinements`` times. None (default): every case at the given settings.
    max_refinements : int
        See ``error_target``, >= 0.
    **numerics
        Fields of :class:`cavex.fem.settings.Numerics`, shared by all cases.
        ``assembly="forms"`` runs the cases one at a time through :func:`expand_cavity` (the
        reference path, for debugging).

    Returns
    -------
    list of CaseResult
        In the order of ``problems``.

    Raises
    ------
    CavexInputError
        A bad problem (the message names its index and the parameter) or bad numerics.
    CavexNumericalError
        With ``on_error="raise"``, when some case failed.
    """
    require(isinstance(batch_size, int) and not isinstance(batch_size, bool) and batch_size >= 1,
            "batch_size", "an integer >= 1", batch_size)
    require(on_error in ON_ERROR, "on_error", " or ".join(map(repr, ON_ERROR)), on_error)
    settings = make_numerics(**numerics)
    problems = [_problem(i, p) for i, p in enumerate(problems)]
    for i, (_, _, _, radius) in enumerate(problems):
        require(settings.seed_radius is None or settings.seed_radius < radius,
                f"problems[{i}]: seed_radius", f"in (0, radius = {radius})",
                settings.seed_radius)
    require(error_target is None or (isinstance(error_target, float) and 0 < error_target < 1),
            "error_target", "None or a float in (0, 1)", error_target)
    require(isinstance(max_refinements, int) and not isinstance(max_refinements, bool)
            and max_refinements >= 0, "max_refinements", "an integer >= 0", max_refinements)
    results = _run(problems, settings, batch_size)
    for refinement in range(1, max_refinements + 1):
        if error_target is None or not settings.error_estimate:
            break
        redo = [i for i, r in enumerate(results) if r.ok and r.error_estimate > error_target]
        if not redo:
            break
        settings = replace(settings, elements_per_decade=2.0 * settings.elements_per_decade,
                           growth_per_step=0.5 * settings.growth_per_step)
        for i, r in zip(redo, _run([problems[i] for i in redo], settings, batch_size),
                        strict=True):
            r.stats["refinements"] = refinement
            results[i] = r
    if on_error == "raise":
        for r in results:
            if r.error is not None:
                raise r.error
    return results


def _run(problems, settings, batch_size):
    if settings.assembly == "forms":
        results = [_one_case(p, settings) for p in problems]
    else:
        results = _batched(problems, settings, batch_size)
    for r in results:
        r.stats.setdefault("refinements", 0)
        r.numerics = settings.as_dict()
    return results


def _one_case(problem, settings):
    layers, interfaces, velocity, radius = problem
    try:
        r = expand_cavity(layers, interfaces, velocity, radius, **settings.as_dict())
    except CavexNumericalError as exc:
        return CaseResult(velocity, radius, math.nan, None, math.nan, None, {}, exc)
    stats = {k: r.stats[k] for k in ("elements", "dofs", "steps", "newton_iterations",
                                     "cutbacks")}
    for name in ("coarse_cavity_stress", "finer_cavity_stress", "error_companion"):
        if name in r.stats:
            stats[name] = r.stats[name]
    return CaseResult(velocity, radius, r.cavity_stress, r.error_estimate, r.plastic_radius,
                      r.fields["u"], stats)


def _run_all(problems, numerics, batch_size):
    """One run of every problem at ``numerics`` (stacks of ``batch_size``); list of dicts."""

    def disc(layers, interfaces, radius):
        key = (layers, interfaces, radius, numerics)
        if key not in _DISCS:
            if len(_DISCS) >= DISC_CACHE:
                _DISCS.clear()
            _DISCS[key] = build_model(layers, interfaces, radius, numerics)[0]
        return _DISCS[key]

    out = [None] * len(problems)
    for dynamic in (True, False):
        group = [i for i, p in enumerate(problems) if (numerics.dynamic and p[2] > 0.0) == dynamic]
        for start in range(0, len(group), batch_size):
            chunk = group[start:start + batch_size]
            models = [(disc(problems[i][0], problems[i][1], problems[i][3]), problems[i][2],
                       problems[i][3]) for i in chunk]
            for i, r in zip(chunk, _run_batch(models, numerics), strict=True):
                out[i] = r
    return out


def _batched(problems, settings, batch_size):
    """Main runs, then the error-estimate companions as :func:`expand_cavity` does them: the
    2x coarser run, or the 2x finer one where the coarser fails."""
    fine = _run_all(problems, settings, batch_size)
    companion = [None] * len(problems)
    kind = [None] * len(problems)
    if settings.error_estimate:
        todo = [i for i, r in enumerate(fine) if r["error"] is None]
        coarse = _run_all([problems[i] for i in todo], settings.coarsened(), batch_size)
        retry = []
        for i, r in zip(todo, coarse, strict=True):
            if r["error"] is None:
                companion[i], kind[i] = r, "coarse"
            else:
                retry.append(i)
        finer = _run_all([problems[i] for i in retry], settings.coarsened(0.5), batch_size)
        for i, r in zip(retry, finer, strict=True):
            companion[i], kind[i] = r, "finer"
    results = []
    for i, (_, _, velocity, radius) in enumerate(problems):
        main, other = fine[i], companion[i]
        stats = dict(main["stats"])
        error = main["error"]
        estimate = None
        if other is not None:
            stats[f"{kind[i]}_cavity_stress"] = other["cavity_stress"]
            stats["error_companion"] = kind[i]
            if other["error"] is not None:
                error = other["error"]
            elif kind[i] == "coarse":
                estimate = richardson_error(main["cavity_stress"], other["cavity_stress"])
            else:
                estimate = richardson_error_from_finer(main["cavity_stress"],
                                                       other["cavity_stress"])
        if error is not None:
            results.append(CaseResult(velocity, radius, math.nan, None, math.nan, None, stats,
                                      error))
        else:
            results.append(CaseResult(velocity, radius, main["cavity_stress"], estimate,
                                      main["plastic_radius"], main["u"], stats))
    return results


def timed(function, *args, **kwargs):
    """``(seconds, value)`` of one call (for the benchmarks)."""
    started = time.perf_counter()
    value = function(*args, **kwargs)
    return time.perf_counter() - started, value


def expand_chunk(case):
    """:func:`expand_cavities` on a JSON-able chunk of problems (for a process pool or Dask).

    ``case``: ``{"id": str, "problems": [{"layers": [Material fields], "interfaces": [...],
    "velocity": V, "radius": a}, ...], "numerics": {...}, "error_target": e}`` (the last two
    optional; see :func:`expand_cavities`). Returns a
    JSON-able dict of lists in the order of the problems: ``cavity_stress``,
    ``error_estimate``, ``plastic_radius`` (None where the case failed) and ``error`` (the
    one-line failure message, or None).
    """
    from cavex.materials import Material

    problems = [([Material(**m) for m in p["layers"]], p["interfaces"], p["velocity"],
                 p["radius"]) for p in case["problems"]]
    results = expand_cavities(problems, error_target=case.get("error_target"),
                              **case.get("numerics", {}))

    def value(x):
        return None if x is None or not math.isfinite(x) else float(x)

    return {"cavity_stress": [value(r.cavity_stress) for r in results],
            "error_estimate": [value(r.error_estimate) for r in results],
            "plastic_radius": [value(r.plastic_radius) for r in results],
            "error": [None if r.error is None else str(r.error) for r in results]}
