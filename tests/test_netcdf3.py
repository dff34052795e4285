"""The netCDF-3 format without xarray (cavex.netcdf3): a written file reads back, through
xarray, as the dataset it was given and as the file xarray's own scipy engine writes for it;
the reader reads files as xarray does; ``write_table`` writes a PlainDataset and its Dataset
alike, atomically."""

import numpy as np
import pytest
import xarray as xr

from cavex.analytic.penetration.tabulated import read_table
from cavex.config import load_config
from cavex.netcdf3 import PlainDataset, read_netcdf3, write_netcdf3
from cavex.verification.fedata.table import analytic_table, write_table

#: every kind of variable the tables hold: floats with NaN (64 and 32 bit), booleans, int32
#: with flag attributes, a text dimension name, numeric and text global attributes
VARIABLES = {
    "sigma_r": (("velocity", "depth"), np.array([[1.5e8, np.nan, 2.0e8], [3.0, 4.0, -5.0]]),
                {"units": "Pa", "long_name": "stress"}),
    "ratio": (("velocity", "depth"), np.array([[0.5, 1.0, np.nan], [2.0, 3.0, 4.0]],
                                              dtype=np.float32), {"units": "1"}),
    "failed": (("velocity", "depth"), np.array([[True, False, False], [False, True, False]]),
               {"long_name": "failed", "flag_values": np.array([0, 1], dtype=np.int8),
                "flag_meanings": "ok failed"}),
    "wall_layer": ("depth", np.array([0, 1, 2], dtype=np.int32),
                   {"flag_values": np.array([0, 1, 2], dtype=np.int32),
                    "flag_meanings": "concrete macadam soil"}),
    "velocity": ("velocity", np.array([0.0, 600.0]), {"units": "m s-1"}),
    "depth": ("depth", np.array([0.1, 0.5, 1.3]), {"units": "m"}),
}
ATTRS = {"Conventions": "CF-1.10", "title": "a test", "cases": 6, "scale": 0.25}


def _dataset():
    coords = ("velocity", "depth")
    return xr.Dataset({k: v for k, v in VARIABLES.items() if k not in coords},
                      coords={k: VARIABLES[k] for k in coords}, attrs=ATTRS)


def _read(path):
    with xr.open_dataset(path, engine="scipy") as ds:
        return ds.load()


def test_reads_back_as_the_dataset_and_as_xarrays_own_file(tmp_path):
    ours = write_netcdf3(tmp_path / "ours.nc", VARIABLES, ATTRS)
    _dataset().to_netcdf(tmp_path / "xarray.nc", engine="scipy")
    back = _read(ours)
    xr.testing.assert_identical(back, _read(tmp_path / "xarray.nc"))
    xr.testing.assert_identical(back, _dataset())
    assert back["failed"].dtype == bool and back["wall_layer"].dtype == np.int32
    assert back["ratio"].dtype == np.float32 and np.isnan(back["ratio"].values[0, 2])
    np.testing.assert_array_equal(back["wall_layer"].attrs["flag_values"], [0, 1, 2])


def test_reads_as_xarray_reads(tmp_path):
    """:func:`read_netcdf3` gives what ``xr.load_dataset`` gives: the same variables,
    dtypes, attributes and their types (a file of ours and one of xarray's)."""
    ours = write_netcdf3(tmp_path / "ours.nc", VARIABLES, ATTRS)
    _dataset().to_netcdf(tmp_path / "xarray.nc", engine="scipy")
    for path in (ours, tmp_path / "xarray.nc"):
        expected = xr.load_dataset(path, engine="scipy")
        read = read_netcdf3(path)
        got = read.dataset()
        xr.testing.assert_identical(got, expected)
        assert sorted(read.order) == sorted(expected.variables)
        assert set(read.coords) == {"velocity", "depth"}
        for name, variable in expected.variables.items():
            assert got[name].dtype == variable.dtype, name
            assert {k: type(v) for k, v in got[name].attrs.items()} == {
                k: type(v) for k, v in variable.attrs.items()}, name
        assert {k: type(v) for k, v in got.attrs.items()} == {
            k: type(v) for k, v in expected.attrs.items()}


def test_refuses_what_it_cannot_encode(tmp_path):
    with pytest.raises(TypeError, match="no encoding for <U"):
        write_netcdf3(tmp_path / "x.nc", {"name": ("n", np.array(["a", "b"]), {})}, {})


def test_a_failed_write_leaves_no_file(tmp_path):
    """An error after the temporary file was opened (values that do not fit their
    dimension, which an earlier variable defined) leaves neither the table nor the temporary
    file."""
    target, projectile = load_config()
    table = PlainDataset.from_dataset(analytic_table(target, projectile, [0.0, 700.0],
                                                     [0.1, 0.9]))
    bad = PlainDataset({**table.data, "extra": ("depth", np.zeros(7), {})}, table.coords,
                       table.attrs)
    with pytest.raises(ValueError, match="broadcast"):
        write_table(bad, tmp_path / "t.nc")
    assert list(tmp_path.iterdir()) == []


def test_write_table_writes_a_table_as_its_dataset(tmp_path):
    """The PlainDataset (what ``cavex table`` writes, without xarray) and its Dataset (what
    the other commands write) give files that read back identical, rounded alike; the table
    reader (``read_table``, no xarray) reads them as ``load_table`` does."""
    target, projectile = load_config()
    ds = analytic_table(target, projectile, [0.0, 700.0], [0.1, 0.9])
    table = PlainDataset.from_dataset(ds)
    xr.testing.assert_identical(table.dataset(), ds)
    from_table = _read(write_table(table, tmp_path / "table.nc"))
    from_dataset = _read(write_table(ds, tmp_path / "dataset.nc"))
    xr.testing.assert_identical(from_table, from_dataset)
    assert "created" in ds.attrs and "created" not in from_table.attrs
    # rounded to the written digits: 6 significant for the stress (number_format)
    assert not np.array_equal(from_table["sigma_r"], ds["sigma_r"])
    np.testing.assert_allclose(from_table["sigma_r"], ds["sigma_r"], rtol=5e-6)
    read = read_table(tmp_path / "table.nc")
    assert read.attrs.pop("source") == str(tmp_path / "table.nc")
    xr.testing.assert_identical(read.dataset(), from_table)
