"""The user's input files (target config, sweep, calibration: TOML; shots: CSV): one way to
open, decode and parse them, and one form of error.

Every refusal of an input file is one line ``'<path>': <where> <what>``:

- ``<where>`` is where in the file: a TOML key path (``layers[1].E``, ``grid.velocities[0]``),
  a line and column (``line 3, column 5``: TOML syntax, text encoding) or a CSV line and column
  (``line 7 (shot 'B2'), column V0_m_s``); absent for the file as a whole;
- ``<what>`` is what is wrong, for a value with the accepted range and the value given
  (``must be a finite number > 0 (got -1.0)``).

For example ``'case.toml': layers[1].E must be a finite number > 0 (got -1.0)`` or
``'case.toml': cannot be read (No such file or directory)``.
"""

import codecs
import re
import tomllib

from cavex.errors import CavexInputError

# tomllib words a syntax error "<what> (at line L, column C)" or "<what> (at end of document)"
_TOML_PLACE = re.compile(r"(?P<what>.*) \(at (?:line (?P<line>\d+), column (?P<column>\d+)|"
                         r"end of document)\)", re.DOTALL)


def file_error(path, what, where=None):
    """The :class:`CavexInputError` ``'<path>': <where> <what>`` (``'<path>': <what>``)."""
    error = CavexInputError(f"'{path}': {what}" if where is None else f"'{path}': {where} {what}")
    error.path = str(path)
    return error


def in_file(path, parse, *args, **kwargs):
    """``parse(*args, **kwargs)``; an input error it raises is reworded to name ``path``: the
    parameter or key it names becomes ``<where>``, e.g. ``'case.toml': layers[1].E must be ...``.
    (An error that already names a file is passed on unchanged.)"""
    try:
        return parse(*args, **kwargs)
    except CavexInputError as exc:
        if exc.path is not None:
            raise
        raise file_error(path, exc.problem, exc.where) from None


def read_text(path):
    """The text of the UTF-8 file ``path``; a byte-order mark at its start is dropped, line
    ends are kept as they are.

    Raises
    ------
    CavexInputError
        A missing or unreadable file, a folder, bytes that are not UTF-8 (their line and column
        named).
    """
    try:
        with open(path, "rb") as handle:
            data = handle.read()
    except OSError as exc:
        raise file_error(path, f"cannot be read ({exc.strerror or exc})") from None
    data = data.removeprefix(codecs.BOM_UTF8)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise file_error(path, f"is not UTF-8 text (byte 0x{data[exc.start]:02x})",
                         _line_and_column(data, exc.start)) from None


def _line_and_column(data, offset):
    """``line L, column C`` (1-based, C in characters) of byte ``offset`` of ``data``."""
    line = data.count(b"\n", 0, offset) + 1
    start = data.rfind(b"\n", 0, offset) + 1
    column = len(data[start:offset].decode("utf-8", errors="replace")) + 1
    return f"line {line}, column {column}"


def read_toml(path):
    """The parsed TOML file ``path`` (a dict); see :func:`read_text` for the file itself.

    Raises
    ------
    CavexInputError
        As :func:`read_text`, and a TOML syntax error with its line and column.
    """
    text = read_text(path)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        match = _TOML_PLACE.fullmatch(str(exc))
        if match is None:
            raise file_error(path, f"is not valid TOML ({exc})") from None
        where = (f"line {match['line']}, column {match['column']}" if match["line"]
                 else "the end of the file")
        raise file_error(path, f"is not valid TOML ({match['what']})", where) from None
    except (ValueError, RecursionError) as exc:  # tomllib's own: an integer of > 4300 digits
        raise file_error(path, "is not a TOML file cavex reads ("  # or arrays nested too deep
                         f"{str(exc).splitlines()[0][:80] or type(exc).__name__})") from None
