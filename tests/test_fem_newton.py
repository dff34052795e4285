"""The line-searched last attempt of a failing step (cavex.fem.newton.line_search_newton).

Quasi-static soil (Table 1, E/tau = 20) at half the default resolution used to fail: a point at
the Mohr-Coulomb apex whose solution lies on the cone's face just next to the apex made plain
Newton alternate between an elastic and an apex state (docs/fem.md, "Newton at the apex").
"""

import numpy as np
import pytest

from cavex import load_config
from cavex.fem import expand_cavities, expand_cavity, newton
from cavex.fem.estimate import richardson_error, richardson_error_from_finer
from cavex.fem.newton import StepFailure, line_search_newton

SOIL = load_config()[0].layers[2]
ARGS = ([SOIL], [], 0.0, 0.0125)
HALF = {"elements_per_decade": 15.0, "growth_per_step": 0.06, "error_estimate": False}


@pytest.fixture
def line_searches(monkeypatch):
    """Counts the calls of the line-searched Newton iteration."""
    calls = []

    def counted(*args, **kwargs):
        calls.append(1)
        return line_search_newton(*args, **kwargs)

    monkeypatch.setattr(newton, "line_search_newton", counted)
    return calls


def kinked(x):
    """1-D model of the soil failure in the point's pressure coordinate (Pa beyond the apex):
    apex (x < 0, slope 3.8e-4), Mohr-Coulomb face (0 <= x < 18800, slope 1, root at 37.8),
    elastic (slope 1/1.08). Returns ``(r, scale, slope)``."""
    x = float(x[0])
    if x < 0.0:
        r, k = -37.8 + 3.8e-4 * x, 3.8e-4
    elif x < 18800.0:
        r, k = x - 37.8, 1.0
    else:
        r, k = 18800.0 - 37.8 + (x - 18800.0) / 1.08, 1.0 / 1.08
    return np.array([r]), 1e6, k


def test_plain_newton_two_cycles_where_the_line_search_converges():
    x = np.array([98400.0])  # elastic start, as the soil point at the failing step
    seen = []
    for _ in range(6):
        r, _, k = kinked(x)
        seen.append(round(float(x[0]), 6))
        x = x - r / k
    assert seen[1] == seen[3] == seen[5] < 0 < seen[2] == seen[4]  # apex <-> elastic, forever
    x, out, iterations = line_search_newton(kinked, lambda out, r: r / out[2],
                                            np.array([98400.0]), 1e-12, 30)
    assert abs(x[0] - 37.8) < 1e-9 and iterations <= 4


def test_line_search_failure_is_a_step_failure():
    with pytest.raises(StepFailure, match="line search did not converge in 3"):
        line_search_newton(kinked, lambda out, r: r / out[2], np.array([98400.0]), 0.0, 3)


def test_half_resolution_quasi_static_soil_converges(line_searches):
    half = expand_cavity(*ARGS, **HALF)
    assert line_searches  # the failing step was rescued by the line search
    default = expand_cavity(*ARGS, error_estimate=False)
    finer = expand_cavity(*ARGS, elements_per_decade=60.0, growth_per_step=0.015,
                          error_estimate=False)
    # measured: 18.73130 (half), 18.71114 (default), 18.71614 MPa (2x finer), i.e. the
    # half-resolution run is 1.08e-3 above the default one
    assert half.cavity_stress == pytest.approx(18.7313e6, rel=1e-5)
    assert abs(half.cavity_stress / default.cavity_stress - 1.0) < 1.5e-3
    # the default run's Richardson error from the half-resolution run (3.591e-4) agrees with
    # the one from the 2x finer run (3.566e-4): the half-resolution result is in the
    # asymptotic range, second order
    from_coarse = richardson_error(default.cavity_stress, half.cavity_stress)
    from_finer = richardson_error_from_finer(default.cavity_stress, finer.cavity_stress)
    assert from_coarse == pytest.approx(from_finer, rel=0.05)
    assert from_coarse < 0.005


def test_error_estimate_uses_the_coarse_companion_again():
    result = expand_cavity(*ARGS)
    assert result.stats["error_companion"] == "coarse"
    assert result.error_estimate == richardson_error(result.cavity_stress,
                                                     result.stats["coarse_cavity_stress"])
    assert result.error_estimate == pytest.approx(3.59e-4, rel=0.01)  # measured 3.591e-4


def test_the_rescue_is_the_same_inside_a_stack(line_searches):
    # the same case alone and inside a stack with two others: one line search each, the same
    # bits (the same code on the same data)
    alone = expand_cavity(*ARGS, **HALF)
    assert len(line_searches) == 1 and alone.stats["line_search_steps"] == 1
    concrete = load_config()[0].layers[0]
    stacked = expand_cavities([([concrete], [], 0.0, 0.0125), ARGS, ([concrete], [], 0.0, 0.02)],
                              **HALF)
    assert len(line_searches) == 2
    b = stacked[1]
    assert b.ok and b.cavity_stress == alone.cavity_stress
    assert np.array_equal(b.u, alone.u)
    assert b.stats["newton_iterations"] == alone.stats["newton_iterations"]
    assert b.stats["cutbacks"] == alone.stats["cutbacks"]


# --- the stall rule: a failing attempt ends early -----------------------------------------------

def stall_iteration(residuals):
    """Iteration (1-based) at which the stall rule (:func:`cavex.fem.newton.stalls`) fails a
    case whose relative residuals are ``residuals`` (the first is the predictor's), or None."""
    best, stalled = np.full(1, np.inf), np.zeros(1, dtype=np.int64)
    for iteration, r in enumerate(residuals[1:], start=2):
        if newton.stalls(r, best, stalled, 0, newton.STALL_ITERATIONS):
            return iteration
    return None


# relative residuals of two attempts measured on the issue grid (V = 200 m/s, L = 0.8 m): one
# that ended in a two-cycle and used to run its 30 iterations, one that converged after
# climbing twice
CYCLING = [6.8e-2, 3.4e-1, 3.8e-1, 3.5e-1, 2.2e-1, 1.7e-1, 6.2e-2, 1.1e-2] + [5.9e-2, 1.1e-2] * 11
CONVERGING = [8.6e-2, 3.8e-1, 4.3e-1, 4.0e-1, 2.7e-1, 3.9e-1, 5.4e-6, 1.0e-14]


def test_stall_rule_on_measured_residuals():
    assert newton.STALL_ITERATIONS == 4
    assert stall_iteration(CYCLING) == 12  # 4 iterations after the last new low (iteration 8)
    assert stall_iteration(CONVERGING) is None  # the predictor's residual is not a low to beat
    assert stall_iteration([1.0, 0.5] + [0.6] * 3) is None
    assert stall_iteration([1.0, 0.5] + [0.6] * 4) == 6


def test_stall_rule_saves_work_and_keeps_the_answer(monkeypatch):
    """Quasi-static macadam over soil (interface at 0.02 m): its failing attempts cycle; ending
    them at the stall instead of after 30 iterations saves residual evaluations (measured 1058
    against 1898, 69 cut-backs against 67) and leaves the wall stress within its error estimate
    (measured: unchanged)."""
    macadam, soil = load_config()[0].layers[1:]
    args = ([macadam, soil], [0.02], 0.0, 0.0125)
    with_rule = expand_cavity(*args)
    monkeypatch.setattr(newton, "STALL_ITERATIONS", newton.MAX_ITERATIONS)
    without = expand_cavity(*args)
    assert with_rule.stats["residual_evaluations"] < 0.7 * without.stats["residual_evaluations"]
    change = abs(with_rule.cavity_stress / without.cavity_stress - 1.0)
    assert change <= without.error_estimate


def test_quasi_static_predictor_follows_the_wall_increments():
    """Quasi-static steps are all of pseudo-time 1 while the wall increments grow 3 % a step;
    the predictor scaled by the wall's increment ratio (not by dt / dt_old) lets the default
    concrete run take its 102 steps without a cut-back (measured 0; 29 cut-backs and 131 steps
    with the dt ratio)."""
    concrete = load_config()[0].layers[0]
    run = expand_cavity([concrete], [], 0.0, 0.0125, error_estimate=False)
    assert run.stats["cutbacks"] <= 3 and run.stats["steps"] == 102 + run.stats["cutbacks"]
