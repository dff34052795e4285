"""Li and Chen's (2003) empirical formula: Forrestal's form with ``S = 72 f_c^-0.5`` and the
crater ``0.707 + h/d`` calibres (:func:`cavex.analytic.empirical.li_chen_depth`)."""

from cavex.analytic.models.registry import Model, register


class LiChen2003(Model):
    name = "li-chen-2003"
    report_words = ("S = 72 f_c^-0.5 (f_c in MPa), crater 0.707 + h/d calibres (Li and Chen "
                    "2003, fitted by them to published shots)")
    predicts_shots = True
    prediction_seconds = 0.0
    regime_figure = True

    def shot_depth(self, shot, **options):
        from cavex.analytic.empirical import li_chen_depth

        return li_chen_depth(shot)


register(LiChen2003())
