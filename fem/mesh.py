"""Radial meshes: geometric grading in the final configuration, mapped to the reference one.

The mesh is designed where the answer is read, at the final cavity radius ``a``: element
boundaries are spaced uniformly in ``ln r`` between the wall and each interface, and between the
last interface and the outer boundary, so that every element spans the same ratio
``r_out/r_in``. Each final radius ``r`` is then mapped to the reference configuration (cavity
seed radius ``a0``) by incompressibility, ``R^3 = r^3 - a^3 + a0^3`` (exact for incompressible
material, so interfaces land exactly where they are asked to be).
"""

import math

import numpy as np
from skfem import MeshLine


def log_spaced(r_in, r_out, elements_per_decade):
    """Radii from ``r_in`` to ``r_out`` (both included), uniform in ``ln r``."""
    n = max(1, math.ceil(elements_per_decade * math.log10(r_out / r_in) - 1e-9))
    return np.geomspace(r_in, r_out, n + 1)


def final_vertices(radius, interfaces, outer_radius, elements_per_decade):
    """Vertex radii in the final configuration, with a vertex on every interface."""
    anchors = [radius, *[h for h in interfaces if h < outer_radius], outer_radius]
    pieces = [log_spaced(lo, hi, elements_per_decade) for lo, hi in zip(anchors, anchors[1:],
                                                                          strict=False)]
    return np.concatenate([pieces[0]] + [p[1:] for p in pieces[1:]])


def to_reference(r, radius, seed_radius):
    """Reference radius ``R`` of material at ``r`` when the cavity is ``radius``, incompressible."""
    return np.cbrt(np.asarray(r, dtype=float) ** 3 - radius ** 3 + seed_radius ** 3)


def reference_mesh(radius, seed_radius, interfaces, outer_radius, elements_per_decade):
    """Reference ``MeshLine`` and the vertex indices of the interfaces.

    Returns
    -------
    mesh : skfem.MeshLine
    interface_vertices : list of int
        Index of the vertex on each interface that lies inside the mesh (in order).
    """
    r = final_vertices(radius, interfaces, outer_radius, elements_per_decade)
    R = to_reference(r, radius, seed_radius)
    R[0] = seed_radius
    interface_vertices = [int(np.argmin(abs(r - h))) for h in interfaces if h < outer_radius]
    return MeshLine(R), interface_vertices


def element_layers(mesh, interface_vertices):
    """Layer index of each element (layer ``i`` lies between interface vertices ``i-1``, ``i``)."""
    first_vertex = mesh.t[0]
    return np.searchsorted(np.asarray(interface_vertices), first_vertex, side="right")
