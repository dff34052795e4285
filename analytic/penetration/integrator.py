r"""Rigid-projectile penetration: crater stage, then tunnel stages (paper Eqs. 15, 30-34).

Crater (Eqs. 31-34): ``m L'' = -K L`` for ``0 <= L <= L_c``, so
``L = V_0 sqrt(m/K) sin(sqrt(K/m) t)``, ``V = V_0 cos(sqrt(K/m) t)``. ``K`` and the exit velocity
``V_c`` follow from energy, ``K L_c^2 = m (V_0^2 - V_c^2)``, and continuity of force with the
single-medium tunnel resistance, ``K L_c = F_1(V_c)``; for ``F_1 = C_A + C_B V^2`` this is the
paper's ``V_c^2 = (m V_0^2 - L_c C_A)/(m + L_c C_B)``. ``L_c = 4.5 r`` is the crater depth
measured from the nose base (``crater="nose-base"``, the nose tip then at ``l + 4.5 r``) or from
the nose tip (``crater="nose-tip"``).

Tunnel: ``m dV/dt = -F(L, V)``, ``dL/dt = V`` with ``scipy.integrate.solve_ivp``; a phase ends
(terminal event) where the response-state label of the resistance changes, where the nose tip
crosses an interface depth ``H_i``, or where ``V = 0``. :func:`integrate` runs one such stretch
from any start state ``(t0, L0, V0)``; :func:`penetrate` chains them, and the Table 2 study runs
it from the paper's own row states.

The resistance is any :class:`~cavex.analytic.penetration.resistance.Resistance`. One that
has ``force_jumps`` (nose-tip depths where ``F`` jumps in ``L``: the plain law's rings crossing
the surface and the interfaces, :class:`~cavex.analytic.penetration.plain_law.
PlainLawResistance`) gets a step end at each: the stretch stops there and the same phase goes
on (unless its label changes there), so that no step straddles a jump and the tolerance holds;
a resistance without them integrates as before.
"""

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from cavex.analytic.penetration.zones import CRATER_MODES, CRATER_RATIO, crater_depth, scab_depth
from cavex.errors import CavexNumericalError

__all__ = ["CRATER_MODES", "CRATER_RATIO", "crater_depth", "penetrate", "integrate"]

STOPPED = "projectile stopped"
STATE_CHANGED = "response state changed"
DEPTH_REACHED = "stop depth reached"
FORCE_JUMP = "force jumps"  # a stretch's end at one of the resistance's force_jumps
RTOL, ATOL = 1e-9, 1e-12  # solve_ivp's tolerances
MAX_PHASE_DURATION = 10.0  # s; a phase that has not ended by then is a numerical failure


@dataclass(frozen=True)
class Phase:
    """One phase of the trajectory: its label (None where :func:`integrate` did not watch the
    state), where and when it ends, and its stage (:data:`~cavex.analytic.penetration.zones.
    STAGES`: "crater", "tunnel", or "rear face" in the rear zone above a debonded
    interface)."""

    label: str
    end_depth: float
    end_velocity: float
    end_time: float
    end_reason: str
    stage: str = "tunnel"
    end_mass: float | None = None  # kg, with erosion only (None: the rigid mass throughout)


ROWS_PER_PHASE = 20  # intervals of an integrated phase in the written trajectory (rows)


@dataclass(frozen=True)
class Trajectory:
    """Time, nose depth, velocity, deceleration and phase index at every output point."""

    t: np.ndarray
    depth: np.ndarray
    velocity: np.ndarray
    deceleration: np.ndarray
    phase: np.ndarray
    phases: tuple
    mass: np.ndarray | None = None  # kg at every output point, with erosion only
    erosion: dict | None = None  # :meth:`~cavex.analytic.penetration.erosion.ErodingNose.summary`
    sampled: dict | None = None  # the rows of :meth:`rows`

    def as_columns(self):
        """Columns for CSV output, in SI units (``mass_kg`` with erosion only)."""
        columns = {"t_s": self.t, "depth_m": self.depth, "velocity_m_s": self.velocity,
                   "deceleration_m_s2": self.deceleration, "phase": self.phase}
        return columns if self.mass is None else {**columns, "mass_kg": self.mass}

    def rows(self):
        """The columns of the written trajectory: :data:`ROWS_PER_PHASE` equal intervals of
        time within each integrated phase (its start and end included; the crater stages'
        closed-form samples as they are), on the integrator's dense output with the force
        evaluated at each row, instead of at the integrator's steps, whose places move with
        the last bits of the force (another CPU would write other rows). With erosion the
        rows carry the mass too (``mass_kg``, the dense output's third state)."""
        if self.sampled is None:
            return self.as_columns()
        return dict(self.sampled)


def crater_exit(projectile, force, depth, speed=None):
    """Exit velocity ``V_c`` and stiffness ``K`` of the crater: ``m (V0^2 - Vc^2) = L_c F(Vc)``
    (``speed``: the velocity ``V0`` at the crater's start; None: the striking velocity)."""
    m, v0 = projectile.m, projectile.V0 if speed is None else speed

    def balance(v):
        return m * (v0 ** 2 - v ** 2) - depth * force(v)

    if balance(0.0) <= 0.0:
        raise CavexNumericalError(
            f"projectile stops inside the crater (V0={v0} m/s, crater depth {depth} m)")
    vc = brentq(balance, 0.0, v0, xtol=1e-13, rtol=1e-15)
    return vc, m * (v0 ** 2 - vc ** 2) / depth ** 2


def crater_stage(projectile, force, depth, samples=50, start=None):
    """Crater trajectory samples ``(t, L, V, a)`` and the exit ``(t_c, V_c)``, from
    ``start = (t0, L0, V0)`` (None: the entry face, ``(0, 0, V_0)``): ``L = L0 + V0/omega
    sin(omega (t - t0))``, ``V = V0 cos(omega (t - t0))``, ``omega = sqrt(K/m)``, for a nose-tip
    travel ``depth`` (:func:`cavex.analytic.penetration.zones.crater_depth`).

    A projectile the crater stops (``m V0^2 <= L_c F(0)``) rests at
    ``L_s = V0 sqrt(m / K) = sqrt(m V0^2 L_c / F(0))``, ``K L_c = F(0)`` (the crater's force
    continuous with the tunnel's at rest), at ``t_s = (pi / 2) sqrt(m / K)``, ``V_c = 0``; at
    the threshold ``L_s = L_c``, continuous with the tunnel branch."""
    t0, depth0, v0 = (0.0, 0.0, projectile.V0) if start is None else start
    m = projectile.m
    if m * v0 ** 2 <= depth * force(0.0):
        stiffness = force(0.0) / depth
        omega = math.sqrt(stiffness / m)
        tc, vc, end = 0.5 * math.pi / omega, 0.0, v0 / omega
    else:
        vc, stiffness = crater_exit(projectile, force, depth, v0)
        omega = math.sqrt(stiffness / m)
        if not omega > 0.0:  # V_c = V0 to round-off: a mass that the target cannot slow
            raise CavexNumericalError(f"the crater does not slow the projectile (m = "
                                      f"{m:g} kg, V0 = {v0:g} m/s)")
        tc, end = math.acos(vc / v0) / omega, depth
    t = np.linspace(0.0, tc, samples)
    depths = v0 / omega * np.sin(omega * t)
    velocity = v0 * np.cos(omega * t)
    depths[-1], velocity[-1] = end, vc  # the exit state exactly, not re-rounded
    deceleration = stiffness * depths / m
    if start is not None:
        t, depths = t + t0, depths + depth0
    return (t, depths, velocity, deceleration), t0 + tc, vc


def penetrate(target, projectile, resistance, *, crater="nose-base", rtol=RTOL, atol=ATOL,
              erosion=None):
    """Integrate the projectile through the target.

    Parameters
    ----------
    target, projectile : Target, Projectile
        At a debonded interface (``target.debonded``; docs/analytic.md "Debonded
        interfaces") the phase ends where the nose tip enters the rear zone (then stage "rear
        face") and where it reaches the interface; a crater stage in the next layer follows.
    resistance : Resistance
        With a debonded interface, one that has ``layer_force(index, V)`` (the crater medium
        below it): :class:`~cavex.analytic.penetration.resistance.ClosedFormResistance`.
    crater : {"nose-base", "nose-tip"}
        Where the crater depth ``4.5 r`` is measured from; ``None`` skips the crater stages.
    erosion : ErodingNose, optional
        Nose erosion (:mod:`cavex.analytic.penetration.erosion`): the mass and the nose's CRH
        become state, the force is the current nose's; the crater's loss is applied at its
        end. None, or a law that is off for this striking velocity (``erosion.active``
        False): the rigid projectile, the same numbers bit for bit. With erosion the depths
        (and so the layers' geometry and the interface stops) are the original nose tip's;
        the eroded tip's final depth is ``Trajectory.erosion["tip_depth_m"]``.

    Returns
    -------
    Trajectory
    """
    if erosion is not None and erosion.active:
        return _eroding_penetrate(target, projectile, resistance, crater, rtol, atol, erosion)
    columns = [[] for _ in range(6)]  # t, depth, velocity, deceleration, phase; rows
    phases = []
    t0, depth0, v0 = 0.0, 0.0, projectile.V0
    if crater is not None:
        depth0 = crater_depth(projectile, crater)
        samples, t0, v0 = crater_stage(projectile, resistance.crater_force, depth0)
        _append(columns, *samples, 0)
        depth0 = samples[1][-1]  # short of the crater depth where the crater stops it
        phases.append(Phase("crater", depth0, v0, t0,
                            "crater depth reached" if v0 > 0.0 else STOPPED, "crater"))
    return _tunnel(target, projectile, resistance, (t0, depth0, v0), columns, phases,
                   crater=crater, rtol=rtol, atol=atol)


def _eroding_penetrate(target, projectile, resistance, crater, rtol, atol, erosion):
    """:func:`penetrate` with an eroding nose: the rigid crater stage, its loss
    (:meth:`~cavex.analytic.penetration.erosion.ErodingNose.crater_loss`) applied at its end,
    then the tunnel phases of the state ``(L, V, m)`` (:func:`_tunnel`)."""
    columns = [[] for _ in range(6)]  # t, depth, velocity, deceleration, phase; rows
    phases, masses = [], []
    t0, depth0, v0 = 0.0, 0.0, projectile.V0
    mass = projectile.m - erosion.lost
    if crater is not None:
        depth0 = crater_depth(projectile, crater)
        samples, t0, v0 = crater_stage(replace(projectile, m=mass, crh=None),
                                       resistance.crater_force, depth0)
        _append(columns, *samples, 0)
        depth0 = samples[1][-1]
        masses.append(np.full(len(samples[0]), mass))
        columns[5][-1].append(masses[-1])  # the crater's rows are its samples: one mass array
        mass -= erosion.crater_loss(projectile, 0.5 * mass * (projectile.V0 ** 2 - v0 ** 2))
        masses[-1][-1] = mass
        phases.append(Phase("crater", depth0, v0, t0,
                            "crater depth reached" if v0 > 0.0 else STOPPED, "crater",
                            end_mass=mass))
    trajectory = _tunnel(target, projectile, resistance, (t0, depth0, v0), columns, phases,
                         crater=crater, rtol=rtol, atol=atol, erosion=erosion, mass=mass,
                         masses=masses)
    end_mass = float(trajectory.mass[-1])
    return replace(trajectory, erosion=erosion.summary(end_mass, float(trajectory.depth[-1])))


def phase_stops(target, projectile):
    """``[(depth, reason, next stage)]``: where a tunnel phase ends by the nose tip's depth.
    A bonded interface ``H`` ends it (stage "tunnel" goes on); a debonded one twice: at the
    rear zone's top ``H - s`` ("rear face") and at ``H`` ("crater": the next layer's crater
    stage follows)."""
    stops = []
    for j, H in enumerate(target.interface_depths):
        reached = f"nose tip reached interface {j + 1}"
        if target.bottoms[j] == "debonded":
            stops.append((H - scab_depth(target, projectile, j),
                          f"nose tip reached the rear zone of interface {j + 1}", "rear face"))
            stops.append((H, reached + " (debonded)", "crater"))
        else:
            stops.append((H, reached, "tunnel"))
    return stops


def _tunnel(target, projectile, resistance, start, columns, phases, crater, rtol, atol,
            erosion=None, mass=None, masses=None):
    """Phases from ``start = (t0, L0, V0)`` to rest, each ended by :func:`integrate` (and a
    crater stage below each debonded interface, :func:`phase_stops`). With ``erosion`` the
    mass is state too: ``mass`` at the start, ``masses`` the list its samples go to."""
    label = resistance.label(start[1], start[2])
    stops = phase_stops(target, projectile)
    jumps = [(depth, FORCE_JUMP, None) for depth in getattr(resistance, "force_jumps", ())]
    ahead = sorted((stop for stop in stops + jumps if stop[0] > start[1]),
                   key=lambda stop: stop[0])
    stage = "rear face" if any(s[2] == "rear face" and s[0] <= start[1] < d[0]
                               for s, d in zip(stops, stops[1:], strict=False)) else "tunnel"
    while start[2] > 0.0:
        stop_depth, stop_reason = (ahead[0][0], ahead[0][1]) if ahead else (None, None)
        if erosion is None:
            phase, sol = integrate(resistance, projectile.m, start, stop_depth=stop_depth,
                                   stop_reason=stop_reason, label=label, rtol=rtol, atol=atol)
            _append_solution(columns, sol, phase, resistance, projectile.m, len(phases))
        else:
            phase, sol = integrate(resistance, mass, start, stop_depth=stop_depth,
                                   stop_reason=stop_reason, label=label, rtol=rtol, atol=atol,
                                   erosion=erosion)
            _append_solution(columns, sol, phase, resistance, None, len(phases), erosion)
            masses.append(np.append(sol.sol(columns[0][-1][:-1])[2], phase.end_mass))
            mass = phase.end_mass
        start = (phase.end_time, phase.end_depth, phase.end_velocity)
        if phase.end_reason == FORCE_JUMP:  # a step ends where the force jumps; the phase
            ahead.pop(0)                    # goes on past it unless the label changes there
            new = _next_label(resistance, sol, phase.end_time, label)
            if new == label and start[2] > 0.0:
                continue
            phase, label = replace(phase, end_reason=STATE_CHANGED), new
            phases.append(replace(phase, stage=stage))
            continue
        phases.append(replace(phase, stage=stage))
        if phase.end_reason == stop_reason:
            stage = ahead.pop(0)[2]
            if stage == "crater":
                if erosion is not None:
                    start, mass = _eroding_interface_crater(target, projectile, resistance,
                                                            start, columns, phases, crater,
                                                            erosion, mass, masses)
                else:
                    start = _interface_crater(target, projectile, resistance, start, columns,
                                              phases, crater)
                stage = "tunnel"
                ahead = [stop for stop in ahead if stop[0] > start[1]]
                if start[2] > 0.0:
                    label = resistance.label(start[1], start[2])
                continue
        if start[2] > 0.0:
            label = _next_label(resistance, sol, phase.end_time, label)
    if erosion is not None:
        return replace(_trajectory(columns, phases), mass=np.concatenate(masses))
    return _trajectory(columns, phases)


def _eroding_interface_crater(target, projectile, resistance, start, columns, phases, crater,
                              erosion, mass, masses):
    """:func:`_interface_crater` of the eroding projectile (its current mass, its nose as it
    struck; the crater's loss at its end); returns the state at its end and the mass."""
    flown = replace(projectile, m=mass, crh=None)
    n = len(columns[0])
    end = _interface_crater(target, flown, resistance, start, columns, phases, crater)
    if len(columns[0]) == n:  # no crater stage
        return end, mass
    mass = float(mass - erosion.crater_loss(projectile, 0.5 * mass * (start[2] ** 2 - end[2] ** 2)))
    masses.append(np.full(len(columns[0][-1]), mass))
    columns[5][-1].append(masses[-1])  # the crater's rows are its samples: one mass array
    phases[-1] = replace(phases[-1], end_mass=mass)
    return end, mass


def _interface_crater(target, projectile, resistance, start, columns, phases, crater):
    """The crater stage of the layer below a debonded interface, from ``start = (t, H, V)``
    at the interface: the entry crater's closed form (:func:`crater_stage`) with that layer's
    single-medium force; returns the state at its end (``crater`` None: no crater, ``start``)."""
    if crater is None or start[2] <= 0.0:
        return start
    index = target.layer_at(start[1])
    length = crater_depth(projectile, crater)
    samples, t_end, v_end = crater_stage(
        projectile, lambda v: resistance.layer_force(index, v), length, start=start)
    _append(columns, *samples, len(phases))
    reason = (f"crater depth reached ({target.layer_name(index)})" if v_end > 0.0
              else STOPPED)  # the crater may stop it, short of its depth
    phases.append(Phase("crater", samples[1][-1], v_end, t_end, reason, "crater"))
    return t_end, float(samples[1][-1]), v_end


def integrate(resistance, mass, start, *, stop_depth=None, stop_reason=DEPTH_REACHED,
              label=None, rtol=RTOL, atol=ATOL, erosion=None):
    r"""Integrate ``m dV/dt = -F(L, V)``, ``dL/dt = V`` from ``start = (t0, L0, V0)`` to the first
    of: rest (``V = 0``), the nose tip at ``stop_depth``, the response state leaving ``label``.

    ``scipy.integrate.solve_ivp`` (DOP853, dense output) with a terminal event for each end.
    The force is evaluated at ``(max(L, L0), max(V, 0))``: the true motion has ``V >= 0``, but a
    trial stage of a step that overshoots rest (``V < 0``) can carry ``L`` back above the start,
    even to the free surface.

    Parameters
    ----------
    resistance : Resistance
        Its ``force`` drives the motion, its ``label`` is watched when ``label`` is given.
    mass : float
        Projectile mass ``m`` (kg).
    start : tuple of float
        ``(t0, L0, V0)``: time (s), nose-tip depth (m), velocity (m/s) > 0.
    stop_depth : float, optional
        Nose-tip depth (m) at which the integration ends (None: not watched), with the reason
        ``stop_reason``; a state change at that depth (to 1e-12 relative) is reported as
        reaching it, and a phase that reaches it ends at it exactly (the next stage starts
        there: from the event's located depth, 1e-12 m on either side, a rear zone 1e-8 or
        1e-13 m deep gave the next layer's crater the upper layer's material, and 1e-15 m lost
        the debonded interface).
    label : str, optional
        The response-state label of the start; the integration ends where
        ``resistance.label`` differs from it (None: the state is not watched).
    rtol, atol : float
        Tolerances of ``solve_ivp``.
    erosion : ErodingNose, optional
        The mass ``m`` becomes a third state, ``mass`` its start:
        ``m dV/dt = -F_m(L, V)``, ``dm/dt = -V F_f / Q``
        (:meth:`~cavex.analytic.penetration.erosion.ErodingNose.forces`); the phase's
        ``end_mass`` is set. ``atol`` applies to the mass too (kg).

    Returns
    -------
    (Phase, scipy.integrate.OdeResult)
        The end (``end_velocity`` exactly 0 at rest; ``label`` as given) and the solution,
        whose ``sol`` interpolates inside the phase.
    """
    t0, depth0, v0 = start

    def rhs(t, y):  # depth never falls below the start: a trial stage past rest is clamped
        return (y[1], -resistance.force(max(y[0], depth0), max(y[1], 0.0)) / mass)

    def eroding_rhs(t, y):
        v = max(y[1], 0.0)
        force, friction = erosion.forces(resistance, max(y[0], depth0), v, y[2])
        return (y[1], -force / y[2], erosion.mass_rate(friction, v))

    events = _phase_events(resistance, stop_depth, stop_reason, label, t0)
    sol = solve_ivp(rhs if erosion is None else eroding_rhs, (t0, t0 + MAX_PHASE_DURATION),
                    (depth0, v0) if erosion is None else (depth0, v0, mass),
                    method="DOP853", events=[e for e, _ in events], dense_output=True,
                    rtol=rtol, atol=atol)
    if sol.status == 0:  # reached t0 + MAX_PHASE_DURATION: no event
        raise CavexNumericalError(
            f"the projectile was still moving {MAX_PHASE_DURATION:g} s into a phase (depth "
            f"{sol.y[0, -1]:.4g} m, {sol.y[1, -1]:.4g} m/s): a body this heavy or slender for "
            "the target, or a resistance this weak for the body, is beyond the model")
    if sol.status != 1:
        raise CavexNumericalError(f"penetration integration failed at t={sol.t[-1]} s, "
                                  f"depth {sol.y[0, -1]} m: {sol.message}")
    which = next(i for i, te in enumerate(sol.t_events) if te.size)
    t_end, (depth_end, v_end) = sol.t_events[which][0], sol.y_events[which][0][:2]
    reason = events[which][1]
    if (reason == STATE_CHANGED and stop_depth is not None
            and abs(depth_end - stop_depth) <= 1e-12 * stop_depth):
        reason = stop_reason  # a state change at the stop depth itself (nose-tip switch)
    if reason == STOPPED:
        v_end = 0.0
    if reason == stop_reason:  # at the stop's depth exactly: the event lands within its
        depth_end = stop_depth  # tolerance on either side, and the next stage starts there
    if erosion is not None:
        return Phase(label, depth_end, v_end, t_end, reason,
                     end_mass=float(sol.y_events[which][0][2])), sol
    return Phase(label, depth_end, v_end, t_end, reason), sol


def _phase_events(resistance, stop_depth, stop_reason, label, start_time=None):
    """Terminal events of one phase, each with the reason it ends the phase.

    The state event is +1 at the phase's start time ``start_time`` itself: a phase that
    starts where the previous one's state changed starts at that event's root, which may sit
    a root's width (``solve_ivp``'s 4 eps) before the jump, with the old label. Counted as -1
    there, the event would miss the phase's own end whenever the first step crosses the whole
    phase (a short phase under a smooth force: the nose's rings crossing an interface under
    the plain law). Only the value at the start changes: the steps do not depend on it."""

    def stopped(t, y):
        return y[1]

    def state_changed(t, y):
        if t == start_time:
            return 1.0
        # a trial point past the stop may lie above the surface (a force that does not fall
        # with V, e.g. a constant one, lets the error estimate vanish and the steps grow far
        # beyond the stop): the label there is the surface's; the stop event ends the phase
        return 1.0 if resistance.label(max(y[0], 0.0), max(y[1], 0.0)) == label else -1.0

    stopped.direction = state_changed.direction = -1.0
    events = [(stopped, STOPPED)]
    if stop_depth is not None:  # before the state change: where both coincide, the depth
        events.append((_depth_event(stop_depth), stop_reason))  # names the phase end
    if label is not None:
        events.append((state_changed, STATE_CHANGED))
    for event, _ in events:
        event.terminal = True
    return events


def _depth_event(depth):
    def reached(t, y):
        return y[0] - depth

    reached.direction = 1.0
    return reached


def _next_label(resistance, sol, t_end, label):
    """Label just past a phase end (the event root may sit on either side of the jump)."""
    for nudge in (0.0, 1e-13, 1e-11, 1e-9):
        depth, v = sol.sol(t_end * (1.0 + nudge))[:2]
        new = resistance.label(depth, max(v, 0.0))
        if new != label:
            return new
    return label


def _append(columns, t, depth, velocity, deceleration, phase, rows=True):
    """Append samples to the step columns ``columns[0:5]`` and (``rows``) as a block of the
    written rows ``columns[5]``."""
    block = [np.asarray(values, dtype=float) for values in (t, depth, velocity, deceleration,
                                                             np.full(len(t), phase))]
    for column, values in zip(columns[:5], block, strict=True):
        column.append(values)
    if rows:
        columns[5].append(block)


def _append_solution(columns, sol, phase_end, resistance, mass, phase, erosion=None):
    """The phase's samples at the integrator's steps up to its end, and its written rows
    (:meth:`Trajectory.rows`); at a stop the last velocity is exactly 0 m/s, as
    :func:`integrate` returns it (the dense output there is round-off, ~1e-14 m/s, that
    differs between CPUs)."""
    t_end = phase_end.end_time
    for t, rows in ((np.append(sol.t[sol.t < t_end], t_end), False),
                    (np.linspace(sol.t[0], t_end, ROWS_PER_PHASE + 1), True)):
        t[-1] = t_end
        y = sol.sol(t)
        y[0, -1] = phase_end.end_depth  # a stop depth exactly (:func:`integrate`)
        if phase_end.end_reason == STOPPED:
            y[1, -1] = 0.0
        depth = y[0].copy()
        if rows:  # the force at the ends on the phase's own side of a jump in it
            nudge = 1e-9 * abs(depth[-1] - depth[0])
            depth[0], depth[-1] = depth[0] + nudge, depth[-1] - nudge
        if erosion is None:
            deceleration = np.array([resistance.force(x, max(v, 0.0)) / mass
                                     for x, v in zip(depth, y[1], strict=True)])
        else:
            deceleration = np.array([erosion.forces(resistance, x, max(v, 0.0), m)[0] / m
                                     for x, v, m in zip(depth, y[1], y[2], strict=True)])
        if rows:
            block = [t, y[0], np.maximum(y[1], 0.0), deceleration, np.full(len(t), float(phase))]
            if erosion is not None:  # the mass at the rows, the phase's end mass at its end
                block.append(np.append(y[2][:-1], phase_end.end_mass))
            columns[5].append(block)
        else:
            _append(columns, t, y[0], np.maximum(y[1], 0.0), deceleration, phase, rows=False)


def _trajectory(columns, phases):
    t, depth, velocity, deceleration, phase = (np.concatenate(c) for c in columns[:5])
    names = ("t_s", "depth_m", "velocity_m_s", "deceleration_m_s2", "phase", "mass_kg")
    blocks = list(zip(*columns[5], strict=True))  # a mass column with erosion only
    sampled = {name: np.concatenate(c) for name, c in zip(names, blocks, strict=False)}
    sampled["phase"] = sampled["phase"].astype(int)
    return Trajectory(t, depth, velocity, deceleration, phase.astype(int), tuple(phases),
                      sampled=sampled)
