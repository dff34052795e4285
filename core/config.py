"""Targets and projectiles as TOML: read (strict: unknown keys and wrong types are errors) and
written back (the tables, their TOML text and its fingerprint)."""

import hashlib
import json
import tomllib
from dataclasses import replace
from importlib import resources

from cavex.concrete import Concrete
from cavex.errors import CavexInputError, check_keys, prefixed, require
from cavex.input_files import in_file, read_toml
from cavex.materials import (
    Material,
    Projectile,
    Target,
    fe_only_parameters,
    material_parameters,
)

#: a layer's keys: the material's parameters (declared by :class:`cavex.materials.Material`),
#: or a concrete that gives them (:func:`concrete_layer`), and the layer's own (its name,
#: thickness, bottom face, plain law, tunnel wall)
LAYER_KEYS = {"name", "thickness", *material_parameters(), "bottom", "scab_depth", "law_A",
              "law_B", "tunnel_wall", "concrete"}
#: the keys of a layer's ``concrete = {fc = <Pa>, rho = <kg/m^3>}``: a concrete from its
#: strength and density (:class:`cavex.concrete.Concrete`), instead of the material's keys
CONCRETE_KEYS = {"fc", "rho", "capped"}
#: FE-only layer keys (docs/config.md), written back only when given: targets without them keep
#: their tables and fingerprints
OPTIONAL_LAYER_KEYS = fe_only_parameters()
BOTTOM_KEYS = ("bottom", "scab_depth")  # how a layer's bottom face holds: not on the last layer
PROJECTILE_KEYS = {"r", "l", "R", "crh", "m", "V0", "length", "inertia", "cg", "mu"}
TOP_KEYS = {"projectile", "layers"}
# written by `cavex calibrate` beside the calibrated target; read by `cavex validate`
# (cavex.verification.validation.calibration), ignored by the commands that only need the target
OPTIONAL_TOP_KEYS = {"calibration"}


def default_config_text():
    """The text of the embedded default configuration (the paper's Table 1)."""
    return resources.files("cavex").joinpath("data/runway.toml").read_text()


def load_config(path=None):
    """Read ``(target, projectile)`` from a TOML file (the embedded default if ``path`` is None).

    Raises
    ------
    CavexInputError
        ``'<path>': <where> <what>`` (:mod:`cavex.input_files`): an unreadable, non-UTF-8 or
        malformed file, unknown or missing keys, wrong types or out-of-range values.
    """
    if path is None:
        return parse_config(tomllib.loads(default_config_text()))
    return in_file(path, parse_config, read_toml(path))


def parse_config(data):
    """Build ``(target, projectile)`` from an already parsed TOML mapping."""
    check_keys(data, TOP_KEYS | OPTIONAL_TOP_KEYS, "", required=TOP_KEYS)
    if "calibration" in data:
        require(isinstance(data["calibration"], dict), "calibration", "a table",
                data["calibration"])
    return parse_target(data["layers"]), parse_projectile(data["projectile"])


def parse_target(layers):
    """Build a :class:`Target` from a list of ``[[layers]]`` tables."""
    require(isinstance(layers, list) and layers, "layers", "a non-empty array of tables", layers)
    materials, thicknesses, bottoms, scabs, laws, walls = [], [], [], [], [], []
    for i, table in enumerate(layers):
        where = f"layers[{i}]."
        require(isinstance(table, dict), f"layers[{i}]", "a table", table)
        last = i == len(layers) - 1
        material_keys = set() if "concrete" in table else {"E", "nu", "rho", "lam"}
        required = material_keys | (set() if last else {"thickness"})
        check_keys(table, LAYER_KEYS, where, required=required)
        for key in ("thickness", *BOTTOM_KEYS) if last else ():
            if key in table:
                raise CavexInputError("must be absent (the last layer is semi-infinite)",
                                      f"{where}{key}")
        if "bottom" in table:
            require(isinstance(table["bottom"], str), f"{where}bottom", "a string",
                    table["bottom"])
        numbers = {k: _number(table[k], where + k) for k in table
                   if k not in ("name", "bottom", "concrete")}
        thickness = numbers.pop("thickness", None)
        scab = numbers.pop("scab_depth", None)
        law = numbers.pop("law_A", None), numbers.pop("law_B", None)
        if (law[0] is None) != (law[1] is None):
            missing = "law_B" if law[1] is None else "law_A"
            raise CavexInputError("must be given with law_A and law_B both (the plain law "
                                  "S = A + B rho V^2 / tau)", f"{where}{missing}")
        laws.append(None if law[0] is None else law)
        walls.append(numbers.pop("tunnel_wall", 1.0))
        if "concrete" in table:
            materials.append(concrete_layer(table["concrete"], where, table.get("name"),
                                            numbers))
        else:
            materials.append(prefixed(Material, where, name=table.get("name", ""), **numbers))
        if thickness is not None:
            thicknesses.append(thickness)
            bottoms.append(table.get("bottom", "bonded"))
            scabs.append(scab)
    return prefixed(Target, "", materials, thicknesses, bottoms, scabs, laws, walls)


def concrete_layer(table, where="", name=None, material=()):
    """The material of a layer's ``concrete = {fc, rho}`` table (``where``: the layer's key
    path, e.g. ``"layers[0]."``): :meth:`cavex.concrete.Concrete.layer`, a concrete of strength
    ``fc`` (Pa) and density ``rho`` (kg/m^3) with ``E``, ``nu``, ``lam`` and ``tau`` from the
    published correlations (:mod:`cavex.concrete`); with ``capped = true``
    :meth:`~cavex.concrete.Concrete.fe_layer` (the cap ``tau_max = 7 f_c``, the tension
    cut-off and HJC's compaction hydrostat that the FE carries). Named ``name`` (default
    ``"concrete"``). The layer's own material keys (``material``) are refused: the concrete is
    its material."""
    if material:
        raise CavexInputError("must be absent with concrete (the layer's material is the "
                              "concrete's)", f"{where}{next(iter(material))}")
    key = f"{where}concrete"
    require(isinstance(table, dict), key, "a table {fc = <Pa>, rho = <kg/m^3>}", table)
    check_keys(table, CONCRETE_KEYS, f"{key}.", required={"fc", "rho"})
    capped = table.get("capped", False)
    require(isinstance(capped, bool), f"{key}.capped", "true or false", capped)
    concrete = prefixed(Concrete, f"{key}.", fc=_number(table["fc"], f"{key}.fc"),
                        rho=_number(table["rho"], f"{key}.rho"))
    layer = prefixed(concrete.fe_layer if capped else concrete.layer, f"{key}.")
    return layer if name is None else prefixed(replace, where, layer, name=name)


def parse_projectile(table):
    """Build a :class:`Projectile` from the ``[projectile]`` table."""
    require(isinstance(table, dict), "projectile", "a table", table)
    check_keys(table, PROJECTILE_KEYS, "projectile.", required={"r", "l", "m", "V0"})
    numbers = {k: _number(v, "projectile." + k) for k, v in table.items()}
    return prefixed(Projectile, "projectile.", **numbers)


def _number(value, name):
    """Type check only: ranges (and finiteness) are checked by the objects built from it."""
    require(isinstance(value, (int, float)) and not isinstance(value, bool), name, "a number",
            value)
    return float(value)


def target_table(target):
    """The ``[[layers]]`` tables of a :class:`cavex.materials.Target` (JSON-able, exact)."""
    tables = []
    for i, material in enumerate(target.layers):
        table = {"name": material.name} if material.name else {}
        if i < len(target.thicknesses):
            table["thickness"] = float(target.thicknesses[i])
            if target.bottoms[i] != "bonded":  # the default is not written: bonded targets
                table["bottom"] = target.bottoms[i]  # keep their tables and fingerprints
            if target.scab_depths[i] is not None:
                table["scab_depth"] = float(target.scab_depths[i])
        table.update(E=float(material.E), nu=float(material.nu), rho=float(material.rho),
                     lam=float(material.lam), tau=float(material.tau))
        for key in OPTIONAL_LAYER_KEYS:
            if getattr(material, key) is not None:
                table[key] = float(getattr(material, key))
        if target.plain_laws[i] is not None:  # absent keys are not written: the tables
            table["law_A"], table["law_B"] = target.plain_laws[i]  # and fingerprints stay
        if target.tunnel_walls[i] != 1.0:  # the default is not written (fingerprints)
            table["tunnel_wall"] = target.tunnel_walls[i]
        tables.append(table)
    return tables


def projectile_table(projectile):
    """The ``[projectile]`` table of a :class:`cavex.materials.Projectile`."""
    return {key: float(getattr(projectile, key)) for key in ("r", "l", "R", "m", "V0")}


def config_text(target, projectile):
    """TOML text that :func:`cavex.config.load_config` reads back to ``(target, projectile)``."""
    lines = ["[projectile]"]
    lines += [f"{k} = {_toml_value(v)}" for k, v in projectile_table(projectile).items()]
    for table in target_table(target):
        lines += ["", "[[layers]]"] + [f"{k} = {_toml_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def _toml_value(value):
    return toml_string(value) if isinstance(value, str) else repr(float(value))


def _toml_escape(text):
    """``text`` with backslash, quote and the control characters TOML forbids unescaped
    (U+0000-U+001F but tab, U+007F) as ``\\uXXXX``; a lone surrogate (a file name's undecodable
    byte), which no TOML file can hold, as U+FFFD. Everything else is written as itself."""
    out = []
    for char in str(text):
        code = ord(char)
        if char in '"\\':
            out.append("\\" + char)
        elif (code < 0x20 and char != "\t") or code == 0x7F:
            out.append(f"\\u{code:04X}")
        elif 0xD800 <= code <= 0xDFFF:
            out.append("\ufffd")
        else:
            out.append(char)
    return "".join(out)


def toml_string(text):
    """A TOML basic string that reads back to ``text`` (any Unicode, any control character)."""
    return f'"{_toml_escape(text)}"'


def toml_comment(text):
    """A one-line TOML comment holding ``text`` (control characters escaped as in
    :func:`toml_string`)."""
    return f"# {_toml_escape(text)}"


def fingerprint_data(target, projectile):
    """The data the table depends on: every layer key and the projectile's ``r`` and ``l``."""
    p = projectile_table(projectile)
    return {"layers": target_table(target), "projectile": {"r": p["r"], "l": p["l"]}}


def fingerprint(target, projectile):
    """sha256 of the canonical JSON (sorted keys, repr floats) of :func:`fingerprint_data`."""
    text = json.dumps(fingerprint_data(target, projectile), sort_keys=True,
                      separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()
