"""``cavex validate --cross-validate`` (docs/validation.md "Cross-validation"): the folds, the
choice made without each fold, the statistics, the JSON keys, the report and figure, and the
one-line refusals of bad input.

The synthetic cases are made so that the answer is known by hand: the depths of each option
are ``measured x e^k`` with integer or simple ``k``, so each mean ``|ln ratio|`` is a sum of
those ``k``; compared to 1e-12 (round-off of a few logarithms and means), and the command's
statistics, written with 6 significant digits, to half a unit of the 6th digit.
"""

import json
import math

import pytest

from cavex.verification.cli import main
from cavex.verification.validation.calibration import Calibration
from cavex.verification.validation.cross_validation import (
    FOLDS,
    check_folds,
    choose,
    cross_validation,
    fold_indices,
)
from cavex.verification.validation.shots import Shot

DIGITS_6 = 5e-6 * (1 + 1e-9)  # half a unit in the 6th significant digit, relative
E = math.e


def shot(i, source, diameter=0.03, V0=500.0, strength="", depth=1.0):
    return Shot(id=f"S{i}", mass=1.0, diameter=diameter, length=None, crh=2.0, V0=V0,
                fc=40e6, rho=2300.0, depth=depth,
                extra={"source": source, "proj_yield_MPa": strength})


#: references A, B, C of two shots each; C's shots are fast and small, one A shot soft
SHOTS = [shot(0, "A", strength="500"), shot(1, "A", strength="1500"), shot(2, "B"),
         shot(3, "B"), shot(4, "C", diameter=0.01, V0=1200.0), shot(5, "C", diameter=0.01,
                                                                     V0=1100.0)]


def rows_of(shots):
    return [{"id": s.id, "fc_Pa": s.fc, "V0_m_s": s.V0, "flag": None, "measured_m": s.depth}
            for s in shots]


def test_folds_of_a_synthetic_shot_set():
    """One fold per reference (a partition) and one per kind, with the shots of each."""
    folds = fold_indices(SHOTS, FOLDS)
    assert folds == {"reference A": ("reference", [0, 1]), "reference B": ("reference", [2, 3]),
                     "reference C": ("reference", [4, 5]),
                     "calibre <= 13 mm": ("calibre", [4, 5]),
                     "projectile yield < 1 GPa": ("yield", [0]),
                     "V0 > 1000 m/s": ("velocity", [4, 5])}
    assert check_folds(None, SHOTS) == FOLDS == check_folds([], SHOTS)
    assert check_folds(["velocity", "reference"], SHOTS) == ("velocity", "reference")


def test_the_choice_without_each_fold_is_the_one_worked_by_hand():
    """Option x is exact on A and B and e^-1.2 on C; option y is e^0.5 on A and B and exact on
    C. Without A (or B) y is better on the rest (0.25 against 0.6), without C x (0 against
    0.5): A and B are predicted by y (|ln| 0.5, bias +0.5), C by x (1.2, -1.2). A model with
    nothing chosen on shots keeps its plain depths."""
    x = [1.0, 1.0, 1.0, 1.0, E ** -1.2, E ** -1.2]
    y = [E ** 0.5] * 4 + [1.0, 1.0]
    plain = [2.0, 2.0, 0.5, 0.5, 1.0, 1.0]
    result = {"models": ["chooser", "fixed"], "shots": rows_of(SHOTS), "regimes": {}}
    cross_validation(result, SHOTS, {"chooser": {"x": x, "y": y}, "fixed": {None: plain}}, {},
                     FOLDS, refit=None)
    cv = result["cross_validation"]
    folds = {fold["name"]: fold for fold in cv["folds"]}
    choices = {name: fold["models"]["chooser"]["choice"] for name, fold in folds.items()}
    assert choices == {"reference A": "y", "reference B": "y", "reference C": "x",
                       "calibre <= 13 mm": "x", "projectile yield < 1 GPa": "y",
                       "V0 > 1000 m/s": "x"}
    assert [r["cross_validated_m"]["chooser"] for r in result["shots"]] == \
        [y[0], y[1], y[2], y[3], x[4], x[5]]
    every = cv["regimes"]["all"]["chooser"]
    assert every["n"] == 6
    assert every["mean_abs_log_ratio"] == pytest.approx((4 * 0.5 + 2 * 1.2) / 6, rel=DIGITS_6)
    assert every["mean_log_ratio"] == pytest.approx((4 * 0.5 - 2 * 1.2) / 6, rel=DIGITS_6)
    fold = folds["reference C"]["models"]["chooser"]
    assert (fold["n"], fold["mean_abs_log_ratio"], fold["mean_log_ratio"]) == (2, 1.2, -1.2)
    assert cv["choice_on_all_shots"] == {"chooser": "y"}  # 2/6 against 2.4/6
    fixed = cv["regimes"]["all"]["fixed"]
    assert fixed["mean_abs_log_ratio"] == pytest.approx(4 * math.log(2.0) / 6, rel=DIGITS_6)
    assert [r["cross_validated_m"]["fixed"] for r in result["shots"]] == plain
    assert cv["chosen_on_shots"]["fixed"] is None


def test_an_option_without_a_depth_loses_and_a_tie_goes_to_the_first():
    """Fewest missing depths first, then the mean |ln ratio|, then the option's order."""
    measured = [1.0, 1.0, 1.0]
    assert choose({"a": [None, 1.0, 1.0], "b": [E, E, E]}, measured, [0, 1, 2]) == "b"
    assert choose({"a": [None, 1.0, 1.0], "b": [E, E, E]}, measured, [1, 2]) == "a"
    assert choose({"a": [E, 1.0, 1.0], "b": [1.0, E, 1.0]}, measured, [0, 1, 2]) == "a"
    assert choose({"b": [1.0, E, 1.0], "a": [E, 1.0, 1.0]}, measured, [0, 1, 2]) == "b"


def test_a_calibration_is_refitted_only_without_a_fold_that_holds_its_fitted_shots():
    """Fitted on S0, S2, S4: leaving out A refits on S2, S4; a fold of none of them (the soft
    projectile's is S0: it holds one) keeps the calibration; every call is recorded."""
    calibration = Calibration("derived-dynamic", None, ("lam",), ("S0", "S2", "S4"))
    column = calibration.column
    calls = []

    def refit(c, train, held):
        calls.append(([s.id for s in train], [s.id for s in held]))
        return "refitted", [E ** 0.1] * len(held)

    result = {"models": [column], "shots": rows_of(SHOTS), "regimes": {}}
    plain = [1.0] * 6
    cross_validation(result, SHOTS, {column: {None: plain}}, {column: calibration},
                     ("reference", "velocity"), refit)
    assert calls == [(["S2", "S4"], ["S0", "S1"]), (["S0", "S4"], ["S2", "S3"]),
                     (["S0", "S2"], ["S4", "S5"]), (["S0", "S2"], ["S4", "S5"])]
    folds = result["cross_validation"]["folds"]
    assert all(f["models"][column]["choice"] == "refitted" for f in folds)
    assert result["cross_validation"]["regimes"]["all"][column]["mean_abs_log_ratio"] == \
        pytest.approx(0.1, rel=DIGITS_6)
    calls.clear()
    cross_validation(result, SHOTS, {column: {None: plain}},
                     {column: Calibration("derived-dynamic", None, ("lam",), ("S1", "S3"))},
                     ("velocity",), refit)
    assert calls == []
    assert folds is not result["cross_validation"]["folds"]
    fold = result["cross_validation"]["folds"][0]
    assert fold["name"] == "V0 > 1000 m/s" and fold["models"][column]["choice"] == "as calibrated"


def write_shots(path, sources=("A", "A", "B", "B"), yields=("", "", "", "")):
    lines = ["id,mass_kg,diameter_m,crh,V0_m_s,fc_Pa,rho_kg_m3,depth_m,source,proj_yield_MPa"]
    for i, (source, strength) in enumerate(zip(sources, yields, strict=True)):
        lines.append(f"X{i},0.9,0.0269,2,{400 + 100 * i},{35e6 + 5e6 * i},2300,"
                     f"{0.3 + 0.05 * i},{source},{strength}")
    path.write_text("\n".join(lines) + "\n")
    return path


def test_the_command_writes_the_cross_validation(capsys, tmp_path):
    """JSON keys, per-shot cross-validated depths, the report's section, the figure; Li and
    Chen and Forrestal choose nothing on shots, so their cross-validated statistics are their
    plain ones."""
    shots = write_shots(tmp_path / "s.csv", yields=("500", "", "", ""))
    out = tmp_path / "out"
    code = main(["validate", "--shots", str(shots), "--models", "li-chen-2003",
                 "forrestal-1994", "--cross-validate", "--json", "--out", str(out)])
    text = capsys.readouterr().out
    assert code == 0
    result = json.loads(text)
    cv = result["cross_validation"]
    assert set(cv) == {"families", "folds", "regimes", "chosen_on_shots", "choice_on_all_shots",
                       "option_depths_m"}
    assert cv["option_depths_m"] == {}  # nothing chosen on shots
    assert cv["families"] == ["reference", "yield"]  # no shot of 13 mm or above 1000 m/s
    assert [f["name"] for f in cv["folds"]] == ["reference A", "reference B",
                                                "projectile yield < 1 GPa"]
    for fold in cv["folds"]:
        assert set(fold) == {"name", "family", "n", "models", "regimes"}
        for stats in fold["models"].values():
            assert set(stats) == {"choice", "n", "mean_abs_log_ratio", "mean_log_ratio"}
    assert cv["chosen_on_shots"] == {"li-chen-2003": None, "forrestal-1994": None}
    assert cv["regimes"] == result["regimes"]
    for row in result["shots"]:
        assert row["cross_validated_m"] == row["predicted_m"]
    from test_json_keys import offending_keys

    assert offending_keys(result) == []
    report = (out / "report.md").read_text()
    assert "## Cross-validation" in report and "(cross_validation.png)" in report
    assert "nothing chosen on shots: predicted as it is" in report
    assert (out / "cross_validation.png").stat().st_size > 10_000
    assert "--cross-validate --out" in report


@pytest.mark.parametrize("argv, sources, message", [
    (["--cross-validate", "folds"], ("A", "A", "B", "B"),
     "parameter 'cross-validate' must be 'reference' or 'calibre' or 'yield' or 'velocity' "
     "(got 'folds')"),
    (["--cross-validate", "reference", "reference"], ("A", "A", "B", "B"),
     "must be fold names without repeats"),
    (["--models", "li-chen-2003", "li-chen-2003"], ("A", "A", "B", "B"),  # replaces the first
     "parameter 'models' must be labels without repeats"),
    (["--cross-validate", "reference"], ("A", "A", "A", "A"),
     "must be a family the file can fold ('reference': shots of at least two references"),
    (["--cross-validate", "reference"], ("A", "", "B", "B"),
     "reference needs every shot's reference in the shot file's column 'source' (shot 'X1'"),
    (["--cross-validate", "velocity"], ("A", "A", "B", "B"),
     "must be a kind of shot the file holds beside others ('velocity': V0 > 1000 m/s) (got "
     "'0 of 4"),
    (["--cross-validate"], ("A", "A", "A", "A"),
     "must be applicable to the shots"),
])
def test_bad_cross_validate_input_is_one_line(capsys, tmp_path, argv, sources, message):
    shots = write_shots(tmp_path / "s.csv", sources)
    out = tmp_path / "out"
    code = main(["validate", "--shots", str(shots), "--models", "li-chen-2003", *argv,
                 "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_yield_that_is_not_a_number_is_refused(capsys, tmp_path):
    shots = write_shots(tmp_path / "s.csv", yields=("hard", "", "", ""))
    code = main(["validate", "--shots", str(shots), "--models", "li-chen-2003",
                 "--cross-validate", "yield", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "proj_yield_MPa of shot 'X0'' must be a yield strength in MPa > 0" in err


def test_a_calibrated_column_is_refitted_without_each_reference(capsys, tmp_path):
    """A derived-quasi-static calibration of ``strength_factor`` on all four shots: leaving out
    reference A, its mapping is fitted again on B's two shots (the same fit as
    :func:`cavex.verification.validation.calibration.fit` there, to the 6 written digits), and
    A's shots are predicted with it."""
    from cavex.verification.validation.calibration import fit
    from cavex.verification.validation.predict import predict
    from cavex.verification.validation.shots import read_shots

    shots_path = write_shots(tmp_path / "s.csv")
    cal = tmp_path / "cal.toml"
    assert main(["calibrate", "--shots", str(shots_path), "--resistance", "derived",
                 "--boundary", "quasi-static", "--params", "strength_factor",
                 "--out", str(cal)]) == 0
    capsys.readouterr()
    code = main(["validate", "--shots", str(shots_path), "--models", "li-chen-2003",
                 "--calibration", str(cal), "--cross-validate", "reference", "--json",
                 "--out", str(tmp_path / "out")])
    result = json.loads(capsys.readouterr().out)
    assert code == 0
    column = "derived-quasi-static calibrated"
    shots = read_shots(str(shots_path)).shots
    refit = fit(shots[2:], "derived", ("strength_factor",), boundary="quasi-static")
    value = refit.mapping.strength_factor
    fold = result["cross_validation"]["folds"][0]["models"][column]
    assert fold["choice"] == f"refitted on 2 shots: strength_factor = {value:.6g}"
    for row, shot in zip(result["shots"][:2], shots[:2], strict=True):
        assert row["cross_validated_m"][column] == pytest.approx(
            predict(shot, "derived-quasi-static", refit.mapping), rel=DIGITS_6)
    assert result["cross_validation"]["chosen_on_shots"][column].startswith("a mapping fitted")
