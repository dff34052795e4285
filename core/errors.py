"""Errors that cavex reports to its users, and the checks that raise them."""

import math
import re


class CavexInputError(ValueError):
    """Bad input: the message names the parameter and its accepted range, on one line."""


class CavexNumericalError(RuntimeError):
    """A computation that failed numerically (never returned as NaN or a plausible number)."""


def require(condition, parameter, accepted, value):
    """Raise :class:`CavexInputError` unless ``condition`` holds.

    Parameters
    ----------
    condition : bool
        The check that must hold.
    parameter : str
        Name of the offending parameter, as the user wrote it.
    accepted : str
        The accepted range, e.g. ``"> 0"`` or ``"in [0, 3)"``.
    value : object
        The value that was given.
    """
    if not condition:
        raise CavexInputError(f"parameter '{parameter}' must be {accepted} (got {value!r})")


def require_choice(value, choices, parameter):
    """Raise :class:`CavexInputError` unless ``value`` is one of ``choices``."""
    if value not in choices:
        require(False, parameter, " or ".join(map(repr, choices)), value)


def is_finite_number(value):
    """True for a finite int or float (booleans are not numbers here)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def check_keys(table, allowed, where, required=()):
    """Reject unknown keys and report the first missing required key of a TOML table.

    ``where`` prefixes the key in the message, e.g. ``"layers[0]."``.
    """
    for key in table:
        if key not in allowed:
            accepted = ", ".join(sorted(allowed))
            raise CavexInputError(f"unknown key '{where}{key}' (accepted: {accepted})")
    for key in sorted(required):
        if key not in table:
            raise CavexInputError(f"missing key '{where}{key}'")


def prefixed(factory, where, *args, **kwargs):
    """Call ``factory``; prefix the parameter or key named in an input error with ``where``."""
    try:
        return factory(*args, **kwargs)
    except CavexInputError as exc:
        message = re.sub(r"(parameter|key) '", lambda m: f"{m.group(1)} '{where}", str(exc),
                         count=1)
        raise CavexInputError(message) from None
