"""The verification report: files, numbers traced to grid.nc, validity, failure paths."""

import json
import re

import numpy as np
import pytest
import xarray as xr
from cf_check import check_cf, check_quantify

from cavex.config import default_config_text, load_config
from cavex.verification.fedata import table as table_module
from cavex.verification.report import build as report
from cavex.verification.report import picture as report_picture
from cavex.verification.report.analysis import TOLERANCES

PNG = b"\x89PNG\r\n\x1a\n"
PERCENT = re.compile(r"^([+-]\d+\.\d{3}) %$")


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory):
    """``verify(quick=True)`` on the default target (the real FE table, 2 workers)."""
    out = tmp_path_factory.mktemp("quick")
    target, projectile = load_config()
    summary = report.verify(target, projectile, quick=True, out_dir=out, workers=2,
                            config_text=default_config_text())
    return out, summary, xr.load_dataset(out / "grid.nc", engine="scipy")


def appendix_rows(markdown):
    """Rows of the appendix cell table as lists of cell strings."""
    section = markdown.split("## Appendix: every cell", 1)[1]
    lines = [x for x in section.splitlines() if x.startswith("|")]
    header = [c.strip() for c in lines[0].strip("|").split("|")]
    return header, [[c.strip() for c in x.strip("|").split("|")] for x in lines[2:]]


PNGS = ["error_maps", "validity", "S_depth", "states", "plastic_radius", "error_estimate",
        "stresses", "trajectories"]


def test_quick_report_writes_every_file(quick_report):
    out, summary, grid = quick_report
    for name in ("report.md", "report.html", "grid.nc", "target.toml"):
        assert (out / name).stat().st_size > 0
    for name in PNGS:
        assert (out / f"{name}.png").read_bytes()[:8] == PNG, name
    html = (out / "report.html").read_text()
    assert html.count("<img ") == len(PNGS) and "<table>" in html
    assert summary["cells"] == grid.sizes["velocity"] * grid.sizes["depth"] >= 3 * 3
    assert grid.sizes["velocity"] == len(report.QUICK_VELOCITY_FRACTIONS) == 5
    assert set(np.unique(grid["wall_layer"])) == {0, 1, 2}
    # nothing that differs from run to run: wall times and the creation time only in the summary
    assert summary["wall_time_s"] > 0 and summary["created"]
    assert "created" not in grid.attrs and "wall_time_s" not in grid.attrs["report"]
    for name in ("report.md", "report.html"):
        text = (out / name).read_text()
        assert "wall time" not in text and summary["created"] not in text
        assert str(out) not in text


def test_report_numbers_equal_grid(quick_report):
    out, _, grid = quick_report
    header, rows = appendix_rows((out / "report.md").read_text())
    assert len(rows) == grid.sizes["velocity"] * grid.sizes["depth"]
    col = {name: i for i, name in enumerate(header)}
    checked = 0
    for row in rows:
        cell = grid.sel(velocity=float(row[0]), depth=float(row[1]), method="nearest")
        assert abs(float(cell.velocity) - float(row[0])) < 1e-9
        if bool(cell["failed"]):
            assert row[col["flags"]] == "FE FAILED"
            continue
        assert float(row[col["FE sigma_r (MPa)"]]) == pytest.approx(
            float(cell["sigma_r"]) / 1e6, abs=5e-5)
        for key, name in (("dynamic", "derived-dynamic error"),
                          ("quasi_static", "derived-quasi-static error"),
                          ("paper", "paper error")):
            printed = float(PERCENT.match(row[col[name]]).group(1))
            assert printed == pytest.approx(100 * float(cell[f"rel_err_{key}"]), abs=5e-4)
            checked += 1
        meanings = dict(zip(cell["state_dynamic"].attrs["flag_values"].tolist(),
                            cell["state_dynamic"].attrs["flag_meanings"].split(), strict=True))
        assert row[col["state (dynamic)"]] == meanings[int(cell["state_dynamic"])]
    assert checked >= 3 * 20


def test_quick_report_is_complete(quick_report):
    """The quick grid reaches the crater's end and V0: the trajectory comparison is there."""
    out, summary, grid = quick_report
    md = (out / "report.md").read_text()
    section = md.split("## Trajectories: closed forms against the FE table", 1)[1]
    assert "not possible" not in md and "![trajectories](trajectories.png)" in section
    rows = [x for x in section.split("\n## ", 1)[0].splitlines() if x.startswith("| ")]
    names = [r.strip("|").split("|")[0].strip() for r in rows[1:5]]
    assert names == ["derived-quasi-static", "derived-dynamic", "paper", "table"]
    trajectories = json.loads(grid.attrs["trajectories"])
    assert trajectories["table"]["final_depth_m"] > 1.3  # through all three layers
    target, projectile = load_config()
    assert grid.depth.values[0] <= 0.06 + 4.5 * projectile.r  # the crater's end (nose base)
    assert grid.velocity.values[-1] >= projectile.V0
    assert "stress figure not drawn" not in md and "![stresses](stresses.png)" in md


def test_report_html_is_self_contained_and_leads_with_a_figure(quick_report):
    out, _, _ = quick_report
    import xml.etree.ElementTree as ET
    from html.parser import HTMLParser

    html = (out / "report.html").read_text()
    root = ET.fromstring(html.split("\n", 1)[1])  # well-formed (after the DOCTYPE line)
    sources, hrefs = [], []

    class Collect(HTMLParser):
        def handle_starttag(self, tag, attrs):
            attrs = dict(attrs)
            if "src" in attrs:
                sources.append(attrs["src"])
            if tag == "a":
                hrefs.append(attrs["href"])

    Collect().feed(html)
    assert len(sources) == len(PNGS)
    assert all(s.startswith("data:image/png;base64,") for s in sources)
    assert 'src="' not in html.replace('src="data:', "")  # nothing loaded from a file
    # a table of contents whose every link reaches a heading
    ids = {e.get("id") for e in root.iter() if e.get("id")}
    assert len(hrefs) >= 10 and all(h[1:] in ids for h in hrefs if h.startswith("#"))
    # one figure and one table first, the prose after
    body = root.find("body")
    kinds = [e.tag for e in body if e.tag in ("figure", "div", "ul")]
    assert kinds[:3] == ["figure", "div", "ul"]
    assert body.find("div").find("table") is not None
    # numbers do not wrap inside table cells
    assert "td.num{text-align:right;white-space:nowrap}" in html
    assert '<td class="num">+' in html and '<td>derived-dynamic</td>' in html


def test_grid_nc_is_cf(quick_report):
    """grid.nc: CF-1.10, units and long_name everywhere, coded variables with flags."""
    _, _, grid = quick_report
    coded = ["failed", "failed_first_layer", "wall_layer",
             *(f"{kind}_{key}" for kind in ("validity", "resolved")
               for key in ("dynamic", "quasi_static", "paper")),
             "state_dynamic", "state_quasi_static"]
    check_cf(grid, coded)
    assert grid["velocity"].attrs["units"] == "m s-1"
    assert grid["validity_paper"].attrs["flag_meanings"] == (
        "FE_failed within_1_percent within_5_percent beyond_5_percent")
    assert grid["wall_layer"].attrs["flag_meanings"] == "concrete macadam soil"
    check_quantify(grid)


def test_response_states_are_explained(quick_report):
    out, _, grid = quick_report
    md = (out / "report.md").read_text()
    labels = grid["state_dynamic"].attrs["flag_meanings"].split()
    assert "a" in labels and "f" in labels
    for label in labels:
        assert f"- `{label}`: " in md
    assert "- `a`: concrete + macadam + soil around the cavity; the plastic zone (radius b) " \
           "ends inside concrete" in md
    assert "- `f`: macadam + soil around the cavity" in md


def test_accuracy_table_and_conclusion_from_grid(quick_report):
    out, summary, grid = quick_report
    md = (out / "report.md").read_text()
    for key, label in (("dynamic", "derived-dynamic"), ("paper", "paper (She 2020)")):
        for index, name in enumerate(("concrete", "macadam", "soil")):
            mask = (grid["wall_layer"] == index).broadcast_like(grid["sigma_r"])
            rel = grid[f"rel_err_{key}"].where(mask).values
            worst = rel.flat[np.nanargmax(np.abs(rel))]
            row = next(x for x in md.splitlines()
                       if x.startswith(f"| {label} | {name} |"))
            cells = [c.strip() for c in row.strip("|").split("|")]
            assert float(cells[4].split()[0]) == pytest.approx(100 * np.nanmedian(rel), abs=5e-4)
            assert float(cells[5].split()[0]) == pytest.approx(100 * worst, abs=5e-4)
    assert summary["conclusions"] == json.loads(grid.attrs["conclusions"])
    assert all(line in md for line in summary["conclusions"])


PARTS = {"dynamic": ("idealisation",), "quasi_static": ("convention", "idealisation"),
         "paper": ("formulas", "convention", "idealisation")}
PART_NAMES = {"formulas": "printed formulas/switch", "convention": "boundary convention",
              "idealisation": "idealisation"}
NUMBER = r"([+-]\d+\.\d{3}) %"


def _parts_from_stresses(grid):
    """(paper - FE)/FE split into formulas + convention + idealisation, from the stresses."""
    fe = np.where(grid["failed"].values.astype(bool), np.nan, grid["sigma_r"].values)
    paper, qs, dyn = (grid[v].values for v in ("sigma_r_paper", "sigma_r_quasi_static",
                                                "sigma_r_dynamic"))
    return {"formulas": (paper - qs) / fe, "convention": (qs - dyn) / fe,
            "idealisation": (dyn - fe) / fe}


def _listed(text):
    """``{part: percent}`` from ``"name +1.234 %, name -0.500 %"``."""
    names = {v: k for k, v in PART_NAMES.items()}
    items = [re.fullmatch(r"([a-z /]+) " + NUMBER, x) for x in text.split(", ")]
    return {names[m.group(1)]: float(m.group(2)) for m in items}


def _expected_within(rel, velocities, tolerance):
    """Largest V up to which every depth is within ``tolerance`` (rows all-NaN skipped)."""
    limit = None
    for i, V in enumerate(velocities):
        row = rel[i][np.isfinite(rel[i])]
        if row.size == 0:
            continue
        if np.any(np.abs(row) > tolerance):
            break
        limit = V
    return limit


def test_conclusions_attribute_the_error_from_recomputed_parts(quick_report):
    """Every number of the conclusion lines, recomputed here from the stresses in grid.nc."""
    _, summary, grid = quick_report
    parts = _parts_from_stresses(grid)
    fe = np.where(grid["failed"].values.astype(bool), np.nan, grid["sigma_r"].values)
    velocities, depths = grid.velocity.values, grid.depth.values
    var = {"dynamic": "sigma_r_dynamic", "quasi_static": "sigma_r_quasi_static",
           "paper": "sigma_r_paper"}
    labels = {"dynamic": "derived-dynamic", "quasi_static": "derived-quasi-static",
              "paper": "paper (She 2020)"}
    checked = set()
    for key in PARTS:
        rel_all = (grid[var[key]].values - fe) / fe
        # the parts add up exactly to the model's error, cell by cell
        np.testing.assert_allclose(sum(parts[p] for p in PARTS[key]), rel_all, rtol=0,
                                   atol=1e-12)
        for index, name in enumerate(("concrete", "macadam", "soil")):
            mask = (grid["wall_layer"].values == index)[None, :] & np.isfinite(rel_all)
            rel = np.where(mask, rel_all, np.nan)
            line = next(x for x in summary["conclusions"]
                        if x.startswith(f"{labels[key]}, {name} at the wall: "))
            # where within 1 % and 5 %
            for tolerance in TOLERANCES:
                t = f"within {100 * tolerance:g} % of FE"
                limit = _expected_within(rel, velocities, tolerance)
                fraction = np.mean(np.abs(rel[mask]) <= tolerance)
                if limit is None:
                    assert (f"never {t}" in line if fraction == 0 else
                            f"{t} in only {100 * fraction:.1f} % of its cells" in line)
                elif limit == velocities[-1]:
                    assert f"{t} in every cell (V up to {limit:g} m/s)" in line
                elif limit == 0:
                    assert f"{t} at every depth only at V = 0" in line
                else:
                    assert f"{t} at every depth only for V <= {limit:g} m/s" in line
            # the worst cell
            i, j = np.unravel_index(np.nanargmax(np.abs(rel)), rel.shape)
            worst = re.search(r"worst " + NUMBER + r" at V = (\S+) m/s, L = (\S+) m\.", line)
            assert float(worst.group(1)) == pytest.approx(100 * rel[i, j], abs=5e-4)
            assert float(worst.group(2)) == velocities[i]
            assert float(worst.group(3)) == pytest.approx(depths[j], rel=5e-4)
            # medians of the parts, and the parts at the worst cell
            medians = {p: 100 * np.nanmedian(np.where(mask, parts[p], np.nan))
                       for p in PARTS[key]}
            at_worst = {p: 100 * parts[p][i, j] for p in PARTS[key]}
            median_part = max(medians, key=lambda p: abs(medians[p]))
            worst_part = max(at_worst, key=lambda p: abs(at_worst[p]))
            if key == "dynamic":
                alone = re.search(r"Its error is the idealisation part alone \(median "
                                  + NUMBER + r"\)", line)
                assert float(alone.group(1)) == pytest.approx(medians["idealisation"],
                                                              abs=5e-4)
                assert medians["idealisation"] == pytest.approx(100 * np.nanmedian(rel))
            else:
                listed = re.search(r"Medians of its error parts: (.*?) \(median error "
                                   + NUMBER + r"\)\.", line)
                printed = _listed(listed.group(1))
                assert printed.keys() == medians.keys()
                for p in medians:
                    assert printed[p] == pytest.approx(medians[p], abs=5e-4), (line, p)
                assert float(listed.group(2)) == pytest.approx(100 * np.nanmedian(rel),
                                                               abs=5e-4)
                there = _listed(re.search(r"\(there: (.*?)\)", line).group(1))
                assert there.keys() == at_worst.keys()
                for p in at_worst:
                    assert there[p] == pytest.approx(at_worst[p], abs=5e-4), (line, p)
                if median_part == worst_part:
                    assert (f"The {PART_NAMES[median_part]} part dominates both the median "
                            "and the worst cell" in line)
                else:
                    assert f"The {PART_NAMES[median_part]} part dominates the median" in line
                    assert (f"At the worst cell the {PART_NAMES[worst_part]} part dominates"
                            in line)
            checked.add((key, index))
    assert len(checked) == 9


def test_validity_matches_recomputed_errors(quick_report):
    _, _, grid = quick_report
    fe = grid["sigma_r"].values
    for key, var in (("dynamic", "sigma_r_dynamic"), ("quasi_static", "sigma_r_quasi_static"),
                     ("paper", "sigma_r_paper")):
        rel = (grid[var].values - fe) / fe
        expected = np.where(np.abs(rel) <= TOLERANCES[0], 0,
                            np.where(np.abs(rel) <= TOLERANCES[1], 1, 2))
        expected = np.where(grid["failed"].values.astype(bool) | ~np.isfinite(rel), -1,
                            expected)
        np.testing.assert_array_equal(grid[f"validity_{key}"].values, expected)
        resolved = grid["error_estimate"].values < np.abs(rel) / 3
        ok = ~grid["failed"].values.astype(bool)
        np.testing.assert_array_equal(grid[f"resolved_{key}"].values[ok], resolved[ok])
    # the quick grid has cells in all three classes for the quasi-static form
    assert {0, 2} <= set(np.unique(grid["validity_quasi_static"]))


def test_failed_cell_and_renderer_failure(tmp_path, monkeypatch, capsys):
    from cavex.verification.commands import verify as verify_command
    from cavex.verification.fedata.cases import fe_cases

    def failing(chunk):
        out = fe_cases(chunk)
        return [RuntimeError("injected failure")
                if case["velocity"] == 1000.0 and case["depth"] == 0.5 else result
                for case, result in zip(chunk, out, strict=True)]

    def cannot_draw(*args, **kwargs):
        raise RuntimeError("cannot draw\nsecond line")

    monkeypatch.setattr(table_module, "fe_cases", failing)  # workers=1: runs in this process
    monkeypatch.setattr(report_picture, "plot_stresses", cannot_draw)
    target, projectile = load_config()
    summary = report.verify(target, projectile, out_dir=tmp_path, workers=1,
                            velocities=(0.0, 1000.0), depths=(0.3, 0.5),
                            numerics=dict(report.QUICK_NUMERICS))
    print(verify_command.text(summary))
    md = (tmp_path / "report.md").read_text()
    message = "stress figure not drawn (RuntimeError: cannot draw)"
    assert summary["picture"] == message and message in md
    assert message in capsys.readouterr().out
    assert not (tmp_path / "stresses.png").exists()
    assert not (tmp_path / "trajectories.png").exists()  # no trajectories: no figure
    assert (tmp_path / "validity.png").read_bytes()[:8] == PNG
    grid = xr.load_dataset(tmp_path / "grid.nc", engine="scipy")
    assert int(grid["failed"].sum()) == 1 and bool(grid["failed"].sel(velocity=1000.0, depth=0.5))
    assert int(grid["validity_paper"].sel(velocity=1000.0, depth=0.5)) == -1
    assert np.isnan(grid["plastic_radius"].sel(velocity=1000.0, depth=0.5))
    assert int(np.isnan(grid["plastic_radius"]).sum()) == 1
    assert "| 1000 | 0.5 | RuntimeError: injected failure |" in md
    _, rows = appendix_rows(md)
    assert [r[:2] for r in rows if r[-1] == "FE FAILED"] == [["1000", "0.5"]]
    assert "Trajectory comparison not possible" in md


def _sections(markdown):
    """``{heading: lines}`` of a report's ``## `` sections (the title part under ``""``)."""
    sections, heading = {"": []}, ""
    for line in markdown.splitlines():
        if line.startswith("## "):
            heading = line[3:]
            sections[heading] = []
        else:
            sections[heading].append(line)
    return sections


def test_quick_report_without_figures(quick_report, tmp_path):
    """``cavex verify --quick --no-figures``: no PNG; in ``report.md`` every figure's line says
    it was not drawn (the stresses' section that line alone, its caption being the picture's
    message) and every other line is the drawn report's."""
    from cavex.verification.cli import main

    out = quick_report[0]
    bare = tmp_path / "bare"
    assert main(["verify", "--quick", "--no-figures", "--workers", "2", "--no-progress",
                 "--out", str(bare)]) == 0
    assert sorted(p.name for p in bare.iterdir()) == ["grid.nc", "report.html", "report.md",
                                                      "target.toml"]
    drawn, plain = (_sections(p.read_text()) for p in (out / "report.md", bare / "report.md"))
    assert list(plain) == list(drawn)
    stresses = "Stresses around the cavity"
    assert plain.pop(stresses) == ["", report.NOT_DRAWN, ""]
    assert drawn.pop(stresses)[1].startswith("![stresses]")
    for heading, lines in drawn.items():
        expected = [report.NOT_DRAWN if x.startswith("![") else x for x in lines]
        assert plain[heading] == expected, heading
    assert sum(x.startswith("![") for lines in drawn.values() for x in lines) == len(PNGS) - 1


def test_a_wall_layer_without_fe_results_ranks_no_closed_form():
    """Every FE cell with concrete at the wall failed (a concrete of E = 1e300): the conclusion
    named "the closest closed form ... (median error n/a)", a ranking with no data."""
    from cavex.verification.report.text import conclusions

    target, _ = load_config()
    grid = xr.Dataset(coords={"velocity": [0.0, 500.0]})
    stats = {key: {0: {"median": float("nan")}} for key in ("dynamic", "quasi_static", "paper")}
    (line,) = conclusions(grid, target, stats)
    assert line == ("**concrete at the wall**: no FE result (every cell failed), so no closed "
                    "form is ranked there.")
