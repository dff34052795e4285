"""Shot files: published penetration tests of rigid ogive-nose projectiles into thick concrete.

A shot file is CSV with a header row naming at least the columns :data:`REQUIRED_COLUMNS`
(any order; ``length_m``, the projectile's overall length, may be absent or empty), SI units,
lines starting with ``#`` are comments (the attribution of the data goes there) and blank lines
are skipped. Extra columns are kept, as text, in :attr:`Shot.extra`.

The file is UTF-8 (a byte-order mark at its start is accepted). Every value is checked before
anything is computed; a bad value is a one-line :class:`~cavex.errors.CavexInputError` in the
form of every input file (:mod:`cavex.input_files`) naming the file, the line, the shot and the
column, e.g. ``'x.csv': line 12 (shot 'F94-45'), column fc_Pa must be a compressive strength in
Pa in [1e+06, 1e+09] (is it in MPa?) (got '35.4')``.

From a shot to cavex's objects: :func:`shot_projectile` (the ``[projectile]`` table) here, the
concrete in :mod:`cavex.concrete`.
"""

import csv
import io
import math
from dataclasses import dataclass, field

from cavex.analytic.models.shots import shot_projectile, shot_target  # noqa: F401 (re-exported)
from cavex.errors import CavexInputError, require_name, shown
from cavex.input_files import in_file, read_text
from cavex.materials import MASS_RANGE, MAX_CRH, MAX_VELOCITY, RADIUS_RANGE

REQUIRED_COLUMNS = ("id", "mass_kg", "diameter_m", "crh", "V0_m_s", "fc_Pa", "rho_kg_m3",
                    "depth_m")
OPTIONAL_COLUMNS = ("length_m",)
COLUMNS = ("id", "mass_kg", "diameter_m", "length_m", "crh", "V0_m_s", "fc_Pa", "rho_kg_m3",
           "depth_m")
MIN_SHOT_VELOCITY = 1.0  # m/s: a test fires the projectile
MEASURED_DEPTH_RANGE = (1e-4, 1e3)  # m: a tenth of a millimetre to a kilometre
# column -> (attribute, lower, upper, accepted range as said in a message)
NUMBER_COLUMNS = {
    # mass, diameter, crh: the projectile's accepted range (cavex.materials.Projectile)
    "mass_kg": ("mass", MASS_RANGE[0], MASS_RANGE[1],
                f"a number in [{MASS_RANGE[0]:g}, {MASS_RANGE[1]:g}]"),
    "diameter_m": ("diameter", 2.0 * RADIUS_RANGE[0], 2.0 * RADIUS_RANGE[1],
                   f"a number in [{2.0 * RADIUS_RANGE[0]:g}, {2.0 * RADIUS_RANGE[1]:g}]"),
    "length_m": ("length", 0.0, math.inf, "empty or a finite number > 0"),
    # a tangent ogive needs R = crh d >= d/2 (crh 0.5 is a hemisphere)
    "crh": ("crh", 0.5, MAX_CRH,
            f"a number in [0.5, {MAX_CRH:g}] (ogive radius R = crh d >= d/2)"),
    "V0_m_s": ("V0", MIN_SHOT_VELOCITY, MAX_VELOCITY,
               f"a number in [{MIN_SHOT_VELOCITY:g}, {MAX_VELOCITY:g}] (rigid-projectile "
               "penetration)"),
    "fc_Pa": ("fc", 1e6, 1e9, "a compressive strength in Pa in [1e+06, 1e+09] (is it in MPa?)"),
    "rho_kg_m3": ("rho", 1000.0, 4000.0,
                  "a concrete density in kg/m^3 in [1000, 4000] (is it in g/cm^3?)"),
    "depth_m": ("depth", *MEASURED_DEPTH_RANGE,
                f"a number in [{MEASURED_DEPTH_RANGE[0]:g}, {MEASURED_DEPTH_RANGE[1]:g}] m"),
}
INCLUSIVE_LOWER = set(NUMBER_COLUMNS) - {"length_m"}


@dataclass(frozen=True)
class Shot:
    """One test: projectile, striking velocity, concrete and the measured depth (SI units).

    Attributes
    ----------
    id : str
    mass, diameter : float
        Projectile mass (kg) and shank diameter (m).
    length : float or None
        Overall projectile length (m); not used by the rigid-projectile models.
    crh : float
        Calibre-radius-head ``R / d`` of the tangent ogive nose.
    V0 : float
        Striking velocity (m/s), normal incidence.
    fc, rho : float
        Unconfined compressive strength (Pa) and density (kg/m^3) of the concrete.
    depth : float
        Measured penetration depth of the nose tip (m).
    extra : dict
        Any further columns of the file, as text.
    line : int
        Line of the file the shot was read from (1-based).
    """

    id: str
    mass: float
    diameter: float
    length: float | None
    crh: float
    V0: float
    fc: float
    rho: float
    depth: float
    extra: dict = field(default_factory=dict, compare=False)
    line: int = field(default=0, compare=False)


@dataclass(frozen=True)
class ShotFile:
    """The shots of a file, its comment lines (attribution) and its column names."""

    path: str
    shots: tuple
    comments: tuple
    columns: tuple

    def by_id(self, ids):
        """The shots with ``ids``, in the order given; an unknown or repeated id is an input
        error (a repeat would weigh a shot twice in a fit)."""
        repeated = sorted({i for i in ids if list(ids).count(i) > 1})
        if repeated:
            raise CavexInputError(f"shot id(s) {', '.join(map(repr, repeated))} given more than "
                                  "once", "ids")
        known = {s.id: s for s in self.shots}
        missing = [i for i in ids if i not in known]
        if missing:
            raise CavexInputError(f"shot id(s) {', '.join(map(repr, missing))} not in shots file "
                                  f"'{self.path}' (it has {', '.join(known)})")
        return tuple(known[i] for i in ids)


def read_shots(path):
    """Read and check a shot file; see the module docstring for the format.

    Raises
    ------
    CavexInputError
        ``'<path>': <where> <what>`` (:mod:`cavex.input_files`): an unreadable or non-UTF-8
        file, a missing header or column, a row with the wrong number of cells, a value out of
        range (its line, shot and column named), repeated ids, no shots.
    """
    return parse_shots(read_text(path), str(path))


def parse_shots(text, path="<text>"):
    """Shots from the text of a shot file (``path`` names it in messages)."""
    return in_file(path, _shot_file, text, path)


def _shot_file(text, path):
    comments, rows = [], []
    for number, line in enumerate(io.StringIO(text, newline=None), start=1):
        stripped = line.strip()
        if stripped.startswith("#"):
            comments.append(stripped[1:].strip())
        elif stripped:
            rows.append((number, line))
    if not rows:
        raise CavexInputError("has no header row (and no shots)")
    (header_line, header_text), data = rows[0], rows[1:]
    header = [c.strip() for c in _cells(header_line, header_text)]
    where = f"line {header_line} (header)"
    for column in REQUIRED_COLUMNS:
        if column not in header:
            raise CavexInputError(f"has no column {column} (required: "
                                  f"{', '.join(REQUIRED_COLUMNS)})", where)
    repeated = sorted({c for c in header if header.count(c) > 1})
    if repeated or "" in header:
        raise CavexInputError(f"must name each column once (got {header})", where)
    if not data:
        raise CavexInputError("has a header but no shots")
    shots, seen = [], {}
    for number, line in data:
        shot = _parse_row(number, _cells(number, line), header)
        if shot.id in seen:
            raise CavexInputError(f"must be unique (got {shot.id!r}, as on line "
                                  f"{seen[shot.id]})", f"line {number}, column id")
        seen[shot.id] = number
        shots.append(shot)
    return ShotFile(path, tuple(shots), tuple(comments), tuple(header))


def _cells(number, line):
    try:
        return next(csv.reader([line]))
    except csv.Error as exc:
        raise CavexInputError(f"is not a CSV row ({exc})", f"line {number}") from None


def _parse_row(number, cells, header):
    """The :class:`Shot` of line ``number``; a refused value names the line, shot and column."""
    if len(cells) != len(header):
        raise CavexInputError(f"must have {len(header)} cells, as the header (got "
                              f"{len(cells)})", f"line {number}")
    row = {name: cell.strip() for name, cell in zip(header, cells, strict=True)}
    shot_id = row["id"]
    if not shot_id:
        raise CavexInputError("must be a non-empty shot name (got '')", f"line {number}, "
                              "column id")
    require_name(shot_id, f"line {number}, column id")
    where = f"line {number} (shot {shot_id!r})"
    values = {}
    for column, (attribute, lower, upper, accepted) in NUMBER_COLUMNS.items():
        text = row.get(column, "")
        if column in OPTIONAL_COLUMNS and text == "":
            values[attribute] = None
            continue
        value = _number(text)
        low_ok = value >= lower if column in INCLUSIVE_LOWER else value > lower
        if not (math.isfinite(value) and low_ok and value <= upper):
            raise CavexInputError(f"must be {accepted} (got {shown(text)})",
                                  f"{where}, column {column}")
        values[attribute] = value
    extra = {k: v for k, v in row.items() if k not in COLUMNS}
    shot = Shot(id=shot_id, extra=extra, line=number, **values)
    try:
        shot_projectile(shot)
    except CavexInputError as exc:
        raise CavexInputError(f"gives no projectile: {exc}", where) from None
    return shot


def _number(text):
    """The number a cell holds in plain decimal notation (``1e6``, ``-0.5``, ``nan``); NaN
    for anything else, e.g. ``3_00`` (Python's ``float`` reads it as 300) or ``0x12C``."""
    if "_" in text:
        return math.nan
    try:
        return float(text)
    except ValueError:
        return math.nan
