"""Errors that cavex reports to its users, and the checks that raise them."""

import math


class CavexInputError(ValueError):
    """Bad input: the message names the parameter and its accepted range, on one line.

    Parameters
    ----------
    problem : str
        What is wrong, e.g. ``"must be a finite number > 0 (got -1.0)"``; the whole message
        when ``where`` is None.
    where : str, optional
        The parameter or key path it is wrong in, e.g. ``"layers[1].E"``. The message is then
        ``parameter '<where>' <problem>``; :func:`prefixed` extends ``where``, and an input file
        reader (:func:`cavex.input_files.in_file`) words it ``'<path>': <where> <problem>``.
    """

    #: the input file the message names (set by :func:`cavex.input_files.file_error`)
    path = None

    def __init__(self, problem, where=None):
        super().__init__(problem if where is None else f"parameter '{where}' {problem}")
        self.problem, self.where = problem, where


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
        raise CavexInputError(f"must be {accepted} (got {shown(value)})", parameter)


#: the characters of a refused value a message shows (a huge array or string is cut)
SHOWN_CHARACTERS = 120


def shown(value):
    """``repr(value)``, cut to :data:`SHOWN_CHARACTERS` with ``...`` (one short line)."""
    text = repr(value)
    return text if len(text) <= SHOWN_CHARACTERS else text[:SHOWN_CHARACTERS - 3] + "..."


def require_choice(value, choices, parameter):
    """Raise :class:`CavexInputError` unless ``value`` is one of ``choices``."""
    if value not in choices:
        require(False, parameter, " or ".join(map(repr, choices)), value)


#: the bidirectional formatting characters (U+202A-U+202E, U+2066-U+2069): they reorder the
#: text printed after them, so that an id could show as another ("Trojan source")
BIDI_CONTROLS = frozenset(chr(c) for c in (*range(0x202A, 0x202F), *range(0x2066, 0x206A)))


def has_control_characters(text):
    """Whether ``text`` holds a control character (U+0000-U+001F, U+007F-U+009F, NUL too) or
    a bidirectional formatting one (:data:`BIDI_CONTROLS`): none belongs in an id or a name
    that is written into files and printed."""
    return any(ord(ch) < 0x20 or 0x7F <= ord(ch) <= 0x9F or ch in BIDI_CONTROLS
               for ch in text)


def require_name(text, parameter):
    """Raise :class:`CavexInputError` unless ``text`` is a string without control
    characters (:func:`has_control_characters`)."""
    require(isinstance(text, str), parameter, "a string", text)
    require(not has_control_characters(text), parameter, "a string without control characters",
            text)


def is_finite_number(value):
    """True for a finite int or float (booleans are not numbers here)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def check_keys(table, allowed, where, required=()):
    """Refuse unknown keys of a TOML table (naming every one, and the accepted keys), then
    missing required keys (naming every one).

    ``where`` prefixes the key path, e.g. ``"layers[0]."``; the error's ``where`` is the first
    offending key, e.g. ``layers[0].Young is not a known key, nor is colour (accepted: ...)``.
    """
    unknown = [key for key in table if key not in allowed]
    if unknown:
        raise CavexInputError(f"is not a known key{_others('nor', unknown[1:])} (accepted: "
                              f"{', '.join(sorted(allowed))})", f"{where}{unknown[0]}")
    missing = [key for key in sorted(required) if key not in table]
    if missing:
        raise CavexInputError(f"is missing{_others('as', missing[1:])} (required)",
                              f"{where}{missing[0]}")


def _others(word, keys):
    """``", nor is b"``, ``", as are b, c"``: the further keys of a :func:`check_keys` error."""
    if not keys:
        return ""
    return f", {word} {'is' if len(keys) == 1 else 'are'} {', '.join(map(str, keys))}"


def prefixed(factory, where, *args, **kwargs):
    """Call ``factory``; prefix the parameter or key named in an input error with ``where``."""
    try:
        return factory(*args, **kwargs)
    except CavexInputError as exc:
        if exc.where is None:
            raise
        raise CavexInputError(exc.problem, where + exc.where) from None
