"""Li and Chen (2003) for normal-strength concrete (``f_c <= 100 MPa``), the concrete model
above: a comparison model of ``cavex validate`` (docs/validation.md; no constant fitted to any
shot, but the split chosen on the development shots). It was the recommended model until the
cross-validation (issue 31) showed that the choice does not transfer; the recommended model is
now the concrete model alone.

Li and Chen fitted ``S = 72 f_c^-1/2`` to published shots; above 100 MPa, on the development
shots, it over-predicts depths threefold (bias +1.10), the concrete model, whose strength is
capped at ``7 f_c`` from its correlations, twofold (+0.68).

The choice made on shots is which part predicts on each side of :data:`SPLIT_STRENGTH`
(:data:`OPTIONS`: every pair of its parts, ``"<below> | <above>"``); ``cavex validate
--cross-validate`` makes it again without each fold."""

from itertools import product

from cavex.analytic.models.registry import Model, get, register, require_option

#: f_c (Pa) above which the model leaves Li and Chen's formula for the concrete model: the
#: upper bound of normal strength in the validation's regimes
SPLIT_STRENGTH = 100e6
PARTS = ("li-chen-2003", "concrete")
#: ``"<below> | <above>"``: the part below and above the split, every pair of the parts
OPTIONS = tuple(f"{below} | {above}" for below, above in product(PARTS, PARTS))


class LiChenConcrete(Model):
    name = "li-chen-concrete"
    report_words = ("`li-chen-2003` for f_c <= 100 MPa, `concrete` above (no constant "
                    "fitted; the split chosen on the development shots, docs/validation.md)")
    recommendation_reason = ("`li-chen-2003` at normal strength, f_c <= 100 MPa, `concrete` "
                             "above, each where it is the better on the development shots; "
                             "no constant fitted by cavex")
    predicts_shots = True
    parts = PARTS  # the models that predict its shots, each on one side of SPLIT_STRENGTH
    options = OPTIONS
    option = OPTIONS[1]  # Li and Chen below, the concrete model above
    option_words = "which part predicts below and above 100 MPa"
    prediction_seconds = 6.3e-3
    concrete_table_seconds = 2.3  # the concrete model's, for its shots above 100 MPa

    def part(self, shot, option=None):
        """The model that predicts ``shot`` under ``option`` (default :attr:`option`): the
        option's first part up to :data:`SPLIT_STRENGTH`, its second above."""
        option = self.option if option is None else option
        require_option(self, option)
        return get(option.split(" | ")[shot.fc > SPLIT_STRENGTH])

    def shot_depth(self, shot, option=None, **options):
        return self.part(shot, option).shot_depth(shot, **options)


register(LiChenConcrete())
