"""Faults lose nothing and write nowhere else (issue 32): planted symlinks never written
through, clashes refused before anything is moved, validate's FE tables staged with the report,
refusals (debonded batch keys, control characters), a scheduler only when asked.

The FE-table cache's faults and the kill sweeps are in tests/test_faults_cache.py and
tests/test_faults_signals.py."""

import json
import os
from pathlib import Path

import pytest
from tmpfs_helpers import fill, small_tmpfs, unmount

from cavex.errors import CavexInputError
from cavex.verification.cli import main
from cavex.verification.output import files
from cavex.verification.output.paths import planned_moves, staged_output, write_staged

ROOT = Path(__file__).resolve().parents[1]
SHOTS = ROOT / "examples" / "shots_forrestal1994.csv"
OUTSIDE = "outside: must not be written\n"


def planted(tmp_path, *names):
    """Symlinks ``names`` (relative to ``tmp_path``) to one file outside; returns the file."""
    outside = tmp_path / "outside.txt"
    outside.write_text(OUTSIDE)
    for name in names:
        link = tmp_path / name
        link.parent.mkdir(parents=True, exist_ok=True)
        link.symlink_to(outside)
    return outside


def old_temporary_names(path):
    """The fixed temporary names the writers used before (issue 32): ``<path>.tmp``,
    ``<path>.<pid>.tmp`` and ``<path>.<pid>.tmp.png``."""
    pid = os.getpid()
    return [f"{path}.tmp", f"{path}.{pid}.tmp", f"{path}.{pid}.tmp.png"]


def no_temporaries_left(folder):
    return [p.name for p in Path(folder).iterdir() if p.name.endswith(".tmp")
            or ".tmp." in p.name]


# --- temporary files created exclusively ----------------------------------------------------

def test_temporary_file_is_new_hidden_and_of_this_process(tmp_path):
    handle, name = files.exclusive_temporary(tmp_path / "a.csv")
    os.close(handle)
    assert Path(name).parent == tmp_path and Path(name).name.startswith(f".a.csv.{os.getpid()}.")
    assert not files.stale_temporary(Path(name).name)
    assert files.stale_temporary(".a.csv.999999999.abcdefgh.tmp")  # no such process
    assert files.stale_temporary("a.csv.tmp")  # an older cavex's: no process named


@pytest.mark.parametrize("writer", ["text", "csv", "copy", "figure", "table"])
def test_no_writer_follows_a_planted_symlink(tmp_path, writer):
    """Every writer of output/files.py and the table writer: symlinks planted at the old fixed
    temporary names and at the final name; the file outside stays as it was, the final name
    becomes a regular file."""
    target = tmp_path / ("out.png" if writer == "figure" else "out.nc" if writer == "table"
                         else "out.txt")
    outside = planted(tmp_path, *[Path(n).name for n in old_temporary_names(target)],
                      target.name)
    if writer == "text":
        files.write_text_atomic(target, "new\n")
    elif writer == "csv":
        files.write_columns_csv(target, {"a": [1.0, 2.0]})
    elif writer == "copy":
        source = tmp_path / "source.txt"
        source.write_text("copied\n")
        files.copy_atomic(source, target)
    elif writer == "figure":
        fig = files.agg_figure(figsize=(1, 1))
        files.save_figure(fig, target)
    else:
        import numpy as np

        from cavex.netcdf3 import PlainDataset
        from cavex.verification.fedata.table import write_table

        table = PlainDataset({"x": (("v",), np.array([1.0, 2.0]), {})},
                             {"v": (("v",), np.array([0.0, 1.0]), {})}, {"a": "b"})
        write_table(table, target)
    assert outside.read_text() == OUTSIDE
    assert target.is_file() and not target.is_symlink()
    for name in old_temporary_names(target):  # still the planted links, untouched
        assert Path(name).is_symlink()
    assert not [n for n in no_temporaries_left(tmp_path) if not Path(tmp_path / n).is_symlink()]


def test_staged_write_replaces_a_planted_symlink_not_its_target(tmp_path):
    out = tmp_path / "out"
    outside = planted(tmp_path, "out/report.md")

    def write(stage):
        (stage / "report.md").write_text("report\n")
        return [stage / "report.md"]

    write_staged(out, write)
    assert outside.read_text() == OUTSIDE
    assert (out / "report.md").read_text() == "report\n" and not (out / "report.md").is_symlink()


def test_calibrate_out_never_writes_through_a_planted_symlink(tmp_path, capsys):
    """``calibrate --out X.toml``: symlinks at ``X.toml.tmp`` (the old fixed name) and at the
    ``.<pid>.tmp`` name."""
    out = tmp_path / "cal.toml"
    outside = planted(tmp_path, "cal.toml.tmp")
    code = main(["calibrate", "--shots", str(SHOTS), "--out", str(out), "--params", "lam",
                 "--ids", "F94-39", "F94-40", "--workers", "1"])
    capsys.readouterr()
    assert code == 0
    assert outside.read_text() == OUTSIDE
    assert out.is_file() and "lam" in out.read_text()


SWEEP = """
[sweep]
name = "tiny"
workers = 1
[grid]
velocities = [300.0]
depths = [0.0]
"""


def test_batch_never_writes_through_a_planted_sweep_json_tmp(tmp_path, capsys):
    sweep = tmp_path / "s.toml"
    sweep.write_text(SWEEP)
    out = tmp_path / "out"
    outside = planted(tmp_path, "out/sweep.json.tmp")
    assert main(["batch", str(sweep), "--out", str(out)]) == 0
    capsys.readouterr()
    assert outside.read_text() == OUTSIDE
    assert json.loads((out / "sweep.json").read_text())["name"] == "tiny"


# --- every output staged, clashes refused before anything moves ------------------------------

def test_a_clash_is_found_before_anything_is_moved(tmp_path):
    out = tmp_path / "out"
    (out / "b.json").mkdir(parents=True)
    with pytest.raises(CavexInputError, match="'out'.*b.json"):
        with staged_output(out) as stage:
            for name in ("a.csv", "b.json", "c.md"):
                (stage / name).write_text(name)
    assert sorted(p.name for p in out.iterdir()) == ["b.json"]


def test_staged_folders_merge_into_existing_ones(tmp_path):
    out, stage = tmp_path / "out", tmp_path / "stage"
    (out / "tables").mkdir(parents=True)
    (out / "tables" / "old.nc").write_text("old")
    (stage / "tables").mkdir(parents=True)
    (stage / "tables" / "new.nc").write_text("new")
    (stage / "r.json").write_text("{}")
    moves = planned_moves(stage, out)
    assert sorted(d.relative_to(out).as_posix() for _, d in moves) == ["r.json",
                                                                       "tables/new.nc"]


@pytest.mark.parametrize("occupant", ["file", "symlink"])
def test_a_staged_folder_onto_a_file_or_symlink_is_refused(tmp_path, occupant):
    out, stage = tmp_path / "out", tmp_path / "stage"
    out.mkdir()
    if occupant == "file":
        (out / "tables").write_text("x")
    else:
        (tmp_path / "elsewhere").mkdir()
        (out / "tables").symlink_to(tmp_path / "elsewhere")
    (stage / "tables").mkdir(parents=True)
    (stage / "tables" / "t.nc").write_text("t")
    with pytest.raises(CavexInputError, match="'out'"):
        planned_moves(stage, out)
    assert not list((tmp_path / "elsewhere").iterdir()) if occupant == "symlink" else True


def test_trajectory_clash_leaves_out_as_it_was(tmp_path, capsys):
    out = tmp_path / "out"
    (out / "summary.json").mkdir(parents=True)
    before = sorted(p.name for p in out.iterdir())
    code = main(["trajectory", "--no-figures", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "'out'" in err
    assert sorted(p.name for p in out.iterdir()) == before


def test_validate_clash_leaves_out_as_it_was(tmp_path, capsys):
    out = tmp_path / "out"
    (out / "validation.json").mkdir(parents=True)
    code = main(["validate", "--shots", str(SHOTS), "--models", "paper", "--no-figures",
                 "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "'out'" in err.strip().splitlines()[-1]
    assert sorted(p.name for p in out.iterdir()) == ["validation.json"]
    assert not list((out / "validation.json").iterdir())


# --- refusals --------------------------------------------------------------------------------

DEBONDED_SWEEP = SWEEP + """
[[target.layers]]
thickness = 0.5
E = 25e9
nu = 0.2
rho = 2500.0
lam = 0.15
tau = 25e6
bottom = "debonded"
[[target.layers]]
E = 25e9
nu = 0.2
rho = 2500.0
lam = 0.15
tau = 25e6
"""


def test_batch_refuses_debonded_keys(tmp_path, capsys):
    sweep = tmp_path / "s.toml"
    sweep.write_text(DEBONDED_SWEEP)
    code = main(["batch", str(sweep), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "target.layers[0].bottom" in err and "debonded" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("character", ["\x00", "\x07", "\x1b", "\x7f", "\n"])
def test_control_characters_in_a_shot_id_are_refused(tmp_path, capsys, character):
    lines = SHOTS.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("id,"))
    row = lines[header + 1]
    shots = tmp_path / "s.csv"
    shots.write_bytes(("\n".join([lines[header], "F94" + character + row[3:]]) + "\n").encode())
    code = main(["validate", "--shots", str(shots), "--models", "paper", "--no-figures",
                 "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err and not (tmp_path / "out").exists()
    if character != "\n":  # a newline ends the CSV row: the row is refused for its cells
        assert "column id" in err and "control characters" in err


@pytest.mark.parametrize("character", ["\\u0000", "\\u001b", "\\u007f"])
def test_control_characters_in_a_layer_name_are_refused(tmp_path, capsys, character):
    config = (ROOT / "core" / "data" / "runway.toml").read_text()
    assert 'name = "' in config
    bad = tmp_path / "bad.toml"
    bad.write_text(config.replace('name = "', f'name = "x{character}', 1))
    code = main(["penetrate", "--config", str(bad), "--no-figures", "--out",
                 str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "name" in err and "control characters" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


# --- a scheduler only when asked -------------------------------------------------------------

def test_a_sweep_files_scheduler_needs_the_opt_in(tmp_path, capsys):
    sweep = tmp_path / "s.toml"
    sweep.write_text(SWEEP.replace('name = "tiny"', 'name = "tiny"\nscheduler = '
                                   '"tcp://127.0.0.1:1"'))
    code = main(["batch", str(sweep), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "sweep.scheduler" in err and "--allow-file-scheduler" in err
    assert not (tmp_path / "out").exists()
    # with the opt-in the address is used (and found unreachable: port 1)
    code = main(["batch", str(sweep), "--out", str(tmp_path / "out"),
                 "--allow-file-scheduler"])
    err = capsys.readouterr().err
    assert code == 2 and "reachable" in err


def test_the_command_lines_scheduler_overrides_the_file_without_opt_in(tmp_path, capsys):
    sweep = tmp_path / "s.toml"
    sweep.write_text(SWEEP.replace('name = "tiny"', 'name = "tiny"\nscheduler = '
                                   '"tcp://127.0.0.1:2"'))
    code = main(["batch", str(sweep), "--out", str(tmp_path / "out"), "--scheduler",
                 "tcp://127.0.0.1:1"])
    err = capsys.readouterr().err
    assert code == 2 and "127.0.0.1:1" in err and "allow-file-scheduler" not in err


@pytest.mark.parametrize("extra, parameter", [
    (["--scheduler-tls-ca", "{ca}"], "scheduler-tls-ca"),  # no --scheduler
    (["--scheduler", "tcp://127.0.0.1:1", "--scheduler-tls-ca", "{ca}"], "'scheduler'"),
    (["--scheduler", "tls://127.0.0.1:1", "--scheduler-tls-ca", "{tmp}/none.pem"],
     "scheduler-tls-ca"),
    (["--scheduler", "tls://127.0.0.1:1", "--scheduler-tls-ca", "{ca}",
      "--scheduler-tls-cert", "{ca}"], "scheduler-tls-cert"),  # a certificate without key
    (["--scheduler", "tls://127.0.0.1:1", "--scheduler-tls-cert", "{ca}",
      "--scheduler-tls-key", "{ca}"], "scheduler-tls-ca"),  # no CA
    (["--scheduler", "tls://127.0.0.1:1"], "--scheduler-tls-ca"),  # tls:// without settings
])
def test_bad_tls_settings_are_refused(tmp_path, capsys, extra, parameter):
    ca = tmp_path / "ca.pem"
    ca.write_text("not checked before connecting\n")
    words = [w.format(ca=ca, tmp=tmp_path) for w in extra]
    code = main(["table", "--velocities", "100", "--depths", "0", "-o",
                 str(tmp_path / "t.nc"), *words])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and parameter in err, err
    assert not (tmp_path / "t.nc").exists()


def test_tls_settings_become_a_distributed_security(tmp_path):
    pytest.importorskip("distributed")
    from cavex.verification.fedata.runner import SchedulerAddress, scheduler_with_tls

    for name in ("ca.pem", "cert.pem", "key.pem"):
        (tmp_path / name).write_text("x")
    address = scheduler_with_tls("tls://127.0.0.1:8786", str(tmp_path / "ca.pem"),
                                 str(tmp_path / "cert.pem"), str(tmp_path / "key.pem"))
    assert isinstance(address, SchedulerAddress) and address == "tls://127.0.0.1:8786"
    security = address.security()
    assert security.require_encryption
    assert security.tls_ca_file == str(tmp_path / "ca.pem")
    assert security.tls_client_cert == str(tmp_path / "cert.pem")
    assert security.tls_client_key == str(tmp_path / "key.pem")
    assert scheduler_with_tls("tcp://127.0.0.1:8786") == "tcp://127.0.0.1:8786"


# --- a full or read-only --out ---------------------------------------------------------------

@pytest.mark.parametrize("command", [
    ["validate", "--shots", str(SHOTS), "--models", "paper", "--no-figures"],
    ["trajectory", "--no-figures"],
    ["penetrate", "--no-figures"],
])
def test_a_full_out_is_named_and_left_as_it_was(tmp_path, capsys, command):
    disk = small_tmpfs(tmp_path / "disk", "size=64k")
    try:
        out = disk / "out"
        out.mkdir()
        (out / "keep.txt").write_text("kept\n")
        fill(disk / "filler")
        code = main([*command, "--out", str(out)])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and "'out'" in err[-1] and "No space left" in err[-1], err
        assert "Traceback" not in "".join(err)
        assert sorted(p.name for p in out.iterdir()) == ["keep.txt"]
    finally:
        unmount(disk)


def test_calibrate_onto_a_full_disk_names_out(tmp_path, capsys):
    disk = small_tmpfs(tmp_path / "disk", "size=64k")
    try:
        fill(disk / "filler")
        code = main(["calibrate", "--shots", str(SHOTS), "--out", str(disk / "cal.toml"),
                     "--params", "lam", "--ids", "F94-39", "F94-40", "--workers", "1"])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and len(err) == 1 and "'out'" in err[0] and "No space" in err[0]
        assert sorted(p.name for p in disk.iterdir()) == ["filler"]
    finally:
        unmount(disk)


def test_a_read_only_out_is_refused_before_any_work(tmp_path, capsys):
    disk = small_tmpfs(tmp_path / "disk", "ro,size=64k")
    try:
        code = main(["validate", "--shots", str(SHOTS), "--models", "paper", "--no-figures",
                     "--out", str(disk / "out")])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and len(err) == 1 and "'out'" in err[0]
        assert not list(disk.iterdir())
    finally:
        unmount(disk)


def test_a_tls_scheduler_is_reached_with_the_tls_options(tmp_path, capsys):
    """A local TLS cluster (certificates made by openssl, encryption required): ``cavex
    table`` reaches it with ``--scheduler-tls-*`` and writes its table."""
    import shutil
    import subprocess

    if shutil.which("openssl") is None:
        pytest.skip("needs openssl to make the certificates")
    distributed = pytest.importorskip("distributed")

    def openssl(*words):
        subprocess.run(["openssl", *words], cwd=tmp_path, check=True, capture_output=True)

    openssl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", "ca.key", "-out",
            "ca.pem", "-days", "1", "-subj", "/CN=cavex-test-ca")
    openssl("req", "-newkey", "rsa:2048", "-nodes", "-keyout", "key.pem", "-out", "leaf.csr",
            "-subj", "/CN=127.0.0.1")
    (tmp_path / "ext.cnf").write_text("subjectAltName=IP:127.0.0.1,DNS:localhost\n")
    openssl("x509", "-req", "-in", "leaf.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
            "-CAcreateserial", "-out", "cert.pem", "-days", "1", "-extfile", "ext.cnf")
    ca, cert, key = (str(tmp_path / n) for n in ("ca.pem", "cert.pem", "key.pem"))
    security = distributed.Security(
        tls_ca_file=ca, tls_scheduler_cert=cert, tls_scheduler_key=key, tls_worker_cert=cert,
        tls_worker_key=key, tls_client_cert=cert, tls_client_key=key, require_encryption=True)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  protocol="tls://", security=security,
                                  dashboard_address=None) as cluster:
        assert cluster.scheduler_address.startswith("tls://")
        code = main(["table", "--velocities", "0", "100", "--depths", "0", "0.1", "-o",
                     str(tmp_path / "t.nc"), "--scheduler", cluster.scheduler_address,
                     "--scheduler-tls-ca", ca, "--scheduler-tls-cert", cert,
                     "--scheduler-tls-key", key])
    out = capsys.readouterr().out
    assert code == 0 and (tmp_path / "t.nc").is_file() and "failed  0" in out
