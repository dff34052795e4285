"""``cavex.api``: the types it returns, a table's units quantified with pint's default registry
in a fresh interpreter, the DataFrames against the files the commands write for the same inputs
(the same job functions on the same data in one process: the numbers are the same, so the
files are compared byte for byte or cell for cell), and the plotting functions drawing on the
``Axes`` they are given.
"""

import csv
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from cavex import api

ROOT = Path(__file__).resolve().parents[1]
SHOTS = ROOT / "examples" / "shots_forrestal1994.csv"
CHEAP_MODELS = ("forrestal-1994", "li-chen-2003")
TABLE_V, TABLE_L = (0.0, 400.0), (0.3, 0.5)  # concrete at the wall: no switch added


@pytest.fixture(scope="module")
def table():
    return api.build_table(TABLE_V, TABLE_L)


@pytest.fixture(scope="module")
def command_table(tmp_path_factory):
    """The file ``cavex table`` writes on the grid of :func:`table`."""
    from cavex.verification.cli import main

    out = tmp_path_factory.mktemp("table") / "cmd.nc"
    assert main(["table", "--velocities", *map(str, TABLE_V), "--depths", *map(str, TABLE_L),
                 "-o", str(out), "--no-figures", "--workers", "1"]) == 0
    return out


@pytest.fixture(scope="module")
def penetration():
    return api.penetrate()


@pytest.fixture(scope="module")
def shot():
    return api.fly(obliquity=20.0)


@pytest.fixture(scope="module")
def validation(tmp_path_factory):
    with pytest.MonkeyPatch.context() as patch:  # this module's own FE-table cache
        patch.setenv("CAVEX_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
        return api.validate(SHOTS, models=CHEAP_MODELS)


def test_table_is_a_dataset_with_its_grid(table):
    import xarray as xr

    assert isinstance(table, xr.Dataset)
    assert table["sigma_r"].dims == ("velocity", "depth")
    np.testing.assert_array_equal(table["velocity"], TABLE_V)
    np.testing.assert_array_equal(table["depth"], TABLE_L)
    assert table["velocity"].attrs["units"] == "m/s"
    assert table["sigma_r"].attrs["units"] == "Pa"


def test_table_equals_the_command_file(table, command_table, tmp_path):
    """``cavex table`` on the same grid writes the same numbers: both written by the command's
    writer (its rounding) and read back by :func:`cavex.api.open_table` are equal cell for
    cell; only the units' spelling differs between the file and the API's dataset."""
    from cavex.verification.fedata.table import write_table

    command = api.open_table(command_table)
    ours = api.open_table(write_table(table, tmp_path / "api.nc"))
    for name in ("sigma_r", "S", "error_estimate", "plastic_radius", "sigma_r_dynamic",
                 "sigma_r_first_layer"):
        np.testing.assert_array_equal(ours[name].values, command[name].values, err_msg=name)
    assert {n: v.attrs.get("units") for n, v in ours.variables.items()} == \
        {n: v.attrs.get("units") for n, v in command.variables.items()}


def test_open_table_quantifies_in_a_fresh_interpreter(command_table, tmp_path):
    """``ds.pint.quantify()`` on the file of ``cavex table`` with pint's default registry, no
    cf-xarray imported: every unit parses; the stress is Pa, the velocity m/s, S
    dimensionless, the depth m."""
    pytest.importorskip("pint_xarray")
    path = command_table
    probe = (
        "import sys\n"
        "from cavex import api\n"
        "import pint_xarray  # noqa\n"
        f"q = api.open_table({str(path)!r}).pint.quantify()\n"
        "assert 'cf_xarray.units' not in sys.modules\n"
        "print(q['sigma_r'].pint.units, q['velocity'].pint.units, q['S'].pint.units,"
        " q['depth'].pint.units, sep=';')\n")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().split(";") == ["pascal", "meter / second", "dimensionless",
                                              "meter"]


def test_the_files_own_spelling_is_what_pint_misreads(command_table):
    """Why :func:`cavex.api.open_table` respells: the file's UDUNITS ``m s-1`` does not quantify
    with pint's default registry (cf-xarray's registry reads both spellings)."""
    pint_xarray = pytest.importorskip("pint_xarray")  # noqa: F841
    import xarray as xr

    path = command_table
    with xr.open_dataset(path) as raw:
        assert raw["velocity"].attrs["units"] == "m s-1"
        with pytest.raises(TypeError):
            raw.pint.quantify()
    cf_units = pytest.importorskip("cf_xarray.units")
    quantified = api.open_table(path).pint.quantify(unit_registry=cf_units.units)
    assert str(quantified["velocity"].pint.units) == "meter / second"


def test_penetration_frames_equal_the_command_csv(penetration, capsys, tmp_path):
    """The phase table and both trajectories, written by the command's own CSV writer, are the
    command's files byte for byte."""
    import pandas as pd

    from cavex.verification.output.files import write_columns_csv
    from cavex.verification.output.number_format import TRAJECTORY_QUANTA

    assert isinstance(penetration.phases, pd.DataFrame)
    assert isinstance(penetration.trajectory, pd.DataFrame)
    code, _, err = run(capsys, "penetrate", "--out", tmp_path / "cmd", "--no-figures")
    assert code == 0, err
    for frame, name in ((penetration.trajectory, "trajectory_target.csv"),
                        (penetration.first_layer_trajectory,
                         "trajectory_first_layer_only.csv")):
        mine = write_columns_csv(tmp_path / name, {c: frame[c].to_numpy() for c in frame},
                                 TRAJECTORY_QUANTA)
        assert mine.read_bytes() == (tmp_path / "cmd" / name).read_bytes(), name
    phases = penetration.phases.drop(columns="stage")  # a bonded target's file has none
    mine = write_columns_csv(tmp_path / "phases_target.csv",
                             {c: phases[c].tolist() for c in phases})
    assert mine.read_bytes() == (tmp_path / "cmd" / "phases_target.csv").read_bytes()
    assert penetration.final_depth == penetration.trajectory["depth_m"].iloc[-1]
    assert penetration.phases["end_depth_m"].iloc[-1] == pytest.approx(penetration.final_depth,
                                                                       rel=1e-12)


def test_shot_history_equals_the_command_csv(shot, capsys, tmp_path):
    import pandas as pd

    from cavex.verification.output.files import write_columns_csv

    assert isinstance(shot.history, pd.DataFrame) and isinstance(shot.phases, pd.DataFrame)
    code, _, err = run(capsys, "trajectory", "--obliquity", 20, "--out", tmp_path / "cmd",
                       "--no-figures")
    assert code == 0, err
    mine = write_columns_csv(tmp_path / "h.csv",
                             {c: shot.history[c].to_numpy() for c in shot.history})
    assert mine.read_bytes() == (tmp_path / "cmd" / "history_target.csv").read_bytes()
    assert shot.end["state"] == "stopped"
    assert shot.summary["settings"]["obliquity_deg"] == 20.0


def test_validation_frame_equals_the_command_csv(validation, capsys, tmp_path):
    """``predictions.csv`` (6 significant digits) holds the DataFrame's numbers rounded to its
    digits, cell for cell, in the same columns."""
    import pandas as pd

    frame = validation.predictions
    assert isinstance(frame, pd.DataFrame) and isinstance(validation.statistics, pd.DataFrame)
    code, _, err = run(capsys, "validate", "--shots", SHOTS, "--models", *CHEAP_MODELS,
                       "--out", tmp_path / "cmd", "--no-figures")
    assert code == 0, err
    with open(tmp_path / "cmd" / "predictions.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert list(rows[0]) == list(frame.columns)
    assert [r["id"] for r in rows] == frame["id"].tolist()
    for column in frame.columns[1:]:
        if column == "flag":
            assert [r[column] for r in rows] == frame[column].tolist()
            continue
        written = [float(r[column]) if r[column] else np.nan for r in rows]
        rounded = [float(f"{x:.6g}") for x in frame[column]]
        np.testing.assert_array_equal(written, rounded, err_msg=column)
    assert set(validation.statistics.index) == set(CHEAP_MODELS)
    assert validation.statistics.loc["forrestal-1994", "n"] == len(frame)


def test_validate_reads_a_dataframe_as_the_file(validation):
    """A DataFrame of the file's columns gives the file's predictions (the same reader)."""
    import pandas as pd

    shots = pd.read_csv(SHOTS, comment="#")
    again = api.validate(shots, models=CHEAP_MODELS)
    pd.testing.assert_frame_equal(again.predictions, validation.predictions)


def test_validate_refuses_an_unknown_model():
    from cavex.errors import CavexInputError

    with pytest.raises(CavexInputError, match="models"):
        api.validate(SHOTS, models=["no-such-model"])


def _axes(projection=None):
    """An ``Axes`` of a figure on an Agg canvas, as pyplot and the notebooks' inline backend
    give."""
    from cavex.verification.output.files import agg_figure

    fig = agg_figure()
    return fig.add_subplot(projection=projection,
                           **({"computed_zorder": False} if projection else {}))


def test_plots_draw_on_the_given_axes(table, penetration, shot, validation):
    """Every plotting function draws on the ``Axes`` it is given (lines or markers there,
    labelled axes), nothing elsewhere."""
    cases = [(api.plot_table, table, "cavity expansion velocity V (m/s)"),
             (api.plot_velocity, penetration, "time (ms)"),
             (api.plot_deceleration, penetration, "nose-tip depth (m)"),
             (api.plot_trajectory, shot, "x (m, horizontal, plane of obliquity)"),
             (api.plot_pitch, shot, "t (ms)"),
             (api.plot_validation, validation, None),
             (api.plot_residuals, validation, None)]
    for plot, result, xlabel in cases:
        ax = _axes()
        plot(result, ax)
        drawn = len(ax.lines) + len(ax.collections)
        assert drawn > 0, plot.__name__
        if xlabel is not None:
            assert ax.get_xlabel() == xlabel, plot.__name__
        assert ax.get_xlabel(), plot.__name__
    ax3 = _axes("3d")
    handles = api.plot_view_3d(shot, ax3)
    assert handles and (ax3.lines or ax3.collections)


def test_plot_table_takes_a_quantified_table(table):
    pytest.importorskip("pint_xarray")
    ax = _axes()
    api.plot_table(table.pint.quantify(), ax)
    assert len(ax.lines) == table.sizes["depth"]


def test_the_readme_example_runs(monkeypatch):
    """README "Python API": its code block runs as printed (from the repository root) and
    gives the types it names."""
    pytest.importorskip("pint_xarray")
    import matplotlib
    import pandas as pd
    import xarray as xr

    matplotlib.use("Agg")
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = text.split("## Python API", 1)[1].split("```python", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(ROOT)
    scope = {}
    exec(compile(block, "README.md", "exec"), scope)
    assert isinstance(scope["ds"], xr.Dataset)
    assert isinstance(scope["shot"].phases, pd.DataFrame)
    assert isinstance(scope["oblique"].history, pd.DataFrame)
    assert isinstance(scope["check"].predictions, pd.DataFrame)
    assert scope["ax"].lines


def test_results_print_in_one_line(penetration, shot, validation):
    """A result's repr is one line of what it is (a notebook prints it), not its arrays."""
    assert repr(penetration) == (f"Penetration(derived-dynamic, runway (the paper's Table 1): "
                                 f"{len(penetration.phases)} phases, final depth "
                                 f"{penetration.final_depth:.4g} m)")
    assert repr(shot).startswith("Shot(1000 m/s at 20 deg, derived: stopped")
    assert repr(validation) == ("Validation(17 shots, models "
                                + ", ".join(validation.result["models"]) + ")")
    assert set(validation.result["models"]) == set(CHEAP_MODELS)  # in the registry's order
