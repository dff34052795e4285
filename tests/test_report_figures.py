"""The report's and the penetration job's figures and HTML, without FE: the grid is a table
filled from the closed form (``analytic_table``) and analysed as the report analyses it.

What an engineer reads off the figures is checked on the matplotlib objects (captured
instead of saved): one colour scale for the three error maps, cells on the true coordinates,
the meaning of every marker inside the image, the response states explained, percentages,
titles without file paths or settings the model does not use.
"""

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from cavex.analytic.geometry import switch_depths
from cavex.analytic.penetration.integrator import crater_depth
from cavex.config import load_config
from cavex.verification.commands import penetrate as penetration_report
from cavex.verification.fedata.table import analytic_table, write_table
from cavex.verification.report import penetration_figures, plots
from cavex.verification.report.analysis import analyse
from cavex.verification.report.build import quick_axes
from cavex.verification.report.html import markdown_to_html, slug

PNG = b"\x89PNG\r\n\x1a\n"
DEPTHS = (0.1, 0.3, 0.5, 0.7, 0.9, 1.1, 1.3, 2.0, 3.0)
VELOCITIES = (0.0, 100.0, 300.0, 600.0, 1000.0, 1200.0)


@pytest.fixture(scope="module")
def runway():
    return load_config()


@pytest.fixture(scope="module")
def grid(runway):
    """A report grid over an unequally spaced (V, L) grid reaching far below the layers."""
    target, projectile = runway
    table = analytic_table(target, projectile, VELOCITIES, DEPTHS, boundary="dynamic")
    rng = np.random.default_rng(1)
    table["error_estimate"][:] = 10.0 ** rng.uniform(-6, -2.5, table["sigma_r"].shape)
    return analyse(table, target, projectile)


@pytest.fixture
def figures(monkeypatch):
    """Figures are kept (and closed by the test) instead of written."""
    import matplotlib.pyplot as plt

    kept = {}

    def keep(fig, path, *args, **kwargs):
        kept[path.name] = fig
        return path

    monkeypatch.setattr(plots, "_save", keep)
    monkeypatch.setattr(penetration_figures, "_save", keep)
    yield kept
    plt.close("all")


def _texts(fig):
    from matplotlib.text import Text

    return [t.get_text() for t in fig.findobj(Text) if t.get_text()]


def test_error_maps_share_one_scale_on_true_coordinates(grid, runway, figures, tmp_path):
    from matplotlib.collections import QuadMesh

    target, _ = runway
    plots.error_maps(grid, target, tmp_path)
    fig = figures["error_maps.png"]
    meshes = [c for ax in fig.axes if ax.get_label() != "<colorbar>" for c in ax.collections
              if isinstance(c, QuadMesh)]
    # three models, each on a broken depth axis (the grid reaches 3 m, the layers end at 1.1 m)
    assert len(meshes) == 6
    assert plots.depth_parts(grid, target)[0][1] < 2.0
    norms = {id(m.norm) for m in meshes}
    assert len(norms) == 1
    np.testing.assert_array_equal(meshes[0].norm.boundaries, plots.ERROR_BOUNDS)
    assert {-1.0, 1.0, -5.0, 5.0} <= set(plots.ERROR_BOUNDS)
    # cells on the true coordinates: edges half-way between the (unequally spaced) grid points
    coords = meshes[0].get_coordinates()
    np.testing.assert_allclose(coords[0, :, 0], plots.edges(grid.velocity.values, lower=0.0))
    np.testing.assert_allclose(coords[:, 0, 1], plots.edges(grid.depth.values, lower=0.0))
    np.testing.assert_allclose(plots.edges([0.0, 100.0, 300.0], lower=0.0),
                               [0.0, 50.0, 200.0, 400.0])
    # the meaning of the lines and dots is inside the image
    texts = " ".join(_texts(fig))
    assert "|error| = 1 % contour" in texts and "|error| = 5 % contour" in texts
    assert "not resolved: FE error estimate" in texts and "interface depth H" in texts
    assert "(analytic - FE) / FE (%)" in texts
    for name in ("concrete", "macadam", "soil"):
        assert name in texts


def test_validity_is_colour_blind_safe(grid, runway, figures, tmp_path):
    from matplotlib.colors import to_hex
    from matplotlib.patches import Patch

    plots.validity_map(grid, runway[0], tmp_path)
    legend = figures["validity.png"].legends[0]
    colours = {t.get_text(): to_hex(h.get_facecolor()) for t, h in
               zip(legend.get_texts(), legend.legend_handles, strict=True)
               if isinstance(h, Patch)}
    # Okabe-Ito blue, sky blue, orange, grey: no red/green pair
    assert colours == {"within 1 % of FE": "#0072b2", "within 5 %": "#56b4e9",
                       "beyond 5 %": "#e69f00", "FE failed": "#bbbbbb"}


def test_state_map_explains_every_state(grid, runway, figures, tmp_path):
    plots.state_map(grid, runway[0], tmp_path)
    texts = _texts(figures["states.png"])
    labels = grid["state_dynamic"].attrs["flag_meanings"].split()
    assert {"a", "f", "single"} <= set(labels)
    for label in labels:
        assert any(t.startswith(f"{label}: ") for t in texts), label
    assert "a: plastic zone ends inside concrete" in texts
    assert "f: plastic zone ends inside macadam" in texts
    assert any("a-e: 3 layers around the cavity (concrete, macadam, soil)" in t for t in texts)


def test_error_estimate_in_percent(grid, runway, figures, tmp_path):
    plots.error_estimate_map(grid, runway[0], tmp_path)
    fig = figures["error_estimate.png"]
    bar = fig.axes[-1]
    assert bar.get_ylabel() == "FE relative error estimate (%)"
    fig.canvas.draw()
    ticks = [t.get_text() for t in bar.get_yticklabels() if t.get_text()]
    assert ticks and all(re.fullmatch(r"[\d.]+ %", t) for t in ticks)
    assert "log10" not in " ".join(_texts(fig))


def test_every_report_figure_is_written(grid, runway, tmp_path):
    target, projectile = runway
    curves = [100.0, 600.0, 1000.0]
    written = [plots.error_maps(grid, target, tmp_path),
               plots.validity_map(grid, target, tmp_path),
               plots.state_map(grid, target, tmp_path),
               plots.error_estimate_map(grid, target, tmp_path),
               plots.s_curves(grid, target, tmp_path, curves),
               plots.plastic_radius_plot(grid, target, tmp_path, curves)]
    for path in written:
        assert path.read_bytes()[:8] == PNG, path


def test_quick_axes_reach_the_crater_and_the_striking_velocity(runway):
    target, projectile = runway
    velocities, depths = quick_axes(target, projectile)
    assert velocities == (0.0, 100.0, 300.0, 600.0, 1000.0)  # 0, 0.1, 0.3, 0.6, 1 V0
    assert depths[0] <= crater_depth(projectile) < depths[1]
    assert depths[-1] > switch_depths(target, projectile)[-1]
    assert len(depths) == 4
    single_v, single_d = quick_axes(target.single(0), projectile)
    assert single_d[0] <= crater_depth(projectile) and single_d[-1] >= 1.0


def test_penetration_titles(runway, figures, tmp_path):
    target, projectile = runway
    from cavex.analytic.models import get

    assert get("derived").describe("dynamic", "quasi-static") == "derived model, dynamic boundary"
    paper = get("paper").describe("quasi-static", "cylindrical-sigma_c")
    assert "boundary" not in paper and "cylindrical-sigma_c" in paper
    path = tmp_path / "a" / "very" / "long" / "folder" / "table.nc"
    write_table(analytic_table(target, projectile, [0.0, 300.0, 700.0, 1200.0],
                               [0.1, 0.4, 0.8, 1.2, 1.3]), path)
    job = penetration_report.penetration_job(target, projectile, resistance="table", table=path)
    assert job["table"] == str(path)  # the command's own output keeps the full path
    assert (job["model"], job["first_layer_model"]) == ("table", "derived-dynamic")
    penetration_figures.figures(job, tmp_path)
    for name in ("velocity_time.png", "deceleration_depth.png"):
        ax = figures[name].axes[0]
        assert str(tmp_path) not in ax.get_title() and "table.nc" in ax.get_title()
        assert "runway (layered, FE table)" in [t.get_text() for t in ax.get_legend().texts]
    assert figures["deceleration_depth.png"].axes[0].get_ylabel() == r"deceleration ($10^3$ g)"
    job = penetration_report.penetration_job(target, projectile, resistance="paper")
    penetration_figures.figures(job, tmp_path)
    titles = [figures[n].axes[0].get_title() for n in ("velocity_time.png",
                                                        "deceleration_depth.png")]
    assert all("boundary" not in t and "paper model" in t for t in titles)


def test_markdown_to_html_is_self_contained(tmp_path):
    (tmp_path / "a.png").write_bytes(PNG + b"\x00" * 10)
    text = "\n".join([
        "# Title", "", "Contents: [Numbers](#numbers-1-and-5-) · [Other](#other)", "",
        "## Numbers (1 % and 5 %)", "", "![a](a.png)", "", "![gone](missing.png)", "",
        "| name | value | where |", "|---|---|---|", "| x | +1.234 % | 600 / 0.685 |",
        "| long text cell | 1.5e-03 | n/a |", "", "## Other", "", "- `a`: **b**", ""])
    assert slug("Numbers (1 % and 5 %)") == "numbers-1--and-5-"
    html = markdown_to_html(text, "t", base_dir=tmp_path)
    root = ET.fromstring(html.split("\n", 1)[1])
    images = [e.get("src") for e in root.iter("img")]
    assert len(images) == 1 and images[0].startswith("data:image/png;base64,iVBORw0KGgo")
    assert "missing.png not available" in html and 'src="missing.png"' not in html
    assert {e.get("id") for e in root.iter("h2")} == {"numbers-1--and-5-", "other"}
    cells = {e.text: e.get("class") for e in root.iter("td")}
    assert cells["+1.234 %"] == cells["600 / 0.685"] == cells["1.5e-03"] == "num"
    assert cells["x"] is None and cells["long text cell"] is None
    assert '<a href="#other">Other</a>' in html


def test_stress_figure_warns_when_V_outruns_a_layers_elastic_wave(tmp_path, monkeypatch):
    """Issue 33: a user's target whose subgrade (E 50 MPa, nu 0.3, rho 1600: c_p = 205 m/s)
    is slower than the 600 m/s of verify's stress figure showed jagged FE fields without a
    word. The figure and its caption (verify's text output) now warn, naming the layer and
    its c_p = sqrt((K + 4G/3)/rho); the paper's target (slowest c_p 11 km/s) gets none."""
    from dataclasses import replace

    from cavex.materials import Target
    from cavex.verification.output import files
    from cavex.verification.report import picture

    target, _ = load_config()
    named = [replace(layer, name=name) for layer, name in zip(
        target.layers, ("asphalt", "crushed stone base", "subgrade"), strict=True)]
    soft = replace(named[2], E=50e6, nu=0.3)
    user = Target((*named[:2], soft), target.thicknesses)
    c_p = picture.elastic_wave_speed(soft)
    G, K = soft.E / (2.0 * 1.3), soft.E / (3.0 * 0.4)
    assert c_p == pytest.approx(np.sqrt((K + 4.0 * G / 3.0) / 1600.0), rel=1e-12)
    assert 200.0 < c_p < 210.0
    warning = picture.wave_speed_warning(user, 600.0)
    assert warning is not None and f"({c_p:.0f} m/s)" in warning
    assert user.layer_names()[2] in warning and user.layer_names()[0] not in warning
    assert picture.wave_speed_warning(target, 600.0) is None
    assert picture.wave_speed_warning(user, 600.0, names=user.layer_names()[:2]) is None
    r = np.geomspace(0.0125, 0.5, 200)
    fields = {"r": r, "sigma_r": 1e9 * (0.0125 / r) ** 2, "sigma_theta": 5e8 * (0.0125 / r) ** 2,
              "layer": np.where(r < 0.3, 1, 2), "a": 0.0125, "b": 0.06, "interfaces": [0.3],
              "layers": user.layer_names()[1:], "cavity_stress": 1e9,
              "closed_form": {"dynamic": {"b": 0.05, "stress": 1.1e9, "state": "f"},
                              "quasi-static": {"b": 0.1, "stress": 1.2e9, "state": "f"}}}
    drawn = {}
    monkeypatch.setattr(files, "save_figure", lambda fig, path, **_: drawn.setdefault(
        "texts", " ".join(t.get_text() for t in fig.texts)) and path)
    picture.plot_stresses(fields, tmp_path / "s.png", "title", warning)
    assert "exceeds the elastic wave speed" in drawn["texts"].replace("\n", " ")
    # verify's text output and report.md carry make_picture's caption: the warning is in it
    monkeypatch.setattr(picture, "fe_fields", lambda *args: fields)
    path, caption = picture.make_picture(user, load_config()[1], 600.0, 0.7,
                                         tmp_path / "t.png")
    assert path is not None and caption.endswith(warning)
