r"""The regimes a validation is reported by, and each model's statistics in them.

A shot's regime follows from its inputs only (never from a measured depth):

- ``all``;
- ``normal_strength``: ``f_c <= 100`` MPa and ``V0 <= 1000`` m/s (where the empirical formulas
  were fitted and rigid projectiles are the rule);
- ``fast``: ``V0 > 1000`` m/s;
- ``high_strength``: ``f_c > 100`` MPa (high- and ultra-high-strength concrete);
- ``not_flagged``: the shots the rigid-regime rule keeps
  (:func:`cavex.verification.validation.regimes.rigid_flag`: the concrete model's mean
  nose pressure at impact at most the projectile's listed yield strength, or no yield listed).

The flag is about the nose yielding (deforming), which no model here covers. Nose erosion by
abrasion is modelled (``--erosion``, :mod:`cavex.analytic.penetration.erosion`), but its law
(Silling and Forrestal 2007) has no velocity threshold that could replace the flag: its mass
loss grows as ``V0^2`` from 0. So the flag is unchanged: 110 of the 286 development shots
(49 of them above 800 m/s, 61 below; docs/erosion.md).

Per regime and model: ``n``, the mean ``|ln(predicted/measured)|`` and the bias, the mean
``ln(predicted/measured)`` (positive: too deep), rounded like every statistic of a validation.
"""

import math

import numpy as np

from cavex.errors import require
from cavex.verification.output.number_format import FE_DIGITS, round_significant

DEPTH_DIGITS = FE_DIGITS  # predicted depths and statistics in the result files

NORMAL_STRENGTH = 100e6  # Pa
FAST = 1000.0  # m/s
NON_RIGID = "non-rigid"
#: name (a JSON key) -> membership from a shot's ``f_c`` (Pa), ``V0`` (m/s) and rigid flag
REGIMES = {
    "all": lambda fc, V0, flag: True,
    "normal_strength": lambda fc, V0, flag: fc <= NORMAL_STRENGTH and V0 <= FAST,
    "fast": lambda fc, V0, flag: V0 > FAST,
    "high_strength": lambda fc, V0, flag: fc > NORMAL_STRENGTH,
    "not_flagged": lambda fc, V0, flag: flag is not None and flag != NON_RIGID,
}
#: name -> the words tables and figures show
REGIME_TITLES = {"all": "all", "normal_strength": "normal strength, V0 <= 1000 m/s",
                 "fast": "V0 > 1000 m/s", "high_strength": "f_c > 100 MPa",
                 "not_flagged": "not flagged non-rigid"}


def log_statistics(ratios, digits):
    """``{n, mean_abs_log_ratio, mean_log_ratio}`` of the positive finite ``ratios`` (None
    where there are none), rounded to ``digits`` significant digits."""
    logs = np.log([r for r in ratios if r is not None and math.isfinite(r) and r > 0.0])
    if not logs.size:
        return {"n": 0, "mean_abs_log_ratio": None, "mean_log_ratio": None}
    return {"n": int(logs.size),
            "mean_abs_log_ratio": round_significant(float(np.abs(logs).mean()), digits),
            "mean_log_ratio": round_significant(float(logs.mean()), digits)}


def regime_statistics(rows, columns, digits):
    """``{regime: {column: log_statistics}}`` over ``rows`` (dicts with ``fc_Pa``, ``V0_m_s``,
    ``flag`` and ``ratio``); a regime with no shot is left out."""
    out = {}
    for name, member in REGIMES.items():
        chosen = [row for row in rows if member(row["fc_Pa"], row["V0_m_s"], row.get("flag"))]
        if chosen:
            out[name] = {c: log_statistics([row["ratio"][c] for row in chosen], digits)
                         for c in columns}
    return out


def nose_pressure(shot, resistance):
    """Mean nose pressure at impact ``F(V0)/(pi a^2)`` (Pa)."""
    return resistance.force(0.0, shot.V0) / (math.pi * 0.25 * shot.diameter ** 2)


def rigid_flag(shot, resistance):
    """``"non-rigid"`` when the mean nose pressure at impact exceeds the projectile's listed
    yield strength (column ``proj_yield_MPa``), ``""`` otherwise or when it is not listed."""
    text = shot.extra.get("proj_yield_MPa", "")
    try:
        strength = float(text) * 1e6
    except ValueError:
        return ""
    require(strength > 0.0, "proj_yield_MPa", "a positive strength in MPa", text)
    return "non-rigid" if nose_pressure(shot, resistance) > strength else ""
