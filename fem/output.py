"""Writing a result for ParaView and meshio: an XDMF time series of the radial fields.

``<path>.xdmf`` (XML data, no HDF5 library needed) holds the 1-D radial mesh in the *reference*
configuration (points on the x axis, radius ``R``, m) and, at every snapshot time, the nodal
displacement ``u`` as a vector ``(u, 0, 0)`` (ParaView's "Warp By Vector" shows the current
configuration) and, per element, the averages of ``sigma_r``, ``sigma_theta`` (Cauchy, Pa,
compression positive), the accumulated equivalent plastic log strain and the layer index. Units
are part of the field names (``"sigma_r [Pa]"``). meshio reads the series back
(``meshio.xdmf.TimeSeriesReader``). The step history (``time``, ``radius``, ``wall_stress``,
``plastic_radius``) goes to ``<path>_history.csv`` with units in its header.
"""

from pathlib import Path

import meshio
import numpy as np

HISTORY = (("time", "s"), ("radius", "m"), ("wall_stress", "Pa"), ("plastic_radius", "m"))
CELL_FIELDS = (("sigma_r", "sigma_r [Pa]"), ("sigma_theta", "sigma_theta [Pa]"),
               ("plastic_strain", "plastic_strain [1]"), ("layer", "layer [index]"))


def write_result(result, path):
    """Write a recorded ``result`` (from :func:`cavex.fem.expand_cavity`) as ``<path>.xdmf`` and
    ``<path>_history.csv``; return the XDMF path.

    Parameters
    ----------
    result : ExpansionResult
        With its history and snapshots (``record=True``, as :func:`expand_cavity` runs).
    path : str or Path
        Output path; an ``.xdmf`` suffix is added (or replaces another suffix).
    """
    if result.history is None or "snapshots" not in result.fields:
        raise ValueError("write_result needs a recorded result (expand_cavity, or "
                         "expand_cavities(..., record=True))")
    path = Path(path).with_suffix(".xdmf")
    path.parent.mkdir(parents=True, exist_ok=True)
    snapshots = result.fields["snapshots"]
    R_vertices = result.fields["R_nodes"][::_degree(result, snapshots)]
    points = np.column_stack([R_vertices, np.zeros_like(R_vertices), np.zeros_like(R_vertices)])
    n = len(R_vertices)
    cells = [("line", np.column_stack([np.arange(n - 1), np.arange(1, n)]))]
    with meshio.xdmf.TimeSeriesWriter(path, data_format="XML") as writer:
        writer.write_points_cells(points, cells)
        for snap in snapshots:
            u = np.column_stack([snap["u"], np.zeros(n), np.zeros(n)])
            writer.write_data(snap["time"], point_data={"u [m]": u},
                              cell_data={label: [np.asarray(snap[name])]
                                         for name, label in CELL_FIELDS})
    table = np.column_stack([np.asarray(result.history[name]) for name, _ in HISTORY])
    np.savetxt(path.with_name(path.stem + "_history.csv"), table, delimiter=",",
               header=",".join(f"{name} [{unit}]" for name, unit in HISTORY), comments="")
    return path


def _degree(result, snapshots):
    """Nodes per element edge: the snapshots hold vertex values only."""
    return (len(result.fields["R_nodes"]) - 1) // len(snapshots[0]["sigma_r"])
