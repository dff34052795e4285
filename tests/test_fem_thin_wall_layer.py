"""A wall layer that is a thin shell around the cavity (a nose depth just above a wall-layer
switch, docs/fem.md "Thin wall layer"): left out when it is the rounding of the switch depth,
refused (a failed case, no run) when thinner than the FE resolves, run when thicker."""

import pytest

from cavex.analytic.geometry import switch_depths
from cavex.config import load_config
from cavex.fem.expansion import GONE_SHELL, THIN_SHELL, expand_problems, wall_shell
from cavex.fem.settings import make_numerics
from cavex.verification.fedata.comparison import compare_at_depth, fe_problem

TARGET, PROJECTILE = load_config(None)
SWITCHES = switch_depths(TARGET, PROJECTILE)
RADIUS = PROJECTILE.r


@pytest.mark.parametrize("switch", SWITCHES)
@pytest.mark.parametrize("velocity", [0.0, 500.0])
def test_the_switch_depth_itself_runs_as_past_the_switch(switch, velocity):
    """At L_s as typed (0.6975, 1.1475 m) the rounding leaves a shell of 1e-17 to 1e-16 m
    (every such FE cell failed: Newton, a folded element); it is left out, and the run is the
    one 1e-9 m past the switch (the table's switch node) to the FE's reproducibility: the two
    problems differ only in the deeper interfaces, by 1e-9 m."""
    typed = round(switch, 4)
    assert wall_shell(fe_problem(TARGET, PROJECTILE, typed, velocity, None)) < GONE_SHELL * RADIUS
    at = compare_at_depth(TARGET, PROJECTILE, typed, velocity)
    past = compare_at_depth(TARGET, PROJECTILE, switch + 1e-9, velocity)
    assert at["fe_sigma_r_Pa"] == pytest.approx(past["fe_sigma_r_Pa"], rel=1e-6)
    assert at["interface_radii_final_m"][0] == RADIUS


@pytest.mark.parametrize("shell", [1e-8, 1e-6, 3e-5])
def test_a_shell_thinner_than_the_fe_resolves_fails_without_a_run(shell):
    problem = fe_problem(TARGET, PROJECTILE, SWITCHES[0] - shell, 1000.0, None)
    assert GONE_SHELL * RADIUS < wall_shell(problem) < THIN_SHELL * RADIUS
    result, = expand_problems([problem], make_numerics())
    assert not result.ok and result.stats["steps"] == 0
    assert "thinner than the FE resolves" in str(result.error)


@pytest.mark.parametrize("velocity", [0.0, 1000.0])
def test_a_shell_above_the_bound_runs_and_follows_the_thicker_shells(velocity):
    """At 1e-4 m (8e-3 of the radius) the FE runs; its wall stress lies between the 1 mm
    shell's and the switch's (measured 91.746 between 91.962 and 91.726 MPa quasi-static,
    4441 between 4385 and 4492 MPa at 1000 m/s)."""
    values = [compare_at_depth(TARGET, PROJECTILE, depth, velocity)["fe_sigma_r_Pa"]
              for depth in (SWITCHES[0] - 1e-3, SWITCHES[0] - 1e-4, SWITCHES[0] + 1e-9)]
    assert min(values[0], values[2]) < values[1] < max(values[0], values[2])
