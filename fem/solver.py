"""The one FE solver: time stepping of a stack of radial models with per-case cut-backs.

:class:`RadialSolver` holds the state of every case of a :class:`~cavex.fem.stack.Stack` (a
single problem is a stack of one) and advances them through their own step lists
(:meth:`RadialSolver.run`). A round advances every unfinished case by one (sub-)step with one
call of :func:`cavex.fem.newton.newton`, so cases whose cut-backs differ stay independent and a
case gives the same bits alone and inside any stack. The policy for a failing step, the same for
every case:

1. a step whose Newton iteration fails (a stall or no convergence, folded element,
   non-finite value, singular tangent) is retried as two half steps (the load interpolated
   linearly), recursively, up to ``max_cutbacks`` times;
2. a step that still fails at the deepest cut-back is tried once more with an energy line search
   (:func:`cavex.fem.newton.newton_line_search`), which cures the two-cycle of plain Newton at
   the Mohr-Coulomb apex (docs/fem.md); steps that plain Newton solves never reach it;
3. only then does the case fail, with a :class:`~cavex.errors.CavexNumericalError` naming the
   time, wall radius, load and step (and what :meth:`RadialSolver.run` is told about the step).

Histories, fields and snapshots are *observers*: callables ``observer(solver, case, step)``
called when a case has completed a step of its list; a run without observers keeps only the
state. Energies (wall work, dissipation) are accumulated for every case; kinetic and stored
energy are evaluated on request.
"""

from types import SimpleNamespace

import numpy as np
from numba import njit

from cavex.errors import CavexNumericalError
from cavex.fem.newton import newton, newton_line_search, replace_points
from cavex.fem.records import (
    CaseState,
    DofState,
    Layout,
    PointResponse,
    PointState,
    Rows,
    Scheme,
    StepStart,
    Trial,
)
from cavex.fem.stack import Stack

DOF_STATE = DofState._fields
POINT_STATE = PointState._fields
CASE_STATE = CaseState._fields
COUNTERS = ("steps", "newton_iterations", "cutbacks", "line_search_steps",
            "residual_evaluations")


def failure_message(depth, t, wall_radius, load, dt, plain, line_searched):
    """Why a step failed for good."""
    return (f"Newton failed after {depth} step cut-backs at t = {t:.6g} s, wall radius "
            f"{wall_radius:.6g} m, wall load {load:.6g} (dt = {dt:.3g} s): {plain}; "
            f"{line_searched}")


@njit(cache=True, error_model="numpy")
def commit_cases(ok, rows, trial, resp, w, layout, scheme, dofs, points, cases):
    r"""Accept step ``n -> n+1`` of every case ``c`` of a working stack with ``ok[c]``: its
    :class:`~cavex.fem.records.Trial` state (``u, a, f`` per dof) and its point response
    ``resp`` (a :class:`~cavex.fem.records.PointResponse`) are written into the solver's state
    (``dofs``, ``points``, ``cases``:
    :class:`~cavex.fem.records.DofState`, :class:`~cavex.fem.records.PointState`,
    :class:`~cavex.fem.records.CaseState`; at the :class:`~cavex.fem.records.Rows` ``rows`` of
    the working stack's dofs and elements, per case row ``rows.cases[c]``), with

    - the Newmark velocity ``v = v_n + dt[(1 - gamma) a_n + gamma a]`` (dynamic; else 0) and
      the increment ``du_prev = u - u_n``;
    - the equivalent plastic strain ``eq_p += (2/3)|gamma_p - gamma_p,n|``;
    - the wall reaction ``f_wall + (M a)_wall`` (dynamic; else ``f_wall``) and the wall work
      ``F_mid (u_wall - u_wall,n)``, ``F_mid = (M[(1 - alpha_m) a + alpha_m a_n])_wall
      + (1 - alpha_f) f_wall + alpha_f f_wall,n`` (quasi-static: ``(f_wall + f_wall,n)/2``);
    - the dissipation ``sum W [-P (theta_p - theta_p,n) - (2/3) Q (gamma_p - gamma_p,n)]``
      with ``P = -(tau_r + 2 tau_t)/3``, ``Q = tau_t - tau_r``.

    ``layout.wall_*`` are the CSR rows of the mass matrix at the wall dofs (one per case),
    summed in their stored order as scipy's product does. The start-of-step arrays of ``w``
    (a :class:`~cavex.fem.records.StepStart`) may be views of the state: each value is read
    before its row is written. The records come as plain tuples (:mod:`cavex.fem.records`, the
    boundary rule)."""
    rows, trial, resp, w = Rows(*rows), Trial(*trial), PointResponse(*resp), StepStart(*w)
    layout, scheme, dofs = Layout(*layout), Scheme(*scheme), DofState(*dofs)
    points, cases = PointState(*points), CaseState(*cases)
    u, a, f = trial.u, trial.a, trial.f
    u0, v0, a0, f0, dt = w.u0, w.v0, w.a0, w.f0, w.dt
    theta_p0, gamma_p0 = w.theta_p, w.gamma_p
    tau_r, tau_t, theta_p, gamma_p = resp.tau_r, resp.tau_t, resp.theta_p, resp.gamma_p
    dof_start, dof_count = layout.dof_start, layout.dof_count
    el_start, el_count, weights = layout.el_start, layout.el_count, layout.weights
    wall_indptr, wall_indices, wall_data = (layout.wall_indptr, layout.wall_indices,
                                            layout.wall_data)
    dynamic, gamma, alpha_m, alpha_f = scheme.dynamic, scheme.gamma, scheme.alpha_m, \
        scheme.alpha_f
    U, V, A, F, DU = dofs.u, dofs.v, dofs.a, dofs.f, dofs.du_prev
    wall_force, work, dissipated = cases.wall_force, cases.work, cases.dissipated
    root_dofs, root_elements = rows.dofs, rows.elements
    nq = weights.shape[1]
    for c in range(dof_start.size):
        if not ok[c]:
            continue
        s0, s1 = dof_start[c], dof_start[c] + dof_count[c]
        if dynamic:  # first: the start-of-step arrays may be views of the state written below
            mid = 0.0
            inertia = 0.0
            for j in range(wall_indptr[c], wall_indptr[c + 1]):
                col = wall_indices[j]
                mid += wall_data[j] * ((1.0 - alpha_m) * a[col] + alpha_m * a0[col])
                inertia += wall_data[j] * a[col]
            mid_force = mid + ((1.0 - alpha_f) * f[s0] + alpha_f * f0[s0])
            end_force = f[s0] + inertia
        else:
            mid_force = 0.5 * (f[s0] + f0[s0])
            end_force = f[s0]
        k = rows.cases[c]
        wall_force[k] = end_force
        work[k] += mid_force * (u[s0] - u0[s0])
        h = dt[c]
        for i in range(s0, s1):
            row = root_dofs[i]
            DU[row] = u[i] - u0[i]
            V[row] = v0[i] + h * ((1.0 - gamma) * a0[i] + gamma * a[i]) if dynamic else 0.0
            U[row] = u[i]
            A[row] = a[i]
            F[row] = f[i]
        total = 0.0
        for e in range(el_start[c], el_start[c] + el_count[c]):
            row = root_elements[e]
            for q in range(nq):
                P = -(tau_r[e, q] + 2.0 * tau_t[e, q]) / 3.0
                Q = tau_t[e, q] - tau_r[e, q]
                total += weights[e, q] * (-P * (theta_p[e, q] - theta_p0[e, q])
                                          - (2.0 / 3.0) * Q * (gamma_p[e, q] - gamma_p0[e, q]))
                points.eq_p[row, q] += abs(gamma_p[e, q] - gamma_p0[e, q]) * (2.0 / 3.0)
                points.theta_p[row, q] = theta_p[e, q]
                points.gamma_p[row, q] = gamma_p[e, q]
                points.plastic[row, q] = resp.plastic[e, q]
                points.yield_ratio[row, q] = resp.yield_ratio[e, q]
                points.tau_r[row, q] = tau_r[e, q]
                points.tau_t[row, q] = tau_t[e, q]
        dissipated[k] += total


def padded(rows):
    """Per-case arrays of different lengths as one 2-D array (NaN beyond each one's end)."""
    table = np.full((len(rows), max((len(r) for r in rows), default=0)), np.nan)
    for c, row in enumerate(rows):
        table[c, :len(row)] = row
    return table


class RadialSolver:
    """State and stepping of a stack of radial models.

    Parameters
    ----------
    discs : Discretisation or sequence of Discretisation
        The cases (one degree).
    dynamic : bool
        Inertia on, or quasi-static load stepping.
    rho_inf : float
        Generalized-alpha high-frequency spectral radius.
    outer : {"fixed", "free"}
    newton_tol : float
        Relative residual tolerance (against the largest nodal force of one point, the
        reactions and the wall load).
    max_cutbacks : int
    wall_velocity : float or array
        Initial velocity of each case's wall node (the others start at rest).
    wall_control : {"displacement", "pressure"}
        What a step prescribes at the wall: its displacement, or a pressure (follower load
        ``p 4 pi r^2`` on the current wall).
    """

    def __init__(self, discs, *, dynamic=True, rho_inf=0.5, outer="fixed", newton_tol=1e-10,
                 max_cutbacks=10, wall_velocity=0.0, wall_control="displacement"):
        discs = [discs] if not isinstance(discs, (list, tuple)) else list(discs)
        self.stack = root = Stack(discs, outer_fixed=outer == "fixed", wall_control=wall_control)
        self.dynamic = dynamic
        self.params = Scheme.from_rho_inf(rho_inf, dynamic)
        self.newton_tol = newton_tol
        self.max_cutbacks = max_cutbacks
        k = root.n_cases
        self.dofs = {name: np.zeros(root.ndof) for name in DOF_STATE}
        self.dofs["v"][root.wall] = wall_velocity
        shape = root.R_points.shape
        self.points = {name: np.zeros(shape) for name in POINT_STATE}
        assembly, resp = root.assemble(self.dofs["u"], self.points["theta_p"],
                                       self.points["gamma_p"])
        self.dofs["f"] = assembly.f
        self.points.update(plastic=resp.plastic, yield_ratio=resp.yield_ratio,
                           tau_r=resp.tau_r, tau_t=resp.tau_t)
        self.cases = {name: np.zeros(k) for name in CASE_STATE}
        self.cases["dt_old"][:] = 1.0
        self.has_prev = np.zeros(k, dtype=bool)
        self.counters = {name: np.zeros(k, dtype=int) for name in COUNTERS}
        self._rows = np.arange(root.ndof)  # the whole stack's rows of the state
        self._point_rows = np.arange(shape[0])

    # ------------------------------------------------------------------ stepping
    def run(self, loads, times, observers=(), describe=None):
        """Advance every case through its own step list.

        Parameters
        ----------
        loads : sequence of array
            Per case, the wall load (displacement or pressure) at the end of each step.
        times : sequence of array or None
            Per case, the time at the end of each step (dynamic); None: unit pseudo-time steps.
        observers : sequence of callable
            ``observer(solver, case, step)`` after case ``case`` has completed step ``step``.
        describe : callable, optional
            ``describe(case, step) -> str`` prefixed to a failure message.

        Returns
        -------
        list
            Per case None, or the :class:`~cavex.errors.CavexNumericalError` it failed with
            (its state is then that of the last completed (sub-)step).
        """
        root = self.stack
        k = root.n_cases
        n_steps = np.array([len(x) for x in loads])
        load_table, time_table = padded(loads), padded(times) if times is not None else None
        next_step = np.zeros(k, dtype=int)
        pending = [[] for _ in range(k)]
        n_pending = np.zeros(k, dtype=int)      # len(pending[c])
        finished = np.zeros(k, dtype=bool)
        errors = [None] * k
        task_load, task_dt = np.zeros(k), np.zeros(k)
        task_depth = np.zeros(k, dtype=int)
        task_search = np.zeros(k, dtype=bool)   # the task is the line-searched last attempt
        plain_reason = [None] * k               # why its plain Newton attempt failed
        t, load = self.cases["t"], self.cases["load"]
        stack, cases = root, np.arange(k)
        dofs = elements = slice(None)  # the working stack's rows of the state: all of it
        while True:
            resumed = ~finished & (n_pending > 0)   # a cut-back's next sub-step
            for c in np.flatnonzero(resumed):
                task_load[c], task_dt[c], task_depth[c], task_search[c] = pending[c].pop()
            n_pending[resumed] -= 1
            fresh = ~finished & ~resumed
            finished |= fresh & (next_step == n_steps)
            fresh &= ~finished                      # the next step of its list
            s = next_step[fresh]
            task_load[fresh] = load_table[fresh, s]
            task_dt[fresh] = time_table[fresh, s] - t[fresh] if times is not None else 1.0
            task_depth[fresh], task_search[fresh] = 0, False
            next_step[fresh] += 1
            if finished.all():
                return errors
            active = ~finished[cases]
            if active.sum() < 0.5 * stack.n_cases:
                cases = np.flatnonzero(~finished)
                stack, dofs, elements = root.subset(cases)
                active = np.ones(cases.size, dtype=bool)
            w = StepStart(u0=self.dofs["u"][dofs], v0=self.dofs["v"][dofs],
                          a0=self.dofs["a"][dofs], f0=self.dofs["f"][dofs],
                          du_prev=self.dofs["du_prev"][dofs],
                          theta_p=self.points["theta_p"][elements],
                          gamma_p=self.points["gamma_p"][elements],
                          load=task_load[cases], dt=task_dt[cases],
                          dt_old=self.cases["dt_old"][cases], has_prev=self.has_prev[cases],
                          active=active & ~task_search[cases])
            trial, ok, iterations, reasons, evaluations = self._attempt(stack, w, active,
                                                                        task_search[cases])
            self.counters["residual_evaluations"][cases] += evaluations
            self._commit(stack, cases, dofs, elements, ok, w, trial)
            done = cases[ok]
            self.cases["dt_old"][done] = task_dt[done]
            self.has_prev[done] = True
            load[done] = task_load[done]
            t[done] += task_dt[done]
            self.counters["steps"][done] += 1
            self.counters["newton_iterations"][done] += iterations[ok]
            self.counters["line_search_steps"][done] += task_search[done]
            if observers:
                for c in done[n_pending[done] == 0]:
                    for observer in observers:
                        observer(self, c, next_step[c] - 1)
            for i in np.flatnonzero(active & ~ok):
                c = cases[i]
                depth = task_depth[c]
                if depth >= self.max_cutbacks and not task_search[c]:
                    plain_reason[c] = reasons[i]
                    pending[c].append((task_load[c], task_dt[c], depth, True))
                    n_pending[c] += 1
                elif depth >= self.max_cutbacks:
                    wall = root.R_dofs[root.wall[c]] + self.dofs["u"][root.wall[c]]
                    prefix = describe(c, next_step[c] - 1) + ": " if describe else ""
                    errors[c] = CavexNumericalError(prefix + failure_message(
                        depth, t[c], wall, task_load[c], task_dt[c], plain_reason[c],
                        reasons[i]))
                    finished[c] = True
                else:
                    self.counters["cutbacks"][c] += 1
                    half = 0.5 * task_dt[c]
                    pending[c].append((task_load[c], half, depth + 1, False))
                    pending[c].append((0.5 * (load[c] + task_load[c]), half, depth + 1, False))
                    n_pending[c] += 2

    def _attempt(self, stack, w, active, search):
        """One Newton attempt of the active cases (the line-searched ones case by case).
        Returns ``((trial, response), ok, iterations, reasons, evaluations)`` on the working
        stack (``evaluations``: plain Newton's residual evaluations per case)."""
        u, a, f, resp, iterations, reasons, evaluations = newton(
            stack, w, self.params, self.newton_tol)
        if search.any():
            u, a, f = u.copy(), a.copy(), f.copy()
            resp = resp.copy()
            for i in np.flatnonzero(search):
                sub, sdofs, selements = stack.subset([i])
                sw = w.subset(sdofs, selements, [i])
                su, sa, sf, sresp, iterations[i], reasons[i] = newton_line_search(
                    sub, sw, self.params, self.newton_tol)
                if reasons[i] is None:
                    u[sdofs], a[sdofs], f[sdofs] = su, sa, sf
                    replace_points(resp, selements, sresp)
        ok = active & np.array([r is None for r in reasons])
        return (Trial(u, a, f), resp), ok, iterations, reasons, evaluations

    def _commit(self, stack, cases, dofs, elements, ok, w, trial):
        """Accept the converged cases ``ok`` of the working ``stack`` (compiled:
        :func:`commit_cases`): velocities, plastic state, energies, wall reaction."""
        rows = (cases, self._rows if isinstance(dofs, slice) else dofs,
                self._point_rows if isinstance(elements, slice) else elements)  # Rows
        state = (tuple(self.dofs[name] for name in DOF_STATE),
                 tuple(self.points[name] for name in POINT_STATE),
                 tuple(self.cases[name] for name in CASE_STATE))
        trial, response = trial
        commit_cases(ok, rows, tuple(trial), tuple(response), tuple(w), tuple(stack.layout),
                     tuple(self.params), *state)

    def start_under_load(self, load):
        """Consistent start for a wall pressure ``load`` applied suddenly at ``t = 0+``.

        Sets the acceleration from ``M a_0 = r - f(u_0)`` on the free dofs (``r``: the wall
        load ``p 4 pi r^2``) and holds ``load`` as the current load, so that cut-backs do not
        ramp it. Call before the first step of a dynamic, pressure-controlled solver.
        """
        s = self.stack
        if not (self.dynamic and s.pressure_control and not self.counters["steps"].any()):
            raise ValueError("start_under_load needs a dynamic, pressure-controlled solver "
                             "before its first step")
        d = self.dofs
        residual = -d["f"] - s.mass @ d["a"]
        r_wall = s.R_dofs[s.wall] + d["u"][s.wall]
        residual[s.wall] += load * 4.0 * np.pi * r_wall ** 2
        increment, _ = s.solve(s.mass_band.copy(), residual, np.zeros(s.n_cases, dtype=bool))
        d["a"] += increment
        self.cases["load"][:] = load

    # ------------------------------------------------------------------ views of one case
    def case(self, c=0):
        """The state of case ``c``: ``u, v, a, f`` (radial dof order), ``response`` (per point
        ``tau_r, tau_t, theta_p, gamma_p, plastic, yield_ratio``), ``state`` (``theta_p,
        gamma_p, eq_p``), ``disc``, ``t``, ``load``, ``wall_force``, energies and counters."""
        s = self.stack
        d, e = s.dofs(c), s.elements(c)
        pts = {name: value[e] for name, value in self.points.items()}
        return SimpleNamespace(
            disc=s.discs[c], **{name: value[d] for name, value in self.dofs.items()},
            response=SimpleNamespace(**{n: pts[n] for n in POINT_STATE if n != "eq_p"}),
            state={n: pts[n] for n in ("theta_p", "gamma_p", "eq_p")},
            **{name: float(value[c]) for name, value in self.cases.items()},
            **{name: int(value[c]) for name, value in self.counters.items()})

    def kinetic_energy(self, c=0):
        d = self.stack.dofs(c)
        v = self.dofs["v"][d]
        return 0.5 * float(v @ (self.stack.discs[c].mass @ v))

    def stored_energy(self, c=0):
        """Hencky energy ``K theta_e^2/2 + (2/3) G gamma_e^2`` integrated over case ``c``;
        where the hydrostat is locked (fully compacted, ``x = -theta_e`` past ``x_l =
        lock_pressure/K``), the volumetric part ``K x_l^2/2 + P_l (x - x_l) + K_l (x -
        x_l)^2/2`` (:func:`cavex.fem.constitutive.hydrostat`)."""
        one = self.case(c)
        disc = one.disc
        g_r, g_t = disc.displacement_gradients(one.u)
        eps_r, eps_t = np.log1p(g_r), np.log1p(g_t)
        theta_e = eps_r + 2.0 * eps_t - one.state["theta_p"]
        gamma_e = eps_r - eps_t - one.state["gamma_p"]
        m = disc.material[:, None]  # per element
        K, G = m["K"], m["G"]
        volumetric = 0.5 * K * theta_e ** 2
        if np.any(np.isfinite(m["crush"])):
            # a layer without the hydrostat (crush = inf) is never locked; its infinite lock
            # constants are replaced by 0 before the arithmetic (no inf - inf, no inf * 0)
            compacting = np.isfinite(m["crush"])
            P_l, e_l, K_l = (np.where(compacting, m[k], 0.0)
                             for k in ("lock_pressure", "lock_strain", "locked_modulus"))
            x_l = P_l / K
            x = -theta_e
            locked = compacting & (-one.state["theta_p"] >= e_l - x_l) & (x > x_l)
            past = np.where(locked, x - x_l, 0.0)
            volumetric = np.where(locked, 0.5 * K * x_l ** 2 + P_l * past
                                  + 0.5 * K_l * past ** 2, volumetric)
        return float(np.sum(disc.weights * (volumetric + (2.0 / 3.0) * G * gamma_e ** 2)))

    # single-case shorthands (the solver of one problem)
    u = property(lambda self: self.case().u)
    v = property(lambda self: self.case().v)
    a = property(lambda self: self.case().a)
    f = property(lambda self: self.case().f)
    t = property(lambda self: float(self.cases["t"][0]))
    load = property(lambda self: float(self.cases["load"][0]))
    response = property(lambda self: self.case().response)
    state = property(lambda self: self.case().state)
