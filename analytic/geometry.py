"""From nose depth in a plane layered target to the concentric spherical problem.

The cavity centre sits at the nose base, depth ``L - l`` below the free surface, and the cavity
radius is the shank radius ``r``. A plane interface at depth ``H_i`` becomes a sphere of radius
``h_i = H_i - L + l`` (paper Eq. 16). A layer stops surrounding the cavity when

- ``switch="cavity"`` (derived model): its outer interface reaches the cavity, ``h_i <= r``;
- ``switch="nose-tip"`` (the paper): the nose tip crosses its lower face, ``L >= H_i``.
"""

import math

from cavex.errors import require, require_choice

SWITCHES = ("cavity", "nose-tip")


def spherical_problem(target, projectile, depth, switch="cavity"):
    """``(layers, interfaces)`` of the spherical problem at nose-tip depth ``depth`` (m)."""
    require(math.isfinite(depth) and depth >= 0.0, "depth", "a finite number >= 0", depth)
    require_choice(switch, SWITCHES, "switch")
    first, radii = surrounding(target.interface_depths, projectile, depth, switch)
    return target.layers[first:], radii


def surrounding(interface_depths, projectile, depth, switch):
    """``(first, radii)``: index of the layer at the cavity wall and the interface radii of the
    layers that surround the cavity, for validated arguments (the integrator's hot path)."""
    radii = [H - depth + projectile.l for H in interface_depths]
    if switch == "cavity":
        first = sum(1 for h in radii if h <= projectile.r)
    else:
        first = sum(1 for H in interface_depths if depth >= H)
    return first, radii[first:]


def wall_layer(target, projectile, depth, switch="cavity"):
    """Index in ``target.layers`` of the layer at the cavity wall at nose depth ``depth``."""
    layers, _ = spherical_problem(target, projectile, depth, switch)
    return len(target.layers) - len(layers)


def switch_depths(target, projectile):
    """Nose depths ``H_i + l - r`` where the wall layer changes (``switch="cavity"``)."""
    return tuple(H + projectile.l - projectile.r for H in target.interface_depths)
