"""Every resistance model, one module each, registered by name (:mod:`.registry`), and the API
that builds a model's resistance, stress law and trajectory from its name.

To add a model: write one module here that defines a :class:`~.registry.Model` and calls
``register`` (docs/models.md: a worked example), and import it below. The import order is the
order of the choices and of ``cavex validate``'s columns.
"""

# isort: off
# one line a model, in the order of the choices and of validate's columns
from cavex.analytic.models import derived as _derived
from cavex.analytic.models import paper as _paper  # noqa: F401
from cavex.analytic.models import table as _table  # noqa: F401
from cavex.analytic.models import plain_law as _plain_law  # noqa: F401
from cavex.analytic.models import concrete as _concrete  # noqa: F401
from cavex.analytic.models import li_chen_2003 as _li_chen_2003  # noqa: F401
from cavex.analytic.models import li_chen_concrete as _li_chen_concrete  # noqa: F401
from cavex.analytic.models import forrestal_1994 as _forrestal_1994  # noqa: F401
# isort: on
from cavex.analytic.models.registry import (  # noqa: F401
    Model,
    get,
    labels,
    line_style,
    models,
    names,
    parse_label,
    the,
)
from cavex.errors import require

#: the derived model's default boundary convention
DEFAULT_BOUNDARY = _derived.Derived.default_boundary


def make_resistance(target, projectile, resistance="derived", boundary=None,
                    epsilon="quasi-static", table=None, *, law_A=None, law_B=None):
    """The 1-D resistance of the model ``resistance`` (a name of ``names(flies=True)``) for
    ``target`` and ``projectile``: the closed forms with ``boundary`` (the derived model's
    convention) and ``epsilon`` (the paper model's reading), the FE table ``table`` (a Dataset
    or a table file built for this target), the plain law (the global ``law_A`` Pa, ``law_B``
    kg/m^3, or neither: each layer's ``law_A``, ``law_B`` keys)."""
    model = get(resistance, offered=names(flies=True))
    return model.resistance(target, projectile, boundary=boundary, epsilon=epsilon,
                            table=table, law_A=law_A, law_B=law_B)


def make_law(target, projectile, resistance="derived", *, boundary="dynamic",
             free_surface=True, table=None, law_A=None, law_B=None, epsilon="quasi-static",
             bottom=None):
    """The 3-D stress law of the model ``resistance`` (a name of ``names(flies_3d=True)``;
    :mod:`cavex.analytic.penetration.stress_laws`)."""
    model = get(resistance, offered=names(flies_3d=True))
    return model.stress_law(target, projectile, boundary=boundary, free_surface=free_surface,
                            table=table, law_A=law_A, law_B=law_B, epsilon=epsilon,
                            bottom=bottom)


def fly(target, projectile, strike=None, resistance="derived", *, body=None, bottom=None,
        progress=None, **options):
    """One trajectory of the oblique model (:class:`cavex.analytic.penetration.oblique.
    ObliqueModel`): its :class:`~cavex.analytic.penetration.oblique.Result` of ``strike``
    (default: normal incidence at ``V0``) under the stress law of the model ``resistance``.
    ``options`` are the law's (``boundary``, ``free_surface``, ``table``, ``law_A``,
    ``law_B``, ``epsilon``) and the oblique model's (``rtol``, ``atol``, ``method``,
    ``contact_ramp``, ``contact_hold``, ``hold_time``, ``tangency_psi``, ``entry_crater``,
    ``crater``); ``progress(t, y)`` is called after every integrator step."""
    from cavex.analytic.penetration.oblique import ObliqueModel
    from cavex.analytic.penetration.strike import Strike

    model = get(resistance, offered=names(flies_3d=True))
    require(model.debonded or not target.debonded, "interfaces",
            f"'bonded' unless the resistance is '{names(debonded=True)[0]}' (a debonded "
            "interface needs its traction-free sphere)", "debonded")
    law_keys = ("boundary", "free_surface", "table", "law_A", "law_B", "epsilon")
    law = make_law(target, projectile, resistance, bottom=bottom,
                   **{k: options.pop(k) for k in law_keys if k in options})
    oblique = ObliqueModel(target, projectile, law, body=body, bottom=bottom, **options)
    return oblique.run(strike or Strike(projectile.V0), progress=progress)


#: Earlier spellings of a model label (validation's columns, ``calibrate --model``), each with
#: the label that replaced it; refused with a line that names the new one.
OLD_LABELS = {"derived quasi-static": "derived-quasi-static",
              "derived dynamic": "derived-dynamic", "FE table": "table", "fe-table": "table"}


def model_label(resistance, boundary=None):
    """The label of the model ``resistance`` with ``boundary`` (checked; None: its default):
    ``derived-<boundary>``, ``paper``, ``table``, ``law``..."""
    return get(resistance).label(boundary)


def parse_model_label(label, parameter="model"):
    """``(model name, boundary)`` of a label of a model that fits the mapping (``calibrate``,
    validation columns), ``boundary`` None where the model has no choice of it, so that
    ``model_label(*parse_model_label(label)) == label``. An old spelling (:data:`OLD_LABELS`)
    is refused with the label that replaced it."""
    if isinstance(label, str) and label in OLD_LABELS:
        from cavex.errors import CavexInputError

        raise CavexInputError(f"must be '{OLD_LABELS[label]}' (the label '{label}' was "
                              "replaced)", parameter)
    model, boundary = parse_label(label, parameter, labels(fits_mapping=True))
    return model.name, boundary


def label_options(label):
    """The command-line options that choose ``label``, e.g. ``--resistance derived --boundary
    quasi-static``."""
    resistance, boundary = parse_model_label(label)
    return f"--resistance {resistance}" + (f" --boundary {boundary}" if boundary else "")
