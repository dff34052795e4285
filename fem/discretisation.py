"""Bases, quadrature, dof ordering and the two assembly paths (scikit-fem forms and vectorised).

Anti-locking: the stiffness is integrated with a reduced Gauss rule of ``degree`` points per
element (one point for P1, two for P2). In 1-D spherical symmetry this is free of spurious
modes (``u' = 0`` and ``u/R = 0`` at ``degree`` points force ``u = 0`` on a P``degree``
element) and imposes exactly one volumetric constraint per displacement unknown, so the
near-incompressible limit is a Gauss collocation of ``d(r^3)/dR = 3R^2`` instead of an
over-constrained (locked) system. The mass matrix uses a full rule.

Both paths return the internal force and the tangent in *radial* dof order (dofs numbered from
the cavity outwards, element ``e`` owning dofs ``p e ... p e + p``), which makes the tangent
banded with ``p`` sub- and super-diagonals.
"""

import numpy as np
from cavex.fem import forms
from cavex.fem.constitutive import PointMaterial, hencky_mohr_coulomb
from skfem import Basis, ElementLineP1, ElementLineP2, asm

ELEMENTS = {1: ElementLineP1, 2: ElementLineP2}


def gauss_rule(n):
    """``n``-point Gauss-Legendre rule on the reference line ``[0, 1]`` as ``(X, W)``."""
    x, w = np.polynomial.legendre.leggauss(n)
    return np.array([0.5 * (x + 1.0)]), 0.5 * w


class FastAssembly:
    """The vectorised kernels over (element, point) arrays, shared with batches of models.

    Needs ``degree``, ``ndof``, ``element_dofs`` (nel, nb), ``N`` (nb, nq), ``dNdR``
    (nel, nb, nq), ``R_points`` and ``weights`` (nel, nq).
    """

    def displacement_gradients(self, u):
        """``(lambda_r - 1, lambda_t - 1) = (du/dR, u/R)`` at the reduced quadrature points.

        Strains are formed as ``log1p`` of these, which keeps full relative precision at the
        tiny strains of the elastic verification problems.
        """
        ue = u[self.element_dofs]  # (nel, nb)
        g_r = (ue[:, :, None] * self.dNdR).sum(1)
        g_t = (ue @ self.N) / self.R_points
        return g_r, g_t

    def assemble_response(self, lam_r, lam_t, resp, tangent=True):
        """Internal force, banded tangent and ``resp`` from the stretches and point response."""
        W = self.weights
        Br = self.dNdR / lam_r[:, None, :]                       # (nel, nb, nq)
        Bt = self.N[None, :, :] / (self.R_points * lam_t)[:, None, :]
        fe = ((W * resp.tau_r)[:, None, :] * Br + (2.0 * W * resp.tau_t)[:, None, :] * Bt).sum(2)
        f = np.bincount(self.element_dofs.ravel(), fe.ravel(), minlength=self.ndof)
        if not tangent:
            return f, None, resp
        C = resp.tangent
        # d tau_i / du_b minus the geometric term, then K_ab = sum_q W (Br_a X_b + 2 Bt_a Y_b)
        X = C[0, 0][:, None, :] * Br + C[0, 1][:, None, :] * Bt - resp.tau_r[:, None, :] * Br
        Y = C[1, 0][:, None, :] * Br + C[1, 1][:, None, :] * Bt - resp.tau_t[:, None, :] * Bt
        P = Br * W[:, None, :]
        Q = Bt * (2.0 * W)[:, None, :]
        # K_ab = sum_q P_aq X_bq + sum_q Q_aq Y_bq, summed in q order (not BLAS): reproducible
        k1 = P[:, :, None, 0] * X[:, None, :, 0]
        k2 = Q[:, :, None, 0] * Y[:, None, :, 0]
        for q in range(1, P.shape[2]):
            k1 += P[:, :, None, q] * X[:, None, :, q]
            k2 += Q[:, :, None, q] * Y[:, None, :, q]
        Ke = k1 + k2
        return f, self._band(Ke), resp

    def _band(self, Ke):
        """Scatter element matrices (nel, nb, nb) into LAPACK band storage (2p+1, ndof)."""
        p = self.degree
        if not hasattr(self, "_band_index"):
            rows = np.repeat(self.element_dofs[:, :, None], self.element_dofs.shape[1], axis=2)
            cols = np.repeat(self.element_dofs[:, None, :], self.element_dofs.shape[1], axis=1)
            self._band_index = ((p + rows - cols) * self.ndof + cols).ravel()
        band = np.bincount(self._band_index, Ke.ravel(), minlength=(2 * p + 1) * self.ndof)
        return band.reshape(2 * p + 1, self.ndof)


class Discretisation(FastAssembly):
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
        See :class:`cavex.fem.constitutive.PointMaterial`.
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
        self.material = PointMaterial.from_layers(self.layers, self.point_layer, dilatancy_deg,
                                                  tension_cutoff)
        # quadrature data of the reduced rule
        self.N = np.array([np.asarray(b[0])[0] for b in self.basis.basis])  # (nb, nq)
        self.dNdR = np.array([b[0].grad[0] for b in self.basis.basis]).transpose(1, 0, 2)
        self.R_points = self.basis.mapping.F(self.basis.X)[0]  # (nel, nq)
        self.weights = self.basis.dx * forms.FOUR_PI * self.R_points ** 2
        self.force_weights = self.weights * np.maximum(
            np.abs(self.dNdR).max(axis=1), self.N.max(axis=0) / self.R_points)
        rho = np.array([m.rho for m in self.layers])[self.element_layer]
        nqm = self.mass_basis.X.shape[1]
        self._rho_mass = np.repeat(rho[:, None], nqm, axis=1)
        self.mass = self._assemble_mass()
        self.mass_band = to_banded(self.mass, degree)

    # ------------------------------------------------------------------ helpers
    def to_skfem(self, u_radial):
        """Radial-ordered dof vector in scikit-fem's order."""
        return u_radial[self.radial]

    def _assemble_mass(self):
        M = asm(forms.mass, self.mass_basis, rho=self._rho_mass)
        return M[np.argsort(self.radial)][:, np.argsort(self.radial)].tocsr()

    def new_state(self):
        """Zero plastic strains at every quadrature point."""
        shape = self.R_points.shape
        return {"theta_p": np.zeros(shape), "gamma_p": np.zeros(shape),
                "eq_p": np.zeros(shape)}

    # ------------------------------------------------------------------ kinematics
    def respond(self, u, state, g=None):
        """Return map at the points from radial dofs ``u`` (or given gradients ``g``).

        Returns ``(lambda_r, lambda_t, response)``; raises FloatingPointError if an element
        folds (a non-positive stretch).
        """
        g_r, g_t = self.displacement_gradients(u) if g is None else g
        if not (np.all(g_r > -1.0) and np.all(g_t > -1.0)):
            raise FloatingPointError("non-positive stretch")
        response = hencky_mohr_coulomb(np.log1p(g_r), np.log1p(g_t), state["theta_p"],
                                       state["gamma_p"], self.material)
        return 1.0 + g_r, 1.0 + g_t, response

    def force_scale(self, response):
        """Largest nodal force one point contributes (the yardstick of Newton's tolerance)."""
        return float(np.max((np.abs(response.tau_r) + 2.0 * np.abs(response.tau_t))
                            * self.force_weights))

    # ------------------------------------------------------------------ fast path
    def assemble_fast(self, u, state, tangent=True):
        """Internal force (radial order), banded tangent and point response, vectorised."""
        lam_r, lam_t, resp = self.respond(u, state)
        return self.assemble_response(lam_r, lam_t, resp, tangent)

    # ------------------------------------------------------------------ forms path
    def assemble_forms(self, u, state, tangent=True):
        """Same as :meth:`assemble_fast`, re-assembled from the scikit-fem forms each call."""
        field = self.basis.interpolate(self.to_skfem(u))
        lam_r, lam_t, resp = self.respond(u, state, g=(field.grad[0],
                                                       np.asarray(field) / self.R_points))
        fields = {"lam_r": lam_r, "lam_t": lam_t, "tau_r": resp.tau_r, "tau_t": resp.tau_t}
        f_sk = asm(forms.internal_force, self.basis, **fields)
        f = np.empty(self.ndof)
        f[self.radial] = f_sk
        if not tangent:
            return f, None, resp
        C = resp.tangent
        K_sk = asm(forms.tangent, self.basis, C_rr=C[0, 0], C_rt=C[0, 1], C_tr=C[1, 0],
                   C_tt=C[1, 1], **fields)
        order = np.argsort(self.radial)
        return f, to_banded(K_sk[order][:, order], self.degree), resp


def to_banded(A, p):
    """Sparse ``A`` with ``p`` sub/super-diagonals to LAPACK band storage ``(2p+1, n)``."""
    coo = A.tocoo()
    band = np.zeros((2 * p + 1, A.shape[1]))
    np.add.at(band, (p + coo.row - coo.col, coo.col), coo.data)
    return band
