"""Helpers that only the tests use, on top of the product's FE data and kernels.

- :func:`return_map`: the compiled point kernel :func:`cavex.fem.constitutive.return_point` on
  arrays of points (the element kernel calls it point by point inside its own loop);
- :func:`to_skfem`: a radial-ordered dof vector of a
  :class:`~cavex.fem.discretisation.Discretisation` in scikit-fem's order (for its bases);
- :func:`point_material`: the material records of layers at points, with attribute access
  (``m.K``) for numpy arithmetic;
- :func:`take_points`: the material records at a subset of the points;
- :func:`advance`: one step of a :class:`~cavex.fem.solver.RadialSolver` (its
  :meth:`~cavex.fem.solver.RadialSolver.run` on a one-step list).
"""

import numpy as np
from numba import njit

from cavex.fem.constitutive import OUTPUTS, return_point
from cavex.fem.material_records import pack_layers


@njit(cache=True, error_model="numpy")
def _return_points(eps_r, eps_t, theta_p, gamma_p, material, out, plastic):
    for i in range(eps_r.size):
        plastic[i], row = return_point(eps_r[i], eps_t[i], theta_p[i], gamma_p[i], material[i])
        for j in range(9):
            out[j, i] = row[j]


def return_map(eps_r, eps_t, theta_p, gamma_p, material):
    """:func:`~cavex.fem.constitutive.return_point` at every point of the arrays (all of one
    shape; ``material``: records of :data:`~cavex.fem.material_records.MATERIAL` broadcast to
    it).

    Returns a dict of arrays of that shape: the :data:`~cavex.fem.constitutive.OUTPUTS` and
    ``plastic``.
    """
    shape = np.shape(eps_r)
    flat = [np.ascontiguousarray(np.broadcast_to(x, shape), dtype=float).ravel()
            for x in (eps_r, eps_t, theta_p, gamma_p)]
    records = np.ascontiguousarray(np.broadcast_to(np.asarray(material), shape)).ravel()
    out = np.empty((len(OUTPUTS), flat[0].size))
    plastic = np.empty(flat[0].size, dtype=np.bool_)
    _return_points(*flat, records, out, plastic)
    result = {name: out[i].reshape(shape) for i, name in enumerate(OUTPUTS)}
    result["plastic"] = plastic.reshape(shape)
    return result


def to_skfem(disc, u_radial):
    """Radial-ordered dof vector of ``disc`` in scikit-fem's order."""
    return u_radial[disc.radial]


def point_material(layers, layer_of_point, dilatancy_deg=0.0, tension_cutoff=None):
    """The product's material records (:func:`~cavex.fem.material_records.pack_layers`) at
    points whose layer index is ``layer_of_point``, as a record array: ``m.K`` is the array of
    the points' bulk moduli."""
    return pack_layers(layers, layer_of_point, dilatancy_deg, tension_cutoff).view(np.recarray)


def take_points(material, index):
    """The material records at ``index`` (anything that indexes the point arrays)."""
    return material[index]


def advance(solver, load, dt):
    """One step of every case of ``solver`` to the wall ``load`` (per case or shared) over
    ``dt``, with the cut-back policy; raises the first case's :class:`CavexNumericalError`."""
    k = solver.stack.n_cases
    load = np.broadcast_to(np.asarray(load, dtype=float), (k,))
    times = [[solver.cases["t"][c] + dt] for c in range(k)] if solver.dynamic else None
    errors = solver.run([[x] for x in load], times)
    for error in errors:
        if error is not None:
            raise error
