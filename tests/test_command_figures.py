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
import subprocess
import sys
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
        self.limits_3d = {}
        self.words = {}  # per figure: every text drawn (labels, titles, notes, legends)
        self.axes = {}  # per figure: per axes {xlabel, lines (x data), shaded spans}
        self.legend_styles = {}  # per figure: its figure legend's (label, linestyle)

    def wrap(self, original):
        def save(fig, path, **kwargs):
            name = Path(path).name
            self.checked[name] = check_axes(fig)
            for ax in fig.axes:
                if ax.name == "3d":
                    self.limits_3d[name] = (ax.get_xlim(), ax.get_ylim(), ax.get_zlim())
            self.words[name] = figure_words(fig)
            self.axes[name] = [{"xlabel": ax.get_xlabel(),
                                "x": [np.asarray(x, dtype=float) for x, _ in data_lines(ax)],
                                "spans": sum(type(p).__name__ in ("Rectangle", "Polygon")
                                             for p in ax.patches)}
                               for ax in fig.axes if ax.name != "3d"]
            self.legend_styles[name] = [(t.get_text(), h.get_linestyle())
                                        for legend in fig.legends
                                        for t, h in zip(legend.get_texts(),
                                                        legend.legend_handles, strict=True)
                                        if hasattr(h, "get_linestyle")]
            return original(fig, path, **kwargs)
        return save


def figure_words(fig):
    """Every text of ``fig``: figure and axes texts, titles, axis labels, legend entries (its
    words, a wrapped line joined)."""
    texts = [t.get_text() for t in fig.texts]
    for legend in fig.legends:
        texts += [t.get_text() for t in legend.get_texts()]
    for ax in fig.axes:
        texts += [ax.get_title(), ax.get_title(loc="left"), ax.get_xlabel(), ax.get_ylabel()]
        texts += [t.get_text() for t in ax.texts]
        if ax.get_legend() is not None:
            texts += [t.get_text() for t in ax.get_legend().get_texts()]
    return " ".join(" ".join(texts).split())


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


def check_axes_3d(ax):
    """A 3-D view: drawn to scale (the box's sides in proportion to the axis ranges), every
    line (path, surface, interfaces) inside the limits, at least two tick labels on each axis
    (a scale), and no tick or axis label overlapping another (readable: the pyvista view once
    crowded its y labels into one corner)."""
    limits = [sorted(ax.get_xlim()), sorted(ax.get_ylim()), sorted(ax.get_zlim())]
    ranges = np.array([hi - lo for lo, hi in limits])
    assert (ranges > 0).all()
    box = np.asarray(ax.get_box_aspect(), dtype=float)
    np.testing.assert_allclose(box / box.max(), ranges / ranges.max(), rtol=1e-9)
    lines = ax.get_lines()
    assert lines
    for line in lines:
        for values, (lo, hi) in zip(line.get_data_3d(), limits, strict=True):
            assert lo <= np.min(values) and np.max(values) <= hi, ("cut off", line.get_label())
    ax.figure.canvas.draw()
    renderer = ax.figure.canvas.get_renderer()
    boxes = []
    for axis, (lo, hi) in zip((ax.xaxis, ax.yaxis, ax.zaxis), limits, strict=True):
        shown = [tick.label1 for tick in axis.get_major_ticks()
                 if lo <= tick.get_loc() <= hi and tick.label1.get_visible()
                 and tick.label1.get_text()]
        assert len(shown) >= 2, ("no scale", axis.get_label_text())
        boxes += [label.get_window_extent(renderer) for label in [*shown, axis.label]]
    for i, a in enumerate(boxes):
        for b in boxes[i + 1:]:
            assert not a.overlaps(b), ("labels overlap", a, b)
    return 1


def check_axes(fig):
    """The checks of the module docstring on every visible axes; returns how many showed data."""
    shown = 0
    for ax in fig.axes:
        if ax.name == "3d":
            shown += check_axes_3d(ax)
            continue
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
    from cavex.verification.output import files
    from cavex.verification.report import (
        penetration_figures,
        trajectory_figures,
        validation_figures,
    )

    record = Drawn()
    for module in (penetration_figures, trajectory_figures, validation_figures, files):
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


# the one-layer shot with attack at 200 m/s: at the default 1000 m/s it took 80 000
# derivative calls (29 s of CPU; 300 m/s: 25 000), at 200 m/s 1 000 (0.4 s), and what is
# checked here, the figures drawn and the 3-D block, does not depend on the speed
@pytest.mark.parametrize(("case", "argv", "config"), [
    ("normal incidence", [], None),
    ("70 deg ricochet", ["--obliquity", "70"], None),
    ("one layer, with attack", ["--attack", "3", "--velocity", "200"], ONE_LAYER),
    ("stops in the crater", [], CRATER_STOP),
])
def test_trajectory_figures(capsys, tmp_path, drawn, case, argv, config):
    out = tmp_path / "t"
    assert main(["trajectory", *argv, "--out", str(out), "--no-progress",
                 *_config(tmp_path, config)]) == 0
    capsys.readouterr()
    assert set(drawn.checked) == {"path_side.png", "pitch_time.png", "overload.png",
                                  "path_3d.png"}
    assert drawn.checked["path_side.png"] == 1 and drawn.checked["overload.png"] >= 2
    assert drawn.checked["path_3d.png"] == 1
    for name in drawn.checked:
        not_blank(out / name)
    # the 3-D block holds the surface and every interface the path reaches; the layers below
    # it are named in its legend (a ricochet's block is not the whole target, issue 33)
    target, _ = load_config(tmp_path / "target.toml" if config else None)
    (_, _, (bottom, top)) = drawn.limits_3d["path_3d.png"]  # depth downward
    deepest = np.loadtxt(out / "history_target.csv", delimiter=",", skiprows=1,
                         usecols=6).max()
    assert top < 0.0 < deepest < bottom
    for name, H in zip(target.layer_names()[1:], target.interface_depths, strict=True):
        assert (top < H < bottom) or (H > deepest and f"below the block: {name}"
                                      in drawn.words["path_3d.png"]), (name, H, bottom)


@pytest.mark.parametrize(("case", "strike"), [
    ("normal incidence", (1000.0, 0.0)), ("30 deg", (800.0, 30.0)),
    ("70 deg ricochet", (1000.0, 70.0)), ("stops in the first layer", (150.0, 0.0))])
def test_the_3d_block_holds_the_body(case, strike):
    """The 3-D view's block (:func:`block_limits`) holds the body's outline at every drawn time
    (the body is drawn as polygons, which the line check above does not see), with room for
    readable ticks: each horizontal side at least 0.4 of the largest."""
    from cavex.analytic.penetration.oblique import Strike
    from cavex.verification.commands.trajectory import trajectory_job
    from cavex.verification.report.trajectory_figures import block_limits, body_outline_3d

    target, projectile = load_config()
    result = trajectory_job(target, projectile, Strike(*strike))["runs"]["runway"]
    limits = block_limits(result, target)
    times = np.linspace(0.0, result.history["t_s"][-1], 6)
    points = np.concatenate([body_outline_3d(result, result.state(t)) for t in times])
    for k, (lo, hi) in enumerate(limits):
        assert lo < points[:, k].min() and points[:, k].max() < hi, (case, k, limits)
    sides = np.array([hi - lo for lo, hi in limits])
    assert sides[:2].min() >= 0.4 * sides.max() * (1.0 - 1e-12)


def test_a_normal_shot_draws_notes_not_round_off(tmp_path, drawn, capsys):
    """Normal incidence: pitch and lateral overload are round-off, so their axes hold a note
    and no curve (the check above would refuse the curve)."""
    assert main(["trajectory", "--out", str(tmp_path / "t"), "--no-progress"]) == 0
    capsys.readouterr()
    assert drawn.checked["pitch_time.png"] == 0  # a note only
    assert drawn.checked["overload.png"] == 2  # the axial row; the lateral row is a note


def test_a_ricochet_is_drawn_to_its_own_scale(tmp_path, drawn, capsys):
    """Issue 33: the 75 deg, 300 m/s ricochet (the nose tip 9 mm deep at most) once sat in a
    1.2 m block and its overload against depth was a loop. Its block now scales with the body
    (0.15 m long): no side beyond 4 body lengths (it was 8 deep); the overloads are drawn
    against the nose tip's path length, which only grows; the lateral overload has its mean
    over one nose length drawn and the steps of its samples explained; the side view's two
    legend entries of a run differ in style."""
    from cavex.config import load_config

    out = tmp_path / "t"
    assert main(["trajectory", "--obliquity", "75", "--velocity", "300", "--out", str(out),
                 "--no-progress"]) == 0
    assert "ricochet" in capsys.readouterr().out
    _, projectile = load_config()
    length = projectile.body_length
    sides = [abs(hi - lo) for lo, hi in drawn.limits_3d["path_3d.png"]]
    assert max(sides) <= 4.0 * length, (sides, length)
    assert "below the block: macadam" in drawn.words["path_3d.png"]
    depth_panels = [a for a in drawn.axes["overload.png"] if "path length" in a["xlabel"]]
    assert len(depth_panels) == 2  # axial and lateral
    for panel in depth_panels:
        assert all(np.all(np.diff(x) >= 0.0) for x in panel["x"])
    assert "mean over one nose length" in drawn.words["overload.png"]
    styles = dict(drawn.legend_styles["path_side.png"])
    assert styles["runway: centre of mass"] != styles[
        "runway: outline at 9 equal time intervals"]


def test_overloads_shade_the_open_zones(tmp_path, drawn, capsys):
    """Issue 33: a debonded shot's overload figure shades its open zones (craters and rear
    zones at the interfaces) on every panel, as the study's figures do; a bonded one has none
    to shade."""
    out = tmp_path / "t"
    assert main(["trajectory", "--obliquity", "20", "--velocity", "600", "--interfaces",
                 "debonded", "--out", str(out), "--no-progress"]) == 0
    capsys.readouterr()
    assert "shaded: open zones" in drawn.words["overload.png"]
    assert all(a["spans"] >= 1 for a in drawn.axes["overload.png"])
    assert main(["trajectory", "--obliquity", "20", "--velocity", "600", "--out",
                 str(tmp_path / "b"), "--no-progress"]) == 0
    capsys.readouterr()
    assert "shaded" not in drawn.words["overload.png"]
    assert all(a["spans"] == 0 for a in drawn.axes["overload.png"])


def test_the_homogeneous_run_says_it_has_no_interfaces(tmp_path, drawn, capsys):
    """Issue 33: with --compare-homogeneous the concrete-only shot is drawn past the first
    interface: its legend says the first layer is its material throughout, and the layers
    below are marked as the layered target's only."""
    assert main(["trajectory", "--obliquity", "20", "--velocity", "600",
                 "--compare-homogeneous", "--out", str(tmp_path / "t"), "--no-progress"]) == 0
    capsys.readouterr()
    words = drawn.words["path_side.png"]
    assert "first layer only (concrete throughout)" in words
    assert "macadam (runway only)" in words
    assert "first layer only (concrete throughout)" in drawn.words["overload.png"]


@pytest.mark.parametrize(("argv", "noted"), [
    (["--resistance", "law", "--law-A", "1e8", "--law-B", "2000"], True), ([], False)])
def test_penetrate_says_when_the_two_curves_coincide(tmp_path, drawn, capsys, argv, noted):
    """Issue 33: the global plain law is one law in every layer, so the layered run and the
    first layer alone are one curve (measured: 2.2e-6 of the depth apart): both figures say
    so; the default runs differ (6.8e-2) and say nothing."""
    assert main(["penetrate", *argv, "--out", str(tmp_path / "p")]) == 0
    capsys.readouterr()
    for name in ("velocity_time.png", "deceleration_depth.png"):
        assert ("one curve, drawn on each other" in drawn.words[name]) is noted


@pytest.mark.parametrize("calibrated", [True, False])
def test_validation_figures(tmp_path, drawn, calibrated):
    from cavex.verification.report.validation_figures import (
        FIGURES,
        REGIME_FIGURES,
        write_figures,
    )
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


def test_validation_points_of_alike_models_both_show():
    """Li and Chen's and Forrestal's formulas predict alike: in both panels (predicted against
    measured, residuals) Forrestal's larger markers lie behind Li and Chen's, so neither
    model's points hide the other's (issue 33: the li-chen-2003 points hid)."""
    from matplotlib.figure import Figure

    from cavex.verification.report.validation_figures import draw_models, draw_residuals

    result = json.loads((ROOT / "results" / "validation" / "compilation_dev"
                         / "validation.json").read_text())
    models = ["li-chen-2003", "forrestal-1994"]
    for draw in (lambda ax: draw_models(ax, result, models),
                 lambda ax: draw_residuals(ax, result, models, "velocity")):
        ax = Figure().subplots()
        draw(ax)
        lines = {line.get_label(): line for line in ax.lines if line.get_label() in models}
        li_chen, forrestal = lines["li-chen-2003"], lines["forrestal-1994"]
        assert forrestal.get_markersize() > li_chen.get_markersize()
        assert forrestal.get_zorder() < li_chen.get_zorder()


def test_trajectory_figures_import_neither_pyplot_nor_a_3d_engine(tmp_path):
    """The figures are drawn on Agg canvases without pyplot, the 3-D view with mplot3d (the
    figure time, issue 21: benchmarks/commands.py, docs/oblique.md "Speed")."""
    probe = ("import sys; from cavex.verification.cli import main; "
             f"code = main(['trajectory', '--velocity', '300', '--no-progress', '--out', "
             f"{str(tmp_path / 't')!r}]); "
             "print(code, sorted(m for m in ('matplotlib.pyplot', 'pyvista', 'vtk') "
             "if m in sys.modules), 'matplotlib' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=300, check=True)
    assert done.stdout.split("\n")[-2] == "0 [] True"
    assert (tmp_path / "t" / "path_3d.png").exists()


def test_the_collector_pause_restores_the_collector():
    """``collector_paused`` (the figures' pause of the cyclic garbage collector) leaves it as it
    found it: on after the block, also when the block raises; off if it was off."""
    import gc

    from cavex.verification.output.files import collector_paused

    assert gc.isenabled()
    with collector_paused():
        assert not gc.isenabled()
    assert gc.isenabled()
    with pytest.raises(KeyboardInterrupt), collector_paused():
        raise KeyboardInterrupt
    assert gc.isenabled()
    gc.disable()
    try:
        with collector_paused():
            pass
        assert not gc.isenabled()
    finally:
        gc.enable()


def test_penetrate_layer_names_fit_without_overlap():
    """The deceleration figure's layer names: every layer is named (issue 33: none dropped);
    a layer narrower than its name keeps it on the first row when its neighbours leave room
    (the runway's macadam on a 5 m axis), else its name goes up a row; a name that would stick
    out of the axes is moved in to the edge; a layer below the view is named "below: name";
    names never overlap."""
    from cavex.verification.output.files import agg_figure
    from cavex.verification.report.penetration_figures import layer_names

    def placed(bounds, names, xlim):
        """``{name: row}`` of the placed names (row 0: just above the axes)."""
        fig = agg_figure(figsize=(6.4, 4.8))
        ax = fig.add_subplot()
        ax.set_xlim(*xlim)
        rows = layer_names(ax, names, [xlim[0], *bounds, xlim[1]])
        renderer = fig.canvas.get_renderer()
        boxes = [(t.get_window_extent(renderer), t.get_text()) for t in ax.texts]
        for i, (a, _) in enumerate(boxes):
            assert not any(a.overlaps(b) for b, _ in boxes[i + 1:])  # never overlapping
        frame = ax.get_window_extent(renderer)
        assert all(frame.x0 - 0.5 <= box.x0 and box.x1 <= frame.x1 + 0.5 for box, _ in boxes)
        bottoms = sorted({round(box.y0, 3) for box, _ in boxes})
        assert len(bottoms) == rows
        return {name: bottoms.index(round(box.y0, 3)) for box, name in boxes}

    names = ["concrete", "macadam", "soil"]
    # macadam 7.8 % of the axis: one row
    assert placed([0.65, 1.1], names, (-0.26, 5.52)) == {n: 0 for n in names}
    crowded = placed([0.65, 0.7], names, (0.0, 5.5))  # a 5 cm layer between two names
    assert crowded == {"concrete": 0, "macadam": 1, "soil": 0}
    # only concrete in view: the layers below named at the right edge
    assert placed([0.65, 1.1], names, (0.0, 0.5)) == {"concrete": 0, "below: macadam": 0,
                                                      "below: soil": 1}
