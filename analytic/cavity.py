r"""Spherical cavity expansion in concentric incompressible Mohr-Coulomb layers (derived model).

A cavity of radius ``a`` opened from zero radius at constant velocity ``V`` in concentric layers
(``layers[i]`` occupies ``interfaces[i-1] < r < interfaces[i]``, the last layer unbounded).
Compression is positive. With ``y = a/r`` the exact incompressible kinematics give the particle
acceleration ``Dv/Dt = 2 V^2 (a/r^2 - a^4/r^5)`` and the momentum balance

.. math:: \frac{d\sigma_r}{dy} = \frac{2 D}{y} + 2\rho V^2 (1 - y^3), \qquad
          D = \sigma_r - \sigma_\theta,

integrated from ``y = 0`` (``r = oo``, ``sigma_r = 0``) to the wall ``y = 1``. The deviator is

- elastic (small strain, ``u = a^3/(3 r^2)``, ``G = E/3``): ``D = (2E/3) y^3``;
- plastic: ``D = alpha sigma_r + k`` with ``alpha = 3 lam/(3 + 2 lam)`` and
  ``k = 3 tau/(3 + 2 lam)``, i.e. ``sigma_r - sigma_theta = lam sigma + tau``.

Both are linear, so each piece of a layer integrates in closed form. With
``I(p, x) = int_1^x t^(p-1) dt = (x^p - 1)/p`` (``ln x`` at ``p = 0``, evaluated with ``expm1`` so
that every ``lam`` in ``[0, 3)`` is finite and continuous, including ``alpha = 1/2``), going
inward from ``y_o = a/r_o`` to ``y_i = a/r_i``, ``x = r_o/r_i``:

- elastic: ``s_i = s_o + (4E/9)(y_i^3 - y_o^3) + 2 rho V^2 [(y_i - y_o) - (y_i^4 - y_o^4)/4]``
- plastic: ``s_i = x^(2 alpha) s_o + 2k I(2 alpha, x)
  + 2 rho V^2 [y_i I(2 alpha - 1, x) - y_i^4 I(2 alpha - 4, x)]``.

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
"""

import math
from dataclasses import dataclass

from cavex.errors import CavexNumericalError, require, require_choice

BOUNDARIES = ("dynamic", "quasi-static")

# Paper's Fig. 2 states, by number of concentric layers and position code of b:
# code 2j = b inside layer j, code 2j+1 = b held at interface j (layer j+1 not yielded).
PAPER_STATES = {3: "abcde", 2: "fgh"}


@dataclass(frozen=True)
class CavityState:
    """Solution of one layered cavity-expansion problem.

    Attributes
    ----------
    stress : float
        ``sigma_r`` at the cavity wall (Pa, compression positive).
    S : float
        ``stress / tau`` of the layer at the wall (``layers[0]``).
    plastic_radius : float
        Outermost radius of yielded material, ``b`` (equals ``radius`` if nothing yielded).
    plastic_zones : tuple of (layer, r_inner, r_outer)
        Yielded intervals, innermost first.
    state : str
        Paper's Fig. 2 letter (``a``-``h``), ``"single"`` for one layer, with ``"+island"``
        appended when a layer between plastic ones stays elastic.
    """

    stress: float
    S: float
    radius: float
    velocity: float
    plastic_radius: float
    plastic_zones: tuple
    state: str
    boundary: str


def power_integral(p, x):
    """``int_1^x t^(p-1) dt = (x^p - 1)/p`` (``ln x`` at ``p = 0``; ``x = inf`` needs ``p < 0``)."""
    if math.isinf(x):
        return -1.0 / p
    if p == 0.0:
        return math.log(x)
    return math.expm1(p * math.log(x)) / p


def elastic_terms(material, y_out, y_in):
    """``(1, static, inertial)``: elastic ``s_i = s_o + static + rho V^2 inertial``."""
    return (1.0, (4.0 * material.E / 9.0) * (y_in ** 3 - y_out ** 3),
            2.0 * ((y_in - y_out) - 0.25 * (y_in ** 4 - y_out ** 4)))


def plastic_terms(material, y_out, y_in):
    """``(x^(2 alpha), static, inertial)`` of a plastic piece, ``x = y_in / y_out``:
    ``s_i = x^(2 alpha) s_o + static + rho V^2 inertial``, ``x = y_in / y_out``.
    """
    two_alpha = 2.0 * material.alpha
    x = y_in / y_out
    return (x ** two_alpha, 2.0 * material.yield_intercept * power_integral(two_alpha, x),
            2.0 * (y_in * power_integral(two_alpha - 1.0, x)
                   - y_in ** 4 * power_integral(two_alpha - 4.0, x)))


def elastic_step(material, s_out, y_out, y_in, rho_v2):
    """``sigma_r`` at ``y_in`` from its value ``s_out`` at ``y_out`` through elastic material."""
    _, static, inertial = elastic_terms(material, y_out, y_in)
    return s_out + static + rho_v2 * inertial


def plastic_step(material, s_out, y_out, y_in, rho_v2):
    """``sigma_r`` at ``y_in`` from its value ``s_out`` at ``y_out`` through plastic material."""
    amplification, static, inertial = plastic_terms(material, y_out, y_in)
    return amplification * s_out + static + rho_v2 * inertial


def yield_function(material, y, s, boundary):
    """Elastic deviator minus yield deviator at ``y = a/r``, radial stress ``s`` (>= 0: yields)."""
    if boundary == "quasi-static":
        limit = material.tau
    else:
        limit = material.alpha * s + material.yield_intercept
    return (2.0 * material.E / 3.0) * y ** 3 - limit


def yield_point(material, s_out, y_out, y_in, rho, velocity, boundary):
    """``y`` in ``[y_out, y_in]`` where the layer first yields going inward, or None."""
    rho_v2 = rho * velocity ** 2
    if yield_function(material, y_out, s_out, boundary) >= 0.0:
        return y_out
    s_in = elastic_step(material, s_out, y_out, y_in, rho_v2)
    if yield_function(material, y_in, s_in, boundary) < 0.0:
        return None
    if boundary == "quasi-static":
        return material.quasi_static_epsilon
    return _dynamic_yield_root(material, s_out, y_out, y_in, rho_v2)


def _dynamic_yield_root(material, s_out, y_out, y_in, rho_v2):
    """Root of the convex ``g(y) = (2E/3)y^3 - alpha s(y) - k`` by Newton from ``y_in``."""
    E23, alpha = 2.0 * material.E / 3.0, material.alpha
    y = y_in
    for _ in range(100):
        s = elastic_step(material, s_out, y_out, y, rho_v2)
        g = E23 * y ** 3 - alpha * s - material.yield_intercept
        dg = 3.0 * E23 * y ** 2 - alpha * ((4.0 * material.E / 3.0) * y ** 2
                                          + 2.0 * rho_v2 * (1.0 - y ** 3))
        step = g / dg
        y -= step
        if abs(step) <= 4e-16 * y:
            return max(y, y_out)
    raise CavexNumericalError(
        "dynamic elastic-plastic boundary did not converge "
        f"(V={math.sqrt(rho_v2 / material.rho)} m/s)")


def check_problem(layers, interfaces, velocity, radius, boundary):
    """Validate a concentric-layer problem; raise ``CavexInputError`` naming the parameter."""
    require(len(layers) >= 1, "layers", "at least one material", len(layers))
    require(len(interfaces) == len(layers) - 1, "interfaces",
            f"of length len(layers) - 1 = {len(layers) - 1}", len(interfaces))
    require(math.isfinite(radius) and radius > 0.0, "radius", "a finite number > 0", radius)
    require(math.isfinite(velocity) and velocity >= 0.0, "velocity", "a finite number >= 0",
            velocity)
    require_choice(boundary, BOUNDARIES, "boundary")
    previous = radius
    for i, h in enumerate(interfaces):
        require(math.isfinite(h) and h > previous, f"interfaces[{i}]",
                f"finite and > {previous} (increasing, outside the cavity)", h)
        previous = h


def cavity_solution(layers, interfaces, velocity, radius, *, boundary="dynamic"):
    """Solve the layered cavity-expansion problem; see the module docstring.

    Parameters
    ----------
    layers : sequence of Material
        ``layers[0]`` surrounds the cavity; the last is unbounded.
    interfaces : sequence of float
        Interface radii from the cavity centre (m), increasing, all > ``radius``.
    velocity : float
        Constant cavity expansion velocity ``V`` (m/s), >= 0.
    radius : float
        Cavity radius ``a`` (m), > 0.
    boundary : {"dynamic", "quasi-static"}
        Yield-at-boundary convention (physics.md section 2).

    Returns
    -------
    CavityState
    """
    check_problem(layers, interfaces, velocity, radius, boundary)
    return solve_checked(layers, interfaces, velocity, radius, boundary)


def solve_checked(layers, interfaces, velocity, radius, boundary):
    """:func:`cavity_solution` for an already validated problem (hot loops skip the checks)."""
    s, zones = wall_stress(layers, interfaces, velocity, radius, boundary)
    b = zones[-1][2] if zones else radius
    return CavityState(stress=s, S=s / layers[0].tau, radius=radius, velocity=velocity,
                       plastic_radius=b, plastic_zones=tuple(zones),
                       state=response_state(zones, interfaces, radius), boundary=boundary)


def wall_stress(layers, interfaces, velocity, radius, boundary):
    """``(sigma_r(a), plastic zones)`` of a validated problem: the outside-in walk."""
    s, y_out, zones = 0.0, 0.0, []
    for i in range(len(layers) - 1, -1, -1):
        material = layers[i]
        rho_v2 = material.rho * velocity ** 2
        r_in = interfaces[i - 1] if i > 0 else radius
        y_in = radius / r_in
        y_yield = yield_point(material, s, y_out, y_in, material.rho, velocity, boundary)
        if y_yield is None:
            s = elastic_step(material, s, y_out, y_in, rho_v2)
        else:
            s = elastic_step(material, s, y_out, y_yield, rho_v2)
            s = plastic_step(material, s, y_yield, y_in, rho_v2)
            zones.append((i, r_in, interfaces[i] if y_yield == y_out else radius / y_yield))
        y_out = y_in
    zones.reverse()
    return s, zones


def quasi_static_coefficients(layers, interfaces, radius):
    """``(sigma_0, sigma_2)`` with ``sigma_r(a) = sigma_0 + sigma_2 V^2`` (quasi-static, exact).

    One walk carrying both parts: the quasi-static yield radii depend on neither ``V`` nor
    ``sigma_r``, so the solution is affine in ``V^2``.
    """
    static, per_v2, y_out = 0.0, 0.0, 0.0
    for i in range(len(layers) - 1, -1, -1):
        material = layers[i]
        y_in = radius / interfaces[i - 1] if i > 0 else 1.0
        epsilon = material.quasi_static_epsilon
        y_yield = None if epsilon > y_in else max(epsilon, y_out)
        pieces = (((elastic_terms, y_out, y_in),) if y_yield is None else
                  ((elastic_terms, y_out, y_yield), (plastic_terms, y_yield, y_in)))
        for terms, y0, y1 in pieces:
            amplification, s0, s2 = terms(material, y0, y1)
            static = amplification * static + s0
            per_v2 = amplification * per_v2 + material.rho * s2
        y_out = y_in
    return static, per_v2


def cavity_stress(layers, interfaces, velocity, radius, *, boundary="dynamic"):
    """``sigma_r`` at the wall (Pa, compression positive) of a cavity opened from zero radius.

    See :func:`cavity_solution` for the parameters.
    """
    return cavity_solution(layers, interfaces, velocity, radius, boundary=boundary).stress


def plastic_radius(layers, interfaces, velocity, radius, *, boundary="dynamic"):
    """Elastic-plastic boundary radius ``b`` (m); see :func:`cavity_solution`."""
    return cavity_solution(layers, interfaces, velocity, radius, boundary=boundary).plastic_radius


def response_state(zones, interfaces, radius):
    """Label of the response state: paper Fig. 2 letter, ``"single"`` or ``"elastic"``."""
    if not zones:
        return "elastic"
    n = len(interfaces) + 1
    contiguous = zones[0][1] == radius and all(
        inner[2] == outer[1] for inner, outer in zip(zones, zones[1:], strict=False))
    layer, _, b = zones[-1]
    code = 2 * layer + (1 if layer < n - 1 and b == interfaces[layer] else 0)
    label = "single" if n == 1 else PAPER_STATES.get(n, "")[code:code + 1] or f"b{code}"
    return label if contiguous else label + "+island"
