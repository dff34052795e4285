"""The concrete cavity-expansion model (docs/concrete.md): the self-similar cavity in concrete
(cracked, crushed and compacting zones, a strength cap) from published correlations with
``f_c`` (:mod:`cavex.concrete`), tabulated per concrete and flown through Li and Chen's
crater (:mod:`cavex.analytic.penetration.concrete_table`). A model of measured shots only: its
material is its own, not the Mohr-Coulomb mapping."""

from cavex.analytic.models.registry import Model, register


class Concrete(Model):
    name = "concrete"
    report_words = ("the concrete cavity-expansion model (docs/concrete.md): Mohr-Coulomb "
                    "capped at 7 f_c, radial cracking, compaction to lock-up, every constant "
                    "published (none fitted to shots), its own crater (Li and Chen 2003); it does "
                    "not use the mapping below")
    recommendation_reason = "uncalibrated, every constant published, none fitted to shots"
    predicts_shots = regime_figure = True
    erodes = True
    prediction_seconds = 6.3e-3  # the integrator a shot, besides its table (docs/concrete.md)
    # one concrete's table of 33 cavity solutions: docs/concrete.md measured 15 s for the 96
    # tables of the development shots (0.16 s each)
    concrete_table_seconds = 0.2

    def shot_depth(self, shot, *, constants=None, erosion=None, **options):
        from cavex.analytic.penetration.concrete_table import model_depth

        return model_depth(shot, constants, erosion)


register(Concrete())
