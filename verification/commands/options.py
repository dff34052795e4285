"""The one choice "which resistance" on the command line, shared by every command that makes it.

Options (``penetrate``, ``stress``, ``trajectory``, ``calibrate``): ``--resistance`` one of
the registry's models (:mod:`cavex.analytic.models`: ``penetrate`` and ``trajectory`` every
flown model, ``law`` with ``--law-A``/``--law-B``; ``stress`` only the closed forms), ``--boundary
{dynamic,quasi-static}`` (the derived model's convention; default dynamic; the paper model
keeps its own quasi-static and refuses another), ``--table FILE`` with ``table``,
``--epsilon`` (the paper model's reading of epsilon). Together they name one model label
(:meth:`cavex.analytic.models.registry.Model.label`; the plain law's is ``law``).

The earlier spellings (``--model derived|paper``, ``--resistance closed-form``, ``calibrate
--model derived-dynamic|derived-quasi-static|paper|fe-table``) are refused with one line that
names the new options (exit code 2).
"""

import argparse

from cavex.analytic.models import DEFAULT_BOUNDARY, OLD_LABELS, get, label_options, labels, names
from cavex.analytic.paper_model import EPSILON_READINGS
from cavex.errors import CavexInputError
from cavex.materials import BONDINGS, fe_only_parameters
from cavex.problem import BOUNDARIES

# the models a command offers, as the capabilities it selects from the registry (read when the
# parser is built, so that a model registered later is offered too)
FLOWN = {"flies": True}  # penetrate: every model with a 1-D resistance
FLOWN_3D = {"flies_3d": True}  # trajectory: every model with a 3-D stress law
CLOSED_FORMS = {"closed_form": True}  # stress: the closed forms of the wall stress
FITTED = {"fits_mapping": True}  # calibrate: the models of the (f_c, rho) mapping
#: The two plain laws of ``--resistance law``, in the words of the help and of the errors: the
#: options' global law and each layer's own (its keys), which share the letters A and B
GLOBAL_LAW = "sigma_n = A + B V_n^2 (A in Pa, B in kg/m^3)"
LAYER_LAW = "S = law_A + law_B rho V^2 / tau (law_A, law_B dimensionless)"
TABLE_BUILT = " (built by the command)"  # a table model where the command has no --table
NEW_OPTIONS = "--resistance derived|paper|table (with --boundary dynamic|quasi-static)"
#: old values of --resistance and --model that are no label, with what replaced them
OLD_VALUES = {"closed-form": "--resistance derived or --resistance paper",
              "derived": "--resistance derived"}


def add_resistance_options(command, offered=FITTED, table=True, epsilon=True):
    """``--resistance`` (one of ``offered``), ``--boundary``, ``--table`` (if ``table``),
    ``--epsilon`` (if ``epsilon``), ``--law-A/--law-B`` (where a model offered takes them)
    and the refused ``--model``; ``offered``: the capabilities of the models offered."""
    offered = names(**offered)
    models = [get(name) for name in offered]
    phrases = [(m.help if table or not m.takes_table else m.help.replace(" (--table)", TABLE_BUILT))
               + (" (--epsilon)" if m.takes_epsilon and epsilon else "") for m in models]
    command.add_argument("--resistance", default="derived", metavar="{" + ",".join(offered) + "}",
                         help="the resistance: " + ", ".join(phrases))
    command.add_argument("--boundary", choices=BOUNDARIES,
                         help="yield-at-boundary convention of the derived model (default: "
                         "dynamic; the paper model has its own, quasi-static)")
    if table:
        command.add_argument("--table", help="NetCDF table from `cavex table` (--resistance "
                             "table; the first layer alone: the derived model; default: none)")
    if epsilon:
        command.add_argument("--epsilon", choices=EPSILON_READINGS,
                             help="the paper model's reading of epsilon (docs/table2.md) "
                             "(default: quasi-static)")
    if any(m.takes_law for m in models):
        add_law_options(command)
    command.add_argument("--model", dest="old_model", help=argparse.SUPPRESS)


def add_erosion_option(command):
    """``--erosion {none,silling-forrestal}``: nose erosion by abrasion in the 1-D integrator
    (:mod:`cavex.analytic.penetration.erosion`; ``penetrate``, ``validate``)."""
    from cavex.analytic.penetration.erosion import CHOICES

    command.add_argument("--erosion", choices=CHOICES, default="none",
                         help="nose erosion by abrasion: silling-forrestal (Silling and Forrestal "
                         "2007: mass lost at the frictional power over a heat of ablation, the "
                         "nose blunting; mu 0.1 and Q 1.31 MJ/kg are not the source's, "
                         "docs/erosion.md) or none (the rigid projectile)")


def add_law_options(command):
    """``--law-A PA --law-B KG_PER_M3``: the global plain law of ``--resistance law`` (added by
    :func:`add_resistance_options` where "law" is offered: ``penetrate``, ``trajectory``)."""
    command.add_argument("--law-A", dest="law_A", type=float, help="A of the global plain law "
                         f"{GLOBAL_LAW} (with --resistance law and --law-B; default: none, "
                         f"each layer's own plain law {LAYER_LAW} from its keys)")
    command.add_argument("--law-B", dest="law_B", type=float, help="B of the global plain law "
                         f"{GLOBAL_LAW} (with --law-A; default: none)")


def law_settings(args, target):
    """``{"law_A", "law_B"}`` of the parsed ``--law-A``/``--law-B`` (None: each layer's own),
    checked: both or neither, only with a model that takes them (``--resistance law``); with
    that model and without them every layer of ``target`` has its ``law_A``, ``law_B`` keys
    (the first without is named); no ``--boundary`` with the law. The values' ranges are
    checked where the law is made (:class:`cavex.analytic.penetration.stress_laws.PlainLaw`)."""
    law = [args.law_A is not None, args.law_B is not None]
    takes_law = get(args.resistance).takes_law
    if any(law) and not (all(law) and takes_law):
        raise CavexInputError("options '--law-A PA --law-B KG_PER_M3' (the global plain law "
                              f"{GLOBAL_LAW}) go with '--resistance law' (both, or neither: "
                              f"each layer's own plain law {LAYER_LAW} from its keys)")
    if takes_law and not any(law):
        missing = next((i for i, plain in enumerate(target.plain_laws) if plain is None), None)
        if missing is not None:
            raise CavexInputError("must be given on every layer for '--resistance law' without "
                                  "'--law-A PA --law-B KG_PER_M3' (the layer's own plain law "
                                  f"{LAYER_LAW}; the options give instead the global plain "
                                  f"law {GLOBAL_LAW}; docs/config.md)",
                                  f"layers[{missing}].law_A")
    if takes_law and args.boundary is not None:
        refuse_boundary(args.resistance)
    return {"law_A": args.law_A, "law_B": args.law_B}


def refuse_boundary(resistance):
    """Refuse ``--boundary`` for the model ``resistance``, which has no boundary convention."""
    raise CavexInputError(f"option '--boundary' goes with '--resistance derived' (or table); "
                          f"'--resistance {resistance}' has no boundary convention")


def replaced(value):
    """What replaced the old option value ``value`` (None: ``value`` is no old spelling)."""
    if value in OLD_VALUES:
        return OLD_VALUES[value]
    label = OLD_LABELS.get(value, value)
    return label_options(label) if label in labels(fits_mapping=True) else None


def resistance_settings(args, offered=FITTED):
    """``{"resistance", "boundary", "epsilon", "table"}`` of the parsed options, checked: no
    old spelling; the resistance is a model with the capabilities ``offered``; ``--table
    FILE`` goes with a model that takes a table (both or neither, where the command has
    ``--table``: ``calibrate`` builds its own tables); the model takes the boundary given;
    ``--epsilon`` only with the model that reads it (default quasi-static). ``boundary`` is
    resolved: for a table the first layer's model's, for a model with no convention (the
    law) the derived model's default."""
    if args.old_model is not None:
        hint = replaced(args.old_model)
        raise CavexInputError(f"option --model was replaced by {NEW_OPTIONS}"
                              + (f"; for '{args.old_model}' use {hint}" if hint else ""))
    resistance, offered = args.resistance, names(**offered)
    if resistance not in offered:
        hint = None if resistance in names() else replaced(resistance)
        if hint:
            raise CavexInputError(f"option --resistance {resistance} was replaced by {hint}")
        refused = get(resistance) if resistance in names() else None
        raise CavexInputError(f"option --resistance must be one of {', '.join(offered)} (got "
                              f"{resistance!r})" + ("; a table is no closed form: `cavex fem` "
                                                    "gives the FE wall stress"
                                                    if refused and refused.takes_table else ""))
    model = get(resistance)
    table = getattr(args, "table", None)
    if "table" in args and model.takes_table != (table is not None):
        raise CavexInputError("option '--table FILE' goes with '--resistance table' (both or "
                              "neither)")
    if not model.has_boundary() and not model.first_layer and args.boundary is not None:
        if not model.takes_law:  # the law's options are checked first (law_settings)
            refuse_boundary(resistance)
    model.check(args.boundary)
    epsilon = getattr(args, "epsilon", None)
    if epsilon is not None and not model.takes_epsilon:
        raise CavexInputError(f"option '--epsilon' goes with '--resistance paper' (the paper "
                              f"model's reading of epsilon; got --resistance {resistance})")
    return {"resistance": resistance,
            # a model without a convention (the law) carries the derived model's default
            "boundary": model.boundary(args.boundary) or DEFAULT_BOUNDARY,
            "epsilon": epsilon or "quasi-static", "table": table}


def add_interface_option(command):
    """``--interfaces bonded|debonded``: every interface of the target so, overriding the
    config file's ``bottom`` keys (default: as the file says; docs/config.md)."""
    command.add_argument("--interfaces", choices=BONDINGS, default=None,
                         help="every interface bonded or debonded (a traction-free rear face, "
                         "a rear zone and a crater in the next layer; docs/analytic.md); "
                         "default: each layer's 'bottom' key in the config (bonded)")


def interface_target(args, target, resistance):
    """``target`` with ``--interfaces`` applied, checked: a debonded interface needs the
    derived closed form (the traction-free sphere of its rear face)."""
    target = target.with_interfaces(getattr(args, "interfaces", None))
    if target.debonded and not get(resistance).debonded:
        raise CavexInputError(f"option --interfaces debonded (or a layer's bottom = "
                              f"\"debonded\") goes with --resistance "
                              f"{names(debonded=True)[0]} (got --resistance {resistance})")
    return target


def refuse_debonded(target, command):
    """Refuse a target with a debonded interface in a command that solves the bonded spherical
    problem only (``stress``, ``fem``, ``table``, ``verify``): its answer would silently ignore
    the key."""
    if target.debonded:
        j = target.debonded[0]
        raise CavexInputError(f"is \"debonded\", which `cavex {command}` does not model (the "
                              "spherical problem is one bonded continuum): remove the key, or "
                              "use penetrate or trajectory", f"layers[{j}].bottom")


def fe_only_layers(target):
    """``"name (key, key)"`` of every layer with FE-only keys (``tau_max``,
    ``tensile_strength``, the hydrostat: the realistic concrete), which the closed forms
    ignore."""
    named = []
    for i, material in enumerate(target.layers):
        keys = [k for k in fe_only_parameters() if getattr(material, k) is not None]
        if keys:
            named.append(f"{target.layer_name(i)} ({', '.join(keys)})")
    return named
