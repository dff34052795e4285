"""A toy resistance model, the worked example of docs/models.md: a constant normal stress
``sigma_n = p`` on the nose, in every layer, at every velocity (a "constant-pressure" target).

One module is the whole model: it declares what it offers (a 1-D resistance, a 3-D stress law,
the depth of a measured shot) and registers itself. Importing this file makes it a choice of
``cavex penetrate --resistance``, ``cavex trajectory --resistance`` and ``cavex validate
--models`` in that process; a model of cavex's own is one module in ``analytic/models/`` and one
import line in ``analytic/models/__init__.py``.

With a constant stress the axial nose force is ``F = p pi r^2`` (the ogive's projected area),
so the 1-D depth has a closed form that ``tests/test_model_registry.py`` checks the integrator
against: over the crater stage (``F = K L`` up to ``L_c``, ``K L_c = F``) the projectile loses
``L_c F / 2`` of kinetic energy, then ``F`` over the tunnel, so ``m V0^2 / 2 = F (L - L_c/2)``:

.. math:: L = \\frac{m V_0^2}{2 F} + \\frac{L_c}{2}\\qquad (m V_0^2 > L_c F).
"""

from cavex.analytic.models.registry import Model, register

PRESSURE = 400e6  # Pa


class ConstantPressure(Model):
    name = "toy-constant-pressure"
    help = "a constant normal stress (the toy model)"
    flies = flies_3d = predicts_shots = True

    def resistance(self, target, projectile, **options):
        from cavex.analytic.penetration.plain_law import PlainLawResistance

        return PlainLawResistance(target, projectile, PRESSURE, 0.0)

    def stress_law(self, target, projectile, **options):
        from cavex.analytic.penetration.stress_laws import PlainLaw

        return PlainLaw(PRESSURE, 0.0)

    def shot_depth(self, shot, **options):
        from cavex.analytic.models.shots import flown_depth

        return flown_depth(self, shot)


MODEL = register(ConstantPressure())
