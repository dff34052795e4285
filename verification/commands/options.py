"""The one choice "which resistance" on the command line, shared by every command that makes it.

Options (``penetrate``, ``stress``, ``trajectory``, ``calibrate``): ``--resistance`` one of
:data:`cavex.analytic.penetration.resistance.RESISTANCES` (``penetrate`` and ``trajectory`` also
``law``, with ``--law-A``/``--law-B``; ``stress`` only the closed forms), ``--boundary
{dynamic,quasi-static}`` (the derived model's convention; default dynamic; the paper model
keeps its own quasi-static and refuses another), ``--table FILE`` with ``table``,
``--epsilon`` (the paper model's reading of epsilon). Together they name one model label
(:func:`cavex.analytic.penetration.resistance.model_label`; the plain law's is ``law``).

The earlier spellings (``--model derived|paper``, ``--resistance closed-form``, ``calibrate
--model derived-dynamic|derived-quasi-static|paper|fe-table``) are refused with one line that
names the new options (exit code 2).
"""

import argparse

from cavex.analytic.paper_model import EPSILON_READINGS
from cavex.analytic.penetration.labels import (
    MODEL_LABELS,
    MODELS,
    OLD_LABELS,
    PLAIN_LAW,
    RESISTANCES,
    check_model,
    label_options,
    model_boundary,
)
from cavex.errors import CavexInputError
from cavex.materials import BONDINGS
from cavex.problem import BOUNDARIES

CLOSED_FORMS = MODELS  # the resistances that are closed forms
NEW_OPTIONS = "--resistance derived|paper|table (with --boundary dynamic|quasi-static)"
#: old values of --resistance and --model that are no label, with what replaced them
OLD_VALUES = {"closed-form": "--resistance derived or --resistance paper",
              "derived": "--resistance derived"}


def add_resistance_options(command, offered=RESISTANCES, table=True, epsilon=True):
    """``--resistance`` (one of ``offered``), ``--boundary``, ``--table`` (if ``table``),
    ``--epsilon`` (if ``epsilon``) and the refused ``--model``."""
    command.add_argument("--resistance", default="derived", metavar="{" + ",".join(offered) + "}",
                         help="the resistance: the derived closed form (--boundary), the "
                         "paper's printed model" + (" (--epsilon)" if epsilon else "")
                         + (", an FE table (--table)" if "table" in offered else "")
                         + (", sigma_n = A + B V_n^2 (--law-A, --law-B)" if "law" in offered
                            else ""))
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
    if PLAIN_LAW in offered:
        add_law_options(command)
    command.add_argument("--model", dest="old_model", help=argparse.SUPPRESS)


def add_law_options(command):
    """``--law-A PA --law-B KG_PER_M3``: the global plain law of ``--resistance law`` (added by
    :func:`add_resistance_options` where "law" is offered: ``penetrate``, ``trajectory``)."""
    command.add_argument("--law-A", dest="law_A", type=float, help="A of sigma_n = A + B "
                         "V_n^2 everywhere (Pa; with --resistance law; default: none, each "
                         "layer's law_A, law_B keys)")
    command.add_argument("--law-B", dest="law_B", type=float, help="B (kg/m^3; with "
                         "--law-A; default: none)")


def law_settings(args, target):
    """``{"law_A", "law_B"}`` of the parsed ``--law-A``/``--law-B`` (None: each layer's own),
    checked: both or neither, only with ``--resistance law``; without them every layer of
    ``target`` has its ``law_A``, ``law_B`` keys (the first without is named); no
    ``--boundary`` with the law. The values' ranges are checked where the law is made
    (:class:`cavex.analytic.penetration.stress_laws.PlainLaw`)."""
    law = [args.law_A is not None, args.law_B is not None]
    if any(law) and not (all(law) and args.resistance == PLAIN_LAW):
        raise CavexInputError("options '--law-A PA --law-B KG_PER_M3' go with "
                              "'--resistance law' (both, or neither: each layer's law_A, "
                              "law_B keys)")
    if args.resistance == PLAIN_LAW and not any(law):
        missing = next((i for i, plain in enumerate(target.plain_laws) if plain is None), None)
        if missing is not None:
            raise CavexInputError("must be given on every layer for '--resistance law' without "
                                  "'--law-A PA --law-B KG_PER_M3' (the layer's plain law "
                                  "S = A + B rho V^2 / tau; docs/config.md)",
                                  f"layers[{missing}].law_A")
    if args.resistance == PLAIN_LAW and args.boundary is not None:
        raise CavexInputError("option '--boundary' goes with '--resistance derived' (or table); "
                              "'--resistance law' has no boundary convention")
    return {"law_A": args.law_A, "law_B": args.law_B}


def replaced(value):
    """What replaced the old option value ``value`` (None: ``value`` is no old spelling)."""
    if value in OLD_VALUES:
        return OLD_VALUES[value]
    label = OLD_LABELS.get(value, value)
    return label_options(label) if label in MODEL_LABELS else None


def resistance_settings(args, offered=RESISTANCES):
    """``{"resistance", "boundary", "epsilon", "table"}`` of the parsed options, checked: no
    old spelling, the resistance is one of ``offered``, ``--table FILE`` goes with
    ``--resistance table`` (both or neither, where the command has ``--table``: ``calibrate``
    builds its own tables), the paper model takes only its own boundary, ``--epsilon`` only
    with the paper model (default quasi-static). ``boundary`` is
    resolved (for a table or a law the derived model's default: the first layer alone, where
    it is flown, is derived)."""
    if args.old_model is not None:
        hint = replaced(args.old_model)
        raise CavexInputError(f"option --model was replaced by {NEW_OPTIONS}"
                              + (f"; for '{args.old_model}' use {hint}" if hint else ""))
    resistance = args.resistance
    if resistance not in offered:
        hint = None if resistance in (*RESISTANCES, "law") else replaced(resistance)
        if hint:
            raise CavexInputError(f"option --resistance {resistance} was replaced by {hint}")
        raise CavexInputError(f"option --resistance must be one of {', '.join(offered)} (got "
                              f"{resistance!r})" + ("; a table is no closed form: `cavex fem` "
                                                    "gives the FE wall stress"
                                                    if resistance == "table" else ""))
    table = getattr(args, "table", None)
    if "table" in args and (resistance == "table") != (table is not None):
        raise CavexInputError("option '--table FILE' goes with '--resistance table' (both or "
                              "neither)")
    if resistance in CLOSED_FORMS:
        check_model(resistance, args.boundary)
    epsilon = getattr(args, "epsilon", None)
    if epsilon is not None and resistance != "paper":
        raise CavexInputError(f"option '--epsilon' goes with '--resistance paper' (the paper "
                              f"model's reading of epsilon; got --resistance {resistance})")
    return {"resistance": resistance,
            "boundary": model_boundary(resistance if resistance in CLOSED_FORMS else "derived",
                                       args.boundary),
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
    if target.debonded and resistance != "derived":
        raise CavexInputError(f"option --interfaces debonded (or a layer's bottom = "
                              f"\"debonded\") goes with --resistance derived (got "
                              f"--resistance {resistance})")
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


def law_echo(target, law_A, law_B):
    """The plain law as the JSON settings of ``penetrate`` and ``trajectory`` give it: the
    global ``{"A_Pa", "B_kg_m3"}``, or each layer's ``{"layer", "law_A", "law_B"}``."""
    if law_A is not None:
        return {"A_Pa": law_A, "B_kg_m3": law_B}
    return [{"layer": name, "law_A": A, "law_B": B}
            for name, (A, B) in zip(target.layer_names(), target.plain_laws, strict=True)]
