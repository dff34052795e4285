"""``cavex penetrate``: trajectories, the Table 2 comparison, CSV and PNG outputs (the figures:
:mod:`cavex.verification.report.penetration_figures`).

The CSV files carry :data:`~cavex.verification.output.number_format.TRAJECTORY_DIGITS` significant
digits (the integrator's tolerance; see :mod:`cavex.verification.output.number_format`), so that
they are the same when regenerated on another CPU.
"""

from pathlib import Path

from cavex.analytic.models import get
from cavex.analytic.models.plain_law import law_echo
from cavex.analytic.penetration.zones import crater_depth, scab_depth
from cavex.config import load_config
from cavex.errors import CavexInputError
from cavex.verification.commands.options import (
    FLOWN,
    add_erosion_option,
    add_interface_option,
    add_resistance_options,
    interface_target,
    law_settings,
    resistance_settings,
)
from cavex.verification.commands.shared_options import add_config_option, add_figures_option
from cavex.verification.output.files import run_stem, write_columns_csv
from cavex.verification.output.number_format import TRAJECTORY_QUANTA
from cavex.verification.output.paths import check_output_dir, write_staged
from cavex.verification.studies.table2 import not_reproduced_line, table2_comparison

HELP = "integrate the projectile through the target"
DEFAULT_OUT = "results/penetration"


def add_arguments(parser):
    """The options of ``cavex penetrate``."""
    add_config_option(parser)
    add_resistance_options(parser, FLOWN)
    add_interface_option(parser)
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.add_argument("--out", default=DEFAULT_OUT, help="output folder")
    add_figures_option(parser, "the CSV trajectories and phase table")
    parser.add_argument("--crater", choices=("nose-base", "nose-tip"), default="nose-base",
                        help="where the crater depth 4.5 r is measured from")
    add_erosion_option(parser)


def run(args, target, projectile):
    """``cavex penetrate``: fly, write every file or none (also on Ctrl-C or kill); returns
    the job with the files written (``outputs``)."""
    settings = resistance_settings(args, FLOWN)
    target = interface_target(args, target, settings["resistance"])
    laws = law_settings(args, target)
    folder = check_output_dir(args.out, "out")
    job = penetration_job(target, projectile, crater=args.crater, erosion=args.erosion,
                          **settings, **laws)
    job["outputs"] = write_staged(folder,
                                  lambda stage: write_outputs(job, stage, draw=args.figures),
                                  replaces=OUTPUTS)
    return job


#: every file ``cavex penetrate`` can write (a rerun into the folder replaces them all)
OUTPUTS = ("trajectory_*.csv", "phases_*.csv", "velocity_time.png", "deceleration_depth.png")


def penetration_job(target, projectile, *, resistance="derived", boundary=None,
                    epsilon="quasi-static", crater="nose-base", table=None, law_A=None,
                    law_B=None, erosion="none"):
    """Run the target and its first layer alone (the paper's Fig. 4 pair); nothing is written.

    ``resistance`` is a flown model of the registry (:mod:`cavex.analytic.models`);
    ``boundary`` None is the default: dynamic for the derived model, the paper's own
    quasi-static for the paper model (:meth:`cavex.analytic.models.registry.Model.boundary`).

    With ``resistance="table"`` the runway uses the FE-tabulated resistance of ``table`` (the
    path of a table built for this target); the first layer alone keeps the derived closed
    form with ``boundary``. With ``resistance="law"`` both use the plain law: the global
    ``law_A`` (Pa), ``law_B`` (kg/m^3), or neither: each layer's ``law_A``, ``law_B`` keys
    (:class:`~cavex.analytic.penetration.plain_law.PlainLawResistance`); it has no boundary
    convention (``boundary`` None).

    ``erosion``: a law of :data:`cavex.analytic.penetration.erosion.CHOICES` ("none": the rigid
    projectile); both runs fly the eroding nose, each run's ``erosion`` summary says what it
    lost. Not with an FE table (its interpolation-error estimate flies the rigid projectile).
    """
    from cavex.analytic.penetration.erosion import ErodingNose, law_named

    law = law_named(erosion)
    if law is not None and table is not None:
        raise CavexInputError("option '--erosion' goes with a closed form or the plain law, "
                              "not '--resistance table' (the table's interpolation-error "
                              "estimate flies the rigid projectile)")
    from cavex.analytic.models import make_resistance
    from cavex.analytic.penetration.integrator import penetrate

    def nose():
        return None if law is None else ErodingNose(law, projectile)

    model = get(resistance)
    first_model = get(model.first_layer or resistance)  # flies the first layer alone
    closed = first_model.name
    label, first = model.label(boundary), first_model.label(boundary)
    boundary = first_model.boundary(boundary)
    single = target.single(0)
    laws = {"law_A": law_A, "law_B": law_B}
    runs = {"runway": penetrate(target, projectile, make_resistance(
                target, projectile, resistance, boundary, epsilon, table, **laws),
                crater=crater, erosion=nose()),
            "first_layer_only": penetrate(single, projectile, make_resistance(
                single, projectile, closed, boundary, epsilon, **laws), crater=crater,
                erosion=nose())}
    paper = (target.with_interfaces("bonded"), projectile) == load_config()
    settings = {"law": law_echo(target, law_A, law_B)} if model.takes_law else {}
    if erosion != "none":
        settings["erosion"] = {name: run.erosion for name, run in runs.items()}
    if model.takes_table:
        settings["interpolation_error"] = table_error(target, projectile, table, crater,
                                                      runs["runway"])
    return {**settings, "model": label, "interfaces": interface_summary(target, projectile),
            "first_layer_model": first, "resistance": resistance,
            "boundary": boundary, "epsilon": epsilon,
            "table": None if table is None else str(table), "crater": crater,
            "runs": runs, "table2": table2_comparison(runs["runway"]) if paper else None,
            "target_label": target_label(paper, target.debonded),
            "notes": crater_notes(target, projectile, crater)
            + fe_only_notes(target, closed, model.takes_table),
            "debonded": bool(target.debonded),
            "interface_depths": target.interface_depths,
            "title": model.describe(boundary, epsilon, table, settings.get("law")),
            "layer_names": target.layer_names()}


def target_label(paper, debonded):
    """The target in words: "runway (the paper's Table 1)" for the paper's (its layers and
    projectile, whatever the interfaces), else "layered target"; ", debonded interfaces"
    added where any is."""
    if paper:
        return "runway (the paper's Table 1" + (", debonded interfaces)" if debonded else ")")
    return "layered target" + (" (debonded interfaces)" if debonded else "")


def table_error(target, projectile, table, crater, runway):
    """The runway's FE-table interpolation-error estimate
    (:func:`cavex.analytic.penetration.table_error.interpolation_error`: the table with every
    other node in V and in L, the final-depth changes added)."""
    from cavex.analytic.penetration.table_error import interpolation_error
    from cavex.analytic.penetration.tabulated import read_table

    data = table if hasattr(table, "attrs") else read_table(table)
    reference = {"final_depth_m": float(runway.depth[-1]),
                 "phase_end_velocities_m_s": [float(p.end_velocity) for p in runway.phases],
                 "phase_labels": [p.label for p in runway.phases]}
    return interpolation_error(target, projectile, data, crater, reference)


SETTINGS = ("model", "first_layer_model", "resistance", "boundary", "epsilon", "table",
            "law", "crater", "interfaces", "target_label", "notes",
            "erosion")  # "law": the plain law's; "erosion": each run's, with a law only


def interface_summary(target, projectile):
    """Each interface's bonding and, where debonded, its rear-zone depth (m)."""
    return [{"depth_m": H, "bottom": bottom} | (
        {"rear_zone_m": scab_depth(target, projectile, j)} if bottom == "debonded" else {})
        for j, (H, bottom) in enumerate(zip(target.interface_depths, target.bottoms,
                                            strict=True))]


def summary(job):
    """What ``cavex penetrate --json`` prints: the settings, the runway's phases, the rows
    beside the paper's Table 2 (None for another target) and the files written
    (``job["outputs"]``, none before they are)."""
    error = job.get("interpolation_error")  # an FE table's only
    estimate = {} if error is None else {
        "interpolation_error_estimate_m": error["estimate_m"],
        "interpolation_error": {axis: error[axis] for axis in ("velocity", "depth")}}
    return {**{key: job[key] for key in SETTINGS if key in job},
            "phases": phases_as_dicts(job["runs"]["runway"]), "table2": job["table2"],
            "outputs": list(job.get("outputs", ())), **estimate}


def text(job):
    """The phase table, the rows beside the paper's Table 2 and the files written."""
    s = summary(job)
    debonded = [i for i in s["interfaces"] if i["bottom"] == "debonded"]
    lines = [f"model {s['model']}{get(s['resistance']).settings_text(s)}, crater from "
             f"{s['crater']}" + (", debonded interfaces" if debonded else "")]
    if debonded:
        lines.append("debonded interfaces at " + ", ".join(
            f"{i['depth_m']:g} m (rear zone {i['rear_zone_m']:.4g} m)" for i in debonded))
    lines += [f"note: {note}" for note in s["notes"]]
    for run, eroded in (s.get("erosion") or {}).items():
        lines.append(erosion_line(run, eroded))
    stage = (lambda p: f" {p['stage']:<9}") if debonded else (lambda p: "")
    width = max([24, *(len(p["label"]) for p in s["phases"])])  # a long layer name fits
    lines += ["", f"phases ({s['target_label']}):",
              f"{'#':>2}{' stage    ' if debonded else ''} {'label':<{width}} {'L (m)':>8} "
              f"{'V (m/s)':>9} {'t (ms)':>8}  ends because"]
    lines += [f"{p['phase']:>2}{stage(p)} {p['label']:<{width}} {p['end_depth_m']:8.4f} "
              f"{p['end_velocity_m_s']:9.2f} {p['end_time_s'] * 1e3:8.3f}  {p['end_reason']}"
              for p in s["phases"]]
    if "interpolation_error_estimate_m" in s:
        lines.append(interpolation_line(s))
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


def erosion_line(run, eroded):
    """One run's nose erosion in words (``eroded`` None: the law is off at this velocity)."""
    if eroded is None:
        return f"erosion ({run}): off at this striking velocity (the rigid projectile)"
    return (f"erosion ({run}, {eroded['law']}): {eroded['mass_lost_kg']:.4g} kg lost "
            f"({100 * eroded['mass_loss_fraction']:.3g} %), nose CRH {eroded['crh_final']:.3g}, "
            f"eroded tip {eroded['tip_setback_m']:.4g} m behind the original, at "
            f"{eroded['tip_depth_m']:.4f} m")


def interpolation_line(s):
    """The FE table's interpolation-error estimate of the final depth, in words."""
    if s["interpolation_error_estimate_m"] is None:
        return "FE-table interpolation error: no estimate (the table cannot be coarsened)"
    parts = ", ".join(f"every other {axis} node {e['difference_m']:+.4f} m"
                      for axis, e in s["interpolation_error"].items() if e is not None)
    return (f"FE-table interpolation error of the final depth: estimate "
            f"{s['interpolation_error_estimate_m']:.4f} m ({parts})")


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


def fe_only_notes(target, closed, table):
    """A sentence if a layer has FE-only keys (``tau_max``, ``tensile_strength``, the
    hydrostat: the realistic concrete, ``concrete = {..., capped = true}``): the closed forms
    ignore them, so the run flown with the closed form ``closed`` (the first layer alone with a
    table, else both runs) is of another material than the FE's (docs/table2.md)."""
    from cavex.verification.commands.options import fe_only_layers

    named = fe_only_layers(target)
    if not named:
        return []
    runs = "the first layer alone is" if table else "both runs are"
    return [f"{runs} flown with the {closed} closed form, which ignores the FE-only keys of "
            f"{'; '.join(named)}: another material than the FE's; an FE table of the target "
            "carries them (docs/table2.md)"]


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
        written.append(write_columns_csv(out / f"trajectory_{run_stem(name)}.csv",
                                         trajectory.rows(),
                                         TRAJECTORY_QUANTA))
    rows = phases_as_dicts(job["runs"]["runway"])
    if not job["debonded"]:  # the stage column only where there is more than one tunnel
        rows = [{k: v for k, v in row.items() if k != "stage"} for row in rows]
    written.append(write_columns_csv(out / f"phases_{run_stem('runway')}.csv", _columns(rows)))
    if draw:
        from cavex.verification.report.penetration_figures import figures

        written += figures(job, out)
    return [str(p) for p in written]


def _columns(rows):
    return {key: [row[key] for row in rows] for key in rows[0]}
