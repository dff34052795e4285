"""Bases, quadrature, dof ordering and the point data of one radial model (scikit-fem).

Anti-locking: the stiffness is integrated with a reduced Gauss rule of ``degree`` points per
element (one point for P1, two for P2). In 1-D spherical symmetry this is free of spurious
modes (``u' = 0`` and ``u/R = 0`` at ``degree`` points force ``u = 0`` on a P``degree``
element) and imposes exactly one volumetric constraint per displacement unknown, so the
near-incompressible limit is a Gauss collocation of ``d(r^3)/dR = 3R^2`` instead of an
over-constrained (locked) system. The mass matrix uses a full rule.

Dofs are numbered in *radial* order (from the cavity outwards, element ``e`` owning dofs
``p e ... p e + p``), which makes the tangent banded with ``p`` sub- and super-diagonals. The
internal force and tangent are computed by the compiled kernel of :mod:`cavex.fem.element` on
the quadrature data gathered here.
"""

import numpy as np
from skfem import Basis, ElementLineP1, ElementLineP2, asm

from cavex.fem import forms
from cavex.fem.material_records import pack_layers

ELEMENTS = {1: ElementLineP1, 2: ElementLineP2}


def gauss_rule(n):
    """``n``-point Gauss-Legendre rule on the reference line ``[0, 1]`` as ``(X, W)``."""
    x, w = np.polynomial.legendre.leggauss(n)
    return np.array([0.5 * (x + 1.0)]), 0.5 * w


class Discretisation:
    """Mesh, bases and point data of one radial model.

    Parameters
    ----------
    mesh : skfem.MeshLine
        Reference mesh, vertices increasing from the cavity wall.
    degree : {1, 2}
    element_layer : ndarray of int
        Layer index of every element.
    layers : sequence of Material
    dilatancy_deg, tension_cutoff
        See :func:`cavex.fem.material_records.pack_layers`.
    stiffness_points : int, optional
        Gauss points per element for the stiffness; default ``degree`` (the locking-free
        reduced rule). ``degree + 1`` is the full rule, kept to demonstrate locking.
    """

    def __init__(self, mesh, degree, element_layer, layers, dilatancy_deg=0.0,
                 tension_cutoff=None, stiffness_points=None):
        element = ELEMENTS[degree]()
        self.degree = degree
        self.mesh = mesh
        self.basis = Basis(mesh, element, quadrature=gauss_rule(stiffness_points or degree))
        self.mass_basis = Basis(mesh, element, quadrature=gauss_rule(degree + 2))
        nel = mesh.t.shape[1]
        self.n_elements = nel
        self.ndof = degree * nel + 1
        local = [0, degree] + list(range(1, degree))  # skfem local order: ends, then interior
        radial_of_local = degree * np.arange(nel)[None, :] + np.array(local)[:, None]
        self.radial = np.empty(self.basis.N, dtype=int)  # radial index of each skfem dof
        self.radial[self.basis.element_dofs] = radial_of_local
        self.element_dofs = radial_of_local.T  # (nel, nb) radial dofs in skfem local order
        self.R_dofs = np.empty(self.ndof)
        self.R_dofs[self.radial] = self.basis.doflocs[0]
        self.layers = list(layers)
        self.element_layer = np.asarray(element_layer)
        nq = self.basis.X.shape[1]
        self.point_layer = np.repeat(self.element_layer[:, None], nq, axis=1)
        # one material record per element: the kernels' material, the mass matrix's density
        self.material = pack_layers(self.layers, self.element_layer, dilatancy_deg,
                                    tension_cutoff)
        # quadrature data of the reduced rule
        self.N = np.array([np.asarray(b[0])[0] for b in self.basis.basis])  # (nb, nq)
        self.dNdR = np.array([b[0].grad[0] for b in self.basis.basis]).transpose(1, 0, 2)
        self.R_points = self.basis.mapping.F(self.basis.X)[0]  # (nel, nq)
        self.weights = self.basis.dx * forms.FOUR_PI * self.R_points ** 2
        self.force_weights = self.weights * np.maximum(
            np.abs(self.dNdR).max(axis=1), self.N.max(axis=0) / self.R_points)
        rho = self.material["rho"]
        nqm = self.mass_basis.X.shape[1]
        self._rho_mass = np.repeat(rho[:, None], nqm, axis=1)
        self.mass = self._assemble_mass()
        self.mass_band = to_banded(self.mass, degree)

    # ------------------------------------------------------------------ helpers
    def _assemble_mass(self):
        M = asm(forms.mass, self.mass_basis, rho=self._rho_mass)
        return M[np.argsort(self.radial)][:, np.argsort(self.radial)].tocsr()

    def displacement_gradients(self, u):
        """``(lambda_r - 1, lambda_t - 1) = (du/dR, u/R)`` at the reduced quadrature points."""
        ue = u[self.element_dofs]  # (nel, nb)
        return (ue[:, :, None] * self.dNdR).sum(1), (ue @ self.N) / self.R_points


def to_banded(A, p):
    """Sparse ``A`` with ``p`` sub/super-diagonals to LAPACK band storage ``(2p+1, n)``."""
    coo = A.tocoo()
    band = np.zeros((2 * p + 1, A.shape[1]))
    np.add.at(band, (p + coo.row - coo.col, coo.col), coo.data)
    return band
