"""FE cases for :func:`cavex.verification.fedata.runner.run_cases`: built and checked once.

An FE case is described by a plain, JSON-able dict::

    {"id": "v0500.000_L0.30000", "velocity": 500.0, "depth": 0.3,
     "nu": 0.4999,                        # optional: Poisson's ratio for every layer
     "numerics": {"elements_per_decade": 10},   # optional: cavex.fem.Numerics settings
     "error_target": 0.005,               # optional: refine above it (null: never)
     "target": [{"name": "concrete", "thickness": 0.65, "E": 25e9, ...}, ...],
     "projectile": {"r": 0.0125, "l": 0.06, "R": 0.075, "m": 0.505, "V0": 1000.0}}

``target`` is the list of ``[[layers]]`` tables and ``projectile`` the ``[projectile]`` table of
the config TOML schema (``core/data/runway.toml``), so a description carries everything it
needs; it is what the runner's store keeps (``{"case": ..., "result": ...}``).

:func:`make_fe_cases` (and the batch sweeps) build every case once, in the process that makes
them, into an :class:`FECase`: the description (a read-only mapping) with the checked objects
the FE runs on, a :class:`~cavex.problem.SphericalProblem` and a :class:`~cavex.fem.Numerics`
(each distinct target, projectile and numerics parsed once, :class:`CaseBuilder`). A process or
a Dask worker receives them pickled and parses or checks nothing again. FE cases are run in
chunks (:func:`fe_cases`, the work unit of :func:`cavex.verification.fedata.runner.run_cases`):
the cases of a chunk that share their numerics run together on the one FE solver.
"""

import json
import math
import os
import time
import uuid
from collections.abc import Mapping
from dataclasses import fields, replace

from cavex.analytic.geometry import spherical_problem
from cavex.config import load_config, parse_projectile, parse_target, projectile_table, target_table
from cavex.errors import CavexInputError, CavexNumericalError, check_keys, require
from cavex.errors import is_finite_number as _finite
from cavex.fem.estimate import DEFAULT_ERROR_TARGET
from cavex.fem.settings import Numerics, check_seed_radius, make_numerics
from cavex.problem import SphericalProblem

CASE_KEYS = {"id", "velocity", "depth", "nu", "numerics", "error_target", "target",
             "projectile"}
#: FE cases per second per worker, measured on table grids at the default settings with
#: error estimates (docs/fem.md "Throughput": 12-20 per process); used for estimates only.
CASES_PER_SECOND_PER_WORKER = 15.0
LARGE_RUN = 20_000  # FE cases above which a run needs an explicit request


def check_run_size(n_cases, workers, allow_large, option="allow-large"):
    """The one-line estimate of an FE run of ``n_cases`` cases on ``workers`` workers; refuses
    (naming ``option``) more than :data:`LARGE_RUN` cases unless ``allow_large``."""
    hours = n_cases / (CASES_PER_SECOND_PER_WORKER * max(1, workers)) / 3600.0
    minutes = hours * 60.0
    estimate = (f"{n_cases} FE cases, under a minute" if minutes < 1.0
                else f"{n_cases} FE cases, about {minutes:.0f} min" if hours < 1.0
                else f"{n_cases} FE cases, about {hours:.1f} h")
    if n_cases > LARGE_RUN and not allow_large:
        raise CavexInputError(f"{estimate} on {workers} worker(s): more than {LARGE_RUN} cases "
                              f"need the option '--{option}'")
    return f"{estimate} on {workers} worker(s) (at ~{CASES_PER_SECOND_PER_WORKER:g} cases/s " \
           "per worker)"


class FECase(Mapping):
    """One FE case, built and checked once.

    A read-only mapping: the case's JSON-able description (module docstring), which the store
    keeps and the id names. Beside it what the FE runs on, so that nothing is parsed or
    checked again where the case runs:

    Attributes
    ----------
    problem : SphericalProblem
        The spherical problem at the case's depth (``nu`` applied), checked.
    numerics : Numerics
        The FE settings, checked (the seed radius against the problem too).
    error_target : float or None
        Refine while the error estimate exceeds it (None: never).
    """

    def __init__(self, description, problem, numerics, error_target):
        self._description = description
        self.problem = problem
        self.numerics = numerics
        self.error_target = error_target

    def __getitem__(self, key):
        return self._description[key]

    def __iter__(self):
        return iter(self._description)

    def __len__(self):
        return len(self._description)

    def __repr__(self):
        return f"FECase({self._description!r})"

    def renamed(self, case_id):
        """The same case under another id."""
        return FECase({**self._description, "id": case_id}, self.problem, self.numerics,
                      self.error_target)


class CaseBuilder:
    """Builds :class:`FECase` from descriptions, parsing each distinct target, projectile and
    numerics once (the cases of a grid share them); a ``target`` and ``projectile`` given are
    taken for their tables (:func:`target_table`, :func:`projectile_table`) without parsing."""

    def __init__(self, target=None, projectile=None):
        self._parsed = {}
        if target is not None:
            self._parsed[self._key(parse_target, target_table(target))] = target
        if projectile is not None:
            self._parsed[self._key(parse_projectile, projectile_table(projectile))] = projectile

    @staticmethod
    def _key(parse, value):
        return parse.__name__, json.dumps(value, sort_keys=True)

    def _once(self, parse, value):
        key = self._key(parse, value)
        if key not in self._parsed:
            self._parsed[key] = parse(value)
        return self._parsed[key]

    def target(self, layers):
        """The :class:`~cavex.materials.Target` of ``[[layers]]`` tables (or
        ``{"layers": [...]}``)."""
        return self._once(parse_target, _layers(layers))

    def projectile(self, table):
        return self._once(parse_projectile, table)

    def numerics(self, settings):
        return self._once(_numerics, settings)

    def __call__(self, description):
        """The :class:`FECase` of a description; raises :class:`CavexInputError` (or
        ``KeyError``/``TypeError``/``ValueError`` for a malformed dict) if it is not a valid
        case."""
        check_keys(description, CASE_KEYS, "")
        target = self.target(description["target"])
        projectile = self.projectile(description["projectile"])
        numerics = self.numerics(description.get("numerics", {}))
        error_target = description.get("error_target", DEFAULT_ERROR_TARGET)
        require(error_target is None or (_finite(error_target) and 0 < error_target < 1),
                "error_target", "null or a number in (0, 1)", error_target)
        problem = fe_problem(target, projectile, description["depth"], description["velocity"],
                             description.get("nu"))
        check_seed_radius(numerics, problem.radius)
        return FECase(description, problem, numerics,
                      None if error_target is None else float(error_target))


def fe_problem(target, projectile, depth, velocity, nu=None):
    """The :class:`~cavex.problem.SphericalProblem` of the FE at nose-tip depth ``depth``
    (:func:`cavex.analytic.geometry.spherical_problem`; cavity radius = shank radius), with
    Poisson's ratio ``nu`` for every layer when given; checked as it is built
    (plain: the commands check their cases with it before scikit-fem loads)."""
    layers, interfaces = spherical_problem(target, projectile, depth)
    if nu is not None:
        layers = [replace(m, nu=nu) for m in layers]
    return SphericalProblem(tuple(layers), interfaces, velocity, projectile.r)


def _numerics(settings):
    return make_numerics(**settings)


def fe_cases(chunk):
    """Run a chunk of FE cases: per case :func:`~cavex.verification.fedata.comparison.
    fe_record`'s dict plus ``"id"``, or the exception the case failed with.

    The cases that share their numerics and error target run together
    (:func:`~cavex.verification.fedata.fe_record.fe_records`: stacks of the one FE solver); a
    case computes the same bits in any chunk. The closed forms are not evaluated here: they
    are evaluated once where the results are kept
    (:func:`~cavex.verification.fedata.comparison.closed_forms`).

    Parameters
    ----------
    chunk : list of FECase or dict
        Built cases (:func:`make_fe_cases`), or descriptions (module docstring), which are
        built here: a bad one fails alone.
    """
    from cavex.verification.fedata.fe_record import fe_records

    out = [None] * len(chunk)
    build = CaseBuilder()
    groups = {}
    for i, case in enumerate(chunk):
        if not isinstance(case, FECase):
            try:
                case = build(case)
            except (CavexInputError, KeyError, TypeError, ValueError) as exc:
                out[i] = exc
                continue
        key = (json.dumps(case.numerics.as_dict(), sort_keys=True), case.error_target)
        groups.setdefault(key, []).append((i, case))
    for members in groups.values():
        first = members[0][1]
        results = fe_records([case["depth"] for _, case in members],
                             [case.problem for _, case in members], first.numerics,
                             first.error_target)
        for (i, case), result in zip(members, results, strict=True):
            out[i] = result if isinstance(result, Exception) else {**result, "id": case["id"]}
    return out


def make_fe_cases(target_table, projectile_table, velocities, depths, nu=None, numerics=None,
                  error_target=DEFAULT_ERROR_TARGET, build=None):
    """FE cases on the grid ``velocities x depths`` (velocity outermost), with stable ids.

    Parameters
    ----------
    target_table : list of dict or dict
        The ``[[layers]]`` tables (or ``{"layers": [...]}``), see :func:`target_table`.
    projectile_table : dict
        The ``[projectile]`` table, see :func:`projectile_table`.
    velocities, depths : sequence of float
        Expansion velocities (m/s, >= 0; 0 is a quasi-static FE run) and nose-tip depths
        (m, >= 0).
    nu : float, optional
        Poisson's ratio for every layer (default: each layer's own).
    numerics : dict, optional
        :class:`cavex.fem.Numerics` settings shared by all cases.
    error_target : float or None
        Refine an FE case while its error estimate exceeds this (None: never).
    build : CaseBuilder, optional
        The builder to use (one made with the target and projectile objects of the tables
        saves parsing them back).

    Returns
    -------
    list of FECase
        Built cases with ids ``"v0500.000_L0.30000"`` (``"_nu0.499900"`` appended when ``nu``
        is given); the ids are unique and depend only on the values.

    Raises
    ------
    CavexInputError
        Invalid target, projectile, numerics, velocities or depths, a spherical problem that
        cannot be run (e.g. a seed radius beyond ``r/5``), or two values too close to be told
        apart by the id format.
    """
    layers = [dict(table) for table in _layers(target_table)]
    projectile = dict(projectile_table)
    numerics = dict(numerics or {})
    build = build or CaseBuilder()
    build.target(layers)
    build.projectile(projectile)
    build.numerics(numerics)
    if nu is not None:
        require(_finite(nu) and -1.0 < nu < 0.5, "nu", "in (-1, 0.5)", nu)
    cases = []
    for i, velocity in enumerate(velocities):
        require(_finite(velocity) and velocity >= 0, f"velocities[{i}]", "a finite number >= 0",
                velocity)
        for j, depth in enumerate(depths):
            require(_finite(depth) and depth >= 0, f"depths[{j}]", "a finite number >= 0", depth)
            case = {"id": fe_case_id(velocity, depth, nu), "velocity": float(velocity),
                    "depth": float(depth)}
            if nu is not None:
                case["nu"] = float(nu)
            if numerics:
                case["numerics"] = dict(numerics)
            if error_target != DEFAULT_ERROR_TARGET:
                case["error_target"] = error_target
            cases.append({**case, "target": layers, "projectile": projectile})
    check_unique_ids(cases)
    return [build(case) for case in cases]


def fe_case_id(velocity, depth, nu=None):
    """``"v0500.000_L0.30000"`` (plus ``"_nu0.499900"`` when ``nu`` is given)."""
    text = f"v{velocity:08.3f}_L{depth:.5f}"
    return text if nu is None else f"{text}_nu{nu:.6f}"


def check_unique_ids(cases):
    """Raise ``CavexInputError`` if two cases share an id (values closer than the id format)."""
    seen = {}
    for case in cases:
        if case["id"] in seen:
            raise CavexInputError(f"cases {seen[case['id']]} and {case} both get id "
                                  f"'{case['id']}': values too close to tell apart")
        seen[case["id"]] = {k: v for k, v in case.items() if k not in ("target", "projectile")}


def config_tables(path=None):
    """``(layer tables, projectile table)`` of a config TOML (default: the embedded Table 1)."""
    target, projectile = load_config(path)
    return target_table(target), projectile_table(projectile)


def numerics_names():
    """Names of the :class:`cavex.fem.Numerics` settings."""
    return [f.name for f in fields(Numerics)]


def probe_cases(chunk):
    """:func:`probe_case` on every case of a chunk (the exception in place of a failed one)."""
    out = []
    for case in chunk:
        try:
            out.append(probe_case(case))
        except CavexNumericalError as exc:
            out.append(exc)
    return out


def probe_case(case):
    """A cheap deterministic case for checking runners and clusters (no FE).

    Keys: ``id``; ``x`` (float); optional ``fail`` (message: raises ``CavexNumericalError``);
    optional ``sleep`` (seconds); optional ``marker_dir`` (a file is created there for every
    computation, so that computations can be counted).

    Returns
    -------
    dict
        ``{"x": x, "value": exp(sin(x)) / 3, "values": [x / 7, sqrt(|x|) / 3, |x| ** 0.1]}``.
    """
    if case.get("marker_dir"):
        name = f"{case['id']}.{os.getpid()}.{uuid.uuid4().hex}.done"
        with open(os.path.join(case["marker_dir"], name), "w", encoding="utf-8"):
            pass
    if case.get("sleep"):
        time.sleep(case["sleep"])
    if case.get("fail"):
        raise CavexNumericalError(f"{case['fail']} (x = {case['x']})")
    x = float(case["x"])
    return {"x": x, "value": math.exp(math.sin(x)) / 3.0,
            "values": [x / 7.0, math.sqrt(abs(x)) / 3.0, abs(x) ** 0.1]}


def _layers(target):
    if isinstance(target, dict):
        require(set(target) == {"layers"}, "target", "a list of layer tables or {'layers': [...]}",
                sorted(target))
        return target["layers"]
    return target
