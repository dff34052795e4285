"""The ``cavex penetrate`` job: trajectories, the Table 2 comparison, CSV and PNG outputs.

The CSV files carry :data:`~cavex.verification.output.number_format.TRAJECTORY_DIGITS` significant
digits (the integrator's tolerance; see :mod:`cavex.verification.output.number_format`), so that
they are the same when regenerated on another CPU.
"""

from pathlib import Path

from cavex.analytic.penetration.integrator import crater_depth, penetrate
from cavex.analytic.penetration.resistance import ClosedFormResistance, check_model, model_boundary
from cavex.config import load_config
from cavex.verification.output.files import save_figure, write_columns_csv
from cavex.verification.studies.table2 import table2_comparison


def penetration_job(target, projectile, *, model="derived", boundary=None,
                    epsilon="quasi-static", crater="nose-base", table_path=None):
    """Run the target and its first layer alone (the paper's Fig. 4 pair); nothing is written.

    ``boundary`` None is the model's default: dynamic for the derived model, the paper's own
    quasi-static for the paper model (:func:`cavex.analytic.penetration.resistance.model_boundary`).

    With ``table_path`` the runway uses the FE-tabulated resistance of that table (which must
    have been built for this target); the first layer alone keeps the closed form ``model``.
    """
    check_model(model, boundary)
    boundary = model_boundary(model, boundary)
    single = target.single(0)
    runs = {"runway": _runway(target, projectile, model, boundary, epsilon, crater, table_path),
            "first_layer_only": penetrate(single, projectile, ClosedFormResistance(
                single, projectile, model, boundary, epsilon=epsilon), crater=crater)}
    title = resistance_title(model, boundary, epsilon, table_path)
    if table_path is not None:
        model = f"FE table {table_path} (first layer alone: {model})"
    paper = (target, projectile) == load_config()
    return {"model": model, "boundary": boundary, "epsilon": epsilon, "crater": crater,
            "runs": runs, "table2": table2_comparison(runs["runway"]) if paper else None,
            "target_label": "runway (the paper's Table 1)" if paper else "layered target",
            "notes": crater_notes(target, projectile, crater),
            "interface_depths": target.interface_depths, "title": title,
            "table": None if table_path is None else str(table_path),
            "layer_names": target.layer_names()}


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


def resistance_title(model, boundary, epsilon, table_path=None):
    """What the figures say about the resistance: the settings the model uses (the paper's
    model has its own quasi-static boundary and an epsilon reading; the derived model has a
    boundary convention), and only the file name of an FE table."""
    closed = (f"paper model (She 2020), epsilon: {epsilon}" if model == "paper"
              else f"derived model, {boundary} boundary")
    if table_path is None:
        return closed
    return f"FE table {Path(table_path).name} (first layer alone: {closed})"


def _runway(target, projectile, model, boundary, epsilon, crater, table_path):
    if table_path is None:
        resistance = ClosedFormResistance(target, projectile, model, boundary, epsilon=epsilon)
        return penetrate(target, projectile, resistance, crater=crater)
    from cavex.analytic.penetration.tabulated import penetrate_with_table

    return penetrate_with_table(target, projectile, table_path, crater=crater)


def phases_as_dicts(trajectory):
    """The phase table as JSON-able rows."""
    return [{"phase": i + 1, "label": p.label, "end_depth_m": p.end_depth,
             "end_velocity_m_s": p.end_velocity, "end_time_s": p.end_time,
             "end_reason": p.end_reason} for i, p in enumerate(trajectory.phases)]


def write_outputs(job, out_dir):
    """Write CSV trajectories, the phase table and PNG figures; return the written paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, trajectory in job["runs"].items():
        written.append(write_columns_csv(out / f"trajectory_{name}.csv", trajectory.as_columns()))
    written.append(write_columns_csv(out / "phases_runway.csv",
                              _columns(phases_as_dicts(job["runs"]["runway"]))))
    written += _write_figures(job, out)
    return [str(p) for p in written]


def _columns(rows):
    return {key: [row[key] for row in rows] for key in rows[0]}


def _write_figures(job, out):
    import textwrap

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runway, single = job["runs"]["runway"], job["runs"]["first_layer_only"]
    subtitle = textwrap.fill(job.get("title", job["model"]), 70)
    names = job.get("layer_names", [])
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    runway_label = "runway (layered)" if job.get("table") is None else \
        "runway (layered, FE table)"
    ax.plot(runway.t * 1e3, runway.velocity, label=runway_label)
    ax.plot(single.t * 1e3, single.velocity, "--", label=f"{names[0] if names else 'first layer'}"
            " alone")
    ax.set(xlabel="time (ms)", ylabel="velocity (m/s)")
    ax.set_title(f"Velocity against time\n{subtitle}", fontsize=10)
    ax.legend()
    velocity_png = _save(fig, out / "velocity_time.png", plt)
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.plot(runway.depth, runway.deceleration / 9.81 / 1e3, label=runway_label)
    ax.plot(single.depth, single.deceleration / 9.81 / 1e3, "--",
            label=f"{names[0] if names else 'first layer'} alone")
    left, right = ax.get_xlim()
    bounds = [left, *job["interface_depths"], right]
    for depth in job["interface_depths"]:
        ax.axvline(depth, color="grey", linewidth=0.8, linestyle=":")
    for k, name in enumerate(names[:len(bounds) - 1]):
        lo, hi = max(bounds[k], left), min(bounds[k + 1], right)
        if hi - lo > 0.08 * (right - left):
            ax.text(0.5 * (lo + hi), 1.0, name, ha="center", va="bottom", fontsize=8,
                    style="italic", transform=ax.get_xaxis_transform())
    ax.set_xlim(left, right)
    ax.set(xlabel="nose-tip depth (m)", ylabel=r"deceleration ($10^3$ g)")
    ax.set_title(f"Deceleration against depth\n{subtitle}", fontsize=10, pad=14)
    ax.legend(loc="center right")
    return [velocity_png, _save(fig, out / "deceleration_depth.png", plt)]


def _save(fig, path, plt):
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)
