"""What users read and see (issue 33): the table's figure of S(V, L), debonded runs that say
so, a user's own target named by its layers and not "runway", the help's words, the version
in every JSON output. Figures are drawn on matplotlib Axes and their limits, labels and titles
asserted; the pictures themselves were looked at when these tests were written."""

import json
from pathlib import Path

import numpy as np
import pytest

from cavex.config import load_config
from cavex.netcdf3 import PlainDataset
from cavex.verification.cli import build_parser
from cavex.verification.output.files import agg_figure

RUNWAY_TOML = Path(__file__).parents[1] / "core" / "data" / "runway.toml"
USER_NAMES = ("asphalt", "crushed stone base", "subgrade")


@pytest.fixture(scope="module")
def user_config(tmp_path_factory):
    """A user's own three layers (thinner, named asphalt / crushed stone base / subgrade)."""
    text = RUNWAY_TOML.read_text()
    for old, new in (('"concrete"', '"asphalt"'), ('"macadam"', '"crushed stone base"'),
                     ('"soil"', '"subgrade"'), ("thickness = 0.65", "thickness = 0.15"),
                     ("thickness = 0.45", "thickness = 0.30")):
        text = text.replace(old, new)
    path = tmp_path_factory.mktemp("user") / "user.toml"
    path.write_text(text)
    return path


def axes():
    return agg_figure(figsize=(8.0, 5.2)).add_subplot()


def legend_texts(ax):
    return [t.get_text() for t in ax.get_legend().get_texts()]


# --- 1. cavex table draws S(V, L) -------------------------------------------------------------

@pytest.fixture(scope="module")
def paper_table():
    """The quasi-static closed form on a table grid of the paper's target (13 velocities, the
    default depths with the two switch nodes): the shape of an FE table, in a second."""
    from cavex.verification.fedata.table import DEFAULT_DEPTHS, DEFAULT_VELOCITIES, analytic_table

    return analytic_table(*load_config(), DEFAULT_VELOCITIES, DEFAULT_DEPTHS,
                          boundary="quasi-static")


def test_table_figure_lines_per_depth_with_the_switches(paper_table):
    from cavex.verification.report.table_figures import draw_table

    ax = axes()
    bar = draw_table(ax, paper_table)
    depths = paper_table["depth"].values
    assert len(ax.get_lines()) == depths.size  # one line a depth
    assert ax.get_xlim() == (0.0, 1200.0)
    assert ax.get_xlabel() == "cavity expansion velocity V (m/s)"
    assert "S = " in ax.get_ylabel()
    assert ax.get_title() == (f"Tabulated S(V, L): 13 velocities x {depths.size} depths, "
                              "3 layers")
    bottom, top = bar.ax.get_ylim()
    assert (bottom, top) == (pytest.approx(depths.max()), pytest.approx(depths.min()))
    assert bar.ax.get_ylabel() == "nose-tip depth L (m)"
    legend = legend_texts(ax)
    for name in ("concrete", "macadam", "soil"):
        assert any(text.startswith(f"wall in {name}: L ") for text in legend)
    switches = [line.get_ydata()[0] for line in bar.ax.get_lines()]
    # the wall leaves a layer where the nose tip is l - r past its interface (the spherical
    # problem's centre, analytic.geometry), + the switch node's 1e-9 m
    _, projectile = load_config()
    expected = [H + projectile.l - projectile.r for H in (0.65, 1.10)]
    assert switches == pytest.approx(expected, abs=1e-8)
    assert legend[-1] == ("wall layer switches (colour bar): L = "
                          + ", ".join(f"{L:.4g}" for L in expected) + " m")


def synthetic(velocities, depths, wall, names):
    """A table of the shape ``cavex table`` writes, ``S = 1 + V/100 + L``."""
    v, d = np.asarray(velocities, float), np.asarray(depths, float)
    S = 1.0 + v[:, None] / 100.0 + d[None, :]
    return PlainDataset({"S": (("velocity", "depth"), S, {}),
                         "wall_layer": (("depth",), np.asarray(wall, np.int32), {})},
                        {"velocity": (("velocity",), v, {}), "depth": (("depth",), d, {})},
                        {"layer_names": json.dumps(names)})


@pytest.mark.parametrize(("velocities", "depths", "wall", "names", "switches"), [
    ([0.0, 600.0], [0.1, 0.2, 0.3], [0, 1, 1], ["asphalt", "base"], 1),  # two velocities
    ([0.0, 300.0, 600.0, 900.0], [0.4], [0], ["asphalt"], 0),  # one depth
    ([0.0, 300.0, 600.0, 900.0], [0.1, 0.5, 0.9], [0, 0, 0], ["only"], 0),  # one layer
    ([0.0, 300.0, 600.0, 900.0], [0.1, 0.5], [0, 1], ["", "second"], 1),  # a nameless layer
])
def test_table_figure_degenerate_grids(velocities, depths, wall, names, switches):
    from cavex.verification.report.table_figures import draw_table

    ax = axes()
    bar = draw_table(ax, synthetic(velocities, depths, wall, names))
    assert len(ax.get_lines()) == len(depths)
    assert ax.get_xlim() == (velocities[0], velocities[-1])
    assert ax.get_title().startswith(f"Tabulated S(V, L): {len(velocities)} velocities x "
                                     f"{len(depths)} depths")
    assert len(bar.ax.get_lines()) == switches
    low, high = sorted(bar.ax.get_ylim())
    assert low <= min(depths) < high and low < max(depths) <= high
    assert high > low  # one depth: a bar of some height around it
    layers = [t for t in legend_texts(ax) if t.startswith("wall in")]
    assert len(layers) == len(set(wall))  # one entry a wall layer
    assert not any("wall in :" in t for t in layers)  # a nameless layer is "layer k"
    marker = ax.get_lines()[0].get_marker()
    assert marker == ("o" if len(velocities) < 4 else "None")


def test_table_command_writes_the_figure_beside_the_table(paper_table, tmp_path):
    from cavex.verification.commands import table

    store = tmp_path / "t.nc.cases"
    store.mkdir()
    written = table.write_outputs({"table": paper_table, "store": store}, tmp_path / "t.nc")
    assert written == [str(tmp_path / "t.nc"), str(tmp_path / "t_S.png")]
    assert (tmp_path / "t_S.png").stat().st_size > 10_000 and not store.exists()
    plain = table.write_outputs({"table": paper_table, "store": store}, tmp_path / "u.nc",
                                draw=False)
    assert plain == [str(tmp_path / "u.nc")] and not (tmp_path / "u_S.png").exists()
    args = build_parser("table").parse_args(["table", "--no-figures"])
    assert args.figures is False
