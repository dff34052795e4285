"""``cavex view``: the 3-D pictures rendered off screen with pyvista (the ``view`` extra).

The refusals run everywhere; the pictures where pyvista is installed and VTK finds an
off-screen OpenGL context (VTK >= 9.4: EGL, else OSMesa, where there is no display; the
project's machines have Mesa's EGL). Each picture is checked on its pixels (size, not blank,
the colours of what it must show) and on its summary; the pictures were opened and looked at
(docs/fem.md "cavex view")."""

import importlib.util
import json
import subprocess
import sys

import numpy as np
import pytest
from cli_helpers import refused, run
from test_json_keys import offending_keys

HAS_PYVISTA = importlib.util.find_spec("pyvista") is not None


def _offscreen():
    """Whether VTK renders off screen here (asked in a child process: a VTK without any
    context could end the process)."""
    if not HAS_PYVISTA:
        return False
    probe = ("from cavex.verification.commands.view import require_offscreen; "
             "print(require_offscreen())")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120)
    return done.returncode == 0


needs_rendering = pytest.mark.skipif(
    not HAS_PYVISTA, reason='pyvista is not installed (pip install ".[view]")')


@pytest.fixture(scope="module")
def rendering():
    if not _offscreen():
        pytest.skip("VTK finds no off-screen OpenGL context (EGL or OSMesa) on this machine")


def pixels(path):
    """The PNG as RGB floats in [0, 1]."""
    import matplotlib.image as mpimg

    return mpimg.imread(path)[..., :3]


def share_near(image, colour, tolerance=0.12):
    """Fraction of the pixels within ``tolerance`` (each channel) of ``colour`` (hex)."""
    rgb = np.array([int(colour[i:i + 2], 16) / 255.0 for i in (1, 3, 5)])
    return float(np.all(np.abs(image - rgb) <= tolerance, axis=-1).mean())


def blue_share(image):
    """Fraction of the pixels of a dark blue (the bodies, navy, shaded and seen through the
    translucent layers)."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return float(((b > r + 0.15) & (b > g + 0.15) & (r < 0.4)).mean())


def red_share(image):
    """Fraction of the pixels of a strong red (the path; the legend's mark is 0.02 %)."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return float(((r > g + 0.4) & (r > b + 0.4)).mean())


def drawn_share(image):
    """Fraction of the pixels that are not the white background."""
    return float((image.min(axis=-1) < 0.95).mean())


def view_json(capsys, *argv):
    code, out, err = run(capsys, "view", *argv, "--json")
    assert code == 0, err
    return json.loads(out)


# -- refusals (no pyvista needed) ---------------------------------------------------------

@pytest.mark.parametrize("argv, name", [
    (["fields", "--velocity", "300"], "depth"),
    (["fields", "--depth", "0.3"], "velocity"),
    (["fields", "--velocity", "300", "--depth", "0.3", "--extent", "100"], "extent"),
    (["fields", "--velocity", "300", "--depth", "0.3", "--extent", "nan"], "extent"),
    (["fields", "--velocity", "300", "--depth", "0.3", "--obliquity", "20"], "--obliquity"),
    (["shot", "--depth", "0.3"], "--depth"),
    (["shot", "--stress", "hoop"], "--stress"),
    (["shot", "--velocity", "-5"], "velocity"),
    (["shot", "--velocity", "inf"], "velocity"),
    (["scene"], "scene"),
])
def test_bad_input_is_refused_in_one_line(capsys, tmp_path, argv, name):
    line = refused(capsys, tmp_path, ["view", *argv, "--out", tmp_path / "v"], name)
    assert "in [" in line or "goes with" in line or "given" in line or "choose" in line \
        or "in (" in line, line


def test_without_pyvista_the_command_names_the_extra(capsys, tmp_path, monkeypatch):
    """A machine without pyvista: one line telling the user to install the extra, exit 2,
    nothing written, nothing computed."""
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "pyvista" else real(name, *a))
    for argv in (["fields", "--velocity", "300", "--depth", "0.3"], ["shot"]):
        line = refused(capsys, tmp_path, ["view", *argv, "--out", tmp_path / "v"],
                       'pip install "cavex[view]"')
        assert "pyvista" in line


@needs_rendering
def test_without_an_offscreen_context_one_line(tmp_path):
    """VTK made to take OSMesa (``VTK_DEFAULT_OPENGL_WINDOW``) where its library is not found
    (the names patched to none that exists): one line, exit 2, nothing written, where
    rendering would end the process with a segmentation fault (seen)."""
    import os

    out = tmp_path / "v"
    probe = ("import sys; from cavex.verification.commands import view; "
             "view.OSMESA_LIBRARIES = ('libcavex-no-such-osmesa.so',); "
             "from cavex.verification.cli import main; "
             f"print(main(['view', 'fields', '--velocity', '300', '--depth', '0.3', '--out', "
             f"{str(out)!r}]))")
    env = {**os.environ, "VTK_DEFAULT_OPENGL_WINDOW": "vtkOSOpenGLRenderWindow"}
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, env=env)
    assert done.returncode == 0 and done.stdout.splitlines() == ["2"], done
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("cavex: error: no off-screen OpenGL"), lines
    assert not out.exists()


def test_the_command_module_loads_no_3d_engine():
    """``cavex --help`` builds every command's parser, so the view module's import must not
    load pyvista or VTK (the other commands stay fast, issue 33)."""
    probe = ("import sys; import cavex.verification.commands.view; "
             "from cavex.verification.cli import build_parser; build_parser(); "
             "print(sorted(m for m in ('pyvista', 'vtk', 'vtkmodules') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=True)
    assert done.stdout.split("\n")[-2] == "[]"


def test_zone_spans_follow_the_codes():
    from cavex.verification.report.view_scenes import zone_codes, zone_spans

    sigma_theta = np.array([50e6, 20e6, -0.995e6, -0.99e6, -0.5e6, 1e6])
    plastic = np.array([0.1, 1e-3, 1e-4, 0.0, 0.0, 0.0])
    layer = np.array([0, 0, 0, 0, 1, 1])
    codes = zone_codes(sigma_theta, plastic, layer, [1e6, None])
    assert codes.tolist() == [2, 2, 1, 1, 0, 0]
    assert zone_spans(np.arange(7.0), codes) == [
        {"zone": "plastic", "from_m": 0.0, "to_m": 2.0},
        {"zone": "cracked", "from_m": 2.0, "to_m": 4.0},
        {"zone": "elastic", "from_m": 4.0, "to_m": 6.0}]


# -- the pictures --------------------------------------------------------------------------

@needs_rendering
def test_fields_picture(capsys, tmp_path, rendering):
    """The paper's target at 300 m/s, 0.3 m: a plastic zone round the cavity, then elastic;
    the FE's own plastic radius lies in the last plastic cell; the picture is 1400 x 700 px,
    about half drawn, with the plastic zone's orange in it and no cracked blue (no layer has
    a tensile strength)."""
    from cavex.verification.report.view_scenes import FIELDS_WINDOW, ZONE_COLOURS

    out = tmp_path / "v"
    document = view_json(capsys, "fields", "--velocity", "300", "--depth", "0.3", "--out", out)
    assert offending_keys(document) == []
    assert document["layers"] == ["concrete", "macadam", "soil"]
    zones = document["zones"]
    assert [z["zone"] for z in zones] == ["plastic", "elastic"]
    assert zones[0]["from_m"] == pytest.approx(document["cavity_radius_m"], rel=1e-9)
    assert all(a["to_m"] == b["from_m"] for a, b in zip(zones, zones[1:], strict=False))
    assert zones[-1]["to_m"] == pytest.approx(document["radius_shown_m"], rel=1e-12)
    b = document["fe_plastic_radius_m"]
    # the FE places b between its last yielded point and the next (fem/fields.py): inside the
    # plastic zone's last element, whose nodes are 8 % apart there (the mesh's growth)
    assert zones[0]["to_m"] / 1.2 < b <= zones[0]["to_m"]
    assert document["radius_shown_m"] == pytest.approx(3.0 * b, rel=1e-12)  # the default extent
    assert document["shown_cells"] > 10
    assert document["beyond_view"] == ["macadam from r = 0.41 m", "soil from r = 0.86 m"]
    image = pixels(out / "fields.png")
    assert image.shape[:2] == (FIELDS_WINDOW[1], FIELDS_WINDOW[0])
    assert {"width_px": FIELDS_WINDOW[0], "height_px": FIELDS_WINDOW[1]}.items() <= \
        document["image"].items()
    assert 0.2 < drawn_share(image) < 0.8
    right = image[:, FIELDS_WINDOW[0] // 2:]
    assert share_near(right, ZONE_COLOURS[2]) > 0.005  # the plastic zone, seen
    assert share_near(right, ZONE_COLOURS[1], 0.05) < 1e-4  # no cracked zone
    left = image[:, :FIELDS_WINDOW[0] // 2]
    assert left.std() > 0.1  # the colour map, not one colour
    saved = json.loads((out / "view.json").read_text())
    assert saved["zones"] == zones and saved["cavex_version"]
    assert sorted(p.name for p in out.iterdir()) == ["fields.png", "view.json"]


@needs_rendering
def test_fields_picture_of_a_cracked_concrete(capsys, tmp_path, rendering):
    """A concrete layer with a 1 MPa tensile strength expanded slowly (20 m/s): the FE's hoop
    stress reaches the cut-off outside the plastic zone, and the picture shows the cracked
    zone's blue beside the plastic orange."""
    from cavex.verification.report.view_scenes import FIELDS_WINDOW, ZONE_COLOURS

    text = (tmp_path / "c.toml")
    source = subprocess.run([sys.executable, "-m", "cavex", "config", "--default"],
                            capture_output=True, text=True, check=True).stdout
    text.write_text(source.replace("tau = 25e6\n", "tau = 25e6\ntensile_strength = 1e6\n", 1))
    out = tmp_path / "v"
    document = view_json(capsys, "--config", text, "fields", "--velocity", "20", "--depth",
                         "0.3", "--stress", "hoop", "--out", out)
    names = [z["zone"] for z in document["zones"]]
    assert names[:2] == ["plastic", "cracked"], names
    image = pixels(out / "fields.png")
    right = image[:, FIELDS_WINDOW[0] // 2:]
    assert share_near(right, ZONE_COLOURS[1]) > 0.005
    assert share_near(right, ZONE_COLOURS[2]) > 0.0005


@needs_rendering
def test_shot_picture_debonded(capsys, tmp_path, rendering):
    """An oblique debonded shot: the picture (1200 x 850 px) shows the red path and the navy
    bodies; the summary names the layers and the debonded interfaces, as the title does."""
    from cavex.verification.report.view_scenes import SHOT_WINDOW

    out = tmp_path / "v"
    document = view_json(capsys, "shot", "--velocity", "600", "--obliquity", "20",
                         "--interfaces", "debonded", "--out", out)
    assert offending_keys(document) == []
    assert document["layers"] == ["concrete", "macadam", "soil"]
    assert document["settings"]["interfaces"][:2] == ["debonded", "debonded"]
    assert document["settings"]["obliquity_deg"] == 20.0
    image = pixels(out / "shot.png")
    assert image.shape[:2] == (SHOT_WINDOW[1], SHOT_WINDOW[0])
    assert 0.1 < drawn_share(image) < 0.8
    assert blue_share(image) > 0.002  # the bodies (0.5 % when looked at)
    assert red_share(image) > 5e-4  # the path beyond the legend's mark (0.1 % looked at)


@needs_rendering
def test_shot_picture_normal_incidence_one_layer(capsys, tmp_path, rendering):
    """The degenerate case: normal incidence into a one-layer target (its own layer name):
    the summary has one layer and no interface, the shot ends in it, the picture is drawn."""
    source = subprocess.run([sys.executable, "-m", "cavex", "config", "--default"],
                            capture_output=True, text=True, check=True).stdout
    first = source.index("[[layers]]", source.index("[[layers]]") + 1)
    one = source[:first].replace('name = "concrete"', 'name = "apron slab"')
    one = one.replace("thickness = 0.65", "")
    config = tmp_path / "one.toml"
    config.write_text(one)
    out = tmp_path / "v"
    document = view_json(capsys, "--config", config, "shot", "--velocity", "300", "--out", out)
    assert document["layers"] == ["apron slab"] and document["interface_depths_m"] == []
    assert document["end"]["state"] == "stopped"
    assert abs(document["end"]["nose_tip_m"][0]) < 1e-9  # no drift at normal incidence
    image = pixels(out / "shot.png")
    assert 0.05 < drawn_share(image) < 0.8
    assert blue_share(image) > 0.002


def test_bodies_drawn_apart_along_the_path():
    """The shot's bodies: at most 6, at least 2, equally spaced along the path and at least
    1.15 body lengths apart when fewer than 6 fit (a straight normal shot)."""
    from cavex.verification.report.view_scenes import body_instants

    t = np.linspace(0.0, 1e-3, 201)
    depth = 0.4 * (1.0 - (1.0 - t / t[-1]) ** 2)  # decelerating, 0.4 m in all
    history = {"t_s": t, "cg_x_m": 0 * t, "cg_y_m": 0 * t, "cg_z_m": depth}
    for length, count in ((0.1, 4), (0.01, 6), (1.0, 2)):
        instants = body_instants(history, length)
        assert len(instants) == count
        positions = np.interp(instants, t, depth)
        assert positions[0] == 0.0 and positions[-1] == pytest.approx(0.4, rel=1e-12)
        gaps = np.diff(positions)
        assert np.allclose(gaps, gaps[0], rtol=1e-3)  # equal along the path (interpolated)
        if count < 6 and count > 2:
            assert gaps.min() >= 1.15 * length


def test_bad_input_loads_no_numerical_library():
    """A refused ``cavex view`` loads none of the numerical or drawing libraries (the import
    rule of commands/__init__.py): bad input answers at once."""
    probe = ("import sys; from cavex.verification.cli import main; "
             "codes = [main(['view', 'fields', '--velocity', '300']), "
             "main(['view', 'shot', '--velocity', '-3'])]; "
             "print(codes, sorted(m for m in ('numba', 'scipy', 'matplotlib', 'pyvista', 'vtk', "
             "'xarray', 'skfem', 'dask', 'pandas') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=True)
    assert done.stdout.splitlines()[-1] == "[2, 2] []"


@needs_rendering
def test_view_says_a_ricochet_above_the_surface_and_warns_on_stderr(tmp_path, capsys,
                                                                    rendering):
    """A ricochet ends above the surface: "nose tip 0.0477 m above the surface" (it said
    "-0.0477 m deep"). A fields run beyond 1200 m/s warns on stderr, as cavex fem does (the
    warning was a line of the text on stdout)."""
    code, out, err = run(capsys, "view", "shot", "--obliquity", "80", "--out", tmp_path / "s")
    assert code == 0 and "end: ricochet, nose tip 0.0477 m above the surface" in out
    code, out, err = run(capsys, "view", "fields", "--velocity", "1300", "--depth", "0.3",
                         "--out", tmp_path / "f")
    assert code == 0 and "warning" not in out
    assert err.startswith("cavex view: warning: V = 1300 m/s is beyond 1200 m/s")
