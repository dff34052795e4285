"""The resistance vocabulary: which 1-D resistances there are and how a model (resistance and
boundary convention) is labelled in options, JSON, CSV, reports and calibration files.

Kept apart from :mod:`cavex.analytic.penetration.resistance` (which compiles the closed forms)
so that the command line's parser can offer the choices without loading numba or scipy."""

from cavex.errors import CavexInputError, require, require_choice
from cavex.problem import BOUNDARIES

MODELS = ("derived", "paper")  # the closed forms (ClosedFormResistance)
#: Every 1-D resistance a caller can choose (``resistance=``, ``--resistance``): the two closed
#: forms and the FE table (:class:`cavex.analytic.penetration.tabulated.TabulatedResistance`).
RESISTANCES = (*MODELS, "table")
#: The plain law ``sigma_n = A + B V_n^2`` (the global ``--law-A``/``--law-B``) or each layer's
#: own ``tau_k A_k + B_k rho_k V_n^2`` (its ``law_A``, ``law_B`` keys): a resistance of the
#: commands that fly the projectile only, and its label (it has no boundary convention and is
#: no model of ``calibrate`` or ``validate``).
PLAIN_LAW = "law"
#: The resistances of the commands that fly the projectile (``penetrate``, ``trajectory``; the
#: API's ``make_resistance`` and ``make_law``): :data:`RESISTANCES` and :data:`PLAIN_LAW`.
FLIGHT_RESISTANCES = (*RESISTANCES, PLAIN_LAW)
#: The model labels (keys and labels in JSON, CSV, reports, calibration files): the resistance
#: and, for the derived model, its boundary convention (:func:`model_label`).
MODEL_LABELS = ("derived-quasi-static", "derived-dynamic", "paper", "table")
#: The labels of the models that are not a cavex resistance (no ``--resistance`` choice), which
#: ``cavex validate`` also predicts with: the concrete cavity-expansion model
#: (:mod:`cavex.verification.validation.concrete_model`) and the empirical formulas of Li and
#: Chen (2003) and Forrestal et al. (1994) (:mod:`cavex.verification.validation.empirical`).
CONCRETE_LABEL = "concrete"
LI_CHEN_LABEL = "li-chen-2003"  # Li and Chen's (2003) empirical formula
EMPIRICAL_LABEL = "forrestal-1994"
#: Li and Chen (2003) for normal-strength concrete (f_c <= 100 MPa), the concrete model above
#: (:func:`cavex.verification.validation.concrete_model.split_depth`): ``cavex validate``'s
#: recommended model
SPLIT_LABEL = "li-chen-concrete"
#: Every model ``cavex validate`` predicts with (``--models`` choices), in the order of its
#: columns.
VALIDATION_LABELS = (*MODEL_LABELS, CONCRETE_LABEL, LI_CHEN_LABEL, SPLIT_LABEL, EMPIRICAL_LABEL)
#: Earlier spellings of a model label (validation's columns, ``calibrate --model``), each with
#: the label that replaced it; refused with a line that names the new one.
OLD_LABELS = {"derived quasi-static": "derived-quasi-static",
              "derived dynamic": "derived-dynamic", "FE table": "table", "fe-table": "table"}
#: The derived model's default boundary convention: the closed form closest to the FE in every
#: layer of the default target (results/verification/report.md; README "Commands").
DEFAULT_BOUNDARY = "dynamic"
PAPER_BOUNDARY = "quasi-static"  # the paper's printed model has its own convention


def model_boundary(model, boundary=None):
    """The boundary convention ``model`` runs with: ``boundary``, or when None the model's
    default (:data:`DEFAULT_BOUNDARY` for "derived", the paper's quasi-static for "paper")."""
    if boundary is None:
        return PAPER_BOUNDARY if model == "paper" else DEFAULT_BOUNDARY
    return boundary


def check_model(model, boundary=None):
    """The model is known, and the paper model is only offered with its quasi-static boundary
    (None: the model's default, :func:`model_boundary`)."""
    require_choice(model, MODELS, "model")
    if boundary is not None:
        require_choice(boundary, BOUNDARIES, "boundary")
    boundary = model_boundary(model, boundary)
    require(model != "paper" or boundary == PAPER_BOUNDARY, "boundary",
            "'quasi-static' for the paper model", boundary)


def model_label(resistance, boundary=None):
    """The label of ``resistance`` with ``boundary``: ``derived-<boundary>`` (None: the default
    boundary, :func:`model_boundary`), ``paper`` (its own quasi-static boundary only), ``table``
    (the FE has no boundary convention)."""
    require_choice(resistance, RESISTANCES, "resistance")
    if resistance == "table":
        return "table"
    check_model(resistance, boundary)
    return "paper" if resistance == "paper" else f"derived-{model_boundary(resistance, boundary)}"


def parse_model_label(label, parameter="model"):
    """``(resistance, boundary)`` of a label of :data:`MODEL_LABELS` (``boundary`` None for
    ``paper`` and ``table``: they have no choice of it), so that
    ``model_label(*parse_model_label(label)) == label``. An old spelling
    (:data:`OLD_LABELS`) is refused with the label that replaced it."""
    if isinstance(label, str) and label in OLD_LABELS:
        raise CavexInputError(f"must be '{OLD_LABELS[label]}' (the label '{label}' was "
                              "replaced)", parameter)
    require_choice(label, MODEL_LABELS, parameter)
    resistance, _, boundary = label.partition("-")
    return resistance, boundary or None


def label_options(label):
    """The command-line options that choose ``label``, e.g. ``--resistance derived --boundary
    quasi-static``."""
    resistance, boundary = parse_model_label(label)
    return f"--resistance {resistance}" + (f" --boundary {boundary}" if boundary else "")
