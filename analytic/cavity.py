r"""Spherical cavity expansion in concentric incompressible Mohr-Coulomb layers (derived model).

A cavity of radius ``a`` opened from zero radius at constant velocity ``V`` in concentric layers
(``layers[i]`` occupies ``interfaces[i-1] < r < interfaces[i]``, the last layer unbounded, or cut
by a traction-free outer boundary at ``r = c``, ``free_radius``). Compression is positive. With
``y = a/r`` the exact incompressible kinematics give the particle acceleration
``Dv/Dt = 2 V^2 (a/r^2 - a^4/r^5)`` and the momentum balance

.. math:: \frac{d\sigma_r}{dy} = \frac{2 D}{y} + 2\rho V^2 (1 - y^3), \qquad
          D = \sigma_r - \sigma_\theta,

integrated from ``y_c = a/c`` (``sigma_r = 0``; ``y_c = 0`` for the unbounded medium) to the
wall ``y = 1``. The deviator is

- elastic (small strain, ``u = a^3/(3 r^2)``, ``G = E/3``): ``D = (2E/3) y^3``;
- plastic: ``D = alpha sigma_r + k`` with ``alpha = 3 lam/(3 + 2 lam)`` and
  ``k = 3 tau/(3 + 2 lam)``, i.e. ``sigma_r - sigma_theta = lam sigma + tau``.

The kinematics, hence ``D`` in the elastic zone, do not depend on where the medium ends (the
pressure of an incompressible body is fixed by its boundary condition alone), so the finite
sphere differs from the unbounded medium only by the starting point ``y_c`` of the integration.

Both deviators are linear in ``sigma_r``, so each piece of a layer integrates in closed form.
With ``I(p, x) = int_1^x t^(p-1) dt = (x^p - 1)/p`` (``ln x`` at ``p = 0``, evaluated with
``expm1`` so that every ``lam`` in ``[0, 3)`` is finite and continuous, including
``alpha = 1/2``), going inward from ``y_o = a/r_o`` to ``y_i = a/r_i``, ``x = r_o/r_i``:

- elastic: ``s_i = s_o + (4E/9)(y_i^3 - y_o^3) + 2 rho V^2 [(y_i - y_o) - (y_i^4 - y_o^4)/4]``
- plastic: ``s_i = x^(2 alpha) s_o + 2k I(2 alpha, x)
  + 2 rho V^2 [y_i I(2 alpha - 1, x) - y_i^4 I(2 alpha - 4, x)]``.

Every step is affine in ``s_o`` and in ``V^2``, so the walk carries ``sigma_r = s_0 + s_2 V^2``
as its two parts (the quasi-static coefficients of :func:`quasi_static_coefficients`).

Where a layer yields is decided by a yield function at the elastic side of the boundary:

- ``"quasi-static"``: ``(2E/3) y^3 = tau``, i.e. ``b = a/epsilon`` with ``epsilon^3 = 3 tau/(2E)``
  frozen; ``sigma_r(b)`` still comes from the elastic solution (deviator plus inertia), as the
  paper's Eq. (26). ``S`` is then exactly ``A + B rho V^2/tau``.
- ``"dynamic"``: ``(2E/3) y^3 = alpha sigma_r(y) + k`` with the actual elastic-zone pressure,
  inertia included. In a layer this is ``g(y) = 0`` with ``g`` convex in ``y`` (``g'' > 0``), so
  the outermost root is unique and Newton's method from the inner end converges monotonically.

The walk goes outward-in, layer by layer: a layer whose yield function is met at its outer end is
plastic throughout; otherwise it is elastic down to its own yield radius (if reached) and
plastic inside. A layer may therefore stay elastic between plastic ones (an "elastic island");
the paper's eight states (Fig. 2) are the contiguous cases, labelled ``a``-``h`` below.

Implementation: one compiled (numba) loop over points, :func:`_walk`, is the only copy of the
algorithm. Every public function takes numpy arrays (``velocity`` of any shape, ``interfaces``
of shape ``(..., n_interfaces)``, ``radius`` and ``free_radius`` broadcasting with them) and
returns arrays of the broadcast shape; scalars in give a float out. A scalar call is the same
loop on one point.
"""

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numba import njit

from cavex.errors import CavexNumericalError
from cavex.problem import arrays, check_arrays

# Paper's Fig. 2 states, by number of concentric layers and position code of b:
# code 2j = b inside layer j, code 2j+1 = b held at interface j (layer j+1 not yielded).
PAPER_STATES = {3: "abcde", 2: "fgh"}

# Columns of the material table passed to the compiled walk (one row per layer).
E_, RHO, ALPHA, K, TAU, EPS = range(6)
# Bits of the state flags returned by the walk.
ISLAND, FREE, FAILED = 1, 2, 4
NEWTON_ITERATIONS = 100


@dataclass(frozen=True)
class CavityState:
    """Solution of the layered cavity-expansion problem at one point or an array of points.

    Every numeric attribute is a float for scalar input, else an array of the broadcast shape
    of ``velocity``, ``interfaces[..., 0]``, ``radius`` and ``free_radius``.

    Attributes
    ----------
    stress : float or ndarray
        ``sigma_r`` at the cavity wall (Pa, compression positive).
    S : float or ndarray
        ``stress / tau`` of the layer at the wall (``layers[0]``).
    radius, velocity : float or ndarray
        Cavity radius ``a`` (m) and expansion velocity ``V`` (m/s), broadcast.
    plastic_radius : float or ndarray
        Outermost radius of yielded material, ``b`` (equals ``radius`` if nothing yielded).
    zones : ndarray, shape (..., len(layers), 2)
        ``(r_inner, r_outer)`` of the yielded part of every layer, NaN where the layer is
        elastic or lies beyond the free surface.
    state : str or ndarray of str
        Paper's Fig. 2 letter (``a``-``h``), ``"single"`` for one layer or ``"elastic"``, with
        ``"+island"`` appended when a layer between plastic ones stays elastic and ``"+free"``
        when the plastic zone reaches the free surface. Layers beyond ``free_radius`` do not
        count (a three-layer target cut inside layer 2 has the two-layer labels).
    boundary : str
        Yield-at-boundary convention.
    free_radius : float, ndarray or None
        Traction-free outer radius (m), None for the unbounded medium.
    """

    stress: object
    S: object
    radius: object
    velocity: object
    plastic_radius: object
    zones: np.ndarray
    state: object
    boundary: str
    free_radius: object = None

    @property
    def plastic_zones(self):
        """Yielded intervals ``(layer, r_inner, r_outer)``, innermost first: a tuple for scalar
        input, else an object array of such tuples."""
        if self.zones.ndim == 2:
            return _zone_tuple(self.zones)
        out = np.empty(self.zones.shape[:-2], dtype=object)
        for index in np.ndindex(out.shape):
            out[index] = _zone_tuple(self.zones[index])
        return out


def _zone_tuple(zones):
    return tuple((i, float(r0), float(r1)) for i, (r0, r1) in enumerate(zones) if r0 == r0)


# ------------------------------------------------------------------------------------------
# The compiled walk: the one implementation of the closed forms
# ------------------------------------------------------------------------------------------

@njit(cache=True, error_model="numpy", inline="always")
def _power_integral(p, x):
    """``int_1^x t^(p-1) dt = (x^p - 1)/p`` (``ln x`` at ``p = 0``), finite ``x > 0``."""
    if p == 0.0:
        return math.log(x)
    return math.expm1(p * math.log(x)) / p


@njit(cache=True, error_model="numpy")
def _point(props, interfaces, row, a, c, v2, dynamic, zones, p, keep_zones):
    """One point of the outside-in walk through the layers (see :func:`_walk`).

    ``interfaces[row]`` are its interface radii, ``a`` the cavity radius, ``c`` the free radius
    (``inf``: unbounded), ``v2 = V^2``. Returns ``(s_0, s_2, b, position, flags, active)``
    and, if ``keep_zones``, writes the yielded ``(r_inner, r_outer)`` of every layer into
    ``zones[p]``.
    """
    n = props.shape[0]
    active = n  # layers inside the free surface
    for j in range(n - 1):
        if interfaces[row, j] >= c:
            active = j + 1
            break
    s0 = 0.0
    s2 = 0.0
    y_out = a / c
    outer = -1
    position = -1
    flags = 0
    b = a
    if keep_zones:
        for i in range(n):
            zones[p, i, 0] = np.nan
            zones[p, i, 1] = np.nan
    for i in range(active - 1, -1, -1):
        E = props[i, E_]
        rho = props[i, RHO]
        alpha = props[i, ALPHA]
        k = props[i, K]
        r_in = interfaces[row, i - 1] if i > 0 else a
        y_in = a / r_in if i > 0 else 1.0
        r_out = interfaces[row, i] if i < active - 1 else c
        # where the layer first yields going inward: y_yield in [y_out, y_in], or none
        yields = True
        y_yield = y_out
        if dynamic:
            rho_v2 = rho * v2
            s_out = s0 + s2 * v2
            E23 = 2.0 * E / 3.0
            if E23 * y_out ** 3 - alpha * s_out - k < 0.0:
                s_in = (s_out + (4.0 * E / 9.0) * (y_in ** 3 - y_out ** 3)
                        + rho_v2 * 2.0 * ((y_in - y_out) - 0.25 * (y_in ** 4 - y_out ** 4)))
                if E23 * y_in ** 3 - alpha * s_in - k < 0.0:
                    yields = False
                else:  # Newton on the convex g(y) from the inner end: monotone
                    y = y_in
                    converged = False
                    last = np.inf
                    for _ in range(NEWTON_ITERATIONS):
                        s = (s_out + (4.0 * E / 9.0) * (y ** 3 - y_out ** 3)
                             + rho_v2 * 2.0 * ((y - y_out) - 0.25 * (y ** 4 - y_out ** 4)))
                        g = E23 * y ** 3 - alpha * s - k
                        dg = 3.0 * E23 * y ** 2 - alpha * ((4.0 * E / 3.0) * y ** 2
                                                           + 2.0 * rho_v2 * (1.0 - y ** 3))
                        step = g / dg
                        y -= step
                        # converged: the step is at the last bits of y, or it has stopped
                        # shrinking at the level of the rounding noise of g (~1e-15 y when the
                        # terms of g cancel)
                        if abs(step) <= 4e-16 * y or (abs(step) <= 1e-12 * y
                                                      and abs(step) >= last):
                            converged = True
                            break
                        last = abs(step)
                    if not converged:
                        flags |= FAILED
                    y_yield = max(y, y_out)
        else:
            eps = props[i, EPS]
            if y_out < eps:
                if eps <= y_in:
                    y_yield = eps
                else:
                    yields = False
        y_elastic = y_yield if yields else y_in
        if y_elastic > y_out:  # elastic piece from y_out to y_elastic
            s0 += (4.0 * E / 9.0) * (y_elastic ** 3 - y_out ** 3)
            s2 += rho * 2.0 * ((y_elastic - y_out) - 0.25 * (y_elastic ** 4 - y_out ** 4))
        if yields:
            throughout = y_yield == y_out
            x = y_in / y_yield
            amplification = x ** (2.0 * alpha)
            s0 = amplification * s0 + 2.0 * k * _power_integral(2.0 * alpha, x)
            s2 = amplification * s2 + rho * 2.0 * (
                y_in * _power_integral(2.0 * alpha - 1.0, x)
                - y_in ** 4 * _power_integral(2.0 * alpha - 4.0, x))
            r_yield = r_out if throughout else a / y_yield
            if keep_zones:
                zones[p, i, 0] = r_in
                zones[p, i, 1] = r_yield
            if outer < 0:
                outer = i
                b = r_yield
                position = 2 * i + (1 if throughout and i < active - 1 else 0)
                if throughout and i == active - 1 and c < np.inf:
                    flags |= FREE
            elif not throughout:
                flags |= ISLAND
        elif outer >= 0:
            flags |= ISLAND
        y_out = y_in
    return s0, s2, b, position, flags, active


@njit(cache=True, error_model="numpy")
def _walk(props, interfaces, velocity, radius, free_radius, dynamic, values, codes, zones):
    """Wall stress of every point.

    ``props`` is the material table (rows: layers; columns ``E_ .. EPS``); ``interfaces``
    ``(P, n - 1)``, ``radius`` and ``free_radius`` (``inf``: unbounded) have ``P = N`` rows or
    one row shared by all ``N = velocity.size`` points. Writes ``values[p] = (stress, s_0, s_2,
    b)`` with ``stress = s_0 + s_2 V^2``, ``codes[p] = (position, flags, active layers)``
    (position ``-1``: elastic; ``2j``: ``b`` inside layer ``j``; ``2j + 1``: held at interface
    ``j``; flags: ``ISLAND | FREE | FAILED``) and, if ``zones`` has ``N`` rows, the yielded
    ``(r_inner, r_outer)`` of every layer (NaN where elastic). Returns the first point whose
    Newton iteration did not converge, or -1.
    """
    n_points = velocity.shape[0]
    keep_zones = zones.shape[0] == n_points
    shared_if = interfaces.shape[0] == 1
    shared_a = radius.shape[0] == 1
    shared_c = free_radius.shape[0] == 1
    first_failure = -1
    for p in range(n_points):
        v2 = velocity[p] * velocity[p]
        s0, s2, b, position, flags, active = _point(
            props, interfaces, 0 if shared_if else p, radius[0 if shared_a else p],
            free_radius[0 if shared_c else p], v2, dynamic, zones, p, keep_zones)
        stress = s0 + s2 * v2
        if flags & FAILED:
            stress = np.nan
            if first_failure < 0:
                first_failure = p
        values[p, 0] = stress
        values[p, 1] = s0
        values[p, 2] = s2
        values[p, 3] = b
        codes[p, 0] = position
        codes[p, 1] = flags
        codes[p, 2] = active
    return first_failure


@njit(cache=True, error_model="numpy")
def nose_walk(props, interfaces, velocity, cosines, weights, radius, dynamic, codes,
              free_radius=np.inf):
    """The walk for the nose force at one depth (the penetration integrator's hot path).

    Dynamic: returns ``(sum_k w_k sigma_r(V cos(phi_k)), 0, failed)``; quasi-static:
    ``(s_0, s_2, failed)`` of ``sigma_r = s_0 + s_2 V^2`` (the force is then exact,
    ``C_A + C_B V^2``). ``codes`` gets the codes of the point at ``V`` itself (the label).
    ``interfaces`` has one row; the medium is unbounded or (``free_radius``) cut by a
    traction-free sphere.
    """
    failed = False
    first = 0.0
    second = 0.0
    zones = np.empty((0, 1, 2))
    if dynamic:
        for j in range(cosines.shape[0]):
            v2 = (velocity * cosines[j]) ** 2
            s0, s2, b, position, flags, active = _point(props, interfaces, 0, radius, free_radius,
                                                        v2, True, zones, 0, False)
            failed |= (flags & FAILED) != 0
            first += weights[j] * (s0 + s2 * v2)
    s0, s2, b, position, flags, active = _point(props, interfaces, 0, radius, free_radius,
                                                velocity * velocity, dynamic, zones, 0, False)
    failed |= (flags & FAILED) != 0
    if not dynamic:
        first, second = s0, s2
    codes[0] = position
    codes[1] = flags
    codes[2] = active
    return first, second, failed


# ------------------------------------------------------------------------------------------
# Materials, labels, validation
# ------------------------------------------------------------------------------------------

@lru_cache(maxsize=256)
def material_table(layers):
    """Read-only ``(len(layers), 6)`` table ``E, rho, alpha, k, tau, epsilon`` of a tuple of
    materials (the compiled walk's input)."""
    table = np.array([[m.E, m.rho, m.alpha, m.yield_intercept, m.tau, m.quasi_static_epsilon]
                      for m in layers], dtype=float).reshape(len(layers), 6)
    table.setflags(write=False)
    return table


def state_label(position, flags, active):
    """Label of one point from the walk's codes (see :class:`CavityState`)."""
    if position < 0:
        return "elastic"
    if active == 1:
        label = "single"
    else:
        label = PAPER_STATES.get(active, "")[position:position + 1] or f"b{position}"
    if flags & ISLAND:
        label += "+island"
    if flags & FREE:
        label += "+free"
    return label


def state_labels(codes):
    """Labels of an ``(N, 3)`` array of codes, as a numpy string array of length ``N``."""
    keys = (codes[:, 2] * 4096 + codes[:, 0] + 1) * 8 + (codes[:, 1] & (ISLAND | FREE))
    unique, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    labels = np.array([state_label(*codes[i]) for i in first])
    return labels[inverse.reshape(-1)]


# ------------------------------------------------------------------------------------------
# Evaluation
# ------------------------------------------------------------------------------------------

def solve_flat(props, interfaces, velocity, radius, free_radius, dynamic, zones=False):
    """The compiled walk on contiguous float arrays (no checks; see :func:`_walk`).

    Returns ``(values (N, 4), codes (N, 3), zones (N, n, 2) or None)``.
    """
    n_points = velocity.shape[0]
    values = np.empty((n_points, 4))
    codes = np.empty((n_points, 3), dtype=np.int64)
    out_zones = np.empty((n_points if zones else 0, props.shape[0], 2))
    bad = _walk(props, interfaces, velocity, radius, free_radius, dynamic, values, codes,
                out_zones)
    if bad >= 0:
        raise CavexNumericalError("dynamic elastic-plastic boundary did not converge "
                                  f"(V={velocity[bad]} m/s)")
    return values, codes, (out_zones if zones else None)


def _column(x, shape, size, trailing=(), shared=True):
    """``x`` (batch shape broadcasting to ``shape``, then ``trailing``) as a contiguous array of
    ``size`` rows, or of one row when it is the same for every point and ``shared``."""
    batch = x.shape[:x.ndim - len(trailing)]
    if shared and math.prod(batch) == 1:
        return np.ascontiguousarray(x).reshape(1, *trailing)
    if batch != shape:
        x = np.broadcast_to(x, (*shape, *trailing))
    return np.ascontiguousarray(x).reshape(size, *trailing)


def evaluate(layers, interfaces, velocity, radius, boundary, free_radius=None, zones=False,
             check=True):
    """Broadcast, (validate) and solve; returns ``(shape, values, codes, zones)`` flat."""
    layers = tuple(layers)
    interfaces, velocity, radius, c = arrays(interfaces, velocity, radius, free_radius)
    if check:
        check_arrays(layers, interfaces, velocity, radius, c, boundary)
    shape = np.broadcast_shapes(velocity.shape, interfaces.shape[:-1], radius.shape, c.shape)
    size = math.prod(shape)
    values, codes, out_zones = solve_flat(
        material_table(layers), _column(interfaces, shape, size, interfaces.shape[-1:]),
        _column(velocity, shape, size, shared=False), _column(radius, shape, size),
        _column(c, shape, size), boundary == "dynamic", zones)
    return shape, values, codes, out_zones


def _shaped(values, shape):
    return float(values[0]) if shape == () else values.reshape(shape)


def _broadcast(x, shape):
    x = np.asarray(x, dtype=float)
    return x.item() if shape == () else np.broadcast_to(x, shape).copy()


def _labels(codes, shape):
    if shape == ():
        return state_label(*codes[0])
    return state_labels(codes).reshape(shape)


def cavity_solution(layers, interfaces, velocity, radius, *, boundary="dynamic",
                    free_radius=None):
    """Solve the layered cavity-expansion problem; see the module docstring.

    Parameters
    ----------
    layers : sequence of Material
        ``layers[0]`` surrounds the cavity; the last is unbounded (or ends at ``free_radius``).
    interfaces : array_like, shape (..., len(layers) - 1)
        Interface radii from the cavity centre (m), increasing, all > ``radius``.
    velocity : float or array_like
        Constant cavity expansion velocity ``V`` (m/s), >= 0.
    radius : float or array_like
        Cavity radius ``a`` (m), > 0.
    boundary : {"dynamic", "quasi-static"}
        Yield-at-boundary convention (docs/problem.md section 2).
    free_radius : float or array_like, optional
        Traction-free outer boundary (m, current configuration), ``sigma_r = 0`` there; > the
        cavity radius; layers beyond it are ignored. None (or ``inf``): unbounded medium.

    ``velocity``, ``interfaces[..., 0]``, ``radius`` and ``free_radius`` broadcast together.

    Returns
    -------
    CavityState
    """
    shape, values, codes, zones = evaluate(layers, interfaces, velocity, radius, boundary,
                                           free_radius, zones=True)
    stress = _shaped(values[:, 0], shape)
    return CavityState(
        stress=stress, S=stress / layers[0].tau, radius=_broadcast(radius, shape),
        velocity=_broadcast(velocity, shape),
        plastic_radius=_shaped(values[:, 3], shape),
        zones=zones.reshape(*shape, len(layers), 2),
        state=_labels(codes, shape), boundary=boundary,
        free_radius=free_radius)


def cavity_stress(layers, interfaces, velocity, radius, *, boundary="dynamic", free_radius=None):
    """``sigma_r`` at the wall (Pa, compression positive) of a cavity opened from zero radius.

    See :func:`cavity_solution` for the parameters; float for scalar input, else an array of
    the broadcast shape.
    """
    shape, values, _, _ = evaluate(layers, interfaces, velocity, radius, boundary, free_radius)
    return _shaped(values[:, 0], shape)


def plastic_radius(layers, interfaces, velocity, radius, *, boundary="dynamic", free_radius=None):
    """Elastic-plastic boundary radius ``b`` (m); see :func:`cavity_solution`."""
    shape, values, _, _ = evaluate(layers, interfaces, velocity, radius, boundary, free_radius)
    return _shaped(values[:, 3], shape)


def response_state(layers, interfaces, velocity, radius, *, boundary="dynamic",
                   free_radius=None):
    """Response-state label(s) (see :class:`CavityState`); str or array of str."""
    shape, _, codes, _ = evaluate(layers, interfaces, velocity, radius, boundary, free_radius)
    return _labels(codes, shape)


def quasi_static_coefficients(layers, interfaces, radius, *, free_radius=None):
    """``(sigma_0, sigma_2)`` with ``sigma_r(a) = sigma_0 + sigma_2 V^2`` (quasi-static, exact).

    The quasi-static yield radii depend on neither ``V`` nor ``sigma_r``, so the solution is
    affine in ``V^2``: the two parts the walk carries. Arrays as :func:`cavity_solution`.
    """
    shape, values, _, _ = evaluate(layers, interfaces, 0.0, radius, "quasi-static", free_radius)
    return _shaped(values[:, 1], shape), _shaped(values[:, 2], shape)
