r"""The FE against the concrete closed form over velocity and strength (issue 19, item 3).

``python -m cavex.verification.studies.concrete_fe [--out DIR]`` writes
``DIR/fe_vs_closed_form.csv`` (one row per cell), ``DIR/fe_vs_closed_form.md`` (the tables) and
``DIR/fe_vs_closed_form.png`` (the error maps); default folder ``results/concrete``.

For each ``f_c`` in :data:`STRENGTHS` (``E`` from ACI 318, ``rho`` = 2300 kg/m^3) and ``V`` in
:data:`VELOCITIES`, one cavity expanded by cavex's FE (:func:`cavex.fem.expand_cavity`, default
numerics) beside :func:`cavex.analytic.concrete_cavity.wall_stress` of the same material, for
three materials (:data:`CASES`), from where the closed form's assumptions hold to the concrete
model's own material:

- ``capped``: Mohr-Coulomb (``lam = 1.525``, through ``f_c``) capped at ``7 f_c``, nearly
  incompressible elastic zone (``nu = 0.49``), no cracking, the closed form's hydrostat its
  elastic bulk modulus: every assumption of the closed form holds but small elastic strain;
- ``capped, cracking``: the same with the tensile strength of fib MC2010
  (:func:`cavex.concrete.tensile_strength`): the FE holds the
  hoop stress at ``-f_t`` in its cracked zone, the closed form's cracked zone carries none;
- ``concrete model (nu = 0.2)``: the concrete model's elastic constants and cracking, its
  compaction left out of the closed form because the FE has none.

Each cell: the closed form's ``S``, the FE's, their relative difference and the FE's error
estimate; the map colours ``|difference|`` over ``estimate + f_c/E`` (the tests' bound in
tests/test_fem_concrete.py: the FE's discretisation plus the closed form's small-strain
elastic zone): at most 1 where the two agree within what the FE can resolve.
"""

import argparse
import csv
import io
import sys
from pathlib import Path

import numpy as np

from cavex.analytic.concrete_cavity import ConcreteCavity, wall_stress
from cavex.concrete import aci_modulus, tensile_strength
from cavex.errors import CavexInputError, CavexNumericalError
from cavex.fem import expand_cavity
from cavex.materials import Material
from cavex.verification.output.files import save_figure, write_text_atomic
from cavex.verification.output.number_format import round_significant
from cavex.verification.output.paths import check_output_dir

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_OUT = ROOT / "results" / "concrete"
STRENGTHS = (20e6, 40e6, 80e6, 160e6)
VELOCITIES = (0.0, 250.0, 500.0, 750.0, 1000.0)
RHO = 2300.0
LAM = 1.525
CAP = 7.0
RADIUS = 0.01
DIGITS = 6
CASES = ("capped", "capped, cracking", "concrete model (nu = 0.2)")


def materials(case, fc):
    """``(FE Material, ConcreteCavity)`` of ``case`` at ``fc``."""
    E = aci_modulus(fc, RHO)
    nu = 0.2 if case.startswith("concrete") else 0.49
    bulk = E / (3.0 * (1.0 - 2.0 * nu))
    cracking = case != "capped"
    ft = tensile_strength(fc) if cracking else None
    fe = Material(E=E, nu=nu, rho=RHO, lam=LAM, sigma_c=fc, tau_max=CAP * fc,
                  tensile_strength=ft)
    closed = ConcreteCavity(modulus=E / fc, nu=nu, lam=LAM, tau_max=CAP, bulk=bulk / fc,
                            eta_lock=0.0, bulk_locked=bulk / fc,
                            tensile=ft / fc if cracking else float("inf"))
    return fe, closed


def cell(case, fc, velocity):
    """One row: the closed form's and the FE's ``S``, the difference, the estimate."""
    fe, closed = materials(case, fc)
    row = {"case": case, "fc_Pa": fc, "V_m_s": velocity, "E_over_fc": fe.E / fc}
    try:
        S_closed = float(wall_stress(closed, RHO * velocity ** 2 / fc))
    except CavexNumericalError:
        S_closed = float("nan")
    try:
        run = expand_cavity([fe], [], velocity, RADIUS, dynamic=velocity > 0)
        S_fe, estimate = run.cavity_stress / fc, run.error_estimate
    except (CavexInputError, CavexNumericalError):
        S_fe, estimate = float("nan"), float("nan")
    row.update(S_closed=S_closed, S_fe=S_fe, difference=S_fe / S_closed - 1.0,
               estimate=estimate)
    row["ratio_to_bound"] = abs(row["difference"]) / (estimate + fc / fe.E)
    return row


def study():
    return [cell(case, fc, V) for case in CASES for fc in STRENGTHS for V in VELOCITIES]


COLUMNS = ("case", "fc_Pa", "V_m_s", "E_over_fc", "S_closed", "S_fe", "difference", "estimate",
           "ratio_to_bound")


def rows_csv(rows):
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS)
    for row in rows:
        writer.writerow([row[c] if isinstance(row[c], str) else
                         format(round_significant(row[c], DIGITS), ".6g") for c in COLUMNS])
    return out.getvalue()


def report_md(rows):
    lines = ["# The FE against the concrete closed form", "",
             "Made by `python -m cavex.verification.studies.concrete_fe` (docstring: the three "
             "materials). Per cell: FE / closed form - 1 (the FE's error estimate); `*` where "
             "|difference| > estimate + f_c/E (the FE cannot resolve the two as equal).", ""]
    for case in CASES:
        lines += [f"## {case}", "", "| f_c (MPa) | " + " | ".join(f"{v:g} m/s" for v in
                                                                     VELOCITIES) + " |",
                  "|---:|" + "---:|" * len(VELOCITIES)]
        for fc in STRENGTHS:
            cells = []
            for v in VELOCITIES:
                r = next(r for r in rows if r["case"] == case and r["fc_Pa"] == fc
                         and r["V_m_s"] == v)
                mark = "*" if not r["ratio_to_bound"] <= 1.0 else ""
                cells.append(f"{r['difference']:+.2e} ({r['estimate']:.1e}){mark}")
            lines.append(f"| {fc / 1e6:g} | " + " | ".join(cells) + " |")
        lines.append("")
    lines += ["![error maps](fe_vs_closed_form.png)", ""]
    return "\n".join(lines)


def figure(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    fig, axes = plt.subplots(1, len(CASES), figsize=(4.4 * len(CASES), 4.2), sharey=True)
    for ax, case in zip(axes, CASES, strict=True):
        grid = np.array([[next(r["ratio_to_bound"] for r in rows if r["case"] == case
                               and r["fc_Pa"] == fc and r["V_m_s"] == v)
                          for v in VELOCITIES] for fc in STRENGTHS])
        image = ax.imshow(grid, origin="lower", cmap="RdYlGn_r", aspect="auto",
                          norm=LogNorm(vmin=1e-2, vmax=1e2))
        for (i, j), value in np.ndenumerate(grid):
            ax.text(j, i, f"{value:.2g}", ha="center", va="center", fontsize=8)
        ax.set(xticks=range(len(VELOCITIES)), xticklabels=[f"{v:g}" for v in VELOCITIES],
               yticks=range(len(STRENGTHS)), yticklabels=[f"{f / 1e6:g}" for f in STRENGTHS],
               xlabel="V (m/s)", title=case)
    axes[0].set_ylabel("f_c (MPa)")
    fig.colorbar(image, ax=axes, label="|FE/closed - 1| / (FE estimate + f_c/E)", shrink=0.9)
    fig.suptitle("FE against the concrete closed form: at most 1 = agreement within what the "
                 "FE resolves", fontsize=10)
    save_figure(fig, path, dpi=110)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m cavex.verification.studies.concrete_fe",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(DEFAULT_OUT))
    args = parser.parse_args(argv)
    try:
        folder = check_output_dir(args.out, "out")
    except CavexInputError as exc:
        print(f"cavex: {exc}", file=sys.stderr)
        return 2
    rows = study()
    folder.mkdir(parents=True, exist_ok=True)
    write_text_atomic(folder / "fe_vs_closed_form.csv", rows_csv(rows))
    write_text_atomic(folder / "fe_vs_closed_form.md", report_md(rows))
    figure(rows, folder / "fe_vs_closed_form.png")
    print(report_md(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
