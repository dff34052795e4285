"""The report's stress figure: the FE radial and hoop stress across the layers at one (V, L).

One FE run of the spherical problem at expansion velocity ``V`` and nose-tip depth ``L``
(:func:`cavex.fem.expand_cavity`, fields recorded) gives ``sigma_r`` and ``sigma_theta`` at
every quadrature point. They are drawn against the current radius ``r`` (mm, log scale, from
the cavity wall ``a`` to beyond the plastic zone and the first interface), one line per layer
so that the jump of ``sigma_theta`` at an interface shows, with the layers shaded and named,
the interfaces dashed, the closed-form plastic radius ``b`` (derived dynamic and quasi-static
conventions) and the FE one marked, and the closed-form wall stresses as points at ``r = a``.
matplotlib only (no 3-D renderer).
"""

import numpy as np

from cavex.analytic.cavity import cavity_solution
from cavex.analytic.geometry import spherical_problem
from cavex.fem.expansion import expand_cavity

EXTENT_FACTOR = 1.6  # the figure reaches this far beyond b and the first interface
FILE_NAME = "stresses.png"


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
    """One FE run at (V, L) and the closed forms there; what the figure draws.

    Returns
    -------
    dict
        ``r`` (m), ``sigma_r``, ``sigma_theta`` (Pa), ``layer`` (index among ``layers``) per
        quadrature point sorted by radius; ``a`` (cavity radius), ``b`` (FE plastic radius),
        ``interfaces`` (closed-form interface radii at this depth), ``layers`` (names of the
        layers around the cavity), ``cavity_stress`` (FE), ``closed_form`` ({convention:
        {"b", "stress", "state"}}) for the derived dynamic and quasi-static conventions.
    """
    from dataclasses import replace

    layers, interfaces = spherical_problem(target, projectile, depth)
    wall = len(target.layers) - len(layers)  # index of the wall layer in the target
    fe_layers = [replace(m, nu=nu) for m in layers] if nu is not None else layers
    result = expand_cavity(fe_layers, interfaces, velocity, projectile.r,
                           **{**(numerics or {}), "error_estimate": False})
    order = np.argsort(result.fields["r"])
    closed = {}
    for boundary in ("dynamic", "quasi-static"):
        state = cavity_solution(layers, interfaces, velocity, projectile.r, boundary=boundary)
        closed[boundary] = {"b": float(state.plastic_radius), "stress": float(state.stress),
                            "state": str(state.state)}
    return {"r": result.fields["r"][order], "sigma_r": result.fields["sigma_r"][order],
            "sigma_theta": result.fields["sigma_theta"][order],
            "layer": result.fields["layer"][order], "a": projectile.r,
            "b": result.plastic_radius, "interfaces": [float(h) for h in interfaces],
            "layers": target.layer_names()[wall:],
            "cavity_stress": result.cavity_stress, "closed_form": closed}


def elastic_wave_speed(layer):
    """The layer's elastic (dilatational) wave speed ``c_p = sqrt((K + 4 G / 3) / rho)``
    (m/s): the fastest signal in the elastic solid."""
    return float(np.sqrt((layer.bulk_modulus + 4.0 * layer.shear_modulus / 3.0) / layer.rho))


def wave_speed_warning(target, velocity, names=None):
    """One sentence when the expansion velocity exceeds a layer's elastic wave speed
    (:func:`elastic_wave_speed`), naming the layers (of ``names``, default every layer) and
    their speeds; None otherwise. The cavity then outruns every elastic signal in that layer:
    the FE fields there are a shock the mesh resolves as jagged steps, and the closed form's
    elastic zone (a wave speed far above V) does not describe it."""
    names = names if names is not None else target.layer_names()
    fast = [(name, elastic_wave_speed(layer))
            for name, layer in zip(target.layer_names(), target.layers, strict=True)
            if name in names and velocity > elastic_wave_speed(layer)]
    if not fast:
        return None
    which = ", ".join(f"{name} ({c:.0f} m/s)" for name, c in fast)
    return (f"warning: V = {velocity:g} m/s exceeds the elastic wave speed c_p = sqrt((K + "
            f"4G/3)/rho) of {which}: the cavity outruns every elastic signal there, so the FE "
            "fields are a shock (jagged on the mesh) and the closed form does not apply")


def picture_extent(fields):
    """Outer radius of the figure: beyond every ``b`` and the first interface, inside the mesh."""
    radii = [fields["b"], *(c["b"] for c in fields["closed_form"].values()), 2.0 * fields["a"]]
    radii += fields["interfaces"][:1]
    return min(EXTENT_FACTOR * max(r for r in radii if np.isfinite(r)), float(fields["r"][-1]))


def plot_stresses(fields, path, title, warning=None):
    """Draw the stress figure to ``path`` (PNG), with ``warning`` (one sentence, e.g.
    :func:`wave_speed_warning`) in a box under the title; raises if drawing fails."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, LogLocator

    from cavex.verification.output.files import save_figure

    a, outer = fields["a"], picture_extent(fields)
    mm = 1e3
    fig, ax = plt.subplots(figsize=(8, 5))
    bounds = [a, *[h for h in fields["interfaces"] if h < outer], outer]
    for k, (lo, hi) in enumerate(zip(bounds[:-1], bounds[1:], strict=False)):
        ax.axvspan(mm * lo, mm * hi, color="0.93" if k % 2 == 0 else "white", zorder=0)
        ax.text(mm * np.sqrt(lo * hi), 1.0, fields["layers"][k], ha="center", va="bottom",
                fontsize=9, style="italic", transform=ax.get_xaxis_transform())
    for h in bounds[1:-1]:
        ax.axvline(mm * h, color="k", ls="--", lw=1.0)
    shown = fields["r"] <= outer
    # sigma_r is continuous across an interface, sigma_theta jumps: one line per layer
    ax.plot(mm * fields["r"][shown], fields["sigma_r"][shown] / 1e6, "C0-", lw=1.8,
            label="FE sigma_r (radial)")
    for k in np.unique(fields["layer"][shown]):
        inside = shown & (fields["layer"] == k)
        ax.plot(mm * fields["r"][inside], fields["sigma_theta"][inside] / 1e6, "C1-", lw=1.8,
                label="FE sigma_theta (hoop)" if k == fields["layer"][shown][0] else None)
    styles = {"dynamic": ("C3", "-"), "quasi-static": ("C3", ":")}
    for boundary, c in fields["closed_form"].items():
        colour, style = styles[boundary]
        ax.axvline(mm * c["b"], color=colour, ls=style, lw=1.5,
                   label=f"closed-form b, {boundary} ({mm * c['b']:.1f} mm, state {c['state']})")
        ax.plot(mm * a, c["stress"] / 1e6, marker="o" if boundary == "dynamic" else "s",
                mfc="none", color=colour, ms=7, ls="none", clip_on=False,
                label=f"closed-form sigma_r at the wall, {boundary}")
    ax.axvline(mm * fields["b"], color="0.3", ls="-.", lw=1.5,
               label=f"FE b ({mm * fields['b']:.1f} mm)")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xscale("log")
    ax.set_xlim(mm * a, mm * outer)
    ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 3.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
    ax.xaxis.set_minor_formatter(FuncFormatter(lambda x, _: ""))
    ax.set(xlabel="radius r from the cavity centre (mm, log scale; cavity wall a = "
                  f"{mm * a:g} mm)", ylabel="stress (MPa, compression positive)")
    ax.set_title(title, pad=16)
    ax.legend(fontsize=7.5, loc="upper right")
    if warning:
        import textwrap

        text = textwrap.fill(warning, 110)
        room = 0.16 * (text.count("\n") + 1) + 0.15  # in: the box's lines and padding
        fig.set_figheight(fig.get_figheight() + room)
        fig.text(0.5, 1.0 - 0.04 / fig.get_figheight(), text, ha="center", va="top",
                 fontsize=8, color="darkred", bbox={"boxstyle": "round", "facecolor": "#fff0f0",
                                                    "edgecolor": "darkred"})
        fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - room / fig.get_figheight()))
    else:
        fig.tight_layout()
    return save_figure(fig, path, dpi=110)


def first_line(exc):
    """``"ExceptionType: first line of the message"``."""
    lines = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {lines[0] if lines else ''}".rstrip(": ")


def make_picture(target, projectile, velocity, depth, path, numerics=None, nu=None):
    """FE run and stress figure; returns ``(path or None, one-line message)``.

    The message says what is shown, or in one line why no figure was drawn.
    """
    fields = fe_fields(target, projectile, velocity, depth, numerics, nu)
    names = ", ".join(fields["layers"])
    interfaces = ", ".join(f"{h * 1e3:.1f}" for h in fields["interfaces"]) or "none"
    closed = fields["closed_form"]
    caption = (f"V = {velocity:g} m/s, L = {depth:.3f} m: {names} around the cavity "
               f"(interfaces at r = {interfaces} mm); FE b = {fields['b'] * 1e3:.1f} mm, "
               f"closed-form b = {closed['dynamic']['b'] * 1e3:.1f} mm (dynamic, state "
               f"{closed['dynamic']['state']}) and {closed['quasi-static']['b'] * 1e3:.1f} mm "
               f"(quasi-static, state {closed['quasi-static']['state']}); FE wall stress "
               f"{fields['cavity_stress'] / 1e6:.1f} MPa (cavity a = {fields['a'] * 1e3:g} mm)")
    warning = wave_speed_warning(target, velocity, fields["layers"])
    if warning:
        caption += "; " + warning
    try:
        plot_stresses(fields, path, f"Stresses around the cavity, V = {velocity:g} m/s, "
                                    f"L = {depth:.3f} m", warning)
    except Exception as exc:  # noqa: BLE001 - any plotting failure is reported in one line
        return None, f"stress figure not drawn ({first_line(exc)})"
    return path, caption
