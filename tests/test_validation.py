"""Validation against experiments: shot files, the empirical model, the (f_c, rho) mapping,
calibration and ``cavex validate`` / ``cavex calibrate`` (docs/validation.md).

Tolerances, each from a measurement or a printed precision:

- Li and Chen (2003) print X/d = 6.21 (3 digits, +-0.005/6.21 = 0.08 %); the issue asks for
  0.5 %; measured 0.087 % (6.2154).
- the Forrestal and Li-Chen forms of the same model agree to round-off (1e-12).
- calibration recovery: the fitted parameters are written with 6 significant digits (half a
  unit: 5e-6 relative) and the least-squares tolerances are 1e-12; measured: recovered exactly
  to the written digits (2 and 3 parameters); asserted at 1e-5, twice the rounding.
- depths in the result files carry 6 significant digits: half a unit, 5e-6 relative.
"""

import csv
import json
import math
import tomllib

import numpy as np
import pytest

from cavex.analytic import empirical
from cavex.analytic.penetration.integrator import crater_depth, penetrate
from cavex.analytic.penetration.resistance import ClosedFormResistance
from cavex.analytic.penetration.tabulated import TabulatedResistance
from cavex.concrete import Mapping, aci_modulus, concrete_material
from cavex.errors import CavexInputError
from cavex.verification.cli import main
from cavex.verification.fedata.table import analytic_table
from cavex.verification.validation.calibration import fit, read_calibration
from cavex.verification.validation.predict import (
    TABLE_DEPTHS,
    closed_form_depth,
    penetration_depth,
    ratio_statistics,
    table_velocities,
)
from cavex.verification.validation.shots import (
    Shot,
    parse_shots,
    read_shots,
    shot_projectile,
    shot_target,
)

SHOTS = "examples/shots_forrestal1994.csv"
COLUMNS = "id,mass_kg,diameter_m,length_m,crh,V0_m_s,fc_Pa,rho_kg_m3,depth_m"
GOOD_ROW = "A1,0.906,0.0269,0.2424,2.0,277.0,35200000.0,2370.0,0.173"
DIGITS_6 = 5e-6 * (1 + 1e-9)  # half a unit in the 6th significant digit, relative


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# --- the empirical model ----------------------------------------------------------------------

def test_li_chen_worked_example_forrestal_shot_14():
    """Forrestal 1994 shot 14 (0.906 kg, 26.9 mm, CRH 2, 277 m/s, 35.2 MPa, 2370 kg/m^3,
    measured 173 mm): Li and Chen (2003) print X/d = 6.21 with S = 12, crater of 2 calibres."""
    x_d = empirical.penetration_calibres(0.906, 0.0269, 2.0, 277.0, 35.2e6, 2370.0, S=12.0,
                                         crater_calibres=2.0)
    assert x_d == pytest.approx(6.21, rel=5e-3)
    assert abs(x_d - 6.21) < 0.006  # measured 6.2154: within the printed 3 digits + 1e-3
    assert 0.0269 * x_d == pytest.approx(0.167, abs=5e-4)  # "about 167 mm"
    # S = 82.6 f_c^-0.544 at 35.2 MPa is 11.90, printed by Li and Chen as 12
    assert empirical.strength_factor(35.2e6) == pytest.approx(11.903, abs=1e-3)
    assert round(empirical.strength_factor(35.2e6)) == 12
    # the shot in the committed data file (F94-52) is that shot
    shot = read_shots(SHOTS).by_id(["F94-52"])[0]
    assert (shot.mass, shot.diameter, shot.crh, shot.V0, shot.fc, shot.rho, shot.depth) == (
        0.906, 0.0269, 2.0, 277.0, 35.2e6, 2370.0, 0.173)
    assert empirical.shot_depth(shot, S=12.0) == pytest.approx(0.0269 * x_d, rel=1e-15)


def forrestal_dimensional(m, d, crh, v, fc, rho, S):
    """Forrestal et al. (1994) in their own variables (a = d/2, crater 4a), typed from the
    paper's equations independently of the module."""
    a = d / 2.0
    n_star = (8.0 * crh - 1.0) / (24.0 * crh ** 2)
    v1_sq = (m * v ** 2 - 4.0 * math.pi * a ** 3 * S * fc) / (m + 4.0 * math.pi * a ** 3
                                                              * n_star * rho)
    return m / (2.0 * math.pi * a ** 2 * rho * n_star) * math.log(
        1.0 + n_star * rho * v1_sq / (S * fc)) + 4.0 * a


@pytest.mark.parametrize("v, fc, crh", [(277.0, 35.2e6, 2.0), (800.0, 32.4e6, 2.0),
                                        (600.0, 95e6, 3.0), (1200.0, 40e6, 0.5)])
def test_li_chen_form_equals_forrestal_form(v, fc, crh):
    S = empirical.strength_factor(fc)
    ours = empirical.forrestal_depth(0.9, 0.0269, crh, v, fc, 2370.0)
    assert ours == pytest.approx(forrestal_dimensional(0.9, 0.0269, crh, v, fc, 2370.0, S),
                                 rel=1e-12)


def test_empirical_crater_branch_is_continuous():
    """A projectile that stops in the crater: the branch meets the tunnel form at X = 2d."""
    m, d, fc, rho = 0.9, 0.0269, 35e6, 2370.0
    S, n_star = empirical.strength_factor(fc), empirical.ogive_factor(2.0)
    # V_1 = 0 at: m V^2 = 4 pi a^3 S f_c
    v_star = math.sqrt(4.0 * math.pi * (d / 2) ** 3 * S * fc / m)
    for factor in (1.0 - 1e-9, 1.0 + 1e-9):
        assert empirical.penetration_calibres(m, d, 2.0, v_star * factor, fc, rho) == \
            pytest.approx(2.0, rel=1e-8)
    slow = empirical.penetration_calibres(m, d, 2.0, 0.5 * v_star, fc, rho)
    I, N = empirical.li_chen_functions(m, d, 2.0, 0.5 * v_star, fc, rho)  # noqa: E741
    assert slow < 2.0 and slow == pytest.approx(
        math.sqrt(I * (8 / math.pi) * (1 + math.pi / (2 * N)) / (1 + I / N)), rel=1e-14)
    assert n_star == pytest.approx(15.0 / 96.0, rel=1e-15)


# --- mapping and projectile -------------------------------------------------------------------

def test_concrete_mapping_and_projectile():
    fc, rho = 35.2e6, 2370.0
    material = concrete_material(fc, rho)
    # ACI 318-19 19.2.2.1(a), typed in: 0.043 * 2370^1.5 * sqrt(35.2) MPa = 29.435 GPa
    assert material.E == pytest.approx(0.043 * 2370.0 ** 1.5 * 35.2 ** 0.5 * 1e6, rel=1e-14)
    assert material.E == pytest.approx(29.435e9, rel=1e-4)
    assert aci_modulus(fc, rho) == material.E
    # Richart et al. (1928): N_phi = 4.1 -> lam; docs/problem.md N_phi = (3 + 2 lam)/(3 - lam)
    lam = material.lam
    assert (3 + 2 * lam) / (3 - lam) == pytest.approx(4.1, rel=1e-14)
    assert math.degrees(math.asin(3 * lam / (6 + lam))) == pytest.approx(37.4, abs=0.05)
    assert material.tau == pytest.approx((3 - lam) * fc / 3, rel=1e-14)
    assert (material.nu, material.rho) == (0.2, rho)
    calibrated = concrete_material(fc, rho, Mapping(lam=0.5, strength_factor=2.0,
                                                    modulus_factor=0.5))
    assert calibrated.tau == pytest.approx(2.5 * 2 * fc / 3, rel=1e-14)
    assert calibrated.E == pytest.approx(0.5 * material.E, rel=1e-14)
    with pytest.raises(CavexInputError, match="parameter 'lam' must be a number in"):
        Mapping(lam=3.5)
    # the inertial coefficient B = sigma_r per rho V^2 (docs/validation.md, Results)
    from cavex.analytic.cavity import quasi_static_coefficients

    for lam, b in ((0.0, 1.5), (0.6, 4.58)):
        m = concrete_material(fc, rho, Mapping(lam=lam))
        assert quasi_static_coefficients([m], [], 0.01345)[1] / rho == pytest.approx(b, abs=5e-3)
    shot = read_shots(SHOTS).shots[0]
    p = shot_projectile(shot)
    assert (p.r, p.R, p.m, p.V0) == (0.01345, 0.0538, 0.904, 800.0)
    assert p.l == pytest.approx(p.ogive_length, rel=1e-14)  # tangent ogive: r sqrt(4 crh - 1)
    assert p.l == pytest.approx(0.01345 * math.sqrt(7.0), rel=1e-14)


# --- shot files -------------------------------------------------------------------------------

def test_shot_file_reading_keeps_comments_and_extra_columns():
    data = read_shots(SHOTS)
    assert len(data.shots) == 17 and data.shots[0].id == "F94-39"
    assert any("Forrestal, Altman, Cargile, Hanchak (1994)" in c for c in data.comments)
    text = ("# a comment\n\nid,extra,mass_kg,diameter_m,crh,V0_m_s,fc_Pa,rho_kg_m3,depth_m,"
            "length_m\n" "X,hello,1,0.03,3,500,4e7,2400,0.5,\n")
    (shot,) = parse_shots(text).shots
    assert shot.extra == {"extra": "hello"} and shot.length is None and shot.line == 4
    assert shot == Shot("X", 1.0, 0.03, None, 3.0, 500.0, 4e7, 2400.0, 0.5)


BAD_FILES = [  # the text, the message after "'<path>': "
    (f"{COLUMNS}\n{GOOD_ROW}\nB2,0.9,0.0269,,2.0,fast,3.5e7,2370,0.2\n",
     "line 3 (shot 'B2'), column V0_m_s must be a number in [1, 10000] "
     "(rigid-projectile penetration) (got 'fast')"),
    (f"{COLUMNS}\nB2,0.9,0.0269,,2.0,2e4,3.5e7,2370,0.2\n",
     "line 2 (shot 'B2'), column V0_m_s must be a number in [1, 10000] "
     "(rigid-projectile penetration) (got '2e4')"),
    (f"# c\n{COLUMNS}\nB2,-0.9,0.0269,,2.0,300,3.5e7,2370,0.2\n",
     "line 3 (shot 'B2'), column mass_kg must be a number in [1e-06, 1e+06] (got '-0.9')"),
    (f"{COLUMNS}\nB2,0.9,0.0269,,2.0,300,35.2,2370,0.2\n",
     "line 2 (shot 'B2'), column fc_Pa must be a compressive strength in Pa in [1e+06, 1e+09] "
     "(is it in MPa?) (got '35.2')"),
    (f"{COLUMNS}\nB2,0.9,0.0269,,2.0,300,3.5e7,2.37,0.2\n",
     "line 2 (shot 'B2'), column rho_kg_m3 must be a concrete density in kg/m^3 in [1000, 4000] "
     "(is it in g/cm^3?) (got '2.37')"),
    (f"{COLUMNS}\nB2,0.9,0.0269,,0.2,300,3.5e7,2370,0.2\n",
     "line 2 (shot 'B2'), column crh must be a number in [0.5, 1000] (ogive radius R = crh d "
     ">= d/2) (got '0.2')"),
    (f"{COLUMNS}\nB2,0.9,0.0269,,2,300,3.5e7,2370,nan\n",
     "line 2 (shot 'B2'), column depth_m must be a number in [0.0001, 1000] m (got 'nan')"),
    (f"{COLUMNS}\n{GOOD_ROW}\n{GOOD_ROW}\n",
     "line 3, column id must be unique (got 'A1', as on line 2)"),
    (f"{COLUMNS}\nB2,0.9,0.0269,2.0,300,3.5e7,2370,0.2\n",
     "line 2 must have 9 cells, as the header (got 8)"),
    (f"{COLUMNS.replace(',fc_Pa', '')}\nB2,0.9,0.0269,,2,300,2370,0.2\n",
     "line 1 (header) has no column fc_Pa (required: id, mass_kg, diameter_m, crh, V0_m_s, "
     "fc_Pa, rho_kg_m3, depth_m)"),
    (f"{COLUMNS}\n,0.9,0.0269,,2,300,3.5e7,2370,0.2\n",
     "line 2, column id must be a non-empty shot name (got '')"),
    (f"# only comments\n{COLUMNS}\n", "has a header but no shots"),
    ("# only comments\n", "has no header row (and no shots)"),
]


@pytest.mark.parametrize("text, message", BAD_FILES)
def test_bad_shot_files_are_refused_naming_row_and_column(capsys, tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(CavexInputError) as error:
        read_shots(path)
    assert str(error.value) == f"'{path}': {message}"
    out_dir, cal = tmp_path / "out", tmp_path / "cal" / "c.toml"
    for argv in (["validate", "--shots", str(path), "--out", str(out_dir)],
                 ["calibrate", "--shots", str(path), "--out", str(cal)]):
        code, out, err = run(capsys, *argv)
        assert (code, out, err) == (2, "", f"cavex: error: '{path}': {message}\n")
    assert not out_dir.exists() and not cal.parent.exists()


def test_shot_file_with_a_byte_order_mark_and_crlf_reads_as_without(tmp_path):
    """A UTF-8 byte-order mark (a spreadsheet's "CSV UTF-8") and CRLF line ends are accepted."""
    text = f"# shots\n{COLUMNS}\n{GOOD_ROW}\n"
    plain, marked = tmp_path / "plain.csv", tmp_path / "marked.csv"
    plain.write_text(text)
    marked.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    assert read_shots(marked).shots == read_shots(plain).shots
    assert read_shots(marked).columns == tuple(COLUMNS.split(","))


def test_bad_calibration_files_are_refused(capsys, tmp_path):
    good = tmp_path / "good.toml"
    assert run(capsys, "calibrate", "--shots", SHOTS, "--out", str(good), "--ids", "F94-52",
               "--params", "strength_factor")[0] == 0
    text = good.read_text()
    cases = [(text.replace("lam = ", "lamb = ", 1),
              "calibration.lamb is not a known key (accepted: evaluations, lam, "),
             (text.replace('model = "derived-dynamic"', 'model = "quick"'),
              "calibration.model must be 'derived-quasi-static' or 'derived-dynamic' or "
              "'paper' or 'table' (got 'quick')"),
             # the labels before issue 18, refused with the label that replaced them
             (text.replace('model = "derived-dynamic"', 'model = "fe-table"'),
              "calibration.model must be 'table' (the label 'fe-table' was replaced)"),
             (text.replace('model = "derived-dynamic"', 'model = "derived dynamic"'),
              "calibration.model must be 'derived-dynamic' (the label 'derived dynamic' was "
              "replaced)"),
             (text.replace('params = ["strength_factor"]', 'params = ["tau"]'),
              "calibration.params must be names from lam, strength_factor, modulus_factor "
              "(got 'tau')"),
             (text.replace("strength_factor = ", "strength_factor = -", 1),
              "calibration.strength_factor must be a number in [0.05, 20] (got -"),
             (text.replace("[calibration]", "[calibrations]"),
              "calibrations is not a known key (accepted: calibration, layers, projectile)"),
             ("[projectile]" + text.split("\n[projectile]")[1],
              "calibration is missing (a calibration file is written by `cavex calibrate`)"),
             ("[calibration\n", "line 1, column 13 is not valid TOML (Expected ']' at the end "
              "of a table declaration)")]
    for i, (bad, message) in enumerate(cases):
        path = tmp_path / f"bad{i}.toml"
        path.write_text(bad)
        out_dir = tmp_path / f"out{i}"
        code, out, err = run(capsys, "validate", "--shots", SHOTS, "--calibration", str(path),
                             "--out", str(out_dir))
        assert (code, out) == (2, "") and err.count("\n") == 1
        assert err.startswith(f"cavex: error: '{path}': {message}"), err
        assert not out_dir.exists()
    for argv, message in ((["--params", "lam", "lam"], "names without repeats"),
                          (["--params", "tau"], "parameter 'params' must be names from"),
                          (["--resistance", "fem"], "option --resistance must be one of "
                           "derived, paper, table (got 'fem')"),
                          (["--ids", "F94-1"], "shot id(s) 'F94-1' not in shots file")):
        out = tmp_path / "never.toml"
        code, _, err = run(capsys, "calibrate", "--shots", SHOTS, "--out", str(out), *argv)
        assert code == 2 and message in err and not out.exists()


# --- predictions ------------------------------------------------------------------------------

def test_crater_stop_branch_is_continuous_with_the_integrator():
    shot = read_shots(SHOTS).by_id(["F94-52"])[0]
    target, projectile = shot_target(shot), shot_projectile(shot)
    resistance = ClosedFormResistance(target, projectile)
    lc = crater_depth(projectile)
    v_star = math.sqrt(lc * resistance.crater_force(0.0) / projectile.m)
    from dataclasses import replace

    above = penetration_depth(target, replace(projectile, V0=v_star * (1 + 1e-7)), resistance)
    below = penetration_depth(target, replace(projectile, V0=v_star * (1 - 1e-7)), resistance)
    assert above == pytest.approx(lc, rel=1e-6) and below == pytest.approx(lc, rel=1e-6)
    assert below <= lc <= above
    slow = penetration_depth(target, replace(projectile, V0=0.5 * v_star), resistance)
    assert slow == pytest.approx(0.5 * lc, rel=1e-12)  # X^2 = m V0^2 L_c / F(0)
    fast = replace(projectile, V0=1.5 * v_star)
    assert penetration_depth(target, fast, resistance) == float(
        penetrate(target, fast, resistance).depth[-1])


def test_table_grid_reproduces_the_closed_form_it_tabulates():
    """The FE table's grid (50 m/s in V, PCHIP in V^2) filled with the dynamic closed form
    gives the closed form's depth: measured 2.5e-5 (800 m/s), asserted 1e-4."""
    shots = read_shots(SHOTS).shots
    velocities = table_velocities(shots)
    assert velocities[0] == 0.0 and velocities[-1] >= 800.0 * 0.6506
    for shot in (shots[0], shots[13]):  # 800 and 277 m/s
        target, projectile = shot_target(shot), shot_projectile(shot)
        table = analytic_table(target, projectile, velocities, TABLE_DEPTHS, boundary="dynamic")
        tabulated = penetration_depth(target, projectile,
                                      TabulatedResistance(table, target, projectile))
        closed = closed_form_depth(shot, "derived", boundary="dynamic")
        assert tabulated == pytest.approx(closed, rel=1e-4)


def test_ratio_statistics():
    stats = ratio_statistics([0.5, 2.0, None, 1.0])
    assert stats["n"] == 3
    assert stats["mean_ratio"] == pytest.approx(3.5 / 3, rel=DIGITS_6)
    assert stats["std_ratio"] == pytest.approx(np.std([0.5, 2.0, 1.0], ddof=1), rel=DIGITS_6)
    assert stats["mean_abs_log_ratio"] == pytest.approx(2 * math.log(2) / 3, rel=DIGITS_6)
    assert ratio_statistics([None]) == {"n": 0, "mean_ratio": None, "std_ratio": None,
                                        "mean_abs_log_ratio": None}


# --- calibration ------------------------------------------------------------------------------

def synthetic_file(path, mapping, resistance="derived", boundary="quasi-static", every=1):
    """The committed shots' inputs (every ``every``-th) with depths predicted by cavex's own
    model."""
    data = read_shots(SHOTS)
    with open(path, "w", newline="") as handle:
        handle.write("# synthetic: depths from cavex's derived quasi-static model\n")
        writer = csv.writer(handle)
        writer.writerow(COLUMNS.split(","))
        for s in data.shots[::every]:
            writer.writerow([s.id, s.mass, s.diameter, s.length, s.crh, s.V0, s.fc, s.rho,
                             repr(closed_form_depth(s, resistance, boundary=boundary,
                                                    mapping=mapping))])


def test_synthetic_shots_calibrate_back_to_their_parameters(capsys, tmp_path):
    """Depths made by a model under known parameters are fitted back to them. Every third
    shot of the file (6 of 17; f_c 32-91 MPa, V0 561-800 m/s): shots made without noise by
    the model being fitted are fitted exactly by any set that determines the parameters, so
    the 11 others (each a dozen flights per Jacobian) would add time, not a check."""
    truth = Mapping(lam=0.45, strength_factor=0.7)
    shots_path = tmp_path / "synthetic.csv"
    synthetic_file(shots_path, truth, every=3)
    cal = tmp_path / "cal.toml"
    code, out, err = run(capsys, "calibrate", "--shots", str(shots_path), "--out", str(cal),
                         "--resistance", "derived", "--boundary", "quasi-static")
    assert code == 0 and err.startswith("cavex calibrate: warning: every shot of the file")
    fitted = read_calibration(cal)
    assert fitted.params == ("lam", "strength_factor")
    assert fitted.mapping.lam == pytest.approx(0.45, rel=1e-5)
    assert fitted.mapping.strength_factor == pytest.approx(0.7, rel=1e-5)
    assert dict(fitted.statistics)["mean_abs_log_ratio"] < 1e-5
    # three parameters, another model, from the Python API
    truth3 = Mapping(lam=0.8, strength_factor=0.6, modulus_factor=1.5)
    shots = read_shots(SHOTS).shots[::3]
    synthetic = [Shot(s.id, s.mass, s.diameter, s.length, s.crh, s.V0, s.fc, s.rho,
                      closed_form_depth(s, "paper", mapping=truth3)) for s in shots]
    got = fit(synthetic, "paper", ("lam", "strength_factor", "modulus_factor")).mapping
    assert (got.lam, got.strength_factor, got.modulus_factor) == pytest.approx(
        (0.8, 0.6, 1.5), rel=1e-5)


def test_calibration_file_runs_in_penetrate_and_validate(capsys, tmp_path):
    """The calibration TOML is a configuration: `cavex penetrate --config CAL.toml` gives the
    depth `cavex validate --calibration CAL.toml` predicts for the reference shot."""
    ids = ["F94-52", "F94-50"]
    small = tmp_path / "shots.csv"
    lines = read_shots_text_lines(ids)
    small.write_text("\n".join(lines) + "\n")
    cal = tmp_path / "cal.toml"
    assert run(capsys, "calibrate", "--shots", str(small), "--out", str(cal), "--ids",
               "F94-52", "--params", "strength_factor", "--resistance", "derived", "--boundary",
               "quasi-static")[0] == 0
    data = tomllib.loads(cal.read_text())
    assert data["calibration"]["shots"] == ["F94-52"]
    assert abs(math.log(data["calibration"]["strength_factor"])) > 0.1  # it moved
    assert data["calibration"]["reference_shot"] == "F94-52"
    code, out, err = run(capsys, "penetrate", "--config", str(cal), "--boundary", "quasi-static",
                         "--json", "--no-figures", "--out", str(tmp_path / "pen"))
    assert (code, err) == (0, "")
    final = json.loads(out)["phases"][-1]["end_depth_m"]
    out_dir = tmp_path / "val"
    code, out, err = run(capsys, "validate", "--shots", str(small), "--calibration", str(cal),
                         "--json", "--out", str(out_dir))
    assert code == 0 and err.startswith("cavex: validate 2 shots x ") and err.count("\n") == 1
    result = json.loads(out)
    rows = {row["id"]: row for row in result["shots"]}
    assert data["calibration"]["model"] == "derived-quasi-static"
    assert rows["F94-52"]["predicted_m"]["derived-quasi-static calibrated"] == pytest.approx(
        final, rel=DIGITS_6)
    # the JSON of the issue, and the statistics recomputed from it
    assert set(result["summary"]) == {"derived-quasi-static", "derived-dynamic", "paper",
                                      "table", "concrete", "li-chen-2003", "li-chen-concrete",
                                      "forrestal-1994", "derived-quasi-static calibrated"}
    for model, stats in result["summary"].items():
        ratios = [row["predicted_m"][model] / row["measured_m"] for row in result["shots"]]
        assert stats["n"] == 2
        assert stats["mean_ratio"] == pytest.approx(np.mean(ratios), rel=DIGITS_6)
        assert stats["std_ratio"] == pytest.approx(np.std(ratios, ddof=1), rel=DIGITS_6)
        assert stats["mean_abs_log_ratio"] == pytest.approx(np.mean(np.abs(np.log(ratios))),
                                                            rel=DIGITS_6)
    assert result["held_out"] == ["F94-50"]
    assert result["held_out_summary"]["paper"]["n"] == 1
    # the calibrated model fits its one shot (one parameter, one shot: exactly)
    assert rows["F94-52"]["ratio"]["derived-quasi-static calibrated"] == pytest.approx(1.0,
                                                                                      abs=1e-5)
    empirical_depth = empirical.shot_depth(read_shots(small).by_id(["F94-50"])[0])
    assert rows["F94-50"]["predicted_m"]["forrestal-1994"] == pytest.approx(empirical_depth,
                                                                          rel=DIGITS_6)
    # files; one FE table per distinct target (two here), reused by a rerun
    names = {p.name for p in out_dir.iterdir()}
    assert {"validation.json", "predictions.csv", "report.md", "predicted_vs_measured.png",
            "ratio_vs_velocity.png", "tables"} <= names
    assert len(list((out_dir / "tables").glob("table_*.nc"))) == 2
    for png in ("predicted_vs_measured.png", "ratio_vs_velocity.png"):
        assert (out_dir / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    first = (out_dir / "validation.json").read_text()
    # (the rerun draws no figures: validation.json, compared, does not depend on them)
    code, out, err = run(capsys, "validate", "--shots", str(small), "--calibration", str(cal),
                         "--no-figures", "--out", str(out_dir))
    assert code == 0 and "FE tables built 0, reused 2" in out
    assert (out_dir / "validation.json").read_text() == first


@pytest.fixture(scope="module")
def forrestal_concrete_depths():
    """``{shot id: depth}`` of the concrete model (its option's constants) for :data:`SHOTS`,
    computed in this process: their 17 cavity tables (one per concrete, about 1 s each) are
    then in :func:`~cavex.analytic.penetration.concrete_table.material_table`'s cache, where
    the validate runs of this module find them (in this process, or in the workers it forks,
    which inherit it), so this module computes them once."""
    from cavex.analytic.models import get
    from cavex.analytic.penetration.concrete_table import model_depth

    return {shot.id: model_depth(shot, get("concrete").constants(shot))
            for shot in read_shots(SHOTS).shots}


def test_validate_models_runs_only_the_named_models(capsys, tmp_path, forrestal_concrete_depths):
    """``--models concrete li-chen-concrete forrestal-1994``: those three columns and nothing
    else, in JSON, CSV and report; the concrete model's depths are
    :func:`model_depth`'s with its option's constants (the recommended model), those of
    :mod:`cavex.analytic.models.li_chen_concrete` Li and Chen's up to 100 MPa, above the concrete
    model's; the recommended model and its sentence are there.

    The run is in this process (``--workers 1``), where the expected depths
    (:func:`forrestal_concrete_depths`) left the cavity tables cached; the pool of workers is
    test_validate_reports_by_regime's. No figures (``--no-figures``):
    test_calibration_file_runs_in_penetrate_and_validate and test_validate_reports_by_regime
    check them."""
    from cavex.analytic.empirical import li_chen_depth
    from cavex.analytic.models.li_chen_concrete import SPLIT_STRENGTH
    from cavex.verification.report.validation_markdown import recommendation

    out_dir = tmp_path / "val"
    code, out, err = run(capsys, "validate", "--shots", SHOTS, "--models", "concrete",
                         "li-chen-concrete", "forrestal-1994", "--json", "--workers", "1",
                         "--no-figures", "--out", str(out_dir))
    assert code == 0 and err.startswith("cavex: validate 17 shots x 3 models = 51 predictions")
    result = json.loads(out)
    assert result["models"] == ["concrete", "li-chen-concrete", "forrestal-1994"]
    assert result["recommended_model"] == "concrete"
    assert json.loads((out_dir / "validation.json").read_text()) == result
    assert set(result["summary"]) == {"concrete", "li-chen-concrete", "forrestal-1994"}
    assert result["failures"] == {}
    shots = read_shots(SHOTS).shots
    for row, shot in zip(result["shots"], shots, strict=True):
        assert set(row["predicted_m"]) == {"concrete", "li-chen-concrete", "forrestal-1994"}
        split = (li_chen_depth(shot) if shot.fc <= SPLIT_STRENGTH
                 else row["predicted_m"]["concrete"])  # F94-41 and F94-46 are above
        assert row["predicted_m"]["li-chen-concrete"] == pytest.approx(split, rel=DIGITS_6)
        assert row["predicted_m"]["concrete"] == pytest.approx(
            forrestal_concrete_depths[shot.id], rel=DIGITS_6)
        assert row["predicted_m"]["forrestal-1994"] == pytest.approx(
            empirical.shot_depth(shot), rel=DIGITS_6)
    header = (out_dir / "predictions.csv").read_text().splitlines()[0].split(",")
    assert header[5:] == ["flag", "concrete_m", "li_chen_concrete_m", "forrestal_1994_m",
                          "concrete_ratio", "li_chen_concrete_ratio", "forrestal_1994_ratio"]
    report = (out_dir / "report.md").read_text()
    sentence = recommendation("concrete", result["summary"])
    assert sentence.startswith("Recommended model: `concrete`") and sentence in report
    assert "--models concrete li-chen-concrete forrestal-1994" in report
    assert "| derived-dynamic |" not in report and "| table |" not in report


def test_validate_reports_by_regime(capsys, tmp_path, forrestal_concrete_depths):
    """Every regime's statistics recomputed here from the per-shot JSON (the regime of a shot
    from its f_c, V0 and flag written beside it), Li and Chen's column equal to
    :func:`li_chen_depth`, the flag equal to :func:`rigid_flag`,
    the regime table in the report and both regime figures written. (The cavity tables:
    :func:`forrestal_concrete_depths`'s, inherited by the run's forked workers.)"""
    from cavex.analytic.empirical import li_chen_depth
    from cavex.analytic.penetration.concrete_table import TableResistance
    from cavex.verification.validation.regimes import rigid_flag

    out_dir = tmp_path / "val"
    code, out, err = run(capsys, "validate", "--shots", SHOTS, "--models", "concrete",
                         "li-chen-2003", "--json", "--out", str(out_dir))
    assert code == 0
    result = json.loads(out)
    shots = read_shots(SHOTS).shots
    for row, shot in zip(result["shots"], shots, strict=True):
        assert row["predicted_m"]["li-chen-2003"] == pytest.approx(
            li_chen_depth(shot), rel=DIGITS_6)
        assert row["flag"] == rigid_flag(
            shot, TableResistance(shot))
    members = {"all": lambda r: True,
               "normal_strength": lambda r: r["fc_Pa"] <= 100e6 and r["V0_m_s"] <= 1000.0,
               "fast": lambda r: r["V0_m_s"] > 1000.0,
               "high_strength": lambda r: r["fc_Pa"] > 100e6,
               "not_flagged": lambda r: r["flag"] == ""}
    expected = {name: [r for r in result["shots"] if member(r)]
                for name, member in members.items()}
    assert set(result["regimes"]) == {name for name, rows in expected.items() if rows}
    for name, stats in result["regimes"].items():
        for model in ("concrete", "li-chen-2003"):
            logs = np.log([r["predicted_m"][model] / r["measured_m"] for r in expected[name]])
            assert stats[model]["n"] == len(logs)
            assert stats[model]["mean_abs_log_ratio"] == pytest.approx(np.abs(logs).mean(),
                                                                       rel=DIGITS_6)
            assert stats[model]["mean_log_ratio"] == pytest.approx(logs.mean(), rel=DIGITS_6)
    report = (out_dir / "report.md").read_text()
    assert "## By regime" in report
    regime_table = report.split("## By regime")[1]
    line = next(x for x in regime_table.splitlines() if x.startswith("| li-chen-2003 | "))
    stats = result["regimes"]["all"]["li-chen-2003"]
    assert f"{stats['mean_abs_log_ratio']:.3f} / {stats['mean_log_ratio']:+.3f}" in line
    for png in ("by_regime.png", "residuals.png"):
        assert (out_dir / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_validate_refuses_an_unknown_model_in_one_line(capsys, tmp_path):
    out_dir = tmp_path / "val"
    code, out, err = run(capsys, "validate", "--shots", SHOTS, "--models", "concrete", "li-chen",
                         "--out", str(out_dir))
    assert (code, out) == (2, "") and err.count("\n") == 1
    assert "'models'" in err and "'li-chen'" in err
    for label in ("derived-quasi-static", "derived-dynamic", "paper", "table", "concrete",
                  "li-chen-2003", "forrestal-1994"):
        assert f"'{label}'" in err
    assert not out_dir.exists()


def read_shots_text_lines(ids):
    """The committed file's comment lines, header and the rows of ``ids``."""
    lines = open(SHOTS, encoding="utf-8").read().splitlines()
    return [line for line in lines if line.startswith("#") or line.startswith("id,")
            or line.split(",")[0] in ids]


# --- the committed report ---------------------------------------------------------------------

def test_committed_validation_report_is_consistent():
    """results/validation/: every statistic equals the one recomputed from the per-shot depths
    written beside it (6 digits), the held-out shots are those in no calibration's fit, the
    calibration files hold the parameters the report used, and the report's verdict line is
    the one the numbers give."""
    from pathlib import Path

    from cavex.verification.report.validation_markdown import verdict

    folder = Path("results/validation")
    result = json.loads((folder / "validation.json").read_text())
    data = read_shots(SHOTS)
    assert [row["id"] for row in result["shots"]] == [s.id for s in data.shots]
    fitted = set()
    for c in result["calibrations"]:
        stored = read_calibration(c["file"])
        assert stored.mapping.as_dict() == c["mapping"] and list(stored.shots) == c["shots"]
        fitted |= set(c["shots"])
    assert result["held_out"] == [s.id for s in data.shots if s.id not in fitted]
    for name, rows in (("summary", result["shots"]), ("held_out_summary",
                       [r for r in result["shots"] if r["id"] in result["held_out"]])):
        for model, stats in result[name].items():
            ratios = [r["predicted_m"][model] / r["measured_m"] for r in rows
                      if r["predicted_m"][model] is not None]
            assert stats["n"] == len(ratios)
            assert stats["mean_ratio"] == pytest.approx(np.mean(ratios), rel=DIGITS_6)
            assert stats["std_ratio"] == pytest.approx(np.std(ratios, ddof=1), rel=DIGITS_6)
            assert stats["mean_abs_log_ratio"] == pytest.approx(
                np.mean(np.abs(np.log(ratios))), rel=DIGITS_6)
    for row, shot in zip(result["shots"], data.shots, strict=True):
        assert row["predicted_m"]["forrestal-1994"] == pytest.approx(
            empirical.shot_depth(shot), rel=DIGITS_6)
    sentence = verdict(result["held_out_summary"], result["calibrations"])
    assert sentence in (folder / "report.md").read_text()


def test_committed_development_validation_is_consistent():
    """results/validation/compilation_dev/ (the development compilation): every regime's
    statistics equal the ones recomputed from the per-shot depths and flags written beside
    them, and the regime table of docs/validation.md is the committed one."""
    from pathlib import Path

    from cavex.verification.validation.regimes import REGIMES

    folder = Path("results/validation/compilation_dev")
    result = json.loads((folder / "validation.json").read_text())
    assert result["shots_file"]["n"] == 286 and result["recommended_model"] == "concrete"
    for name, models in result["regimes"].items():
        rows = [r for r in result["shots"] if REGIMES[name](r["fc_Pa"], r["V0_m_s"], r["flag"])]
        for model, stats in models.items():
            logs = np.log([r["predicted_m"][model] / r["measured_m"] for r in rows
                           if r["predicted_m"][model] is not None])
            assert stats["n"] == len(logs)
            assert stats["mean_abs_log_ratio"] == pytest.approx(np.abs(logs).mean(),
                                                                rel=DIGITS_6)
            assert stats["mean_log_ratio"] == pytest.approx(logs.mean(), rel=DIGITS_6)
    docs = Path("docs/validation.md").read_text()
    for model in ("concrete", "li-chen-2003", "li-chen-concrete", "forrestal-1994"):
        cells = [f"{s['mean_abs_log_ratio']:.3f} / {s['mean_log_ratio']:+.3f}"
                 for s in (result["regimes"][name][model] for name in REGIMES)]
        assert f"| {model} | " + " | ".join(cells) + " |" in docs


def test_a_shot_id_of_any_characters_is_one_markdown_table_cell():
    """report.md's tables stay tables for ids with '|', line breaks, tabs or emoji."""
    from cavex.verification.report.validation_markdown import table_cell

    for shot_id, cell in (("A|1", "A\\|1"), ("two\nlines", "two lines"), ("t\tab", "t ab"),
                          ("\U0001F3AF", "\U0001F3AF"), ("\x07bell", " bell")):
        assert table_cell(shot_id) == cell
        row = f"| {table_cell(shot_id)} | 1 |"
        assert row.replace("\\|", "").count("|") == 3 and "\n" not in row


def test_committed_cross_validation_is_consistent():
    """results/validation/compilation_dev/ (``--cross-validate``): recomputed here from the
    committed depths of every option and the shot file's references and columns, each fold's
    choice (fewest missing depths, then the smallest mean |ln ratio| on the other shots, the
    first on a tie), its statistics, each shot's cross-validated depth and the regime table; a
    model with nothing chosen keeps its plain depths; and the option the registry gives the
    concrete model is the one it chooses on all the development shots."""
    import csv
    from pathlib import Path

    from cavex.analytic.models import get
    from cavex.verification.validation.regimes import REGIMES

    result = json.loads(Path("results/validation/compilation_dev/validation.json").read_text())
    with open("examples/shots_compilation_dev.csv", newline="") as handle:
        columns = {r["id"]: r for r in csv.DictReader(
            line for line in handle if not line.startswith("#"))}
    rows = result["shots"]
    cv = result["cross_validation"]
    measured = np.array([r["measured_m"] for r in rows])
    info = [columns[r["id"]] for r in rows]
    members = {f"reference {ref}": [i for i, c in enumerate(info) if c["source"] == ref]
               for ref in sorted({c["source"] for c in info})}
    members["calibre <= 13 mm"] = [i for i, c in enumerate(info)
                                   if float(c["diameter_m"]) <= 0.013]
    members["projectile yield < 1 GPa"] = [i for i, c in enumerate(info)
                                           if float(c["proj_yield_MPa"] or "inf") < 1000.0]
    members["V0 > 1000 m/s"] = [i for i, c in enumerate(info) if float(c["V0_m_s"]) > 1000.0]
    folds = {fold["name"]: fold for fold in cv["folds"]}
    assert list(folds) == list(members) and len(members) == 21 + 3
    stored = {c: dict(zip(v["options"], v["depths_m"], strict=True))
              for c, v in cv["option_depths_m"].items()}

    def score(depths, where):
        logs = [abs(math.log(depths[i] / measured[i])) for i in where if depths[i] is not None]
        return len(where) - len(logs), np.mean(logs)

    for column in result["models"]:
        options = stored.get(column, {None: [r["predicted_m"][column] for r in rows]})
        for name, held in members.items():
            rest = sorted(set(range(len(rows))) - set(held))
            ranked = sorted((score(d, rest), k, o) for k, (o, d) in enumerate(options.items()))
            chosen = ranked[0][2]
            stats = folds[name]["models"][column]
            assert stats["choice"] == chosen
            logs = np.log([options[chosen][i] / measured[i] for i in held
                           if options[chosen][i] is not None])
            assert stats["n"] == len(logs)
            assert stats["mean_abs_log_ratio"] == pytest.approx(np.abs(logs).mean(),
                                                                rel=DIGITS_6)
            assert stats["mean_log_ratio"] == pytest.approx(logs.mean(), rel=DIGITS_6)
            if name.startswith("reference "):
                for i in held:
                    assert rows[i]["cross_validated_m"][column] == options[chosen][i]
        if column not in stored:
            assert cv["chosen_on_shots"][column] is None
            assert all(r["cross_validated_m"][column] == r["predicted_m"][column] for r in rows)
    for name, models in cv["regimes"].items():
        chosen = [r for r in rows if REGIMES[name](r["fc_Pa"], r["V0_m_s"], r["flag"])]
        for model, stats in models.items():
            logs = np.log([r["cross_validated_m"][model] / r["measured_m"] for r in chosen
                           if r["cross_validated_m"][model] is not None])
            assert stats["n"] == len(logs)
            assert stats["mean_abs_log_ratio"] == pytest.approx(np.abs(logs).mean(),
                                                                rel=DIGITS_6)
    concrete = get("concrete")
    assert cv["choice_on_all_shots"]["concrete"] == concrete.option
    assert [r["predicted_m"]["concrete"] for r in rows] == stored["concrete"][concrete.option]
