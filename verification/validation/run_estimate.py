"""``cavex validate``'s run estimate: the run's size and its time, from a short measured probe.

Constants measured once on an unloaded machine were off by 10x on a loaded one (issue 32:
1000 shots of the cheap models "under a minute" took 72 s at load 10 on 2 cores). So the
costs are measured now, on this machine under its present load, on a few of the run's own
shots (:data:`PROBE_SHOTS`, at quantiles of their velocity), each model's code path as the
run calls it:

- a model flown per shot (closed forms, empirical formulas): ``t_m``, the mean time of
  :func:`~cavex.verification.validation.predict.predict` after one untimed call (imports and
  compiled code load once, and the run finds them loaded);
- the concrete cavity model (``concrete_table_seconds > 0``): ``t_c``, the time of one
  concrete's cavity table, and ``t_f``, one shot's flight with it
  (:func:`~cavex.verification.validation.predict.concrete_group`'s steps), once for every
  model that uses it (validate computes its depths once);
- an FE table to build: ``t_e``, one FE case of the first table to build, after one untimed
  case, times the cases of a table (:func:`cases_per_table`: its grid and the first-layer
  row); a flight with an FE table: :data:`TABLE_FLIGHT_PER_CLOSED_FORM` times a closed form's
  flight measured now (no table exists yet to time it on).

Each ``t`` is CPU time, so that it does not depend on the moment it was measured; the run's
time is then

    T = f [sum_m n t_m + n t_table + (n_c t_c + n t_f) / s_c + N_e n_e t_e / s_e]

with ``f`` the wall time over the CPU time of one process now, the geometric mean of the
probe's and ``L/c`` of the one-minute load average ``L`` on ``c`` CPUs (:meth:`Clock.slowdown`:
a one-second probe alone can catch a quiet moment of a loaded machine, and the load average
lags a falling load),
with ``n`` shots, ``n_c`` cavity tables (:func:`cavity_tables`), ``N_e`` tables to build of
``n_e`` cases each,
and ``s`` the speed-up of ``w`` worker processes over the one process the probe ran in,
on ``c`` CPUs carrying a load ``L`` besides this process (:func:`parallel_speedup`):
``s = w min(1, c/(L + w)) / min(1, c/(L + 1))``, at most the number of tasks.
"""

import os
import time

from cavex.concrete import Mapping
from cavex.errors import CavexInputError, CavexNumericalError

PROBE_SHOTS = 8  # shots a model is timed on, at quantiles of their velocity
PROBE_BUDGET_SECONDS = 0.5  # a model's timed calls stop once they have taken this long
#: a flight with an FE table against one with a closed form, both measured on the development
#: shots on one machine (29 ms and 2.5 ms: docs/validation.md)
TABLE_FLIGHT_PER_CLOSED_FORM = 12.0
#: the share of the run a model must take to be named in the estimate line
NAMED_SHARE = 0.1


def by_velocity(shots, count):
    """Up to ``count`` of ``shots`` at evenly spaced quantiles of their striking velocity (a
    flight's cost grows with it)."""
    ordered = sorted(shots, key=lambda shot: shot.V0)
    n = len(ordered)
    return ordered if n <= count else [ordered[int((i + 0.5) * n / count)]
                                       for i in range(count)]


def spread(shots, count):
    """Up to ``count`` of ``shots`` at evenly spaced places in the file."""
    n = len(shots)
    if n <= count:
        return list(shots)
    return [shots[round(i * (n - 1) / (count - 1))] for i in range(count)] if count > 1 \
        else [shots[0]]


class Clock:
    """The probe's timings: each call's CPU time (this process's) and, summed over the whole
    probe, wall and CPU time, whose ratio is the slowdown the machine's load caused while the
    probe ran."""

    def __init__(self):
        self.wall = self.cpu = 0.0

    def seconds_of(self, call):
        """CPU time (s) of ``call()``; a refused or failed prediction counts as timed."""
        wall, cpu = time.perf_counter(), time.process_time()
        try:
            call()
        except (CavexInputError, CavexNumericalError):
            pass
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        self.wall += wall
        self.cpu += cpu
        return cpu

    def mean_time(self, calls):
        """Mean CPU time of ``calls`` after an untimed first (the warm-up), stopping once
        :data:`PROBE_BUDGET_SECONDS` are spent (at least one timed call)."""
        calls = list(calls)
        self.seconds_of(calls[0])
        times = []
        for call in calls[1:] or calls[:1]:
            times.append(self.seconds_of(call))
            if sum(times) > PROBE_BUDGET_SECONDS:
                break
        return sum(times) / len(times)

    def slowdown(self, cpus=None, load=None):
        """``f``: wall time over CPU time of one process, the geometric mean of the probe's
        and the one-minute load average's (:func:`load_slowdown`): the probe lasts a second
        and may catch a quiet moment (20 000 shots estimated at 426 s took 980 s), the load
        average lags a minute behind a load that falls (the larger of the two: 1120 s
        estimated, 352 s taken); the mean is within the square root of their ratio of
        either."""
        probe = self.wall / self.cpu if self.cpu > 0.0 else 1.0
        return max(1.0, (max(1.0, probe) * load_slowdown(cpus, load)) ** 0.5)


def load_slowdown(cpus=None, load=None):
    """``max(1, L/c)``: one process among a load average ``L`` (which counts it) on ``c``
    CPUs gets ``c/L`` of one."""
    cpus = cpus or os.cpu_count() or 1
    if load is None:
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0
    return max(1.0, load / cpus)


def prediction_seconds(clock, model, mapping, shots, tables, erosion):
    """``t_m``: one shot's prediction with the column ``model`` under ``mapping``."""
    from cavex.verification.validation.predict import predict

    sample = by_velocity(shots, PROBE_SHOTS + 1)
    return clock.mean_time([lambda s=s: predict(s, model, mapping, tables, erosion)
                      for s in sample])


def concrete_seconds(clock, shots, erosion):
    """``(t_c, t_f)``: one concrete's cavity table and one shot's flight with it, on shots
    of distinct concretes (a concrete's table is computed once per process)."""
    from cavex.analytic.penetration.concrete_table import TableResistance, table_depth
    from cavex.verification.validation.regimes import rigid_flag

    seen, sample = set(), []
    for shot in spread(shots, 4 * PROBE_SHOTS):
        if (shot.fc, shot.rho) not in seen:
            seen.add((shot.fc, shot.rho))
            sample.append(shot)
    table = clock.mean_time([lambda s=s: TableResistance(s) for s in sample[:PROBE_SHOTS]])
    resistances = []
    for shot in sample[:2]:
        try:
            resistances.append((shot, TableResistance(shot)))
        except (CavexInputError, CavexNumericalError):
            pass
    if not resistances:
        return table, 0.0
    flight = clock.mean_time([lambda s=s, r=r: (table_depth(s, r, erosion), rigid_flag(s, r))
                        for s, r in resistances * PROBE_SHOTS][:PROBE_SHOTS + 1])
    return table, flight


def cavity_tables(shots):
    """``n_c``: the concrete model's cavity tables ``shots`` need, one per concrete and table
    top (:func:`~cavex.analytic.penetration.concrete_table.shot_table_top`: shots into one
    concrete at different speeds need several)."""
    from cavex.analytic.penetration.concrete_table import shot_table_top

    return len({(s.fc, s.rho, shot_table_top(s)) for s in shots})


def cases_per_table(target, projectile, velocities):
    """``n_e``: the FE cases of one table (its grid and the first-layer row)."""
    from cavex.verification.fedata.table import grid_depths
    from cavex.verification.validation.predict import TABLE_DEPTHS

    return len(velocities) * (len(grid_depths(TABLE_DEPTHS, target, projectile)) + 1)


def fe_case_seconds(clock, target, projectile, velocities, numerics):
    """``t_e``: one FE case of the table of ``target`` at the middle of the velocity grid
    (after one untimed case at its top)."""
    from cavex.verification.fedata.cases import fe_cases
    from cavex.verification.fedata.table import table_cases

    v = sorted(velocities)
    cases = table_cases(target, projectile, [v[len(v) // 2], v[-1]], [0.0], None, numerics)
    return clock.mean_time([lambda c=c: fe_cases([c]) for c in (cases[-1], cases[0])])


def parallel_speedup(workers, tasks, cpus=None, load=None):
    """``s``: ``workers`` processes on ``tasks`` tasks against one process, on ``cpus`` CPUs
    (default :func:`os.cpu_count`) with a one-minute load average ``load`` (default
    :func:`os.getloadavg`'s, which counts this process)."""
    workers = max(1, min(workers, tasks))
    cpus = cpus or os.cpu_count() or 1
    if load is None:
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0
    others = max(0.0, load - 1.0)
    return workers * min(1.0, cpus / (others + workers)) / min(1.0, cpus / (others + 1.0))


def run_estimate(shots, models, tables, workers, erosion=None, every_option=False):
    """One line: the size of a run of ``models`` (column -> ``(model, mapping)``) over
    ``shots`` and its time ``T`` (module docstring), naming the models that take at least
    :data:`NAMED_SHARE` of it; ``tables``: the run's
    :class:`~cavex.verification.validation.predict.TableCache`; with ``every_option`` (a
    cross-validation) the cavity tables of every option of the concrete model."""
    from cavex.analytic.models import get
    from cavex.verification.validation.predict import CONCRETE_MODEL, model_of

    tables.velocities_for(shots)
    n = len(shots)
    table_columns = [(c, mapping or Mapping()) for c, (model, mapping) in models.items()
                     if model_of(model).takes_table]
    build, reused = tables.plan(shots, [m for _, m in table_columns]) if table_columns \
        else (0, 0)
    shares = {}
    closed_form = None
    clock = Clock()
    for column, (model, mapping) in models.items():
        chosen = model_of(model)
        if chosen.takes_table or chosen.concrete_table_seconds:
            continue
        seconds = prediction_seconds(clock, model, mapping, shots, tables, erosion)
        shares[column] = n * seconds
        if chosen.closed_form:
            closed_form = seconds
    concrete = [c for c, (model, _) in models.items() if model_of(model).concrete_table_seconds]
    if concrete:
        concretes = cavity_tables(shots)
        if every_option:
            concretes *= len(get(CONCRETE_MODEL).options)
        table_s, flight_s = concrete_seconds(clock, shots, erosion)
        total = (concretes * table_s + n * flight_s) / parallel_speedup(workers, concretes)
        for column in concrete:
            shares[column] = total / len(concrete)
    if table_columns:
        if closed_form is None:
            from cavex.analytic.models import labels

            reference = labels(closed_form=True, predicts_shots=True)[0]
            closed_form = prediction_seconds(clock, reference, None, shots, tables, None)
        for column, _ in table_columns:
            shares[column] = n * TABLE_FLIGHT_PER_CLOSED_FORM * closed_form
    cases = 0
    if build:
        target, projectile = tables.to_build[0]
        per_table = cases_per_table(target, projectile, tables._velocities)
        cases = build * per_table
        case_s = fe_case_seconds(clock, target, projectile, tables._velocities,
                                 tables.numerics)
        shares["FE tables"] = cases * case_s / parallel_speedup(workers, per_table)
    slowdown = clock.slowdown()
    shares = {column: cpu * slowdown for column, cpu in shares.items()}
    seconds = sum(shares.values())
    when = ("under a minute" if seconds < 60.0 else f"about {seconds / 60.0:.0f} min"
            if seconds < 3600.0 else f"about {seconds / 3600.0:.1f} h")
    named = sorted((s / seconds, c) for c, s in shares.items()
                   if seconds > 0.0 and s / seconds >= NAMED_SHARE)[::-1]
    mostly = "; mostly " + ", ".join(f"{c} {100.0 * f:.0f} %" for f, c in named) if named \
        else ""
    return (f"{n} shots x {len(models)} models = {n * len(models)} predictions; FE tables: "
            f"{build} to build ({cases} FE cases), {reused} on disk; {when} [~{seconds:.3g} s] "
            f"on {workers} worker(s) at this machine's present speed (measured){mostly}")
