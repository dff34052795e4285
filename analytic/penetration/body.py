r"""The rigid projectile of the 3-D trajectory model: geometry, mass properties, surface.

Body frame: origin at the centre of mass, ``e1`` along the axis from tail to nose, ``e2``,
``e3`` transverse. The tangent ogive of shank radius ``r`` and ogive radius ``R`` (the same
``(R, r)`` as :mod:`cavex.analytic.penetration.nose`) has length ``l_n = sqrt(2 R r - r^2)``; a
point of the ogive is given by the angle ``phi`` of its outward normal from the axis, from
``phi_0 = asin((R - r)/R)`` at the tip to ``pi/2`` at the shoulder:

- distance from the tip ``xi = l_n - R cos(phi)``, radius ``rho = R sin(phi) - (R - r)``,
- outward normal ``n = (cos(phi), sin(phi) cos(theta), sin(phi) sin(theta))``,
- area ``dA = R rho dphi dtheta``.

The shank is the cylinder ``rho = r`` from ``l_n`` to the overall length, normal
``(0, cos(theta), sin(theta))``. The flat tail face is not discretised (it faces backwards:
it meets target material only in a tail slap or a ricochet, outside this model).

Surface quadrature: Gauss-Legendre in ``phi`` (:func:`cavex.analytic.penetration.nose.angle_rule`,
the rule of the 1-D nose force :func:`~cavex.analytic.penetration.nose.nose_rule`, which with
its 8 points gives the 1-D nose force to round-off in an axisymmetric stress field; the 3-D
default is 16 points: at 8 the turn at a debonded interface is a discretisation artefact,
docs/oblique.md "Convergence"), the midpoint rule in ``theta``
and in the shank's axial coordinate. The azimuths are placed in mirror pairs
``theta_k = (k + 1/2) 2 pi / n`` and ``-theta_k`` (computed as the negative, so that the pair's
coordinates are exact mirrors); ``partners`` maps each element to its mirror image. Each
element carries its centroid, normal and area, and its spans: how its normal and position
change across it in ``phi`` (or the shank's axial coordinate) and in ``theta``, from which
the force law reads the element's extent in depth and in normal velocity
(:mod:`cavex.analytic.penetration.surface_force`, "Fractions").

Mass properties: ``m`` is given; ``cg`` (from the tip) and the transverse inertia ``I_t``
about the centre of mass are taken from the projectile when given, else computed for a solid
body of uniform density ``m / volume``; the axial inertia ``I_a`` is always the uniform solid's
(scaled by ``m``), since the config has no key for it.
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad

from cavex.analytic.penetration.nose import angle_rule
from cavex.errors import require

NOSE_POINTS = 16  # Gauss points in phi; convergence: docs/oblique.md "Convergence"
AZIMUTHS = 16
SHANK_RINGS = 16
#: the most points a body takes in each direction (512 x 512 nose elements: ~0.1 GB of
#: element arrays); beyond, a run would exhaust memory before it answered
MAX_POINTS = 512


@dataclass(frozen=True)
class Body:
    """Mass properties and surface elements of a rigid projectile (body frame, SI units).

    Attributes
    ----------
    mass, length, nose_length, radius : float
    cg : float
        Centre of mass, m from the nose tip.
    inertia_axial, inertia_transverse : float
        Moments of inertia about the centre of mass (kg m^2).
    points, normals : ndarray, shape (n, 3)
        Element centroids relative to the centre of mass and outward unit normals.
    areas : ndarray, shape (n,)
    spans : ndarray, shape (n, 5, 3)
        How the element's normal and position change across it, in its two surface
        directions: ``(dn_a, dp_a, dn_b, dp_b)``, ``a`` along ``phi`` (the ogive; the axis on the
        shank) and ``b`` along ``theta``, each the derivative times the element's extent
        (body frame), the extent being the node's cell (for the Gauss rule in ``phi`` the
        consecutive intervals of the weights' widths, each holding its node off centre);
        row 4 holds ``(|dn_a| + |dn_b|, |dp_a| + |dp_b|, e)``, bounds on the changes across
        the element in any frame and the offset ``e`` of the cell's centre from the node
        along ``a`` per cell width (0 on the shank and in ``theta``). The force law
        reads the element's extent in depth and in normal velocity from them
        (:mod:`cavex.analytic.penetration.surface_force`, "Fractions").
    nose : ndarray of bool, shape (n,)
        True for the ogive's elements.
    partners : ndarray of int, shape (n,)
        Index of each element's mirror image ``theta -> -theta`` (itself on the mirror
        plane).
    outline : ndarray, shape (k, 2)
        Half-profile ``(axial coordinate from the cg, radius)`` from tip to tail, for drawing.
    """

    mass: float
    length: float
    nose_length: float
    radius: float
    cg: float
    inertia_axial: float
    inertia_transverse: float
    points: np.ndarray
    normals: np.ndarray
    areas: np.ndarray
    spans: np.ndarray
    nose: np.ndarray
    partners: np.ndarray
    outline: np.ndarray
    #: ``(nose_points, azimuths, shank_rings)`` of the surface rule
    shape: tuple = (0, 0, 0)

    @property
    def inertia(self):
        """Diagonal of the inertia tensor in the body frame ``(I_a, I_t, I_t)``."""
        return np.array([self.inertia_axial, self.inertia_transverse, self.inertia_transverse])

    @property
    def tip(self):
        """Nose tip in the body frame."""
        return np.array([self.cg, 0.0, 0.0])

    @property
    def axial_half_extent(self):
        """Half the largest extent (m) of an element along the axis: a nose tip deeper than
        ``nose_length`` plus this below a face has the whole nose below it at normal
        incidence."""
        return 0.5 * float(np.max(np.abs(self.spans[:, 1, 0]) + np.abs(self.spans[:, 3, 0])))

    @property
    def elements(self):
        return self.areas.size


def profile_radius(projectile, xi):
    """Body radius (m) at distance ``xi`` from the nose tip (array)."""
    r, R = projectile.r, projectile.R
    ln = projectile.ogive_length
    xi = np.asarray(xi, dtype=float)
    x = np.clip(ln - xi, 0.0, None)  # distance ahead of the shoulder
    return np.where(xi < ln, np.sqrt(np.maximum(R * R - x * x, 0.0)) - (R - r), r)


def uniform_mass_properties(projectile, length):
    """``(volume, cg from the tip, I_axial, I_transverse about the cg)`` of the solid of
    revolution with uniform density and mass ``projectile.m`` (adaptive quadrature of the
    profile, to 1e-12 relative)."""
    ln = projectile.ogive_length

    def integral(f):
        return (quad(lambda x: f(x, float(profile_radius(projectile, x))), 0.0, ln,
                     epsabs=0.0, epsrel=1e-13)[0]
                + quad(lambda x: f(x, projectile.r), ln, length, epsabs=0.0,
                       epsrel=1e-13)[0])

    volume = integral(lambda x, rho: math.pi * rho * rho)
    density = projectile.m / volume
    cg = integral(lambda x, rho: x * math.pi * rho * rho) / volume
    axial = density * integral(lambda x, rho: 0.5 * math.pi * rho ** 4)
    transverse = density * integral(
        lambda x, rho: math.pi * rho * rho * (rho * rho / 4.0 + (x - cg) ** 2))
    return volume, cg, axial, transverse


def _with_reach(spans, offsets):
    """``spans`` (n, 4, 3) with the row ``(|dn_a| + |dn_b|, |dp_a| + |dp_b|, e)`` appended
    (:class:`Body`)."""
    length = np.linalg.norm(spans, axis=-1)
    reach = np.stack([length[:, 0] + length[:, 2], length[:, 1] + length[:, 3], offsets], -1)
    return np.ascontiguousarray(np.concatenate([spans, reach[:, None, :]], axis=1))


def build_body(projectile, nose_points=NOSE_POINTS, azimuths=AZIMUTHS, shank_rings=SHANK_RINGS):
    """The :class:`Body` of ``projectile`` with ``nose_points`` Gauss points in ``phi``,
    ``azimuths`` in ``theta`` and ``shank_rings`` rings along the shank."""
    for name, value, low in (("nose_points", nose_points, 1), ("azimuths", azimuths, 4),
                             ("shank_rings", shank_rings, 1)):
        require(isinstance(value, int) and not isinstance(value, bool) and low <= value
                <= MAX_POINTS, name, f"an integer in [{low}, {MAX_POINTS}]", value)
    r, R = projectile.r, projectile.R
    ln = projectile.ogive_length
    length = projectile.body_length
    _, cg_uniform, axial, transverse = uniform_mass_properties(projectile, length)
    cg = projectile.cg if projectile.cg is not None else cg_uniform
    if projectile.inertia is not None:
        transverse = projectile.inertia
    phi, weights, jacobian = angle_rule(float(R), float(r), nose_points)
    dphi = weights * jacobian
    # the nodes' cells: consecutive intervals of the weights' widths from phi_0 to pi/2 (each
    # node lies in its own, not at its centre: the centre's offset from the node per width)
    lower = math.asin((R - r) / R) + np.concatenate([[0.0], np.cumsum(dphi)[:-1]])
    offset = (lower + 0.5 * dphi - phi) / dphi
    k = np.arange(azimuths)
    half = (k + 0.5 < 0.5 * azimuths)
    theta = np.where(half, (k + 0.5) * 2.0 * math.pi / azimuths,
                     -((azimuths - k - 0.5) * 2.0 * math.pi / azimuths))
    mirror = azimuths - 1 - k  # theta_mirror = -theta
    dtheta = 2.0 * math.pi / azimuths
    P, T = np.meshgrid(phi, theta, indexing="ij")
    DP = np.broadcast_to(dphi[:, None], P.shape)
    rho = R * np.sin(P) - (R - r)
    xi = ln - R * np.cos(P)
    nose_pts = np.stack([cg - xi, rho * np.cos(T), rho * np.sin(T)], -1).reshape(-1, 3)
    nose_nrm = np.stack([np.cos(P), np.sin(P) * np.cos(T), np.sin(P) * np.sin(T)],
                        -1).reshape(-1, 3)
    nose_area = (R * rho * DP * dtheta).ravel()
    # the element's extent: d n / d phi dphi, d p / d phi = R d n / d phi, d n / d theta dtheta,
    # d p / d theta dtheta
    dn_a = np.stack([-np.sin(P), np.cos(P) * np.cos(T), np.cos(P) * np.sin(T)], -1) * DP[..., None]
    dn_b = np.stack([np.zeros_like(P), -np.sin(P) * np.sin(T), np.sin(P) * np.cos(T)],
                    -1) * dtheta
    dp_b = np.stack([np.zeros_like(P), -rho * np.sin(T), rho * np.cos(T)], -1) * dtheta
    nose_spans = np.stack([dn_a, R * dn_a, dn_b, dp_b], -2).reshape(-1, 4, 3)
    nose_offsets = np.broadcast_to(offset[:, None], P.shape).ravel()
    dx = (length - ln) / shank_rings
    xs = ln + (np.arange(shank_rings) + 0.5) * dx
    X, T2 = np.meshgrid(xs, theta, indexing="ij")
    shank_pts = np.stack([cg - X, r * np.cos(T2), r * np.sin(T2)], -1).reshape(-1, 3)
    shank_nrm = np.stack([np.zeros_like(X), np.cos(T2), np.sin(T2)], -1).reshape(-1, 3)
    shank_area = np.full(X.size, r * dtheta * dx)
    around = np.stack([np.zeros_like(X), -np.sin(T2), np.cos(T2)], -1) * dtheta
    along = np.broadcast_to(np.array([-dx, 0.0, 0.0]), around.shape)
    shank_spans = np.stack([np.zeros_like(around), along, around, r * around],
                           -2).reshape(-1, 4, 3)
    xi_line = np.concatenate([np.linspace(0.0, ln, 40), [length]])
    outline = np.stack([cg - xi_line, profile_radius(projectile, xi_line)], -1)
    return Body(
        mass=float(projectile.m), length=float(length), nose_length=ln, radius=float(r),
        cg=float(cg), inertia_axial=float(axial), inertia_transverse=float(transverse),
        points=np.concatenate([nose_pts, shank_pts]),
        normals=np.concatenate([nose_nrm, shank_nrm]),
        areas=np.concatenate([nose_area, shank_area]),
        spans=_with_reach(np.concatenate([nose_spans, shank_spans]),
                          np.concatenate([nose_offsets, np.zeros(len(shank_spans))])),
        nose=np.concatenate([np.ones(nose_area.size, bool), np.zeros(shank_area.size, bool)]),
        partners=np.concatenate([(ring * azimuths + mirror[None, :]).ravel()
                                 for ring in (np.arange(nose_points)[:, None],
                                              nose_points + np.arange(shank_rings)[:, None])]),
        outline=outline, shape=(nose_points, azimuths, shank_rings))
