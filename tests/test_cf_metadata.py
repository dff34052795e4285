"""CF metadata of every netCDF file cavex writes: FE tables and batch sweeps (the report's grid.nc
is checked in test_report.py on the quick report). No FE run: the tables are filled from the
closed form and the sweep from synthetic case results."""

import numpy as np
import pytest
import xarray as xr
from cf_check import ALLOWED_UNITS, check_cf, check_quantify

from cavex.analytic.penetration.tabulated import load_table
from cavex.config import load_config
from cavex.verification.fedata.batch import (
    _dataset,
    _description,
    parse_sweep,
    sweep_cases,
    write_sweep,
)
from cavex.verification.fedata.table import analytic_table, write_table
from cavex.verification.output.cf_metadata import UNITS, decode_flags, flag_attrs, flag_word


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    target, projectile = load_config()
    ds = analytic_table(target, projectile, [0.0, 500.0, 1000.0], [0.1, 0.5, 1.3])
    path = write_table(ds, tmp_path_factory.mktemp("table") / "table.nc")
    return load_table(path)


def test_table_is_cf(table):
    check_cf(table, coded=("failed", "failed_first_layer", "wall_layer"))
    assert table["velocity"].attrs == {"units": "m s-1", "long_name": "cavity expansion velocity V"}
    assert table["depth"].attrs == {"units": "m", "long_name": "nose-tip depth L"}
    assert table["wall_layer"].attrs["flag_meanings"] == "concrete macadam soil"
    np.testing.assert_array_equal(table["wall_layer"].attrs["flag_values"], [0, 1, 2])
    assert table["failed"].dtype == bool  # decoded back from int8


def test_table_quantifies_with_pint(table):
    quantified = check_quantify(table)
    assert str(quantified["plastic_radius"].pint.units) == "meter"


SWEEP = {"grid": {"velocities": [300.0, 800.0], "depths": [0.3]},
         "numerics": {"dynamic": [True, False], "outer": ["fixed", "free"],
                      "dilatancy_deg": [0.0, 5.0]},
         "materials": [{"layer": "soil", "rho": [1500.0, 1600.0]}]}


def _result(case):
    both = {"dynamic": 1e8, "quasi-static": 1.1e8}
    return {"id": case["id"], "status": "ok", "fe_sigma_r_Pa": 1e8, "S": 4.0,
            "error_estimate": None, "analytic_sigma_r_Pa": both,
            "relative_difference": {"dynamic": 0.0, "quasi-static": -0.09},
            "fe_plastic_radius_m": 0.1, "analytic_plastic_radius_m": {"dynamic": 0.1,
                                                                      "quasi-static": 0.11},
            "wall_time_s": 1.0}


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    """A sweep Dataset with every kind of axis (number, boolean, text; a material) and one
    missing case, written and read back as ``cavex batch`` writes it."""
    parsed = parse_sweep(SWEEP)
    cases = sweep_cases(parsed)
    results = {case["id"]: _result(case) for case in cases[:-1]}
    ds = _dataset(_description(parsed, cases), results)
    path = tmp_path_factory.mktemp("sweep") / "results.nc"
    write_sweep(ds, path)
    loaded = xr.load_dataset(path, engine="scipy")
    assert loaded.identical(ds)
    return loaded


def test_sweep_is_cf(sweep):
    check_cf(sweep, coded=("failed", "dynamic"))
    assert sweep["velocity"].attrs["units"] == "m s-1"  # the same spelling as the tables
    assert sweep["soil_rho"].attrs["units"] == "kg m-3"
    assert sweep["dilatancy_deg"].attrs["units"] == "degree"
    assert sweep["wall_time"].attrs["units"] == "s"
    assert sweep["outer"].attrs == {"long_name": "FE setting outer"}  # text: no units
    assert sweep["dynamic"].attrs["flag_meanings"] == "false true"
    assert sweep["failed"].attrs["flag_meanings"] == "ok failed_or_missing"
    assert int(sweep["failed"].sum()) == 1 and sweep.attrs["missing_cases"] == 1


def test_sweep_quantifies_with_pint(sweep):
    quantified = check_quantify(sweep)
    assert str(quantified["fe_plastic_radius"].pint.units) == "meter"


def test_one_unit_spelling():
    assert set(UNITS.values()) == ALLOWED_UNITS
    assert UNITS["velocity"] == "m s-1"


def test_flags_round_trip():
    attrs = flag_attrs([0, 1, 2], ["a", "c+island", "the layer 2"], "state")
    assert attrs["flag_meanings"] == "a c+island the_layer_2"
    assert attrs["flag_values"].dtype == np.int8 and attrs["units"] == "1"
    variable = xr.DataArray(np.array([[2, 0], [1, 1]], dtype=np.int8), dims=("x", "y"),
                            attrs=attrs)
    np.testing.assert_array_equal(decode_flags(variable),
                                  [["the_layer_2", "a"], ["c+island", "c+island"]])
    assert flag_word("  ") == "unnamed"
    with pytest.raises(ValueError, match="distinct"):
        flag_attrs([0, 1], ["x y", "x_y"], "clash")
