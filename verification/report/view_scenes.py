"""The 3-D pictures of ``cavex view``, rendered off screen with pyvista (VTK) to PNG.

- :func:`fields_picture`: the FE fields of the spherical cavity problem (``cavex fem``'s run)
  revolved into 3-D: the expanded sphere with a quarter cut away, the left view coloured by a
  stress, the right by the response zones (elastic, cracked, plastic), the zone fronts and the
  layer interfaces as rings on the cut faces;
- :func:`shot_picture`: the oblique shot (``cavex trajectory``'s run) in the layered block cut
  open along the plane of obliquity, each layer a coloured translucent slab named in the
  legend, the centre of mass's path and the body (the outline revolved about its axis) at up
  to 6 points equally spaced along the path, not overlapping (:func:`body_instants`).

The geometry is plain numpy (:func:`sphere_grid`, :func:`revolved_body`); pyvista is
imported inside the functions that render (``pip install "cavex[view]"``): no other module of
cavex imports it. Display coordinates are the target's ``(x, -y, -z)`` (a half turn about x,
so that depth ``z`` points down and the picture is not mirrored).
"""

import numpy as np

#: The zones of the fields picture, in their code order (per radial cell), with colours
ZONES = ("elastic", "cracked", "plastic")
ZONE_COLOURS = ("#9a9a9a", "#2a63c2", "#e07020")  # readable as legend text on white
#: The hoop stress within this fraction of a layer's ``-tensile_strength`` is "at the tension
#: cut-off" (cracked). The cut-off holds the Kirchhoff hoop stress ``J sigma_theta`` at
#: ``-f_t``; the Cauchy stress written differs by the volume change ``|J - 1| <= p / K``,
#: 1e-3 for the pressures of a cracked zone (tens of MPa over K of tens of GPa), so 2 % is
#: above it and far below the gap to the next cell's (an elastic cell's hoop stress falls off
#: as r^-3 away from the crack front).
CUTOFF_FRACTION = 0.98
STRESSES = {"radial": ("sigma_r", "sigma_r (MPa, compression +)"),
            "hoop": ("sigma_theta", "sigma_theta (MPa, compression +)"),
            "deviator": ("deviator", "von Mises stress abs(sigma_r - sigma_theta) (MPa)")}
FIELDS_WINDOW = (1400, 700)  # px: the two views side by side
SHOT_WINDOW = (1200, 850)  # px
BODY_INSTANTS = 6  # the body drawn at most this many times along the path
LAYER_COLOURS = ("#8a8a8a", "#b07a3e", "#6f9a2e", "#5a5a5a")  # top down; readable legend text


def zone_codes(sigma_theta, plastic_strain, layer, tensile_strengths):
    """Per radial cell the index into :data:`ZONES`: cracked where the cell's layer has a
    tensile strength ``f_t`` and its hoop stress is at the cut-off (``sigma_theta <=
    -CUTOFF_FRACTION f_t``, compression positive), else plastic where the accumulated plastic
    strain is positive, else elastic."""
    f_t = np.array([np.inf if f is None else f for f in tensile_strengths])[layer]
    cracked = np.isfinite(f_t) & (sigma_theta <= -CUTOFF_FRACTION * np.where(
        np.isfinite(f_t), f_t, 0.0))
    return np.where(cracked, 1, np.where(plastic_strain > 0.0, 2, 0))


def zone_spans(radii, codes):
    """``[{"zone", "from_m", "to_m"}]``: the runs of equal zone code along the cells between
    ``radii`` (``len(codes) + 1`` nodes), inside out."""
    spans, start = [], 0
    for k in range(1, len(codes) + 1):
        if k == len(codes) or codes[k] != codes[start]:
            spans.append({"zone": ZONES[int(codes[start])], "from_m": float(radii[start]),
                          "to_m": float(radii[k])})
            start = k
    return spans


def sphere_grid(radii, polar=(0.0, 180.0), azimuth=(90.0, 360.0), step_deg=7.5):
    """``(x, y, z)`` arrays of shape ``(len(radii), n_polar, n_azimuth)``: the spherical shells
    at ``radii`` (m) over the polar angles ``polar`` and azimuths ``azimuth`` (deg, ranges),
    nodes about ``step_deg`` apart."""
    r = np.asarray(radii, dtype=float)[:, None, None]
    n_theta = max(2, round((polar[1] - polar[0]) / step_deg) + 1)
    n_phi = max(2, round((azimuth[1] - azimuth[0]) / step_deg) + 1)
    theta = np.radians(np.linspace(*polar, n_theta))[None, :, None]
    phi = np.radians(np.linspace(*azimuth, n_phi))[None, None, :]
    return (r * np.sin(theta) * np.cos(phi), r * np.sin(theta) * np.sin(phi),
            r * np.cos(theta) * np.ones_like(phi))


#: The cut-away sphere as two pieces of shells ``(polar, azimuth)`` ranges (deg): the octant
#: ``x, y, z > 0`` is cut away, its three faces (azimuth 0 and 90 deg above the equator, the
#: equator's quarter) show the radial fields
CUT_AWAY = (((0.0, 180.0), (90.0, 360.0)), ((90.0, 180.0), (0.0, 90.0)))


def octant_rings(radius, points=25):
    """The ring of ``radius`` (m) on the three faces of the cut-away octant: quarter circles
    in the planes azimuth 0 and 90 deg (pole to equator) and in the equator, ``(3, points,
    3)``."""
    a = np.linspace(0.0, 0.5 * np.pi, points)
    zero = np.zeros_like(a)
    return radius * np.stack([np.column_stack([np.sin(a), zero, np.cos(a)]),
                              np.column_stack([zero, np.sin(a), np.cos(a)]),
                              np.column_stack([np.cos(a), np.sin(a), zero])])


def revolved_body(body, y, around=24):
    """The body's surface at state ``y`` as a grid ``(x, y, z)`` of shape ``(k, around)``
    (target frame, m, z depth): its outline (``body.outline``, axial coordinate from the
    centre of mass and radius) revolved about the axis, rotated by the attitude quaternion
    ``y[3:7]`` and moved to the centre of mass ``y[0:3]``."""
    from cavex.analytic.penetration.surface_force import rotation_matrix

    axial, radius = body.outline[:, 0], body.outline[:, 1]
    phi = np.linspace(0.0, 2.0 * np.pi, around)
    local = np.stack([np.repeat(axial[:, None], around, 1), radius[:, None] * np.cos(phi),
                      radius[:, None] * np.sin(phi)], -1)
    world = np.asarray(y[0:3]) + local @ rotation_matrix(y[3:7]).T
    return world[..., 0], world[..., 1], world[..., 2]


def body_instants(history, length, most=BODY_INSTANTS, gap=1.15):
    """Times (s) at which the body is drawn: equally spaced along the centre of mass's path
    (its length from the ``history`` samples), from the strike to the end, at most ``most``
    and at least 2, spaced at least ``gap`` body lengths apart where the path allows (at
    normal incidence bodies drawn at equal times lie on each other)."""
    points = np.column_stack([history["cg_x_m"], history["cg_y_m"], history["cg_z_m"]])
    along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    count = int(min(most, max(2, 1 + along[-1] // (gap * length))))
    return np.interp(np.linspace(0.0, along[-1], count), along, history["t_s"])


def display(x, y, z):
    """Target coordinates to display coordinates: a half turn about x (depth down)."""
    return x, -np.asarray(y), -np.asarray(z)


def _pyvista():
    """pyvista, set to render off screen (no window opened, no display needed)."""
    import pyvista

    pyvista.OFF_SCREEN = True
    return pyvista


def _plotter(pv, window, shape=(1, 1)):
    """An off-screen plotter of ``window`` pixels on white."""
    plotter = pv.Plotter(off_screen=True, window_size=list(window), shape=shape)
    plotter.set_background("white")
    return plotter


def _rings(pv, radius):
    """:func:`octant_rings` of ``radius`` as one polyline mesh."""
    return pv.MultiBlock([pv.lines_from_points(p) for p in octant_rings(radius)]).combine()


def fields_picture(fields, path):
    """Render the FE fields (``fields``: :func:`cavex.verification.commands.view.fields_job`)
    to the PNG ``path``; returns ``{"width_px", "height_px", "render_window"}``.

    The sphere of the picture's radius with an octant cut away (:data:`CUT_AWAY`), each
    shell of the revolved mesh one FE element with its values, the cavity at its expanded
    radius empty. Left: the chosen stress, on a logarithmic scale where it is positive
    throughout (an elastic field falls off as r^-3), else linear. Right: the zones
    (:func:`zone_codes`). Both: black rings at the zone fronts, grey at the layer interfaces
    in view, the title with the problem and what lies beyond the picture."""
    pv = _pyvista()
    radii = np.asarray(fields["radii_m"])
    key, title = STRESSES[fields["stress"]]
    values = np.asarray(fields["cells"][key]) / 1e6
    log = bool(np.all(values > 0.0))
    pieces = []
    for polar, azimuth in CUT_AWAY:
        grid = pv.StructuredGrid(*sphere_grid(radii, polar, azimuth))
        repeat = grid.n_cells // (len(radii) - 1)  # cells run radius fastest (VTK's i index)
        grid.cell_data[title] = np.tile(values, repeat)
        grid.cell_data["zone"] = np.tile(np.asarray(fields["zone_codes"]), repeat)
        pieces.append(grid)
    plotter = _plotter(pv, FIELDS_WINDOW, shape=(1, 2))
    fronts = [s["to_m"] for s in fields["zones"][:-1]]
    codes = [int(c) for c in np.unique(fields["zone_codes"])]
    interfaces = fields["interfaces_in_view_m"]
    for column in (0, 1):
        plotter.subplot(0, column)
        for k, grid in enumerate(pieces):
            if column == 0:
                plotter.add_mesh(grid, scalars=title, cmap="viridis", log_scale=log,
                                 clim=(float(values.min()), float(values.max())),
                                 show_scalar_bar=k == 0, ambient=0.45,
                                 scalar_bar_args={"title": "MPa" + (", log scale" if log else ""),
                                                  "vertical": False, "title_font_size": 15,
                                                  "label_font_size": 13, "fmt": "%.3g",
                                                  "position_x": 0.12, "position_y": 0.03,
                                                  "height": 0.12,
                                                  "width": 0.76, "color": "black"})
            else:
                plotter.add_mesh(grid, scalars="zone", cmap=list(ZONE_COLOURS), ambient=0.45,
                                 clim=(-0.5, len(ZONES) - 0.5), show_scalar_bar=False)
        if column == 1:
            entries = ([[f"{ZONES[c]} zone", ZONE_COLOURS[c]] for c in codes]
                       + ([["zone front", "black"]] if fronts else [])
                       + ([["layer interface", "#666666"]] if interfaces else []))
            _legend(plotter, entries, 0.3)
        for radius in fronts:
            plotter.add_mesh(_rings(pv, radius), color="black", line_width=3)
        for radius in interfaces:
            plotter.add_mesh(_rings(pv, radius), color="#666666", line_width=3)
        _title(plotter, fields["titles"][column] + (f"\ncolour: {title}" if column == 0 else ""))
        plotter.camera_position = [(1.0, 1.25, 0.8), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
        plotter.reset_camera()
        plotter.camera.zoom(1.05)
    return _save(plotter, path)


def _title(plotter, words, size=8):
    """``words`` at the top left of the current view, left-justified, in black."""
    actor = plotter.add_text(words, position=(0.01, 0.985), viewport=True, font_size=size,
                             color="black")
    actor.GetTextProperty().SetJustificationToLeft()
    actor.GetTextProperty().SetVerticalJustificationToTop()
    return actor


def _legend(plotter, entries, width):
    """A legend of ``entries`` (``[label, colour]``) at the bottom right of the current view,
    ``width`` of it wide (viewport fraction), one row 0.05 high."""
    actor = plotter.add_legend(entries, bcolor="white", border=True, face="rectangle")
    height = 0.05 * len(entries)
    actor.GetPositionCoordinate().SetValue(0.99 - width, 0.02)
    actor.GetPosition2Coordinate().SetValue(width, height)
    return actor


def _save(plotter, path):
    """Render ``plotter`` to the PNG ``path``; returns its size and render window class."""
    plotter.screenshot(str(path))
    width, height = plotter.window_size
    window = plotter.ren_win.GetClassName()
    plotter.close()
    return {"width_px": int(width), "height_px": int(height), "render_window": window}


def shot_picture(job, path):
    """Render the oblique shot (``job``: :func:`cavex.verification.commands.trajectory.
    trajectory_job`) to the PNG ``path``; returns ``{"width_px", "height_px",
    "render_window"}``. The block and its limits are those of ``path_3d.png``
    (:func:`cavex.verification.report.trajectory_figures.block_limits`, its ``y`` range
    taken on the side ``y <= 0``: the half behind the plane of obliquity as the camera sees
    it, with x to the right), from above the surface to below the path; the layers in it as
    translucent slabs, a layer below the block named in the legend with its depth."""
    from cavex.verification.report.trajectory_figures import block_limits, shot_title

    pv = _pyvista()
    target, result = job["target"], job["runs"]["runway"]
    h = result.history
    (x0, x1), (y0, y1), (top, bottom) = block_limits(result, target)
    plotter = _plotter(pv, SHOT_WINDOW)
    planes = [max(0.0, top), *(H for H in target.interface_depths if H < bottom), bottom]
    names = target.layer_names()
    legend = []
    for k in range(len(planes) - 1):
        colour = LAYER_COLOURS[k % len(LAYER_COLOURS)]
        slab = pv.Box(bounds=(x0, x1, y0, y1, -planes[k + 1], -planes[k]))
        plotter.add_mesh(slab, color=colour, opacity=0.35, show_edges=True,
                         edge_color="#555555", line_width=1)
        legend.append([names[k], colour])
    legend += [[f"below the block: {names[k + 1]} from {H:.3g} m", "#444444"]
               for k, H in enumerate(target.interface_depths) if H >= bottom]
    path_points = np.column_stack(display(h["cg_x_m"], h["cg_y_m"], h["cg_z_m"]))
    model_body = result.model.body
    tube = pv.lines_from_points(path_points).tube(radius=0.15 * model_body.radius)
    plotter.add_mesh(tube, color="red")
    legend.insert(0, ["centre of mass", "red"])
    instants = body_instants(h, model_body.length)
    for t in instants:
        surface = pv.StructuredGrid(*display(*revolved_body(model_body, result.state(t))))
        plotter.add_mesh(surface, color="navy", smooth_shading=True)
    legend.insert(1, [f"body at {len(instants)} points equally spaced on the path", "navy"])
    _legend(plotter, legend, 0.34)
    _title(plotter, shot_title(job).replace("; ", "\n") + "\nthe block cut open along the "
           "plane of obliquity (x horizontal in it, depth down)")
    plotter.show_bounds(xtitle="x (m)", ytitle="-y (m)", ztitle="-depth (m)", color="black",
                        font_size=10, location="outer", ticks="outside", n_xlabels=4,
                        n_ylabels=2, n_zlabels=4, fmt="%.2g")
    span = max(x1 - x0, bottom - top)
    # the focus right of the block's centre: the block left of the legend
    focus = (0.5 * (x0 + x1) + 0.3 * span, 0.5 * (y0 + y1), -0.5 * (top + bottom))
    plotter.camera_position = [(focus[0] - 1.0 * span, focus[1] - 2.6 * span,
                                focus[2] + 0.8 * span), focus, (0.0, 0.0, 1.0)]
    plotter.camera.zoom(1.1)
    return _save(plotter, path)
