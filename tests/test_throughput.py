"""The batched FE path (cavex.fem.batch) against the one-case path: identity, failures, input."""

import json

import numpy as np
import pytest
from cavex.analytic.geometry import spherical_problem
from cavex.fem import batch, expand_cavity, solver
from cavex.fem.batch import expand_cavities, expand_chunk
from cavex.fem.solver import StepFailure

from cavex import load_config
from cavex.errors import CavexInputError, CavexNumericalError
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

    monkeypatch.setattr(solver, "line_search_newton", fail)
    monkeypatch.setattr(batch, "line_search_newton", fail)


def relative(a, b):
    return abs(a - b) / abs(b)


@pytest.fixture(scope="module")
def mixed():
    return expand_cavities(MIXED, batch_size=3)  # stacks: 3 dynamic + 1, 2 quasi-static


def test_batched_equals_one_case_path_to_1e10(mixed):
    for args, b in zip(MIXED, mixed, strict=True):
        one = expand_cavity(*args)
        assert b.ok
        # measured: identical to the last bit
        assert relative(b.cavity_stress, one.cavity_stress) <= 1e-10
        assert relative(b.error_estimate, one.error_estimate) <= 1e-10
        assert relative(b.plastic_radius, one.plastic_radius) <= 1e-10
        assert np.max(np.abs(b.u - one.fields["u"])) <= 1e-10 * RADIUS
        assert b.stats["newton_iterations"] == one.stats["newton_iterations"]
        assert b.stats["cutbacks"] == one.stats["cutbacks"]
        assert 0 < b.error_estimate < 0.005


def test_numpy_kernels_give_the_same_batch(monkeypatch, mixed):
    monkeypatch.setattr(batch, "kernels", None)
    again = expand_cavities(MIXED[:2], error_estimate=False)
    for a, b in zip(again, mixed[:2], strict=True):
        assert relative(a.cavity_stress, b.cavity_stress) <= 1e-10


def test_newton_failure_is_reported_for_its_case_only(no_line_search):
    # quasi-static expansion in soil on a coarse mesh with large steps fails in the one-case
    # path too (after the cut-backs, without the line-searched last attempt); the others run
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
            assert relative(r.cavity_stress,
                            expand_cavity(*args, **settings).cavity_stress) <= 1e-10
    with pytest.raises(CavexNumericalError, match=r"V = 0 m/s.*cut-backs"):
        expand_cavities(cases[1:2], on_error="raise", **settings)


def test_chunk_function_is_json_able():
    case = {"id": "c0", "numerics": {"error_estimate": False},
            "problems": [{"layers": [{"E": 25e9, "nu": 0.4999, "rho": 2500.0, "lam": 0.15,
                                      "tau": 25e6}], "interfaces": [], "velocity": 500.0,
                          "radius": RADIUS}]}
    out = json.loads(json.dumps(expand_chunk(case)))
    direct = expand_cavity([CONCRETE], [], 500.0, RADIUS, error_estimate=False)
    assert out["cavity_stress"] == [direct.cavity_stress] and out["error"] == [None]


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
    one = expand_cavity(*cases[above], **refined.numerics)
    assert refined.cavity_stress == one.cavity_stress
    assert refined.error_estimate == one.error_estimate < plain[above].error_estimate
    assert results[1 - above].cavity_stress == plain[1 - above].cavity_stress


def test_finer_companion_where_the_coarser_run_fails(no_line_search):
    # quasi-static soil without the line search: the half-resolution run fails, the estimate
    # comes from a 2x finer run
    args = problem(1.25, 0.0)
    b, = expand_cavities([args])
    one = expand_cavity(*args)
    assert b.stats["error_companion"] == one.stats["error_companion"] == "finer"
    assert b.cavity_stress == one.cavity_stress and b.error_estimate == one.error_estimate
    assert b.stats["finer_cavity_stress"] == one.stats["finer_cavity_stress"]
