"""A measured shot as a flown model sees it: a semi-infinite target of the shot's concrete
(:func:`cavex.concrete.concrete_material` under a :class:`~cavex.concrete.Mapping`) and the
shot's tangent-ogive projectile; a shot is any object with ``mass, diameter, crh, V0, fc,
rho`` (SI units)."""

from cavex.concrete import concrete_material
from cavex.materials import Projectile, Target


def shot_target(shot, mapping=None):
    """The semi-infinite one-layer target of a shot (thick concrete)."""
    return Target((concrete_material(shot.fc, shot.rho, mapping),), ())


def shot_projectile(shot):
    """cavex's projectile for a shot (:meth:`cavex.materials.Projectile.tangent_ogive`)."""
    return Projectile.tangent_ogive(shot.mass, shot.diameter, shot.crh, shot.V0)


def flown_depth(model, shot, mapping=None, erosion=None, **options):
    """Final nose-tip depth (m) of the integrator with ``model``'s 1-D resistance (also where
    the crater stops it: ``sqrt(m V0^2 L_c / F(0))``); ``erosion``: an
    :class:`~cavex.analytic.penetration.erosion.ErosionLaw` (None: rigid), then the eroded
    nose tip's depth."""
    from cavex.analytic.penetration.concrete_table import eroding_nose
    from cavex.analytic.penetration.integrator import penetrate

    target, projectile = shot_target(shot, mapping), shot_projectile(shot)
    resistance = model.resistance(target, projectile, **options)
    nose = eroding_nose(erosion, shot, projectile)
    if nose is None:
        return float(penetrate(target, projectile, resistance).depth[-1])
    return penetrate(target, projectile, resistance, erosion=nose).erosion["tip_depth_m"]
