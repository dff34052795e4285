"""The FE table's interpolation-error estimate (issue 30, item 4): the table with every other
node in V and in L (:mod:`cavex.analytic.penetration.table_error`), checked against real
refinements, in ``cavex penetrate --resistance table`` and in the quick verification report.

The numbers quoted are measured by ``benchmarks/table_refinement.py`` (docs/verification.md,
"Interpolation error")."""

import json
from pathlib import Path

import numpy as np
import pytest

from cavex.analytic.geometry import switch_depths
from cavex.analytic.penetration.integrator import penetrate
from cavex.analytic.penetration.resistance import ClosedFormResistance
from cavex.analytic.penetration.table_error import (
    coarsened,
    flown,
    interpolation_error,
    kept_depths,
    kept_velocities,
)
from cavex.analytic.penetration.tabulated import NODE_TOLERANCE, read_table
from cavex.config import default_config_text, load_config
from cavex.verification.cli import main
from cavex.verification.fedata.table import analytic_table

ROOT = Path(__file__).resolve().parents[1]
COMMITTED = ROOT / "results" / "verification" / "grid.nc"  # the default report's FE table
VELOCITIES = np.linspace(0.0, 1200.0, 13)


@pytest.fixture(scope="module")
def runway():
    return load_config()


@pytest.fixture(scope="module")
def committed():
    return read_table(COMMITTED)


def test_every_other_node_keeps_the_ends_and_the_switch_nodes(runway, committed):
    target, projectile = runway
    assert kept_velocities(np.arange(11)) == [0, 2, 4, 6, 8, 10]
    assert kept_velocities(np.arange(4)) == [0, 2, 3]
    depths = np.asarray(committed["depth"])
    kept = depths[kept_depths(depths, target, projectile)]
    assert kept[0] == depths[0] and kept[-1] == depths[-1]
    for s in switch_depths(target, projectile):
        assert np.any(np.abs(kept - s) <= NODE_TOLERANCE)
    assert 0.5 * depths.size <= kept.size < 0.6 * depths.size  # every other on each segment


def test_coarsened_table_is_the_table_on_the_coarser_grid(runway):
    """A cell depends on its own (V, L) only: the coarsened table equals the table built on
    the kept nodes (here the closed-form table, built cell by cell as the FE one)."""
    target, projectile = runway
    fine = analytic_table(target, projectile, VELOCITIES, np.linspace(0.1, 1.3, 31))
    for axis in ("velocity", "depth"):
        coarse = coarsened(fine, axis, target, projectile)
        built = analytic_table(target, projectile, coarse["velocity"], coarse["depth"],
                               refine=())
        for name in ("velocity", "depth", "sigma_r", "sigma_r_first_layer", "wall_layer"):
            np.testing.assert_allclose(coarse[name], np.asarray(built[name]), rtol=1e-12)


@pytest.mark.parametrize("boundary", ["quasi-static", "dynamic"])
def test_estimate_bounds_the_error_against_the_closed_form(runway, boundary):
    """A table of a closed form (13 velocities x 31 depths + switch depths), flown, against
    the closed form flown. Measured: quasi-static error 1.05e-4 m, estimate 1.79e-3 m; dynamic
    5.2e-3 m, estimate 9.7e-2 m. The quasi-static ``sigma_r`` is affine in V^2, which PCHIP in
    V^2 reproduces: its velocity part is 9.6e-6 m, 0.54 % of its depth part (asserted below
    5 %); the dynamic one bends at low V: its velocity part is 0.096 m."""
    target, projectile = runway
    table = analytic_table(target, projectile, VELOCITIES, np.linspace(0.1, 1.3, 31),
                           boundary=boundary)
    exact = penetrate(target, projectile, ClosedFormResistance(target, projectile,
                                                               boundary=boundary))
    estimate = interpolation_error(target, projectile, table)
    error = abs(estimate["final_depth_m"] - float(exact.depth[-1]))
    assert error <= estimate["estimate_m"]
    if boundary == "quasi-static":
        assert (abs(estimate["velocity"]["difference_m"])
                < 0.05 * abs(estimate["depth"]["difference_m"]))


def test_estimate_brackets_the_fe_refinement(runway, committed):
    """The default report's FE table coarsened once in each axis: its estimate (coarsened once
    more) against its real error (the committed table itself). Measured: in V 0.214 m against
    0.0087 m, in L 0.0109 m against 0.0009 m (benchmarks/table_refinement.py, where FE cells at
    the midpoints give the same ordering one level finer)."""
    target, projectile = runway
    finest = flown(target, projectile, committed)["final_depth_m"]
    for axis in ("velocity", "depth"):
        coarse = coarsened(committed, axis, target, projectile)
        estimate = interpolation_error(target, projectile, coarse)
        real = abs(estimate["final_depth_m"] - finest)
        assert real <= abs(estimate[axis]["difference_m"]), axis


def test_penetrate_reports_the_estimate(tmp_path, capsys):
    """``cavex penetrate --resistance table``: the estimate as a new key, every other key as
    with a closed form (the default report's table: 0.0096 m)."""
    table = read_table(COMMITTED)
    assert main(["penetrate", "--resistance", "table", "--table", str(COMMITTED), "--out",
                 str(tmp_path / "t"), "--no-figures", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert main(["penetrate", "--out", str(tmp_path / "d"), "--no-figures", "--json"]) == 0
    closed = json.loads(capsys.readouterr().out)
    assert set(document) == set(closed) | {"interpolation_error_estimate_m",
                                           "interpolation_error", "table"} - {"law"}
    parts = document["interpolation_error"]
    assert document["interpolation_error_estimate_m"] == pytest.approx(
        abs(parts["velocity"]["difference_m"]) + abs(parts["depth"]["difference_m"]), rel=1e-12)
    target, projectile = load_config()
    direct = interpolation_error(target, projectile, table)
    assert document["interpolation_error_estimate_m"] == pytest.approx(direct["estimate_m"],
                                                                       rel=1e-9)
    assert main(["penetrate", "--resistance", "table", "--table", str(COMMITTED), "--out",
                 str(tmp_path / "t"), "--no-figures"]) == 0
    assert "FE-table interpolation error of the final depth: estimate" in capsys.readouterr().out


def test_quick_report_names_its_reference_and_brackets_the_default_grid(tmp_path, runway,
                                                                        committed):
    """``verify(quick=True)`` on the default target: the conclusions open with the warning and
    the estimate (report.md, the summary and grid.nc), and the estimate brackets the quick
    shot's real difference to the default grid's (the committed report's table). Measured:
    3.2587 m against 3.2232 m (0.036 m), estimate 0.366 m; before issue 30 the quick grid
    (3 velocities) stopped at 3.7124 m."""
    from cavex.verification.report import build as report

    target, projectile = runway
    summary = report.verify(target, projectile, quick=True, out_dir=tmp_path, workers=2,
                            config_text=default_config_text(), draw=False)  # text only
    line = summary["conclusions"][0]
    assert line.startswith("**Quick report**")
    assert "the full `cavex verify` is the reference" in line
    estimate = summary["table_interpolation_error"]
    assert f"{estimate['estimate_m']:.4f} m" in line
    assert line in (tmp_path / "report.md").read_text(encoding="utf-8")
    assert json.loads(read_table(tmp_path / "grid.nc").attrs["conclusions"])[0] == line
    default = flown(target, projectile, committed)["final_depth_m"]
    assert abs(estimate["final_depth_m"] - default) <= estimate["estimate_m"]
