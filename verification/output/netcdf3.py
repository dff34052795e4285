"""netCDF-3 files of numeric variables, written with :class:`scipy.io.netcdf_file` directly.

What xarray's ``to_netcdf(engine="scipy")`` writes for the variables cavex tabulates, without
importing xarray: ``xr.open_dataset`` reads such a file back as the dataset xarray would have
written (tested). The encoding is CF's, as xarray applies it:

- float variables carry ``_FillValue = NaN`` (a NaN cell reads back as NaN);
- boolean variables are stored as ``int8`` with the attribute ``dtype = "bool"`` (read back
  as booleans);
- integer variables are stored as they are (netCDF-3 has 8, 16 and 32-bit integers only);
- attributes: text, numbers or numeric arrays.

Why not xarray itself: its first write imports dask and dask.distributed to choose a lock and
a scheduler, and probes for dask arrays when the dataset is built (0.5-0.8 s of CPU per
process on a 2-core machine; ``cavex table`` on a 100-case grid computes its FE in about
twice that), although these files are small and written in one piece.

A *variable* here is ``(dims, values, attrs)``, as in ``xarray.Dataset``'s constructor.
"""

from pathlib import Path

import numpy as np

from cavex.verification.output.files import replaced_atomically

FILL_VALUE = "_FillValue"
#: netCDF-3 classic format with 64-bit offsets: xarray's default for the scipy engine
VERSION = 2


def encoded(dims, values, attrs):
    """``(dims, stored values, stored attributes)`` of one variable, CF-encoded as xarray
    encodes it for netCDF-3 (module docstring)."""
    dims = (dims,) if isinstance(dims, str) else tuple(dims)
    values = np.asarray(values)
    attrs = dict(attrs)
    if values.dtype.kind == "f":
        attrs[FILL_VALUE] = values.dtype.type(np.nan)  # of the variable's type, as xarray's
        return dims, values.astype(values.dtype.newbyteorder(">")), attrs
    if values.dtype.kind == "b":
        attrs["dtype"] = "bool"
        return dims, values.astype("i1"), attrs
    if values.dtype.kind in "iu" and values.dtype.itemsize <= 4:
        return dims, values.astype(values.dtype.newbyteorder(">")), attrs
    raise TypeError(f"netcdf3: no encoding for {values.dtype} values")


def write_netcdf3(path, variables, attrs):
    """Write ``variables`` (name -> ``(dims, values, attrs)``, in the order given) and the
    global ``attrs`` to ``path`` atomically
    (:func:`~cavex.verification.output.files.replaced_atomically`); returns ``path``."""
    path = Path(path)
    if path.parent != Path(""):
        path.parent.mkdir(parents=True, exist_ok=True)
    from scipy.io import netcdf_file  # scipy.io loads its other formats too: not at the top

    stored_variables = {name: encoded(*variable) for name, variable in variables.items()}
    with replaced_atomically(path) as tmp, netcdf_file(tmp, "w", version=VERSION) as out:
        for dims, values, _ in stored_variables.values():
            for dim, size in zip(dims, values.shape, strict=True):
                if dim not in out.dimensions:
                    out.createDimension(dim, size)
        for key, value in attrs.items():
            setattr(out, key, value)
        for name, (dims, values, variable_attrs) in stored_variables.items():
            stored = out.createVariable(name, values.dtype.str[1:], dims)
            for key, value in variable_attrs.items():
                setattr(stored, key, value)
            stored[...] = values
    return path
