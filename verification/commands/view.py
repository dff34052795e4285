"""``cavex view``: 3-D pictures rendered off screen with pyvista (``pip install "cavex[view]"``).

``cavex view fields --velocity V --depth L``: the FE fields of the spherical cavity problem at
nose depth L (the run of ``cavex fem``, :func:`cavex.verification.commands.fem.job`) revolved
into 3-D, the expanded sphere cut open, coloured by a stress, with the elastic, cracked and
plastic zones. ``cavex view shot``: the oblique shot through the layered block (the run of
``cavex trajectory``, :func:`cavex.verification.commands.trajectory.trajectory_job`, with the
derived resistance and trajectory's defaults), the layers coloured and named, the path and the
body at 6 instants. Each writes ``fields.png`` or ``shot.png`` and ``view.json`` (the summary)
into ``--out``; the pictures: :mod:`cavex.verification.report.view_scenes`.

pyvista (and VTK) is imported only by this command, after the checks; the other commands never
load it (``tests/test_command_figures.py``). Without pyvista the command stops with one line
naming the extra; without an off-screen OpenGL context (VTK >= 9.4 finds EGL or OSMesa where
there is no display) with one line saying so; both exit 2 before anything is computed.
"""

import importlib.util
import math
import os
import sys
import tempfile
import textwrap
from pathlib import Path

from cavex.errors import CavexInputError, require
from cavex.materials import BONDINGS, MAX_VELOCITY
from cavex.verification.commands.shared_options import add_config_option
from cavex.verification.output.files import write_text_atomic
from cavex.verification.output.json_document import json_text
from cavex.verification.output.paths import check_output_dir, write_staged

HELP = "3-D pictures off screen with pyvista: the FE fields, the oblique shot (cavex[view])"
SCENES = ("fields", "shot")
DEFAULT_DIR = "results/view"
INSTALL = 'pyvista is not installed: pip install "cavex[view]" (pyvista and VTK >= 9.4)'
STRESS_CHOICES = ("deviator", "radial", "hoop")
#: the fields picture's outer radius in plastic radii: from just past the plastic front to
#: a far field whose stresses are a few thousandths of the wall's (elastic decay as r^-3)
EXTENT_RANGE = (1.2, 50.0)
DEFAULT_EXTENT = 3.0
#: the options of one scene only, with their defaults (given otherwise: refused)
FIELDS_ONLY = {"depth": None, "stress": "deviator", "extent": DEFAULT_EXTENT, "nu": None}
SHOT_ONLY = {"obliquity": 0.0, "attack": 0.0, "interfaces": None}


def add_arguments(parser):
    """The options of ``cavex view``."""
    parser.add_argument("scene", choices=SCENES, help="fields: the FE fields of the cavity "
                        "at nose depth --depth (as cavex fem); shot: the oblique shot through "
                        "the layered block (as cavex trajectory)")
    add_config_option(parser)
    parser.add_argument("--velocity", type=float, help="expansion velocity V (fields, m/s; "
                        "required) or striking speed (shot, m/s; default: the projectile's V0)")
    parser.add_argument("--depth", type=float, help="fields: nose-tip depth L (m; required)")
    parser.add_argument("--stress", choices=STRESS_CHOICES,
                        help="fields: the stress the sphere is coloured by (deviator, the "
                        "default: |sigma_r - sigma_theta|, the von Mises stress of the "
                        "spherical state)")
    parser.add_argument("--extent", type=float,
                        help="fields: the picture's outer radius in FE plastic radii (in "
                        f"[{EXTENT_RANGE[0]:g}, {EXTENT_RANGE[1]:g}]; default "
                        f"{DEFAULT_EXTENT:g})")
    parser.add_argument("--nu", type=float, help="fields: Poisson's ratio for every layer "
                        "(default: the file's)")
    parser.add_argument("--obliquity", type=float,
                        help="shot: angle of the velocity from the target normal (deg; "
                        "default 0)")
    parser.add_argument("--attack", type=float,
                        help="shot: angle of attack in the plane of obliquity (deg; default 0)")
    parser.add_argument("--interfaces", choices=BONDINGS, default=None,
                        help="shot: every interface bonded or debonded (default: each layer's "
                        "'bottom' key in the config, bonded)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.add_argument("--out", default=DEFAULT_DIR, help="output folder")


def check_scene_options(args):
    """Refuse an option of the other scene (given at all: at its default value too, which was
    let through), then set the scene's own options not given to their defaults."""
    other = SHOT_ONLY if args.scene == "fields" else FIELDS_ONLY
    for name in other:
        if getattr(args, name) is not None:
            raise CavexInputError(f"option '--{name}' goes with 'cavex view "
                                  f"{'shot' if args.scene == 'fields' else 'fields'}', not "
                                  f"with 'cavex view {args.scene}'")
    for name, default in (FIELDS_ONLY if args.scene == "fields" else SHOT_ONLY).items():
        if getattr(args, name) is None:
            setattr(args, name, default)


def require_pyvista():
    """Refuse (one line, exit 2) where pyvista is not installed: found without importing it."""
    if importlib.util.find_spec("pyvista") is None:
        raise CavexInputError(INSTALL)


#: the OSMesa libraries VTK's vtkOSOpenGLRenderWindow loads (Mesa's sonames)
OSMESA_LIBRARIES = ("libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so")
NO_CONTEXT = ("no off-screen OpenGL context for VTK: it needs a display, EGL or OSMesa (e.g. "
              "Debian's libegl1 with libegl-mesa0 and libgl1-mesa-dri, or libosmesa6)")


def loadable(names):
    """Whether one of the shared libraries ``names`` loads (``ctypes``)."""
    import ctypes

    for name in names:
        try:
            ctypes.CDLL(name)
            return True
        except OSError:
            continue
    return False


def require_offscreen():
    """Refuse (one line, exit 2) where VTK has no off-screen OpenGL context; returns the
    render window class VTK chose. Without a display VTK >= 9.4 takes EGL where it
    initialises, else OSMesa (docs/fem.md "cavex view"); it does not check that OSMesa's
    library is there (its window then claims OpenGL support and rendering ends the process
    with a segmentation fault, seen with ``VTK_DEFAULT_OPENGL_WINDOW=vtkOSOpenGLRenderWindow``
    on a machine without libOSMesa), so that is checked here. Its complaint that there is no
    X server is dropped (no display is what off-screen rendering is for)."""
    import vtk

    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_ERROR)
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(True)
    name = window.GetClassName()
    if name == "vtkOSOpenGLRenderWindow" and not loadable(OSMESA_LIBRARIES):
        raise CavexInputError(NO_CONTEXT)
    if not window.SupportsOpenGL():
        raise CavexInputError(NO_CONTEXT)
    return name


def run(args, target, projectile):
    """Checks (the scene's options, pyvista and an off-screen context), the run, the files
    (every file or none)."""
    check_scene_options(args)
    folder = check_output_dir(args.out, "out")
    if args.scene == "fields":
        from cavex.verification.commands.options import refuse_debonded

        refuse_debonded(target, "view fields")  # the FE's spherical problem is bonded
        require(args.velocity is not None, "velocity", "given for 'cavex view fields' (m/s)",
                args.velocity)
        require(args.depth is not None, "depth", "given for 'cavex view fields' (m)", args.depth)
        low, high = EXTENT_RANGE
        require(math.isfinite(args.extent) and low <= args.extent <= high, "extent",
                f"in [{low:g}, {high:g}] plastic radii", args.extent)
    else:
        speed = projectile.V0 if args.velocity is None else args.velocity
        require(math.isfinite(speed) and 0.0 < speed <= MAX_VELOCITY, "velocity",
                f"in (0, {MAX_VELOCITY:g}] m/s", speed)
    require_pyvista()
    require_offscreen()
    if args.scene == "fields":
        result = fields_job(target, projectile, args.depth, args.velocity, nu=args.nu,
                            stress=args.stress, extent=args.extent)
    else:
        result = shot_job(target, projectile, speed, args.obliquity, args.attack,
                          args.interfaces)
    result["outputs"] = write_staged(folder, lambda stage: write_outputs(result, stage),
                                     replaces=OUTPUTS)
    for warning in result.get("fe", {}).get("warnings", ()):  # on stderr, as cavex fem does
        print(f"cavex view: warning: {warning}", file=sys.stderr)
    return result


def tip_depth_words(z):
    """The nose tip's depth ``z`` (m) in words: ``m deep``, or ``m above the surface`` for a
    body that left the target (a ricochet)."""
    return f"{z:.4f} m deep" if z >= 0.0 else f"{-z:.4f} m above the surface"


#: every file ``cavex view`` can write (a rerun into the folder replaces them all)
OUTPUTS = ("fields.png", "shot.png", "view.json")


def fields_job(target, projectile, depth, velocity, *, nu=None, stress="deviator",
               extent=DEFAULT_EXTENT):
    """The FE run of ``cavex fem`` (:func:`cavex.verification.commands.fem.job`, its fields
    written to a temporary folder and read back from ``fem_final.vtu``) cut to the picture:
    the current radii ``r = R + u`` of the element nodes out to ``extent`` plastic radii (the
    last element cut there; the FE mesh's outer radius at most), each element's
    ``sigma_r``, ``sigma_theta``, ``deviator = |sigma_r - sigma_theta|`` (Pa) and zone
    (:func:`~cavex.verification.report.view_scenes.zone_codes`), the zone spans, and the
    interfaces in and beyond the picture."""
    import meshio
    import numpy as np

    from cavex.verification.commands import fem
    from cavex.verification.report.view_scenes import ZONES, zone_codes, zone_spans

    require(stress in STRESS_CHOICES, "stress", " or ".join(STRESS_CHOICES), stress)
    with tempfile.TemporaryDirectory() as scratch:
        run = fem.job(target, projectile, depth, velocity, nu=nu, fields=scratch)
        mesh = meshio.read(Path(scratch) / "fem_final.vtu")
    radii = mesh.points[:, 0] + mesh.point_data["u_m"][:, 0]
    cells = {name: np.asarray(mesh.cell_data[f"{name}_Pa"][0], dtype=float)
             for name in ("sigma_r", "sigma_theta")}
    plastic = np.asarray(mesh.cell_data["plastic_strain"][0], dtype=float)
    layer = np.asarray(mesh.cell_data["layer"][0]).astype(int)
    cells["deviator"] = np.abs(cells["sigma_r"] - cells["sigma_theta"])
    outer = min(extent * run["fe_plastic_radius_m"], float(radii[-1]))
    keep = int(np.searchsorted(radii, outer))  # nodes radii[:keep] lie inside
    shown = np.append(radii[:keep], outer)
    cells = {k: v[:keep] for k, v in cells.items()}
    codes = zone_codes(cells["sigma_theta"], plastic[:keep], layer[:keep],
                       [m.tensile_strength for m in target.layers])
    spans = zone_spans(shown, codes)
    interfaces = [float(r) for r in run["interface_radii_final_m"]]
    names = target.layer_names()
    beyond = [f"{names[k + 1]} from r = {r:.3g} m" for k, r in enumerate(interfaces)
              if r >= outer]
    fronts = ", ".join(f"{s['zone']} to {s['to_m']:.3g} m" for s in spans)
    titles = [[f"V = {velocity:g} m/s, nose depth {depth:g} m, cavity radius "
               f"{run['cavity_radius_m']:.3g} m", f"layers: {', '.join(names)} (FE, cavex fem)",
               f"radius shown {outer:.3g} m" + ("; beyond it: " + ", ".join(beyond)
                                                 if beyond else "")],
              [f"zones: {fronts}", "cracked: hoop stress at a layer's tension cut-off",
               "plastic: plastic strain > 0", "rings: zone fronts (black), interfaces (grey)"]]
    titles = ["\n".join(textwrap.fill(line, 64) for line in lines) for lines in titles]
    return {"scene": "fields", "fe": run, "stress": stress, "extent_plastic_radii": extent,
            "radius_shown_m": outer, "radii_m": shown.tolist(),
            "cells": {k: v.tolist() for k, v in cells.items()},
            "zone_codes": codes.tolist(), "zones": spans,
            "zones_present": [ZONES[c] for c in sorted(set(codes.tolist()))],
            "interfaces_in_view_m": [r for r in interfaces if r < outer],
            "beyond_view": beyond, "layers": names, "titles": titles}


def shot_job(target, projectile, speed, obliquity=0.0, attack=0.0, interfaces=None):
    """The oblique shot of ``cavex trajectory`` (:func:`~cavex.verification.commands.
    trajectory.trajectory_job`: the derived resistance, the default contact ramp, no
    progress bar) with ``interfaces`` (bonded, debonded or None: the config's), the striking
    conditions checked by :class:`~cavex.analytic.penetration.strike.Strike`."""
    from cavex.analytic.penetration.strike import Strike
    from cavex.verification.commands.trajectory import trajectory_job

    strike = Strike(speed, obliquity, attack)
    target = target.with_interfaces(interfaces)
    job = trajectory_job(target, projectile, strike, "derived")
    return {"scene": "shot", **job}


def write_outputs(result, out):
    """The picture (``fields.png`` or ``shot.png``) and ``view.json`` (:func:`summary`) into
    ``out``; returns the paths written."""
    from cavex.verification.report.view_scenes import fields_picture, shot_picture

    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    picture = folder / f"{result['scene']}.png"
    draw = fields_picture if result["scene"] == "fields" else shot_picture
    result["image"] = {"file": picture.name, **draw(result, picture)}
    path = folder / "view.json"
    document = summary(result)
    write_text_atomic(path, json_text({k: v for k, v in document.items() if k != "outputs"})
                      + "\n")
    return [str(picture), str(path)]


def summary(result):
    """What ``cavex view --json`` prints (and ``view.json`` holds): the scene, what the picture
    shows and its size, and the files written."""
    if result["scene"] == "fields":
        fe = result["fe"]
        document = {"scene": "fields", "velocity_m_s": fe["velocity_m_s"],
                    "depth_m": fe["depth_m"], "layers": result["layers"],
                    "stress": result["stress"],
                    "cavity_radius_m": fe["cavity_radius_m"],
                    "fe_plastic_radius_m": fe["fe_plastic_radius_m"],
                    "fe_sigma_r_Pa": fe["fe_sigma_r_Pa"],
                    "radius_shown_m": result["radius_shown_m"],
                    "shown_cells": len(result["zone_codes"]),
                    "zones": result["zones"], "zones_present": result["zones_present"],
                    "interfaces_in_view_m": result["interfaces_in_view_m"],
                    "beyond_view": result["beyond_view"], "warnings": fe["warnings"]}
    else:
        from cavex.verification.commands.trajectory import run_summary

        main = run_summary(result["runs"]["runway"])
        target = result["target"]
        document = {"scene": "shot", "settings": result["settings"],
                    "layers": target.layer_names(),
                    "interface_depths_m": list(target.interface_depths),
                    "end": main["end"], "phases": main["phases"]}
    if "image" in result:
        document["image"] = result["image"]
    return document if "outputs" not in result else {**document, "outputs": result["outputs"]}


def text(result):
    """What the picture shows, in a few lines, and the files written."""
    document = summary(result)
    if document["scene"] == "fields":
        lines = [f"FE fields at V = {document['velocity_m_s']:g} m/s, nose depth "
                 f"{document['depth_m']:g} m ({', '.join(document['layers'])}), coloured by "
                 f"{document['stress']}; radius shown {document['radius_shown_m']:.4g} m",
                 "zones: " + ", ".join(f"{z['zone']} {z['from_m']:.4g}-{z['to_m']:.4g} m"
                                       for z in document["zones"])]
        if document["beyond_view"]:
            lines.append("beyond the picture: " + "; ".join(document["beyond_view"]))
    else:
        from cavex.verification.report.trajectory_figures import shot_title

        end = document["end"]
        lines = [shot_title(document), f"layers: {', '.join(document['layers'])}",
                 f"end: {end['state']}, nose tip {tip_depth_words(end['nose_tip_m'][2])}"]
    image = document.get("image", {})
    if image:
        lines.append(f"rendered {image['width_px']} x {image['height_px']} px off screen "
                     f"({image['render_window']})")
    return "\n".join(lines + ["wrote: " + ", ".join(document.get("outputs", []))])
