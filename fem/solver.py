r"""Time stepping: generalized-alpha (Chung-Hulbert) with Newton and the consistent tangent.

The semi-discrete equations in radial dof order are ``M a + f_int(u) = r`` with ``r`` the
reaction at the prescribed dofs (the cavity wall, and the outer boundary when fixed). One step
``n -> n+1`` solves, on the free dofs,

.. math:: M[(1-\alpha_m) a_{n+1} + \alpha_m a_n] + (1-\alpha_f) f(u_{n+1}) + \alpha_f f(u_n) = 0,

with the Newmark updates
``a_{n+1} = (u_{n+1} - u_n - dt v_n)/(beta dt^2) - (1/(2 beta) - 1) a_n``,
``v_{n+1} = v_n + dt[(1 - gamma) a_n + gamma a_{n+1}]`` and
``alpha_m = (2 rho_inf - 1)/(rho_inf + 1)``,
``alpha_f = rho_inf/(rho_inf + 1)``, ``gamma = 1/2 - alpha_m + alpha_f``,
``beta = (1 - alpha_m + alpha_f)^2/4`` (second order; ``rho_inf`` is the spectral radius at
infinite frequency, 1 = no numerical damping). The plastic state is return-mapped at
``u_{n+1}`` (backward Euler), so ``f(u_n)`` is the converged force of the previous step. The
Newton matrix is ``(1-alpha_m)/(beta dt^2) M + (1-alpha_f) K_T``, banded with ``p`` off-diagonals.
``dynamic=False`` drops the inertia (quasi-static load stepping).

The scheme is second order only from a consistent initial acceleration; a load applied
suddenly at ``t = 0`` (Blake's problem) needs :meth:`RadialSolver.start_under_load`, which
solves ``M a_0 = r - f(u_0)`` on the free dofs (the solver otherwise starts from ``a_0 = 0``).

A step whose Newton iteration fails (no convergence, folded element or non-finite value) is
retried as two half steps, recursively, up to ``max_cutbacks`` times. A step that still fails
at the deepest cut-back is tried once more with an energy line search
(:func:`line_search_newton`), which cures the two-cycle of plain Newton steps around the
Mohr-Coulomb apex (docs/fem.md); only then is :class:`~cavex.errors.CavexNumericalError`
raised. Steps that plain Newton solves, with or without cut-backs, never reach the line search,
so their results are those of plain Newton to the last bit.
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_banded

from cavex.errors import CavexNumericalError


@dataclass
class Newmark:
    """Generalized-alpha parameters from ``rho_inf`` in [0, 1]."""

    alpha_m: float
    alpha_f: float
    beta: float
    gamma: float

    @classmethod
    def from_rho_inf(cls, rho_inf):
        am = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0)
        af = rho_inf / (rho_inf + 1.0)
        return cls(alpha_m=am, alpha_f=af, beta=0.25 * (1.0 - am + af) ** 2,
                   gamma=0.5 - am + af)


class StepFailure(Exception):
    """A Newton iteration that did not converge (internal: triggers a cut-back)."""


LINE_SEARCH_EVALUATIONS = 20  # residual evaluations per line search (Illinois steps)
LINE_SEARCH_TOLERANCE = 0.5   # accept s once |G(s)| <= this * |G(0)|


def _dot(x, y):
    """``x . y`` correctly rounded (``math.fsum``): the same bits whatever the array layout."""
    return math.fsum(x * y)


def line_search_newton(evaluate, solve, x, tol, max_iterations):
    """Newton iteration with an energy line search; the last resort of a failing step.

    ``evaluate(x)`` returns a tuple starting with the free-dof residual ``r`` and the force
    yardstick ``scale`` at the free-dof iterate ``x`` (it raises :class:`StepFailure` where the
    equations cannot be evaluated); ``solve(out, r)`` returns the Newton increment ``J^-1 r``
    for the tangent of ``out``. Converged: ``max |r| <= tol * scale`` from the second
    iteration on, as :meth:`RadialSolver._newton`. Returns ``(x, out, iterations)``.

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
        if iteration > 1 and norm <= tol * scale:
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


def failure_message(depth, t, wall_radius, load, dt, plain, line_searched):
    """Why a step failed for good (the same words in the one-case and the batched path)."""
    return (f"Newton failed after {depth} step cut-backs at t = {t:.6g} s, wall radius "
            f"{wall_radius:.6g} m, wall load {load:.6g} (dt = {dt:.3g} s): {plain}; "
            f"{line_searched}")


class RadialSolver:
    """State and stepping of one radial model.

    Parameters
    ----------
    disc : Discretisation
    dynamic : bool
    rho_inf : float
        Generalized-alpha high-frequency spectral radius.
    outer : {"fixed", "free"}
    assembly : {"fast", "forms"}
    newton_tol : float
        Relative residual tolerance (against the largest internal nodal force).
    max_iterations, max_cutbacks : int
    wall_velocity : float
        Initial velocity of the wall node (the others start at rest).
    wall_control : {"displacement", "pressure"}
        What :meth:`advance` prescribes at the wall: its displacement, or a pressure (follower
        load ``p 4 pi r^2`` on the current wall).
    """

    def __init__(self, disc, *, dynamic=True, rho_inf=0.5, outer="fixed", assembly="fast",
                 newton_tol=1e-10, max_iterations=30, max_cutbacks=10, wall_velocity=0.0,
                 wall_control="displacement"):
        self.disc = disc
        self.dynamic = dynamic
        self.params = Newmark.from_rho_inf(rho_inf)
        self.assemble = disc.assemble_fast if assembly == "fast" else disc.assemble_forms
        self.newton_tol = newton_tol
        self.max_iterations = max_iterations
        self.max_cutbacks = max_cutbacks
        n = disc.ndof
        self.pressure_control = wall_control == "pressure"
        first = 0 if self.pressure_control else 1
        self.fixed = [0] * (1 - first) + ([n - 1] if outer == "fixed" else [])
        self.free = slice(first, n - 1 if outer == "fixed" else n)
        self.u = np.zeros(n)
        self.v = np.zeros(n)
        self.v[0] = wall_velocity
        self.a = np.zeros(n)
        self.t = 0.0
        self.state = disc.new_state()
        self.f, _, self.response = self.assemble(self.u, self.state, tangent=False)
        self.dissipated = 0.0
        self.work = 0.0
        self.wall_force = 0.0
        self.load = 0.0
        self.previous_step = None
        self.newton_iterations = 0
        self.steps = 0
        self.cutbacks = 0
        self.line_search_steps = 0

    # -------------------------------------------------------------- one step
    def _start(self, load, dt):
        """First Newton iterate of the step to ``load`` over ``dt``: the predictor."""
        u = self.u.copy()
        if not self.pressure_control:
            u[0] = load
        if self.previous_step is not None:  # predictor: scaled increment of the last step
            du, dt_old = self.previous_step
            u[self.free] = self.u[self.free] + (dt / dt_old) * du[self.free]
        elif self.dynamic:
            u[self.free] = self.u[self.free] + dt * self.v[self.free]
        return u

    def _evaluate(self, u, load, dt):
        """``(r_free, scale, jac, a, f, response)`` of the step's equations at the iterate ``u``."""
        d, p = self.disc, self.params
        M = d.mass
        try:
            f, band, resp = self.assemble(u, self.state)
        except FloatingPointError as exc:
            raise StepFailure(str(exc)) from None
        if self.dynamic:
            a = (u - self.u - dt * self.v) / (p.beta * dt * dt) - (0.5 / p.beta - 1.0) * self.a
            inertia = M @ ((1.0 - p.alpha_m) * a + p.alpha_m * self.a)
            residual = inertia + (1.0 - p.alpha_f) * f + p.alpha_f * self.f
            c_m = (1.0 - p.alpha_m) / (p.beta * dt * dt)
            jac = (1.0 - p.alpha_f) * band + c_m * d.mass_band
        else:
            a = np.zeros_like(u)
            residual = f.copy()
            jac = band
        if self.pressure_control:
            r_wall = d.R_dofs[0] + u[0]
            residual[0] -= load * 4.0 * np.pi * r_wall ** 2
            jac = jac.copy()
            jac[d.degree, 0] -= load * 8.0 * np.pi * r_wall
        r_free = residual[self.free]
        if not np.all(np.isfinite(r_free)):
            raise StepFailure("non-finite residual")
        scale = max(d.force_scale(resp), np.max(np.abs(residual[self.fixed]), initial=0.0),
                    abs(load) * 4.0 * np.pi * d.R_dofs[0] ** 2 * self.pressure_control,
                    1e-300)
        return r_free, scale, jac, a, f, resp

    def _newton(self, load, dt):
        """Converged ``(u, a, f, response)`` at ``t + dt``; ``load`` is the wall's prescribed
        displacement, or its pressure under pressure control."""
        u = self._start(load, dt)
        for iteration in range(1, self.max_iterations + 1):
            r_free, scale, jac, a, f, resp = self._evaluate(u, load, dt)
            if iteration > 1 and np.max(np.abs(r_free)) <= self.newton_tol * scale:
                self.newton_iterations += iteration - 1
                return u, a, f, resp
            du = self._solve(jac, r_free)
            if not np.all(np.isfinite(du)):
                raise StepFailure("non-finite increment")
            u[self.free] -= du
        raise StepFailure(f"Newton did not converge in {self.max_iterations} iterations")

    def _newton_line_search(self, load, dt):
        """:meth:`_newton` with the line search of :func:`line_search_newton` (the last resort
        of :meth:`advance`)."""
        start = self._start(load, dt)

        def evaluate(x):
            u = start.copy()
            u[self.free] = x
            return self._evaluate(u, load, dt) + (u,)

        x, out, iterations = line_search_newton(evaluate, lambda out, r: self._solve(out[2], r),
                                                start[self.free], self.newton_tol,
                                                self.max_iterations)
        self.newton_iterations += iterations
        _, _, _, a, f, resp, u = out
        return u, a, f, resp

    def _solve(self, band, rhs):
        p = self.disc.degree
        return solve_banded((p, p), band[:, self.free], rhs, check_finite=False)

    def _commit(self, u, a, f, resp, dt, load):
        """Accept the step: velocities, plastic state, energies, wall reaction."""
        p = self.params
        d = self.disc
        if self.dynamic:
            v = self.v + dt * ((1.0 - p.gamma) * self.a + p.gamma * a)
            mid_force = (d.mass @ ((1.0 - p.alpha_m) * a + p.alpha_m * self.a)
                         + (1.0 - p.alpha_f) * f + p.alpha_f * self.f)[0]
            end_force = f[0] + (d.mass @ a)[0]
        else:
            v = np.zeros_like(u)
            mid_force = 0.5 * (f[0] + self.f[0])
            end_force = f[0]
        self.work += mid_force * (u[0] - self.u[0])
        self.dissipated += float(np.sum(d.weights * resp.dissipation))
        self.previous_step = (u - self.u, dt)
        self.u, self.v, self.a, self.f, self.response = u, v, a, f, resp
        self.state = {"theta_p": resp.theta_p, "gamma_p": resp.gamma_p,
                      "eq_p": self.state["eq_p"] + np.abs(resp.gamma_p - self.state["gamma_p"])
                      * (2.0 / 3.0)}
        self.wall_force = end_force
        self.load = load
        self.t += dt
        self.steps += 1

    def advance(self, load, dt, depth=0):
        """Step to the wall load (displacement, or pressure) over ``dt``, with cut-backs; a step
        that still fails at the deepest cut-back is tried once more with a line search."""
        try:
            self._commit(*self._newton(load, dt), dt, load)
        except StepFailure as exc:
            if depth >= self.max_cutbacks:
                try:
                    result = self._newton_line_search(load, dt)
                except StepFailure as again:
                    raise CavexNumericalError(failure_message(
                        depth, self.t, self.disc.R_dofs[0] + self.u[0], load, dt, exc,
                        again)) from None
                self.line_search_steps += 1
                self._commit(*result, dt, load)
                return
            self.cutbacks += 1
            previous = self.load
            self.advance(0.5 * (previous + load), 0.5 * dt, depth + 1)
            self.advance(load, 0.5 * dt, depth + 1)

    def start_under_load(self, load):
        """Consistent start for a wall pressure ``load`` applied suddenly at ``t = 0+``.

        Sets the acceleration from ``M a_0 = r - f(u_0)`` on the free dofs (``r``: the wall
        load ``p 4 pi r^2``) and holds ``load`` as the current load, so that cut-backs do not
        ramp it. Call before the first :meth:`advance` of a dynamic, pressure-controlled run.
        """
        if not (self.dynamic and self.pressure_control and self.steps == 0):
            raise ValueError("start_under_load needs a dynamic, pressure-controlled solver "
                             "before its first step")
        d = self.disc
        residual = -self.f - d.mass @ self.a
        residual[0] += load * 4.0 * np.pi * (d.R_dofs[0] + self.u[0]) ** 2
        self.a[self.free] += self._solve(d.mass_band, residual[self.free])
        self.load = load

    # -------------------------------------------------------------- energies
    def kinetic_energy(self):
        return 0.5 * float(self.v @ (self.disc.mass @ self.v))

    def stored_energy(self):
        return float(np.sum(self.disc.weights * self.response.energy))
