"""The oblique study's analysis functions (verification/studies/oblique_study.py) on known
input: every shot at the default discretisation and refined, each number with its estimate."""

import csv
from pathlib import Path

import numpy as np
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


def _study_rows(name):
    """The committed study.csv of ``results/oblique/<name>`` as the study's result dicts
    (numbers as floats, "-" as None)."""
    path = Path(__file__).resolve().parents[1] / "results" / "oblique" / name / "study.csv"
    rows = []
    for row in csv.DictReader(path.open()):
        entry = {}
        for key, value in row.items():
            try:
                entry[key] = float(value)
            except ValueError:
                entry[key] = None if value == "-" else value
        rows.append(entry)
    return rows


def _boxes_overlap(artists, renderer):
    boxes = [a.get_window_extent(renderer) for a in artists if a.get_text()]
    return any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])


def test_pitch_change_gives_the_turn_over_its_own_panel(tmp_path, monkeypatch):
    """Issue 33: the debonded 45 deg turn-over (~50 deg) squashed the other added turns
    (within +-1.3 deg) to a line. Now it is drawn in a panel of its own above them, the lower
    panel spans at most 4 deg, and the two panels' titles do not overlap; the bonded study
    (no such gap) keeps one panel per quantity."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cavex.verification.studies import oblique_study

    saved = {}
    monkeypatch.setattr(oblique_study, "save_figure",
                        lambda fig, path, **_: saved.setdefault(path.parent.name, fig))
    for name in ("debonded", "bonded"):
        folder = tmp_path / name
        folder.mkdir()
        rows = _study_rows("debonded" if name == "debonded" else "")
        oblique_study.pitch_change_figure(rows, folder, plt)
    fig = saved["debonded"]
    fig.canvas.draw()
    assert len(fig.axes) == 4  # two quantities, each a broken axis
    added = oblique_study._added(_study_rows("debonded"), "default")
    large = max(added.values())
    low, high = fig.axes[2].get_ylim()  # the added turn's lower panel
    assert high - low <= 4.0 and large > 40.0
    upper_low, upper_high = fig.axes[3].get_ylim()
    assert upper_low < 13.0 and large < upper_high  # the 45 deg turns in the upper panel
    titles = [ax.title for ax in fig.axes if ax.get_title()]
    assert len(titles) == 2 and not _boxes_overlap(titles, fig.canvas.get_renderer())
    assert len(saved["bonded"].axes) == 2


def test_symlog_axis_labels_both_sides_of_zero():
    """Issue 33: the debonded study's symmetric-log axes had no labelled negative tick. Data
    from -1.2 to 50 get -1, -0.5, 0, 0.5, 1, 10 (and 100 if in view), each labelled."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cavex.verification.studies.study_axes import symlog_axis

    fig, ax = plt.subplots()
    values = [-1.2, -0.3, 0.1, 0.28, 13.0, 50.0]
    ax.plot(range(len(values)), values)
    symlog_axis(ax, values)
    fig.canvas.draw()
    labels = {t.get_text() for t in ax.get_yticklabels() if t.get_text()}
    assert {"-1", "-0.5", "0", "0.5", "1", "10"} <= labels
    low, high = ax.get_ylim()
    assert low <= min(values) and max(values) <= high
    plt.close(fig)


def test_sensitivity_figure_labels_do_not_overlap_and_an_empty_panel_says_why(tmp_path,
                                                                              monkeypatch):
    """Issue 33: the two rows' long y labels overlapped and the crater column's peak panel was
    empty (no crater size gives an interface peak). Now each panel's title names the answer,
    no two y labels of a column overlap, and the empty panel holds a note."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cavex.verification.studies import oblique_study

    numbers = {}
    for v, added, peak in ((1.5, 0.05, None), (2.12, 0.09, None), (2.5, 0.2, (0.67, 1.07e4)),
                           (3.0, -0.45, (0.66, 1.071e4)), (3.5, 48.0, (0.66, 1.056e4))):
        numbers[("rear zone (calibres)", v)] = {"added": (added, added * 0.9),
                                                "peak": (peak, peak)}
    for v in (3.0, 4.0, 4.5, 5.0, 6.0):
        numbers[("crater (shank radii)", v)] = {"added": (0.0948, 0.0961),
                                                "peak": (None, None)}
    saved = {}
    monkeypatch.setattr(oblique_study, "save_figure",
                        lambda fig, path, **_: saved.setdefault("fig", fig))
    oblique_study.sensitivity_figure(tmp_path, numbers, plt)
    fig = saved["fig"]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    axes = np.array(fig.axes).reshape(2, 2)
    for col in range(2):
        assert not _boxes_overlap([axes[0, col].yaxis.label, axes[1, col].yaxis.label],
                                  renderer)
    assert "no axial peak" in " ".join(t.get_text() for t in axes[1, 1].texts)
    assert axes[0, 0].get_yscale() == "symlog"
    assert any(t.get_text().startswith("-") for t in axes[0, 0].get_yticklabels())
    plt.close(fig)
