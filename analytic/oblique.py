r"""Oblique penetration with attitude: a rigid projectile in 3-D through the layered target.

Differential-area force law (``docs/oblique.md``): every surface element of the rigid body
(:mod:`cavex.analytic.projectile_body`) that is inside the target and moving into it
(``V_n = v_P . n > 0``, ``n`` its outward normal, ``v_P`` its velocity) feels the normal
stress ``sigma_n`` of a stress law at its own normal velocity, plus Coulomb friction
``mu sigma_n`` against its tangential velocity. The summed forces and moments about the centre
of mass drive the rigid body:

.. math:: m \dot{\mathbf v} = \sum_i \mathbf f_i, \quad
          I \dot{\boldsymbol\omega} + \boldsymbol\omega \times I \boldsymbol\omega
          = \sum_i \mathbf p_i \times \mathbf f_i \ \text{(body frame)}, \quad
          \dot q = \tfrac12 q \otimes (0, \boldsymbol\omega), \quad \dot{\mathbf x} = \mathbf v,

``f_i = -A_i w_i sigma_n,i (n_i + mu t_i)`` (``t_i`` the unit tangential velocity, ``w_i`` the
embedded fraction of the element). Target frame: free surface ``z = 0``, ``z`` positive into
the target, ``x`` along the striking velocity's horizontal component.

Stress laws (one object, ``stress(z, n, V_n)`` on arrays of wetted elements):

- :class:`DerivedLaw`: the layered cavity-expansion wall stress of :mod:`cavex.analytic.cavity`
  (either boundary convention) for a cavity of the shank radius ``a = r`` whose wall is the
  element: the element's own layer at the wall, then the layers met *along its outward normal*,
  each interface plane at radius ``a + d`` (``d`` the distance from the element to the plane
  along ``n``), the free surface ``z = 0`` (for an upward normal) as the traction-free sphere
  ``free_radius = a + z / (-n_z)``. A horizontal normal sees its own layer alone.
- :class:`PaperLaw`, :class:`TableLaw`: laws that exist only as functions of the 1-D nose depth
  ``L``; an element at depth ``z`` is mapped to ``L = z + l - r`` (the 1-D cavity wall ahead of
  the cavity centre ``L - l`` is at ``z``) and its normal velocity: vertical distances, no
  free-surface reduction.
- :class:`PlainLaw`: ``sigma_n = A + B V_n^2`` everywhere in the target.
"""

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from cavex.analytic.cavity import material_table, solve_flat
from cavex.analytic.paper_model import PaperModel
from cavex.analytic.projectile_body import build_body
from cavex.errors import CavexInputError, CavexNumericalError, require

G = 9.80665  # m/s^2, for overloads in g
HORIZONTAL = 1e-12  # |n_z| below which a normal counts as horizontal
FAR = 1e6  # m: interface radius standing for "never met"
STOP_ENERGY = 1e-6  # stop when translational + transverse rotational energy < this x initial
MAX_TIME = 1.0  # s
ROUND_OFF = 1e-9  # normal velocities below this x the body's velocity scale count as zero
METHOD, RTOL, ATOL = "RK45", 1e-6, 1e-9  # the final depth converged to 1e-4 (benchmark)
# contact regularisation: the stress rises linearly over 0 < V_n < RAMP (m/s); without it a
# shank sliding along the tunnel wall chatters (V_n changes sign every step) and the adaptive
# integrator stalls. Its effect is measured in docs/oblique.md.
RAMP = 1.0
RESISTANCES = ("derived", "paper", "table", "law")
BOUNDARIES = ("quasi-static", "dynamic")


# ------------------------------------------------------------------------------------------
# Stress laws
# ------------------------------------------------------------------------------------------

class DerivedLaw:
    """Layered cavity-expansion stress along each element's normal (see module docstring).

    Elements are grouped by the sequence of layers their normal ray meets (own layer and
    direction: at most ``2 n_layers`` groups); each group is one call of the compiled walk
    :func:`cavex.analytic.cavity.solve_flat` on all its elements, which is what
    :func:`cavex.analytic.cavity.cavity_stress` calls after checking its arguments (the test
    ``test_oblique_law`` checks the two agree element by element).
    """

    name = "derived"

    def __init__(self, target, radius, boundary="quasi-static", free_surface=True,
                 bottom=None):
        require(boundary in BOUNDARIES, "boundary", "'quasi-static' or 'dynamic'", boundary)
        self.target, self.radius, self.boundary = target, float(radius), boundary
        self.free_surface, self.bottom = free_surface, bottom
        self.depths = np.asarray(target.interface_depths, dtype=float)
        n = len(target.layers)
        self._down = [(material_table(tuple(target.layers[k:])), self.depths[k:])
                      for k in range(n)]
        self._up = [(material_table(tuple(target.layers[k::-1])), self.depths[:k][::-1])
                    for k in range(n)]
        self._dynamic = boundary == "dynamic"
        self._a = np.array([self.radius])

    def rays(self, z, nz):
        """``(group, layer index, interface radii, free radius)`` of every element: the
        spherical problem each one is the wall of (also what the tests hand to
        ``cavity_stress``)."""
        k = np.searchsorted(self.depths, z, side="right")
        a = self.radius
        out = []
        for direction in (1, -1, 0):
            if direction == 1:
                sel = nz > HORIZONTAL
            elif direction == -1:
                sel = nz < -HORIZONTAL
            else:
                sel = np.abs(nz) <= HORIZONTAL
            for layer in np.unique(k[sel]):
                idx = np.flatnonzero(sel & (k == layer))
                zi, ni = z[idx], nz[idx]
                if direction == 1:
                    planes = self._down[layer][1]
                    d = (planes[None, :] - zi[:, None]) / ni[:, None]
                    c = (np.full(idx.size, np.inf) if self.bottom is None
                         else a + (self.bottom - zi) / ni)
                    table = self._down[layer][0]
                elif direction == -1:
                    planes = self._up[layer][1]
                    d = (zi[:, None] - planes[None, :]) / (-ni[:, None])
                    c = (a + zi / (-ni) if self.free_surface
                         else np.full(idx.size, np.inf))
                    table = self._up[layer][0]
                else:
                    d = np.empty((idx.size, 0))
                    c = np.full(idx.size, np.inf)
                    table = material_table((self.target.layers[layer],))
                radii = a + np.minimum(np.maximum(d, 1e-12), FAR)
                layers = (self.target.layers[layer:] if direction == 1 else
                          self.target.layers[layer::-1] if direction == -1 else
                          (self.target.layers[layer],))
                out.append((idx, layers, table, radii, c))
        return out

    def stress(self, z, normals, vn):
        sigma = np.empty(z.size)
        for idx, _, table, radii, c in self.rays(z, normals[:, 2]):
            values, _, _ = solve_flat(table, np.ascontiguousarray(radii), vn[idx], self._a,
                                      np.ascontiguousarray(c), self._dynamic)
            sigma[idx] = values[:, 0]
        return sigma


class PaperLaw:
    """The paper's printed ``sigma_r = tau A + B rho V^2`` at the mapped nose depth
    ``L = z + l - r``, tabulated once on a depth grid (``spacing``, linear between nodes: the
    case switches, where the printed coefficients jump, are smeared over one cell)."""

    name = "paper"

    def __init__(self, target, projectile, epsilon="quasi-static", spacing=2e-4, extent=None):
        model = PaperModel(target, projectile, epsilon)
        self.offset = projectile.l - projectile.r
        deepest = (target.interface_depths[-1] if target.interface_depths else 0.0) + 0.5
        self.grid = np.arange(0.0, (extent or deepest) + spacing, spacing)
        terms = [model.terms(float(L)) for L in self.grid]
        self.s0 = np.array([t[2] * t[0] for t in terms])
        self.s2 = np.array([t[1] * t[3] for t in terms])

    def stress(self, z, normals, vn):
        L = np.maximum(z + self.offset, 0.0)
        return np.interp(L, self.grid, self.s0) + np.interp(L, self.grid, self.s2) * vn ** 2


class TableLaw:
    """FE-tabulated ``sigma_r(V, L)`` (:class:`~cavex.verification.tabulated_resistance.
    TabulatedResistance`) at the mapped depth ``L = z + l - r`` and ``V = V_n``: resampled once
    on a fine ``(L, V^2)`` grid through the table's own interpolant, then bilinear. Depths above
    the table's shallowest row take that row; velocities beyond the table's are refused."""

    name = "table"

    def __init__(self, resistance, depth_points=600, velocity_points=121, extent=None):
        self.resistance = resistance
        p = resistance.projectile
        self.offset = p.l - p.r
        lo = float(resistance.depths[0])
        hi = max(float(resistance.depths[-1]), lo + 1e-3) if extent is None else extent
        self.grid = np.linspace(lo, hi, depth_points)
        self.vmax = float(resistance.velocities[-1])
        self.v2 = np.linspace(0.0, self.vmax ** 2, velocity_points)
        self.values = np.array([resistance.wall_stress(L, np.sqrt(self.v2)) for L in self.grid])

    def stress(self, z, normals, vn):
        if vn.size and vn.max() > self.vmax:
            raise CavexInputError(f"normal velocity {vn.max():.6g} m/s exceeds the table's "
                                  f"largest velocity {self.vmax:g} m/s")
        L = np.clip(z + self.offset, self.grid[0], self.grid[-1])
        fi = (L - self.grid[0]) / (self.grid[1] - self.grid[0])
        i = np.minimum(fi.astype(int), self.grid.size - 2)
        u = fi - i
        fj = vn ** 2 / self.v2[1]
        j = np.minimum(fj.astype(int), self.v2.size - 2)
        w = fj - j
        V = self.values
        return ((1 - u) * ((1 - w) * V[i, j] + w * V[i, j + 1])
                + u * ((1 - w) * V[i + 1, j] + w * V[i + 1, j + 1]))


class PlainLaw:
    """``sigma_n = A + B V_n^2`` (A in Pa, B in kg/m^3) everywhere in the target."""

    name = "law"

    def __init__(self, A, B):
        for name, value in (("law_A", A), ("law_B", B)):
            require(isinstance(value, (int, float)) and math.isfinite(value) and value >= 0.0,
                    name, "a finite number >= 0", value)
        self.A, self.B = float(A), float(B)

    def stress(self, z, normals, vn):
        return self.A + self.B * vn ** 2


# ------------------------------------------------------------------------------------------
# Shot set-up
# ------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Shot:
    """Striking conditions. Angles in degrees: ``obliquity`` between the velocity and the
    target normal (+z; negative: the mirror shot, velocity toward -x), ``attack`` between the
    axis and the velocity, turned in the plane at ``attack_plane`` about the velocity (0: in
    the plane of obliquity, nose toward +x / the surface; 90: toward +y). ``spin`` (rad/s)
    about the axis. ``tip_depth``: initial nose-tip depth (m); None: the body's deepest point
    just touches the surface."""

    speed: float
    obliquity: float = 0.0
    attack: float = 0.0
    attack_plane: float = 0.0
    spin: float = 0.0
    tip_depth: float | None = None

    def __post_init__(self):
        require(math.isfinite(self.speed) and self.speed > 0, "speed", "> 0 m/s", self.speed)
        require(math.isfinite(self.obliquity) and abs(self.obliquity) < 90.0, "obliquity",
                "in (-90, 90) degrees", self.obliquity)
        require(math.isfinite(self.attack) and 0.0 <= self.attack < 90.0, "attack",
                "in [0, 90) degrees", self.attack)
        require(math.isfinite(self.attack_plane), "attack_plane", "finite (degrees)",
                self.attack_plane)
        require(math.isfinite(self.spin), "spin", "finite (rad/s)", self.spin)

    def initial_axes(self):
        """``(velocity direction, axis, body e2, body e3)`` in the target frame."""
        th = math.radians(self.obliquity)
        d = np.array([math.sin(th), 0.0, math.cos(th)])
        side = -1.0 if self.obliquity < 0 else 1.0  # negative obliquity: the mirror shot
        ep = np.array([side * math.cos(th), 0.0, -abs(math.sin(th))])  # toward the surface
        ey = np.array([0.0, 1.0, 0.0])
        al, ps = math.radians(self.attack), math.radians(self.attack_plane)
        turn = math.cos(ps) * ep + math.sin(ps) * ey
        axis = math.cos(al) * d + math.sin(al) * turn
        e2 = math.cos(al) * turn - math.sin(al) * d  # unit, orthogonal to the axis
        # e2 stays in the plane of obliquity for in-plane shots, e3 = axis x e2
        e3 = np.cross(axis, e2)
        return d, axis, e2, e3


def quaternion_from_matrix(m):
    """Unit quaternion ``(w, x, y, z)`` of a rotation matrix (body to target)."""
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        q = [0.0] * 4
        q[0] = (m[k, j] - m[j, k]) / s
        q[1 + i] = 0.25 * s
        q[1 + j] = (m[j, i] + m[i, j]) / s
        q[1 + k] = (m[k, i] + m[i, k]) / s
    q = np.array(q)
    return q / np.linalg.norm(q)


def rotation(q):
    """Rotation matrix (body to target) of a quaternion ``(w, x, y, z)`` (normalised here)."""
    w, x, y, z = q / math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def pitch_yaw(axis):
    """Pitch (deg): angle of the axis from +z in the x-z plane, positive toward +x; yaw (deg):
    angle of the axis out of the x-z plane, positive toward +y."""
    axis = np.asarray(axis)
    return (np.degrees(np.arctan2(axis[..., 0], axis[..., 2])),
            np.degrees(np.arctan2(axis[..., 1], np.hypot(axis[..., 0], axis[..., 2]))))


# ------------------------------------------------------------------------------------------
# The model
# ------------------------------------------------------------------------------------------

@dataclass
class Result:
    """Trajectory: samples at the integrator's steps (``history``), phases and the end."""

    history: dict
    phases: list
    end: dict
    solutions: list = field(default_factory=list, repr=False)
    model: object = field(default=None, repr=False)

    def state(self, t):
        """State vector at time ``t`` (dense output of the phase that contains it)."""
        for sol in self.solutions:
            if sol.t[0] <= t <= sol.t[-1]:
                return sol.sol(t)
        raise ValueError(f"t = {t} s is outside the trajectory")


class ObliqueModel:
    """Rigid projectile + stress law + layered target: right-hand side, events, integrator.

    State ``y``: centre of mass ``x`` (3), quaternion ``q`` (4, body to target), velocity ``v``
    (3), body-frame angular velocity ``omega`` (3), work of the surface forces ``W`` (1).
    """

    def __init__(self, target, projectile, law, *, body=None, bottom=None, rtol=RTOL,
                 atol=ATOL, method=METHOD, ramp=RAMP):
        self.target, self.projectile, self.law = target, projectile, law
        self.body = body or build_body(projectile)
        self.bottom = bottom
        self.rtol, self.atol, self.method = rtol, atol, method
        require(math.isfinite(ramp) and ramp >= 0.0, "ramp", ">= 0 m/s", ramp)
        self.ramp = float(ramp)
        self.mu = float(projectile.mu)
        self.interfaces = list(target.interface_depths)
        b = self.body
        self._p, self._n, self._area, self._h = b.points, b.normals, b.areas, b.sizes
        self._inertia = b.inertia
        self._tip = b.tip
        self.evaluations = 0

    # -- forces ---------------------------------------------------------------------------
    def loads(self, y):
        """``(F, M_body, power, rotation)``: total surface force (target frame), moment about
        the centre of mass (body frame), power of the surface forces, rotation matrix."""
        self.evaluations += 1
        rot = rotation(y[3:7])
        p = self._p @ rot.T
        n = self._n @ rot.T
        omega_t = rot @ y[10:13]
        vel = y[7:10] + _cross(omega_t, p)
        vn = np.einsum("ij,ij->i", vel, n)
        # round-off guard: a normal velocity below 1e-9 of the body's velocity scale is zero
        scale = math.sqrt(float(y[7:10] @ y[7:10])) + self.body.length * math.sqrt(
            float(omega_t @ omega_t))
        z = y[2] + p[:, 2]
        frac = np.clip(0.5 + z / self._h, 0.0, 1.0)
        if self.bottom is not None:
            frac = np.minimum(frac, np.clip(0.5 + (self.bottom - z) / self._h, 0.0, 1.0))
        wet = np.flatnonzero((frac > 0.0) & (vn > ROUND_OFF * scale))
        if wet.size == 0:
            return np.zeros(3), np.zeros(3), 0.0, rot
        zi = np.maximum(z[wet], 1e-12)
        sigma = self.law.stress(zi, n[wet], vn[wet])
        load = sigma * self._area[wet] * frac[wet]
        if self.ramp > 0.0:
            load *= np.minimum(vn[wet] / self.ramp, 1.0)
        f = -load[:, None] * n[wet]
        if self.mu > 0.0:
            vt = vel[wet] - vn[wet, None] * n[wet]
            speed = np.linalg.norm(vt, axis=1)
            ok = speed > 1e-12
            f[ok] -= (self.mu * load[ok] / speed[ok])[:, None] * vt[ok]
        force = f.sum(axis=0)
        moment = rot.T @ _cross(p[wet], f).sum(axis=0)
        power = float(np.einsum("ij,ij->", f, vel[wet]))
        return force, moment, power, rot

    def rhs(self, t, y):
        force, moment, power, rot = self.loads(y)
        w, I = y[10:13], self._inertia  # noqa: E741 (the inertia tensor)
        q = y[3:7]
        dq = 0.5 * np.array([
            -q[1] * w[0] - q[2] * w[1] - q[3] * w[2],
            q[0] * w[0] + q[2] * w[2] - q[3] * w[1],
            q[0] * w[1] - q[1] * w[2] + q[3] * w[0],
            q[0] * w[2] + q[1] * w[1] - q[2] * w[0]])
        dw = (moment - _cross(w, I * w)) / I
        return np.concatenate([y[7:10], dq, force / self.body.mass, dw, [power]])

    # -- kinematics -----------------------------------------------------------------------
    def initial_state(self, shot):
        d, axis, e2, e3 = shot.initial_axes()
        rot = np.column_stack([axis, e2, e3])
        q = quaternion_from_matrix(rot)
        rot = rotation(q)
        tip_offset = rot @ self._tip
        x = -tip_offset  # nose tip above the origin
        if shot.tip_depth is None:  # the deepest point of the body on the surface
            x[2] = -max(float((self._p @ rot.T)[:, 2].max()), float(tip_offset[2]))
        else:
            x[2] += shot.tip_depth
        v = shot.speed * d
        omega = np.array([shot.spin, 0.0, 0.0])
        return np.concatenate([x, q, v, omega, [0.0]])

    def energy(self, y, transverse_only=False):
        """Kinetic energy (J): translational plus rotational (without spin if asked)."""
        w, I = y[10:13], self._inertia  # noqa: E741 (the inertia tensor)
        rotational = 0.5 * (I[1] * w[1] ** 2 + I[2] * w[2] ** 2)
        if not transverse_only:
            rotational += 0.5 * I[0] * w[0] ** 2
        return 0.5 * self.body.mass * float(y[7:10] @ y[7:10]) + rotational

    def tip(self, y):
        return y[0:3] + rotation(y[3:7]) @ self._tip

    def axis(self, y):
        return rotation(y[3:7])[:, 0]

    def extreme_depths(self, y):
        """Deepest and shallowest depth of the body surface (elements and tip)."""
        z = y[2] + (self._p @ rotation(y[3:7]).T)[:, 2]
        tz = self.tip(y)[2]
        return max(z.max(), tz), min(z.min(), tz)

    # -- integration ----------------------------------------------------------------------
    def _events(self, y0, energy0):
        events = []

        def make_layer(H, j):
            def crossing(t, y):
                return self.tip(y)[2] - H
            crossing.terminal, crossing.crossing, crossing.interface = True, True, j
            return crossing, f"nose tip crossed interface {j + 1} (z = {H:g} m)"

        for j, H in enumerate(self.interfaces):
            events.append(make_layer(H, j))

        def ricochet(t, y):
            return self.extreme_depths(y)[0]
        ricochet.terminal, ricochet.direction = True, -1.0
        events.append((ricochet, "ricochet: left the target through the entry face"))
        if self.bottom is not None:
            def perforation(t, y):
                return self.extreme_depths(y)[1] - self.bottom
            perforation.terminal, perforation.direction = True, 1.0
            events.append((perforation, "perforation: left through the bottom face"))

        def parallel(t, y):
            return self.axis(y)[2]
        parallel.terminal, parallel.crossing = True, True
        events.append((parallel, "axis parallel to the surface"))

        threshold = STOP_ENERGY * energy0

        def stop(t, y):
            return self.energy(y, transverse_only=True) - threshold
        stop.terminal, stop.direction = True, -1.0
        events.append((stop, "stopped"))
        return events

    def run(self, shot, max_phases=50):
        """Integrate ``shot`` to a final event; returns a :class:`Result`."""
        y = self.initial_state(shot)
        energy0 = self.energy(y, transverse_only=True)
        events = self._events(y, energy0)
        t0, phases, sols = 0.0, [], []
        final = {"stopped", "ricochet: left the target through the entry face",
                 "perforation: left through the bottom face"}
        reason = "time limit"
        for event, _ in events:  # two-way events: the next crossing is away from the side
            if getattr(event, "crossing", False):  # the state is on now
                event.direction = 1.0 if event(t0, y) < 0.0 else -1.0
        label = self.phase_label(y)
        for _ in range(max_phases):
            sol = solve_ivp(self.rhs, (t0, MAX_TIME), y, method=self.method, rtol=self.rtol,
                            atol=self.atol, events=[e for e, _ in events], dense_output=True)
            if sol.status == -1:
                raise CavexNumericalError(f"trajectory integration failed at t = {sol.t[-1]} "
                                          f"s: {sol.message}")
            sols.append(sol)
            if sol.status == 0:
                phases.append(self._phase(label, sol.t[-1], sol.y[:, -1], "time limit"))
                break
            which = next(i for i, te in enumerate(sol.t_events) if te.size)
            t0, y = sol.t_events[which][0], sol.y_events[which][0].copy()
            reason = events[which][1]
            fired = events[which][0]
            phases.append(self._phase(label, t0, y, reason))
            if getattr(fired, "crossing", False):
                j = getattr(fired, "interface", None)
                if j is not None:  # the layer the tip has just entered
                    layer = j + 1 if fired.direction > 0 else j
                    label = self.target.layers[layer].name or f"layer {layer + 1}"
                fired.direction = -fired.direction
            if reason in final:
                break
        else:
            raise CavexNumericalError(f"more than {max_phases} phases")
        history = self._history(sols)
        return Result(history=history, phases=phases, end=self._end_state(y, t0, reason),
                      solutions=sols, model=self)

    def phase_label(self, y):
        layer = self.target.layer_at(max(self.tip(y)[2], 0.0))
        return self.target.layers[layer].name or f"layer {layer + 1}"

    def _phase(self, label, t, y, reason):
        end = self._end_state(y, t, reason)
        return {"label": label, "end_reason": reason, "end_time_s": end["time_s"],
                "end_nose_tip_m": end["nose_tip_m"], "end_pitch_deg": end["pitch_deg"],
                "end_speed_m_s": end["speed_m_s"]}

    def _end_state(self, y, t, reason):
        pitch, yaw = pitch_yaw(self.axis(y))
        state = {"stopped": "stopped", "time limit": "time limit"}.get(
            reason, reason.split(":")[0])
        return {"state": state, "time_s": float(t), "nose_tip_m": [float(c) for c in self.tip(y)],
                "centre_of_mass_m": [float(c) for c in y[0:3]],
                "pitch_deg": float(pitch), "yaw_deg": float(yaw),
                "speed_m_s": float(np.linalg.norm(y[7:10])),
                "work_J": float(y[13])}

    def _history(self, sols):
        t = np.concatenate([s.t if i == 0 else s.t[1:] for i, s in enumerate(sols)])
        Y = np.concatenate([s.y if i == 0 else s.y[:, 1:] for i, s in enumerate(sols)], axis=1)
        n = t.size
        out = {k: np.empty(n) for k in (
            "pitch_deg", "yaw_deg", "axial_g", "lateral_g")}
        tips, forces, moments, omegas = (np.empty((n, 3)) for _ in range(4))
        for i in range(n):
            y = Y[:, i]
            force, moment, _, rot = self.loads(y)
            axis = rot[:, 0]
            tips[i] = y[0:3] + rot @ self._tip
            forces[i], moments[i] = force, rot @ moment
            omegas[i] = rot @ y[10:13]
            axial = float(force @ axis)
            out["axial_g"][i] = -axial / (self.body.mass * G)
            out["lateral_g"][i] = np.linalg.norm(force - axial * axis) / (self.body.mass * G)
            out["pitch_deg"][i], out["yaw_deg"][i] = pitch_yaw(axis)
        history = {"t_s": t}
        for j, c in enumerate("xyz"):
            history[f"cg_{c}_m"] = Y[j]
        for j, c in enumerate("xyz"):
            history[f"tip_{c}_m"] = tips[:, j]
        for j, c in enumerate("xyz"):
            history[f"v_{c}_m_s"] = Y[7 + j]
        history["speed_m_s"] = np.linalg.norm(Y[7:10], axis=0)
        history["pitch_deg"], history["yaw_deg"] = out["pitch_deg"], out["yaw_deg"]
        for j, c in enumerate("xyz"):
            history[f"omega_{c}_rad_s"] = omegas[:, j]
        history["axial_g"], history["lateral_g"] = out["axial_g"], out["lateral_g"]
        for j, c in enumerate("xyz"):
            history[f"force_{c}_N"] = forces[:, j]
        for j, c in enumerate("xyz"):
            history[f"moment_{c}_N_m"] = moments[:, j]
        history["work_J"] = Y[13]
        return history


def _cross(a, b):
    """``a x b`` for ``(3,)`` or ``(n, 3)`` arrays (``np.cross`` costs ~20 us per call)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def make_law(target, projectile, resistance="derived", *, boundary="quasi-static",
             free_surface=True, table=None, law_A=None, law_B=None, epsilon="quasi-static",
             bottom=None):
    """The stress law for ``resistance`` (see the module docstring)."""
    require(resistance in RESISTANCES, "resistance", "one of " + ", ".join(RESISTANCES),
            resistance)
    if resistance == "derived":
        return DerivedLaw(target, projectile.r, boundary, free_surface, bottom)
    if resistance == "paper":
        return PaperLaw(target, projectile, epsilon)
    if resistance == "table":
        require(table is not None, "table", "given for --resistance table", None)
        from cavex.verification.tabulated_resistance import TabulatedResistance
        return TableLaw(TabulatedResistance(table, target, projectile))
    require(law_A is not None and law_B is not None, "law_A", "given with law_B for "
            "--resistance law", law_A)
    return PlainLaw(law_A, law_B)


def fly(target, projectile, shot=None, resistance="derived", *, body=None, bottom=None,
        rtol=RTOL, atol=ATOL, method=METHOD, ramp=RAMP, **law_options):
    """One trajectory: :class:`Result` of ``shot`` (default: normal incidence at ``V0``)."""
    shot = shot or Shot(projectile.V0)
    law = make_law(target, projectile, resistance, bottom=bottom, **law_options)
    model = ObliqueModel(target, projectile, law, body=body, bottom=bottom, rtol=rtol,
                         atol=atol, method=method, ramp=ramp)
    return model.run(shot)
