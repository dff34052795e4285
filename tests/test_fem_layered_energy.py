"""Energy balance, outer boundary, seed ratio, and layered runs over nose depth (default target)."""

import numpy as np
import pytest

from cavex import load_config
from cavex.fem import expand_cavity
from cavex.materials import Material
from cavex.verification.fedata.comparison import compare_at_depth

CONCRETE = Material(E=25e9, nu=0.4999, rho=2500.0, lam=0.15, tau=25e6)


@pytest.mark.parametrize(("velocity", "rho_inf"), [(500.0, 1.0), (0.0, 0.0)])
def test_energy_balance(velocity, rho_inf):
    r = expand_cavity([CONCRETE], [], velocity, 0.0125, rho_inf=rho_inf, error_estimate=False)
    e = r.energy
    balance = (e["kinetic"] + e["stored"] + e["dissipated"]) / e["work"] - 1
    # measured: -0.44 % (dynamic, rho_inf = 1: no numerical damping), +0.21 % (quasi-static)
    assert abs(balance) < 0.01
    assert e["dissipated"] > 0.25 * e["work"]


def test_default_damping_dissipates_little_and_leaves_the_wall_stress():
    damped = expand_cavity([CONCRETE], [], 500.0, 0.0125, error_estimate=False)
    undamped = expand_cavity([CONCRETE], [], 500.0, 0.0125, rho_inf=1.0, error_estimate=False)
    e = damped.energy
    lost = 1 - (e["kinetic"] + e["stored"] + e["dissipated"]) / e["work"]
    assert 0 < lost < 0.04  # measured 2.6 %: the rho_inf = 0 filter of spurious P-wave modes
    assert damped.cavity_stress == pytest.approx(undamped.cavity_stress, rel=0.005)


def test_outer_boundary_is_far_enough():
    # slowest velocity: the P wave reaches farthest; moving the fixed boundary from 1000 a to
    # 3000 a changes the wall stress by 4.5e-4, freeing it by 2.1e-4 (measured), below the
    # 0.5 % error target
    near = expand_cavity([CONCRETE], [], 50.0, 0.0125, error_estimate=False)
    far = expand_cavity([CONCRETE], [], 50.0, 0.0125, outer_ratio=3000.0, error_estimate=False)
    free = expand_cavity([CONCRETE], [], 50.0, 0.0125, outer="free", error_estimate=False)
    assert near.cavity_stress == pytest.approx(far.cavity_stress, rel=0.001)
    assert near.cavity_stress == pytest.approx(free.cavity_stress, rel=0.001)


def test_seed_ratio_effect_is_small():
    S = {k: expand_cavity([CONCRETE], [], 500.0, 0.0125, seed_ratio=k,
                          error_estimate=False).cavity_stress for k in (5, 20, 80)}
    # measured relative to a/a0 = 80: -0.053 % (5), -0.020 % (10), -0.009 % (20)
    assert S[20] == pytest.approx(S[80], rel=0.002)
    assert S[5] == pytest.approx(S[80], rel=0.01)


@pytest.fixture(scope="module")
def default_target():
    return load_config()


@pytest.mark.parametrize("depth", [0.2, 0.45, 0.8])
def test_layered_wall_stress_converges(default_target, depth):
    target, projectile = default_target
    levels = [(15.0, 0.06), (30.0, 0.03), (60.0, 0.015)]
    S = [compare_at_depth(target, projectile, depth, 500.0, elements_per_decade=e,
                          growth_per_step=g, error_estimate=False)["fe_sigma_r_Pa"]
         for e, g in levels]
    # consecutive refinements within 1 % (25-depth study in benchmarks/fem_layered.py:
    # max 0.95 % coarse->mid, 0.77 % mid->fine)
    assert abs(S[1] / S[0] - 1) < 0.01 and abs(S[2] / S[1] - 1) < 0.01


def test_layered_S_of_L_is_smooth_in_the_incompressible_limit(default_target):
    target, projectile = default_target
    depths = np.linspace(0.10, 0.50, 9)
    S = np.array([compare_at_depth(target, projectile, L, 500.0, nu=0.49999, outer_ratio=3000.0,
                                   error_estimate=False)["fe_sigma_r_Pa"] for L in depths])
    # at nu = 0.4999 S(L) wiggles by ~0.5 %: P-wave reverberation between the cavity and the
    # concrete/macadam interface in the compressible solid (amplitude ~ V/c_p). At nu = 0.49999
    # S(L) decreases monotonically, as the incompressible model does, without chatter:
    assert np.all(np.diff(S) < 0)
    second = np.abs(S[2:] - 2 * S[1:-1] + S[:-2]) / S[1:-1]
    assert second.max() < 0.002  # measured 0.07 %
