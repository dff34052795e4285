"""Every figure of every command that draws, for a normal and the degenerate cases (issue 21,
item 3): normal incidence, a 70 deg ricochet, a one-layer target, a shot that stops in the
crater; the validation figures with and without calibrations.

Each figure is written as a user gets it (the command's own writer) and checked: the PNG is not
blank; every axes that shows data has finite, increasing limits that hold every data point (no
curve cut off), its curves span a visible part of the axis range they are drawn on (no curve
squashed to a line by a far-off limit, no plot of round-off: a curve that varies by less than
1e-9 of its magnitude is not drawn, a note is), and a side view drawn to scale (equal axes:
what does not move stays a straight line on it) is no hairline.
"""

import json
from pathlib import Path

import matplotlib
import numpy as np
import pytest

from cavex.config import default_config_text, load_config
from cavex.verification.cli import main

matplotlib.use("Agg")
ROOT = Path(__file__).resolve().parents[1]
ONE_LAYER = default_config_text().split("[[layers]]")[0] + "[[layers]]" + \
    default_config_text().split("[[layers]]")[1].replace("thickness = 0.65\n", "")
CRATER_STOP = default_config_text().replace("V0 = 1000.0", "V0 = 30.0")


class Drawn:
    """The figures a command saved (through ``save_figure``), checked before they close."""

    def __init__(self):
        self.checked = {}

    def wrap(self, original):
        def save(fig, path, **kwargs):
            self.checked[Path(path).name] = check_axes(fig)
            return original(fig, path, **kwargs)
        return save


def data_lines(ax):
    """The data curves of ``ax``: lines in data coordinates with at least two finite points
    (axhline/axvline and legend keys excluded)."""
    lines = []
    for line in ax.get_lines():
        if line.get_transform() != ax.transData:
            continue
        x, y = (np.asarray(v, dtype=float) for v in line.get_data())
        keep = np.isfinite(x) & np.isfinite(y)
        if keep.sum() >= 1:
            lines.append((x[keep], y[keep]))
    return lines


def check_axes(fig):
    """The checks of the module docstring on every visible axes; returns how many showed data."""
    shown = 0
    for ax in fig.axes:
        lines = data_lines(ax)
        if not ax.get_visible() or not lines:
            continue
        shown += 1
        for limits, values, scale in ((ax.get_xlim(), [x for x, _ in lines], ax.get_xscale()),
                                      (ax.get_ylim(), [y for _, y in lines], ax.get_yscale())):
            lo, hi = sorted(limits)
            assert np.isfinite([lo, hi]).all() and hi > lo
            data = np.concatenate(values)
            assert data.min() >= lo - 1e-9 * (hi - lo) and data.max() <= hi + 1e-9 * (hi - lo), \
                ("a curve is cut off", ax.get_title(), limits)
            if scale == "linear" and ax.get_aspect() != 1.0:  # to scale: checked below
                for v in values:
                    span = np.ptp(v)
                    assert span == 0.0 or span > 1e-9 * np.abs(v).max(), \
                        ("a plot of round-off", ax.get_title())
                spans = [np.ptp(v) for v in values if np.ptp(v) > 0.0]
                if spans:
                    assert max(spans) >= 0.05 * (hi - lo), ("squashed", ax.get_title(), limits)
        if ax.get_aspect() == 1.0:  # to scale: the box is no hairline
            x0, x1 = ax.get_xlim()
            y0, y1 = ax.get_ylim()
            ratio = abs(y1 - y0) / abs(x1 - x0)
            assert 0.1 <= ratio <= 10.0, ("hairline side view", ratio)
    return shown


def not_blank(path):
    """The PNG has something drawn: not one colour, and some pixels far from white."""
    import matplotlib.image as mpimg

    image = mpimg.imread(path)[..., :3]
    assert image.std() > 0.02
    assert (image.mean(axis=-1) < 0.8).mean() > 0.002


@pytest.fixture
def drawn(monkeypatch):
    from cavex.verification.commands import penetrate, trajectory, validate
    from cavex.verification.output import files

    record = Drawn()
    for module in (penetrate, trajectory, validate, files):
        if hasattr(module, "save_figure"):
            monkeypatch.setattr(module, "save_figure", record.wrap(module.save_figure))
    return record


def _config(tmp_path, text):
    if text is None:
        return []
    path = tmp_path / "target.toml"
    path.write_text(text)
    load_config(path)  # a valid target
    return ["--config", str(path)]


@pytest.mark.parametrize(("case", "config"), [("runway", None), ("one layer", ONE_LAYER)])
def test_penetrate_figures(capsys, tmp_path, drawn, case, config):
    out = tmp_path / "p"
    assert main(["penetrate", "--out", str(out), *_config(tmp_path, config)]) == 0
    capsys.readouterr()
    assert set(drawn.checked) == {"velocity_time.png", "deceleration_depth.png"}
    assert all(n >= 1 for n in drawn.checked.values())
    for name in drawn.checked:
        not_blank(out / name)


def test_penetrate_draws_a_crater_stop(capsys, tmp_path, drawn):
    """A shot the crater stops (paper Eqs. 31-34 with ``K L_c = F(0)``, issue 22: once refused)
    has its one crater phase drawn like any other."""
    out = tmp_path / "p"
    assert main(["penetrate", "--out", str(out), *_config(tmp_path, CRATER_STOP)]) == 0
    assert "projectile stopped" in capsys.readouterr().out
    assert set(drawn.checked) == {"velocity_time.png", "deceleration_depth.png"}
    for name in drawn.checked:
        not_blank(out / name)


@pytest.mark.parametrize(("case", "argv", "config"), [
    ("normal incidence", [], None),
    ("70 deg ricochet", ["--obliquity", "70"], None),
    ("one layer, with attack", ["--attack", "3"], ONE_LAYER),
    ("stops in the crater", [], CRATER_STOP),
])
def test_trajectory_figures(capsys, tmp_path, drawn, case, argv, config):
    out = tmp_path / "t"
    assert main(["trajectory", *argv, "--out", str(out), "--no-progress",
                 *_config(tmp_path, config)]) == 0
    capsys.readouterr()
    assert {"path_side.png", "pitch_time.png", "overload.png"} <= set(drawn.checked)
    assert drawn.checked["path_side.png"] == 1 and drawn.checked["overload.png"] >= 2
    for name in [*drawn.checked, "path_3d.png"]:
        if (out / name).exists() or name != "path_3d.png":
            not_blank(out / name)


def test_a_normal_shot_draws_notes_not_round_off(tmp_path, drawn, capsys):
    """Normal incidence: pitch and lateral overload are round-off, so their axes hold a note
    and no curve (the check above would refuse the curve)."""
    assert main(["trajectory", "--out", str(tmp_path / "t"), "--no-progress"]) == 0
    capsys.readouterr()
    assert drawn.checked["pitch_time.png"] == 0  # a note only
    assert drawn.checked["overload.png"] == 2  # the axial row; the lateral row is a note


@pytest.mark.parametrize("calibrated", [True, False])
def test_validation_figures(tmp_path, drawn, calibrated):
    from cavex.verification.commands.validate import FIGURES, REGIME_FIGURES, write_figures
    from cavex.verification.validation.regimes import REGIMES

    result = json.loads((ROOT / "results" / "validation" / "validation.json").read_text())
    if not calibrated:
        result = {**result, "calibrations": [],
                  "models": [m for m in result["models"] if m.count(" ") == 0]}
    written = write_figures(result, tmp_path)
    panels = 1 + sum(m.count(" ") > 0 for m in result["models"])
    regimes = [name for name, member in REGIMES.items() if name != "all" and any(
        member(r["fc_Pa"], r["V0_m_s"], r.get("flag")) for r in result["shots"])]
    expected = {name: panels for name in FIGURES} | {REGIME_FIGURES[0]: len(regimes),
                                                     REGIME_FIGURES[1]: 2}
    assert sorted(Path(p).name for p in written) == sorted(expected)
    for path in written:
        assert drawn.checked[Path(path).name] == expected[Path(path).name]
        not_blank(path)
