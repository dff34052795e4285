r"""The FE against the concrete closed form for the published model (issue 31, item 1).

``python -m cavex.verification.studies.concrete_fe [--out DIR] [--workers N]`` writes
``DIR/fe_vs_closed_form.csv`` (one row per cell), ``DIR/fe_vs_closed_form.md`` (the table) and
``DIR/fe_vs_closed_form.png`` (the map); default folder ``results/concrete``.

The material is the published concrete model, one description used twice
(:class:`cavex.concrete.Concrete` at ``rho`` = :data:`RHO`): the FE expands a cavity in its
:meth:`~cavex.concrete.Concrete.fe_layer` (Mohr-Coulomb through ``f_c``, the cap ``7 f_c``,
the tension cut-off ``f_t``, HJC's compaction hydrostat), the closed form
:func:`cavex.analytic.concrete_cavity.solve` solves the self-similar expansion of its
:meth:`~cavex.concrete.Concrete.cavity_parameters` (the same strength, cracked zone and
hydrostat; docs/concrete.md "One law in both"). Every feature of the model is active on the
grid: the cap, cracking (at low speeds), compaction and locking.

Per cell (``f_c`` in :data:`STRENGTHS` x ``V`` in :data:`VELOCITIES`): the closed form's
``S = sigma_r(a)/f_c`` and its structure; the FE's wall stress from a refinement series at
:data:`LEVELS` times the default resolution (``elements_per_decade = 30 k``,
``growth_per_step = 0.03/k``); the finest is the FE's answer. Its error, two ways:

- ``estimate``: the FE's own error estimate (:func:`cavex.fem.estimate.richardson_error`, the
  finest run against its companion at half the resolution, second order assumed);
- ``spread``: the measured spread of the series, ``max |S_k/S_finest - 1|`` over every coarser
  level. The wall stress converges unevenly at speed (the compaction shock, the fronts crossing
  elements, the start from the seed cavity: the levels move by up to 1.7 % at 20 MPa, 1200 m/s),
  where the Richardson estimate, which assumes second order, is far smaller than the change
  between levels; the spread assumes no order.

The bound of a cell is the larger of the two plus ``f_c/E``, the closed form's own modelling
term (its elastic and cracked zones are small-strain, the FE's Hencky: docs/fem.md, measured
linear in ``f_c/E`` in tests/test_fem_concrete.py); ``ratio_to_bound = |difference| / bound``
is at most 1 where the FE agrees with the closed form within what its refinement resolves
(tests/test_concrete_model.py asserts every committed cell, and recomputes two). The table
also counts the cells within the FE's part alone.
"""

import argparse
import csv
import io
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from cavex.analytic.concrete_cavity import ConcreteCavity, solve
from cavex.concrete import Concrete
from cavex.fem import expand_cavity
from cavex.fem.estimate import richardson_error
from cavex.verification.output.files import save_figure, write_text_atomic
from cavex.verification.output.number_format import round_significant
from cavex.verification.studies.inputs import output_folder

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_OUT = ROOT / "results" / "concrete"
STRENGTHS = (20e6, 40e6, 80e6, 160e6)
VELOCITIES = (0.0, 150.0, 300.0, 450.0, 600.0, 750.0, 900.0, 1050.0, 1200.0)
LEVELS = (1, 2, 4, 8)  # resolution of the series, in units of the default
RHO = 2300.0
RADIUS = 0.01
DIGITS = 6
COLUMNS = ("fc_Pa", "V_m_s", "structure", "S_closed", "S_fe", "difference", "estimate",
           "spread", "fc_over_E", "bound", "ratio_to_bound") + tuple(f"S_fe_{k}" for k in LEVELS)


def fe_stress(fc, velocity, level):
    """The FE's ``S`` of the published concrete at ``level`` times the default resolution."""
    layer = Concrete(fc, RHO).fe_layer()
    run = expand_cavity([layer], [], velocity, RADIUS, dynamic=velocity > 0.0,
                        elements_per_decade=30.0 * level, growth_per_step=0.03 / level,
                        error_estimate=False)
    return run.cavity_stress / fc


def cell(fc, velocity):
    """One row (:data:`COLUMNS`)."""
    closed = solve(ConcreteCavity(**Concrete(fc, RHO).cavity_parameters()),
                   RHO * velocity ** 2 / fc)
    series = [fe_stress(fc, velocity, k) for k in LEVELS]
    return cell_row(fc, velocity, closed.name, closed.S, series)


def cell_row(fc, velocity, structure, S_closed, series):
    """The row of a cell from the closed form's ``S`` and the FE's series (one per level)."""
    finest = series[-1]
    row = {"fc_Pa": fc, "V_m_s": velocity, "structure": structure, "S_closed": S_closed,
           "S_fe": finest, "difference": finest / S_closed - 1.0,
           "estimate": richardson_error(finest, series[-2]),
           "spread": max(abs(s / finest - 1.0) for s in series[:-1]),
           "fc_over_E": fc / Concrete(fc, RHO).fe_layer().E}
    row["bound"] = max(row["estimate"], row["spread"]) + row["fc_over_E"]
    row["ratio_to_bound"] = abs(row["difference"]) / row["bound"]
    row.update({f"S_fe_{k}": s for k, s in zip(LEVELS, series, strict=True)})
    return row


def _cell(args):
    return cell(*args)


def study(workers=1):
    cells = [(fc, V) for fc in STRENGTHS for V in VELOCITIES]
    if workers <= 1:
        return [cell(*c) for c in cells]
    with ProcessPoolExecutor(workers) as pool:
        return list(pool.map(_cell, cells))


def rows_csv(rows):
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS)
    for row in rows:
        writer.writerow([row[c] if isinstance(row[c], str) else
                         format(round_significant(row[c], DIGITS), ".6g") for c in COLUMNS])
    return out.getvalue()


def report_md(rows):
    worst = max(rows, key=lambda r: abs(r["difference"]))
    lines = ["# The FE against the concrete closed form: the published model", "",
             "Made by `python -m cavex.verification.studies.concrete_fe` (its docstring: the "
             "material, the refinement series, the bound). The published concrete (cap 7 f_c, "
             "tension cut-off f_t, HJC's compaction hydrostat) at rho = 2300 kg/m^3, the FE at "
             f"{LEVELS[-1]} times the default resolution. Per cell: FE / closed form - 1, then "
             "(the FE's Richardson estimate / the spread of the refinement series); `*` where "
             "|difference| exceeds the bound, the larger of the two plus f_c/E (the closed "
             "form's small-strain term).", "",
             f"Cells: {len(rows)}; within the bound: "
             f"{sum(r['ratio_to_bound'] <= 1.0 for r in rows)}; within the FE's part alone "
             "(without f_c/E): "
             f"{sum(abs(r['difference']) <= max(r['estimate'], r['spread']) for r in rows)}; "
             "largest |difference| "
             f"{abs(worst['difference']):.2e} ({worst['fc_Pa'] / 1e6:g} MPa, "
             f"{worst['V_m_s']:g} m/s).", "",
             "| f_c (MPa) | " + " | ".join(f"{v:g} m/s" for v in VELOCITIES) + " |",
             "|---:|" + "---:|" * len(VELOCITIES)]
    for fc in STRENGTHS:
        cells = []
        for v in VELOCITIES:
            r = next(r for r in rows if r["fc_Pa"] == fc and r["V_m_s"] == v)
            mark = "*" if not r["ratio_to_bound"] <= 1.0 else ""
            cells.append(f"{r['difference']:+.1e} ({r['estimate']:.0e}/{r['spread']:.0e}){mark}")
        lines.append(f"| {fc / 1e6:g} | " + " | ".join(cells) + " |")
    lines += ["", "Structures of the closed form:", ""]
    for fc in STRENGTHS:
        names = [next(r["structure"] for r in rows if r["fc_Pa"] == fc and r["V_m_s"] == v)
                 for v in VELOCITIES]
        lines.append(f"- {fc / 1e6:g} MPa: " + ", ".join(
            f"{v:g} m/s {n}" for v, n in zip(VELOCITIES, names, strict=True)))
    lines += ["", "![error map](fe_vs_closed_form.png)", ""]
    return "\n".join(lines)


def figure(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    grid = np.array([[next(r["ratio_to_bound"] for r in rows if r["fc_Pa"] == fc
                           and r["V_m_s"] == v) for v in VELOCITIES] for fc in STRENGTHS])
    image = ax.imshow(np.maximum(grid, 1e-3), origin="lower", cmap="RdYlGn_r", aspect="auto",
                      norm=LogNorm(vmin=1e-2, vmax=1e2))
    for (i, j), value in np.ndenumerate(grid):
        ax.text(j, i, f"{value:.2g}", ha="center", va="center", fontsize=8)
    ax.set(xticks=range(len(VELOCITIES)), xticklabels=[f"{v:g}" for v in VELOCITIES],
           yticks=range(len(STRENGTHS)), yticklabels=[f"{f / 1e6:g}" for f in STRENGTHS],
           xlabel="V (m/s)", ylabel="f_c (MPa)",
           title="published concrete: |FE/closed - 1| / bound (at most 1: agreement)")
    fig.colorbar(image, ax=ax, shrink=0.9)
    save_figure(fig, path, dpi=110)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m cavex.verification.studies.concrete_fe",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(DEFAULT_OUT))
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args(argv)
    folder = output_folder(args)
    if folder is None:
        return 2
    if not 1 <= args.workers <= 64:
        print(f"cavex: workers must be in [1, 64], got {args.workers}", file=sys.stderr)
        return 2
    rows = study(args.workers)
    folder.mkdir(parents=True, exist_ok=True)
    write_text_atomic(folder / "fe_vs_closed_form.csv", rows_csv(rows))
    write_text_atomic(folder / "fe_vs_closed_form.md", report_md(rows))
    figure(rows, folder / "fe_vs_closed_form.png")
    print(report_md(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
