"""Writing a result for ParaView with meshio: a VTU per snapshot and a PVD time-series index.

Each VTU holds the 1-D radial mesh in its *current* configuration at the snapshot time (points
on the x axis), the nodal displacement ``u`` and the element-averaged ``sigma_r``,
``sigma_theta`` (Pa, compression positive) and ``plastic_strain``. The step history (``time``,
``radius``, ``wall_stress``, ``plastic_radius``) goes to ``<path>_history.csv``. Open the
``.pvd`` file in ParaView to step through time.
"""

from pathlib import Path

import meshio
import numpy as np

HISTORY = ("time", "radius", "wall_stress", "plastic_radius")


def write_result(result, path):
    """Write ``result`` as ``<path>.pvd`` plus ``<path>_NNNN.vtu`` snapshots; return the PVD path.

    Parameters
    ----------
    result : ExpansionResult
    path : str or Path
        Output path; a ``.pvd`` suffix is added (or replaces another suffix).
    """
    path = Path(path).with_suffix(".pvd")
    path.parent.mkdir(parents=True, exist_ok=True)
    R = result.fields["R_nodes"]
    step = (len(R) - 1) // (len(result.fields["snapshots"][0]["sigma_r"]))
    R_vertices = R[::step]
    cells = [("line", np.column_stack([np.arange(len(R_vertices) - 1),
                                       np.arange(1, len(R_vertices))]))]
    history = result.history
    entries = []
    for k, snap in enumerate(result.fields["snapshots"]):
        x = R_vertices + snap["u"]
        points = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
        mesh = meshio.Mesh(points, cells, point_data={"u": snap["u"]},
                           cell_data={name: [snap[name]] for name in
                                      ("sigma_r", "sigma_theta", "plastic_strain")})
        name = f"{path.stem}_{k:04d}.vtu"
        meshio.write(path.parent / name, mesh)
        entries.append(f'    <DataSet timestep="{snap["time"]:.9e}" file="{name}"/>')
    table = np.column_stack([np.asarray(history[k]) for k in HISTORY])
    np.savetxt(path.with_name(path.stem + "_history.csv"), table, delimiter=",",
               header=",".join(HISTORY), comments="")
    path.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                    "  <Collection>\n" + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")
    return path
