"""CF metadata shared by every netCDF file cavex writes (FE tables, sweeps, report grids).

- the global attribute ``Conventions`` (:data:`CONVENTIONS`);
- units in UDUNITS spelling, one spelling per quantity (:data:`UNITS`: ``m s-1``, not ``m/s``),
  so that ``cf_xarray``'s unit registry, and with it ``pint-xarray``, reads every file;
- :func:`pint_readable`: a dataset's units respelled where pint's default registry reads the
  UDUNITS spelling otherwise (``m s-1`` as ``m/s``, ``kg m-3`` as ``kg/m^3``: both spellings are
  UDUNITS, so the dataset stays CF), for the Python API (:mod:`cavex.api`);
- coded variables (booleans stored as ``int8``, validity codes, response states, the wall
  layer) carry ``flag_values`` and ``flag_meanings`` (:func:`flag_attrs`).
"""

import re

import numpy as np

CONVENTIONS = "CF-1.10"

# UDUNITS spellings of every unit the netCDF files use
UNITS = {"velocity": "m s-1", "length": "m", "stress": "Pa", "density": "kg m-3",
         "time": "s", "angle": "degree", "dimensionless": "1"}


#: UDUNITS spellings of :data:`UNITS` that pint's default registry misreads (it parses
#: ``s-1`` as ``s - 1``), each with the UDUNITS spelling it reads as the same unit
PINT_SPELLINGS = {"m s-1": "m/s", "kg m-3": "kg/m^3"}


def pint_readable(ds):
    """A shallow copy of the :class:`xarray.Dataset` ``ds`` whose ``units`` attributes pint's
    default registry reads: :data:`PINT_SPELLINGS` respelled, the others as they are (so that
    ``ds.pint.quantify()`` needs no unit registry of its own)."""
    out = ds.copy()
    for variable in out.variables.values():
        units = variable.attrs.get("units")
        if units in PINT_SPELLINGS:
            variable.attrs = {**variable.attrs, "units": PINT_SPELLINGS[units]}
    return out


def flag_word(text):
    """``text`` as one CF flag-meaning word (letters, digits and ``_ - . + @``)."""
    word = re.sub(r"[^A-Za-z0-9_.+@-]+", "_", str(text).strip()).strip("_")
    return word or "unnamed"


def flag_attrs(values, meanings, long_name, dtype=np.int8):
    """``units``, ``long_name``, ``flag_values`` and ``flag_meanings`` of a coded variable.

    ``flag_values`` has the stored dtype of the variable (``int8`` for booleans and codes).
    """
    words = [flag_word(m) for m in meanings]
    if len(set(words)) != len(words) or len(words) != len(values):
        raise ValueError(f"flag meanings must be distinct, one per value: {words}")
    return {"units": UNITS["dimensionless"], "long_name": long_name,
            "flag_values": np.asarray(values, dtype=dtype), "flag_meanings": " ".join(words)}


def boolean_attrs(long_name, false="no", true="yes"):
    """Flag attributes of a boolean variable (stored as ``int8``: 0 ``false``, 1 ``true``)."""
    return flag_attrs([0, 1], [false, true], long_name)


def flag_labels(variable):
    """``{value: meaning}`` of a coded variable (from its ``flag_values``/``flag_meanings``)."""
    values = np.atleast_1d(variable.attrs["flag_values"]).tolist()
    return dict(zip(values, variable.attrs["flag_meanings"].split(), strict=True))


def decode_flags(variable):
    """The meanings of a coded variable's values, as a numpy string array of its shape."""
    labels = flag_labels(variable)
    codes = np.asarray(variable.values).astype(int)
    return np.vectorize(labels.__getitem__, otypes=[str])(codes) if codes.size else \
        np.array([], dtype=str).reshape(codes.shape)
