"""The compiled point and element kernels against independent numpy/scikit-fem oracles.

Tolerances (measured on 800 000 random points, the sample of these tests):
stresses and plastic strains agree to the last bit on a CPU without AVX-512 (numpy's ``exp``
is then libm's); with AVX-512 numpy's SIMD ``exp`` differs from libm's by 1 ulp on a few
percent of inputs, which moves ``J`` and the stresses by <= 1e-15 of their scale: bound 1e-13.
The consistent tangent differs by up to 1.6e-12 of ``K + G`` (the corner's 2x2 product is
associated differently): bound 1e-11. Element force and tangent against the scikit-fem forms:
measured <= 1.1e-15 of the largest entry (P1 and P2): bound 1e-12.
"""

import numpy as np
import pytest
from fem_helpers import advance, point_material, return_map
from oracles import assemble_forms, hencky_mohr_coulomb

from cavex import load_config
from cavex.fem.expansion import build_model
from cavex.fem.settings import Numerics
from cavex.fem.solver import RadialSolver

LAYERS = load_config()[0].layers


def random_points(rng, n, material):
    """Strains from tiny (elastic) to large (plastic, tension) around each layer's yield."""
    yield_strain = material.tau / material.K
    spread = [0.1, 1.0, 10.0, 100.0, 1e4]
    eps_r, eps_t = (np.clip(rng.normal(0, 1, n) * yield_strain * rng.choice(spread, n),
                            -0.5, 0.5) for _ in range(2))
    theta_p, gamma_p = (rng.normal(0, 1, n) * yield_strain * rng.choice([0.0, 1.0, 10.0], n)
                        for _ in range(2))
    return eps_r, eps_t, theta_p, gamma_p


@pytest.mark.parametrize(("dilatancy", "cutoff"), [(0.0, None), (20.0, None), (0.0, 2e6),
                                                   (10.0, 1e5)])
def test_point_kernel_equals_the_numpy_return_map(dilatancy, cutoff):
    rng = np.random.default_rng(7)
    n = 200_000
    material = point_material(LAYERS, rng.integers(0, 3, n), dilatancy, cutoff)
    eps_r, eps_t, theta_p, gamma_p = random_points(rng, n, material)
    kernel = return_map(eps_r, eps_t, theta_p, gamma_p, material)
    # each point its own group: the oracle chooses the multi-surface return per point, as the
    # kernel does
    oracle = hencky_mohr_coulomb(eps_r, eps_t, theta_p, gamma_p, material, groups=np.arange(n))
    assert np.array_equal(kernel["plastic"], oracle.plastic)
    stress = np.abs(oracle.tau_r) + np.abs(oracle.tau_t) + material.tau
    strain = np.abs(eps_r) + np.abs(eps_t) + material.tau / material.K
    # Points returned to the apex of the cone (no tension cut-off; strength lam P + tau J and
    # the deviator Q both within round-off of 0: about a quarter of this sample) are a singular
    # corner: which part of the plastic strain is deviatoric is decided by round-off there, and
    # two compilations of the same arithmetic (numba's LLVM against numpy) differ by up to
    # 1.3e-11 of the stress (measured: at 42 and 41 of the apex points with dilatancy 0 and 20;
    # none with a cut-off). Both must sit on the apex and agree to 1e-10 there; elsewhere the
    # return is well conditioned and must agree to 1e-13.
    P = -(oracle.tau_r + 2.0 * oracle.tau_t) / 3.0
    J = np.exp(eps_r + 2.0 * eps_t)
    strength = np.abs(material.lam * P + material.tau * J)
    apex = oracle.plastic & (strength <= 1e-9 * stress)
    P_kernel = -(kernel["tau_r"] + 2.0 * kernel["tau_t"]) / 3.0
    assert np.all(np.abs(material.lam * P_kernel + material.tau * J)[apex]
                  <= 1e-9 * stress[apex])
    tolerance = np.where(apex, 1e-10, 1e-13)
    for name, scale in (("tau_r", stress), ("tau_t", stress)):
        assert np.all(np.abs(kernel[name] - getattr(oracle, name)) <= tolerance * scale)
    for name in ("theta_p", "gamma_p"):
        scale = strain + np.abs(getattr(oracle, name))
        assert np.all(np.abs(kernel[name] - getattr(oracle, name)) <= tolerance * scale)
    # the yield ratio c |Q| / strength is 0/0 on the apex; elsewhere the stresses' 1e-13
    # carried through the quotient
    ratio = oracle.yield_ratio
    with np.errstate(divide="ignore"):
        bound = 1e-13 * (1.0 + ratio) * (1.0 + 3.0 * stress / strength)
    assert np.all((np.abs(kernel["yield_ratio"] - ratio) <= bound)[~apex])
    for i, name in enumerate(("C_rr", "C_rt", "C_tr", "C_tt")):
        diff = np.abs(kernel[name] - oracle.tangent[i // 2, i % 2]) / (material.K + material.G)
        assert np.max(diff) <= 1e-11
    # the sample covers the elastic, Mohr-Coulomb (both signs of the deviator) and, with a
    # cut-off, the tension and corner returns
    plastic = oracle.plastic
    assert 0.2 < plastic.mean() < 0.8
    deviator = oracle.tau_t - oracle.tau_r
    assert np.sum(plastic & (deviator > 0)) > 1000 and np.sum(plastic & (deviator < 0)) > 1000
    if dilatancy == 0.0:  # volume changes plastically only through the tension cut-off
        assert np.sum(oracle.theta_p != theta_p) > 1000


def test_element_kernel_equals_the_scikit_fem_forms():
    numerics = Numerics(elements_per_decade=15.0)
    for degree in (1, 2):
        disc, _ = build_model(tuple(LAYERS), (0.03, 0.06), 0.0125,
                              Numerics(degree=degree, elements_per_decade=15.0))
        solver = RadialSolver(disc, dynamic=True, rho_inf=numerics.rho_inf, wall_velocity=600.0)
        seed = disc.R_dofs[0]
        for k in range(1, 31):  # 30 steps of 3 % growth: plastic zone across an interface
            advance(solver, seed * (1.03 ** k - 1.0), seed * 0.03 * 1.03 ** (k - 1) / 600.0)
        one = solver.case()
        rng = np.random.default_rng(3)
        u = one.u * (1.0 + 0.01 * rng.normal(size=one.u.size))  # a Newton iterate
        assembly, resp = solver.stack.assemble(u, one.state["theta_p"], one.state["gamma_p"])
        f, band, folded = assembly.f, assembly.band, assembly.folded
        f_ref, band_ref, resp_ref = assemble_forms(disc, u, one.state["theta_p"],
                                                   one.state["gamma_p"])
        assert not folded[0] and resp_ref.plastic.any() and not resp_ref.plastic.all()
        assert np.array_equal(resp.plastic, resp_ref.plastic)
        assert np.max(np.abs(f - f_ref)) <= 1e-12 * np.max(np.abs(f_ref))
        assert np.max(np.abs(band - band_ref)) <= 1e-12 * np.max(np.abs(band_ref))


def test_block_banded_solver_equals_lapack():
    """Random blocks of different sizes, some needing row interchanges (small diagonals), one
    singular: each block against ``scipy.linalg.solve_banded`` (LAPACK dgbsv). Measured
    agreement <= 1e-16 of the largest solution entry (0 in most blocks): bound 1e-12."""
    from scipy.linalg import solve_banded

    from cavex.fem.banded import solve_blocks

    rng = np.random.default_rng(11)
    for p in (1, 2):
        counts = np.array([1, 2, 5, 40, 7, 33])
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        n = counts.sum()
        band = rng.normal(size=(2 * p + 1, n))
        band[p, : counts[:3].sum()] *= 5.0      # dominant diagonals in the small blocks
        band[p, starts[3]:starts[3] + 40] *= 1e-3  # pivoting needed in block 3
        for s, m in zip(starts, counts, strict=True):  # no coupling entries
            for k in range(1, p + 1):
                band[p - k, s:s + min(k, m)] = 0.0
                band[p + k, s + m - min(k, m):s + m] = 0.0
        band[:, starts[5]:starts[5] + counts[5]][:, 4] = 0.0  # block 5: a zero column
        rhs = rng.normal(size=n)
        solve = np.array([True, True, True, True, False, True])
        du, singular = np.zeros(n), np.zeros(counts.size, dtype=bool)
        solve_blocks(band.copy(), rhs, p, starts, counts, solve, du, singular)
        assert singular.tolist() == [False] * 5 + [True]
        for c in range(4):
            s = slice(starts[c], starts[c] + counts[c])
            reference = solve_banded((p, p), band[:, s], rhs[s])
            assert np.max(np.abs(du[s] - reference)) <= 1e-12 * np.max(np.abs(reference))
        assert np.all(du[starts[4]:] == 0.0)
