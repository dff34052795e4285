r"""The plain law as a 1-D resistance (``cavex penetrate --resistance law``; docs/analytic.md
"Plain law").

The wall stress is the 3-D model's plain law (:mod:`cavex.analytic.penetration.stress_laws`,
one definition): each layer's own ``sigma_n = tau_k A_k + B_k rho_k V_n^2`` (its ``law_A``,
``law_B`` keys, :class:`~cavex.analytic.penetration.stress_laws.LayerPlainLaw`) or the global
``sigma_n = A + B V_n^2`` (:class:`~cavex.analytic.penetration.stress_laws.PlainLaw`). The
axial force on the rigid ogive at normal incidence is cavex's one nose quadrature
(:func:`cavex.analytic.penetration.nose.nose_rule`, the nodes of
:func:`~cavex.analytic.penetration.nose.angle_rule`), each ring ``k`` in the layer it sits in:

.. math:: F(L, V) = \sum_k w_k\, \sigma_n(z_k, V\cos\phi_k)\, [z_k \ge 0], \qquad
          z_k = L - \xi_k, \quad \xi_k = l_n - R\cos\phi_k ,

``l_n = sqrt(2 R r - r^2)`` the ogive's length and ``xi_k`` the ring's distance behind the tip
(the 3-D body's rings at normal incidence, :func:`cavex.analytic.penetration.body.build_body`).
A ring above the surface (``z_k < 0``) carries nothing: with the crater stage (the default)
every ring is in the target when the tunnel starts (``L_c = 4.5 r + l >= l_n`` for Table 1);
without it the nose enters ring by ring, as the 3-D nose does. A ring on an interface is in
the deeper layer (as the 3-D law). In one layer, ``F = C_A + C_B V^2`` of Eqs. 13-14
(Forrestal's ``pi r^2 (A tau + N* B rho V^2)``) to the quadrature's accuracy.

The label is the layers that hold rings (``"air"`` for the rings above the surface) and
``(law)``: ``"concrete (law)"``, ``"concrete + macadam (law)"`` while the nose crosses the
interface. Inside a crossing ``F`` jumps as each ring crosses, at the tip depths
``H_j + xi_k`` (and ``xi_k`` at the surface): :attr:`PlainLawResistance.force_jumps`, where
the integrator ends a step without ending the phase (:mod:`cavex.analytic.penetration.
integrator`).
"""

import math

import numpy as np

from cavex.analytic.penetration.nose import QUADRATURE_POINTS, angle_rule, nose_rule
from cavex.analytic.penetration.resistance import Resistance
from cavex.analytic.penetration.stress_laws import plain_law
from cavex.errors import CavexInputError, require

SURFACE_NAME = "air"  # what the label calls the rings above the surface


class PlainLawResistance(Resistance):
    """The 1-D :class:`~cavex.analytic.penetration.resistance.Resistance` of the plain law
    (module docstring).

    Parameters
    ----------
    target, projectile : Target, Projectile
        Every interface bonded (the plain law has no traction-free face).
    law_A, law_B : float, optional
        The global ``sigma_n = A + B V_n^2`` (Pa, kg/m^3), both or neither; neither: each
        layer's ``law_A``, ``law_B`` keys (every layer must have them).
    points : int
        Points of the nose quadrature (default that of every 1-D resistance).
    """

    def __init__(self, target, projectile, law_A=None, law_B=None, points=QUADRATURE_POINTS):
        require(not target.debonded, "interfaces", "'bonded' for the plain law (a debonded "
                "interface needs the derived closed form's traction-free sphere)", "debonded")
        require(isinstance(points, int) and points >= 1, "points", "an integer >= 1", points)
        self.target, self.projectile = target, projectile
        self.law = plain_law(target, law_A, law_B)
        phi, _, _ = angle_rule(float(projectile.R), float(projectile.r), points)
        self._cosines, self._weights = nose_rule(projectile, points)
        # the rings' distances behind the tip, tip first (xi_k grows with phi_k)
        self._behind = projectile.ogive_length - projectile.R * np.cos(phi)
        self._normals = np.zeros((points, 3))
        self._normals[:, 2] = self._cosines  # a ring's outward normal, axial part down
        self._surface = np.zeros(points)  # every ring at the surface: in the first layer
        self._interfaces = np.asarray(target.interface_depths, dtype=float)
        self._names = target.layer_names()
        #: nose-tip depths (m) where the force jumps: a ring reaching the surface or an
        #: interface (the integrator ends a step there)
        self.force_jumps = tuple(sorted({float(H + xi) for H in (0.0, *self._interfaces)
                                         for xi in self._behind}))

    def force(self, depth, velocity):
        """Axial nose force (N) at nose-tip depth ``depth`` and velocity ``velocity``."""
        z = self._rings(depth, velocity)
        sigma = self.law.stress(z, self._normals, velocity * self._cosines)
        return float(self._weights @ np.where(z >= 0.0, sigma, 0.0))

    def label(self, depth, velocity):
        """The layers holding rings (``air`` above the surface) and ``(law)``."""
        z = self._rings(depth, velocity)
        inside = z >= 0.0
        names = [SURFACE_NAME] if not inside.all() else []
        layers = np.unique(np.searchsorted(self._interfaces, z[inside], side="right"))
        return " + ".join(names + [self._names[k] for k in layers]) + " (law)"

    def crater_force(self, velocity):
        """Force of the first layer alone, the whole nose in it (the crater stage)."""
        self._rings(0.0, velocity)
        sigma = self.law.stress(self._surface, self._normals, velocity * self._cosines)
        return float(self._weights @ sigma)

    def _rings(self, depth, velocity):
        """The rings' depths ``z_k = L - xi_k`` (m), ``depth`` and ``velocity`` checked."""
        if not (math.isfinite(depth) and depth >= 0.0):
            raise CavexInputError(f"must be a finite number >= 0 m (got {depth!r})", "depth")
        if not (math.isfinite(velocity) and velocity >= 0.0):
            raise CavexInputError(f"must be a finite number >= 0 m/s (got {velocity!r})",
                                  "velocity")
        return depth - self._behind
