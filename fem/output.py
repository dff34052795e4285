"""Writing a result for ParaView and meshio: an XDMF time series of the radial fields and the
final state as one VTU file.

``<path>.xdmf`` (XML data, no HDF5 library needed) holds the 1-D radial mesh in the *reference*
configuration (points on the x axis, radius ``R``, m) and, at every snapshot time, the nodal
displacement ``u_m`` as a vector ``(u, 0, 0)`` (ParaView's "Warp By Vector" shows the current
configuration) and, per element, the averages of ``sigma_r_Pa``, ``sigma_theta_Pa`` (Cauchy,
compression positive), the accumulated equivalent plastic log strain ``plastic_strain`` and the
layer index ``layer``: names end in their SI unit as the keys of the JSON output do (README
"JSON output"). A time series is read with ``meshio.xdmf.TimeSeriesReader`` (``meshio.read``
reads one mesh, not a series; docs/fem.md "Output files" shows the reader);
``<path>_final.vtu`` holds the last snapshot with the same names and opens with
``meshio.read``. The step history (``time_s``, ``radius_m``, ``wall_stress_Pa``,
``plastic_radius_m``) goes to ``<path>_history.csv``, with ``digits`` significant digits.
"""

from pathlib import Path

import numpy as np

HISTORY = (("time", "s"), ("radius", "m"), ("wall_stress", "Pa"), ("plastic_radius", "m"))
CELL_FIELDS = (("sigma_r", "sigma_r_Pa"), ("sigma_theta", "sigma_theta_Pa"),
               ("plastic_strain", "plastic_strain"), ("layer", "layer"))
DISPLACEMENT = "u_m"
HISTORY_DIGITS = 17  # significant digits of the history CSV by default (exact round trip)


def write_result(result, path, digits=HISTORY_DIGITS):
    """Write a recorded ``result`` (from :func:`cavex.fem.expand_cavity`) as ``<path>.xdmf``,
    ``<path>_final.vtu`` and ``<path>_history.csv`` (``digits`` significant digits); return
    the XDMF path.

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
    import meshio  # only here: not a cost of every FE run (~0.05 s per process)

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
            writer.write_data(snap["time"], **_data(snap, n))
    meshio.write(path.with_name(path.stem + "_final.vtu"),
                 meshio.Mesh(points, cells, **_data(snapshots[-1], n)))
    table = np.column_stack([np.asarray(result.history[name]) for name, _ in HISTORY])
    np.savetxt(path.with_name(path.stem + "_history.csv"), table, delimiter=",",
               fmt=f"%.{digits}g", header=",".join(f"{name}_{unit}" for name, unit in HISTORY),
               comments="")
    return path


def _data(snapshot, n):
    """``point_data`` (the displacement as a vector) and ``cell_data`` of one snapshot."""
    u = np.column_stack([snapshot["u"], np.zeros(n), np.zeros(n)])
    return {"point_data": {DISPLACEMENT: u},
            "cell_data": {label: [np.asarray(snapshot[name])] for name, label in CELL_FIELDS}}


def _degree(result, snapshots):
    """Nodes per element edge: the snapshots hold vertex values only."""
    return (len(result.fields["R_nodes"]) - 1) // len(snapshots[0]["sigma_r"])
