"""netCDF-3 files of numeric variables, written and read with :class:`scipy.io.netcdf_file`.

The files xarray's scipy engine writes and reads for the variables cavex tabulates, without
importing xarray: ``xr.open_dataset`` reads a file written here as the dataset it was made
from, and :func:`read_netcdf3` reads such a file as ``xr.load_dataset`` does (both tested).
The encoding is CF's, as xarray applies it:

- float variables carry ``_FillValue = NaN`` of their own type (a NaN cell reads back NaN);
- boolean variables are stored as ``int8`` with the attribute ``dtype = "bool"``;
- integer variables are stored as they are (netCDF-3 has 8, 16 and 32-bit integers only);
- attributes: text, numbers or numeric arrays; a variable named as its one dimension is a
  coordinate.

Why not xarray itself: its first write imports dask and dask.distributed (to choose a lock
and a scheduler), its first dataset and its reader probe for dask arrays: with its own import
0.5-1 s of CPU a process on a 2-core machine, as much as the FE of a 100-case ``cavex table``
takes on one core, or three times a ``cavex penetrate`` computation.

A *variable* here is ``(dims, values, attrs)``, as in ``xarray.Dataset``'s constructor;
:class:`PlainDataset` holds a file's variables and attributes as plain arrays.
"""

from dataclasses import dataclass

import numpy as np

FILL_VALUE = "_FillValue"
BOOLEAN = ("dtype", "bool")  # the attribute that marks an int8 variable as booleans
#: netCDF-3 classic format with 64-bit offsets: xarray's default for the scipy engine
VERSION = 2


@dataclass(frozen=True)
class PlainDataset:
    """A dataset as plain arrays: ``data`` and ``coords`` map names to ``(dims, values,
    attrs)``, ``attrs`` are the global attributes, ``order`` the names in the order of the
    file (default: data variables, then coordinates). ``ds[name]`` is the values (an array)
    of a data variable or coordinate; :meth:`dataset` is the :class:`xarray.Dataset`."""

    data: dict
    coords: dict
    attrs: dict
    order: tuple = ()

    def __getitem__(self, name):
        return np.asarray((self.data.get(name) or self.coords[name])[1])

    def __contains__(self, name):
        return name in self.data or name in self.coords

    def variables(self):
        """Data variables and coordinates in one mapping, in the order written: xarray
        defines a file's dimensions in the order its variables first use them."""
        merged = {**self.data, **self.coords}
        return {name: merged[name] for name in self.order or merged}

    def dataset(self):
        import xarray as xr

        order = self.order or tuple(self.variables())
        return xr.Dataset({k: self.data[k] for k in order if k in self.data},
                          coords={k: self.coords[k] for k in order if k in self.coords},
                          attrs=self.attrs)

    @classmethod
    def from_dataset(cls, ds):
        def plain(variables):
            return {str(name): (variable.dims, variable.values, dict(variable.attrs))
                    for name, variable in variables.items()}

        return cls(plain(ds.data_vars), plain(ds.coords), dict(ds.attrs),
                   tuple(str(name) for name in ds.variables))


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
        attrs[BOOLEAN[0]] = BOOLEAN[1]
        return dims, values.astype("i1"), attrs
    if values.dtype.kind in "iu" and values.dtype.itemsize <= 4:
        return dims, values.astype(values.dtype.newbyteorder(">")), attrs
    raise TypeError(f"netcdf3: no encoding for {values.dtype} values")


def decoded(dims, values, attrs):
    """The inverse of :func:`encoded`, as xarray decodes: text attributes as ``str``, the
    fill value (NaN) and the boolean marker dropped, values in the machine's byte order."""
    attrs = {k: v.decode() if isinstance(v, bytes) else v for k, v in attrs.items()}
    values = np.asarray(values)
    values = values.astype(values.dtype.newbyteorder("="))
    if attrs.pop(FILL_VALUE, None) is not None and values.dtype.kind != "f":
        raise ValueError("netcdf3: a fill value on non-float values is not read here")
    if attrs.get(BOOLEAN[0]) == BOOLEAN[1]:
        del attrs[BOOLEAN[0]]
        values = values.astype(bool)
    return tuple(dims), values, attrs


def write_netcdf3(path, variables, attrs):
    """Write ``variables`` (name -> ``(dims, values, attrs)``, in the order given) and the
    global ``attrs`` to ``path`` (for an atomic write, a temporary path the caller then moves:
    :func:`cavex.verification.output.files.replaced_atomically`)."""
    from scipy.io import netcdf_file  # scipy.io loads its other formats too: not at the top

    stored_variables = {name: encoded(*variable) for name, variable in variables.items()}
    with netcdf_file(path, "w", version=VERSION) as out:
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


def read_netcdf3(path):
    """The :class:`PlainDataset` of the netCDF-3 file ``path``, read into memory (the file is
    closed); errors are scipy's (a file that is not netCDF-3, or truncated)."""
    from scipy.io import netcdf_file

    with netcdf_file(path, "r", mmap=False) as source:
        variables = {name: decoded(variable.dimensions, variable.data.copy(),
                                   dict(variable._attributes))
                     for name, variable in source.variables.items()}
        attrs = {k: v.decode() if isinstance(v, bytes) else v
                 for k, v in source._attributes.items()}
    coords = {k: v for k, v in variables.items() if v[0] == (k,)}
    data = {k: v for k, v in variables.items() if k not in coords}
    return PlainDataset(data, coords, attrs, tuple(variables))
