"""The oblique study's analysis functions (verification/studies/oblique_study.py) on known
input: every shot at the default discretisation and refined, each number with its estimate."""

import csv
from pathlib import Path

import pytest

from cavex.verification.studies.oblique_study import (
    findings,
    report_md,
    split_ulp,
    study_cases,
    table_csv,
)


def _shot(o, v, target, change, deep, peaks, depth, level="default"):
    return {"obliquity_deg": o, "speed_m_s": v, "target": target, "state": "stopped",
            "discretisation": level, "tip_x_m": 0.1, "tip_z_m": depth, "pitch_deg": o + change,
            "pitch_change_deg": change, "pitch_change_deep_deg": deep,
            "max_pitch_rate_deg_s": 1e3, "max_axial_g": 2e4,
            "max_lateral_g": 1e4 if o else 1e-5,
            "max_lateral_low_pass_g": 6e3 if o else 1e-5, "overload_peaks": peaks}


def test_findings_are_computed_from_the_table():
    """Three shots at 20 deg: one stops in concrete; two reach the interface. At 600 m/s the
    added turn moves by 0.3 deg under the refinement (-0.5 -> -0.2: not resolved) and its
    interface peak does not survive it; at 800 m/s the turn moves by 0.005 deg (-0.3: resolved)
    and its peak survives within 1 %."""
    results = []
    rows = {400.0: (None, None, None, None), 600.0: (-0.5, -0.2, (0.6, 1e4), None),
            800.0: (-0.3, -0.305, (0.6, 1e4), (0.61, 1.01e4))}
    for v, (added, fine, peak, fine_peak) in rows.items():
        reach = added is not None
        for level, turn, extra in (("default", added, peak), ("refined", fine, fine_peak)):
            peaks = [(0.04, 2e4)] + ([extra] if extra else [])
            results.append(_shot(20.0, v, "runway", 1.0, turn if reach else None, peaks,
                                 1.0 if reach else 0.4, level))
            results.append(_shot(20.0, v, "first layer only", 1.2, 0.0 if reach else None,
                                 [(0.04, 2e4)], 0.9 if reach else 0.4, level))
    for level in ("default", "refined"):
        results.append(_shot(0.0, 800.0, "runway", 0.0, 0.0, [(0.04, 2e4)], 1.2, level))
        results.append(_shot(0.0, 800.0, "first layer only", 0.0, 0.0, [(0.04, 2e4)], 1.0,
                             level))
    answers = findings(results, [0.65, 1.1])
    assert answers["shots_reaching_the_interface"] == 2
    assert answers["stop_before_the_interface"] == ["20 deg 400 m/s"]
    assert answers["toward_the_normal"] == 2
    assert answers["added_change_range_deg"] == pytest.approx([-0.5, -0.3])
    assert answers["largest_estimate_deg"] == pytest.approx(0.3)
    assert answers["within_tolerance"] == 1  # 0.005 deg at -0.3 (tolerance max(0.01, 0.009))
    assert answers["resolved_nonzero"] == 2  # |-0.5| > 0.3, |-0.3| > 0.005
    # 0.65 crossed by the two deep layered shots and the normal one, 1.1 by the normal one;
    # the 800 m/s peak at 0.6 survives (0.61 refined), the 600 m/s one does not
    assert answers["interfaces_crossed"] == 4 and answers["interfaces_with_a_peak"] == 1
    assert answers["interface_peaks_resolved"] == 1
    assert answers["interface_peaks_not_surviving"] == 1
    lines = table_csv(results).splitlines()
    assert lines[0].startswith("obliquity_deg,speed_m_s,discretisation,target")
    normal = next(line for line in lines if line.startswith("0,800,default,runway"))
    assert normal.split(",")[5:7] == ["0.100", "1.200"]  # depths and positions to 1 mm
    assert normal.split(",")[12] == "0"  # lateral overload 1e-5 g: under the noise floor
    report = report_md(results, answers, [0.65, 1.1])
    assert "-0.500 +- 0.300" in report  # the 600 m/s added turn with its estimate
    assert "(not surviving: 0.600)" in report


def test_debonded_study_marks_rows_that_move_one_ulp_faster():
    """The debonded study flies every default runway shot again one ulp faster (study_cases)
    and marks each runway row ``one_ulp_stable`` yes/no by whether it reads the same; the
    report names the rows that move. Constructed: two shots, one whose pitch moves by 0.002
    deg."""
    cases = study_cases((20.0,), (600.0,), interfaces="debonded")
    assert sum(1 for c in cases if c.get("ulp")) == 1  # default runway shots only
    assert all(c["target"] == "runway" and c["discretisation"] == "default"
               for c in cases if c.get("ulp"))
    assert not any(c.get("ulp") for c in study_cases((20.0,), (600.0,)))  # bonded: none
    results = []
    for v, moved in ((600.0, 0.0), (800.0, 0.002)):
        for level in ("default", "refined"):
            results.append(_shot(20.0, v, "runway", 1.0, 0.1, [(0.6, 1e4)], 0.8, level))
            results.append(_shot(20.0, v, "first layer only", 1.0, 0.1, [(0.04, 2e4)], 0.7,
                                 level))
        faster = _shot(20.0, v, "runway", 1.0 + moved, 0.1, [(0.6, 1e4)], 0.8)
        results.append({**faster, "ulp": True})
    nominal, faster = split_ulp(results)
    assert len(nominal) == 8 and len(faster) == 2
    lines = table_csv(nominal, faster).splitlines()
    assert lines[0].endswith(",max_lateral_low_pass_g,overload_peak_depths_m,one_ulp_stable")
    assert all(line.split(",")[13] == "6e+03" for line in lines[1:])  # the low-pass peak
    flags = {(line.split(",")[1], line.split(",")[2], line.split(",")[3]): line.split(",")[-1]
             for line in lines[1:]}
    assert flags[("600", "default", "runway")] == "yes"
    assert flags[("800", "default", "runway")] == "no"
    assert flags[("600", "default", "first layer only")] == ""
    assert flags[("600", "refined", "runway")] == ""  # the refined rows are not repeated
    answers = findings(nominal, [0.65, 1.1])
    report = report_md(nominal, answers, [0.65, 1.1], faster)
    assert "## Reproducibility" in report and "20 deg 800 m/s" in report
    assert "20 deg 600 m/s" not in report.split("## Reproducibility")[1]
    assert "lateral peak over one nose length" in report
    bonded = table_csv(nominal)  # bonded: no low-pass or ulp columns
    assert "one_ulp_stable" not in bonded and "low_pass" not in bonded


def test_committed_debonded_low_pass_peaks():
    """results/oblique/debonded/study.csv: every shot at both levels, and the peak of a running
    mean never exceeds the raw peak (both written to 3 digits)."""
    path = Path(__file__).resolve().parents[1] / "results" / "oblique" / "debonded" / "study.csv"
    rows = list(csv.DictReader(path.open()))
    assert len(rows) == 96 and {r["discretisation"] for r in rows} == {"default", "refined"}
    for row in rows:
        raw, mean = float(row["max_lateral_g"]), float(row["max_lateral_low_pass_g"])
        assert mean <= raw * (1.0 + 1e-2) + 1.0  # 3 digits each; 1 g the noise floor
