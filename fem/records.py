"""The records the compiled FE kernels take, in place of loose arrays.

Each is a named tuple of arrays and scalars: numba compiles it to a struct passed by value and
reads a field as an attribute (``layout.dof_start``) at no cost, and the arrays keep their
layout (one array per quantity), so the kernels do the same arithmetic on the same memory as
with loose arguments. The material is a structured array instead, one record per element
(:mod:`cavex.fem.material_records`: the one place where a layer becomes kernel data).

**The boundary rule.** A record crosses from Python into a compiled kernel as a plain tuple
(``tuple(layout)``), and the kernel names it again on entry (``layout = Layout(*layout)``,
free in compiled code, also when it is already named). numba's dispatcher types a plain tuple
of arrays in C but a named tuple in Python, at 2.4 times the cost of loose arguments
(measured: 20 arrays, 30 us against 12.6 us loose and 13.4 us plain and named on entry), which
on a run of the issue grid's cases (about 700 rounds of a Newton call and a commit) would cost
about 3 % of the CPU. Records are not nested, for the same reason.

- :class:`Layout`: what the kernels read of a stack, fixed for its life;
- :class:`Scheme`, :class:`Convergence`: the time scheme of a step and Newton's rules;
- :class:`StepStart`: the start of a step (state and per-case step data);
- :class:`PointResponse`, :class:`Assembly`, :class:`Equations`, :class:`Progress`: what the
  element kernel, the step equations and the Newton iteration write;
- :class:`Trial`, :class:`Rows`, :class:`DofState`, :class:`PointState`, :class:`CaseState`:
  what a converged step commits, and where, into the solver's state.
"""

from typing import NamedTuple

import numpy as np


class Layout(NamedTuple):
    """A stack's dofs, elements and points as the kernels read them
    (:class:`cavex.fem.stack.Stack`: case ``c`` owns dofs ``dof_start[c] : dof_start[c] +
    dof_count[c]`` and elements ``el_start[c] : el_start[c] + el_count[c]``)."""

    element_dofs: np.ndarray    # (element, basis function) -> dof
    dNdR: np.ndarray            # (element, basis function, point)
    N: np.ndarray               # (basis function, point)
    R_points: np.ndarray        # (element, point) reference radius
    weights: np.ndarray         # (element, point) 4 pi R^2 dR
    force_weights: np.ndarray   # (element, point) the force yardstick's weights
    el_start: np.ndarray        # per case
    el_count: np.ndarray
    dof_start: np.ndarray       # per case; the wall dof
    dof_count: np.ndarray
    free: np.ndarray            # per dof: not prescribed
    R_dofs: np.ndarray          # per dof: reference radius
    mass_band: np.ndarray       # (2 degree + 1, dof) the banded mass matrix
    fixed_entries: np.ndarray   # band entries (flat) of the prescribed dofs' rows and columns
    fixed_diagonal: np.ndarray  # their diagonal entries
    wall_indptr: np.ndarray     # the mass matrix's CSR rows at the wall dofs (one per case)
    wall_indices: np.ndarray
    wall_data: np.ndarray
    degree: int                 # p: the band has p sub- and super-diagonals
    pressure: bool              # the wall is loaded by a pressure (else displaced)
    outer_fixed: bool           # the outermost dof is held


class Scheme(NamedTuple):
    """The time scheme of a step: generalized-alpha (:mod:`cavex.fem.newton`) with inertia
    (``dynamic``), or quasi-static load stepping."""

    alpha_m: float
    alpha_f: float
    beta: float
    gamma: float
    dynamic: bool

    @classmethod
    def from_rho_inf(cls, rho_inf, dynamic=True):
        """Chung-Hulbert's parameters from the spectral radius ``rho_inf`` in [0, 1]."""
        am = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0)
        af = rho_inf / (rho_inf + 1.0)
        return cls(alpha_m=am, alpha_f=af, beta=0.25 * (1.0 - am + af) ** 2,
                   gamma=0.5 - am + af, dynamic=bool(dynamic))


class Convergence(NamedTuple):
    """Newton's rules: the relative tolerance, iterations per attempt, and the stall limit."""

    tol: float
    max_iterations: int
    stall_iterations: int


class StepStart(NamedTuple):
    """Start-of-step data of a Newton call, in stack layout.

    Per dof: ``u0, v0, a0, f0`` (displacement, velocity, acceleration and internal force at
    the start of the step) and ``du_prev`` (the last step's increment); per point:
    ``theta_p, gamma_p`` (plastic strains); per case: ``load`` (the wall load at the end of
    the step), ``dt``, ``dt_old`` (the last step's), ``has_prev`` (a last step exists) and
    ``active`` (the case iterates).
    """

    u0: np.ndarray
    v0: np.ndarray
    a0: np.ndarray
    f0: np.ndarray
    du_prev: np.ndarray
    theta_p: np.ndarray
    gamma_p: np.ndarray
    load: np.ndarray
    dt: np.ndarray
    dt_old: np.ndarray
    has_prev: np.ndarray
    active: np.ndarray

    def subset(self, dofs, elements, cases):
        """The start of a subset of the stack's cases (:meth:`Stack.subset`'s maps), all of
        them active."""
        return StepStart(u0=self.u0[dofs], v0=self.v0[dofs], a0=self.a0[dofs],
                         f0=self.f0[dofs], du_prev=self.du_prev[dofs],
                         theta_p=self.theta_p[elements], gamma_p=self.gamma_p[elements],
                         load=self.load[cases], dt=self.dt[cases], dt_old=self.dt_old[cases],
                         has_prev=self.has_prev[cases],
                         active=np.ones(np.size(cases), dtype=bool))


class PointResponse(NamedTuple):
    """Per (element, point): the Kirchhoff stresses, the new plastic strains, plastic in this
    step, and the yield ratio."""

    tau_r: np.ndarray
    tau_t: np.ndarray
    theta_p: np.ndarray
    gamma_p: np.ndarray
    plastic: np.ndarray
    yield_ratio: np.ndarray

    @classmethod
    def zeros(cls, shape):
        return cls(tau_r=np.zeros(shape), tau_t=np.zeros(shape), theta_p=np.zeros(shape),
                   gamma_p=np.zeros(shape), plastic=np.zeros(shape, dtype=bool),
                   yield_ratio=np.zeros(shape))

    def copy(self):
        return PointResponse(*(value.copy() for value in self))


class Assembly(NamedTuple):
    """What the element kernel writes besides the :class:`PointResponse`
    (:func:`cavex.fem.element.assemble_cases`): the internal force ``f`` and banded tangent
    ``band`` per dof, per case ``folded`` and ``force_scale``, and per point the displacement
    gradients ``Gr = du/dR``, ``Gt = u/R``."""

    f: np.ndarray
    band: np.ndarray
    folded: np.ndarray
    force_scale: np.ndarray
    Gr: np.ndarray
    Gt: np.ndarray


class Equations(NamedTuple):
    """The step's equations at an iterate (:func:`cavex.fem.newton.step_equations`): the
    acceleration ``a``, the free residual ``r_free`` and the Newton matrix ``jac`` (banded),
    per case the force ``scale`` and ``r_max = max |r_free|``."""

    a: np.ndarray
    r_free: np.ndarray
    jac: np.ndarray
    scale: np.ndarray
    r_max: np.ndarray


class Progress(NamedTuple):
    """Per case: the status of :func:`cavex.fem.newton.iterate`, Newton solves and residual
    evaluations."""

    status: np.ndarray
    iterations: np.ndarray
    evaluations: np.ndarray


class Trial(NamedTuple):
    """A step's trial state per dof on a working stack (its points': a
    :class:`PointResponse`)."""

    u: np.ndarray
    a: np.ndarray
    f: np.ndarray


class Rows(NamedTuple):
    """Where a working stack sits in the solver's state: its cases' rows, and the rows of its
    dofs and elements."""

    cases: np.ndarray
    dofs: np.ndarray
    elements: np.ndarray


class DofState(NamedTuple):
    """The solver's state per dof."""

    u: np.ndarray
    v: np.ndarray
    a: np.ndarray
    f: np.ndarray
    du_prev: np.ndarray


class PointState(NamedTuple):
    """The solver's state per (element, point)."""

    theta_p: np.ndarray
    gamma_p: np.ndarray
    eq_p: np.ndarray
    plastic: np.ndarray
    yield_ratio: np.ndarray
    tau_r: np.ndarray
    tau_t: np.ndarray


class CaseState(NamedTuple):
    """The solver's state per case."""

    t: np.ndarray
    load: np.ndarray
    dt_old: np.ndarray
    wall_force: np.ndarray
    work: np.ndarray
    dissipated: np.ndarray
