"""3-D picture of the layered sphere cut open, coloured by the FE ``sigma_r`` (pyvista).

The spherically symmetric FE fields (functions of the current radius only) are revolved into a
structured spherical grid, half of it is clipped away, and the cut face shows ``sigma_r`` with
the layer interfaces (black circles) and the FE elastic-plastic boundary (red circle) drawn on
it; the plastic zone is also shown as a translucent red shell.
"""

import os
from pathlib import Path

import numpy as np

from cavex.analytic.cavity import cavity_solution
from cavex.analytic.geometry import spherical_problem
from cavex.fem.expansion import expand_cavity

MAX_RADIUS_FACTOR = 12.0  # the picture shows r <= 12 a at most


def picture_depth(target, projectile, velocity, depths):
    """First depth of ``depths`` where the derived dynamic plastic zone spans two layers.

    Falls back to the middle depth when it never does.
    """
    for L in depths:
        layers, interfaces = spherical_problem(target, projectile, float(L))
        state = cavity_solution(layers, interfaces, velocity, projectile.r, boundary="dynamic")
        if len(state.plastic_zones) >= 2:
            return float(L)
    return float(depths[len(depths) // 2])


def fe_fields(target, projectile, velocity, depth, numerics=None, nu=None):
    """One FE run at (V, L); returns the radial fields and the radii to draw.

    Returns
    -------
    dict
        ``r``, ``sigma_r`` (Pa), ``plastic_strain`` (sorted by radius), ``a`` (cavity radius),
        ``b`` (FE plastic radius), ``interfaces`` (final interface radii), ``layers`` (names).
    """
    from dataclasses import replace

    layers, interfaces = spherical_problem(target, projectile, depth)
    if nu is not None:
        layers = [replace(m, nu=nu) for m in layers]
    result = expand_cavity(layers, interfaces, velocity, projectile.r,
                           **{**(numerics or {}), "error_estimate": False})
    order = np.argsort(result.fields["r"])
    return {"r": result.fields["r"][order], "sigma_r": result.fields["sigma_r"][order],
            "plastic_strain": result.fields["plastic_strain"][order], "a": projectile.r,
            "b": result.plastic_radius, "interfaces": list(result.interfaces_final),
            "layers": [m.name for m in layers], "cavity_stress": result.cavity_stress}


def picture_extent(fields):
    """Outer radius of the picture: beyond ``b`` and the first interface, at most 12 a."""
    a = fields["a"]
    first = min(fields["interfaces"], default=fields["b"])
    return min(MAX_RADIUS_FACTOR * a, 1.3 * max(fields["b"], first, 2.0 * a))


def spherical_grid(fields, n_r=60, n_theta=48, n_phi=72):
    """Structured grid of the ball ``a <= r <= extent`` with ``sigma_r`` (MPa) interpolated."""
    import pyvista as pv

    a, outer = fields["a"], picture_extent(fields)
    r = np.geomspace(a, outer, n_r)
    theta = np.linspace(0.0, np.pi, n_theta)
    phi = np.linspace(0.0, 2.0 * np.pi, n_phi)
    R, T, P = np.meshgrid(r, theta, phi, indexing="ij")
    grid = pv.StructuredGrid(R * np.sin(T) * np.cos(P), R * np.sin(T) * np.sin(P), R * np.cos(T))
    radius = np.linalg.norm(grid.points, axis=1)
    grid["sigma_r (MPa)"] = np.interp(radius, fields["r"], fields["sigma_r"]) / 1e6
    grid["plastic"] = (radius <= fields["b"]).astype(float)
    return grid


def circle(radius, n=181):
    """Circle of ``radius`` in the cut plane ``y = 0`` (x-z plane) as a polyline."""
    import pyvista as pv

    t = np.linspace(0.0, 2.0 * np.pi, n)
    points = np.column_stack([radius * np.cos(t), np.zeros(n), radius * np.sin(t)])
    return pv.lines_from_points(points)


def render_sphere(fields, path, title):
    """Render the cut-open sphere to ``path`` (PNG) off-screen; raises if rendering fails."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    grid = spherical_grid(fields)
    half = grid.clip(normal=(0.0, -1.0, 0.0), origin=(0.0, 0.0, 0.0))
    plotter = pv.Plotter(off_screen=True, window_size=(900, 750))
    plotter.add_mesh(half, scalars="sigma_r (MPa)", cmap="inferno", log_scale=True,
                     scalar_bar_args={"title": "sigma_r (MPa)", "vertical": True,
                                      "position_x": 0.8, "position_y": 0.1, "width": 0.08,
                                      "height": 0.7, "fmt": "%.0f"})
    outer = picture_extent(fields)
    for h in fields["interfaces"]:
        if h < outer:
            plotter.add_mesh(circle(h), color="black", line_width=4)
    if fields["b"] < outer:
        plotter.add_mesh(circle(fields["b"]), color="red", line_width=5)
        shell = pv.Sphere(radius=fields["b"], theta_resolution=60, phi_resolution=30)
        plotter.add_mesh(shell.clip(normal=(0.0, -1.0, 0.0)), color="red", opacity=0.25)
    plotter.add_text(title, font_size=9)
    plotter.camera_position = [(1.6 * outer, -3.0 * outer, 1.4 * outer), (0, 0, 0), (0, 0, 1)]
    plotter.reset_camera()
    plotter.camera.zoom(1.1)
    tmp = Path(path).with_name(f".{Path(path).name}.{os.getpid()}.tmp.png")
    try:  # a killed run never leaves a partial picture
        plotter.screenshot(str(tmp))
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    plotter.close()
    return path


def first_line(exc):
    """``"ExceptionType: first line of the message"``."""
    lines = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {lines[0] if lines else ''}".rstrip(": ")


def make_picture(target, projectile, velocity, depth, path, numerics=None, nu=None):
    """FE run and picture; returns ``(path or None, one-line message)``.

    The message says what is shown, or in one line why no picture was rendered.
    """
    fields = fe_fields(target, projectile, velocity, depth, numerics, nu)
    names = ", ".join(n or "?" for n in fields["layers"])
    caption = (f"V = {velocity:g} m/s, L = {depth:.3f} m: layers {names}; black: interfaces at "
               + ", ".join(f"{h * 1e3:.1f}" for h in fields["interfaces"]
                           if h < picture_extent(fields))
               + f" mm; red: FE plastic boundary b = {fields['b'] * 1e3:.1f} mm "
               f"(cavity a = {fields['a'] * 1e3:.1f} mm)")
    try:
        render_sphere(fields, path, f"sigma_r, V = {velocity:g} m/s, L = {depth:.3f} m")
    except Exception as exc:  # noqa: BLE001 - any renderer failure (no OpenGL, VTK) is reported
        return None, f"3-D picture not rendered ({first_line(exc)})"
    return path, caption
