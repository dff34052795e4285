"""A check of the CF metadata of a cavex netCDF file, shared by the table, sweep and report tests.

Every file: ``Conventions = "CF-1.10"``; every variable and coordinate has a ``long_name``;
every numeric one has ``units`` from a fixed set of UDUNITS spellings (text variables such as
a sweep's ``status`` and ``case_id`` have none: CF units belong to numbers); every integer or
boolean variable (stored as an integer) is coded with ``flag_values`` (same dtype as stored)
and ``flag_meanings`` (one word per value). Where ``pint-xarray`` and ``cf-xarray`` are
installed (not cavex dependencies), the dataset is quantified with cf-xarray's UDUNITS
registry, the route pint-xarray documents for CF files.
"""

import numpy as np
import pytest

# the only unit strings cavex writes (cavex.verification.output.cf_metadata.UNITS)
ALLOWED_UNITS = {"m s-1", "m", "Pa", "kg m-3", "s", "degree", "1"}
FLAG_WORD = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.+@-")


def check_cf(ds, coded=()):
    """Assert the CF metadata of ``ds``; ``coded`` names variables that must carry flags."""
    assert ds.attrs["Conventions"] == "CF-1.10"
    for name, variable in ds.variables.items():
        attrs = variable.attrs
        assert attrs.get("long_name"), f"{name}: no long_name"
        if variable.dtype.kind in "USO":
            assert "units" not in attrs, name
            continue
        assert attrs.get("units") in ALLOWED_UNITS, f"{name}: units {attrs.get('units')!r}"
        if variable.dtype.kind in "biu" or name in coded:
            values = np.atleast_1d(attrs["flag_values"])
            meanings = attrs["flag_meanings"].split()
            assert len(values) == len(meanings) == len(set(meanings)), name
            assert all(set(word) <= FLAG_WORD for word in meanings), name
            assert set(np.unique(np.asarray(variable.values, dtype=int))) <= set(
                values.tolist()), name
            assert values.dtype.kind == ("i" if variable.dtype.kind == "b"
                                         else variable.dtype.kind), name
    for name in coded:
        assert "flag_values" in ds[name].attrs, name


def check_quantify(ds):
    """``ds.pint.quantify()`` with cf-xarray's UDUNITS registry: every unit parses, and the
    velocity is in m/s (skipped without pint-xarray or cf-xarray)."""
    pytest.importorskip("pint_xarray")
    cf_units = pytest.importorskip("cf_xarray.units")
    numeric = ds[[n for n, v in ds.data_vars.items() if v.dtype.kind not in "USO"]]
    quantified = numeric.pint.quantify(unit_registry=cf_units.units)
    if "fe_sigma_r" in quantified or "sigma_r" in quantified:
        stress = quantified["sigma_r" if "sigma_r" in quantified else "fe_sigma_r"]
        assert str(stress.pint.units) == "pascal"
    if "velocity" in ds.coords:
        speed = cf_units.units(ds["velocity"].attrs["units"])
        assert speed.to("m/s").magnitude == pytest.approx(1.0)
    return quantified
