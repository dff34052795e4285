"""The compiled point and element kernels against independent numpy/scikit-fem oracles.

Tolerances (measured on 800 000 random points, the sample of these tests):
stresses and plastic strains agree to the last bit on a CPU without AVX-512 (numpy's ``exp``
is then libm's); with AVX-512 numpy's SIMD ``exp`` differs from libm's by 1 ulp on a few
percent of inputs, which moves ``J`` and the stresses by <= 1e-15 of their scale: bound 1e-13.
The consistent tangent differs by up to 1.6e-12 of ``K + G`` (the corner's 2x2 product is
associated differently): bound 1e-11. Element force and tangent against the scikit-fem forms:
measured <= 1.1e-15 of the largest entry (P1 and P2): bound 1e-12.
"""

from dataclasses import replace

import numpy as np
import pytest
from fem_helpers import advance, point_material, return_map
from oracles import assemble_forms, hencky_mohr_coulomb

from cavex import load_config
from cavex.fem.expansion import build_model
from cavex.fem.settings import Numerics
from cavex.fem.solver import RadialSolver
from cavex.materials import Material

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


# ------------------------------------------------------------------ the compaction hydrostat
def hjc_concrete(fc, tensile_strength=None, lam=1.525):
    """A concrete of strength ``fc`` with HJC's hydrostat (Holmquist, Johnson and Cook 1993):
    crush at ``f_c/3``, locking at ``p_l = 0.8`` GPa, ``mu_l = 0.1``, ``K_l = 85`` GPa, the lock
    point in the FE's measures (``e_l = ln(1 + mu_l)``, Kirchhoff ``p_l/(1 + mu_l)``)."""
    E = 0.043 * 2300.0 ** 1.5 * np.sqrt(fc / 1e6) * 1e6
    return Material(E=E, nu=0.2, rho=2300.0, lam=lam, sigma_c=fc,
                    tensile_strength=tensile_strength, crush_pressure=fc / 3.0,
                    lock_pressure=0.8e9 / 1.1, lock_strain=np.log(1.1), locked_modulus=85e9)


COMPACTING = [hjc_concrete(20e6), hjc_concrete(48e6, tensile_strength=4e6),
              hjc_concrete(160e6, tensile_strength=6e6)]


def compaction_points(rng, n, material):
    """Volumetric strains from tension to past the locking strain, deviators from elastic to
    far past yield, plastic volumetric strains from opened (cut-off) to fully compacted
    (``material``: the points' records)."""
    e_lock = material.lock_strain
    theta = -rng.uniform(-0.2, 1.6, n) * e_lock
    spread = rng.choice([0.1, 1.0, 10.0, 100.0], n)
    gamma = rng.normal(0, 1, n) * material.tau / material.G * spread
    eps_r = (theta + 2.0 * gamma) / 3.0
    eps_t = (theta - gamma) / 3.0
    e_c_lock = e_lock - material.lock_pressure / material.K
    theta_p = -rng.uniform(-0.1, 1.3, n) * e_c_lock * rng.choice([0.0, 1.0], n, p=[0.3, 0.7])
    gamma_p = rng.normal(0, 1, n) * material.tau / material.G * rng.choice([0.0, 10.0], n)
    return eps_r, eps_t, theta_p, gamma_p


@pytest.mark.parametrize(("dilatancy", "cutoff"), [(0.0, None), (20.0, None), (0.0, 2e6)])
def test_point_kernel_with_compaction_equals_the_numpy_return_map(dilatancy, cutoff):
    """The kernel's hydrostat (the compaction return in the plastic volumetric strain) against
    the oracle's loading curve in the total strain (tests/oracles.py), then the same
    Mohr-Coulomb and cut-off returns. The two compute the compacted pressure by different
    arithmetic (``K x_tr - K dl`` against ``P_c + K_c (e - e_0)``), so their round-off is of the
    elastic trial pressure ``K |x_tr|`` (up to ~3 GPa here), which the returns can bring down to a
    much smaller stress: the stress scale includes it. Measured on this sample (with the apex
    points): stresses <= 4.9e-14, plastic strains <= 1.8e-14 of their scale, tangents
    <= 7.8e-15 of K + G: bounds 2e-13 (1e-10 at the apex, as above) and 1e-11."""
    rng = np.random.default_rng(17)
    n = 150_000
    material = point_material(COMPACTING, rng.integers(0, 3, n), dilatancy, cutoff)
    eps_r, eps_t, theta_p, gamma_p = compaction_points(rng, n, material)
    kernel = return_map(eps_r, eps_t, theta_p, gamma_p, material)
    oracle = hencky_mohr_coulomb(eps_r, eps_t, theta_p, gamma_p, material, groups=np.arange(n))
    assert np.array_equal(kernel["plastic"], oracle.plastic)
    theta = eps_r + 2.0 * eps_t
    stress = (np.abs(oracle.tau_r) + np.abs(oracle.tau_t) + material.tau
              + material.K * np.abs(theta - theta_p))
    strain = np.abs(eps_r) + np.abs(eps_t) + material.tau / material.K
    P = -(oracle.tau_r + 2.0 * oracle.tau_t) / 3.0
    J = np.exp(theta)
    apex = oracle.plastic & (np.abs(material.lam * P + material.tau * J) <= 1e-9 * stress)
    tolerance = np.where(apex, 1e-10, 2e-13)
    for name in ("tau_r", "tau_t"):
        assert np.all(np.abs(kernel[name] - getattr(oracle, name)) <= tolerance * stress)
    for name in ("theta_p", "gamma_p"):
        scale = strain + np.abs(getattr(oracle, name))
        assert np.all(np.abs(kernel[name] - getattr(oracle, name)) <= tolerance * scale)
    for i, name in enumerate(("C_rr", "C_rt", "C_tr", "C_tt")):
        diff = np.abs(kernel[name] - oracle.tangent[i // 2, i % 2]) / (material.K + material.G)
        assert np.max(diff) <= 1e-11
    # every branch of the hydrostat is sampled: elastic, the opened volume closing at the crush
    # pressure, compaction, compacted through the lock, fully compacted (elastic and locked)
    e = -(eps_r + 2.0 * eps_t)
    x_l = material.lock_pressure / material.K
    e_c_lock = material.lock_strain - x_l
    full = -theta_p >= e_c_lock
    compacted = oracle.theta_p != theta_p
    assert np.sum(compacted & (P < material.crush * (1 + 1e-9)) & (theta_p > 0)) > 100
    assert np.sum(compacted & (e < material.lock_strain) & (P > material.crush * 1.01)) > 1000
    assert np.sum(compacted & (e > material.lock_strain)) > 1000
    assert np.sum(full & (e + theta_p > x_l)) > 1000 and np.sum(full & (e + theta_p < x_l)) > 1000
    assert np.sum(~compacted & ~full & (P > 0)) > 1000


def exact_hydrostat(m, path):
    """The Kirchhoff pressure of the hydrostat along a path of log volumetric strains ``e``
    (compression positive), written from its definition: loading on ``H(e)``; unloading from
    the largest strain ``e_max`` elastic, ``H(e_max) - K (e_max - e)``; once past the lock,
    reversibly on the locked line down to ``x_l = P_l/K`` above the compaction left,
    ``e_l - x_l``, elastic below."""
    K, P_c, P_l, e_l, K_l = (m.bulk_modulus, m.crush_pressure, m.lock_pressure, m.lock_strain,
                             m.locked_modulus)
    e_0 = P_c / K

    def loading(e):
        if e <= e_0:
            return K * e
        if e <= e_l:
            return P_c + (P_l - P_c) * (e - e_0) / (e_l - e_0)
        return P_l + K_l * (e - e_l)

    pressures, e_max = [], 0.0
    for e in path:
        e_max = max(e_max, e)
        if e_max > e_l:
            left = e_l - P_l / K
            pressures.append(P_l + K_l * (e - e_l) if e > e_l else K * (e - left))
        else:
            pressures.append(loading(e_max) - K * (e_max - e))
    return np.array(pressures)


@pytest.mark.parametrize("uniaxial", [False, True])
def test_the_kernel_follows_the_exact_hydrostat_on_a_loading_path(uniaxial):
    """A point driven hydrostatically (``eps_r = eps_t``) or in uniaxial strain (``eps_t = 0``:
    the cavity's comminuted zone is near it) through crushing, unloading, reloading, locking and
    unloading from the lock: its pressure is the hydrostat's (:func:`exact_hydrostat`; dilatancy
    0, so the Mohr-Coulomb and cap returns leave it alone), and in uniaxial strain its deviator is
    the strength ``min(lam P + tau J, tau_max J)``. Measured: <= 2.6e-16 of the largest
    pressure, the deviator <= 1.8e-15 of the largest strength: bound 1e-13 (the kernel tests'
    bound for a different CPU's ``exp``)."""
    m = replace(hjc_concrete(48e6), tau_max=7.0 * 48e6)
    e_l = m.lock_strain
    path = e_l * np.concatenate([np.linspace(0.0, 0.5, 40), np.linspace(0.5, 0.42, 20),
                                 np.linspace(0.42, 1.6, 80), np.linspace(1.6, 0.65, 60)])
    material = point_material([m], [0])
    theta_p = gamma_p = 0.0
    pressure, deviator = [], []
    for e in path:
        eps_r, eps_t = (-e, 0.0) if uniaxial else (-e / 3.0, -e / 3.0)
        out = return_map(np.array([eps_r]), np.array([eps_t]), np.array([theta_p]),
                         np.array([gamma_p]), material)
        theta_p, gamma_p = out["theta_p"][0], out["gamma_p"][0]
        pressure.append(-(out["tau_r"][0] + 2.0 * out["tau_t"][0]) / 3.0)
        deviator.append(out["tau_t"][0] - out["tau_r"][0])
    pressure, deviator = np.array(pressure), np.array(deviator)
    exact = exact_hydrostat(m, path)
    assert np.max(np.abs(pressure - exact)) <= 1e-13 * np.max(exact)
    if uniaxial:
        J = np.exp(-path)
        strength = np.minimum(m.lam * pressure + m.tau * J, m.tau_max * J)
        # past the largest strain so far, beyond the elastic deviator: on the strength
        first = (path >= np.maximum.accumulate(path)) & (path > 0.0)
        yielded = first & (2.0 * m.shear_modulus * path > strength)
        assert yielded.sum() > 80 and np.any(strength[yielded] == m.tau_max * J[yielded])
        assert np.max(np.abs(deviator[yielded] - strength[yielded])) <= 1e-13 * np.max(strength)
        assert np.all(deviator <= strength * (1.0 + 1e-13))
    else:
        assert np.all(deviator == 0.0)
    # the path crushed, unloaded from compaction, locked and unloaded below the lock
    assert np.max(path) > e_l and 0.0 < exact[-1] < 0.5 * m.lock_pressure
    assert np.min(np.diff(exact)) < 0.0
