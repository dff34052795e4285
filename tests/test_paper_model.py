"""The paper's printed Eqs. (19)-(29) against the derived layered cavity expansion.

Where the paper (after the OCR fixes of docs/paper_model.md) is the derived quasi-static model
up to its dropped elastic-zone quartic inertia, the two agree to round-off once that term is
restored; that term and the paper's two genuine errors (the sign in Eqs. 24-25, the stray term
of Eq. 29) are recomputed here from the derived solution, not copied from the implementation.
"""

import math

import pytest

from cavex.analytic.cavity import cavity_solution
from cavex.analytic.geometry import spherical_problem
from cavex.analytic.paper_model import (
    paper_coefficients,
    paper_phase_depths,
    paper_single_coefficients,
    paper_stress,
)
from cavex.config import load_config
from cavex.errors import CavexInputError
from cavex.materials import Material, Projectile, Target

REL = 1e-10


def default():
    return load_config()


def coverage_target():
    """Thin middle layer and eps1 < eps2 < eps3, so all eight states a-h have extent."""
    layers = (Material(E=25e9, nu=0.3, rho=2500.0, lam=0.15, tau=25e6),
              Material(E=10e9, nu=0.3, rho=1800.0, lam=0.35, tau=20e6),
              Material(E=1e9, nu=0.3, rho=1600.0, lam=0.5, tau=5e6))
    target = Target(layers, (0.5, 0.03))
    projectile = Projectile(r=0.0125, l=0.03, m=0.5, V0=800.0, R=0.075)
    return target, projectile


def eps(material):
    return (1.5 * material.tau / material.E) ** (1.0 / 3.0)


def derived(target, projectile, depth, velocity):
    layers, radii = spherical_problem(target, projectile, depth, switch="nose-tip")
    return cavity_solution(layers, radii, velocity, projectile.r, boundary="quasi-static"), layers


def dropped_quartic(state, layers, radii, velocity):
    """Elastic-zone inertia ``-(rho V^2/2) y^4`` terms the paper omits, carried to the wall.

    The derived elastic step contains ``-2 rho V^2 (y_in^4 - y_out^4)/4`` for every elastic
    piece outside ``b``; plastic layers multiply a boundary stress by ``(r_out/r_in)^(2 alpha)``.
    """
    a, b = state.radius, state.plastic_radius
    edges = [b] + [h for h in radii if h > b] + [math.inf]
    first = sum(1 for h in radii if h <= b)
    at_boundary = 0.0
    for j, (inner, outer) in enumerate(zip(edges, edges[1:], strict=False)):
        rho = layers[first + j].rho
        at_boundary += 0.5 * rho * velocity ** 2 * ((a / inner) ** 4 - (a / outer) ** 4)
    transfer = math.prod((r_out / r_in) ** (2.0 * layers[i].alpha)
                         for i, r_in, r_out in state.plastic_zones)
    return transfer * at_boundary


def sign_error(layers, velocity):
    """Printed ``+2 rho1/(rho_n (p1 - 1))`` instead of ``-``: ``4 rho1 V^2/(p1 - 1)`` in stress."""
    return 4.0 * layers[0].rho * velocity ** 2 / (2.0 * layers[0].alpha - 1.0)


def expected_paper_stress(target, projectile, depth, velocity):
    state, layers = derived(target, projectile, depth, velocity)
    _, radii = spherical_problem(target, projectile, depth, switch="nose-tip")
    expected = state.stress + dropped_quartic(state, layers, radii, velocity)
    if state.state in ("d", "e"):
        expected += sign_error(layers, velocity)
    if state.state == "single":
        expected += layers[0].rho * velocity ** 2 * eps(layers[0]) ** (-2.0 * layers[0].alpha)
    return expected, state.state


def coverage_depths():
    target, projectile = coverage_target()
    d = paper_phase_depths(target, projectile)
    mid = lambda x, y: 0.5 * (x + y)  # noqa: E731
    return {"a": 0.3, "b": mid(d["L1"], d["L2"]), "c": mid(d["L2"], d["L3"]),
            "d": mid(d["L3"], d["L4"]), "e": mid(d["L4"], d["H1"]),
            "h": mid(d["H1"], d["H2"]), "single": 0.8}


def test_phase_depths_of_table_1():
    target, projectile = default()
    d = paper_phase_depths(target, projectile)
    r, nose = projectile.r, projectile.l
    e1, e2, e3 = (eps(m) for m in target.layers)
    assert d["L1"] == pytest.approx(0.65 + nose - r / e1, rel=1e-14)
    assert d["L3"] == pytest.approx(1.1 + nose - r / e2, rel=1e-14)
    assert d["L4"] == pytest.approx(1.1 + nose - r / e3, rel=1e-14)
    # Table 1 has tau/E = 1e-3 in concrete and macadam: eps1 == eps2, L1 == L2 (no state b).
    assert d["L2"] == pytest.approx(d["L1"], rel=1e-14)
    assert d["L1"] == pytest.approx(0.6008024419, rel=1e-9)
    assert (d["H1"], d["H2"]) == (0.65, 1.1)


@pytest.mark.parametrize("velocity", [0.0, 300.0, 1000.0])
@pytest.mark.parametrize("state", ["a", "b", "c", "d", "e", "h", "single"])
def test_every_state_matches_derived_up_to_documented_terms(state, velocity):
    target, projectile = coverage_target()
    depth = coverage_depths()[state]
    expected, derived_state = expected_paper_stress(target, projectile, depth, velocity)
    coefficients = paper_coefficients(target, projectile, depth)
    assert coefficients.state == derived_state == state
    assert paper_stress(target, projectile, depth, velocity) == pytest.approx(expected, rel=REL)


@pytest.mark.parametrize("depth, equation, state", [
    (0.2, 19, "a"), (0.45, 19, "a"), (0.62, 23, "c"), (0.64, 23, "c"), (0.7, 26, "f"),
    (0.95, 26, "f"), (1.07, 27, "g"), (1.3, 29, "single")])
@pytest.mark.parametrize("velocity", [0.0, 600.0])
def test_default_target_states_and_stress(depth, equation, state, velocity):
    target, projectile = default()
    coefficients = paper_coefficients(target, projectile, depth)
    assert (coefficients.equation, coefficients.state) == (equation, state)
    expected, derived_state = expected_paper_stress(target, projectile, depth, velocity)
    assert derived_state == state
    assert coefficients.stress(velocity) == pytest.approx(expected, rel=REL)


def test_coefficients_normalise_by_the_equation_layer():
    target, projectile = coverage_target()
    depths = coverage_depths()
    layer = {"a": 0, "b": 0, "c": 1, "d": 1, "e": 2, "h": 2, "single": 2}
    for state, depth in depths.items():
        c = paper_coefficients(target, projectile, depth)
        material = target.layers[layer[state]]
        assert (c.tau, c.rho) == (material.tau, material.rho)
        assert c.S(500.0) == pytest.approx(c.A + c.B * c.rho * 500.0 ** 2 / c.tau, rel=1e-14)


def test_a_coefficient_is_the_derived_static_stress():
    """At V = 0 only the OCR fixes matter: paper A == derived S (own tau) to round-off."""
    target, projectile = coverage_target()
    for depth in coverage_depths().values():
        c = paper_coefficients(target, projectile, depth)
        state, _ = derived(target, projectile, depth, 0.0)
        assert c.tau * c.A == pytest.approx(state.stress, rel=REL)


def test_single_medium_is_eq19_with_identical_layers_minus_stray_term():
    concrete = default()[0].layers[0]
    same = Target((concrete,) * 3, (0.65, 0.45))
    projectile = default()[1]
    layered = paper_coefficients(same, projectile, 0.3)
    single = paper_single_coefficients(concrete)
    assert layered.equation == 19
    assert layered.A == pytest.approx(single.A, rel=REL)
    assert single.B - layered.B == pytest.approx(eps(concrete) ** (-2 * concrete.alpha), rel=REL)


def test_single_medium_against_derived_single_layer():
    soil = default()[0].layers[2]
    c = paper_single_coefficients(soil)
    e = eps(soil)
    for velocity in (0.0, 250.0, 900.0):
        state = cavity_solution([soil], [], velocity, 0.01, boundary="quasi-static")
        quartic = 0.5 * soil.rho * velocity ** 2 * e ** 4 * e ** (-2 * soil.alpha)
        stray = soil.rho * velocity ** 2 * e ** (-2 * soil.alpha)
        assert c.stress(velocity) == pytest.approx(state.stress + quartic + stray, rel=REL)


def test_single_medium_hopkins_limit():
    """lam -> 0: A -> (2/3)(1 + ln(2E/3tau)); B -> 3/2 + 1 (stray term) + eps^4/2."""
    tresca_like = Material(E=25e9, nu=0.3, rho=2500.0, lam=1e-7, tau=25e6)
    c = paper_single_coefficients(tresca_like)
    assert c.A == pytest.approx(2 / 3 * (1 + math.log(2 * 25e9 / (3 * 25e6))), rel=1e-5)
    assert c.B == pytest.approx(1.5 + 1.0 + 0.5 * eps(tresca_like) ** 4, rel=1e-5)


def test_continuity_at_phase_depths():
    """Continuous at L1, L2, L4 and f->g at L3; jumps by the sign error at c->d (L3) and at the
    nose-tip switches H1, H2 (documented)."""
    target, projectile = coverage_target()
    d = paper_phase_depths(target, projectile)
    velocity, gap = 500.0, 1e-9

    def jump(depth):
        below = paper_stress(target, projectile, depth - gap, velocity)
        above = paper_stress(target, projectile, depth + gap, velocity)
        return above - below, below

    for name in ("L1", "L2", "L4"):
        step, level = jump(d[name])
        assert abs(step) < 1e-6 * abs(level), name
    step, level = jump(d["L3"])
    assert step == pytest.approx(sign_error(target.layers, velocity), rel=1e-5)
    for name in ("H1", "H2"):
        step, level = jump(d[name])
        assert abs(step) > 1e-3 * abs(level), name
    table_target, table_projectile = default()
    table = paper_phase_depths(table_target, table_projectile)
    for name in ("L1", "L3"):  # a -> c (L1 == L2) and f -> g
        below = paper_stress(table_target, table_projectile, table[name] - gap, velocity)
        above = paper_stress(table_target, table_projectile, table[name] + gap, velocity)
        assert abs(above - below) < 1e-6 * below, name


@pytest.mark.parametrize("call, parameter", [
    (lambda t, p: paper_coefficients(t, p, -0.1), "depth"),
    (lambda t, p: paper_coefficients(t, p, 0.3, epsilon="dynamic"), "epsilon"),
    (lambda t, p: paper_phase_depths(t, p, epsilon="table-2"), "epsilon"),
    (lambda t, p: paper_stress(t, p, 0.3, -5.0), "velocity"),
    (lambda t, p: paper_coefficients(
        Target((Material(E=1e9, nu=0.3, rho=2e3, lam=0.0, tau=1e6),), ()), p, 0.3),
     "layers[0].lam"),
    (lambda t, p: paper_coefficients(Target(t.layers + t.layers[-1:], (0.65, 0.45, 0.5)), p, 0.3),
     "target.layers"),
])
def test_bad_input_names_the_parameter(call, parameter):
    target, projectile = default()
    with pytest.raises(CavexInputError) as error:
        call(target, projectile)
    message = str(error.value)
    assert f"'{parameter}'" in message and "\n" not in message


def test_cylindrical_reading_of_eps():
    """eps^2 = 3 tau/(2E): L1 = H1 + l - r/sqrt(1.5e-3) ~ 0.387 m (Table 2 ends phase 2 at 0.40)."""
    target, projectile = default()
    d = paper_phase_depths(target, projectile, epsilon="cylindrical")
    assert d["L1"] == pytest.approx(0.65 + 0.06 - 0.0125 / math.sqrt(1.5e-3), rel=1e-14)
    assert d["L4"] == pytest.approx(1.1 + 0.06 - 0.0125 / math.sqrt(1.5 * 6e6 / 0.12e9), rel=1e-14)
    states = [paper_coefficients(target, projectile, L, epsilon="cylindrical").state
              for L in (0.3, 0.5, 0.7, 0.9, 1.05, 1.2)]
    assert states == ["a", "c", "f", "g", "g", "single"]
    # A keeps the printed 2/3, which presumes eps^3 = 3 tau/(2E): eq. 29 A with the other eps.
    soil = target.layers[2]
    e = math.sqrt(1.5 * soil.tau / soil.E)
    p = 2 * soil.alpha
    assert paper_single_coefficients(soil, "cylindrical").A == pytest.approx(
        (2 / 3 + 1 / soil.lam) * e ** -p - 1 / soil.lam, rel=REL)
