"""How many significant digits the committed result files carry, and the one place that rounds.

Regenerating ``results/`` on another CPU must not change a committed file. The numbers differ
between CPUs in their last bits: numpy's SIMD ``exp``/``log``/``sin`` (AVX-512) and libm differ
by an ulp, and the solvers amplify that (FE wall stresses about 1e-11 relative, FE error
estimates about 1e-9, integrated trajectories about 1e-8 through the adaptive step
selection). Every writer of a result file
therefore writes a number with only the digits the numerics support, through this module:

- text (CSV, JSON attributes): :func:`format_number` / :func:`round_nested`;
- netCDF data variables: :func:`round_dataset`, which takes the digits of each variable from
  :data:`VARIABLE_DIGITS` (``cavex.verification.fedata.table.write_table`` applies it to every FE
  table and report grid it writes; a batch sweep's ``results.nc``, which holds wall times, is
  written exactly; the report rounds its grid before analysing it, so that the relative
  errors, validity codes and medians it prints are functions of the stored numbers).

Digits per quantity (:data:`VARIABLE_DIGITS` maps variable names to them), one line of
justification each:

- trajectories and phase ends (integrator): 6. ``solve_ivp`` runs at ``rtol = 1e-9``, but its
  adaptive step selection amplifies a last-bit change of the force into ~1e-8 of the
  trajectory (measured: when the closed form's summation order changed, the soil stage of the
  default run moved by 7e-9 relative); libm's CPU-dependent variants (FMA) make such changes
  across CPUs. 6 digits leave two orders between that spread and the rounding unit.
- FE wall stress ``sigma_r``, FE ``S``, FE plastic radius: 6. Newton tolerance 1e-8 and a
  discretisation error of 1e-4..1e-3 (the error estimate); cross-CPU spread ~1e-11.
- FE error estimate (Richardson): an absolute quantum, not significant digits,
  :data:`ESTIMATE_DECIMALS` = 5 decimals (multiples of 1e-5, i.e. 0.001 % of the wall stress).
  The estimate is a difference of two FE runs, ``|S_h - S_2h| / 3 |S_h|``: its cross-CPU spread
  is *absolute*, about 1e-9 (the spread of ``S_h / S_2h``, set by where Newton stops at its
  tolerance), whatever the estimate's size. Significant digits give a small estimate a fine
  quantum (3 digits of 7.04e-6 are 1e-8, only 10 spreads wide: one machine wrote 7.04e-06 and
  another 7.03e-06 for the same cell); a fixed quantum of 1e-5 is 10**4 spreads wide, so a
  value rounds differently on another CPU with odds of about 2e-4, and it is 500 times finer
  than the 0.5 % that the commands promise (an estimate below 5e-6 is written 0: "below
  0.0005 %"). The estimates of a table reach 5e-3, which keeps 3 significant digits there.
- closed forms (analytic ``sigma_r``, plastic radius ``b``): 10. Scalar libm and Newton to
  4e-16: a few ulps (~1e-15), 5 orders below the 10th digit.
- the report's relative errors, error parts and closed-form ``S`` (``rel_err_*``, ``part_*``,
  ``S_*``): kept as computed. The report computes them from the rounded values, so they are
  the same on every CPU; rounding them again would part them from the percentages it prints.
- other relative differences against FE (``relative_difference_*``): 6, the FE's digits.
- any other float variable: 6 (unknown provenance, treated as FE output).

Trajectory CSVs of ``cavex penetrate`` (:data:`TRAJECTORY_QUANTA`): the rows of a phase are
equally spaced in time from its start to its end (the same number whatever the integrator's steps,
which used to be the rows and moved with the last bits of the force), but the phase's end is an
event whose time is not reproducible to the last digits: a 1-ulp change of the force (a model of
another CPU's libm: each force evaluation times ``1 + k eps``, ``k`` in -1, 0, +1 by a hash of its
arguments, 16 seeds; tests/test_committed_results.py) moved the steps near the stop by up to
5.8e-9 s (1.6e-6 relative) and so the velocity there by ``a dt``, up to 9.3e-4 m/s (at
0.95 m/s: 1e-3 relative, the 0.952771 against 0.95264 m/s that another CPU wrote). Such a
column is written to the coarser of :data:`TRAJECTORY_DIGITS` significant digits and an absolute
quantum that is 10 or more of those spreads wide: ``t_s`` 1e-7 s (17 spreads), ``velocity_m_s``
1e-2 m/s (10 spreads; 1e-3 m/s changed 10 values in the 16 seeds, 1e-2 none). Depth keeps 6
digits (spread 5e-8 m: none changed). The deceleration of a row at a fixed time within a phase
moves with the phase's start time: by up to 2.3e-6 relative (the paper model's runway, 7 values
in the 16 seeds at 6 digits), so it is written to 5 significant digits (a quantum of 1e-5 to
1e-4 relative, 4 to 40 spreads; none changed).

Coordinates (velocity, depth) are inputs, not results, and are never rounded (the switch nodes
sit 1e-9 m past the switch depths); integer, boolean and string variables are written as they
are.

Rounding goes through Python's float-to-decimal conversion (``format(x, ".{n}e")``), which is
correctly rounded in software: no libm call, so it is the same on every CPU, and rounding a
rounded number again returns it unchanged. A value lying on a rounding boundary (within the
cross-CPU spread of it) can still round differently on another CPU; the digits above make that
unlikely (about spread x 10**digits per value), not impossible.
"""

import fnmatch
import numbers

import numpy as np

TRAJECTORY_DIGITS = 6
FE_DIGITS = 6
ESTIMATE_DECIMALS = 5   # an absolute quantum (10**-5), not significant digits (docstring)
CLOSED_FORM_DIGITS = 10
RELATIVE_DIGITS = FE_DIGITS
DEFAULT_DIGITS = FE_DIGITS
KEPT = None  # derived by the report from rounded values: written as computed



class Decimals(int):
    """A rule of :data:`VARIABLE_DIGITS` that rounds to this many decimal places (an absolute
    quantum ``10**-n``) instead of significant digits."""

    def __repr__(self):
        return f"Decimals({int(self)})"


ESTIMATE = Decimals(ESTIMATE_DECIMALS)

# Rules of ``cavex penetrate``'s trajectory columns (module docstring): a Decimals is an absolute
# quantum (the coarser of it and TRAJECTORY_DIGITS significant digits), an int significant digits.
TRAJECTORY_QUANTA = {"t_s": Decimals(7), "velocity_m_s": Decimals(2), "deceleration_m_s2": 5}

# (variable-name pattern, significant digits, Decimals or KEPT); the first matching pattern
# decides.
# Names of the FE tables and report grids (cavex.verification.fedata.table, report_analysis) and of
# the batch sweeps (cavex.verification.fedata.batch.VARIABLES).
VARIABLE_DIGITS = (
    ("error_estimate", ESTIMATE),
    ("sigma_r_dynamic", CLOSED_FORM_DIGITS),
    ("sigma_r_quasi_static", CLOSED_FORM_DIGITS),
    ("sigma_r_paper", CLOSED_FORM_DIGITS),
    ("analytic_*", CLOSED_FORM_DIGITS),
    ("b_dynamic", CLOSED_FORM_DIGITS),
    ("b_quasi_static", CLOSED_FORM_DIGITS),
    ("sigma_r", FE_DIGITS),
    ("fe_sigma_r", FE_DIGITS),
    ("sigma_r_first_layer", FE_DIGITS),
    ("S", FE_DIGITS),
    ("plastic_radius", FE_DIGITS),
    ("fe_plastic_radius", FE_DIGITS),
    ("rel_err_*", KEPT),
    ("part_*", KEPT),
    ("S_*", KEPT),
    ("relative_difference_*", RELATIVE_DIGITS),
)


def _round_scalar(x, digits):
    return float(format(x, f".{digits - 1}e"))


def round_significant(values, digits):
    """``values`` rounded to ``digits`` significant decimal digits.

    NaN, infinities and zeros (of either sign) are returned unchanged. A scalar gives a
    ``float``, anything else an array of floats of the same shape.
    """
    if digits < 1:
        raise ValueError(f"digits must be >= 1, got {digits}")
    if np.ndim(values) == 0:
        return _round_scalar(float(values), digits)
    array = np.asarray(values, dtype=float)
    flat = [_round_scalar(x, digits) for x in array.ravel().tolist()]
    return np.array(flat, dtype=float).reshape(array.shape)


def round_decimals(values, decimals):
    """``values`` rounded to ``decimals`` places after the point (correctly rounded, through
    ``format(x, ".{decimals}f")``; the sign of a zero result is dropped). NaN and infinities
    unchanged; a scalar gives a ``float``, anything else an array of the same shape."""
    if decimals < 0:
        raise ValueError(f"decimals must be >= 0, got {decimals}")

    def one(x):
        return x if not np.isfinite(x) else float(format(x, f".{decimals}f")) + 0.0

    if np.ndim(values) == 0:
        return one(float(values))
    array = np.asarray(values, dtype=float)
    return np.array([one(x) for x in array.ravel().tolist()], dtype=float).reshape(array.shape)


def round_rule(values, rule):
    """``values`` rounded by one rule of :data:`VARIABLE_DIGITS`: :class:`Decimals` or
    significant digits."""
    if isinstance(rule, Decimals):
        return round_decimals(values, int(rule))
    return round_significant(values, rule)


def format_number(value, digits=TRAJECTORY_DIGITS, quantum=None):
    """Text of one value for a CSV cell: floats with ``digits`` significant digits (``%g``
    style), or, with ``quantum`` (a :class:`Decimals` ``n``), to the coarser of those digits
    and the absolute quantum ``10**-n`` (for a quantity whose spread is absolute: near zero it
    keeps no digit the numerics do not support); integers, booleans and strings as they are."""
    if isinstance(value, (str, bool, np.bool_, numbers.Integral)):
        return str(value)
    if isinstance(value, numbers.Real):
        x = float(value)
        if quantum is not None and np.isfinite(x) and _finer_than(x, digits, int(quantum)):
            x = round_decimals(x, int(quantum))
        return format(x, f".{digits}g")
    return str(value)


def _finer_than(x, digits, decimals):
    """Whether the last of ``digits`` significant digits of ``x`` is finer than ``10**-decimals``
    (from the decimal exponent of the correctly rounded text, no libm)."""
    if x == 0.0:
        return False
    exponent = int(format(x, f".{digits - 1}e").rsplit("e", 1)[1])
    return exponent - (digits - 1) < -decimals


def round_nested(value, digits=TRAJECTORY_DIGITS):
    """Every float in nested dicts, lists and tuples rounded (for JSON attributes)."""
    if isinstance(value, dict):
        return {k: round_nested(v, digits) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [round_nested(v, digits) for v in value]
    if isinstance(value, (float, np.floating)):
        return round_significant(value, digits)
    return value


def variable_digits(name):
    """Significant digits of the float variable ``name`` (see :data:`VARIABLE_DIGITS`), a
    :class:`Decimals` (an absolute quantum), or ``None``: written as computed."""
    return next((digits for pattern, digits in VARIABLE_DIGITS
                 if fnmatch.fnmatchcase(name, pattern)), DEFAULT_DIGITS)


def round_variable(name, values):
    """``values`` of the data variable ``name`` rounded to :func:`variable_digits` if they
    are floats (else, or if the variable is :data:`KEPT`, unchanged)."""
    values = np.asarray(values)
    digits = variable_digits(str(name))
    if values.dtype.kind != "f" or digits is KEPT:
        return values
    return round_rule(values, digits).astype(values.dtype)


def round_dataset(ds):
    """A copy of ``ds`` with every float data variable rounded (:func:`round_variable`);
    coordinates and non-float variables unchanged, attributes kept."""
    out = ds.copy()
    for name, variable in ds.data_vars.items():
        if variable.dtype.kind == "f":
            out[name] = variable.copy(data=round_variable(name, variable.values))
    return out
