"""The predictive concrete model (analytic/penetration/concrete_table.py) and the committed
study (results/concrete, made by verification/studies/concrete_validation.py)."""

import csv
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cavex.analytic import empirical
from cavex.analytic.empirical import crater_calibres, li_chen_depth
from cavex.analytic.penetration.concrete_table import (
    TableResistance,
    concrete_cavity,
    model_depth,
    table_depth,
)
from cavex.concrete import Concrete, aci_modulus, tensile_strength
from cavex.verification.studies import concrete_validation as study
from cavex.verification.validation.regimes import rigid_flag
from cavex.verification.validation.shots import read_shots, shot_projectile

ROOT = Path(__file__).resolve().parents[1]
SHOTS = ROOT / "examples" / "shots_compilation_dev.csv"
RESULTS = ROOT / "results" / "concrete"


@pytest.fixture(scope="module")
def shots():
    return read_shots(SHOTS).shots


def test_tensile_strength_fib():
    assert tensile_strength(30e6) == pytest.approx(0.3 * 22.0 ** (2.0 / 3.0) * 1e6)
    below, above = tensile_strength(58e6), tensile_strength(58e6 * (1 + 1e-12))
    assert above == pytest.approx(below, rel=3e-3)  # the two branches meet (4.07 / 4.06 MPa)


def test_crater_of_li_and_chen():
    assert crater_calibres(2.0) == pytest.approx(0.707 + math.sqrt(7.0) / 2.0)


class ParabolaResistance(TableResistance):
    """``sigma_r = f_c (A + B rho V^2 / f_c)`` exactly, through the table machinery."""

    def __init__(self, shot, A, B):
        super().__init__(shot)
        self.A, self.B = A, B

    def wall_stress(self, velocity):
        return self.shot.fc * self.A + self.B * self.shot.rho * np.asarray(velocity) ** 2


@pytest.mark.parametrize("index", [0, 40, 120])
def test_crater_and_integrator_reproduce_forrestal_closed_form(shots, index):
    """With ``sigma_r = A f_c + B rho V^2`` the depth is Forrestal's closed form with
    ``S = A`` and ``N* B`` (i.e. ``rho B``) and the same crater: the crater stage, the nose
    quadrature and cavex's integrator together (integrator rtol 1e-9)."""
    shot = shots[index]
    A, B = 11.0, 1.3
    depth = table_depth(shot, ParabolaResistance(shot, A, B))
    closed = shot.diameter * empirical.penetration_calibres(
        shot.mass, shot.diameter, shot.crh, shot.V0, shot.fc, B * shot.rho, S=A,
        crater_calibres=crater_calibres(shot.crh))
    assert depth == pytest.approx(closed, rel=1e-7)


def test_stop_in_the_crater(shots):
    slow = replace(shots[0], V0=5.0)
    resistance = ParabolaResistance(slow, 11.0, 1.3)
    crater = crater_calibres(slow.crh) * slow.diameter
    depth = table_depth(slow, resistance)
    assert depth < crater
    assert depth == pytest.approx(math.sqrt(slow.mass * slow.V0 ** 2 * crater
                                            / resistance.force(0.0, 0.0)))


def test_li_chen_headline_numbers(shots):
    """Li and Chen (2003) on the 286 development shots: mean |ln ratio| 0.483 (all), 0.356
    (f_c <= 100 MPa, V0 <= 1000 m/s), 1.152 (f_c > 100 MPa) (issue 19 quotes 0.48 / 0.36 /
    1.15)."""
    logs = np.array([math.log(li_chen_depth(s) / s.depth) for s in shots])
    fc = np.array([s.fc for s in shots])
    v = np.array([s.V0 for s in shots])
    assert len(shots) == 286
    assert np.mean(np.abs(logs)) == pytest.approx(0.483, abs=5e-4)
    assert np.mean(np.abs(logs[(fc <= 100e6) & (v <= 1000.0)])) == pytest.approx(0.356, abs=5e-4)
    assert np.mean(np.abs(logs[fc > 100e6])) == pytest.approx(1.152, abs=5e-4)


def test_rigid_flag(shots):
    shot = shots[0]
    resistance = TableResistance(shot)
    soft = replace(shot, extra={**shot.extra, "proj_yield_MPa": "50"})
    hard = replace(shot, extra={**shot.extra, "proj_yield_MPa": "5000"})
    unknown = replace(shot, extra={**shot.extra, "proj_yield_MPa": ""})
    assert rigid_flag(soft, resistance) == "non-rigid"
    assert rigid_flag(hard, resistance) == ""
    assert rigid_flag(unknown, resistance) == ""


def test_material_from_correlations():
    material = concrete_cavity(40e6, 2300.0)
    assert material.lam == pytest.approx(3.0 * 3.1 / 6.1)
    assert material.tau_max == 7.0
    # HJC's hydrostat in the FE's measures: crush at f_c/3, the lock point (mu_l, p_l) =
    # (0.1, 0.8 GPa) as (ln 1.1, 0.8 GPa/1.1), the locked slope (K_1 - p_l)/1.1
    E = aci_modulus(40e6, 2300.0)
    assert material.eta_lock == 0.0 and material.compacts
    assert material.bulk * 40e6 == pytest.approx(E / (3.0 * (1.0 - 2.0 * 0.2)))
    assert material.crush == pytest.approx(1.0 / 3.0)
    assert material.lock_pressure * 40e6 == pytest.approx(0.8e9 / 1.1)
    assert material.lock_strain == pytest.approx(math.log(1.1))
    assert material.bulk_locked * 40e6 == pytest.approx((85e9 - 0.8e9) / 1.1)
    assert material.tensile * 40e6 == pytest.approx(tensile_strength(40e6))
    layer = Concrete(40e6, 2300.0).fe_layer()
    assert (layer.crush_pressure / 40e6, layer.lock_strain) == (material.crush,
                                                               material.lock_strain)


def test_table_resistance_is_the_nose_quadrature(shots):
    shot = shots[10]
    resistance = TableResistance(shot)
    nodes = resistance._cosines
    assert resistance.force(0.3, 200.0) == pytest.approx(
        float(np.dot(resistance._weights, resistance.wall_stress(200.0 * nodes))))
    assert shot_projectile(shot).psi == pytest.approx(shot.crh)


# --- the committed study ------------------------------------------------------------------

def read_csv(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


@pytest.fixture(scope="module")
def committed():
    return read_csv(RESULTS / "predictions.csv"), read_csv(RESULTS / "grid_depths.csv")


def written_as(text_value, exact, digits=study.DIGITS):
    """``exact`` rounds to the written value (``digits`` significant): within half a unit of
    its last digit, plus 1e-9 relative for another CPU's last bits."""
    unit = 10.0 ** (math.floor(math.log10(abs(exact))) - digits + 1)
    return abs(float(text_value) - exact) <= 0.5 * unit * (1.0 + 1e-9) + 1e-9 * abs(exact)


def test_committed_study_is_consistent(shots, committed):
    """Every statistic of report.md is recomputed from the committed per-shot depths; the
    empirical depths are recomputed; the published-constants model is recomputed for every
    20th shot; LORO and the in-sample fit are redone from the committed grid."""
    rows, grid_rows = committed
    assert [r["id"] for r in rows] == [s.id for s in shots]
    depths = {m: [float(r[m]) if r[m] else None for r in rows] for m in study.MODELS}
    flags = [r["flag"] for r in rows]
    for i, shot in enumerate(shots):
        assert written_as(depths[study.LI_CHEN][i], li_chen_depth(shot))
        assert written_as(depths[study.FORRESTAL][i], empirical.shot_depth(shot))
    for i in range(0, len(shots), 20):
        assert written_as(depths[study.MODEL][i], model_depth(shots[i]))
    grid = {point: [float(r[f"S_max={point[0]:g};p_l={point[1]:g}"]) for r in grid_rows]
            for point in study.GRID}
    assert grid[study.PUBLISHED] == depths[study.MODEL]
    loro_depths, chosen = study.loro(grid, shots)
    assert loro_depths == depths[study.LORO]
    assert grid[study.best_point(grid, shots, range(len(shots)))] == depths[study.FIT]
    report = (RESULTS / "report.md").read_text()
    for model in study.MODELS:
        stats = study.statistics(depths[model], shots, flags)
        cells = " | ".join(f"{stats[r][1]:.3f} / {stats[r][2]:+.3f}" for r in study.REGIMES)
        assert f"| {model} | {cells} |" in report


def test_headline_numbers(shots, committed):
    """The numbers docs/concrete.md quotes (mean |ln ratio| per regime), from the committed
    depths (which test_committed_study_is_consistent ties to the code)."""
    rows, _ = committed
    flags = [r["flag"] for r in rows]
    expected = {study.MODEL: (0.484, 0.405, 0.473, 0.853), study.LORO: (0.552, 0.471, 0.389, 0.980),
                study.LI_CHEN: (0.483, 0.356, 0.251, 1.151),
                study.CAVEX: (0.707, 0.646, 1.167, 0.822)}
    for model, numbers in expected.items():
        stats = study.statistics([float(r[model]) for r in rows], shots, flags)
        got = tuple(stats[regime][1] for regime in list(study.REGIMES)[:4])
        assert got == pytest.approx(numbers, abs=5e-4)


def study_lambda():
    """The published concrete's ``lam`` (Richart's confinement)."""
    from cavex.concrete import mohr_coulomb_lambda

    return mohr_coulomb_lambda()


def test_committed_fe_against_closed_form_study():
    """results/concrete/fe_vs_closed_form.csv, the published concrete (cap, cracking,
    compaction, locking) over f_c 20-160 MPa x V 0-1200 m/s: in every cell the FE agrees with
    the closed form within its bound, the larger of its Richardson estimate and the spread of
    its refinement series (both recomputed here from the series in the file, so the file is
    consistent with itself) plus the closed form's small-strain term f_c/E; the grid reaches the
    cap, cracking and the lock. The full grid
    takes minutes (a series of four resolutions per cell): two cells, one cracked at rest and
    one moving, are recomputed here and equal the committed ones (to 1e-5: another CPU's
    last digits)."""
    from cavex.concrete import Concrete
    from cavex.fem.estimate import richardson_error
    from cavex.verification.studies import concrete_fe

    path = Path(__file__).resolve().parents[1] / "results" / "concrete" / "fe_vs_closed_form.csv"
    rows = list(csv.DictReader(path.read_text().splitlines()))
    assert len(rows) == len(concrete_fe.STRENGTHS) * len(concrete_fe.VELOCITIES) >= 30
    assert {float(r["fc_Pa"]) for r in rows} == set(concrete_fe.STRENGTHS)
    assert max(float(r["V_m_s"]) for r in rows) == 1200.0
    finest = f"S_fe_{concrete_fe.LEVELS[-1]}"
    for r in rows:
        series = [float(r[f"S_fe_{k}"]) for k in concrete_fe.LEVELS]
        S_fe, S_closed = float(r["S_fe"]), float(r["S_closed"])
        assert S_fe == float(r[finest])
        estimate = richardson_error(series[-1], series[-2])
        spread = max(abs(x / series[-1] - 1.0) for x in series[:-1])
        small_strain = float(r["fc_Pa"]) / Concrete(float(r["fc_Pa"]), concrete_fe.RHO).modulus
        # the file's S have 6 significant digits (up to 5e-6 relative each, for a leading 1):
        # a relative difference of two of them is good to 1e-5
        assert estimate == pytest.approx(float(r["estimate"]), abs=1e-5)
        assert spread == pytest.approx(float(r["spread"]), abs=1e-5)
        assert abs(S_fe / S_closed - 1.0) <= max(estimate, spread) + small_strain, r
    # every feature is active somewhere: cracking, the cap at the wall, the lock at the wall
    assert any("cracked" in r["structure"] for r in rows)
    # (on the cap D = cap f_c; below it D is smaller, so the pressure S - 2 cap/3 a lower bound)
    cap, lam = Concrete(20e6, concrete_fe.RHO).constants.cap, study_lambda()
    s_cap = (cap - (1.0 - lam / 3.0)) / lam + 2.0 * cap / 3.0
    assert sum(float(r["S_closed"]) > s_cap for r in rows) >= 10
    wall_pressure = [(float(r["S_closed"]) - 2.0 * cap / 3.0) * float(r["fc_Pa"]) for r in rows]
    assert sum(p > 0.8e9 for p in wall_pressure) >= 5
    for fc, velocity in ((40e6, 0.0), (80e6, 750.0)):
        row = concrete_fe.cell(fc, velocity)
        committed = next(r for r in rows if float(r["fc_Pa"]) == fc
                         and float(r["V_m_s"]) == velocity)
        for key in ("S_closed", "S_fe", f"S_fe_{concrete_fe.LEVELS[0]}"):
            assert row[key] == pytest.approx(float(committed[key]), rel=1e-5)
        assert row["ratio_to_bound"] <= 1.0
