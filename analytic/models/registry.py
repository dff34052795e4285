"""The registry of resistance models: every model cavex can fly, compare or validate, by name.

A model is one module of :mod:`cavex.analytic.models` that defines a :class:`Model` and
registers it (``register(MyModel())``), plus one line in the package's ``__init__`` that
imports the module. What a model offers is declared on the object (MOOSE's "an object declares
its own parameters"):

- ``resistance(target, projectile, **options)``: the 1-D resistance the integrator flies
  (:class:`cavex.analytic.penetration.resistance.Resistance`), where ``flies``;
- ``stress_law(target, projectile, **options)``: the 3-D normal-stress law of the oblique
  model (:mod:`cavex.analytic.penetration.stress_laws`), where ``flies_3d``;
- ``wall_stress(target, projectile, depth, velocity, **options)``: the closed form's cavity
  wall stress at one nose depth (``cavex stress``), where ``closed_form``;
- ``shot_depth(shot, **options)``: the depth (m) of a measured shot (``cavex validate``;
  ``erosion``, an :class:`~cavex.analytic.penetration.erosion.ErosionLaw` or None, is taken
  by the models that fly the 1-D integrator and ignored by the empirical formulas),
  where ``predicts_shots``; a shot is any object with ``mass, diameter, crh, V0, fc, rho``;
- its options (``boundaries``, ``takes_table``, ``takes_epsilon``, ``takes_law``) and their
  checks (:meth:`Model.check`), its label(s) (:meth:`Model.label`) and its words
  (:meth:`Model.describe`).

Everything that offers or compares models (the command line's choices, the labels in JSON, CSV
and reports, ``validate``'s columns, ``calibrate``) reads this registry; no other code compares
model names. The modules stay light: a model imports its numerical code (numba, scipy) only
when it computes, so that the command line can list the choices and refuse bad input first.
"""

from cavex.errors import CavexInputError, require, require_choice
from cavex.problem import BOUNDARIES

_REGISTRY = {}  # name -> Model, in registration order (the order of validate's columns)


class Model:
    """A resistance model (subclass it, set the class attributes, implement what it offers).

    Attributes
    ----------
    name : str
        Its ``--resistance`` choice (where it flies) or ``--models`` label.
    help : str
        A phrase for ``--resistance``'s help.
    flies, flies_3d : bool
        Has a 1-D resistance (``penetrate``, ``calibrate``), a 3-D stress law
        (``trajectory``).
    closed_form : bool
        A closed form of the cavity wall stress (``stress``; the incompressible closed forms).
    predicts_shots : bool
        ``cavex validate`` predicts with it.
    fits_mapping : bool
        Its material comes from the ``(f_c, rho)`` mapping (:class:`cavex.concrete.Mapping`),
        which ``cavex calibrate`` can fit.
    boundaries : tuple of str
        The yield-at-boundary conventions it offers (``--boundary``), in the order of its
        labels; empty: no choice.
    default_boundary : str or None
        The convention without ``--boundary`` (also what a model with no choice runs with).
    debonded : bool
        Models a debonded interface (a traction-free rear face).
    free_surface_option : bool
        Its 3-D law reduces the wall stress near the free surface (``--no-free-surface``
        turns that off).
    takes_table, takes_epsilon, takes_law : bool
        Its options ``--table FILE``, ``--epsilon``, ``--law-A/--law-B``.
    first_layer : str or None
        The model that flies the first layer alone beside a layered run (``penetrate``'s
        comparison); None: the model itself.
    recommended : bool
        ``cavex validate``'s recommended model (one model has it).
    parts : tuple of str
        A model that predicts each shot with one of these models (:meth:`part`).
    report_words : str
        What the model is, for ``validate``'s report (``{nu}`` is the mapping's Poisson's
        ratio); consecutive models with the same words share one line.
    recommendation_reason : str
        Why the model is recommended, in words, where it is.
    prediction_seconds, concrete_table_seconds : float
        Time of one shot's prediction, and of one concrete's cavity table where the model
        needs one (``validate``'s run estimate).
    compared_with_fe : bool
        Flown, each of its labels, beside the FE table on the report's target (the
        analytic-against-FE report's trajectories, :mod:`.comparison`).
    line_styles : tuple of (colour, linestyle)
        Its curves' matplotlib colour and line style, one per label (:meth:`labels`' order);
        empty: the default colour, a solid line.
    line_width : float
        Its curves' line width (points).
    marker_size : float
        Its points' marker size in ``validate``'s figures (points).
    compressible_partner : str or None
        The label of the incompressible closed form the model is the compressible
        counterpart of: ``validate`` also runs the model with that label's calibrated mapping
        (the compressibility column) and reports the depth ratio, same material.
    empirical_reference : bool
        The empirical formula ``validate``'s report compares the calibrated models with (one
        model has it).
    regime_figure : bool
        Drawn in ``validate``'s regime figures (beside the recommended model).
    options : tuple of str
        The published options the model chooses among on measured shots (``shot_depth(shot,
        option=...)``); empty: nothing is chosen on shots. ``cavex validate --cross-validate``
        makes the choice again without each fold (:mod:`cavex.verification.validation.
        cross_validation`).
    option : str or None
        The option the model runs with: the one chosen on the development shots (one of
        ``options``; None where it has none).
    option_words : str
        How the option was chosen, in words, for the reports.
    tabulates_concrete : bool
        Predicts with the concrete cavity model's tables (one per concrete; ``validate`` runs
        it once per option and shares it with the models that have it as a part).
    """

    name = None
    help = ""
    flies = flies_3d = closed_form = predicts_shots = fits_mapping = False
    boundaries = ()
    default_boundary = None
    debonded = free_surface_option = False
    takes_table = takes_epsilon = takes_law = False
    first_layer = None
    recommended = False
    report_words = ""
    recommendation_reason = "uncalibrated, no constant fitted to the shots"
    parts = ()
    prediction_seconds = 2.5e-3  # a closed form, measured on the development shots
    concrete_table_seconds = 0.0
    compared_with_fe = False
    line_styles = ()
    line_width = 1.3
    marker_size = 7
    compressible_partner = None
    empirical_reference = regime_figure = False
    #: its shots can be flown with nose erosion (``shot_depth(..., erosion=law)``)
    erodes = False
    options = ()
    option = None
    option_words = ""
    tabulates_concrete = False

    # --- labels and options -----------------------------------------------------------------

    def labels(self):
        """Every label of the model: one per boundary convention offered, else its name."""
        return tuple(f"{self.name}-{b}" for b in self.boundaries) or (self.name,)

    def boundary(self, boundary=None):
        """The convention the model runs with: ``boundary``, or its default; None for a model
        with no convention (whatever is asked)."""
        if not self.has_boundary():
            return None
        return self.default_boundary if boundary is None else boundary

    def has_boundary(self):
        """The model has a boundary convention (a choice of it, or one of its own)."""
        return bool(self.boundaries or self.default_boundary)

    def check(self, boundary=None):
        """``boundary`` (None: the default) is one the model takes; a model with no convention
        ignores it (the command line refuses ``--boundary`` for it)."""
        if boundary is None or not self.has_boundary():
            return
        require_choice(boundary, BOUNDARIES, "boundary")
        accepted = self.boundaries or ((self.default_boundary,) if self.default_boundary
                                       else ())
        require(boundary in accepted, "boundary",
                f"'{self.default_boundary}' for the {self.name} model" if accepted
                else f"none for the {self.name} model", boundary)

    def label(self, boundary=None):
        """The label of the model with ``boundary`` (checked): ``<name>-<boundary>`` where it
        offers a choice, else its name."""
        self.check(boundary)
        return f"{self.name}-{self.boundary(boundary)}" if self.boundaries else self.name

    def describe(self, boundary=None, epsilon=None, table=None, law=None):
        """The model in words, as the figures' titles give it."""
        return f"{self.name} model"

    def settings_text(self, summary):
        """What the text header adds after the label (e.g. the paper model's epsilon)."""
        return ""

    def variants(self):
        """``[(label, boundary)]``: each label with the boundary convention that gives it
        (None where the model offers no choice)."""
        return [(self.label(b), b) for b in self.boundaries or (None,)]

    def line_style(self, label):
        """``(colour, linestyle, linewidth)`` of the curve of ``label``, one of its labels."""
        styles = dict(zip(self.labels(), self.line_styles, strict=False))
        return (*styles.get(label, (None, "-")), self.line_width)

    # --- what it computes -------------------------------------------------------------------

    def resistance(self, target, projectile, **options):
        raise CavexInputError(f"has no 1-D resistance (the {self.name} model)", "resistance")

    def stress_law(self, target, projectile, **options):
        raise CavexInputError(f"has no 3-D stress law (the {self.name} model)", "resistance")

    def wall_stress(self, target, projectile, depth, velocity, **options):
        raise CavexInputError(f"has no closed-form wall stress (the {self.name} model)",
                              "resistance")

    def shot_depth(self, shot, **options):
        raise CavexInputError(f"predicts no shot (the {self.name} model)", "models")


def register(model):
    """Add ``model`` (a :class:`Model`) under its name; a second model of one name is refused."""
    if model.name in _REGISTRY:
        raise ValueError(f"a model named {model.name!r} is already registered")
    _REGISTRY[model.name] = model
    return model


def unregister(name):
    """Remove the model ``name`` (for tests that register a toy model)."""
    _REGISTRY.pop(name, None)


def models(**capabilities):
    """The registered models with every given capability (e.g. ``flies=True``), in order."""
    return tuple(m for m in _REGISTRY.values()
                 if all(getattr(m, key) == value for key, value in capabilities.items()))


def names(**capabilities):
    """The names of :func:`models` ``(**capabilities)``."""
    return tuple(m.name for m in models(**capabilities))


def labels(**capabilities):
    """Every label of :func:`models` ``(**capabilities)``, in order."""
    return tuple(label for m in models(**capabilities) for label in m.labels())


def the(**capabilities):
    """The one model with the given capabilities (e.g. ``recommended=True``)."""
    found = models(**capabilities)
    if len(found) != 1:
        raise LookupError(f"{len(found)} models have {capabilities}, not one")
    return found[0]


def line_style(label):
    """``(colour, linestyle, linewidth)`` of the curves of a model's ``label``
    (:meth:`Model.line_style`)."""
    model, _ = parse_label(label)
    return model.line_style(label)


def get(name, parameter="resistance", offered=None):
    """The model ``name``, one of ``offered`` names (default: every registered model)."""
    offered = tuple(_REGISTRY) if offered is None else offered
    require_choice(name, offered, parameter)
    return _REGISTRY[name]


def parse_label(label, parameter="model", offered=None):
    """``(model, boundary)`` of a label of ``offered`` (default every label); ``boundary`` is
    None for a model with no choice of it, so that ``model.label(boundary) == label``."""
    offered = labels() if offered is None else offered
    require_choice(label, offered, parameter)
    for model in _REGISTRY.values():
        if label in model.labels():
            boundary = label[len(model.name) + 1:] if model.boundaries else None
            return model, boundary
    raise AssertionError(label)  # every offered label is some model's


def require_option(model, option):
    """``option`` is one of ``model``'s published :attr:`Model.options` (one line naming them
    otherwise)."""
    require_choice(option, model.options, f"option of the {model.name} model")
