"""What an interactive user meets first: ``--help`` and bad input answer without loading the
numerical libraries, ``python -m cavex`` runs the command line, every option states its default,
``cavex config`` prints the embedded configuration, ``--no-figures`` writes no PNG, and numba's
compiling is announced once (issue 21, item 1)."""

import argparse
import io
import os
import subprocess
import sys
from importlib.metadata import entry_points
from pathlib import Path

import pytest

from cavex.config import default_config_text, load_config
from cavex.verification.cli import (
    COMPILING,
    GC_THRESHOLDS,
    announce_compiling,
    build_parser,
    main,
)

HEAVY = ("numba", "scipy", "matplotlib", "skfem", "xarray", "dask", "pandas")
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SHOTS = str(EXAMPLES / "shots_forrestal1994.csv")


def _run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_the_parser_loads_no_numerical_library():
    """``cavex --help`` and argument errors need only the parser: none of :data:`HEAVY` is
    imported by building it (the time itself: benchmarks/commands.py)."""
    probe = ("import sys; from cavex.verification.cli import build_parser; build_parser(); "
             f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=True)
    assert done.stdout.strip() == "[]"


def _loaded_after(argv, cwd=None):
    """``(exit code, stderr, the HEAVY modules loaded)`` of ``cavex argv`` run in a fresh
    process (in ``cwd``: None, this one's)."""
    probe = ("import sys; from cavex.verification.cli import main; code = main(sys.argv[1:]); "
             f"print(code, sorted(m for m in {HEAVY!r} if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", probe, *argv], capture_output=True,
                          text=True, timeout=120, check=True, cwd=cwd)
    code, loaded = done.stdout.strip().splitlines()[-1].split(" ", 1)
    return int(code), done.stderr, loaded


#: A sweep with a key the batch schema does not have (written as ``{tmp}/bad_key.toml``).
BAD_SWEEP = '[sweep]\nname = "bad"\n\n[grid]\nvelocity = [0.0, 100.0]\n'

#: One bad input of each kind a command checks itself (after the parser), for the commands
#: that refuse it before loading the numerical libraries (verification/commands/__init__.py);
#: ``{tmp}``: the folder the command runs in (nothing may be written there).
BAD_INPUTS = {
    "penetrate --resistance table": ["penetrate", "--resistance", "table"],
    "penetrate --out in /proc": ["penetrate", "--out", "/proc/cavex-no-such-dir/x"],
    "trajectory --velocity -1": ["trajectory", "--velocity", "-1"],
    "trajectory --obliquity 90": ["trajectory", "--obliquity", "90"],
    "trajectory --spin 1e9": ["trajectory", "--spin", "1e9"],
    "trajectory --contact-ramp 5": ["trajectory", "--contact-ramp", "5"],
    "trajectory --tangency-psi 99": ["trajectory", "--tangency-psi", "99"],
    "trajectory --law-A without law": ["trajectory", "--law-A", "5"],
    "stress --velocity -1": ["stress", "--velocity", "-1", "--depth", "0.3"],
    "stress --depth -1": ["stress", "--velocity", "800", "--depth", "-1"],
    "fem --velocity 1e9": ["fem", "--velocity", "1e9", "--depth", "0.3"],
    "config missing file": ["config", "--config", "/proc/cavex-no-such-file.toml"],
    "table --velocities -5": ["table", "--velocities", "-5", "0", "--out", "{tmp}/t.nc"],
    "table --velocities without 0": ["table", "--velocities", "100", "200"],
    "table --depths 0": ["table", "--depths", "0"],
    "table --nu 0.6": ["table", "--velocities", "0", "100", "--depths", "0.2", "0.3", "--nu",
                       "0.6", "--out", "{tmp}/t.nc"],
    "table --workers 0": ["table", "--workers", "0"],
    "table --out in /proc": ["table", "--out", "/proc/cavex-no-such-dir/t.nc"],
    "verify --workers 0": ["verify", "--workers", "0"],
    "verify --scheduler nosuch": ["verify", "--quick", "--scheduler", "nosuch"],
    "verify --out in /proc": ["verify", "--out", "/proc/cavex-no-such-dir/report"],
    "batch missing sweep": ["batch", "/proc/cavex-no-such-file.toml"],
    "batch bad key": ["batch", "{tmp}/bad_key.toml"],
    "batch --workers 0": ["batch", str(EXAMPLES / "sweep.toml"), "--workers", "0", "--out",
                          "{tmp}/sweep"],
    "calibrate missing shots": ["calibrate", "--shots", "/proc/cavex-no-such.csv", "--out",
                                "{tmp}/c.toml"],
    "calibrate --params nosuch": ["calibrate", "--shots", SHOTS, "--out", "{tmp}/c.toml",
                                  "--params", "nosuch"],
    "calibrate --ids nosuch": ["calibrate", "--shots", SHOTS, "--out", "{tmp}/c.toml",
                               "--ids", "nosuch"],
    "calibrate --out in /proc": ["calibrate", "--shots", SHOTS, "--out",
                                 "/proc/cavex-no-such-dir/c.toml"],
    "validate missing shots": ["validate", "--shots", "/proc/cavex-no-such.csv"],
    "validate --models nosuch": ["validate", "--shots", SHOTS, "--models", "nosuch"],
    "validate missing calibration": ["validate", "--shots", SHOTS, "--calibration",
                                     "/proc/cavex-no-such.toml"],
    "validate --workers 0": ["validate", "--shots", SHOTS, "--workers", "0", "--out",
                             "{tmp}/v"],
}


@pytest.mark.parametrize("argv", BAD_INPUTS.values(), ids=BAD_INPUTS.keys())
def test_bad_input_is_refused_before_the_numerical_libraries_load(argv, tmp_path):
    """A bad input the command checks itself answers (one line, exit 2) without loading any of
    :data:`HEAVY` (the time: benchmarks/commands.py) and writes nothing (run in ``tmp_path``,
    so that a default output folder would show there too)."""
    (tmp_path / "bad_key.toml").write_text(BAD_SWEEP)
    before = sorted(tmp_path.rglob("*"))
    code, err, loaded = _loaded_after([a.format(tmp=tmp_path) for a in argv], cwd=tmp_path)
    assert (code, len(err.splitlines()), loaded) == (2, 1, "[]"), err
    assert sorted(tmp_path.rglob("*")) == before


def test_the_paper_model_loads_no_compiled_kernel():
    """``cavex stress --resistance paper`` computes with the paper's printed model (numpy):
    it neither loads numba nor scipy."""
    code, err, loaded = _loaded_after(["stress", "--velocity", "800", "--depth", "0.3",
                                       "--resistance", "paper"])
    assert (code, err, loaded) == (0, "", "[]")



def test_table_writes_without_xarray(tmp_path):
    """``cavex table`` writes its netCDF without xarray (cavex.netcdf3),
    so neither xarray nor dask nor pandas is loaded by it (their import and xarray's probes
    for dask cost ~1 s of CPU: benchmarks/table.py); the file reads back through xarray. Its
    figure (t_S.png) loads matplotlib."""
    out = tmp_path / "t.nc"
    code, _, loaded = _loaded_after(["table", "--velocities", "0", "500", "--depths", "0.1",
                                     "0.2", "--workers", "1", "-o", str(out)])
    assert (code, loaded) == (0, "['matplotlib', 'numba', 'scipy', 'skfem']")
    assert (tmp_path / "t_S.png").stat().st_size > 0
    import xarray as xr

    with xr.open_dataset(out, engine="scipy") as table:
        assert table["sigma_r"].shape == (2, 2) and not bool(table["failed"].any())

@pytest.mark.parametrize("command", ["penetrate", "trajectory"])
def test_a_table_is_read_without_xarray(command, tmp_path):
    """``--resistance table`` reads the table without xarray (``read_table``): neither
    xarray, dask nor pandas is loaded (their import and probes: ~0.5 s of CPU)."""
    from cavex.verification.fedata.table import analytic_table, write_table

    target, projectile = load_config()
    table = write_table(analytic_table(target, projectile, [0.0, 400.0, 800.0, 1200.0],
                                       [0.05, 0.5, 1.0, 1.5, 3.5]), tmp_path / "t.nc")
    code, err, loaded = _loaded_after([command, "--resistance", "table", "--table", str(table),
                                       "--no-figures", "--out", str(tmp_path / "out")])
    assert (code, loaded) == (0, "['numba', 'scipy']"), err


def test_the_program_leaves_its_objects_to_the_exit():
    """The installed ``cavex`` runs :func:`cavex.__main__.console`: :func:`main`'s exit code,
    with the collector at ``GC_THRESHOLDS`` and what the command left frozen (``gc.freeze``),
    so that the collections do not walk numba's and scipy's objects again and again (the time:
    benchmarks/commands.py)."""
    scripts = entry_points(group="console_scripts", name="cavex")
    assert [s.value for s in scripts] == ["cavex.__main__:console"]
    probe = ("import gc, sys; from cavex.__main__ import console; "
             "sys.argv[1:] = ['stress', '--velocity', '-1', '--depth', '0.3']; "
             "code = console(); print(code, gc.get_freeze_count() > 0, gc.get_threshold())")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=True)
    code, frozen, thresholds = done.stdout.strip().split(" ", 2)
    assert (code, frozen, thresholds) == ("2", "True", str(GC_THRESHOLDS))


@pytest.mark.parametrize("given, expected", [(None, "1"), ("2", "2")])
def test_the_program_runs_openblas_without_its_threads(given, expected):
    """The program sets ``OPENBLAS_NUM_THREADS`` to 1 before numpy loads (a user's setting
    wins): numpy's and scipy's OpenBLAS then start no thread pool, which would only spin
    beside the work (measured: benchmarks/commands.md); the process has one thread."""
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    probe = ("import os, sys; from cavex.__main__ import console; "
             "sys.argv[1:] = ['stress', '--velocity', '500', '--depth', '0.3', '--json']; "
             "code = console(); import scipy.linalg; "
             "print(code, 'numpy' in sys.modules, os.environ['OPENBLAS_NUM_THREADS'], "
             "len(os.listdir('/proc/self/task')), file=sys.stderr)")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=True, env=env)
    code, loaded, threads, tasks = [line for line in done.stderr.splitlines()
                                    if line != COMPILING][0].split()  # a cold numba cache
    assert (code, loaded, threads) == ("0", "True", expected)
    if given is None and sys.platform.startswith("linux"):
        assert tasks == "1"


def test_python_dash_m_cavex_is_the_command_line():
    done = subprocess.run([sys.executable, "-m", "cavex", "stress", "--velocity", "-1",
                           "--depth", "0.3"], capture_output=True, text=True, timeout=120,
                          check=False)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.splitlines() == [
        "cavex: error: parameter 'velocity' must be in [0, 10000] m/s (got -1.0)"]


def _subcommands():
    parser = build_parser()
    actions = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return actions[0].choices


@pytest.mark.parametrize("command", sorted(_subcommands()))
def test_every_option_states_its_default(command):
    """Each option's help says its default or that it is required; only flags (off unless
    given) and --help say neither."""
    sub = _subcommands()[command]
    formatter = sub._get_formatter()
    silent = []
    for action in sub._actions:
        if action.help == argparse.SUPPRESS or isinstance(action, argparse._HelpAction):
            continue
        if action.nargs == 0 and action.default is False:
            continue  # a flag
        shown = formatter._get_help_string(action) % vars(action)
        if "default" not in shown and "required" not in shown:
            silent.append(action.option_strings or action.dest)
    assert not silent, f"cavex {command}: no default shown for {silent}"


def test_a_zero_default_is_shown(capsys):
    with pytest.raises(SystemExit):
        main(["trajectory", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "target normal (deg) (default: 0.0)" in text


def test_config_prints_the_embedded_configuration(capsys, tmp_path):
    code, out, err = _run(capsys, "config", "--default")
    assert (code, err) == (0, "") and out == default_config_text().rstrip("\n") + "\n"
    copy = tmp_path / "copy.toml"
    copy.write_text(out)
    assert load_config(copy) == load_config()
    assert _run(capsys, "config")[1] == out
    code, out, err = _run(capsys, "config", "--config", str(copy), "--default")
    assert code == 2 and out == "" and len(err.splitlines()) == 1


def test_config_of_a_bad_file_is_refused(capsys, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(default_config_text().replace("[projectile]", "[projectil]"))
    code, out, err = _run(capsys, "config", "--config", str(bad))
    assert code == 2 and out == "" and err.startswith(f"cavex: error: '{bad}'")


def test_penetrate_no_figures_writes_no_png(capsys, tmp_path):
    code, out, err = _run(capsys, "penetrate", "--no-figures", "--out", str(tmp_path / "p"))
    assert (code, err) == (0, "")
    written = sorted(p.name for p in (tmp_path / "p").iterdir())
    assert written == ["phases_target.csv", "trajectory_first_layer_only.csv",
                       "trajectory_target.csv"]


def test_compiling_is_announced_once():
    """Two kernels compiled (cache misses: fresh functions, not cached) give one line."""
    from numba import njit
    from numba.core import event

    stream = io.StringIO()
    listener = announce_compiling(stream)
    try:
        njit(lambda x: x + 1)(1)
        njit(lambda x: x * 2.0)(1.0)
    finally:
        event.unregister("numba:compile", listener)
    assert stream.getvalue().splitlines() == [
        "cavex: compiling the numerical kernels (first run after installing or updating; "
        "cached for later runs)"]


def test_the_program_says_it_compiles_where_stderr_is_no_terminal():
    """The installed program (``console``) with stderr piped (a log, CI): a command that
    compiles a kernel says so in one line (the first ``trajectory`` compiled for about 2 min
    in silence there, issue 33); a refused input loads no numba for it, and says nothing
    more."""
    probe = ("import sys\n"
             "from cavex.verification.commands import stress\n"
             "def run(args, target, projectile):\n"
             "    from numba import njit\n"
             "    return {'compiled': njit(lambda x: x + 1)(1)}\n"
             "stress.run, stress.text = run, lambda result: str(result['compiled'])\n"
             "from cavex.__main__ import console\n"
             "sys.argv[1:] = sys.argv[1:] or ['stress', '--velocity', '500', '--depth', '0.3']\n"
             "code = console()\n"
             "print(code, 'numba' in sys.modules)\n")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=True)
    assert done.stdout.splitlines() == ["2", "0 True"]
    assert done.stderr.splitlines() == [COMPILING]
    bad = subprocess.run([sys.executable, "-c", probe, "stress", "--velocity", "fast",
                          "--depth", "0.3"], capture_output=True, text=True, timeout=120,
                         check=True)
    assert bad.stdout.splitlines() == ["2 False"]
    assert bad.stderr.splitlines() == [
        "cavex: error: argument --velocity: invalid float value: 'fast'"]


def test_no_announcement_without_compiling():
    from numba import njit
    from numba.core import event

    kernel = njit(lambda x: x - 1)
    kernel(1)  # compiled before the listener is there
    stream = io.StringIO()
    listener = announce_compiling(stream)
    try:
        kernel(2)
    finally:
        event.unregister("numba:compile", listener)
    assert stream.getvalue() == ""
