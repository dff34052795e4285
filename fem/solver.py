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
retried as two half steps, recursively, up to ``max_cutbacks`` times; then
:class:`~cavex.errors.CavexNumericalError` is raised.
"""

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

    # -------------------------------------------------------------- one step
    def _newton(self, load, dt):
        """Converged ``(u, a, f, response)`` at ``t + dt``; ``load`` is the wall's prescribed
        displacement, or its pressure under pressure control."""
        d, p = self.disc, self.params
        M = d.mass
        u = self.u.copy()
        if not self.pressure_control:
            u[0] = load
        if self.previous_step is not None:  # predictor: scaled increment of the last step
            du, dt_old = self.previous_step
            u[self.free] = self.u[self.free] + (dt / dt_old) * du[self.free]
        elif self.dynamic:
            u[self.free] = self.u[self.free] + dt * self.v[self.free]
        scale = None
        for iteration in range(1, self.max_iterations + 1):
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
            if iteration > 1 and np.max(np.abs(r_free)) <= self.newton_tol * scale:
                self.newton_iterations += iteration - 1
                return u, a, f, resp
            du = self._solve(jac, r_free)
            if not np.all(np.isfinite(du)):
                raise StepFailure("non-finite increment")
            u[self.free] -= du
        raise StepFailure(f"Newton did not converge in {self.max_iterations} iterations")

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
        """Step to the wall load (displacement, or pressure) over ``dt``, with cut-backs."""
        try:
            self._commit(*self._newton(load, dt), dt, load)
        except StepFailure as exc:
            if depth >= self.max_cutbacks:
                raise CavexNumericalError(
                    f"Newton failed after {depth} step cut-backs at t = {self.t:.6g} s, "
                    f"wall radius {self.disc.R_dofs[0] + self.u[0]:.6g} m, wall load {load:.6g} "
                    f"(dt = {dt:.3g} s): {exc}") from None
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
