"""Helpers that only the tests use, on top of the product's FE data and kernels.

- :func:`return_map`: the compiled point kernel :func:`cavex.fem.constitutive.return_point` on
  arrays of points (the element kernel calls it point by point inside its own loop);
- :func:`to_skfem`: a radial-ordered dof vector of a
  :class:`~cavex.fem.discretisation.Discretisation` in scikit-fem's order (for its bases);
- :func:`take_points`: the constants of a :class:`~cavex.fem.constitutive.PointMaterial` at a
  subset of its points;
- :func:`advance`: one step of a :class:`~cavex.fem.solver.RadialSolver` (its
  :meth:`~cavex.fem.solver.RadialSolver.run` on a one-step list).
"""

import numpy as np
from numba import njit

from cavex.fem.constitutive import OUTPUTS, PointMaterial, return_point


@njit(cache=True, error_model="numpy")
def _return_points(eps_r, eps_t, theta_p, gamma_p, K, G, lam, tau, lam_psi, tension, cap, out,
                   plastic):
    for i in range(eps_r.size):
        plastic[i], row = return_point(eps_r[i], eps_t[i], theta_p[i], gamma_p[i], K[i], G[i],
                                       lam[i], tau[i], lam_psi[i], tension[i], cap[i])
        for j in range(9):
            out[j, i] = row[j]


def return_map(eps_r, eps_t, theta_p, gamma_p, material):
    """:func:`~cavex.fem.constitutive.return_point` at every point of the arrays (all of one
    shape).

    Returns a dict of arrays of that shape: the :data:`~cavex.fem.constitutive.OUTPUTS` and
    ``plastic``.
    """
    shape = np.shape(eps_r)
    flat = [np.ascontiguousarray(np.broadcast_to(x, shape), dtype=float).ravel()
            for x in (eps_r, eps_t, theta_p, gamma_p)]
    props = [np.ascontiguousarray(np.broadcast_to(getattr(material, name), shape),
                                  dtype=float).ravel()
             for name in ("K", "G", "lam", "tau", "lam_psi", "tension", "cap")]
    out = np.empty((len(OUTPUTS), flat[0].size))
    plastic = np.empty(flat[0].size, dtype=np.bool_)
    _return_points(*flat, *props, out, plastic)
    result = {name: out[i].reshape(shape) for i, name in enumerate(OUTPUTS)}
    result["plastic"] = plastic.reshape(shape)
    return result


def to_skfem(disc, u_radial):
    """Radial-ordered dof vector of ``disc`` in scikit-fem's order."""
    return u_radial[disc.radial]


def take_points(material, index):
    """The :class:`PointMaterial` constants at ``index`` (anything that indexes the point
    arrays)."""
    return PointMaterial(**{name: value[index] for name, value in vars(material).items()})


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
