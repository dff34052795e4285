"""``cavex penetrate``: trajectories, the Table 2 comparison, CSV and PNG outputs.

The CSV files carry :data:`~cavex.verification.output.number_format.TRAJECTORY_DIGITS` significant
digits (the integrator's tolerance; see :mod:`cavex.verification.output.number_format`), so that
they are the same when regenerated on another CPU.
"""

import json
from pathlib import Path

from cavex.analytic.penetration.labels import (
    FLIGHT_RESISTANCES,
    PLAIN_LAW,
    model_boundary,
    model_label,
)
from cavex.analytic.penetration.zones import crater_depth, scab_depth
from cavex.config import load_config
from cavex.verification.output.files import (
    agg_figure,
    collector_paused,
    save_figure,
    write_columns_csv,
)
from cavex.verification.output.number_format import TRAJECTORY_QUANTA
from cavex.verification.output.paths import check_output_dir, write_staged
from cavex.verification.studies.table2 import not_reproduced_line, table2_comparison


def run(args, target, projectile):
    """``cavex penetrate``: fly, write every file or none (also on Ctrl-C or kill), return the
    text or JSON to print."""
    from cavex.verification.commands.options import (
        interface_target,
        law_settings,
        resistance_settings,
    )

    settings = resistance_settings(args, FLIGHT_RESISTANCES)
    target = interface_target(args, target, settings["resistance"])
    laws = law_settings(args, target)
    folder = check_output_dir(args.out, "out")
    job = penetration_job(target, projectile, crater=args.crater, **settings, **laws)
    written = write_staged(folder, lambda stage: write_outputs(job, stage, draw=args.figures))
    document = summary(job, written)
    return json.dumps(document, indent=2) if args.json else text(document)


def penetration_job(target, projectile, *, resistance="derived", boundary=None,
                    epsilon="quasi-static", crater="nose-base", table=None, law_A=None,
                    law_B=None):
    """Run the target and its first layer alone (the paper's Fig. 4 pair); nothing is written.

    ``resistance`` is one of :data:`cavex.analytic.penetration.labels.FLIGHT_RESISTANCES`;
    ``boundary`` None is the default: dynamic for the derived model, the paper's own
    quasi-static for the paper model (:func:`cavex.analytic.penetration.resistance.model_boundary`).

    With ``resistance="table"`` the runway uses the FE-tabulated resistance of ``table`` (the
    path of a table built for this target); the first layer alone keeps the derived closed
    form with ``boundary``. With ``resistance="law"`` both use the plain law: the global
    ``law_A`` (Pa), ``law_B`` (kg/m^3), or neither: each layer's ``law_A``, ``law_B`` keys
    (:class:`~cavex.analytic.penetration.plain_law.PlainLawResistance`); it has no boundary
    convention (``boundary`` None).
    """
    from cavex.analytic.penetration.integrator import penetrate
    from cavex.analytic.penetration.resistance import make_resistance
    from cavex.verification.commands.options import law_echo

    law = resistance == PLAIN_LAW
    model = PLAIN_LAW if law else model_label(resistance, boundary)
    closed = "derived" if resistance == "table" else resistance
    first = model if law else model_label(closed, boundary)
    boundary = None if law else model_boundary(closed, boundary)
    single = target.single(0)
    laws = {"law_A": law_A, "law_B": law_B}
    runs = {"runway": penetrate(target, projectile, make_resistance(
                target, projectile, resistance, boundary, epsilon, table, **laws),
                crater=crater),
            "first_layer_only": penetrate(single, projectile, make_resistance(
                single, projectile, closed, boundary, epsilon, **laws), crater=crater)}
    paper = (target.with_interfaces("bonded"), projectile) == load_config()
    settings = {"law": law_echo(target, law_A, law_B)} if law else {}
    return {**settings, "model": model, "interfaces": interface_summary(target, projectile),
            "first_layer_model": first, "resistance": resistance,
            "boundary": boundary, "epsilon": epsilon,
            "table": None if table is None else str(table), "crater": crater,
            "runs": runs, "table2": table2_comparison(runs["runway"]) if paper else None,
            "target_label": "runway (the paper's Table 1)" if paper else "layered target",
            "notes": crater_notes(target, projectile, crater),
            "debonded": bool(target.debonded),
            "interface_depths": target.interface_depths,
            "title": resistance_title(resistance, boundary, epsilon, table,
                                      settings.get("law")),
            "layer_names": target.layer_names()}


SETTINGS = ("model", "first_layer_model", "resistance", "boundary", "epsilon", "table",
            "law", "crater", "interfaces", "target_label", "notes")  # "law": the plain law's


def interface_summary(target, projectile):
    """Each interface's bonding and, where debonded, its rear-zone depth (m)."""
    return [{"depth_m": H, "bottom": bottom} | (
        {"rear_zone_m": scab_depth(target, projectile, j)} if bottom == "debonded" else {})
        for j, (H, bottom) in enumerate(zip(target.interface_depths, target.bottoms,
                                            strict=True))]


def summary(job, written=()):
    """What ``cavex penetrate --json`` prints: the settings, the runway's phases, the rows
    beside the paper's Table 2 (None for another target) and the files written."""
    return {**{key: job[key] for key in SETTINGS if key in job},
            "phases": phases_as_dicts(job["runs"]["runway"]), "table2": job["table2"],
            "outputs": list(written)}


def text(summary):
    """The phase table, the rows beside the paper's Table 2 and the files written."""
    s = summary
    settings = {"paper": f", epsilon {s['epsilon']}",
                "table": f" ({s['table']}; first layer alone: {s['first_layer_model']})",
                PLAIN_LAW: f" ({law_text(s['law'])})" if "law" in s else ""}
    debonded = [i for i in s["interfaces"] if i["bottom"] == "debonded"]
    lines = [f"model {s['model']}{settings.get(s['resistance'], '')}, crater from {s['crater']}"]
    if debonded:
        lines.append("debonded interfaces at " + ", ".join(
            f"{i['depth_m']:g} m (rear zone {i['rear_zone_m']:.4g} m)" for i in debonded))
    lines += [f"note: {note}" for note in s["notes"]]
    stage = (lambda p: f" {p['stage']:<9}") if debonded else (lambda p: "")
    lines += ["", f"phases ({s['target_label']}):",
              f"{'#':>2}{' stage    ' if debonded else ''} {'label':<24} {'L (m)':>8} "
              f"{'V (m/s)':>9} {'t (ms)':>8}  ends because"]
    lines += [f"{p['phase']:>2}{stage(p)} {p['label']:<24} {p['end_depth_m']:8.4f} "
              f"{p['end_velocity_m_s']:9.2f} {p['end_time_s'] * 1e3:8.3f}  {p['end_reason']}"
              for p in s["phases"]]
    if s["table2"] is not None:
        lines += ["", "beside the paper's Table 2:",
                  f"{'row':<32} {'L ours':>7} {'paper':>6} {'V ours':>8} {'paper':>7} "
                  f"{'t ours':>7} {'paper':>6}"]
    for row in s["table2"] or []:
        ours, paper = row["ours"], row["paper"]
        mine = ("{:7.3f} {:>6} {:8.1f} {:>7} {:7.2f} {:>6.2f}".format(
            ours["depth_m"], paper["depth_m"], ours["velocity_m_s"], paper["velocity_m_s"],
            ours["time_s"] * 1e3, paper["time_s"] * 1e3) if ours else "(phase not reached)")
        lines.append(f"{row['phase']} {row['name']:<30} {mine}")
    if s["table2"] is not None:
        lines.append(not_reproduced_line(s["table2"]))
    lines += ["", "wrote: " + ", ".join(s["outputs"])]
    return "\n".join(lines)


def crater_notes(target, projectile, crater):
    """What the user must know about the crater stage: it uses the first layer's properties,
    which is wrong where the crater reaches deeper than that layer."""
    if crater is None or not target.interface_depths:
        return []
    depth, first = crater_depth(projectile, crater), target.interface_depths[0]
    if depth <= first:
        return []
    return [f"the crater ({depth:.4g} m, 4.5 r from the {crater}) reaches below the first layer "
            f"({first:.4g} m thick); the crater stage uses the first layer's properties "
            "throughout"]


def law_text(law):
    """The plain law (:func:`~cavex.verification.commands.options.law_echo`) in words:
    ``sigma_n = A + B V_n^2, A 2e+08 Pa, B 2500 kg/m^3`` (global) or ``sigma_n = tau_k A_k +
    B_k rho_k V_n^2; concrete A 20, B 1; ...`` (each layer's keys, by the layer's name)."""
    if isinstance(law, dict):
        return f"sigma_n = A + B V_n^2, A {law['A_Pa']:g} Pa, B {law['B_kg_m3']:g} kg/m^3"
    return "sigma_n = tau_k A_k + B_k rho_k V_n^2; " + "; ".join(
        f"{k['layer']} A {k['law_A']:g}, B {k['law_B']:g}" for k in law)


def resistance_title(resistance, boundary, epsilon, table=None, law=None):
    """What the figures say about the resistance: the settings the closed form uses (the
    paper's model has its own quasi-static boundary and an epsilon reading; the derived model
    has a boundary convention), for a table (``resistance`` "table") only its file name, for
    the plain law (``resistance`` "law") ``law`` in words (:func:`law_text`)."""
    if resistance == PLAIN_LAW:
        return "plain law " + law_text(law)
    closed = (f"paper model (She 2020), epsilon: {epsilon}" if resistance == "paper"
              else f"derived model, {boundary} boundary")
    if resistance != "table":
        return closed
    return f"FE table {Path(str(table)).name} (first layer alone: {closed})"


def phases_as_dicts(trajectory):
    """The phase table as JSON-able rows."""
    return [{"phase": i + 1, "stage": p.stage, "label": p.label, "end_depth_m": p.end_depth,
             "end_velocity_m_s": p.end_velocity, "end_time_s": p.end_time,
             "end_reason": p.end_reason} for i, p in enumerate(trajectory.phases)]


def write_outputs(job, out_dir, draw=True):
    """Write CSV trajectories, the phase table and (if ``draw``) PNG figures; return the
    written paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, trajectory in job["runs"].items():
        written.append(write_columns_csv(out / f"trajectory_{name}.csv", trajectory.as_columns(),
                                         TRAJECTORY_QUANTA))
    rows = phases_as_dicts(job["runs"]["runway"])
    if not job["debonded"]:  # the stage column only where there is more than one tunnel
        rows = [{k: v for k, v in row.items() if k != "stage"} for row in rows]
    written.append(write_columns_csv(out / "phases_runway.csv", _columns(rows)))
    if draw:
        written += _write_figures(job, out)
    return [str(p) for p in written]


def _columns(rows):
    return {key: [row[key] for row in rows] for key in rows[0]}


def _write_figures(job, out):
    """The two figures, made without pyplot and drawn with the garbage collector paused
    (:func:`~cavex.verification.output.files.collector_paused`); returns their paths."""
    with collector_paused():
        return _draw_figures(job, out)


def _draw_figures(job, out):
    import textwrap

    runway, single = job["runs"]["runway"], job["runs"]["first_layer_only"]
    subtitle = textwrap.fill(job["title"], 70)
    names = job.get("layer_names", [])
    fig = agg_figure(figsize=(6.4, 4.8))
    ax = fig.add_subplot()
    runway_label = "runway (layered)" if job.get("table") is None else \
        "runway (layered, FE table)"
    if job.get("debonded"):
        runway_label = "runway (layered, debonded interfaces)"
    ax.plot(runway.t * 1e3, runway.velocity, label=runway_label)
    ax.plot(single.t * 1e3, single.velocity, "--", label=f"{names[0] if names else 'first layer'}"
            " alone")
    ax.set(xlabel="time (ms)", ylabel="velocity (m/s)")
    ax.set_title(f"Velocity against time\n{subtitle}", fontsize=10)
    _legend_below(ax)
    velocity_png = _save(fig, out / "velocity_time.png")
    fig = agg_figure(figsize=(6.4, 4.8))
    ax = fig.add_subplot()
    ax.plot(runway.depth, runway.deceleration / 9.81 / 1e3, label=runway_label)
    ax.plot(single.depth, single.deceleration / 9.81 / 1e3, "--",
            label=f"{names[0] if names else 'first layer'} alone")
    left, right = ax.get_xlim()
    bounds = [left, *job["interface_depths"], right]
    for depth in job["interface_depths"]:
        ax.axvline(depth, color="grey", linewidth=0.8, linestyle=":")
    ax.set_xlim(left, right)
    _layer_names(ax, names, bounds)
    ax.set(xlabel="nose-tip depth (m)", ylabel=r"deceleration ($10^3$ g)")
    ax.set_title(f"Deceleration against depth\n{subtitle}", fontsize=10, pad=14)
    _legend_below(ax)
    return [velocity_png, _save(fig, out / "deceleration_depth.png")]


def _layer_names(ax, names, bounds):
    """Each layer's name above the axes, centred on the part of its depth range ``bounds[k]``
    to ``bounds[k + 1]`` in view; a name that would stick out of the axes or overlap a
    name already placed is left out (its extent measured, not guessed: a layer narrower
    than its name keeps it when its neighbours leave room)."""
    left, right = ax.get_xlim()
    renderer = ax.figure.canvas.get_renderer()
    frame, placed = ax.get_window_extent(renderer), []
    for k, name in enumerate(names[:len(bounds) - 1]):
        lo, hi = max(bounds[k], left), min(bounds[k + 1], right)
        if hi <= lo:
            continue
        text = ax.text(0.5 * (lo + hi), 1.0, name, ha="center", va="bottom", fontsize=8,
                       style="italic", transform=ax.get_xaxis_transform())
        box = text.get_window_extent(renderer)
        if (box.x0 < frame.x0 or box.x1 > frame.x1
                or any(box.x0 < other.x1 and other.x0 < box.x1 for other in placed)):
            text.remove()
        else:
            placed.append(box)


def _legend_below(ax):
    """The legend below the axes, off the data."""
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, frameon=False,
              fontsize=9)


def _save(fig, path):
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)
