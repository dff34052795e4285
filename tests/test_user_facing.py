"""What users read and see (issue 33): the table's figure of S(V, L), debonded runs that say
so, a user's own target named by its layers and not "runway", the help's words, the version
in every JSON output. Figures are drawn on matplotlib Axes and their limits, labels and titles
asserted; the pictures themselves were looked at when these tests were written."""

import json
from pathlib import Path

import numpy as np
import pytest

from cavex import __version__
from cavex.config import load_config
from cavex.netcdf3 import PlainDataset
from cavex.verification.cli import build_parser, main
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
    depth_words = "1 depth" if len(depths) == 1 else f"{len(depths)} depths"
    assert ax.get_title() == (f"Tabulated S(V, L): {len(velocities)} velocities x "
                              f"{depth_words}, {len(names)} layer" + "s" * (len(names) > 1))
    assert len(bar.ax.get_lines()) == switches
    low, high = sorted(bar.ax.get_ylim())
    assert low <= min(depths) < high and low < max(depths) <= high
    assert high > low  # one depth: a bar of some height around it
    layers = [t for t in legend_texts(ax) if t.startswith("wall in")]
    assert len(layers) == len(set(wall))  # one entry a wall layer
    assert not any("wall in :" in t for t in layers)  # a nameless layer is "layer k"
    if len(depths) == 1:
        assert layers == [f"wall in {names[0]}: L {depths[0]:g} m"]
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


# --- 2. debonded runs say so; 3. a user's target is not "runway" -----------------------------

def penetrate_job(target, projectile):
    from cavex.verification.commands.penetrate import penetration_job

    return penetration_job(target, projectile)


def draw_penetration(job):
    """The two panels of ``cavex penetrate``'s figures, drawn as the command draws them
    (figure size, then tight layout)."""
    from cavex.verification.report.penetration_figures import draw_deceleration, draw_velocity

    panels = []
    for draw in (draw_velocity, draw_deceleration):
        fig = agg_figure(figsize=(6.4, 4.8))
        ax = fig.add_subplot()
        draw(ax, job)
        fig.tight_layout()
        fig.canvas.draw()
        panels.append(ax)
    return panels


def test_penetrate_debonded_says_so_in_text_titles_and_legends():
    from cavex.verification.commands.penetrate import text

    target, projectile = load_config()
    job = penetrate_job(target.with_interfaces("debonded"), projectile)
    assert text(job).splitlines()[0].endswith(", debonded interfaces")
    assert job["target_label"] == "runway (the paper's Table 1, debonded interfaces)"
    for ax in draw_penetration(job):
        assert "debonded interfaces" in ax.get_title()
        assert legend_texts(ax)[0] == "runway (layered, debonded interfaces)"
    bonded = penetrate_job(target, projectile)
    assert "debonded" not in text(bonded).splitlines()[0]
    assert all("debonded" not in ax.get_title() for ax in draw_penetration(bonded))


def test_penetrate_user_target_names_every_layer_and_is_no_runway(user_config, tmp_path):
    from cavex.verification.commands.penetrate import text

    target, projectile = load_config(user_config)
    job = penetrate_job(target, projectile)
    assert job["target_label"] == "layered target" and "runway" not in text(job)
    from cavex.verification.commands.penetrate import write_outputs

    written = write_outputs(job, tmp_path, draw=False)  # no file is called a runway either
    assert written and not any("runway" in Path(name).name for name in written), written
    velocity, deceleration = draw_penetration(job)
    for ax in (velocity, deceleration):
        assert legend_texts(ax) == ["layered target", "asphalt alone"]
    names = [t for t in deceleration.texts if t.get_text() in USER_NAMES]
    assert sorted(t.get_text() for t in names) == sorted(USER_NAMES)  # none dropped
    renderer = deceleration.figure.canvas.get_renderer()
    frame = deceleration.get_window_extent(renderer)
    boxes = [t.get_window_extent(renderer) for t in names]
    title = deceleration.title.get_window_extent(renderer)
    for box in boxes:  # inside the axes' width, below the title, none over another
        assert frame.x0 - 0.5 <= box.x0 and box.x1 <= frame.x1 + 0.5
        assert box.y1 <= title.y0 + 0.5
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])


def test_penetrate_paper_target_keeps_its_words():
    """The paper's target is still the runway (its committed figures and text unchanged)."""
    target, projectile = load_config()
    job = penetrate_job(target, projectile)
    assert job["target_label"] == "runway (the paper's Table 1)"
    velocity, deceleration = draw_penetration(job)
    assert legend_texts(velocity) == ["runway (layered)", "concrete alone"]
    assert {t.get_text() for t in deceleration.texts} == {"concrete", "macadam", "soil"}


@pytest.fixture(scope="module")
def trajectory_jobs(user_config):
    """A debonded paper target and a user's target, 30 deg at 500 m/s (the derived model)."""
    from cavex.analytic.penetration.strike import Strike
    from cavex.verification.commands.trajectory import trajectory_job

    target, projectile = load_config()
    user, user_projectile = load_config(user_config)
    strike = Strike(500.0, 30.0, 0.0, 0.0, 0.0)
    return {"debonded": trajectory_job(target.with_interfaces("debonded"), projectile, strike),
            "user": trajectory_job(user, user_projectile, strike, compare_homogeneous=True)}


@pytest.fixture
def kept_trajectory_figures(monkeypatch):
    """The trajectory figures kept (by file name) instead of written."""
    from cavex.verification.report import trajectory_figures

    kept = {}

    def keep(fig, path, **savefig):
        fig.canvas.draw()
        kept[path.name] = fig
        return path

    monkeypatch.setattr(trajectory_figures, "save_figure", keep)
    return kept


def titles(fig):
    """The figure's title and its axes' titles, in one string."""
    words = [fig._suptitle.get_text() if fig._suptitle else ""]
    return " | ".join(words + [ax.get_title() for ax in fig.axes])


def test_trajectory_debonded_says_so_in_text_and_every_figure(trajectory_jobs, tmp_path,
                                                               kept_trajectory_figures):
    from cavex.verification.commands.trajectory import text
    from cavex.verification.report.trajectory_figures import figures

    job = trajectory_jobs["debonded"]
    assert text({**job, "outputs": []}).splitlines()[0].endswith("; debonded interfaces")
    figures(job, tmp_path)
    assert sorted(kept_trajectory_figures) == ["overload.png", "path_3d.png", "path_side.png",
                                               "pitch_time.png"]
    for name, fig in kept_trajectory_figures.items():
        assert "debonded interfaces" in titles(fig), name


def test_trajectory_user_target_is_a_layered_target_with_its_names(trajectory_jobs, tmp_path,
                                                                    kept_trajectory_figures):
    from cavex.verification.commands.trajectory import summary, text
    from cavex.verification.report.trajectory_figures import figures

    job = trajectory_jobs["user"]
    words = text({**job, "outputs": []})
    assert "layered target:" in words and "runway" not in words
    assert "runway" in summary(job)["runs"]  # the JSON key stays (scripts read it)
    figures(job, tmp_path)
    for name, fig in kept_trajectory_figures.items():
        labels = [t.get_text() for legend in [*fig.legends, *(a.get_legend() for a in fig.axes)]
                  if legend for t in legend.get_texts()]
        assert not any("runway" in label for label in labels), name
        assert "debonded" not in titles(fig), name
    side = kept_trajectory_figures["path_side.png"]
    assert any(label.startswith("layered target: ") for label in
               (t.get_text() for t in side.legends[0].get_texts()))
    renderer = side.canvas.get_renderer()
    names = {t.get_text().replace("\n", " ").removesuffix(" (layered target only)"): t
             for t in side.axes[0].texts}  # the layers below the first: the layered run's
    assert set(USER_NAMES) <= set(names)
    for name in USER_NAMES:  # inside the figure: not cropped at its right edge
        assert names[name].get_window_extent(renderer).x1 <= side.bbox.x1, name
    assert "\n" in names["crushed stone base"].get_text()  # wrapped to fit
    legend_3d = [t.get_text().replace("\n", " ") for t in
                 kept_trajectory_figures["path_3d.png"].legends[0].get_texts()]
    for name in USER_NAMES:  # a layer in the block, or named below it ("below the block: ...")
        assert any(label == name or label.startswith(f"below the block: {name} ")
                   for label in legend_3d), (name, legend_3d)


# --- 4. help ------------------------------------------------------------------------------------

def help_text(*command):
    parser = build_parser(command[0] if command else None)
    return (parser._subparsers._group_actions[0].choices[command[0]] if command
            else parser).format_help()


def test_command_list_tags_no_command_required():
    text = help_text()
    assert "(required)" not in text
    for name in ("penetrate", "calibrate", "trajectory", "config"):
        assert name in text


def test_calibrate_help_offers_no_table_option_it_refuses():
    text = " ".join(help_text("calibrate").split())
    assert "--table" not in text and "an FE table (built by the command)" in text
    assert "--table" in help_text("penetrate")  # where it is an option, it is named


def test_law_help_and_errors_describe_the_same_two_laws(capsys):
    from cavex.verification.commands.options import GLOBAL_LAW, LAYER_LAW

    flat = " ".join(help_text("penetrate").split())
    assert f"A of the global plain law {GLOBAL_LAW}" in flat
    assert f"B of the global plain law {GLOBAL_LAW}" in flat
    assert f"each layer's own plain law {LAYER_LAW}" in flat
    assert main(["penetrate", "--law-A", "1e8", "--no-figures"]) == 2
    error = capsys.readouterr().err
    assert GLOBAL_LAW in error and LAYER_LAW in error
    assert main(["penetrate", "--resistance", "law", "--no-figures"]) == 2
    error = capsys.readouterr().err
    assert "layers[0].law_A" in error and LAYER_LAW in error and GLOBAL_LAW in error


def test_trajectory_velocity_help_gives_the_number():
    flat = " ".join(help_text("trajectory").split())
    V0 = load_config()[1].V0
    assert V0 == 1000.0
    assert ("--velocity VELOCITY striking speed (m/s; default: the projectile's V0, 1000 m/s "
            "for the paper's Table 1)") in flat


# --- 5. the version in every JSON output --------------------------------------------------------

def test_every_json_print_opens_with_the_version(capsys, tmp_path):
    """``--json`` goes through one function for every command (cli.main); two commands run."""
    for argv in (["stress", "--depth", "0.3", "--velocity", "500", "--json"],
                 ["penetrate", "--json", "--no-figures", "--out", str(tmp_path / "p")]):
        assert main(argv) == 0, argv
        document = json.loads(capsys.readouterr().out)
        assert next(iter(document)) == "cavex_version" and document["cavex_version"] == (
            __version__), argv


def test_json_files_open_with_the_version(trajectory_jobs, tmp_path):
    from cavex.verification.commands.trajectory import write_outputs

    write_outputs(trajectory_jobs["user"], tmp_path, draw=False)
    document = json.loads((tmp_path / "summary.json").read_text())
    assert list(document) == ["cavex_version", "settings", "runs"]
    assert document["cavex_version"] == __version__
    root = Path(__file__).parents[1] / "results" / "validation"
    for path in (root / "validation.json", root / "compilation_dev" / "validation.json"):
        committed = json.loads(path.read_text())
        assert next(iter(committed)) == "cavex_version", path  # regenerated with the key


def test_citation_names_this_version():
    """CITATION.cff (validated against CFF 1.2.0 with cffconvert 2.0.0 when written) carries
    the package's version."""
    text = (Path(__file__).parents[1] / "CITATION.cff").read_text()
    assert "cff-version: 1.2.0" in text
    assert f"\nversion: {__version__}\n" in text


def test_phase_table_columns_hold_a_long_layer_name(user_config, tmp_path):
    from cavex.verification.commands.penetrate import text

    long_name = "crushed and compacted stone base course"
    path = tmp_path / "long.toml"
    path.write_text(user_config.read_text().replace('"crushed stone base"', f'"{long_name}"'))
    lines = text(penetrate_job(*load_config(path))).splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith(" # label"))
    rows = [line for line in lines[header + 1:] if line[:2].strip().isdigit()]
    assert any(long_name in row for row in rows)
    column = lines[header].index("L (m)") + len("L (m)")  # the depth column's right edge
    assert all(row[column - 6:column].strip().replace(".", "").isdigit() for row in rows)
