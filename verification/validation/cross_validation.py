r"""Cross-validation of ``cavex validate``'s models (``--cross-validate``; docs/validation.md
"Cross-validation").

A model makes a choice on measured shots where it has published options to choose among
(:attr:`cavex.analytic.models.registry.Model.options`: the concrete model's lock strain, the
split of ``li-chen-concrete``) or a calibration (a mapping fitted to shots). Each such choice is
made again without each fold, on the other shots given, and the fold's shots are predicted with
it. A model with nothing chosen on shots (Li and Chen's formula, the uncalibrated closed forms)
predicts a fold as it predicts every shot: its cross-validated score is its plain score.

Folds (:data:`FOLDS`), on the shots given:

- ``reference``: each reference (the shot file's column ``source``) left out in turn. The
  references partition the shots, so every shot is predicted once by the choices made without
  its reference (each shot's ``cross_validated_m``; the ``regimes`` table);
- ``calibre``: the shots of calibre ``<= 13`` mm left out against the rest; ``yield``: the
  projectile's listed yield strength below 1 GPa (column ``proj_yield_MPa``; a shot without one
  is not of the kind); ``velocity``: ``V0 > 1000`` m/s (:data:`KINDS`).

The choice (:func:`choose`) among a model's options on the shots not left out: the option with
the fewest shots without a depth there, then the smallest mean ``|ln(predicted/measured)|``
over its depths there; a tie goes to the first in the model's order. A calibration is fitted
again (its model and free parameters, :func:`cavex.verification.validation.calibration.fit`) on
its fitted shots less the fold, where the fold holds any of them; else it is used as it is.

Statistics (:func:`cross_validation`; ``option_depths_m``: every option's depth of every shot,
for the models that choose one, so that each choice can be checked from the file): per fold
(a list: ``name``, ``family``, ``n``) and model the choice, ``n``, mean
``|ln(predicted/measured)|`` and bias (mean ``ln``) over the fold's shots, and the same by
regime (:mod:`cavex.verification.validation.regimes`); over the reference folds together, by
regime (``regimes``). Rounded like every statistic of a validation.
"""

import math

import numpy as np

from cavex.errors import CavexInputError, require, require_choice
from cavex.verification.validation.regimes import (
    DEPTH_DIGITS,
    FAST,
    log_statistics,
    regime_statistics,
)

REFERENCE_COLUMN = "source"
YIELD_COLUMN = "proj_yield_MPa"
SMALL_CALIBRE = 0.013  # m
SOFT_YIELD = 1000.0  # MPa


def projectile_yield(shot):
    """The projectile's listed yield strength (MPa; inf where none is listed); a listed value
    that is not a number > 0 is refused."""
    text = str(shot.extra.get(YIELD_COLUMN, "") or "").strip()
    if not text:
        return math.inf
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    require(math.isfinite(value) and value > 0.0, f"{YIELD_COLUMN} of shot '{shot.id}'",
            "a yield strength in MPa > 0, or empty", text)
    return value


#: fold family -> (words, membership of a shot) for the kinds of shot left out
KINDS = {
    "calibre": (f"calibre <= {SMALL_CALIBRE * 1e3:g} mm",
                lambda shot: shot.diameter <= SMALL_CALIBRE),
    "yield": (f"projectile yield < {SOFT_YIELD / 1e3:g} GPa",
              lambda shot: projectile_yield(shot) < SOFT_YIELD),
    "velocity": (f"V0 > {FAST:g} m/s", lambda shot: shot.V0 > FAST),
}
FOLDS = ("reference", *KINDS)


def check_folds(families, shots):
    """The fold families asked (``families``), checked against ``shots``: known names without
    repeats; ``reference``: every shot names its reference (column ``source``) and there are
    at least two; a kind: some shots of it and some not. One line naming ``--cross-validate``
    otherwise. None named (empty or None): every family of :data:`FOLDS` that ``shots``
    admit, at least one."""
    if not families:
        admitted = []
        for name in FOLDS:
            try:
                admitted.append(check_folds((name,), shots)[0])
            except CavexInputError:
                continue
        require(bool(admitted), "cross-validate",
                "applicable to the shots: two references or more (column 'source'), or "
                "shots of a kind (" + "; ".join(w for w, _ in KINDS.values()) + ") and others",
                "none of " + ", ".join(FOLDS))
        return tuple(admitted)
    families = tuple(families)
    for name in families:
        require_choice(name, FOLDS, "cross-validate")
    require(len(set(families)) == len(families), "cross-validate", "fold names without repeats",
            list(families))
    if "reference" in families:
        missing = [s.id for s in shots if not str(s.extra.get(REFERENCE_COLUMN, "")).strip()]
        if missing:
            raise CavexInputError(
                f"reference needs every shot's reference in the shot file's column "
                f"'{REFERENCE_COLUMN}' (shot '{missing[0]}' has none)", "cross-validate")
        references = {reference_of(s) for s in shots}
        require(len(references) >= 2, "cross-validate",
                f"a family the file can fold ('reference': shots of at least two references, "
                f"column '{REFERENCE_COLUMN}')", f"{len(references)} reference")
    for name in families:
        if name in KINDS:
            words, member = KINDS[name]
            count = sum(1 for s in shots if member(s))
            require(0 < count < len(shots), "cross-validate",
                    f"a kind of shot the file holds beside others ('{name}': {words})",
                    f"{count} of {len(shots)} shots of the kind")
    return families


def reference_of(shot):
    """The shot's reference (column ``source``, stripped)."""
    return str(shot.extra.get(REFERENCE_COLUMN, "")).strip()


def fold_indices(shots, families):
    """``{fold name: (family, [shot indices])}``: one fold per reference (named
    ``"reference <source>"``, sorted) and one per kind (named by its words)."""
    folds = {}
    if "reference" in families:
        references = {}
        for i, shot in enumerate(shots):
            references.setdefault(reference_of(shot), []).append(i)
        for name in sorted(references):
            folds[f"reference {name}"] = ("reference", references[name])
    for family in families:
        if family in KINDS:
            words, member = KINDS[family]
            folds[words] = (family, [i for i, s in enumerate(shots) if member(s)])
    return folds


def mean_abs_log(depths, measured, indices):
    """``(missing, mean |ln(depth/measured)|)`` over ``indices``: the shots without a depth,
    and the mean over the others (inf without any)."""
    logs = [abs(math.log(depths[i] / measured[i])) for i in indices if depths[i] is not None]
    return len(indices) - len(logs), (float(np.mean(logs)) if logs else math.inf)


def choose(by_option, measured, indices):
    """The option of ``by_option`` (``{option: [depth or None]}``, in the model's order) chosen
    on the shots ``indices``: the fewest shots without a depth, then the smallest mean
    ``|ln(depth/measured)|``; a tie goes to the first."""
    ranked = [(mean_abs_log(depths, measured, indices), k, option)
              for k, (option, depths) in enumerate(by_option.items())]
    return min(ranked)[2]


def cross_validation(result, shots, option_depths, calibrations, families, refit):
    """Set ``result["cross_validation"]`` and each shot row's ``cross_validated_m``.

    Parameters
    ----------
    result : dict
        :func:`cavex.verification.validation.predict.validate`'s, with ``shots`` rows and
        ``models`` (the columns).
    shots : sequence of Shot
        The shots, in the rows' order.
    option_depths : dict
        ``{column: {option: [depth or None]}}``; a column with nothing chosen on shots has
        the one option ``None`` (its plain depths).
    calibrations : dict
        ``{column: Calibration}`` of the calibrated columns.
    families : sequence of str
        The fold families (:func:`check_folds`).
    refit : callable
        ``refit(calibration, train shots, held shots) -> (choice, depths of the held shots)``.
    """
    measured = [s.depth for s in shots]
    columns = result["models"]
    index = {s.id: i for i, s in enumerate(shots)}
    folds = fold_indices(shots, families)
    everyone = set(range(len(shots)))
    held_out = {c: [None] * len(shots) for c in columns}  # the reference folds' predictions
    out = []
    for name, (family, held) in folds.items():
        rest = sorted(everyone - set(held))
        models, predicted = {}, {}
        for column in columns:
            calibration = calibrations.get(column)
            if calibration is not None:
                choice, depths = _calibration_fold(calibration, shots, held, index,
                                                   option_depths[column][None], refit)
            else:
                choice = choose(option_depths[column], measured, rest)
                depths = [option_depths[column][choice][i] for i in held]
            predicted[column] = depths
            models[column] = {"choice": choice, **log_statistics(
                [None if d is None else d / measured[i] for d, i in zip(depths, held,
                                                                         strict=True)],
                DEPTH_DIGITS)}
            if family == "reference":
                for d, i in zip(depths, held, strict=True):
                    held_out[column][i] = d
        rows = [_row(result["shots"][i], {c: predicted[c][k] for c in columns})
                for k, i in enumerate(held)]
        out.append({"name": name, "family": family, "n": len(held), "models": models,
                    "regimes": regime_statistics(rows, columns, DEPTH_DIGITS)})
    document = {"families": list(families), "folds": out,
                "chosen_on_shots": chosen_on_shots(columns, option_depths, calibrations),
                "choice_on_all_shots": {c: choose(option_depths[c], measured, sorted(everyone))
                                        for c in columns if c not in calibrations
                                        and list(option_depths[c]) != [None]},
                "option_depths_m": {c: {"options": list(option_depths[c]),
                                        "depths_m": list(option_depths[c].values())}
                                    for c in columns if c not in calibrations
                                    and list(option_depths[c]) != [None]}}
    if "reference" in families:
        for i, row in enumerate(result["shots"]):
            row["cross_validated_m"] = {c: held_out[c][i] for c in columns}
        rows = [_row(row, row["cross_validated_m"]) for row in result["shots"]]
        document["regimes"] = regime_statistics(rows, columns, DEPTH_DIGITS)
    result["cross_validation"] = document
    return result


def fold_validator(families, erosion=None):
    """The ``cross_validate`` of :func:`cavex.verification.validation.predict.validate`:
    :func:`cross_validation` over the fold ``families``, a calibrated column refitted per fold
    (:func:`cavex.verification.validation.calibration.refitted_depths`, with ``erosion``)."""
    def run(result, shots, option_depths, calibrations, tables):
        from cavex.verification.validation.calibration import refitted_depths

        def refit(calibration, train, held):
            return refitted_depths(calibration, train, held, tables, erosion, shots)

        return cross_validation(result, shots, option_depths, calibrations, families, refit)

    return run


def chosen_on_shots(columns, option_depths, calibrations):
    """``{column: what it chooses on shots, in words, or None}``."""
    from cavex.analytic.models import labels, parse_label

    out = {}
    for column in columns:
        if column in calibrations:
            out[column] = "a mapping fitted to shots (its calibration, refitted per fold)"
        elif list(option_depths[column]) != [None]:
            offered = labels(predicts_shots=True)
            words = (parse_label(column, "models", offered)[0].option_words if column in offered
                     else "an option")
            out[column] = (f"{words}: one of "
                           + ", ".join(f"'{o}'" for o in option_depths[column]))
        else:
            out[column] = None
    return out


def _calibration_fold(calibration, shots, held, index, depths, refit):
    """``(choice, depths of the held shots)`` of a calibrated column: fitted again without the
    fold where the fold holds a fitted shot, else as calibrated (``depths``: its column's)."""
    fitted = [index[i] for i in calibration.shots if i in index]
    left = set(held)
    if not left & set(fitted):
        return "as calibrated", [depths[i] for i in held]
    train = [shots[i] for i in fitted if i not in left]
    if len(train) < len(calibration.params):
        return "too few fitted shots left", [None] * len(held)
    return refit(calibration, train, [shots[i] for i in held])


def _row(row, depths):
    """A shot row with the ratios of ``depths`` (``{column: depth}``) for the regime
    statistics."""
    return {"fc_Pa": row["fc_Pa"], "V0_m_s": row["V0_m_s"], "flag": row.get("flag"),
            "ratio": {c: None if d is None else d / row["measured_m"]
                      for c, d in depths.items()}}
