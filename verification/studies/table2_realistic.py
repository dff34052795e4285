r"""The paper's Table 2 under the Mohr-Coulomb layers and under the realistic concrete (issue 31,
item 5).

``python -m cavex.verification.studies.table2_realistic [--out DIR] [--workers N]`` writes, in
``DIR`` (default ``results/table2_realistic``):

- ``rows.csv``: per column (the paper's Table 2, the closed forms of the Mohr-Coulomb runway,
  the FE table of the Mohr-Coulomb runway, the FE table of the realistic concrete) and Table 2
  row: ``L``, ``V``, ``t`` and, for the FE tables, the estimate of each. Rows 1, 3, 4 are the
  flight's events (:func:`~cavex.verification.studies.table2.table2_rows`); row 2, the end of
  the closed forms' state ``a``, is for a table the point where the FE's elastic-plastic
  boundary reaches the concrete-macadam interface (:func:`state_a_end`);
- ``convergence.csv``: every flight of the refinement (per target: the table; the table with
  every other node in ``V`` once, twice, three times and in ``L`` once, twice; the FE mesh at
  the default and at twice the resolution on the coarse grid) and its rows;
- ``table2.md``: the one table of docs/table2.md ("Table 2 under the Mohr-Coulomb layers and
  under the realistic concrete");
- ``trajectories.png``: velocity against depth and time, both FE tables and the paper model's
  closed form beside Table 2's points;
- ``table_realistic.nc``, ``table_realistic_mesh.nc`` (and ``_mohr_coulomb``): the FE tables
  flown (netCDF-3, as the FE-table cache stores them), which the tests fly again; the first
  drives ``cavex penetrate --resistance table --table results/table2_realistic/
  table_realistic.nc --config examples/runway_realistic_concrete.toml`` (and ``cavex
  trajectory`` with the same options).

The targets. *Mohr-Coulomb*: the paper's Table 1 (``core/data/runway.toml``). *Realistic*:
``examples/runway_realistic_concrete.toml``, the same runway with the concrete layer the
published concrete of strength ``f_c = 3 tau/(3 - lam)`` = 26.32 MPa (the uniaxial strength of
the paper's layer): capped Mohr-Coulomb, tension cut-off, HJC's compaction hydrostat
(:meth:`cavex.concrete.Concrete.fe_layer`, docs/fem.md "Concrete", "Compaction"). No closed form
covers a layered target of that concrete (the concrete cavity model is one semi-infinite
medium), so its column is the FE's alone.

The tables (:func:`cached_table`, through the FE-table cache
:mod:`cavex.verification.fedata.table_cache`): velocities :data:`VELOCITIES`, 0 to 750 m/s
every 25 (the ogive's nose sees at most ``0.543 V``, 543 m/s at ``V0`` = 1000 m/s; row 2 reads
the plastic front at the projectile's own ``V``, reached below 700 m/s), depths :data:`DEPTHS`
(0.10 to 1.30 m every 0.02, twice ``cavex table``'s default density, with the switch depths
and their refinement added). Built from an empty cache the study took 7.3 min wall (180 s of CPU) on
two cores shared with other jobs; cached, about 25 s.

The estimate of a number ``q`` (a row's ``L``, ``V`` or ``t``) of a table's flight is

    E_q = |q_V(2h) - q| + |q_L(2h) - q| + |q_mesh(2) - q_mesh(1)|,

the table with every other node in ``V`` and in ``L``
(:func:`cavex.analytic.penetration.table_error.coarsened`, an upper estimate of the
interpolation error wherever its rate is at least 1) and the change when the FE's space and
time resolution is doubled (:data:`MESH_NUMERICS` against the default, both on the coarse
grid :data:`MESH_VELOCITIES` x :data:`MESH_DEPTHS`, whose default-resolution cells are the
fine table's own). Each number is written to the decimal of its estimate's leading digit.
"""

import argparse
import csv
import io
import math
import sys
from pathlib import Path

import numpy as np

from cavex.config import load_config
from cavex.verification.output.files import save_figure, write_text_atomic
from cavex.verification.output.number_format import Decimals, format_number
from cavex.verification.output.paths import check_output_dir
from cavex.verification.studies.inputs import output_folder
from cavex.verification.studies.table2 import PAPER_TABLE2, ROW_KEYS, table2_rows

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_OUT = ROOT / "results" / "table2_realistic"
REALISTIC_FILE = ROOT / "examples" / "runway_realistic_concrete.toml"
#: m/s: 0, 25, ..., 750 (the nose sees at most 0.543 V0 = 543 m/s; row 2 reads the plastic
#: front at the projectile's own V, below 750 m/s where it is reached)
VELOCITIES = tuple(float(v) for v in np.linspace(0.0, 750.0, 31))
#: nose depths (m): 0.10 ... 1.30 every 0.02, twice ``cavex table``'s default density (the
#: switch depths are added)
DEPTHS = tuple(float(d) for d in np.round(np.linspace(0.10, 1.30, 61), 6))
#: the coarse grid of the FE-mesh check: a subset of the table's
MESH_VELOCITIES = (0.0, 250.0, 500.0, 750.0)
MESH_DEPTHS = DEPTHS[::4]
#: twice the default space and time resolution (cavex.fem.Numerics: 30 per decade, 0.03)
MESH_NUMERICS = {"elements_per_decade": 60.0, "growth_per_step": 0.015}
TARGETS = ("mohr_coulomb", "realistic")
TARGET_WORDS = {"mohr_coulomb": "Mohr-Coulomb layers (Table 1), FE table",
                "realistic": "realistic concrete, FE table"}
ROW_NAMES = ("crater", "end of state a", "nose at H1", "rest")
#: the closed forms of the Mohr-Coulomb runway: (column, make_resistance options)
CLOSED_FORMS = (("paper model, cylindrical-sigma_c",
                 {"resistance": "paper", "epsilon": "cylindrical-sigma_c"}),
                ("derived, dynamic", {"resistance": "derived"}))
UNITS = {"depth_m": 1.0, "velocity_m_s": 1.0, "time_s": 1e3}  # t written in ms
#: the CSVs' quanta (SI): 1e-6 m, 0.01 m/s, 1e-7 s, 10 or more of the spreads a 1-ulp change
#: of the force makes in a flight (cavex.verification.output.number_format,
#: TRAJECTORY_QUANTA: 5e-8 m, 9.3e-4 m/s, 5.8e-9 s), so that another CPU writes the same text
CSV_QUANTA = {"depth_m": Decimals(6), "velocity_m_s": Decimals(2), "time_s": Decimals(7)}
CSV_DIGITS = 9  # significant digits, where the quantum is finer
ESTIMATE_DIGITS = 3


def target_of(name):
    """``(target, projectile)`` of the study's target ``name`` (:data:`TARGETS`)."""
    return load_config(None if name == "mohr_coulomb" else REALISTIC_FILE)


def cached_table(target, projectile, velocities, depths, numerics=None, workers=None):
    """The FE table on the grid, from the FE-table cache (claimed: concurrent runs build it
    once) or built (:func:`cavex.verification.fedata.table.tabulate`) and stored there; as read
    back from the file (rounded as stored)."""
    from cavex.verification.fedata.table import tabulate
    from cavex.verification.fedata.table_cache import (
        cache_dir,
        claimed,
        entry_path,
        read_entry,
        store,
        table_key,
    )

    path = entry_path(table_key(target, projectile, velocities, depths, numerics), cache_dir())
    with claimed(path):
        table, reason = read_entry(path, target, projectile, velocities, numerics)
        if table is not None:
            return table
        if reason is not None:
            print(f"table2_realistic: rebuilding '{path}': {reason[:200]}", file=sys.stderr)
        built = tabulate(target, projectile, velocities, depths, numerics=numerics,
                         workers=workers)
        failed = int(np.sum(built["failed"])) + int(np.sum(built["failed_first_layer"]))
        if failed:
            raise RuntimeError(f"{failed} FE cell(s) failed: {built.attrs['failures'][:300]}")
        return store(built, path)


def node_indices(table, velocities, depths):
    """Indices of the nodes of the coarser grid ``velocities x depths`` (as
    :func:`~cavex.verification.fedata.table.grid_depths` completes it) in ``table``'s grid,
    which contains them."""
    v = np.asarray(table["velocity"], dtype=float)
    d = np.asarray(table["depth"], dtype=float)
    iv = [int(np.argmin(np.abs(v - x))) for x in velocities]
    idp = [int(np.argmin(np.abs(d - x))) for x in depths]
    if not (np.allclose(v[iv], velocities, rtol=0, atol=1e-9)
            and np.allclose(d[idp], depths, rtol=0, atol=1e-9)):
        raise ValueError("the coarse grid is not a subset of the table's grid")
    return iv, idp


def nodes_of(table, velocities, depths):
    """``table`` restricted to the nodes of the coarser grid ``velocities x depths``
    (:func:`node_indices`)."""
    from cavex.analytic.penetration.table_error import table_at_nodes

    return table_at_nodes(table, *node_indices(table, velocities, depths), " (coarse grid)")


def plastic_front(table, iv=None, idp=None):
    """``(velocities, depths, b)``: the FE elastic-plastic boundary radius ``b`` of ``table``
    (its ``plastic_radius``) on the nodes ``iv x idp`` (default all)."""
    v = np.asarray(table["velocity"], dtype=float)
    d = np.asarray(table["depth"], dtype=float)
    iv = np.arange(v.size) if iv is None else np.asarray(iv)
    idp = np.arange(d.size) if idp is None else np.asarray(idp)
    b = np.asarray(table["plastic_radius"], dtype=float)[np.ix_(iv, idp)]
    return v[iv], d[idp], b


def state_a_end(run, front, target, projectile):
    """Row 2 of a table's flight, "before b reaches H1": the first point of the trajectory
    (after the crater) where the FE's elastic-plastic boundary ``b(V, L)`` (:func:`plastic_front`,
    bilinear in ``V`` and ``L``; the yielded zone: crushed and, in the realistic concrete,
    cracked) reaches the concrete-macadam interface, at radius ``H1 + l - L`` from the cavity
    centre, as the closed forms' state ``a`` ends (the same ``V`` and ``L``). Located by
    linear interpolation between the trajectory's points; None if ``b`` never reaches it."""
    from scipy.interpolate import RegularGridInterpolator

    velocities, depths, b = front
    boundary = RegularGridInterpolator((velocities, depths), b, method="linear")
    L, V, t = (np.asarray(x, dtype=float) for x in (run.depth, run.velocity, run.t))
    interface = target.interface_depths[0] + projectile.l - L
    # while the concrete surrounds the cavity (up to the switch depth, where the interface's
    # radius is the cavity's r <= b: the state has ended there at the latest)
    inside = ((L >= depths[0]) & (L <= depths[-1]) & (V <= velocities[-1])
              & (interface >= projectile.r))
    gap = np.full(L.shape, -np.inf)
    gap[inside] = boundary(np.column_stack([V[inside], L[inside]])) - interface[inside]
    reached = np.flatnonzero(gap >= 0.0)
    if reached.size == 0 or reached[0] == 0 or not np.isfinite(gap[reached[0] - 1]):
        return None  # never reached, or reached before the table's range: not located
    k = int(reached[0])
    s = gap[k - 1] / (gap[k - 1] - gap[k])
    return {key: float(x[k - 1] + s * (x[k] - x[k - 1]))
            for key, x in (("depth_m", L), ("velocity_m_s", V), ("time_s", t))}


def flight_rows(target, projectile, table, front=None):
    """Table 2's four rows (:func:`~cavex.verification.studies.table2.table2_rows`; row 2 from
    the FE's plastic front ``front`` by :func:`state_a_end`, None without it) and the final
    depth of the trajectory flown with ``table``."""
    from cavex.analytic.penetration.integrator import penetrate
    from cavex.analytic.penetration.tabulated import TabulatedResistance

    run = penetrate(target, projectile, TabulatedResistance(table, target, projectile),
                    crater="nose-base")
    rows = table2_rows(run)
    rows[1] = None if front is None else state_a_end(run, front, target, projectile)
    return {"rows": rows, "final_depth_m": float(run.depth[-1]), "run": run}


#: how often each axis is coarsened for the refinement series (every other node each time):
#: V spacing 25, 50, 100, 200 m/s; L spacing 0.02, 0.04, 0.08, 0.16 m
COARSENINGS = (("velocity", 3), ("depth", 3))


def variants(fine, target, projectile):
    """``{flight: (iv, idp)}``: the node indices in ``fine`` of each coarsened table:
    ``velocity``, ``velocity_x4``, ``velocity_x8`` (every other node in ``V``, once, twice,
    three times), ``depth``, ``depth_x4`` (in ``L``, :func:`~cavex.analytic.penetration.
    table_error.kept_depths`: the switch nodes kept), ``mesh_base`` (the coarse grid of the
    mesh check)."""
    from cavex.analytic.penetration.table_error import kept_depths, kept_velocities
    from cavex.verification.fedata.table import grid_depths

    v = np.asarray(fine["velocity"], dtype=float)
    d = np.asarray(fine["depth"], dtype=float)
    iv_all, idp_all = np.arange(v.size), np.arange(d.size)
    out = {}
    iv = iv_all
    for k in range(COARSENINGS[0][1]):
        iv = iv[kept_velocities(v[iv])]
        out["velocity" if k == 0 else f"velocity_x{2 ** (k + 1)}"] = (iv, idp_all)
    idp = idp_all
    for k in range(COARSENINGS[1][1]):
        idp = idp[kept_depths(d[idp], target, projectile)]
        out["depth" if k == 0 else f"depth_x{2 ** (k + 1)}"] = (iv_all, idp)
    out["mesh_base"] = node_indices(fine, MESH_VELOCITIES,
                                    grid_depths(MESH_DEPTHS, target, projectile))
    return out


def refinement(name, workers=None):
    """The flights of target ``name`` (:func:`flights_of`) and its two tables (``fine``,
    ``mesh``: the coarse grid at twice the FE resolution), from the cache or built."""
    target, projectile = target_of(name)
    fine = cached_table(target, projectile, VELOCITIES, DEPTHS, workers=workers)
    mesh = cached_table(target, projectile, MESH_VELOCITIES, MESH_DEPTHS, MESH_NUMERICS,
                        workers=workers)
    return flights_of(target, projectile, fine, mesh), {"fine": fine, "mesh": mesh}


def flights_of(target, projectile, fine, mesh):
    """``{flight: flight_rows}``: ``fine`` (the table), the coarsened tables of
    :func:`variants` and ``mesh_refined`` (``mesh``, the coarse grid at twice the FE
    resolution), each with its own plastic front for row 2."""
    from cavex.analytic.penetration.table_error import table_at_nodes

    flights = {"fine": flight_rows(target, projectile, fine, plastic_front(fine))}
    for flight, (iv, idp) in variants(fine, target, projectile).items():
        flights[flight] = flight_rows(target, projectile,
                                      table_at_nodes(fine, iv, idp, f" ({flight})"),
                                      plastic_front(fine, iv, idp))
    flights["mesh_refined"] = flight_rows(target, projectile, mesh, plastic_front(mesh))
    return flights


ESTIMATED = ("fine", "velocity", "depth", "mesh_base", "mesh_refined")


def estimates(flights):
    """Per row, ``{key: E}`` of the module docstring (None where a row is absent)."""
    out = []
    for i in range(len(PAPER_TABLE2)):
        rows = {k: f["rows"][i] for k, f in flights.items() if k in ESTIMATED}
        if any(r is None for r in rows.values()):
            out.append(None)
            continue
        out.append({k: abs(rows["velocity"][k] - rows["fine"][k])
                    + abs(rows["depth"][k] - rows["fine"][k])
                    + abs(rows["mesh_refined"][k] - rows["mesh_base"][k]) for k in ROW_KEYS})
    return out


def closed_form_runs():
    """The closed forms of the Mohr-Coulomb runway, flown as ``cavex penetrate`` flies them
    (:func:`cavex.analytic.models.make_resistance` with each model's default boundary, crater
    from the nose base): ``{column: trajectory}``."""
    from cavex.analytic.models import get, make_resistance
    from cavex.analytic.penetration.integrator import penetrate

    target, projectile = target_of("mohr_coulomb")
    runs = {}
    for column, options in CLOSED_FORMS:
        boundary = get(options["resistance"]).boundary(None)
        resistance = make_resistance(target, projectile, boundary=boundary, **options)
        runs[column] = penetrate(target, projectile, resistance, crater="nose-base")
    return runs


def decimals_of(estimate, unit=1.0, floor=0.0):
    """Decimals to write a number of estimate ``estimate`` (in ``unit``): those of its
    leading digit; ``floor`` (in ``unit``) for an estimate below it."""
    e = max(abs(estimate) * unit, floor)
    return max(0, -math.floor(math.log10(e))) if e > 0 else 6


#: the least a number is written to (in its written unit): the trajectories' CSV quanta
#: (cavex.verification.output.number_format.TRAJECTORY_QUANTA: 1e-7 s, 0.01 m/s; 1e-6 m)
WRITE_FLOOR = {"depth_m": 1e-6, "velocity_m_s": 1e-2, "time_s": 1e-4}


def written(value, estimate, key):
    """``value`` and ``"± estimate"`` to the decimals of the estimate's leading digit; an
    estimate below the written floor (:data:`WRITE_FLOOR`) as ``"(± < floor)"``; the stop's
    velocity (0 by definition) as ``"0"``."""
    unit = UNITS[key]
    if value is None:
        return "-"
    if key == "velocity_m_s" and value == 0.0:
        return "0"
    n = decimals_of(estimate, unit, WRITE_FLOOR[key])
    if estimate * unit < WRITE_FLOOR[key] / 2:
        return f"{value * unit:.{n}f} (± < {WRITE_FLOOR[key]:g})"
    return f"{value * unit:.{n}f} ± {estimate * unit:.{n}f}"


def columns(results, closed):
    """The columns of the one table: ``[(name, rows, estimates or None)]``."""
    paper = [{k: row[k] for k in ROW_KEYS} for row in PAPER_TABLE2]
    out = [("She (2020) Table 2", paper, None)]
    out += [(f"Mohr-Coulomb layers, {name}", rows, None) for name, rows in closed.items()]
    for name in TARGETS:
        flights = results[name]
        out.append((TARGET_WORDS[name], flights["fine"]["rows"], estimates(flights)))
    return out


def markdown(cols):
    """The one table: rows of Table 2, one column per model; ``L m, V m/s, t ms``."""
    head = "| row | " + " | ".join(name for name, _, _ in cols) + " |"
    lines = [head, "|" + "---|" * (len(cols) + 1)]
    for i, row_name in enumerate(ROW_NAMES):
        cells = []
        for name, rows, est in cols:
            row, e = rows[i], (est[i] if est else None)
            if row is None:
                cells.append("- (not reached)")
                continue
            if name.startswith("She"):
                cells.append(f"{row['depth_m']:.2f} m, {row['velocity_m_s']:.1f} m/s, "
                             f"{row['time_s'] * 1e3:.2f} ms")
                continue
            if est is None:  # closed form: the integrator's (rtol 1e-9), written as the commands
                cells.append(f"{row['depth_m']:.3f} m, {row['velocity_m_s']:.1f} m/s, "
                             f"{row['time_s'] * 1e3:.3f} ms")
                continue
            if e is None:
                cells.append("- (no estimate: a refined flight lacks the row)")
                continue
            cells.append(", ".join(f"{written(row[k], e[k], k)} {u}"
                                   for k, u in zip(ROW_KEYS, ("m", "m/s", "ms"), strict=True)))
        lines.append(f"| {i + 1} {row_name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def csv_value(value, key):
    """A row's ``value`` of ``key`` (SI) as the CSVs write it (:data:`CSV_QUANTA`)."""
    return format_number(value, CSV_DIGITS, CSV_QUANTA[key])


def rows_csv(cols):
    """One line per column and row: the values (SI) and estimates (empty where none)."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["column", "row", "name", *ROW_KEYS, *(f"estimate_{k}" for k in ROW_KEYS)])
    for name, rows, est in cols:
        for i, row in enumerate(rows):
            e = est[i] if est else None
            values = ["" if row is None else csv_value(row[k], k) for k in ROW_KEYS]
            errs = ["" if e is None else format_number(e[k], ESTIMATE_DIGITS, CSV_QUANTA[k])
                    for k in ROW_KEYS]
            writer.writerow([name, i + 1, ROW_NAMES[i], *values, *errs])
    return out.getvalue()


def convergence_csv(results):
    """One line per target and flight: the final depth and each row's ``L, V, t``."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["target", "flight", "final_depth_m",
                     *(f"row{i + 1}_{k}" for i in range(4) for k in ROW_KEYS)])
    for name in TARGETS:
        for flight, f in results[name].items():
            values = [("" if row is None else csv_value(row[k], k))
                      for row in f["rows"] for k in ROW_KEYS]
            writer.writerow([name, flight, csv_value(f["final_depth_m"], "depth_m"), *values])
    return out.getvalue()


def figure(results, paper_model, path):
    """Velocity against depth and against time: both FE tables, the paper model's closed form
    (``paper_model``, its trajectory) and Table 2's points."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_l, ax_t) = plt.subplots(1, 2, figsize=(10, 4))
    styles = {"mohr_coulomb": ("C0", "Mohr-Coulomb layers (Table 1), FE table"),
              "realistic": ("C3", "realistic concrete, FE table")}
    for name, (color, label) in styles.items():
        run = results[name]["fine"]["run"]
        ax_l.plot(run.depth, run.velocity, color=color, label=label)
        ax_t.plot(run.t * 1e3, run.velocity, color=color, label=label)
    label = f"Mohr-Coulomb layers, {CLOSED_FORMS[0][0]}"
    ax_l.plot(paper_model.depth, paper_model.velocity, "k--", lw=1, label=label)
    ax_t.plot(paper_model.t * 1e3, paper_model.velocity, "k--", lw=1, label=label)
    paper = [(r["depth_m"], r["velocity_m_s"], r["time_s"]) for r in PAPER_TABLE2]
    ax_l.plot([p[0] for p in paper], [p[1] for p in paper], "ko", label="She (2020) Table 2")
    ax_t.plot([p[2] * 1e3 for p in paper], [p[1] for p in paper], "ko",
              label="She (2020) Table 2")
    target, _ = target_of("mohr_coulomb")
    for ax in (ax_l,):
        for h in target.interface_depths:
            ax.axvline(h, color="0.6", lw=0.8, ls="--")
    ax_l.set_xlabel("nose-tip depth L (m)")
    ax_t.set_xlabel("time t (ms)")
    for ax in (ax_l, ax_t):
        ax.set_ylabel("velocity V (m/s)")
        ax.grid(alpha=0.3)
    ax_l.legend(fontsize=8)
    ax_l.set_title("V0 = 1000 m/s: concrete 0.65 m | macadam 0.45 m | soil", fontsize=9)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def run_study(out=DEFAULT_OUT, workers=None):
    """Build (or read from the cache) the tables, fly them, write the files; returns the
    results ``{target: flights}`` and the columns."""
    from cavex.verification.fedata.table import write_table

    out = check_output_dir(out, "out")
    results, tables = {}, {}
    for name in TARGETS:
        results[name], tables[name] = refinement(name, workers)
    closed = closed_form_runs()
    cols = columns(results, {name: table2_rows(run) for name, run in closed.items()})
    out.mkdir(parents=True, exist_ok=True)
    for name in TARGETS:
        for kind, table in tables[name].items():
            suffix = "" if kind == "fine" else "_mesh"
            write_table(table, out / f"table_{name}{suffix}.nc")
    write_text_atomic(out / "rows.csv", rows_csv(cols))
    write_text_atomic(out / "convergence.csv", convergence_csv(results))
    write_text_atomic(out / "table2.md", markdown(cols))
    figure(results, closed[CLOSED_FORMS[0][0]], out / "trajectories.png")
    return results, cols


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(DEFAULT_OUT))
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args(argv)
    folder = output_folder(args)
    if folder is None:
        return 2
    results, cols = run_study(folder, args.workers)
    print(markdown(cols))
    for name in TARGETS:
        f = results[name]
        print(name, {k: round(v["final_depth_m"], 6) for k, v in f.items()})
    return 0


if __name__ == "__main__":
    sys.exit(main())
