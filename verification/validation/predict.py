"""Predicted against measured penetration depth: every resistance cavex has, and Forrestal's.

For each shot (:mod:`cavex.verification.validation.shots`) the target is one semi-infinite concrete
layer from the shot's ``(f_c, rho)`` (:mod:`cavex.concrete`) and the
projectile the shot's (:func:`~cavex.verification.validation.shots.shot_projectile`). The models
(:data:`MODELS`, labelled as everywhere in cavex:
:mod:`cavex.analytic.models`, the registry):

- ``derived-quasi-static``, ``derived-dynamic``, ``paper``: the closed forms
  (:class:`cavex.analytic.penetration.resistance.ClosedFormResistance`), incompressible;
- ``table``: the FE-tabulated resistance
  (:class:`cavex.analytic.penetration.tabulated.TabulatedResistance`) of a table built by
  :func:`cavex.verification.fedata.table.build_table` for the shot's target with the mapping's
  Poisson's ratio (0.2): compressible, finite strain, which no closed form gives;
- ``concrete``: the concrete cavity-expansion model
  (:mod:`cavex.analytic.penetration.concrete_table`, published constants, none fitted to the
  shots; its own crater and material, not the mapping), the recommended model
  (:data:`RECOMMENDED_MODEL`);
- ``li-chen-2003``: Li and Chen's (2003) empirical formula (Forrestal's form with
  ``S = 72 f_c^-0.5`` and the crater ``0.707 + h/d`` calibres,
  :func:`cavex.analytic.empirical.li_chen_depth`);
- ``forrestal-1994``: the empirical model (:mod:`cavex.analytic.empirical`).

cavex's models run the penetration integrator
(:func:`cavex.analytic.penetration.integrator.penetrate`,
crater of ``4.5 r`` from the nose base, as ``cavex penetrate``); the predicted depth is the nose
tip's final depth; a projectile that the crater stage stops (``m V0^2 <= L_c F(0)``) reaches
``sqrt(m V0^2 L_c / F(0))`` (:func:`cavex.analytic.penetration.integrator.crater_stage`).

A calibrated model (:mod:`cavex.verification.validation.calibration`) is one of cavex's models with
the fitted mapping parameters, named ``"<model> calibrated"``.
"""

import math
import os
import sys
from pathlib import Path

import numpy as np

from cavex.analytic.models import get, labels, names, parse_label, the
from cavex.analytic.penetration.nose import nose_rule
from cavex.concrete import Mapping
from cavex.errors import CavexInputError, CavexNumericalError, require, require_choice
from cavex.verification.output.number_format import round_significant
from cavex.verification.validation.regimes import DEPTH_DIGITS, regime_statistics, rigid_flag
from cavex.verification.validation.shots import shot_projectile, shot_target

#: the labels of the models validate runs, in the order of its columns (the registry's when
#: this module is imported; the functions below read the registry when called)
MODELS = labels(predicts_shots=True)
CAVEX_MODELS = labels(fits_mapping=True)  # what a calibration can fit: the flown models
FE_MODEL = names(takes_table=True)[0]  # the model that needs FE tables
#: the closed form the FE model is the compressible counterpart of: the compressibility
#: column runs the FE with that label's calibrated mapping
FE_PARTNER = get(FE_MODEL).compressible_partner
EMPIRICAL = the(empirical_reference=True).name  # the report compares the calibrated with it
#: The model ``cavex validate`` recommends (the registry's ``recommended`` model: the concrete
#: cavity model; docs/validation.md)
RECOMMENDED_MODEL = names(recommended=True)[0]
#: the model of the concrete cavity tables (run once per option, shared with its parts' users)
CONCRETE_MODEL = names(tabulates_concrete=True)[0]
TABLE_VELOCITY_STEP = 50.0  # m/s between FE table velocities (interpolated by PCHIP in V^2)
TABLE_DEPTHS = (0.0, 1.0)  # a one-layer target's sigma_r does not depend on depth
# for run estimates only, measured on the development shots (one worker, x86_64, unloaded):
# 95 FE tables of 25 velocities and 2 depths in ~90 s; a prediction 1.4-2.6 ms with a closed
# form, 29 ms with an FE table (5000 shots: 12 min on a machine loaded ~2x)
TABLE_CASES_PER_SECOND_PER_WORKER = 45.0
# a shot every model misses by more than this factor (either way) is flagged as an outlier:
# 21 of the 286 development shots (C133: 1.2 mm measured at 86 m/s, every model ~25 mm), none
# of Forrestal's 17
OUTLIER_FACTOR = 3.0


# --- one prediction ---------------------------------------------------------------------------

def penetration_depth(target, projectile, resistance):
    """Final nose-tip depth (m) of the integrator (also where the crater stops it)."""
    from cavex.analytic.penetration.integrator import penetrate

    return float(penetrate(target, projectile, resistance).depth[-1])


def closed_form_depth(shot, resistance="derived", *, boundary=None, mapping=None):
    """Depth (m) of the closed form ``resistance`` ("derived" with ``boundary``, or "paper")
    for ``shot`` under ``mapping``."""
    model = get(resistance, offered=names(closed_form=True))
    return model.shot_depth(shot, boundary=boundary, mapping=mapping)


def table_depth(shot, table, mapping=None):
    """Depth (m) with the FE-tabulated resistance of ``table`` (built for the shot's target)."""
    from cavex.analytic.models.shots import flown_depth

    return flown_depth(get(FE_MODEL), shot, mapping, table=table)


def model_of(label):
    """The registry's model of a column's ``label`` (one of validate's models, checked)."""
    return parse_label(label, "models", labels(predicts_shots=True))[0]


def predict(shot, model, mapping=None, tables=None, erosion=None):
    """Predicted depth (m) of ``model`` (one of :data:`MODELS`) for ``shot``.

    ``tables`` (a :class:`TableCache`) gives the FE tables of the ``table`` model; ``erosion``
    an :class:`~cavex.analytic.penetration.erosion.ErosionLaw` (None: rigid), flown by the
    models that integrate (the empirical formulas ignore it).
    """
    chosen, boundary = parse_label(model, "models", labels(predicts_shots=True))  # checked
    if chosen.takes_table:
        tables = tables or TableCache()
    if erosion is None:  # the rigid call, as before erosion existed
        return chosen.shot_depth(shot, boundary=boundary, mapping=mapping, tables=tables)
    return chosen.shot_depth(shot, boundary=boundary, mapping=mapping, tables=tables,
                             erosion=erosion)


# --- FE tables --------------------------------------------------------------------------------

def table_velocities(shots, step=TABLE_VELOCITY_STEP):
    """Velocity grid ``0, step, ...`` reaching the largest ``V0 cos(phi_1)`` any of ``shots``'
    noses sees (the table's upper end must cover it; nothing is extrapolated)."""
    top = max(shot.V0 * float(nose_rule(shot_projectile(shot))[0].max()) for shot in shots)
    count = max(2, math.ceil(top / step * (1.0 + 1e-12)) + 1)
    return tuple(step * i for i in range(count))


class TableCache:
    """FE tables of one-layer targets, built once per distinct target and reused: within a run
    in memory, across commands and runs through the shared cache
    (:mod:`cavex.verification.fedata.table_cache`).

    Parameters
    ----------
    directory : str or Path, optional
        A copy of every table the run uses is written there (``table_<key>.nc``, as the cache
        stores it), so that a results folder holds its tables; nothing is read from it.
    numerics : dict, optional
        FE settings (:class:`cavex.fem.Numerics`); default the solver's.
    workers, scheduler : passed to :func:`cavex.verification.fedata.table.build_table`.
    progress : bool, optional
        A line on stderr per table built.
    cache : str or Path, optional
        The cache folder; default :func:`cavex.verification.fedata.table_cache.cache_dir`.
    """

    def __init__(self, directory=None, numerics=None, workers=None, scheduler=None,
                 progress=False, cache=None):
        from cavex.verification.fedata.table_cache import (
            cache_dir,
            folder_problem,
            max_bytes,
            warn,
        )

        max_bytes()  # a bad size limit is refused before any work
        self.directory = None if directory is None else Path(directory)
        self.cache = cache_dir() if cache is None else Path(cache)
        problem = folder_problem(self.cache)  # before any FE work
        if problem is not None:
            warn(self.cache, problem)
            self.cache = None
        self.numerics, self.workers, self.scheduler = numerics, workers, scheduler
        self.progress = progress
        self._tables = {}
        self._checked = {}  # entries read and trusted by :meth:`plan`
        self._velocities = None
        self.built = 0
        self.reused = 0
        self.to_build = []  # (target, projectile) of each table :meth:`plan` found to build

    def velocities_for(self, shots):
        """Set the velocity grid to cover ``shots`` (call before :meth:`table`)."""
        self._velocities = table_velocities(shots)

    def plan(self, shots, mappings):
        """``(to build, on disk)``: the distinct FE tables ``shots`` need under ``mappings``
        (call :meth:`velocities_for` first); on disk: in the cache (checked when read)."""
        from cavex.verification.fedata.table_cache import read_entry

        wanted = {}
        for m in mappings:
            for shot in shots:
                target, projectile = shot_target(shot, m), shot_projectile(shot)
                wanted.setdefault(self.key(target, projectile, self._velocities),
                                  (target, projectile))
        keys = set(wanted) - set(self._tables)
        self.to_build = []
        for k in keys - set(self._checked) if self.cache is not None else ():
            table = read_entry(self._entry(k), *wanted[k], self._velocities, self.numerics)[0]
            if table is not None:  # checked now, used by :meth:`table` without a second read
                self._checked[k] = table
        cached = keys & set(self._checked)
        self.to_build = [wanted[k] for k in sorted(keys - cached)]
        return len(keys - cached), len(cached)

    def key(self, target, projectile, velocities):
        """The cache key (:func:`cavex.verification.fedata.table_cache.table_key`)."""
        from cavex.verification.fedata.table_cache import table_key

        return table_key(target, projectile, velocities, TABLE_DEPTHS, self.numerics)

    def _entry(self, key):
        from cavex.verification.fedata.table_cache import entry_path

        return entry_path(key, self.cache)

    def table(self, shot, mapping=None):
        """The FE table of ``shot``'s target (velocities: :meth:`velocities_for`, else the
        shot's own): from memory, else the cache (claimed, so that concurrent runs build it
        once: :func:`cavex.verification.fedata.table_cache.claimed`), else built and cached;
        an untrusted entry is rebuilt with one line on stderr."""
        from cavex.verification.fedata.table_cache import claimed, read_entry

        target, projectile = shot_target(shot, mapping), shot_projectile(shot)
        velocities = self._velocities or table_velocities([shot])
        key = self.key(target, projectile, velocities)
        if key in self._tables:
            return self._tables[key]
        if key in self._checked:
            table = self._checked.pop(key)
            self.reused += 1
        elif self.cache is None:
            table = self._build(shot, target, projectile, velocities, key)
        else:
            with claimed(self._entry(key)):
                table, reason = read_entry(self._entry(key), target, projectile, velocities,
                                           self.numerics)
                if reason is not None:
                    print(f"cavex: FE-table cache entry '{self._entry(key)}' is rebuilt: "
                          f"{reason.splitlines()[0][:200]}", file=sys.stderr, flush=True)
                if table is None:
                    table = self._build(shot, target, projectile, velocities, key)
                else:
                    self.reused += 1
        failed = int(table["failed"].sum()) + int(table["failed_first_layer"].sum())
        if failed:
            raise CavexNumericalError(f"{failed} FE cell(s) failed building the table for "
                                      f"shot '{shot.id}': {table.attrs['failures'][:300]}")
        if self.directory is not None:
            self._copy(key)
        self._tables[key] = table
        return table

    def _build(self, shot, target, projectile, velocities, key):
        """Build the table, store it in the cache (unless it holds failed cells, or there
        is no usable cache) and return it as stored; a store that fails (a full disk) leaves
        the cache unused for the rest of the run after one warning line."""
        from cavex.verification.fedata.table import build_table, reproducible_table
        from cavex.verification.fedata.table_cache import store, warn

        if self.progress:
            print(f"cavex: FE table for f_c = {shot.fc / 1e6:.4g} MPa, rho = {shot.rho:g} "
                  f"kg/m^3 ({len(velocities)} velocities)", file=sys.stderr, flush=True)
        table = build_table(target, projectile, velocities, TABLE_DEPTHS,
                            numerics=self.numerics, workers=self.workers,
                            scheduler=self.scheduler, progress=False)
        self.built += 1
        failed = int(np.sum(table["failed"])) + int(np.sum(table["failed_first_layer"]))
        if self.cache is not None and not failed:
            try:
                return store(table, self._entry(key))
            except OSError as exc:
                warn(self.cache, exc.strerror or str(exc))
                self.cache = None
        from cavex.netcdf3 import PlainDataset

        return reproducible_table(PlainDataset.from_dataset(table)).dataset()

    def _copy(self, key, folder=None):
        """Copy the cache entry ``key`` into ``folder`` (default :attr:`directory`),
        atomically; an entry gone from the cache (pruned by another run, or the cache
        unusable) is written from memory. Returns the path written."""
        from cavex.verification.fedata.table import write_table
        from cavex.verification.output.files import copy_atomic

        path = Path(self.directory if folder is None else folder) / f"table_{key}.nc"
        if self.cache is not None:
            try:
                return copy_atomic(self._entry(key), path)
            except FileNotFoundError:
                pass
        return write_table(self._tables[key], path)

    def write_used(self, folder):
        """Write every table this run used into ``folder`` (``table_<key>.nc``, as the cache
        stores it); returns the paths. A command calls it inside its staged write
        (:func:`cavex.verification.output.paths.write_staged`): the tables arrive in the
        results folder with the report, or not at all."""
        if not self._tables:
            return []
        Path(folder).mkdir(parents=True, exist_ok=True)
        return [Path(self._copy(key, folder)) for key in sorted(self._tables)]


# --- many shots -------------------------------------------------------------------------------

def predictions(shots, models, tables=None, progress=None, erosion=None):
    """``{model: [depth or None]}`` and ``{model: {shot id: reason}}`` for the failures.

    ``models`` maps a column name to ``(model, mapping)`` (``mapping`` None: default);
    ``erosion``: :func:`predict`'s.
    """
    from cavex.verification.fedata.runner import Progress, show_progress

    tables = tables or TableCache()
    depths = {name: [] for name in models}
    failures = {}
    bar = Progress(len(shots) * len(models), 0, show_progress(progress), unit="prediction")
    for name, (model, mapping) in models.items():
        for shot in shots:
            try:
                value = round_significant(predict(shot, model, mapping, tables, erosion),
                                          DEPTH_DIGITS)
            except (CavexInputError, CavexNumericalError) as exc:
                value = None
                failures.setdefault(name, {})[shot.id] = str(exc).splitlines()[0]
            depths[name].append(value)
            bar.update()
    bar.close()
    return depths, failures


def ratio_statistics(ratios):
    """``n``, mean and sample standard deviation of ``ratios`` and their mean ``|ln ratio|``
    (None where undefined; a missing, non-finite or non-positive ratio is not counted), rounded
    to :data:`DEPTH_DIGITS` significant digits."""
    r = np.array([x for x in ratios if x is not None and math.isfinite(x) and x > 0.0],
                 dtype=float)
    n = int(r.size)

    def rounded(value):
        return None if not math.isfinite(value) else round_significant(float(value),
                                                                       DEPTH_DIGITS)

    return {"n": n,
            "mean_ratio": rounded(r.mean()) if n else None,
            "std_ratio": rounded(r.std(ddof=1)) if n > 1 else None,
            "mean_abs_log_ratio": rounded(np.abs(np.log(r)).mean()) if n else None}


def check_models(models):
    """``models`` (None: all of :data:`MODELS`) as a tuple of distinct labels in the order of
    :data:`MODELS`; an unknown one is refused naming the accepted labels."""
    offered = labels(predicts_shots=True)
    if models is None:
        return offered
    for name in models:
        require_choice(name, offered, "models")
    require(len(set(models)) == len(models), "models", "labels without repeats", list(models))
    return tuple(m for m in offered if m in models)


def validation_columns(calibrations=(), mapping=None, models=None):
    """Column name -> ``(model, mapping)``: every model of ``models`` (default :data:`MODELS`,
    :func:`check_models`) under ``mapping`` (default :class:`Mapping`), then
    ``"<model> calibrated"`` per calibration."""
    mapping = mapping or Mapping()
    columns = {name: (name, mapping) for name in check_models(models)}
    for calibration in calibrations:
        columns[calibration.column] = (calibration.model, calibration.mapping)
    return columns


def validate(shots, *, calibrations=(), tables=None, progress=None, mapping=None, models=None,
             erosion=None, cross_validate=None):
    """Per-shot predictions of every model and their statistics.

    Parameters
    ----------
    shots : sequence of Shot
    calibrations : sequence of Calibration
        Each adds the column ``"<model> calibrated"`` (its model with its fitted mapping).
    tables : TableCache, optional
    mapping : Mapping, optional
        The uncalibrated mapping (default :class:`~cavex.concrete.Mapping`).
    models : sequence of str, optional
        The uncalibrated models to run (labels of :data:`MODELS`; default all).
    erosion : ErosionLaw, optional
        Nose erosion in every model that flies the integrator
        (:mod:`cavex.analytic.penetration.erosion`); None: rigid. Set, the result says so
        (``erosion``: the law's name).
    cross_validate : callable, optional
        ``cross_validate(result, shots, option_depths, calibrations, tables)``, from
        :func:`cavex.verification.validation.cross_validation.fold_validator` (the fold
        families, checked with the shots by its ``check_folds``): every option's depths are
        then computed, and the result gets ``cross_validation`` and each shot
        ``cross_validated_m``. Passed in, not imported: the cross-validation refits
        calibrations, which predict through this module.

    Returns
    -------
    dict
        ``shots`` (``id``, ``V0_m_s``, ``fc_Pa``, ``rho_kg_m3``, ``measured_m``,
        ``predicted_m`` and ``ratio`` per model), ``summary`` (per model, all shots),
        ``held_out`` (ids in no calibration's fit) and ``held_out_summary`` (with
        calibrations), ``outliers`` and ``summary_without_outliers`` (:func:`flag_outliers`),
        ``failures``, ``models``, ``calibrations``, ``recommended_model``.
    """
    mapping = mapping or Mapping()
    columns = validation_columns(calibrations, mapping, models)
    tables = tables or TableCache()
    tables.velocities_for(shots)
    concrete = [name for name, (model, _) in columns.items()
                if model_of(model).concrete_table_seconds]
    ids = [shot.id for shot in shots]
    depths, failures = predictions(
        shots, {k: v for k, v in columns.items() if k not in concrete}, tables, progress,
        erosion)
    flags = [None] * len(shots)
    option_depths = {}  # column -> {option: depths}, the columns with options, when asked
    if concrete:  # the concrete model's depths and flags, once for the models that use them
        runs = concrete_runs(shots, tables.workers, progress, erosion,
                             every_option=cross_validate is not None)
        concrete_depths, flags, concrete_failures = runs[get(CONCRETE_MODEL).option]
        for name in concrete:
            chosen = model_of(columns[name][0])
            depths[name], failed = concrete_depths, concrete_failures
            if chosen.parts:
                depths[name] = split_depths(chosen, shots, concrete_depths)
                failed = {i: reason for i, reason in concrete_failures.items()
                          if depths[name][ids.index(i)] is None}
            if failed:
                failures[name] = failed
            if cross_validate is not None:
                option_depths[name] = every_option_depths(chosen, shots, runs)
    depths = {name: depths[name] for name in columns}
    rows = []
    for i, shot in enumerate(shots):
        predicted = {name: depths[name][i] for name in columns}
        ratio = {name: None if d is None else d / shot.depth for name, d in predicted.items()}
        rows.append({"id": shot.id, "V0_m_s": shot.V0, "fc_Pa": shot.fc,
                     "rho_kg_m3": shot.rho, "measured_m": shot.depth, "predicted_m": predicted,
                     "ratio": ratio, "flag": flags[i]})
    fitted = {i for c in calibrations for i in c.shots}
    result = {"models": list(columns), "recommended_model": RECOMMENDED_MODEL,
              "mapping": mapping.as_dict(),
              "calibrations": [c.describe() for c in calibrations], "shots": rows,
              "failures": failures}
    if calibrations:
        result["held_out"] = [row["id"] for row in rows if row["id"] not in fitted]
    if erosion is not None:
        result["erosion"] = erosion.name
    add_statistics(result)
    if cross_validate is not None:
        for name in columns:  # a column with nothing chosen on shots: its one "option"
            option_depths.setdefault(name, {None: depths[name]})
        cross_validate(result, shots, option_depths, {c.column: c for c in calibrations},
                       tables)
    return result


def split_depths(model, shots, concrete_depths, option=None):
    """Depths of ``model`` (one with ``parts``, the concrete model one of them) under
    ``option`` (default its own) from the concrete model's ``concrete_depths`` (None where
    that failed and the shot needs it), rounded like every depth."""
    out = []
    for shot, depth in zip(shots, concrete_depths, strict=True):
        part = model.part(shot, option)
        if not part.tabulates_concrete:
            out.append(round_significant(part.shot_depth(shot), DEPTH_DIGITS))
        else:
            out.append(None if depth is None else round_significant(depth, DEPTH_DIGITS))
    return out


def concrete_runs(shots, workers=None, progress=None, erosion=None, every_option=False):
    """``{option: (depths, flags, failures)}`` of :func:`concrete_predictions` under the
    concrete model's option, and (``every_option``) under each of its options."""
    concrete = get(CONCRETE_MODEL)
    chosen = concrete.options if every_option else (concrete.option,)
    return {option: concrete_predictions(shots, workers, progress, erosion, option)
            for option in chosen}


def every_option_depths(model, shots, runs):
    """``{option: depths}`` of ``model`` (the concrete model or one with it as a part) under
    every option, from the concrete model's ``runs`` (:func:`concrete_runs`); a model with
    parts takes every pair of its own option and the concrete model's (``"<own>;
    concrete: <option>"``)."""
    if not model.parts:
        return {option: runs[option][0] for option in model.options}
    return {f"{own}; {CONCRETE_MODEL}: {inner}": split_depths(model, shots, runs[inner][0], own)
            for own in model.options for inner in runs}


def concrete_predictions(shots, workers=None, progress=None, erosion=None, option=None):
    """The concrete model's ``(depths, flags, failures)`` for ``shots``: per shot the depth
    (rounded like every depth, None if it failed), the rigid-regime flag
    (:func:`~cavex.verification.validation.regimes.rigid_flag`, None if it failed) and
    ``{shot id: reason}``. The shots of one concrete (``f_c``, ``rho``) go to one task, so its
    cavity table is built once; tasks run on ``workers`` local processes (default: the CPUs).
    ``erosion``: :func:`~cavex.analytic.penetration.concrete_table.table_depth`'s; ``option``:
    one of the concrete model's published options (default its own).
    """
    from cavex.analytic.penetration import concrete_table  # noqa: F401 (before the fork)
    from cavex.verification.fedata.runner import Progress, process_pool, show_progress

    groups = {}
    for i, shot in enumerate(shots):
        groups.setdefault((shot.fc, shot.rho), []).append(i)
    tasks = [([shots[i] for i in group], erosion, option) for group in groups.values()]
    workers = min(workers or os.cpu_count() or 1, len(tasks))
    bar = Progress(len(shots), 0, show_progress(progress), unit="prediction")
    results = []
    if workers > 1:
        with process_pool(workers) as pool:
            for task, answers in zip(tasks, pool.map(_concrete_task, tasks), strict=True):
                results.append(answers)
                bar.update(len(task[0]))
    else:
        for task in tasks:
            results.append(_concrete_task(task))
            bar.update(len(task[0]))
    bar.close()
    depths, flags, failures = [None] * len(shots), [None] * len(shots), {}
    for group, answers in zip(groups.values(), results, strict=True):
        for i, (depth, flag, reason) in zip(group, answers, strict=True):
            depths[i], flags[i] = depth, flag
            if reason is not None:
                failures[shots[i].id] = reason
    return depths, flags, failures


def _concrete_task(task):
    """:func:`concrete_group` of one task ``(shots, erosion, option)`` (a pool maps one
    argument)."""
    return concrete_group(*task)


def concrete_group(shots, erosion=None, option=None):
    """``[(depth, flag, reason)]`` of the concrete model for ``shots`` (one concrete) under
    ``option`` (default the model's own); ``erosion``:
    :func:`~cavex.analytic.penetration.concrete_table.table_depth`'s."""
    from cavex.analytic.penetration.concrete_table import TableResistance, table_depth

    model = get(CONCRETE_MODEL)
    out = []
    for shot in shots:
        try:
            resistance = TableResistance(shot, model.constants(shot, option))
            depth = round_significant(table_depth(shot, resistance, erosion), DEPTH_DIGITS)
            out.append((depth, rigid_flag(shot, resistance), None))
        except (CavexInputError, CavexNumericalError) as exc:
            out.append((None, None, str(exc).splitlines()[0]))
    return out


def add_statistics(result):
    """Set ``result``'s statistics from its ``shots`` and ``models``: ``summary`` (all shots),
    ``held_out_summary`` (when it has ``held_out``), ``regimes``
    (:func:`cavex.verification.validation.regimes.regime_statistics`), ``outliers`` and
    ``summary_without_outliers`` (:func:`flag_outliers`)."""
    rows, columns = result["shots"], result["models"]
    result["summary"] = summaries(rows, columns)
    if "held_out" in result:
        held = set(result["held_out"])
        result["held_out_summary"] = summaries([r for r in rows if r["id"] in held], columns)
    result["regimes"] = regime_statistics(rows, columns, DEPTH_DIGITS)
    return flag_outliers(result)


def is_outlier(ratios, factor=OUTLIER_FACTOR):
    """Whether every model that gave a depth (at least one) is off by more than ``factor``:
    ``|ln(predicted / measured)| > ln factor`` for every ratio that is not None."""
    given = [r for r in ratios if r is not None]
    return bool(given) and all(abs(math.log(r)) > math.log(factor) for r in given)


def flag_outliers(result, factor=OUTLIER_FACTOR):
    """Set ``result["outliers"]`` (``factor``, the flagged shot ids) and
    ``result["summary_without_outliers"]`` (:func:`summaries` over the other shots) from its
    ``shots`` and the columns of its ``summary``. The flagged shots stay in every other
    statistic: they are flagged, not dropped."""
    columns = list(result["summary"])
    flagged = [row["id"] for row in result["shots"]
               if is_outlier([row["ratio"][c] for c in columns], factor)]
    result["outliers"] = {"factor": factor, "shots": flagged}
    result["summary_without_outliers"] = summaries(
        [row for row in result["shots"] if row["id"] not in flagged], columns)
    return result


def summaries(rows, columns):
    """:func:`ratio_statistics` per column over ``rows``."""
    return {name: ratio_statistics([row["ratio"][name] for row in rows]) for name in columns}

