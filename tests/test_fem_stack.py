"""The one FE solver on many problems: a case gives the same bits alone and inside any stack,
failures stay with their case, the error companion and refinement policies, bad input."""

import numpy as np
import pytest

from cavex import load_config
from cavex.analytic.geometry import spherical_problem
from cavex.errors import CavexInputError, CavexNumericalError
from cavex.fem import expand_cavities, expand_cavity, newton
from cavex.fem.estimate import richardson_error, richardson_error_from_finer
from cavex.fem.newton import StepFailure
from cavex.materials import Material

TARGET, PROJECTILE = load_config()
RADIUS = PROJECTILE.r
CONCRETE = Material(E=25e9, nu=0.4999, rho=2500.0, lam=0.15, tau=25e6, name="concrete")


def problem(depth, velocity):
    layers, interfaces = spherical_problem(TARGET, PROJECTILE, depth)
    return layers, interfaces, velocity, RADIUS


# three, two and one layers at the wall; quasi-static, slow (many cut-backs) and fast cases;
# quasi-static soil, whose half-resolution error-estimate run needs the line-searched last
# attempt (tests/test_fem_newton.py)
MIXED = [problem(0.30, 500.0), problem(0.64, 1200.0), problem(1.00, 40.0),
         problem(1.25, 150.0), ([CONCRETE], [], 0.0, RADIUS), problem(1.25, 0.0)]


@pytest.fixture
def no_line_search(monkeypatch):
    """The line-searched last attempt of a failing step switched off (fails at once)."""

    def fail(*args, **kwargs):
        raise StepFailure("line search switched off")

    monkeypatch.setattr(newton, "line_search_newton", fail)


@pytest.fixture(scope="module")
def mixed():
    return expand_cavities(MIXED, batch_size=3)  # stacks: 3 dynamic + 1, 2 quasi-static


def test_a_case_alone_and_inside_mixed_stacks_is_the_same_to_the_last_bit(mixed):
    # the same code on the same data: the stack only concatenates independent blocks
    for args, b in zip(MIXED, mixed, strict=True):
        one = expand_cavity(*args)
        assert b.ok and one.ok
        assert b.cavity_stress == one.cavity_stress
        assert b.error_estimate == one.error_estimate
        assert b.plastic_radius == one.plastic_radius
        assert np.array_equal(b.u, one.u)
        for name in ("newton_iterations", "cutbacks", "steps", "line_search_steps"):
            assert b.stats[name] == one.stats[name]
        assert 0 < b.error_estimate < 0.005
    # and in another stack composition
    again = expand_cavities(MIXED[::-1], batch_size=4)[::-1]
    assert [r.cavity_stress for r in again] == [r.cavity_stress for r in mixed]
    # cut-backs and the line search are exercised by this set
    assert max(r.stats["cutbacks"] for r in mixed) > 0


def test_one_case_history_ends_at_the_stack_result(mixed):
    one = expand_cavity(*MIXED[0])
    assert one.history["wall_stress"][-1] == one.cavity_stress == mixed[0].cavity_stress
    assert one.history["radius"][-1] == pytest.approx(RADIUS, rel=1e-12)
    assert mixed[0].history is None and "sigma_r" not in mixed[0].fields


def test_newton_failure_is_reported_for_its_case_only(no_line_search):
    # quasi-static expansion in soil on a coarse mesh with large steps fails after the
    # cut-backs (without the line-searched last attempt); the others run
    settings = {"max_cutbacks": 2, "error_estimate": False, "growth_per_step": 0.06,
                "elements_per_decade": 15.0}
    cases = [problem(0.30, 500.0), problem(1.25, 0.0), problem(1.25, 300.0),
             ([CONCRETE], [], 800.0, RADIUS)]
    results = expand_cavities(cases, **settings)
    assert [r.ok for r in results] == [True, False, True, True]
    failed = results[1]
    assert isinstance(failed.error, CavexNumericalError) and np.isnan(failed.cavity_stress)
    with pytest.raises(CavexNumericalError) as one:
        expand_cavity(*cases[1], **settings)
    assert str(failed.error) == str(one.value)
    assert str(failed.error).startswith("V = 0 m/s, step to cavity radius")
    assert "wall radius" in str(failed.error) and "cut-backs" in str(failed.error)
    assert str(failed.error).endswith("iterations; line search switched off")
    for args, r in zip(cases, results, strict=True):
        if r.ok:
            assert r.cavity_stress == expand_cavity(*args, **settings).cavity_stress
    with pytest.raises(CavexNumericalError, match=r"V = 0 m/s.*cut-backs"):
        expand_cavities(cases[1:2], on_error="raise", **settings)


@pytest.mark.parametrize(("problems", "kwargs", "name"), [
    ([([CONCRETE], [], -1.0, RADIUS)], {}, r"problems\[0\]: .*'velocity'"),
    ([MIXED[4], ([CONCRETE], [0.1], 100.0, RADIUS)], {}, r"problems\[1\]: .*'interfaces'"),
    ([([CONCRETE], [], 100.0, 0.0)], {}, r"problems\[0\]: .*'radius'"),
    ([([CONCRETE], [], "fast", RADIUS)], {}, r"problems\[0\]: .*'velocity'"),
    ([([CONCRETE], [], 100.0)], {}, r"'problems\[0\]'"),
    ([{"layers": [CONCRETE], "speed": 1.0}], {}, r"'problems\[0\]'"),
    ([MIXED[4]], {"batch_size": 0}, "'batch_size'"),
    ([MIXED[4]], {"on_error": "ignore"}, "'on_error'"),
    ([MIXED[4]], {"growth_per_step": 2.0}, "'growth_per_step'"),
    ([MIXED[4]], {"seed_radius": 1.0}, r"seed_radius"),
    ([MIXED[4]], {"error_target": 2.0}, "'error_target'"),
    ([MIXED[4]], {"assembly": "forms"}, "'assembly'"),
])
def test_bad_input_is_rejected(problems, kwargs, name):
    with pytest.raises(CavexInputError, match=name):
        expand_cavities(problems, **kwargs)


def test_empty_list_gives_empty_result():
    assert expand_cavities([]) == []


def test_error_target_refines_only_the_cases_above_it():
    cases = [([CONCRETE], [], 500.0, RADIUS), ([CONCRETE], [], 100.0, RADIUS)]
    plain = expand_cavities(cases)
    target = 0.5 * (plain[0].error_estimate + plain[1].error_estimate)
    above = int(plain[1].error_estimate > target)
    results = expand_cavities(cases, error_target=target, max_refinements=1)
    refined = results[above]
    assert refined.stats["refinements"] == 1 and results[1 - above].stats["refinements"] == 0
    assert refined.numerics["elements_per_decade"] == 60.0
    assert refined.numerics["growth_per_step"] == 0.015
    one = expand_cavity(*cases[above], **refined.numerics)
    assert refined.cavity_stress == one.cavity_stress
    assert refined.error_estimate == one.error_estimate < plain[above].error_estimate
    assert results[1 - above].cavity_stress == plain[1 - above].cavity_stress


def test_finer_companion_where_the_coarser_run_fails(no_line_search):
    # quasi-static soil without the line search: the half-resolution run fails, the estimate
    # comes from a 2x finer run
    args = problem(1.25, 0.0)
    b, = expand_cavities([args])
    assert b.stats["error_companion"] == "finer"
    assert b.error_estimate == richardson_error_from_finer(b.cavity_stress,
                                                           b.stats["finer_cavity_stress"])
    finer = expand_cavity(*args, elements_per_decade=60.0, growth_per_step=0.015,
                          error_estimate=False)
    assert b.stats["finer_cavity_stress"] == finer.cavity_stress


def test_coarse_companion_is_the_half_resolution_run():
    r, = expand_cavities([([CONCRETE], [], 500.0, RADIUS)])
    coarse = expand_cavity([CONCRETE], [], 500.0, RADIUS, elements_per_decade=15.0,
                           growth_per_step=0.06, error_estimate=False)
    assert r.stats["error_companion"] == "coarse"
    assert r.stats["coarse_cavity_stress"] == coarse.cavity_stress
    assert r.error_estimate == richardson_error(r.cavity_stress, coarse.cavity_stress)
