r"""Normal stress on one surface element of the 3-D projectile (``docs/oblique.md``).

Every law is one compiled function of the element's depth ``z``, the vertical component
``n_z`` of its outward normal and its normal velocity ``V_n``
(:func:`element_stress`); a law object only builds the arrays that function reads
(``law.data``):

- :class:`DerivedLaw` (``DERIVED``): the layered cavity-expansion wall stress of
  :mod:`cavex.analytic.cavity` (either boundary convention) for a cavity of the shank radius
  ``a = r`` whose wall is the element. Its layer sequence is the element's own layer, then the
  layers met along the outward normal; interface ``j`` at radius ``a + d_j`` with ``d_j`` the
  distance from the element to the plane ``z = H_j`` along the normal,
  ``d_j = (H_j - z) / n_z``; for an upward normal the free surface ``z = 0`` is the
  traction-free outer sphere at ``c = a + z / (-n_z)`` (:func:`cavex.analytic.cavity.
  cavity_stress` with ``free_radius``), for a downward one a finite bottom at ``z_b`` is
  ``c = a + (z_b - z) / n_z``. A normal with ``|n_z| <= 1e-12`` sees its own layer alone.
  The element is one point of the compiled walk ``cavity._point`` (what ``cavity_stress``
  runs after checking its arguments; ``tests/test_oblique.py`` re-derives the layer sequence
  and the radii independently and compares element by element).
- :class:`PaperLaw` (``DEPTH_QUADRATIC``): the paper's printed ``sigma_r = tau A + B rho V^2``
  at the 1-D nose depth ``L = z + l - r`` (the 1-D cavity wall ahead of the cavity centre
  ``L - l`` is at ``z``): ``s_0(L) + s_2(L) V_n^2`` tabulated once on a uniform depth grid,
  linear between nodes, constant beyond its ends.
- :class:`TableLaw` (``TABLE``): the FE-tabulated ``sigma_r(V, L)`` at ``L = z + l - r`` and
  ``V = V_n``, resampled once on a uniform ``(L, V^2)`` grid through the table's own
  interpolant, then bilinear; depths outside the table take its end rows; normal velocities
  beyond its largest velocity are refused.
- :class:`PlainLaw` (``DEPTH_QUADRATIC`` on one depth): ``sigma_n = A + B V_n^2`` everywhere.
- :class:`LayerPlainLaw` (``LAYER_QUADRATIC``): each layer's own plain law (its ``law_A``,
  ``law_B`` keys), ``sigma_n = tau_k (A_k + B_k rho_k V_n^2 / tau_k)`` in the element's layer
  ``k`` (the layer holding its depth ``z``).
"""


import numpy as np
from numba import njit

from cavex.analytic.cavity import FAILED, _point, material_table
from cavex.errors import (
    CavexInputError,
    CavexNumericalError,
    is_finite_number,
    require,
    require_choice,
)
from cavex.problem import BOUNDARIES

HORIZONTAL = 1e-12  # |n_z| below which a normal counts as horizontal
FAR = 1e6  # m: interface radius standing for "never met"
DEPTH_QUADRATIC, TABLE, DERIVED, LAYER_QUADRATIC = range(4)
OK, WALK_FAILED, BEYOND_TABLE, NOT_FINITE = range(4)
_EMPTY1 = np.empty(0)
_EMPTY2 = np.empty((0, 0))
_EMPTY3 = np.empty((0, 0, 6))
_NO_COUNTS = np.empty(0, dtype=np.int64)


# ------------------------------------------------------------------------------------------
# The compiled stress of one element
# ------------------------------------------------------------------------------------------

@njit(cache=True, error_model="numpy", inline="always")
def _lerp(x, x0, dx, column, values):
    """``values[:, column]`` on the uniform grid ``x0 + i dx``, linear, constant outside."""
    f = (x - x0) / dx
    last = values.shape[0] - 1
    if f <= 0.0 or last == 0:
        return values[0, column]
    if f >= last:
        return values[last, column]
    i = int(f)
    u = f - i
    return (1.0 - u) * values[i, column] + u * values[i + 1, column]


@njit(cache=True, error_model="numpy")
def _derived(scalars, faces, tables, counts, depths, z, nz, vn, radii, zones):
    """Layered cavity-expansion wall stress of an element (see the module docstring)."""
    a, bottom, dynamic = scalars[0], scalars[2], scalars[3] > 0.0
    n = depths.shape[0] + 1
    k = np.searchsorted(depths, z, side="right")  # the element's own layer
    c = np.inf
    if nz > HORIZONTAL:  # down: layers k, k + 1, ..., then the bottom or a debonded face
        group = k
        for j in range(counts[group] - 1):
            radii[0, j] = a + min(max((depths[k + j] - z) / nz, 1e-12), FAR)
        face = min(bottom, faces[0, k])
        if face < np.inf:
            c = a + (face - z) / nz
    elif nz < -HORIZONTAL:  # up: layers k, k - 1, ..., then the free surface or an open face
        group = n + k
        for j in range(counts[group] - 1):
            radii[0, j] = a + min(max((z - depths[k - 1 - j]) / (-nz), 1e-12), FAR)
        if faces[1, k] > -np.inf:
            c = a + (z - faces[1, k]) / (-nz)
    else:
        group = 2 * n + k
    props = tables[group, :counts[group]]
    s0, s2, b, position, flags, active = _point(props, radii, 0, a, c, vn * vn, dynamic,
                                                zones, 0, False)
    if flags & FAILED:
        return np.nan, WALK_FAILED
    return s0 + s2 * vn * vn, OK


@njit(cache=True, error_model="numpy")
def element_stress(kind, scalars, values, tables, counts, depths, z, nz, vn, radii, zones):
    """``(sigma_n, status)`` of one element of any law. ``status``: ``OK``; ``WALK_FAILED``
    (``sigma_n`` NaN); ``BEYOND_TABLE`` (``sigma_n`` at the table's largest velocity).
    ``scalars`` per kind: ``DEPTH_QUADRATIC`` ``(offset, L_0, dL)`` with ``values[:, 0:2] =
    (s_0, s_2)``; ``TABLE`` ``(offset, L_0, dL, dV2)`` with ``values[i, j]`` at
    ``(L_0 + i dL, j dV2)``; ``LAYER_QUADRATIC`` ``values[k, 0:2] = (s_0, s_2)`` of layer
    ``k`` (interfaces ``depths``); ``DERIVED`` ``(a, free surface, bottom, dynamic)`` with the
    material tables of every (own layer, direction) group and ``values`` the traction-free
    faces ``(2, n)`` below and above each layer (``inf`` / ``-inf``: none). ``radii``
    ``(1, >= n - 1)`` and
    ``zones`` ``(0, 1, 2)`` are scratch."""
    if kind == DERIVED:
        return _derived(scalars, values, tables, counts, depths, z, nz, vn, radii, zones)
    if kind == LAYER_QUADRATIC:  # the element's own layer's (s_0, s_2)
        k = np.searchsorted(depths, z, side="right")
        return values[k, 0] + values[k, 1] * vn * vn, OK
    depth = z + scalars[0]
    if kind == DEPTH_QUADRATIC:
        return (_lerp(depth, scalars[1], scalars[2], 0, values)
                + _lerp(depth, scalars[1], scalars[2], 1, values) * vn * vn), OK
    # TABLE: bilinear in (L, V^2); beyond the largest velocity: that velocity's value, flagged
    fj = vn * vn / scalars[3]
    beyond = fj > values.shape[1] - 1
    if beyond:
        fj = values.shape[1] - 1.0
    fi = min(max((depth - scalars[1]) / scalars[2], 0.0), values.shape[0] - 1.0)
    i = min(int(fi), values.shape[0] - 2)
    j = min(int(fj), values.shape[1] - 2)
    u, w = fi - i, fj - j
    return ((1.0 - u) * ((1.0 - w) * values[i, j] + w * values[i, j + 1])
            + u * ((1.0 - w) * values[i + 1, j] + w * values[i + 1, j + 1])), (
                BEYOND_TABLE if beyond else OK)


@njit(cache=True, error_model="numpy")
def _stress_array(kind, scalars, values, tables, counts, depths, z, nz, vn, out):
    radii = np.empty((1, max(depths.shape[0], 1)))
    zones = np.empty((0, 1, 2))
    for i in range(z.shape[0]):
        sigma, status = element_stress(kind, scalars, values, tables, counts, depths, z[i],
                                       nz[i], vn[i], radii, zones)
        if status != OK:
            return i, status
        out[i] = sigma
    return -1, OK


def raise_for(status, vn):
    """The error of a non-OK ``status`` of :func:`element_stress` at normal velocity ``vn``."""
    if status == WALK_FAILED:
        raise CavexNumericalError("dynamic elastic-plastic boundary did not converge on a "
                                  f"surface element (V_n = {vn:.6g} m/s)")
    if status == NOT_FINITE:
        raise CavexNumericalError("the equations of motion are not finite (forces far beyond "
                                  "the projectile's mass and inertia)")
    raise CavexInputError(f"parameter 'table' must reach the normal velocity {vn:.6g} m/s of "
                          "a surface element (its velocities stop below it: build it to a "
                          "higher velocity, `cavex table --velocities`)")


class _Law:
    """A stress law: ``data = (kind, scalars, values, tables, counts, depths)``."""

    def stress(self, z, normals, vn):
        """``sigma_n`` (Pa) of elements at depths ``z`` with outward normals ``normals``
        ``(N, 3)`` and normal velocities ``vn`` (arrays; the compiled element law)."""
        z, vn = (np.ascontiguousarray(x, dtype=float) for x in (z, vn))
        nz = np.ascontiguousarray(np.asarray(normals, dtype=float)[:, 2])
        out = np.empty(z.size)
        bad, status = _stress_array(*self.data, z, nz, vn, out)
        if bad >= 0:
            raise_for(status, vn[bad])
        return out


class DerivedLaw(_Law):
    """Layered cavity-expansion stress along each element's normal (module docstring)."""

    name = "derived"

    def __init__(self, target, radius, boundary="dynamic", free_surface=True, bottom=None):
        require_choice(boundary, BOUNDARIES, "boundary")
        self.target, self.radius, self.boundary = target, float(radius), boundary
        self.free_surface, self.bottom = free_surface, bottom
        layers = target.layers
        n = len(layers)
        faces = traction_free_faces(target, free_surface)
        # groups: 0..n-1 down from layer k, n..2n-1 up from layer k, 2n..3n-1 horizontal; a
        # group ends at a debonded interface (its face is traction-free)
        below = [next((j for j in target.debonded if j >= k), n - 1) for k in range(n)]
        above = [max((j + 1 for j in target.debonded if j < k), default=0) for k in range(n)]
        sequences = ([layers[k:below[k] + 1] for k in range(n)]
                     + [layers[k:above[k] - 1 if above[k] else None:-1] for k in range(n)]
                     + [(layers[k],) for k in range(n)])
        tables = np.zeros((3 * n, n, 6))
        counts = np.array([len(s) for s in sequences], dtype=np.int64)
        for g, sequence in enumerate(sequences):
            tables[g, :counts[g]] = material_table(tuple(sequence))
        scalars = np.array([self.radius, 1.0 if free_surface else 0.0,
                            np.inf if bottom is None else float(bottom),
                            1.0 if boundary == "dynamic" else 0.0])
        self.data = (DERIVED, scalars, faces, tables, counts,
                     np.asarray(target.interface_depths, dtype=float))


def traction_free_faces(target, free_surface=True):
    """``(2, n)``: for each layer the depth of the traction-free face its downward normals
    meet, the first debonded interface below (``inf``: none), and that its upward normals
    meet, the last debonded interface above, else the free surface ``0`` (``-inf`` without
    ``free_surface``)."""
    depths, n = target.interface_depths, len(target.layers)
    faces = np.empty((2, n))
    for k in range(n):
        faces[0, k] = next((depths[j] for j in target.debonded if j >= k), np.inf)
        faces[1, k] = max((depths[j] for j in target.debonded if j < k),
                          default=0.0 if free_surface else -np.inf)
    return faces


class PaperLaw(_Law):
    """The paper's printed model at the mapped nose depth (module docstring); the grid
    ``spacing`` smears its case switches, where the printed coefficients jump, over one cell."""

    name = "paper"

    def __init__(self, target, projectile, epsilon="quasi-static", spacing=2e-4, extent=None):
        from cavex.analytic.paper_model import PaperModel

        model = PaperModel(target, projectile, epsilon)
        deepest = (target.interface_depths[-1] if target.interface_depths else 0.0) + 0.5
        grid = np.arange(0.0, (extent or deepest) + spacing, spacing)
        terms = [model.terms(float(L)) for L in grid]
        values = np.array([[t[2] * t[0], t[1] * t[3]] for t in terms])
        self.data = (DEPTH_QUADRATIC, np.array([projectile.l - projectile.r, 0.0, spacing]),
                     values, _EMPTY3, _NO_COUNTS, _EMPTY1)


class TableLaw(_Law):
    """FE-tabulated ``sigma_r(V, L)`` (a :class:`~cavex.analytic.penetration.tabulated.
    TabulatedResistance`) resampled on a uniform ``(L, V^2)`` grid (module docstring)."""

    name = "table"

    def __init__(self, resistance, depth_points=600, velocity_points=121, extent=None):
        p = resistance.projectile
        lo = float(resistance.depths[0])
        hi = max(float(resistance.depths[-1]), lo + 1e-3) if extent is None else extent
        grid = np.linspace(lo, hi, depth_points)
        v2 = np.linspace(0.0, float(resistance.velocities[-1]) ** 2, velocity_points)
        values = np.array([resistance.wall_stress(L, np.sqrt(v2)) for L in grid])
        self.data = (TABLE, np.array([p.l - p.r, lo, grid[1] - grid[0], v2[1]]), values,
                     _EMPTY3, _NO_COUNTS, _EMPTY1)


MAX_LAW_A = 1e12  # Pa
MAX_LAW_B = 1e6  # kg/m^3


class PlainLaw(_Law):
    """``sigma_n = A + B V_n^2`` (A in Pa, B in kg/m^3) everywhere in the target."""

    name = "law"

    def __init__(self, A, B):
        # the upper bounds are far beyond any target (1 TPa; 40 times the densest solid) and
        # keep the forces finite: 1e40 Pa stalls the integrator, 1e100 Pa overflows it
        for name, value, top, unit in (("law_A", A, MAX_LAW_A, "Pa"),
                                       ("law_B", B, MAX_LAW_B, "kg/m^3")):
            require(is_finite_number(value) and 0.0 <= value <= top, name,
                    f"in [0, {top:g}] {unit}", value)
        self.A, self.B = float(A), float(B)
        self.data = (DEPTH_QUADRATIC, np.array([0.0, 0.0, 1.0]), np.array([[self.A, self.B]]),
                     _EMPTY3, _NO_COUNTS, _EMPTY1)


class LayerPlainLaw(_Law):
    """Each layer's plain law ``S_k = A_k + B_k rho_k V_n^2 / tau_k`` (the target's
    ``plain_laws``, the layers' ``law_A``, ``law_B`` keys): ``sigma_n = tau_k S_k`` in the
    element's own layer (module docstring)."""

    name = "law"

    def __init__(self, target):
        for i, law in enumerate(target.plain_laws):
            if law is None:
                raise CavexInputError("must be given on every layer for --resistance law "
                                      "without --law-A/--law-B (the plain law S = A + B rho "
                                      "V^2 / tau of each layer)", f"layers[{i}].law_A")
        values = np.array([[m.tau * A, B * m.rho] for m, (A, B)
                           in zip(target.layers, target.plain_laws, strict=True)])
        self.data = (LAYER_QUADRATIC, np.zeros(1), values, _EMPTY3, _NO_COUNTS,
                     np.asarray(target.interface_depths, dtype=float))


def plain_law(target, law_A=None, law_B=None):
    """The plain law: the global ``sigma_n = A + B V_n^2`` (:class:`PlainLaw`, both given),
    else each layer's own (:class:`LayerPlainLaw`, neither given)."""
    if law_A is None and law_B is None:  # each layer's own law_A, law_B
        return LayerPlainLaw(target)
    require(law_A is not None and law_B is not None, "law_A", "given with law_B for "
            "--resistance law", law_A)
    return PlainLaw(law_A, law_B)
