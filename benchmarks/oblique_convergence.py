"""Convergence of the 3-D oblique model in every discretisation parameter (issue 30).

Each series varies one parameter from the defaults, the others at their defaults: nose points
(Gauss points in phi), azimuths, shank rings (:func:`cavex.analytic.penetration.body.build_body`),
the integrator tolerance ``rtol`` (``atol = 1e-3 rtol``), the contact ramp, and the held
contact (``--contact-hold``) instead of the ramp; and the refined rerun of ``--estimate``
(:mod:`cavex.analytic.penetration.refinement`). Shots: the runway bonded and debonded at
300, 600 and 1000 m/s and 0, 20 and 45 deg (a subset of the oblique study's grid, which adds
400 and 800 m/s and 10, 30, 60 deg: the full grid over every level is too slow on two shared
cores). Quantities: final nose-tip depth, final pitch, each phase's pitch change, the added
turn at the first debonded interface (the phase after the nose tip crosses it, debonded minus
bonded, :func:`cavex.verification.studies.oblique_study.turn_after_interface`), the largest
axial overload and the overload peaks (:func:`cavex.analytic.penetration.oblique.overload_peaks`).

Prints, per series and level, the largest change over the shots against the series' finest
level and a fitted rate (``np.polyfit`` of log change on log level); writes every run's
numbers to ``results/oblique/convergence.json`` (``--out``).

Run as ``python benchmarks/oblique_convergence.py [--workers 2] [--out FILE]``;
``--table FILE`` prints the tables again from a written file.
"""

import argparse
import json
import sys
import time
from multiprocessing import Pool
from pathlib import Path

import numpy as np

from cavex.analytic.penetration.body import AZIMUTHS, NOSE_POINTS, SHANK_RINGS

INTERFACES = ("bonded", "debonded")
VELOCITIES = (300.0, 600.0, 1000.0)
OBLIQUITIES = (0.0, 20.0, 45.0)
RTOL, RAMP = 1e-3, 0.01  # the defaults (oblique.RTOL, oblique.CONTACT_RAMP)
DEFAULT = {"nose_points": NOSE_POINTS, "azimuths": AZIMUTHS, "shank_rings": SHANK_RINGS,
           "rtol": RTOL, "contact_ramp": RAMP}
SERIES = {
    "nose_points": (8, 16, 24, 32, 48, 64),
    "azimuths": (8, 16, 32),
    "shank_rings": (8, 16, 32),
    "rtol": (3e-3, 1e-3, 3e-4),
    "contact_ramp": (0.03, 0.01, 0.003),
}
# the surface rule refined as a whole: nose points, azimuths and shank rings times each factor
UNIFORM = (1.0, 1.5, 2.0)
HOLD = 1e-6  # m, the held contact (600 m/s shots only: its runs are the slowest)
# the first interface of the default runway and the window of "a peak at it" (oblique_study)
INTERFACE, WINDOW = 0.65, (0.1, 0.166)


def settings_list():
    """Every distinct setting: ``(name, options)``."""
    out = {}
    for key, levels in SERIES.items():
        for level in levels:
            options = {**DEFAULT, key: level}
            out[_name(options)] = options
    for factor in UNIFORM[1:]:
        options = {**DEFAULT, **{k: int(round(factor * DEFAULT[k]))
                                 for k in ("nose_points", "azimuths", "shank_rings")}}
        out[_name(options)] = options
    out["hold"] = {**DEFAULT, "contact_hold": HOLD}
    out["refined"] = {"nose_points": 2 * NOSE_POINTS, "azimuths": 2 * AZIMUTHS,
                      "shank_rings": 2 * SHANK_RINGS, "rtol": RTOL / 3.0,
                      "contact_ramp": RAMP / 2.0}
    return out


def _name(options):
    return ("n{nose_points}_a{azimuths}_s{shank_rings}_rtol{rtol:g}_ramp{contact_ramp:g}"
            .format(**options))


def run_one(task):
    """Numbers of one shot at one setting."""
    from cavex.analytic.models import make_law
    from cavex.analytic.penetration.body import build_body
    from cavex.analytic.penetration.oblique import ObliqueModel, Strike, overload_peaks, peaks
    from cavex.config import load_config
    from cavex.verification.studies.oblique_study import turn_after_interface

    name, options, (interfaces, speed, obliquity) = task
    target, projectile = load_config()
    target = target.with_interfaces(interfaces)
    body = build_body(projectile, options["nose_points"], options["azimuths"],
                      options["shank_rings"])
    hold = options.get("contact_hold", 0.0)
    model = ObliqueModel(target, projectile, make_law(target, projectile), body=body,
                         rtol=options["rtol"], atol=1e-3 * options["rtol"],
                         contact_ramp=options["contact_ramp"], contact_hold=hold)
    start = time.perf_counter()
    result = model.run(Strike(speed, obliquity=obliquity))
    wall = time.perf_counter() - start
    return {"setting": name, "interfaces": interfaces, "speed_m_s": speed,
            "obliquity_deg": obliquity, "wall_s": wall,
            "steps": int(sum(s.t.size - 1 for s in result.solutions)),
            "tip_depth_m": result.end["nose_tip_m"][2], "pitch_deg": result.end["pitch_deg"],
            "phases": [[p["end_reason"], p["pitch_change_deg"]] for p in result.phases],
            "turn_after_interface_deg": turn_after_interface(result),
            "max_axial_g": peaks(result.history)["max_axial_g"],
            "overload_peaks": overload_peaks(result.history)}


def tasks(names=None):
    out = []
    for name, options in settings_list().items():
        if names and name not in names:
            continue
        for shot in ((i, v, o) for i in INTERFACES for v in VELOCITIES for o in OBLIQUITIES):
            if name == "hold" and shot[1] != 600.0:
                continue
            out.append((name, options, shot))
    return out


# --- tables -----------------------------------------------------------------------------------

def _interface_peak(run):
    """The largest overload peak at the first interface (g), None: none."""
    near = [g for z, g in run["overload_peaks"]
            if INTERFACE - WINDOW[0] <= z <= INTERFACE + WINDOW[1]]
    return max(near) if near else None


def _added(runs, setting, speed, obliquity):
    by = {r["interfaces"]: r for r in runs if r["setting"] == setting
          and r["speed_m_s"] == speed and r["obliquity_deg"] == obliquity}
    turns = [by[i]["turn_after_interface_deg"] if i in by else None for i in INTERFACES]
    return None if None in turns else turns[1] - turns[0]


def changes(runs, setting, reference):
    """Largest change over the shots of every quantity, ``setting`` against ``reference``."""
    index = {(r["setting"], r["interfaces"], r["speed_m_s"], r["obliquity_deg"]): r
             for r in runs}
    out = {"depth_rel": 0.0, "pitch_deg": 0.0, "phase_deg": 0.0, "added_deg": 0.0,
           "axial_rel": 0.0, "peaks_differ": 0, "interface_peak": [], "wall_s": []}
    shots = sorted({k[1:] for k in index if k[0] == setting})
    for shot in shots:
        a, b = index[(setting, *shot)], index.get((reference, *shot))
        out["wall_s"].append(a["wall_s"])
        if b is None:
            continue
        out["depth_rel"] = max(out["depth_rel"],
                               abs(a["tip_depth_m"] / b["tip_depth_m"] - 1.0))
        out["pitch_deg"] = max(out["pitch_deg"], abs(a["pitch_deg"] - b["pitch_deg"]))
        if [p[0] for p in a["phases"]] == [p[0] for p in b["phases"]]:
            out["phase_deg"] = max([out["phase_deg"]] + [abs(x[1] - y[1]) for x, y in zip(
                a["phases"], b["phases"], strict=True)])
        else:
            out["phase_deg"] = float("nan")
        out["axial_rel"] = max(out["axial_rel"],
                               abs(a["max_axial_g"] / b["max_axial_g"] - 1.0))
        pa = [round(z / 0.04) for z, _ in a["overload_peaks"]]
        pb = [round(z / 0.04) for z, _ in b["overload_peaks"]]
        out["peaks_differ"] += int(len(pa) != len(pb))
        if shot[0] == "debonded" and shot[1] == 600.0 and shot[2] == 20.0:
            out["interface_peak"] = [_interface_peak(a), _interface_peak(b)]
    for v in VELOCITIES:
        for o in OBLIQUITIES[1:]:
            x, y = _added(runs, setting, v, o), _added(runs, reference, v, o)
            if x is not None and y is not None:
                out["added_deg"] = max(out["added_deg"], abs(x - y))
    out["wall_s"] = float(np.median(out["wall_s"])) if out["wall_s"] else float("nan")
    return out


def _rate(levels, errors):
    """Fitted order: slope of log error on log level (levels with a non-zero error)."""
    pairs = [(x, e) for x, e in zip(levels, errors, strict=True) if e > 0 and np.isfinite(e)]
    if len(pairs) < 2:
        return float("nan")
    x, e = np.log(np.array(pairs)).T
    return float(np.polyfit(x, e, 1)[0])


DEPTH_TOL, PITCH_TOL_DEG, PITCH_TOL_REL = 1e-3, 0.01, 0.03  # the tolerances


def shot_table(runs, uniform):
    """Per shot: the default's depth and pitch, and their changes against the finest level of
    each series, the refined rerun and the uniformly refined rule; whether every change is
    within the tolerances (depth 0.1 %, pitch max(0.01 deg, 3 %))."""
    index = {(r["setting"], r["interfaces"], r["speed_m_s"], r["obliquity_deg"]): r
             for r in runs}
    default = _name(DEFAULT)
    finest = [_name({**DEFAULT, key: (levels[-1] if key not in ("rtol", "contact_ramp")
                                      else min(levels))}) for key, levels in SERIES.items()]
    against = [*finest, "refined", uniform]
    lines = ["", "per shot, the default against the finest level of each series ("
             + ", ".join(against) + "):", "",
             "| shot | depth (m) | pitch (deg) | depth changes (%) | pitch changes (deg) | "
             "within tolerance |", "|---|---|---|---|---|---|"]
    for shot in sorted({k[1:] for k in index if k[0] == default}):
        a = index[(default, *shot)]
        depth = [100 * (a["tip_depth_m"] / index[(n, *shot)]["tip_depth_m"] - 1.0)
                 for n in against if (n, *shot) in index]
        pitch = [a["pitch_deg"] - index[(n, *shot)]["pitch_deg"]
                 for n in against if (n, *shot) in index]
        ok = (max(map(abs, depth)) <= 100 * DEPTH_TOL and max(map(abs, pitch)) <= max(
            PITCH_TOL_DEG, PITCH_TOL_REL * abs(a["pitch_deg"])))
        lines.append(f"| {shot[0]} {shot[1]:g} m/s {shot[2]:g} deg | {a['tip_depth_m']:.3f} | "
                     f"{a['pitch_deg']:.2f} | " + " / ".join(f"{d:+.3f}" for d in depth)
                     + " | " + " / ".join(f"{p:+.3f}" for p in pitch)
                     + f" | {'yes' if ok else 'no'} |")
    return lines


def tables(runs):
    """The tables (text, markdown)."""
    names = settings_list()
    lines = []
    header = ("| {0} | depth change (%) | final pitch (deg) | phase pitch change (deg) | added "
              "turn (deg) | largest axial (%) | shots whose peaks differ | interface peak "
              "600/20 debonded (g) | median time (s) |")
    for key, levels in SERIES.items():
        last = levels[-1] if key not in ("rtol", "contact_ramp") else min(levels)
        finest = _name({**DEFAULT, key: last})
        lines += ["", f"{key} (against {key} = {last:g}):", "",
                  header.format(key), "|---|---|---|---|---|---|---|---|---|"]
        errors = {q: [] for q in ("depth_rel", "pitch_deg", "phase_deg", "added_deg",
                                  "axial_rel")}
        coarse = []
        for level in levels:
            name = _name({**DEFAULT, key: level})
            c = changes(runs, name, finest)
            if name != finest:
                coarse.append(level)
                for q in errors:
                    errors[q].append(c[q])
            peak = c["interface_peak"][0] if c["interface_peak"] else None
            lines.append(f"| {level:g}{' (default)' if level == DEFAULT[key] else ''} | "
                         f"{100 * c['depth_rel']:.3f} | {c['pitch_deg']:.4f} | "
                         f"{c['phase_deg']:.4f} | {c['added_deg']:.4f} | "
                         f"{100 * c['axial_rel']:.2f} | {c['peaks_differ']} | "
                         f"{'-' if peak is None else f'{peak:.0f}'} | {c['wall_s']:.2f} |")
        rates = {q: _rate(coarse, e) for q, e in errors.items()}
        lines.append("| fitted rate | " + " | ".join(
            f"{rates[q]:.2f}" for q in ("depth_rel", "pitch_deg", "phase_deg", "added_deg",
                                        "axial_rel")) + " | | | |")
    uniform = [_name({**DEFAULT, **{k: int(round(f * DEFAULT[k]))
                                    for k in ("nose_points", "azimuths", "shank_rings")}})
               for f in UNIFORM]
    lines += ["", f"surface rule refined as a whole (nose points, azimuths, shank rings x "
              f"{', '.join(f'{f:g}' for f in UNIFORM)}; against x {UNIFORM[-1]:g}):", "",
              header.format("factor"), "|---|---|---|---|---|---|---|---|---|"]
    for factor, name in zip(UNIFORM, uniform, strict=True):
        c = changes(runs, name, uniform[-1])
        peak = c["interface_peak"][0] if c["interface_peak"] else None
        lines.append(f"| {factor:g}{' (default)' if factor == 1.0 else ''} | "
                     f"{100 * c['depth_rel']:.3f} | {c['pitch_deg']:.4f} | "
                     f"{c['phase_deg']:.4f} | {c['added_deg']:.4f} | "
                     f"{100 * c['axial_rel']:.2f} | {c['peaks_differ']} | "
                     f"{'-' if peak is None else f'{peak:.0f}'} | {c['wall_s']:.2f} |")
    lines += shot_table(runs, uniform[-1])
    default = _name(DEFAULT)
    lines += ["", "default against the refined rerun (--estimate) and against the held contact:",
              "", header.format("setting"), "|---|---|---|---|---|---|---|---|---|"]
    for name in ("refined", "hold"):
        c = changes(runs, default, name)
        peak = c["interface_peak"]
        lines.append(f"| default vs {name} | {100 * c['depth_rel']:.3f} | "
                     f"{c['pitch_deg']:.4f} | {c['phase_deg']:.4f} | {c['added_deg']:.4f} | "
                     f"{100 * c['axial_rel']:.2f} | {c['peaks_differ']} | "
                     + (" / ".join('-' if p is None else f'{p:.0f}' for p in peak) or "-")
                     + f" | {changes(runs, name, default)['wall_s']:.2f} |")
    lines += ["", "added turn at the first debonded interface, 600 m/s at 20 deg (deg):", ""]
    for name in names:
        x = _added(runs, name, 600.0, 20.0)
        if x is not None:
            lines.append(f"- {name}: {x:+.4f}")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", default="results/oblique/convergence.json")
    parser.add_argument("--table", help="print the tables of a written file")
    parser.add_argument("--reuse", help="a written file whose runs of the same settings (same "
                        "code) are kept instead of being run again")
    args = parser.parse_args(argv)
    if args.table:
        print(tables(json.loads(Path(args.table).read_text())["runs"]))
        return 0
    old = json.loads(Path(args.reuse).read_text()) if args.reuse else {"runs": [], "settings": {}}
    names = settings_list()
    runs = [r for r in old["runs"] if old["settings"].get(r["setting"]) == names.get(r["setting"])]
    done = {(r["setting"], r["interfaces"], r["speed_m_s"], r["obliquity_deg"]) for r in runs}
    work = [t for t in tasks() if (t[0], *t[2]) not in done]
    with Pool(args.workers) as pool:
        for k, run in enumerate(pool.imap_unordered(run_one, work), 1):
            runs.append(run)
            print(f"{k}/{len(work)} {run['setting']} {run['interfaces']} {run['speed_m_s']:g} "
                  f"{run['obliquity_deg']:g}: {run['wall_s']:.2f} s", file=sys.stderr,
                  flush=True)
    runs.sort(key=lambda r: (r["setting"], r["interfaces"], r["speed_m_s"], r["obliquity_deg"]))
    Path(args.out).write_text(json.dumps({"settings": settings_list(), "runs": runs},
                                         indent=1) + "\n")
    print(tables(runs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
