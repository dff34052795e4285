"""The empirical model of Forrestal, Altman, Cargile and Hanchak (1994)
(:mod:`cavex.analytic.empirical`): ``S = 82.6 f_c^-0.544`` and a crater of two calibres."""

from cavex.analytic.models.registry import Model, register


class Forrestal1994(Model):
    name = "forrestal-1994"
    report_words = ("S = 82.6 f_c^-0.544 (f_c in MPa), crater of two calibres (Forrestal "
                    "et al. 1994). Forrestal et al. fitted S to their own shots, so on their data "
                    "it is not an out-of-sample prediction")
    predicts_shots = True
    prediction_seconds = 0.0
    empirical_reference = regime_figure = True
    marker_size = 10  # drawn larger: the reference the others are read against

    def shot_depth(self, shot, **options):
        from cavex.analytic.empirical import shot_depth

        return shot_depth(shot)


register(Forrestal1994())
