r"""Fitting a model's free material parameters to measured depths, and calibration files.

``fit`` minimises ``sum_i ln(predicted_i / measured_i)^2`` over the shots by
:func:`scipy.optimize.least_squares` (trust-region reflective, bounds of
:data:`cavex.concrete.BOUNDS`) in the variables ``lam``, ``ln
strength_factor``,
``ln modulus_factor`` (the factors are scales: their logarithms make the problem better
conditioned); the other parameters keep the starting mapping's values (default: the sources'
mapping, :class:`cavex.concrete.Mapping`). The Jacobian is by forward
differences: a step of 1e-6 for the closed forms (the integrator's ``rtol`` is 1e-9) and 2e-2
for the FE table (its wall stresses carry a discretisation error of about 1e-3, so a smaller
step would difference noise).

A calibration file (``cavex calibrate --out CAL.toml``) is a cavex configuration: its
``[projectile]`` and ``[[layers]]`` are the calibrated target of a reference shot (the first
fitted one), so ``cavex penetrate --config CAL.toml`` (and every command that takes
``--config``) runs it; its ``[calibration]`` table holds the model, the fitted parameters
(6 significant digits, the values every later prediction uses), the fitted shot ids and the fit
statistics, and is what ``cavex validate --calibration CAL.toml`` reads.
"""

import math
import sys
import time
from dataclasses import dataclass

import numpy as np

from cavex.analytic.models import labels, model_label, parse_label, parse_model_label
from cavex.concrete import BOUNDS, FREE_PARAMETERS, Mapping
from cavex.errors import CavexInputError, CavexNumericalError, check_keys, prefixed, require
from cavex.input_files import in_file, read_toml
from cavex.verification.output.number_format import round_significant
from cavex.verification.validation.predict import (
    DEPTH_DIGITS,
    OUTLIER_FACTOR,
    TableCache,
    predict,
)
from cavex.verification.validation.shots import shot_projectile, shot_target

PARAMETER_DIGITS = 6
DEFAULT_PARAMETERS = ("lam", "strength_factor")
LOG_PARAMETERS = ("strength_factor", "modulus_factor")
# forward-difference steps and tolerances: a closed form's depth is smooth to round-off, an
# FE table's (a model that takes a table) carries ~1e-3 noise
DIFF_STEP = {"closed form": 1e-6, "FE table": 2e-2}
TOLERANCE = {"closed form": 1e-12, "FE table": 1e-3}
CALIBRATION_KEYS = {"model", "params", "lam", "strength_factor", "modulus_factor", "nu",
                    "shots", "shots_file", "reference_shot", "n", "mean_abs_log_ratio",
                    "rms_log_ratio", "evaluations", "skipped", "outliers"}
CALIBRATION_REQUIRED = {"model", "params", "lam", "strength_factor", "modulus_factor", "nu",
                        "shots"}


@dataclass(frozen=True)
class Calibration:
    """A fitted model: its label (``labels(fits_mapping=True)`` of :mod:`cavex.analytic.models`),
    mapping, fitted parameter names and shot ids."""

    model: str
    mapping: Mapping
    params: tuple
    shots: tuple
    source: str = ""
    statistics: tuple = ()
    skipped: tuple = ()  # (shot id, reason) of the shots the model could not predict
    outliers: tuple = ()  # fitted shot ids off by more than OUTLIER_FACTOR at the fit
    without_outliers: tuple = ()  # the statistics over the other fitted shots
    #: ``((param, standard error), ...)`` of the fit (:func:`standard_errors`; not in the
    #: calibration file: the command prints them)
    standard_errors: tuple = ()

    @property
    def column(self):
        return f"{self.model} calibrated"

    def describe(self):
        return {"column": self.column, "model": self.model, "file": self.source,
                "params": list(self.params), "mapping": self.mapping.as_dict(),
                "shots": list(self.shots), **dict(self.statistics),
                "skipped": {shot: reason for shot, reason in self.skipped},
                "outliers": list(self.outliers)}


def check_parameters(params):
    """The free parameter names: known, not repeated, at least one."""
    params = tuple(params or DEFAULT_PARAMETERS)
    for name in params:
        require(name in FREE_PARAMETERS, "params", f"names from {', '.join(FREE_PARAMETERS)}",
                name)
    require(len(set(params)) == len(params), "params", "names without repeats", list(params))
    return params


def _to_variables(mapping, params):
    return np.array([math.log(getattr(mapping, p)) if p in LOG_PARAMETERS
                     else getattr(mapping, p) for p in params])


def _to_values(x, params):
    return [math.exp(v) if p in LOG_PARAMETERS else v for p, v in zip(params, x, strict=True)]


def _bounds(params):
    lower = [math.log(BOUNDS[p][0]) if p in LOG_PARAMETERS else BOUNDS[p][0] for p in params]
    upper = [math.log(BOUNDS[p][1]) if p in LOG_PARAMETERS else BOUNDS[p][1] for p in params]
    return lower, upper


class ShotFailure(Exception):
    """``model`` could not predict one shot (its id and the reason)."""

    def __init__(self, shot_id, reason):
        super().__init__(f"shot '{shot_id}': {reason}")
        self.shot_id, self.reason = shot_id, reason


def log_ratios(shots, model, mapping, tables=None):
    """``ln(predicted / measured)`` per shot for ``model`` (a model label); a shot the model
    cannot predict (a numerical or range error, a depth not finite and > 0) raises
    :class:`ShotFailure`."""
    ratios = []
    for shot in shots:
        try:
            depth = predict(shot, model, mapping, tables)
        except (CavexInputError, CavexNumericalError) as exc:
            raise ShotFailure(shot.id, str(exc).splitlines()[0]) from None
        if not (math.isfinite(depth) and depth > 0.0):
            raise ShotFailure(shot.id, f"predicted depth {depth!r} m")
        ratios.append(math.log(depth / shot.depth))
    return np.array(ratios)


def fit(shots, resistance="derived", params=None, start=None, tables=None, progress=False, *,
        boundary=None):
    """Least-squares fit of ``params`` of the mapping for ``resistance`` to ``shots``.

    Parameters
    ----------
    shots : sequence of Shot
    resistance : {"derived", "paper", "table"}
        the models that fit the mapping (:mod:`cavex.analytic.models`).
    boundary : {"dynamic", "quasi-static"}, optional
        The derived model's convention (default dynamic; the paper model has its own).
    params : sequence of str, optional
        Free parameters (default ``lam``, ``strength_factor``).
    start : Mapping, optional
        Starting point and the fixed parameters (default :class:`Mapping`).
    tables : TableCache, optional
        FE tables (``table`` only; default an in-memory cache).
    progress : bool
        One line per evaluation on stderr.

    A shot the model cannot predict at a parameter the fit visits (:class:`ShotFailure`) is
    left out, named in ``skipped`` (and on stderr with ``progress``), and the fit starts again
    without it; too few shots left is a numerical failure.

    Returns
    -------
    Calibration
        Fitted parameters rounded to :data:`PARAMETER_DIGITS` significant digits; statistics
        (``n``, ``mean_abs_log_ratio``, ``rms_log_ratio``, ``evaluations``) at the rounded
        parameters; the fitted shots off by more than
        :data:`~cavex.verification.validation.predict.OUTLIER_FACTOR` there (``outliers``:
        flagged, still fitted) and the statistics without them (``without_outliers``).
    """
    model, params = model_label(resistance, boundary), check_parameters(params)
    require(len(shots) >= len(params), "shots",
            f"at least as many shots as free parameters ({len(params)})", len(shots))
    start = start or Mapping()
    tables = tables or TableCache(progress=False)
    tables.velocities_for(shots)
    active, skipped = list(shots), []
    while True:
        try:
            mapping, evaluations, errors = _least_squares(active, model, params, start,
                                                          tables, progress)
            r = log_ratios(active, model, mapping, tables)
            break
        except ShotFailure as failure:
            skipped.append((failure.shot_id, failure.reason))
            active = [s for s in active if s.id != failure.shot_id]
            if progress:
                print(f"cavex: calibrate {model}: {failure}; fitting again without it",
                      file=sys.stderr, flush=True)
            if len(active) < len(params):
                raise CavexNumericalError(
                    f"calibration of {model}: {len(skipped)} shot(s) the model cannot "
                    f"predict, too few left (last {failure})") from None
    flagged = np.abs(r) > math.log(OUTLIER_FACTOR)
    return Calibration(model, mapping, params, tuple(s.id for s in active),
                       statistics=(*fit_statistics(r), ("evaluations", evaluations)),
                       skipped=tuple(skipped),
                       outliers=tuple(s.id for s, f in zip(active, flagged, strict=True) if f),
                       without_outliers=fit_statistics(r[~flagged]), standard_errors=errors)


def refitted_depths(calibration, train, held, tables=None, erosion=None, shots=None):
    """``(choice, depths)``: ``calibration``'s model fitted again, its free parameters from its
    file, to the shots ``train`` (:func:`cavex.verification.validation.calibration.fit`) and
    its depths of the shots ``held`` (None where it fails); ``choice`` says what was fitted.
    The fit sets the FE tables' velocity grid to its shots': it is set back to cover
    ``shots`` (default ``train`` and ``held``) for the predictions."""
    model, boundary = parse_label(calibration.model, "models", labels(fits_mapping=True))
    tables = tables or TableCache()
    try:
        refit = fit(train, model.name, calibration.params, tables=tables, boundary=boundary)
    except CavexNumericalError as exc:
        return f"refit failed: {str(exc).splitlines()[0]}", [None] * len(held)
    finally:
        tables.velocities_for(list(shots) if shots is not None else [*train, *held])
    depths = []
    for shot in held:
        try:
            depths.append(round_significant(predict(shot, calibration.model, refit.mapping,
                                                    tables, erosion), DEPTH_DIGITS))
        except (CavexInputError, CavexNumericalError):
            depths.append(None)
    values = ", ".join(f"{p} = {getattr(refit.mapping, p):.6g}" for p in calibration.params)
    return f"refitted on {len(refit.shots)} shots: {values}", depths



def fit_statistics(r):
    """``n``, mean ``|ln ratio|`` and rms ``ln ratio`` of the log ratios ``r`` (6 significant
    digits; the means None without shots)."""
    def rounded(value):
        return round_significant(float(value), 6) if r.size else None

    return (("n", int(r.size)), ("mean_abs_log_ratio", rounded(np.abs(r).mean())),
            ("rms_log_ratio", rounded(np.sqrt((r ** 2).mean()))))


def _least_squares(shots, model, params, start, tables, progress):
    """The fitted mapping (parameters rounded to :data:`PARAMETER_DIGITS`), the number of
    residual evaluations and the parameters' standard errors (:func:`standard_errors`);
    :class:`ShotFailure` passes through."""
    from scipy.optimize import least_squares  # not at the top: the checks run without scipy

    kind = "FE table" if parse_label(model, "model")[0].takes_table else "closed form"
    count = [0]
    began = time.monotonic()

    def residuals(x):
        mapping = start.with_values(params, _to_values(x, params))
        r = log_ratios(shots, model, mapping, tables)
        count[0] += 1
        if progress:
            values = ", ".join(f"{p} = {v:.6g}" for p, v in zip(params, _to_values(x, params),
                                                               strict=True))
            print(f"cavex: calibrate {model} evaluation {count[0]}: {values}: mean |ln ratio| "
                  f"{np.abs(r).mean():.4f} ({time.monotonic() - began:.0f} s)", file=sys.stderr,
                  flush=True)
        return r

    lower, upper = _bounds(params)
    x0 = np.clip(_to_variables(start, params), lower, upper)
    jacobian = _ForwardDifferences(residuals, DIFF_STEP[kind], upper)
    tol = TOLERANCE[kind]
    try:
        solution = least_squares(jacobian.residuals, x0, jac=jacobian, bounds=(lower, upper),
                                 method="trf", xtol=tol, ftol=tol, gtol=tol)
    except CavexInputError as exc:
        raise CavexNumericalError(f"calibration of {model} left the models' range: {exc}") \
            from None
    values = [round_significant(v, PARAMETER_DIGITS) for v in _to_values(solution.x, params)]
    errors = standard_errors(solution.jac, solution.fun, params, solution.x)
    # at a bound the linearised error describes no spread (the fit wants the parameter beyond),
    # and the value is the bound (lam = 4.4e-18 was the round-off of 0)
    sides = [at_bound(p, v) for p, v in zip(params, values, strict=True)]
    errors = [None if side else e for side, e in zip(sides, errors, strict=True)]
    values = [BOUNDS[p][0 if side == "lower" else 1] if side else v
              for p, v, side in zip(params, values, sides, strict=True)]
    return start.with_values(params, values), count[0], tuple(zip(params, errors, strict=True))


def at_bound(param, value):
    """``"lower"`` or ``"upper"`` if the fitted ``value`` of ``param`` lies on that bound of
    :data:`BOUNDS` (to 1e-6 of the bounds' span, in ``ln`` for :data:`LOG_PARAMETERS`), else
    None: the fit wants it beyond, so the shots determine neither it nor its error."""
    (lower,), (upper,) = _bounds((param,))
    x = math.log(value) if param in LOG_PARAMETERS else value
    tolerance = 1e-6 * (upper - lower)
    if x - lower <= tolerance:
        return "lower"
    if upper - x <= tolerance:
        return "upper"
    return None


def standard_errors(jacobian, residuals, params, x):
    r"""Standard error of each fitted parameter, from the Jacobian ``J`` of the residuals at
    the solution ``x`` (the linearised least-squares estimate):

    .. math:: \mathrm{cov}(x) = s^2 (J^T J)^{-1}, \qquad s^2 = \frac{\sum_i r_i^2}{n - p}

    with ``n`` shots and ``p`` parameters. A factor fitted as ``ln f`` (:data:`LOG_PARAMETERS`)
    gets ``f * se(ln f)`` (first order). None for every parameter when ``n <= p`` (no degree of
    freedom left to estimate the scatter) and where ``J^T J`` is singular or the variance not
    finite (a parameter the depths do not determine; once ``inf``, printed as such)."""
    jacobian, residuals = np.asarray(jacobian, dtype=float), np.asarray(residuals, dtype=float)
    n, p = jacobian.shape
    if n <= p:
        return [None] * p
    scatter = float(residuals @ residuals) / (n - p)
    normal = jacobian.T @ jacobian
    try:
        variances = scatter * np.diag(np.linalg.inv(normal))
    except np.linalg.LinAlgError:
        return [None] * p
    values = _to_values(x, params)
    errors = [float(math.sqrt(max(v, 0.0)) * (value if name in LOG_PARAMETERS else 1.0))
              for name, v, value in zip(params, variances, values, strict=True)]
    return [e if math.isfinite(e) else None for e in errors]


class _ForwardDifferences:
    """Forward-difference Jacobian with an absolute step ``h`` in every variable (backward at
    the upper bound), reusing the residuals ``least_squares`` has just evaluated at ``x``.

    (``least_squares``' own ``diff_step`` is relative to ``|x|`` and falls back to ~1e-8 at
    ``x = 0``, i.e. at a factor of 1: far too small for the FE table's noise.)
    """

    def __init__(self, function, h, upper):
        self.function, self.h, self.upper = function, h, np.asarray(upper)
        self._last = None

    def residuals(self, x):
        r = self.function(x)
        self._last = (np.array(x, dtype=float), r)
        return r

    def __call__(self, x, *args):
        x = np.asarray(x, dtype=float)
        r0 = self._last[1] if self._last is not None and np.array_equal(self._last[0], x) \
            else self.function(x)
        columns = []
        for j in range(x.size):
            step = self.h if x[j] + self.h <= self.upper[j] else -self.h
            shifted = x.copy()
            shifted[j] += step
            columns.append((self.function(shifted) - r0) / step)
        return np.column_stack(columns)


# --- files ------------------------------------------------------------------------------------

def calibration_text(calibration, shots_file, reference, command=None):
    """The TOML text of a calibration file (see the module docstring); every string and comment
    escaped (:func:`cavex.config.toml_string`), so any shot id or path reads back."""
    from cavex.config import config_text, toml_comment, toml_string

    stats = dict(calibration.statistics)
    m = calibration.mapping
    lines = ["# cavex calibration, written by `cavex calibrate`.",
             *([toml_comment(f"command: {command}")] if command else []),
             toml_comment(f"[projectile] and [[layers]]: the calibrated target of shot "
                          f"'{reference.id}', so"),
             "# `cavex penetrate --config THIS_FILE` runs it (derived-quasi-static: add",
             "# --boundary quasi-static; paper: --resistance paper). `cavex validate --calibration",
             "# THIS_FILE` reads [calibration] and applies its mapping to every shot.",
             "", "[calibration]",
             f"model = {toml_string(calibration.model)}",
             f"params = [{', '.join(toml_string(p) for p in calibration.params)}]",
             *(f"{name} = {getattr(m, name)!r}" for name in ("lam", "strength_factor",
                                                              "modulus_factor", "nu")),
             f"shots_file = {toml_string(str(shots_file))}",
             f"shots = [{', '.join(toml_string(i) for i in calibration.shots)}]",
             *([f"skipped = [{', '.join(toml_string(i) for i, _ in calibration.skipped)}]"]
               if calibration.skipped else []),
             *([f"outliers = [{', '.join(toml_string(i) for i in calibration.outliers)}]"]
               if calibration.outliers else []),
             f"reference_shot = {toml_string(reference.id)}",
             *(f"{k} = {v!r}" for k, v in stats.items()), "", ""]
    target, projectile = shot_target(reference, m), shot_projectile(reference)
    return "\n".join(lines) + config_text(target, projectile)


def read_calibration(path):
    """A :class:`Calibration` from a calibration file; a bad file is a one-line input error
    ``'<path>': <where> <what>`` (:mod:`cavex.input_files`)."""
    return in_file(path, parse_calibration, read_toml(path), source=str(path))


def parse_calibration(data, source=""):
    """A :class:`Calibration` from a parsed calibration file (its target checked too)."""
    from cavex.config import parse_config

    parse_config(data)
    if "calibration" not in data:
        raise CavexInputError("is missing (a calibration file is written by `cavex "
                              "calibrate`)", "calibration")
    table = data["calibration"]
    check_keys(table, CALIBRATION_KEYS, "calibration.", required=CALIBRATION_REQUIRED)
    prefixed(parse_model_label, "calibration.", table["model"])
    require(isinstance(table["params"], list) and all(isinstance(p, str)
                                                      for p in table["params"]),
            "calibration.params", "an array of names", table["params"])
    params = prefixed(check_parameters, "calibration.", table["params"])
    mapping = prefixed(Mapping, "calibration.", **{k: table[k] for k in (
        "lam", "strength_factor", "modulus_factor", "nu")})
    shots = table["shots"]
    require(isinstance(shots, list) and shots and all(isinstance(s, str) for s in shots),
            "calibration.shots", "a non-empty array of shot ids", shots)
    skipped, outliers = table.get("skipped", []), table.get("outliers", [])
    for name, ids in (("skipped", skipped), ("outliers", outliers)):
        require(isinstance(ids, list) and all(isinstance(s, str) for s in ids),
                f"calibration.{name}", "an array of shot ids", ids)
    statistics = tuple((k, table[k]) for k in ("n", "mean_abs_log_ratio", "rms_log_ratio",
                                               "evaluations") if k in table)
    return Calibration(table["model"], mapping, params, tuple(shots), source=source,
                       statistics=statistics,
                       skipped=tuple((s, "not predicted in the fit") for s in skipped),
                       outliers=tuple(outliers))
