r"""The FE table's interpolation error in a trajectory, estimated from the table alone.

A trajectory flown with an FE table
(:class:`~cavex.analytic.penetration.tabulated.TabulatedResistance`) interpolates
``sigma_r(V, L)`` between the table's nodes. With node spacing ``h`` in one axis its final
depth is ``d(h) = d* + C h^p``. An FE cell depends on its own ``(V, L)`` only, so the same
table with every other node of that axis (:func:`coarsened`) *is* the FE table on
spacing ``2 h``, and

    d(2h) - d(h) = C h^p (2^p - 1),

without a new FE run. The estimate (:func:`interpolation_error`) of the error of ``d(h)`` is

    E = |d_V(2h) - d(h)| + |d_L(2h) - d(h)|,

the table coarsened in ``V`` and in ``L`` separately, the two parts added. It is the error
itself at ``p = 1`` and ``2^p - 1`` times it for larger ``p`` (3 at ``p = 2``): an upper
estimate wherever the rate is at least 1. The rates measured on the default verification
grid, and this estimate against tables refined by FE, are in docs/verification.md
("Interpolation error") and ``benchmarks/table_refinement.py``.

Every other node: in ``V`` the indices 0, 2, 4, ... and always the last (``V = 0`` and the top
velocity are kept: the table needs both); in ``L`` the same on each wall-layer segment between
switch nodes (the switch nodes and both ends kept: the table refuses a grid without them).
An axis with nothing to drop (two nodes, or every segment of two) gives no estimate (None).
"""

import numpy as np

from cavex.analytic.geometry import switch_depths
from cavex.analytic.penetration.integrator import penetrate
from cavex.analytic.penetration.tabulated import NODE_TOLERANCE, TabulatedResistance
from cavex.netcdf3 import PlainDataset

#: the variables a :class:`TabulatedResistance` reads, by dimensions
ON_GRID = ("sigma_r", "failed")
ON_VELOCITY = ("sigma_r_first_layer", "failed_first_layer")
ON_DEPTH = ("wall_layer",)
AXES = ("velocity", "depth")


def every_other(count):
    """Indices 0, 2, 4, ... of ``count`` nodes, and always the last."""
    return sorted(set(range(0, count, 2)) | {count - 1})


def kept_velocities(velocities):
    """Indices of the velocities a table on twice the spacing in ``V`` keeps."""
    return every_other(len(velocities))


def kept_depths(depths, target, projectile):
    """Indices of the depths a table on twice the spacing in ``L`` keeps: every other node on
    each wall-layer segment, the segment ends (the switch nodes) kept."""
    depths = np.asarray(depths, dtype=float)
    ends = [0, len(depths) - 1] + [int(np.argmin(np.abs(depths - s)))
                                   for s in switch_depths(target, projectile)
                                   if np.any(np.abs(depths - s) <= NODE_TOLERANCE)]
    ends = sorted(set(ends))
    kept = set()
    for lo, hi in zip(ends[:-1], ends[1:], strict=True):
        kept |= {lo + i for i in every_other(hi - lo + 1)}
    return sorted(kept)


def table_at_nodes(table, velocity_index, depth_index, note=""):
    """The table restricted to the given node indices: a :class:`~cavex.netcdf3.PlainDataset`
    of the variables :class:`TabulatedResistance` reads, with the table's attributes."""
    iv, idp = np.asarray(velocity_index), np.asarray(depth_index)
    data = {name: (("velocity", "depth"), np.asarray(table[name])[np.ix_(iv, idp)], {})
            for name in ON_GRID}
    data |= {name: (("velocity",), np.asarray(table[name])[iv], {}) for name in ON_VELOCITY}
    data |= {name: (("depth",), np.asarray(table[name])[idp], {}) for name in ON_DEPTH}
    coords = {"velocity": (("velocity",), np.asarray(table["velocity"], dtype=float)[iv], {}),
              "depth": (("depth",), np.asarray(table["depth"], dtype=float)[idp], {})}
    attrs = dict(table.attrs)
    attrs["source"] = f"{attrs.get('source', 'in-memory table')}{note}"
    return PlainDataset(data, coords, attrs)


def coarsened(table, axis, target, projectile):
    """The table with every other node in ``axis`` ("velocity" or "depth"), or None when that
    drops nothing."""
    velocities = np.asarray(table["velocity"], dtype=float)
    depths = np.asarray(table["depth"], dtype=float)
    iv, idp = list(range(velocities.size)), list(range(depths.size))
    if axis == "velocity":
        iv = kept_velocities(velocities)
    else:
        idp = kept_depths(depths, target, projectile)
    if len(iv) == velocities.size and len(idp) == depths.size:
        return None
    return table_at_nodes(table, iv, idp, f" (every other {axis} node)")


def flown(target, projectile, table, crater="nose-base"):
    """Final depth (m) and phase-end velocities (m/s) of a trajectory flown with ``table``."""
    run = penetrate(target, projectile, TabulatedResistance(table, target, projectile),
                    crater=crater)
    return {"final_depth_m": float(run.depth[-1]),
            "phase_end_velocities_m_s": [float(p.end_velocity) for p in run.phases],
            "phase_labels": [p.label for p in run.phases]}


def interpolation_error(target, projectile, table, crater="nose-base", reference=None):
    """The estimate ``E`` of the module docstring for ``table``.

    Parameters
    ----------
    target, projectile, table, crater
        As for :func:`~cavex.analytic.penetration.tabulated.penetrate_with_table` (``table``
        read already).
    reference : dict, optional
        :func:`flown` with ``table`` itself, if the caller has it.

    Returns
    -------
    dict
        ``estimate_m`` (``E``; None when neither axis can be coarsened), ``final_depth_m``,
        and per axis (``velocity``, ``depth``): the coarsened table's ``final_depth_m``, its
        difference ``difference_m = d(2h) - d(h)`` and ``phase_end_velocity_difference_m_s``
        (largest |difference| of the phase-end velocities, None where the phases differ), or
        None for an axis that cannot be coarsened.
    """
    fine = reference or flown(target, projectile, table, crater)
    parts = {}
    for axis in AXES:
        coarse_table = coarsened(table, axis, target, projectile)
        parts[axis] = (None if coarse_table is None
                       else _difference(flown(target, projectile, coarse_table, crater), fine))
    known = [abs(p["difference_m"]) for p in parts.values() if p is not None]
    return {"estimate_m": float(sum(known)) if known else None,
            "final_depth_m": fine["final_depth_m"], **parts}


def _difference(coarse, fine):
    same = coarse["phase_labels"] == fine["phase_labels"]
    dv = (max(abs(a - b) for a, b in zip(coarse["phase_end_velocities_m_s"],
                                         fine["phase_end_velocities_m_s"], strict=True))
          if same else None)
    return {"final_depth_m": coarse["final_depth_m"],
            "difference_m": coarse["final_depth_m"] - fine["final_depth_m"],
            "phase_end_velocity_difference_m_s": dv}
