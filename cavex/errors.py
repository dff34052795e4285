"""Errors that cavex reports to its users."""


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
