"""The verification report: files, numbers traced to grid.nc, validity, failure paths."""

import json
import re

import numpy as np
import pytest
import xarray as xr
from cavex.verification import report, report_picture
from cavex.verification import table as table_module
from cavex.verification.report_analysis import TOLERANCES

from cavex.config import default_config_text, load_config

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


def test_quick_report_writes_every_file(quick_report):
    out, summary, grid = quick_report
    for name in ("report.md", "report.html", "grid.nc", "target.toml"):
        assert (out / name).stat().st_size > 0
    pngs = ["error_dynamic", "error_quasi_static", "error_paper", "validity", "S_depth",
            "states", "plastic_radius", "error_estimate", "sphere"]
    for name in pngs:
        assert (out / f"{name}.png").read_bytes()[:8] == PNG, name
    html = (out / "report.html").read_text()
    assert html.count("<img ") == len(pngs) and "<table>" in html
    assert summary["cells"] == grid.sizes["velocity"] * grid.sizes["depth"] >= 3 * 3
    assert grid.sizes["velocity"] == 3 and set(np.unique(grid["wall_layer"])) == {0, 1, 2}


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
        for key, name in (("dynamic", "derived dynamic error"),
                          ("quasi_static", "derived quasi-static error"),
                          ("paper", "paper error")):
            printed = float(PERCENT.match(row[col[name]]).group(1))
            assert printed == pytest.approx(100 * float(cell[f"rel_err_{key}"]), abs=5e-4)
            checked += 1
        assert row[col["state (dynamic)"]] == str(cell["state_dynamic"].values)
    assert checked >= 3 * 20


def test_accuracy_table_and_conclusion_from_grid(quick_report):
    out, summary, grid = quick_report
    md = (out / "report.md").read_text()
    for key, label in (("dynamic", "derived dynamic"), ("paper", "paper (She 2020)")):
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
    from cavex.verification.cases import fe_case

    def failing(case):
        if case["velocity"] == 1000.0 and case["depth"] == 0.5:
            raise RuntimeError("injected failure")
        return fe_case(case)

    def no_opengl(*args, **kwargs):
        raise RuntimeError("no OpenGL context\nsecond line")

    monkeypatch.setattr(table_module, "fe_case", failing)  # workers=1: runs in this process
    monkeypatch.setattr(report_picture, "render_sphere", no_opengl)
    target, projectile = load_config()
    summary = report.verify(target, projectile, out_dir=tmp_path, workers=1,
                            velocities=(0.0, 1000.0), depths=(0.3, 0.5),
                            numerics=dict(report.QUICK_NUMERICS))
    print(report.summary_text(summary))
    md = (tmp_path / "report.md").read_text()
    message = "3-D picture not rendered (RuntimeError: no OpenGL context)"
    assert summary["picture"] == message and message in md
    assert message in capsys.readouterr().out
    assert not (tmp_path / "sphere.png").exists()
    assert (tmp_path / "validity.png").read_bytes()[:8] == PNG
    grid = xr.load_dataset(tmp_path / "grid.nc", engine="scipy")
    assert int(grid["failed"].sum()) == 1 and bool(grid["failed"].sel(velocity=1000.0, depth=0.5))
    assert int(grid["validity_paper"].sel(velocity=1000.0, depth=0.5)) == -1
    assert "| 1000 | 0.5 | RuntimeError: injected failure |" in md
    _, rows = appendix_rows(md)
    assert [r[:2] for r in rows if r[-1] == "FE FAILED"] == [["1000", "0.5"]]
    assert "Trajectory comparison not possible" in md
