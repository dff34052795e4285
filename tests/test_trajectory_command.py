"""``cavex trajectory`` end to end: the files and figures it writes hold the trajectory the API
computes (the study's analysis functions: tests/test_oblique_study.py)."""

import csv
import json

import matplotlib.image
import numpy as np
import pytest

from cavex.analytic.models import fly
from cavex.analytic.penetration.oblique import Strike, overload_peaks
from cavex.config import load_config
from cavex.verification.cli import main

# contact ramp 0.03 m/s, the largest accepted (the default is 0.01): these tests are about the
# files, not the contact
LAW = ["--resistance", "law", "--law-A", "2e8", "--law-B", "2500", "--contact-ramp", "0.03"]


@pytest.fixture(scope="module")
def command_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("trajectory")
    args = ["trajectory", "--velocity", "500", "--obliquity", "25", *LAW,
            "--compare-homogeneous", "--json", "--out", str(out)]
    return out, args


def test_files_figures_and_json_hold_the_api_trajectory(command_run, capsys):
    out, args = command_run
    assert main(args) == 0
    document = json.loads(capsys.readouterr().out)
    target, projectile = load_config()
    strike = Strike(500.0, obliquity=25.0)
    api = fly(target, projectile, strike, "law", law_A=2e8, law_B=2500.0,
            contact_ramp=0.03)
    single = fly(target.single(0), projectile, strike, "law", law_A=2e8, law_B=2500.0,
            contact_ramp=0.03)
    # the same code on the same data: the same numbers
    assert document["end"]["nose_tip_m"] == api.end["nose_tip_m"]
    assert document["end"]["pitch_deg"] == api.end["pitch_deg"]
    assert document["runs"]["first layer only"]["end"]["nose_tip_m"] == single.end["nose_tip_m"]
    assert {"state", "time_s", "nose_tip_m", "pitch_deg", "speed_m_s"} <= set(document["end"])
    assert document["phases"] and document["phases"][-1]["end_reason"] == "stopped"
    for name, result in (("target", api), ("first_layer_only", single)):
        with open(out / f"history_{name}.csv", newline="") as handle:
            rows = list(csv.DictReader(handle))
        assert len(rows) == result.history["t_s"].size
        for key in ("t_s", "tip_z_m", "pitch_deg", "axial_g"):
            column = np.array([float(r[key]) for r in rows])
            # 6 significant digits in the CSV (number_format.TRAJECTORY_DIGITS): half a unit
            np.testing.assert_allclose(column, result.history[key], rtol=5.0001e-6, atol=0.0)
    for picture in ("path_side.png", "pitch_time.png", "overload.png", "path_3d.png"):
        image = matplotlib.image.imread(out / picture)
        assert image.shape[0] > 200 and image.shape[1] > 200
        assert image[..., :3].std() > 0.01  # not blank
    summary = json.loads((out / "summary.json").read_text())
    assert summary["runs"]["runway"]["end"] == document["end"]


def test_no_figures_writes_the_same_numbers_without_pictures(command_run, tmp_path, capsys):
    _, args = command_run
    out = tmp_path / "plain"
    args = [*args[:-1], str(out), "--no-figures"]
    assert main(args) == 0
    document = json.loads(capsys.readouterr().out)
    assert sorted(p.name for p in out.iterdir()) == [
        "history_first_layer_only.csv", "history_target.csv", "summary.json"]
    assert sorted(document["outputs"]) == sorted(str(p) for p in out.iterdir())
    target, projectile = load_config()
    api = fly(target, projectile, Strike(500.0, obliquity=25.0), "law", law_A=2e8, law_B=2500.0,
              contact_ramp=0.03)
    assert document["end"] == api.end


def test_overload_peaks_are_the_prominent_maxima():
    z = np.linspace(0.0, 1.0, 1001)
    g = 1000.0 * np.exp(-((z - 0.3) / 0.05) ** 2) + 400.0 * np.exp(-((z - 0.7) / 0.05) ** 2)
    g += 5.0 * np.sin(200.0 * z)  # ripple: 0.5 % of the largest peak, not a peak
    peaks = overload_peaks({"axial_g": g, "tip_z_m": z})
    assert [round(p, 2) for p, _ in peaks] == [0.3, 0.7]
    # a peak counts by its rise above the dip before it: a smaller one before a larger one,
    # and one on a falling shoulder that rises 10 % above its dip (not 5 % of the largest)
    g = 400.0 * np.exp(-((z - 0.3) / 0.05) ** 2) + 1000.0 * np.exp(-((z - 0.7) / 0.05) ** 2)
    assert [round(p, 2) for p, _ in overload_peaks({"axial_g": g, "tip_z_m": z})] == [0.3, 0.7]
    g = np.interp(z, [0.0, 0.1, 0.5, 0.55, 1.0], [0.0, 1000.0, 300.0, 330.0, 0.0])
    assert [round(p, 2) for p, _ in overload_peaks({"axial_g": g, "tip_z_m": z})] == [0.1, 0.55]
    g = np.interp(z, [0.0, 0.1, 0.5, 0.55, 1.0], [0.0, 1000.0, 300.0, 310.0, 0.0])
    assert [round(p, 2) for p, _ in overload_peaks({"axial_g": g, "tip_z_m": z})] == [0.1]


def test_progress_is_called_once_per_step():
    """``fly(progress=...)`` is called after every integrator step (the command's bar)."""
    target, projectile = load_config()
    seen = []
    result = fly(target, projectile, Strike(500.0, obliquity=15.0), "law", law_A=2e8,
                 law_B=2500.0, contact_ramp=0.03, progress=lambda t, y: seen.append(t))
    steps = sum(s.t.size - 1 for s in result.solutions)
    assert len(seen) == steps
    assert np.array_equal(seen, np.concatenate([s.t[1:] for s in result.solutions]))
    assert seen[-1] == result.end["time_s"]  # the last step ends on the final event
