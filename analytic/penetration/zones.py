r"""The one crater definition and the rear zone of a debonded interface (1-D and 3-D models).

Entry crater and interface crater (paper Eqs. 31-34, docs/analytic.md "Debonded interfaces"):
a crater stage starts where the nose tip meets a fresh face of a layer, the free surface
``z = 0`` or a debonded interface ``z = H_j``, and lasts for the nose tip's travel

.. math:: L_c = 4.5\,r + l \ (\text{"nose-base"}) \quad\text{or}\quad L_c = 4.5\,r
          \ (\text{"nose-tip"}),

the paper's crater depth ``4.5 r`` measured from the nose base or from the nose tip.

Rear zone of the layer above a debonded interface at ``H_j``: the band
``H_j - s_j <= z <= H_j`` that scabs off the layer's traction-free rear face. Its depth
``s_j`` is the layer's ``scab_depth`` key, by default

.. math:: s = 2.12\,d \quad (d = 2 r),

the part of the modified NDRC scabbing thickness that does not grow with the penetration depth
``x``: Kennedy (1976), Nucl. Eng. Des. 37, 183-203, as given in DOE-STD-3014, Appendix C,
Eq. C-65, ``t_s / d = 2.12 + 1.36 x / d`` (``0.65 <= x/d <= 11.75``), so that the scabbed zone
beyond the penetration depth is ``t_s - x = 2.12 d + 0.36 x``. A projectile that goes on
through the interface has no "penetration depth" in the layer, so the rule keeps the
thinnest zone the formula allows; it is not calibrated for runway layers and is a setting.

3-D zones (:func:`open_zones`): every crater band ``[F, F + L_c]`` below a fresh face ``F`` and
every rear zone; a zone *opens* when the nose tip crosses its top (an event of the compiled
integrator), after which the shank's elements inside it carry no load (the crater and the
scab are wider than the shank: no tunnel wall there).
"""

from cavex.errors import require_choice

CRATER_MODES = ("nose-base", "nose-tip")
CRATER_RATIO = 4.5
#: rear-zone depth in calibres (shank diameters): the constant of the modified NDRC scabbing
#: thickness (module docstring)
SCAB_CALIBRES = 2.12
STAGES = ("crater", "tunnel", "rear face")


def crater_depth(projectile, crater="nose-base", ratio=CRATER_RATIO):
    """Nose-tip travel ``L_c`` (m) of a crater stage from the face it starts at (``ratio``: the
    crater depth in shank radii, the paper's 4.5; a sensitivity setting of the 3-D study)."""
    require_choice(crater, CRATER_MODES, "crater")
    length = ratio * projectile.r
    return length + projectile.l if crater == "nose-base" else length


def scab_depth(target, projectile, j):
    """Depth ``s_j`` (m) of the rear zone above interface ``j`` (from 0): the layer's
    ``scab_depth``, else ``SCAB_CALIBRES`` shank diameters, at most the layer's thickness."""
    given = target.scab_depths[j]
    if given is not None:
        return given
    return min(SCAB_CALIBRES * 2.0 * projectile.r, target.thicknesses[j])


def open_zones(target, projectile, crater="nose-base", entry=False, ratio=CRATER_RATIO):
    """``[(top, bottom), ...]`` (m) of the 3-D model's zones, each opening when the nose tip
    crosses ``top``: for every debonded interface ``H_j`` the rear zone ``[H_j - s_j, H_j]``
    and the crater ``[H_j, H_j + L_c]``; with ``entry`` the entry crater ``[0, L_c]``. The
    crater bands are cut at the next interface."""
    zones = [(0.0, min(crater_depth(projectile, crater, ratio), *target.interface_depths[:1],
                       float("inf")))] if entry else []
    depths = target.interface_depths
    for j in target.debonded:
        H = depths[j]
        below = depths[j + 1] if j + 1 < len(depths) else float("inf")
        zones.append((H - scab_depth(target, projectile, j), H))
        zones.append((H, min(H + crater_depth(projectile, crater, ratio), below)))
    return zones


def union(zones):
    """The zones ``[(top, bottom), ...]`` as disjoint intervals sorted by depth (touching or
    overlapping zones merged): a shank element's length without tunnel wall is its overlap
    with their union, which these intervals give as a sum (a rear zone and the crater below
    it meet at the interface; an element straddling the plane has no wall on either side)."""
    merged = []
    for top, bottom in sorted(zones):
        if merged and top <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], bottom))
        else:
            merged.append((top, bottom))
    return merged
