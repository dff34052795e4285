r"""Verification of the layered analytic cavity-expansion model (``cavex.analytic.cavity``).

The closed forms are checked against an independent numerical integration of the momentum
equation of docs/problem.md section 2, written here from the physics and not from the module:

.. math:: \frac{d\sigma_r}{dy} = \frac{2 D}{y} + 2\rho V^2 (1 - y^3), \qquad y = a/r,

from ``y = 0`` (``sigma_r = 0``) to the wall ``y = 1``, with ``D = (2E/3) y^3`` in elastic material
and, in plastic material, ``D`` solved from the paper's yield form ``sigma_r - sigma_theta =
lam sigma + tau`` with ``sigma = sigma_r - 2D/3`` (so ``D = (3 lam sigma_r + 3 tau)/(3 + 2 lam)``,
derived here rather than taken from ``Material.alpha``).

Elastic/plastic rule of the reference (the same rule the model documents): the layers are walked
from the outside in; a layer whose yield function is already met at its outer end is plastic
throughout; otherwise it is integrated as elastic with a solver event on its yield function and,
if the event fires, as plastic from there to its inner end. The yield function is
``(2E/3) y^3 - tau`` (quasi-static convention) or ``(2E/3) y^3 - D_plastic(sigma_r)`` with the
actual integrated ``sigma_r`` (dynamic convention).
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cavex.analytic.cavity import cavity_solution, cavity_stress, plastic_radius
from cavex.errors import CavexInputError
from cavex.materials import Material

BOUNDARIES = ("quasi-static", "dynamic")
RADIUS = 0.0125  # cavity radius a (m): the paper's projectile radius
AGREEMENT = 1e-8  # required relative agreement with the momentum integration


# --------------------------------------------------------------------------------------------
# Independent reference: numerical integration of the momentum equation
# --------------------------------------------------------------------------------------------

def plastic_deviator(lam, tau, sigma_r):
    """``D = sigma_r - sigma_theta`` on the paper's yield surface, from ``lam``, ``tau`` directly.

    ``D = lam (sigma_r - 2D/3) + tau`` solved for ``D``.
    """
    return (3.0 * lam * sigma_r + 3.0 * tau) / (3.0 + 2.0 * lam)


def reference_yield(material, boundary):
    """Yield function ``f(y, [sigma_r])`` (``>= 0``: yielded) as a terminal solver event."""
    E, lam, tau = material.E, material.lam, material.tau

    def yield_function(y, state):
        if boundary == "quasi-static":
            limit = tau
        else:
            limit = plastic_deviator(lam, tau, state[0])
        return (2.0 * E / 3.0) * y ** 3 - limit

    yield_function.terminal = True
    yield_function.direction = 1.0
    return yield_function


def integrate(rhs, y_start, y_end, sigma_start, events=None):
    """One ``solve_ivp`` leg in ``y``; returns the solution object."""
    solution = solve_ivp(rhs, (y_start, y_end), [sigma_start], method="DOP853",
                         rtol=1e-12, atol=1e-9, events=events)
    assert solution.success, solution.message
    return solution


def reference_solution(layers, interfaces, velocity, radius, boundary):
    """Wall stress and plastic zones by numerical integration of the momentum equation.

    Parameters
    ----------
    layers, interfaces, velocity, radius, boundary
        As for ``cavity_solution``.

    Returns
    -------
    stress : float
        ``sigma_r`` at the wall (Pa).
    zones : list of (layer, r_inner, r_outer)
        Yielded intervals, innermost first.
    """
    sigma, y_outer, zones = 0.0, 0.0, []
    for index in range(len(layers) - 1, -1, -1):
        material = layers[index]
        E, lam, tau = material.E, material.lam, material.tau
        rho_v2 = material.rho * velocity ** 2
        y_inner = radius / interfaces[index - 1] if index > 0 else 1.0

        def elastic_rhs(y, state, E=E, rho_v2=rho_v2):
            # 2 D / y with D = (2E/3) y^3, written without the division so that y = 0 is fine
            return [(4.0 * E / 3.0) * y ** 2 + 2.0 * rho_v2 * (1.0 - y ** 3)]

        def plastic_rhs(y, state, lam=lam, tau=tau, rho_v2=rho_v2):
            return [2.0 * plastic_deviator(lam, tau, state[0]) / y
                    + 2.0 * rho_v2 * (1.0 - y ** 3)]

        yield_function = reference_yield(material, boundary)
        if yield_function(y_outer, [sigma]) >= 0.0:
            y_yield = y_outer
        else:
            leg = integrate(elastic_rhs, y_outer, y_inner, sigma, events=yield_function)
            if leg.t_events[0].size:
                y_yield, sigma = leg.t_events[0][0], leg.y_events[0][0][0]
            else:
                y_yield, sigma = None, leg.y[0, -1]
        if y_yield is not None:
            sigma = integrate(plastic_rhs, y_yield, y_inner, sigma).y[0, -1]
            zones.append((index, radius / y_inner, radius / y_yield))
        y_outer = y_inner
    return sigma, zones[::-1]


def standalone_plastic_radius(material, velocity, boundary, radius=RADIUS):
    """``b`` of ``material`` filling all space, from the reference integration."""
    _, zones = reference_solution([material], [], velocity, radius, boundary)
    return zones[-1][2]


def assert_matches_reference(layers, interfaces, velocity, boundary, radius=RADIUS):
    """Compare stress, ``b`` and zones of the model with the reference; return the model state."""
    state = cavity_solution(layers, interfaces, velocity, radius, boundary=boundary)
    stress = cavity_stress(layers, interfaces, velocity, radius, boundary=boundary)
    expected, zones = reference_solution(layers, interfaces, velocity, radius, boundary)
    assert stress == state.stress
    assert stress == pytest.approx(expected, rel=AGREEMENT, abs=0.0)
    assert state.S == stress / layers[0].tau
    assert [zone[0] for zone in state.plastic_zones] == [zone[0] for zone in zones]
    for got, want in zip(state.plastic_zones, zones, strict=True):
        assert got[1:] == pytest.approx(want[1:], rel=1e-9)
    assert plastic_radius(layers, interfaces, velocity, radius, boundary=boundary) == \
        state.plastic_radius
    if zones:
        assert state.plastic_radius == pytest.approx(zones[-1][2], rel=1e-9)
    return state


def relative_error(got, expected):
    """``|got - expected| / |expected|``."""
    return abs(got - expected) / abs(expected)


# --------------------------------------------------------------------------------------------
# Materials
# --------------------------------------------------------------------------------------------

def material_with_ratio(ratio, tau, rho, lam, name=""):
    """Material with quasi-static plastic radius ``ratio`` cavity radii: ``E = 1.5 ratio^3 tau``."""
    return Material(E=1.5 * ratio ** 3 * tau, nu=0.3, rho=rho, lam=lam, tau=tau, name=name)


# Three layers with well separated plastic radii (40 a, 12 a, 4 a at V = 0), so that interface
# radii can put b in each of the paper's states at every tested velocity.
STATE_LAYERS = (
    material_with_ratio(40.0, 30e6, 2400.0, 0.3, "strong"),
    material_with_ratio(12.0, 15e6, 2000.0, 0.5, "medium"),
    material_with_ratio(4.0, 8e6, 1800.0, 0.2, "weak"),
)

# state -> (indices into STATE_LAYERS, interface radii from the standalone plastic radii b[i]).
STATE_RECIPES = {
    # 3 layers, cavity in layer 1
    "a": ((0, 1, 2), lambda b: (1.5 * b[0], 3.0 * b[0])),  # b inside layer 1
    "b": ((0, 1, 2), lambda b: (math.sqrt(b[0] * b[1]), 2.0 * b[0])),  # held at h1
    "c": ((0, 1, 2), lambda b: (b[1] / 1.5, 1.5 * b[1])),  # b inside layer 2
    "d": ((0, 1, 2), lambda b: (b[2] / 1.5, math.sqrt(b[1] * b[2]))),  # held at h2
    "e": ((0, 1, 2), lambda b: (b[2] / 2.0, b[2] / 1.5)),  # b inside layer 3
    # 2 layers, cavity in layer 1 (the paper's macadam over soil)
    "f": ((1, 2), lambda b: (1.5 * b[1],)),  # b inside layer 1
    "g": ((1, 2), lambda b: (math.sqrt(b[1] * b[2]),)),  # held at h1
    "h": ((1, 2), lambda b: (b[2] / 1.5,)),  # b inside layer 2
}

STATE_VELOCITIES = (0.0, 100.0, 300.0)


def state_problem(state, velocity, boundary):
    """``(layers, interfaces)`` putting the elastic-plastic boundary in the paper's ``state``."""
    indices, recipe = STATE_RECIPES[state]
    radii = [standalone_plastic_radius(m, velocity, boundary) for m in STATE_LAYERS]
    return [STATE_LAYERS[i] for i in indices], list(recipe(radii))


# --------------------------------------------------------------------------------------------
# 1. Closed forms against the momentum integration
# --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("boundary", BOUNDARIES)
@pytest.mark.parametrize("velocity", [0.0, 50.0, 400.0, 1000.0])
@pytest.mark.parametrize("lam", [0.0, 1e-9, 0.15, 0.5, 0.75 - 1e-7, 0.75, 0.75 + 1e-7, 1.5,
                                 2.5, 3.0 - 1e-9])
def test_single_layer_matches_momentum_integration(lam, velocity, boundary):
    """One layer, every ``lam`` regime (Tresca, removable singularity at 0.75, near 3)."""
    material = Material(E=25e9, nu=0.2, rho=2500.0, lam=lam, tau=25e6)
    state = assert_matches_reference([material], [], velocity, boundary)
    assert state.state == "single"
    assert state.plastic_zones[0][1] == RADIUS


@pytest.mark.parametrize("boundary", BOUNDARIES)
@pytest.mark.parametrize("velocity", STATE_VELOCITIES)
@pytest.mark.parametrize("state", sorted(STATE_RECIPES))
def test_paper_states_match_momentum_integration(state, velocity, boundary):
    """Every Fig. 2 state, both conventions: stress, state letter, ``b`` and zones."""
    layers, interfaces = state_problem(state, velocity, boundary)
    result = assert_matches_reference(layers, interfaces, velocity, boundary)
    assert result.state == state
    assert result.boundary == boundary and result.velocity == velocity
    assert boundary_location(result.plastic_radius, interfaces) == STATE_LOCATIONS[state]


# where b lies: 2j = strictly inside layer j (0-based), 2j + 1 = exactly at interface j
STATE_LOCATIONS = {"a": 0, "b": 1, "c": 2, "d": 3, "e": 4, "f": 0, "g": 1, "h": 2}


def boundary_location(b, interfaces):
    """Position code of ``b`` among the interface radii (see ``STATE_LOCATIONS``)."""
    for j, h in enumerate(interfaces):
        if b == h:
            return 2 * j + 1
        if b < h:
            return 2 * j
    return 2 * len(interfaces)


@pytest.mark.parametrize("boundary", BOUNDARIES)
@pytest.mark.parametrize("velocity", [0.0, 100.0, 300.0])
def test_elastic_island_matches_momentum_integration(velocity, boundary):
    """A stiff middle layer stays elastic between a yielded inner and a yielded outer layer."""
    layers = [
        material_with_ratio(10.0, 30e6, 2400.0, 0.3),
        material_with_ratio(1.5, 50e6, 2200.0, 0.4),  # would yield only within 1.5 a
        material_with_ratio(12.0, 5e6, 1800.0, 0.2),
    ]
    interfaces = [3.0 * RADIUS, 5.0 * RADIUS]
    result = assert_matches_reference(layers, interfaces, velocity, boundary)
    assert result.state == "e+island"
    assert [zone[0] for zone in result.plastic_zones] == [0, 2]
    assert result.plastic_zones[0][1:] == (RADIUS, interfaces[0])
    assert result.plastic_zones[1][1] == interfaces[1]


@pytest.mark.parametrize("boundary", BOUNDARIES)
@pytest.mark.parametrize("velocity", [0.0, 300.0, 1000.0])
@pytest.mark.parametrize("depth", [0.0, 0.3, 0.55, 0.7, 0.95])
def test_runway_matches_momentum_integration(table1, depth, velocity, boundary):
    """Table 1 runway at several nose depths (interfaces ``H - L + l`` that lie outside ``a``)."""
    materials = [Material(nu=0.3, **layer) for layer in table1["layers"]]
    nose = table1["projectile"]["l"]
    radii = [H - depth + nose for H in table1["interface_depths"]]
    first = sum(1 for h in radii if h <= RADIUS)
    assert_matches_reference(materials[first:], radii[first:], velocity, boundary)


@pytest.mark.parametrize("interface_in_radii", [6.7, 7.2, 7.6, 7.7, 7.8])
@pytest.mark.parametrize("boundary", BOUNDARIES)
def test_boundary_held_at_interface_for_any_interface_radius(interface_in_radii, boundary):
    """States b and g are recognised whatever the float value of ``h`` (no round-off test).

    The chosen ``h = k a`` are values for which ``a / (a / h) != h`` in floating point.
    """
    layers = [material_with_ratio(10.0, 30e6, 2400.0, 0.3), material_with_ratio(5.0, 15e6,
                                                                               2000.0, 0.5)]
    h1 = interface_in_radii * RADIUS
    three = cavity_solution(layers + [layers[1]], [h1, 40 * RADIUS], 0.0, RADIUS,
                            boundary=boundary)
    two = cavity_solution(layers, [h1], 0.0, RADIUS, boundary=boundary)
    assert (three.state, three.plastic_radius) == ("b", h1)
    assert (two.state, two.plastic_radius) == ("g", h1)


def wall_yield_velocity(material):
    """Dynamic convention, one layer: ``V`` above which even the wall ``y = 1`` stays elastic.

    With ``sigma_r(1) = 4E/9 + (3/2) rho V^2`` (elastic) the yield function at the wall is
    ``2E/3 - alpha sigma_r(1) - k``, zero at ``rho V^2 = (2E/3 - 4 alpha E/9 - k)/(1.5 alpha)``.
    """
    E, lam, tau = material.E, material.lam, material.tau
    alpha, k = 3.0 * lam / (3.0 + 2.0 * lam), 3.0 * tau / (3.0 + 2.0 * lam)
    return math.sqrt((2.0 * E / 3.0 - 4.0 * alpha * E / 9.0 - k) / (1.5 * alpha * material.rho))


@pytest.mark.parametrize("lam", [0.5, 1.5])
def test_dynamic_wall_stays_elastic_at_extreme_velocity(table1, lam):
    """Above ``wall_yield_velocity`` the dynamic convention leaves the whole medium elastic.

    For the Table 1 soil (E = 0.12 GPa) this threshold is ~300 m/s: a property of the dynamic
    convention with small-strain elasticity when ``rho V^2`` is comparable with ``E``.
    """
    soil = Material(nu=0.3, **{**table1["layers"][2], "lam": lam})
    threshold = wall_yield_velocity(soil)
    below = assert_matches_reference([soil], [], threshold * (1 - 1e-6), "dynamic")
    above = assert_matches_reference([soil], [], threshold * (1 + 1e-6), "dynamic")
    assert below.state == "single" and above.state == "elastic"
    assert above.plastic_zones == () and above.plastic_radius == RADIUS
    elastic = 4.0 * soil.E / 9.0 + 1.5 * soil.rho * (threshold * (1 + 1e-6)) ** 2
    assert above.stress == pytest.approx(elastic, rel=1e-13)
    assert relative_error(above.stress, below.stress) <= 1e-5
    assert cavity_solution([soil], [], 1000.0, RADIUS, boundary="dynamic").state == "elastic"
    assert cavity_solution([soil], [], 1000.0, RADIUS, boundary="quasi-static").state == "single"


# --------------------------------------------------------------------------------------------
# 2. Reductions to the single-layer result
# --------------------------------------------------------------------------------------------

SINGLE = material_with_ratio(12.0, 20e6, 2200.0, 0.4)


@pytest.mark.parametrize("boundary", BOUNDARIES)
@pytest.mark.parametrize("velocity", [0.0, 200.0, 1000.0])
@pytest.mark.parametrize("interfaces_in_radii", [(2.0,), (30.0,), (2.0, 5.0), (5.0, 11.9),
                                                 (12.1, 50.0), (1.01, 1e6)])
def test_identical_layers_reduce_to_single_layer(interfaces_in_radii, velocity, boundary):
    """Copies of one material at any interface radii give the single-layer value to 1e-12."""
    single = cavity_solution([SINGLE], [], velocity, RADIUS, boundary=boundary)
    interfaces = [k * RADIUS for k in interfaces_in_radii]
    layered = cavity_solution([SINGLE] * (len(interfaces) + 1), interfaces, velocity, RADIUS,
                              boundary=boundary)
    assert relative_error(layered.stress, single.stress) <= 1e-12
    assert layered.plastic_radius == pytest.approx(single.plastic_radius, rel=1e-12)


def elastic_increment(material, velocity, y_from, y_to):
    """Elastic-zone ``sigma_r(y_to) - sigma_r(y_from)``: exact integral of the momentum equation."""
    rho_v2 = material.rho * velocity ** 2
    return ((4.0 * material.E / 9.0) * (y_to ** 3 - y_from ** 3)
            + 2.0 * rho_v2 * ((y_to - y_from) - (y_to ** 4 - y_from ** 4) / 4.0))


def far_interface_estimate(layers, interfaces, velocity):
    """Neglected term of the far-interface limit, quasi-static convention.

    The outer layers replace ``layers[0]`` only where all of them are elastic (``r > h1``), so
    the wall stress changes by the difference of their elastic increments, carried through the
    plastic zone of ``layers[0]`` by the factor ``(b/a)^(2 alpha) = epsilon^(-2 alpha)``.
    """
    inner = layers[0]
    ys = [0.0] + [RADIUS / h for h in reversed(interfaces)]
    change = 0.0
    for material, y_from, y_to in zip(reversed(layers[1:]), ys[:-1], ys[1:], strict=True):
        change += (elastic_increment(material, velocity, y_from, y_to)
                   - elastic_increment(inner, velocity, y_from, y_to))
    alpha = 3.0 * inner.lam / (3.0 + 2.0 * inner.lam)
    epsilon = (1.5 * inner.tau / inner.E) ** (1.0 / 3.0)
    return change * epsilon ** (-2.0 * alpha)


FAR_LAYERS = [SINGLE, material_with_ratio(3.0, 5e6, 1500.0, 0.1),
              material_with_ratio(8.0, 9e6, 3000.0, 0.6)]


@pytest.mark.parametrize("boundary", BOUNDARIES)
@pytest.mark.parametrize("velocity", [0.0, 200.0, 1000.0])
@pytest.mark.parametrize("n_layers", [2, 3])
def test_far_interfaces_reduce_to_single_layer(n_layers, velocity, boundary):
    """Interfaces at ~1e6 a: the single-layer value plus the estimated neglected term.

    The neglected term is ``O(rho V^2 a/h)`` (``O(E (a/h)^3)`` at ``V = 0``, below round-off):
    in the quasi-static convention it is exactly :func:`far_interface_estimate`; in the dynamic
    one ``b`` also shifts, so it is only bounded by a few times the estimate and must halve when
    ``h`` doubles.
    """
    layers = FAR_LAYERS[:n_layers]
    single = cavity_stress([SINGLE], [], velocity, RADIUS, boundary=boundary)
    differences = []
    for scale in (1e6, 2e6):
        interfaces = [scale * RADIUS * (1 + i) for i in range(n_layers - 1)]
        layered = cavity_stress(layers, interfaces, velocity, RADIUS, boundary=boundary)
        estimate = far_interface_estimate(layers, interfaces, velocity)
        difference = layered - single
        differences.append(difference)
        roundoff = 1e-13 * single
        if velocity == 0.0:
            assert abs(difference) <= roundoff
        elif boundary == "quasi-static":
            assert difference == pytest.approx(estimate, rel=1e-5, abs=roundoff)
        else:
            assert abs(estimate) > 1e3 * roundoff
            assert 0.2 * abs(estimate) <= abs(difference) <= 5.0 * abs(estimate)
            assert math.copysign(1.0, difference) == math.copysign(1.0, estimate)
    if velocity > 0.0:
        assert differences[0] / differences[1] == pytest.approx(2.0, rel=1e-3)


# --------------------------------------------------------------------------------------------
# 3. Tresca limit (Hopkins) and continuity in lam
# --------------------------------------------------------------------------------------------

def hopkins(material, velocity):
    """``S = (2/3)[1 + ln(2E/(3 tau))] + (3/2) rho V^2/tau`` (docs/problem.md section 4)."""
    E, tau = material.E, material.tau
    return ((2.0 / 3.0) * (1.0 + math.log(2.0 * E / (3.0 * tau)))
            + 1.5 * material.rho * velocity ** 2 / tau)


@pytest.mark.parametrize("boundary", BOUNDARIES)
@pytest.mark.parametrize("velocity", [0.0, 100.0, 800.0, 3000.0])
@pytest.mark.parametrize(("E", "tau", "rho"), [(25e9, 25e6, 2500.0), (0.12e9, 6e6, 1600.0),
                                               (200e9, 1e9, 7800.0)])
def test_tresca_limit_is_hopkins(E, tau, rho, velocity, boundary):
    """``lam = 0`` gives the Hopkins formula to 1e-12 in both conventions."""
    material = Material(E=E, nu=0.3, rho=rho, lam=0.0, tau=tau)
    state = cavity_solution([material], [], velocity, RADIUS, boundary=boundary)
    assert relative_error(state.S, hopkins(material, velocity)) <= 1e-12
    epsilon = (1.5 * tau / E) ** (1.0 / 3.0)
    assert state.plastic_radius == pytest.approx(RADIUS / epsilon, rel=1e-12)


def single_S(lam, velocity, boundary, layers_after=()):
    """``S`` with a first layer of the given ``lam`` (and optional outer layers)."""
    material = Material(E=25e9, nu=0.2, rho=2500.0, lam=lam, tau=25e6)
    layers = [material, *layers_after]
    interfaces = [4.0 * RADIUS * (i + 1) for i in range(len(layers_after))]
    return cavity_solution(layers, interfaces, velocity, RADIUS, boundary=boundary).S


@pytest.mark.parametrize("boundary", BOUNDARIES)
@pytest.mark.parametrize("velocity", [0.0, 500.0])
@pytest.mark.parametrize("layers_after", [(), (FAR_LAYERS[1], FAR_LAYERS[2])])
def test_continuous_in_lam(layers_after, velocity, boundary):
    """No jump at ``lam = 0`` nor at the removable singularity ``lam = 0.75`` (alpha = 1/2)."""
    S = {lam: single_S(lam, velocity, boundary, layers_after)
         for lam in (0.0, 1e-9, 0.75 - 1e-7, 0.75, 0.75 + 1e-7)}
    assert relative_error(S[1e-9], S[0.0]) <= 1e-8  # O(lam) change only
    assert relative_error(S[0.75 + 1e-7], S[0.75]) <= 1e-6
    assert relative_error(S[0.75 - 1e-7], S[0.75]) <= 1e-6
    # smooth through 0.75: the midpoint of the symmetric pair is S(0.75) to O(d^2) + round-off
    assert relative_error(0.5 * (S[0.75 + 1e-7] + S[0.75 - 1e-7]), S[0.75]) <= 1e-10


@pytest.mark.parametrize("boundary", BOUNDARIES)
def test_smooth_over_lam_range(boundary):
    """``S(lam)`` on a fine grid of ``[0, 3)``: finite, and second differences stay small."""
    lams = np.linspace(0.0, 3.0 - 1e-6, 601)
    S = np.array([single_S(lam, 600.0, boundary) for lam in lams])
    assert np.all(np.isfinite(S))
    assert np.all(np.diff(S) > 0.0)  # stronger with pressure sensitivity at fixed tau
    second = np.abs(np.diff(S, 2))
    first = np.abs(np.diff(S))
    assert second.max() <= 0.05 * first.max()
    near_three = single_S(3.0 - 1e-12, 600.0, boundary)
    assert math.isfinite(near_three) and near_three == pytest.approx(S[-1], rel=1e-4)


# --------------------------------------------------------------------------------------------
# 4. Quasi-static is affine in V^2; dynamic is not
# --------------------------------------------------------------------------------------------

VELOCITIES = (0.0, 150.0, 300.0, 600.0, 1000.0)


def affine_residuals(values, velocities):
    """Residuals of ``values`` about the line in ``V^2`` through the first and last points."""
    v2 = np.asarray(velocities) ** 2
    values = np.asarray(values)
    slope = (values[-1] - values[0]) / v2[-1]
    return (values - (values[0] + slope * v2)) / values[-1], slope


@pytest.mark.parametrize("state", ["a", "c", "e", "g", "single"])
def test_quasi_static_is_affine_in_v2(state):
    """``S = A + B rho V^2/tau`` exactly (to 1e-12) at five velocities, layered or not."""
    if state == "single":
        layers, interfaces = [STATE_LAYERS[0]], []
    else:
        layers, interfaces = state_problem(state, 0.0, "quasi-static")
    S = [cavity_solution(layers, interfaces, v, RADIUS, boundary="quasi-static").S
         for v in VELOCITIES]
    residuals, _ = affine_residuals(S, VELOCITIES)
    assert np.max(np.abs(residuals)) <= 1e-12
    b = {plastic_radius(layers, interfaces, v, RADIUS, boundary="quasi-static")
         for v in VELOCITIES}
    assert len(b) == 1


@pytest.mark.parametrize("lam", [0.15, 0.5, 1.5])
def test_dynamic_boundary_moves_in_with_velocity(lam):
    """Dynamic ``b`` decreases strictly with ``V`` for ``lam > 0``; ``S`` leaves the parabola."""
    material = Material(E=25e9, nu=0.2, rho=2500.0, lam=lam, tau=25e6)
    dynamic = [cavity_solution([material], [], v, RADIUS, boundary="dynamic") for v in VELOCITIES]
    quasi = [cavity_solution([material], [], v, RADIUS, boundary="quasi-static")
             for v in VELOCITIES]
    b = [state.plastic_radius for state in dynamic]
    assert all(outer > inner for outer, inner in zip(b, b[1:], strict=False))
    # at V = 0 the two conventions coincide for one layer: (2E/3)(1 - 2 alpha/3) y^3 = k
    assert relative_error(dynamic[0].S, quasi[0].S) <= 1e-13
    assert dynamic[0].plastic_radius == pytest.approx(quasi[0].plastic_radius, rel=1e-13)
    for dyn, qs in zip(dynamic[1:], quasi[1:], strict=True):
        assert relative_error(dyn.S, qs.S) > 1e-4
    residuals, _ = affine_residuals([s.S for s in dynamic], VELOCITIES)
    assert np.max(np.abs(residuals)) > 1e-4


def test_dynamic_boundary_fixed_for_tresca():
    """``lam = 0``: the dynamic yield condition has no pressure term, ``b`` is frozen."""
    material = Material(E=25e9, nu=0.2, rho=2500.0, lam=0.0, tau=25e6)
    b = {plastic_radius([material], [], v, RADIUS, boundary="dynamic") for v in VELOCITIES}
    assert max(b) == pytest.approx(min(b), rel=1e-14)


# --------------------------------------------------------------------------------------------
# 5. Input validation
# --------------------------------------------------------------------------------------------

GOOD = {"layers": [STATE_LAYERS[0], STATE_LAYERS[1]], "interfaces": [0.1], "velocity": 300.0,
        "radius": RADIUS, "boundary": "dynamic"}

NAN = float("nan")
INF = float("inf")


@pytest.mark.parametrize(("change", "parameter", "accepted"), [
    ({"radius": 0.0}, "radius", "> 0"),
    ({"radius": -0.01}, "radius", "> 0"),
    ({"radius": NAN}, "radius", "> 0"),
    ({"radius": INF}, "radius", "finite"),
    ({"velocity": -1.0}, "velocity", "in [0, 10000] m/s"),
    ({"velocity": NAN}, "velocity", "in [0, 10000] m/s"),
    ({"velocity": INF}, "velocity", "in [0, 10000] m/s"),
    ({"boundary": "static"}, "boundary", "'dynamic' or 'quasi-static'"),
    ({"interfaces": [0.01]}, "interfaces[0]", "outside the cavity"),
    ({"interfaces": [RADIUS]}, "interfaces[0]", "outside the cavity"),
    ({"interfaces": [NAN]}, "interfaces[0]", "finite"),
    ({"interfaces": []}, "interfaces", "len(layers) - 1"),
    ({"interfaces": [0.1, 0.2]}, "interfaces", "len(layers) - 1"),
    ({"layers": [STATE_LAYERS[0]] * 3, "interfaces": [0.2, 0.1]}, "interfaces[1]",
     "increasing"),
    ({"layers": [STATE_LAYERS[0]] * 3, "interfaces": [0.2, 0.2]}, "interfaces[1]",
     "increasing"),
    ({"layers": [], "interfaces": []}, "layers", "at least one"),
])
@pytest.mark.parametrize("function", [cavity_solution, cavity_stress, plastic_radius])
def test_bad_problem_raises_input_error(function, change, parameter, accepted):
    """One-line :class:`CavexInputError` naming the parameter and its accepted range."""
    problem = {**GOOD, **change}
    with pytest.raises(CavexInputError) as error:
        function(problem["layers"], problem["interfaces"], problem["velocity"],
                 problem["radius"], boundary=problem["boundary"])
    message = str(error.value)
    assert "\n" not in message
    assert f"'{parameter}'" in message
    assert accepted in message
