"""FE-tabulated resistance: table files, refusals, interpolation error and the integrator.

Numbers asserted here are measured (docs/verification.md, "FE-tabulated resistance"). The
synthetic tables are filled from the derived quasi-static closed form, so that
``TabulatedResistance`` can be checked against ``ClosedFormResistance`` exactly; the FE tables
use coarse numerics (accuracy is not the point there, except in the interpolation study).
"""

import json
import tomllib
from dataclasses import replace

import numpy as np
import pytest
import xarray as xr
from scipy.interpolate import PchipInterpolator

from cavex.analytic.cavity import cavity_solution, cavity_stress
from cavex.analytic.geometry import spherical_problem, switch_depths
from cavex.analytic.models.comparison import compare_trajectories
from cavex.analytic.penetration.integrator import penetrate
from cavex.analytic.penetration.resistance import ClosedFormResistance
from cavex.analytic.penetration.tabulated import (
    TabulatedResistance,
    load_table,
    pchip,
    trajectory_summary,
)
from cavex.config import load_config, parse_config
from cavex.errors import CavexInputError
from cavex.materials import Target
from cavex.verification.fedata.cases import fe_cases
from cavex.verification.fedata.runner import read_store, run_cases
from cavex.verification.fedata.table import (
    DEFAULT_DEPTHS,
    DEFAULT_VELOCITIES,
    analytic_table,
    build_table,
    table_cases,
    write_table,
)
from cavex.verification.output.number_format import round_dataset

COARSE = {"elements_per_decade": 10, "growth_per_step": 0.1, "outer_ratio": 200,
          "seed_ratio": 5}
VELOCITIES = np.linspace(0.0, 1200.0, 13)


@pytest.fixture(scope="module")
def runway():
    return load_config()


@pytest.fixture(scope="module")
def synthetic(runway):
    """Quasi-static closed-form table on the default grid (13 x 31 depths + switch nodes)."""
    return analytic_table(*runway, DEFAULT_VELOCITIES, DEFAULT_DEPTHS, boundary="quasi-static")


@pytest.fixture(scope="module")
def fe_store(tmp_path_factory):
    """The runner's case store of ``fe_table`` (to compare the table with the case results)."""
    return tmp_path_factory.mktemp("fe_store")


@pytest.fixture(scope="module")
def fe_table(runway, fe_store):
    """A real FE table, 4 velocities x 4 depths + the 2 switch nodes, coarse numerics."""
    return build_table(*runway, [0.0, 400.0, 800.0, 1200.0], [0.1, 0.4, 0.8, 1.2],
                       numerics=COARSE, workers=2, progress=False, refine=(), store=fe_store)


def test_lean_pchip_is_scipys():
    rng = np.random.default_rng(0)
    for n in (2, 3, 5, 13):
        x = np.unique(rng.uniform(0.0, 10.0, n))
        xq = np.linspace(x[0], x[-1], 101)
        for y in (rng.normal(size=x.size), np.cumsum(rng.uniform(0, 1, x.size)), 2 * x + 1):
            np.testing.assert_allclose(pchip(x, y, xq), PchipInterpolator(x, y)(xq),
                                       rtol=0, atol=1e-13 * np.abs(y).max())


def test_netcdf_round_trip_is_exact_with_attributes(synthetic, runway, tmp_path):
    """The file holds the rounded Dataset (number_format.round_dataset) exactly, without the
    creation time; ``reproducible=False`` writes the Dataset itself."""
    path = write_table(synthetic, tmp_path / "sub" / "table.nc")
    assert not list(path.parent.glob("*.tmp"))
    loaded = load_table(path)
    assert loaded.attrs.pop("source") == str(path)
    rounded = round_dataset(synthetic)
    rounded.attrs.pop("created")
    xr.testing.assert_identical(loaded, rounded)
    for name in ("sigma_r", "S", "error_estimate", "plastic_radius", "sigma_r_first_layer"):
        assert np.array_equal(loaded[name].values, rounded[name].values, equal_nan=True)
    exact = load_table(write_table(synthetic, tmp_path / "exact.nc", reproducible=False))
    exact.attrs.pop("source")
    xr.testing.assert_identical(exact, synthetic)
    assert loaded["failed"].dtype == bool and loaded["wall_layer"].dtype == np.int32
    for name in [*loaded.data_vars, *loaded.coords]:
        assert loaded[name].attrs["units"], name
    assert loaded["velocity"].attrs["units"] == "m s-1" and loaded["depth"].attrs["units"] == "m"
    assert loaded.attrs["Conventions"] == "CF-1.10"
    assert loaded["failed"].attrs["flag_meanings"] == "ok failed"
    assert loaded["sigma_r"].attrs["units"] == "Pa"
    for key in ("target", "fingerprint", "solver_settings", "versions"):
        assert loaded.attrs[key], key
    assert set(json.loads(loaded.attrs["versions"])) == {"cavex", "numpy", "scipy",
                                                         "scikit-fem", "xarray"}
    assert len(loaded.attrs["fingerprint"]) == 64
    assert parse_config(tomllib.loads(loaded.attrs["target"])) == runway


def test_grid_has_switch_nodes_and_refinement(synthetic, runway):
    target, projectile = runway
    depths = synthetic["depth"].values
    assert synthetic.sizes == {"velocity": 13, "depth": 31 + 2 * 6}
    for s in switch_depths(target, projectile):
        assert np.any(np.abs(depths - s) < 1e-8)
        assert np.any(np.abs(depths - (s - projectile.r / 8)) < 1e-12)
    assert list(np.unique(synthetic["wall_layer"].values)) == [0, 1, 2]


def test_refuses_a_table_for_another_target(synthetic, runway, tmp_path):
    target, projectile = runway
    layers = list(target.layers)
    layers[1] = replace(layers[1], E=11e9)
    other = Target(layers, target.thicknesses)
    path = write_table(synthetic, tmp_path / "t.nc")
    with pytest.raises(CavexInputError) as info:
        TabulatedResistance(load_table(path), other, projectile)
    message = str(info.value)
    assert "\n" not in message and str(path) in message
    assert "layers[1].E: table 10000000000.0, given 11000000000.0" in message
    with pytest.raises(CavexInputError, match=r"projectile.r: table 0.0125, given 0.013"):
        TabulatedResistance(synthetic, target, replace(projectile, r=0.013))
    # mass and striking velocity do not enter sigma_r(V, L): the table stays valid
    TabulatedResistance(synthetic, target, replace(projectile, m=1.0, V0=800.0))


def test_refuses_use_outside_its_range(synthetic, runway):
    target, projectile = runway
    resistance = TabulatedResistance(synthetic, target, projectile)
    assert resistance.max_velocity == pytest.approx(2209.77, abs=0.01)
    resistance.force(0.3, 2209.0)
    with pytest.raises(CavexInputError, match=r"velocity V = 2300 m/s is outside the table's "
                                              r"range \[0, 2209.77\] m/s \(the nose sees up "
                                              r"to V cos\(phi\) = 0.5430 V; table velocities "
                                              r"reach 1200 m/s"):
        resistance.force(0.3, 2300.0)
    with pytest.raises(CavexInputError, match=r"velocity V = 1300 m/s is outside the table's "
                                              r"range \[0, 1200\] m/s"):
        resistance.wall_stress(0.3, [1300.0])
    with pytest.raises(CavexInputError, match=r"nose depth L = 0.05 m is outside the table's "
                                              r"depth range \[0.1, inf\] m"):
        resistance.force(0.05, 100.0)
    shallow = synthetic.sel(depth=slice(None, 0.9))
    with pytest.raises(CavexInputError) as info:
        penetrate(target, projectile, TabulatedResistance(shallow, target, projectile))
    assert "outside the table's depth range [0.1, 0.9] m" in str(info.value)
    assert "\n" not in str(info.value)
    fast = replace(projectile, V0=2500.0)
    with pytest.raises(CavexInputError, match=r"velocity V = 2500 m/s"):
        penetrate(target, fast, TabulatedResistance(synthetic, target, fast))


def test_refuses_tables_it_cannot_interpolate(synthetic, runway):
    with pytest.raises(CavexInputError, match=r"velocities must increase from V = 0"):
        TabulatedResistance(synthetic.isel(velocity=slice(1, None)), *runway)
    with pytest.raises(CavexInputError, match=r"lacks the wall-layer switch depth\(s\) 0.6975"):
        node = int(np.argmin(np.abs(synthetic["depth"].values - 0.6975)))
        TabulatedResistance(synthetic.drop_isel(depth=[node]), *runway)
    broken = synthetic.copy(deep=True)
    broken["failed"][2, 3] = True
    broken["sigma_r"][2, 3] = np.nan
    with pytest.raises(CavexInputError, match=r"has 1 failed FE cell"):
        TabulatedResistance(broken, *runway)
    with pytest.raises(CavexInputError, match=r"includes V = 0"):
        analytic_table(*runway, [100.0, 200.0], [0.1, 0.2])


def test_force_reproduces_the_closed_form(synthetic, runway):
    """Exact at the depth nodes (PCHIP in V^2 reproduces sigma_r affine in V^2); between them
    the PCHIP-in-L error, measured on 600 random points: median 3.6e-5, max 1.4e-2 (at the kink
    where the plastic zone leaves the macadam, L = 1.128 m)."""
    target, projectile = runway
    closed = ClosedFormResistance(target, projectile, boundary="quasi-static")
    table = TabulatedResistance(synthetic, target, projectile)
    for depth in synthetic["depth"].values[::5]:
        for v in (0.0, 137.0, 650.0, 1200.0):
            assert table.force(depth, v) == pytest.approx(closed.force(depth, v), rel=1e-12)
    for v in (0.0, 333.0, 1000.0):
        assert table.crater_force(v) == pytest.approx(closed.crater_force(v), rel=1e-12)
        assert table.force(3.0, v) == pytest.approx(closed.force(3.0, v), rel=1e-12)
    rng = np.random.default_rng(1)
    depths = np.concatenate([rng.uniform(0.1, 1.3, 400), rng.uniform(0.64, 0.6975, 100),
                             rng.uniform(1.09, 1.1475, 100)])
    velocities = rng.uniform(0.0, 1200.0, depths.size)
    error = np.array([table.force(L, v) / closed.force(L, v) - 1.0
                      for L, v in zip(depths, velocities, strict=True)])
    assert np.median(np.abs(error)) < 1e-4
    assert np.abs(error).max() < 2e-2


def test_labels_change_at_the_wall_layer_switches(synthetic, runway):
    table = TabulatedResistance(synthetic, *runway)
    assert table.label(0.5, 300.0) == "concrete (table)"
    assert table.label(0.70, 300.0) == "macadam (table)"
    assert table.label(2.0, 300.0) == "soil (table)"


def _trajectory_errors(runway, reference, n, method):
    target, projectile = runway
    table = analytic_table(target, projectile, VELOCITIES, np.linspace(0.1, 1.3, n),
                           boundary="quasi-static")
    run = trajectory_summary(penetrate(target, projectile, TabulatedResistance(
        table, target, projectile, depth_method=method)), target)
    return (run["final_depth_m"] - reference["final_depth_m"],
            run["at_H1"]["velocity_m_s"] - reference["at_H1"]["velocity_m_s"])


def test_trajectory_converges_with_the_table_spacing(runway):
    """Refining the depth grid (spacing 0.08, 0.04, 0.02 m): linear-in-L errors fall at the
    fitted rate ~2 (measured final depth 6.8e-3, 1.6e-3, 3.0e-4 m; V at H1 0.38, 0.11, 0.033
    m/s); PCHIP errors are 5-25 times smaller at every level (1.4e-3, 1.1e-4, 4.2e-5 m;
    0.046, 0.0042, 0.0045 m/s) and no longer asymptotic (kinks of sigma_r(L) dominate). On the
    default grid (0.04 m) the table's trajectory matches the closed form's (3.0916 m stop,
    636.17 m/s at H1) within 2e-4 m and 1e-2 m/s."""
    target, projectile = runway
    reference = trajectory_summary(
        penetrate(target, projectile, ClosedFormResistance(target, projectile,
                                                           boundary="quasi-static")), target)
    assert reference["final_depth_m"] == pytest.approx(3.0916, abs=1e-4)
    counts = np.array([16, 31, 61])
    spacing = 1.2 / (counts - 1)
    linear = np.abs([_trajectory_errors(runway, reference, n, "linear") for n in counts])
    smooth = np.abs([_trajectory_errors(runway, reference, n, "pchip") for n in counts])
    for column in range(2):
        rate = np.polyfit(np.log(spacing), np.log(linear[:, column]), 1)[0]
        assert 1.7 < rate < 2.6, rate
        assert np.all(smooth[:, column] < 0.3 * linear[:, column])
    assert smooth[1, 0] < 2e-4 and smooth[1, 1] < 1e-2


def test_fe_interpolation_error_against_extra_fe_points(runway):
    """Interpolated FE sigma_r against FE runs between the nodes (coarse numerics): V grid 300
    m/s (at L = 0.3 m), L grid 0.1 m (at V = 600 m/s). Measured: max 2.1 % (V = 450 m/s, the FE
    scatter of the coarse compressible runs; their estimated error is 0.4 %), median 0.2 %.
    The same grid interpolating the smooth dynamic closed form errs by <= 1.3e-4 in V and
    <= 2.4e-3 in L: the interpolation is far below the FE scatter."""
    target, projectile = runway
    velocities, depths = [0.0, 300.0, 600.0, 900.0, 1200.0], [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    table = build_table(target, projectile, velocities, depths, numerics=COARSE, workers=2,
                        progress=False)
    points = [(v, 0.3) for v in (150.0, 450.0, 750.0, 1050.0)]
    points += [(600.0, L) for L in (0.15, 0.25, 0.35, 0.45, 0.55)]
    cases = [c for v, L in points for c in table_cases(target, projectile, [v], [L], None,
                                                       COARSE)]
    results = run_cases(fe_cases, cases, workers=2, progress=False)
    assert all(r["status"] == "ok" for r in results)
    fe_resistance = TabulatedResistance(table, target, projectile)
    dynamic = TabulatedResistance(analytic_table(target, projectile, velocities, depths,
                                                 boundary="dynamic"), target, projectile)
    fe_error, closed_error = [], []
    for (v, L), result in zip(points, results, strict=True):
        fe_error.append(fe_resistance.wall_stress(L, [v])[0] / result["fe_sigma_r_Pa"] - 1.0)
        layers, interfaces = spherical_problem(target, projectile, L)
        exact = cavity_stress(layers, interfaces, v, projectile.r, boundary="dynamic")
        closed_error.append(dynamic.wall_stress(L, [v])[0] / exact - 1.0)
    fe_error, closed_error = np.abs(fe_error), np.abs(closed_error)
    assert fe_error.max() < 0.03 and np.median(fe_error) < 0.005
    assert closed_error[:4].max() < 3e-4 and closed_error.max() < 3e-3


def test_small_fe_table_builds_and_drives_the_integrator(fe_table, runway, tmp_path):
    target, projectile = runway
    assert fe_table.sizes == {"velocity": 4, "depth": 6}
    assert not fe_table["failed"].any() and not fe_table["failed_first_layer"].any()
    assert list(fe_table["wall_layer"].values) == [0, 0, 1, 1, 2, 2]
    concrete = fe_table.isel(depth=slice(0, 2), velocity=slice(1, None))
    ratio = concrete["sigma_r"] / concrete["sigma_r_dynamic"]
    assert np.all(np.abs(ratio - 1.0) < 0.08)
    assert np.all(fe_table["error_estimate"] < 0.1)
    settings = json.loads(fe_table.attrs["solver_settings"])
    assert settings["numerics"]["elements_per_decade"] == 10 and settings["nu"] is None
    path = write_table(fe_table, tmp_path / "fe.nc")
    from cavex.analytic.penetration.tabulated import penetrate_with_table

    trajectory = penetrate_with_table(target, projectile, path)
    assert trajectory.phases[-1].end_reason == "projectile stopped"
    assert [p.label for p in trajectory.phases[1:4]] == ["concrete (table)"] * 2 + [
        "macadam (table)"]
    summary = compare_trajectories(target, projectile, load_table(path))
    assert set(summary) == {"derived-quasi-static", "derived-dynamic", "paper", "table"}
    fe, dynamic = summary["table"]["at_H1"], summary["derived-dynamic"]["at_H1"]
    assert fe["velocity_m_s"] == pytest.approx(dynamic["velocity_m_s"], rel=0.1)


def test_table_plastic_radius_is_the_case_results(fe_table, fe_store, runway):
    """``plastic_radius`` of every cell is its case result's ``fe_plastic_radius_m`` (NaN where
    the cell failed); the first-layer cases are not in the grid."""
    b = fe_table["plastic_radius"]
    assert b.dims == ("velocity", "depth") and b.attrs["units"] == "m"
    entries = [e for e in read_store(fe_store).values()
               if not str(e["case"]["id"]).startswith("first-layer")]
    assert len(entries) == b.size
    for entry in entries:
        case, result = entry["case"], entry["result"]
        value = float(b.sel(velocity=case["velocity"], depth=case["depth"]))
        if result["status"] == "ok":
            assert value == result["fe_plastic_radius_m"]
        else:
            assert np.isnan(value)
    # no failed cell; b >= the cavity radius (b = a where the soil is elastic, FE to 0.1 %)
    assert np.all(b.values > 0.999 * runway[1].r)


def test_analytic_table_plastic_radius_is_the_closed_forms(synthetic, runway):
    target, projectile = runway
    for V in (0.0, 600.0, 1200.0):
        for L in synthetic.depth.values[::7]:
            layers, interfaces = spherical_problem(target, projectile, float(L))
            state = cavity_solution(layers, interfaces, V, projectile.r, boundary="quasi-static")
            assert float(synthetic["plastic_radius"].sel(velocity=V, depth=L)) == \
                state.plastic_radius
