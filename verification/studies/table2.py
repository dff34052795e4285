"""The paper's Table 2 and how a computed trajectory's phases map onto its rows.

Row definitions (She 2020, text under Table 2):

1. crater: end of the crater stage;
2. "before b reaches H1": the first phase end at which the response state leaves ``a``
   (the elastic-plastic boundary reaches the concrete-macadam interface);
3. "b past H1, still in concrete": the nose tip reaches ``H1``;
4. "in macadam": the projectile stops.
"""

import math

PAPER_TABLE2 = (
    {"phase": 1, "name": "crater", "depth_m": 0.12, "velocity_m_s": 894.7, "time_s": 0.12e-3},
    {"phase": 2, "name": "before b reaches H1", "depth_m": 0.40, "velocity_m_s": 506.4,
     "time_s": 0.53e-3},
    {"phase": 3, "name": "b past H1, still in concrete", "depth_m": 0.65, "velocity_m_s": 284.3,
     "time_s": 1.20e-3},
    {"phase": 4, "name": "in macadam (stop)", "depth_m": 0.79, "velocity_m_s": 0.0,
     "time_s": 2.40e-3},
)

ROW_KEYS = ("depth_m", "velocity_m_s", "time_s")
# half a unit of the last digit Table 2 prints: L to 0.01 m, V to 0.1 m/s, t to 0.01 ms
PRINT_HALF_UNIT = {"depth_m": 0.005, "velocity_m_s": 0.05, "time_s": 0.005e-3}
#: where a reader finds why rows are not reproduced (the readings of the paper's model)
WHY = "docs/table2.md"

# The older runway formula the paper quotes (its ref. 10): velocity after the concrete layer.
PAPER_REF10_EXIT_VELOCITY = 283.39


def table2_rows(trajectory):
    """Our ``(depth, velocity, time)`` at the end of each Table 2 row, or None where absent."""
    phases = trajectory.phases
    crater = next((p for p in phases if p.label == "crater"), None)
    left_a = next((p for p, q in zip(phases, phases[1:], strict=False)
                   if p.label.endswith("(a)") and not q.label.endswith("(a)")), None)
    at_h1 = next((p for p in phases if p.end_reason == "nose tip reached interface 1"), None)
    stop = phases[-1] if phases and phases[-1].end_reason == "projectile stopped" else None
    return [phase_row(p) for p in (crater, left_a, at_h1, stop)]


def phase_row(phase):
    """``{"depth_m", "velocity_m_s", "time_s"}`` where ``phase`` ends (None for None)."""
    if phase is None:
        return None
    return {"depth_m": phase.end_depth, "velocity_m_s": phase.end_velocity,
            "time_s": phase.end_time}


def table2_comparison(trajectory):
    """List of ``{"phase", "name", "paper": {...}, "ours": {...} or None, "reproduced"}``;
    a row is reproduced when :func:`row_score` is 0 (each of L, V, t within the precision Table
    2 prints)."""
    rows = [{"phase": paper["phase"], "name": paper["name"],
             "paper": {k: paper[k] for k in ROW_KEYS}, "ours": ours}
            for paper, ours in zip(PAPER_TABLE2, table2_rows(trajectory), strict=True)]
    return [{**row, "reproduced": bool(row_score(row) == 0.0)} for row in rows]


def row_score(row):
    """Worst relative discrepancy of a row beyond the precision Table 2 prints.

    For each of ``L``, ``V``, ``t``: ``max(0, |ours - paper| - half unit of the last printed
    digit) / paper``; the stop velocity (0 in both) is not counted. ``inf`` if the row is absent.
    """
    if row["ours"] is None:
        return math.inf
    excess = [max(0.0, abs(row["ours"][k] - row["paper"][k]) - PRINT_HALF_UNIT[k])
              / row["paper"][k] for k in ROW_KEYS if row["paper"][k] != 0.0]
    return max(excess)


def not_reproduced_line(comparison):
    """One sentence under the comparison: which rows are not reproduced and where to read why
    (:data:`WHY`)."""
    missed = [str(row["phase"]) for row in comparison if not row["reproduced"]]
    if not missed:
        return "every row reproduced to the precision Table 2 prints"
    rows = "row " + missed[0] if len(missed) == 1 else "rows " + ", ".join(missed)
    return (f"{rows} not reproduced to the precision Table 2 prints (the paper's undefined "
            f"choices and printed errors, not numerics): what reproduces which row, and why: "
            f"{WHY}")
