"""Ctrl-C, SIGTERM and kill -9 at several moments of a ``cavex validate`` that builds FE tables
(issue 32): ``--out`` is left as it was or complete, every time.

A subprocess validates two shots of two targets (two FE tables, --models table) into an
``--out`` that already holds a file, with a fresh ``CAVEX_CACHE_DIR``; it is signalled at a
moment found by watching it: during start-up, after its estimate line, when the first table is
in the cache (the moment the tables used to be copied into ``--out``), when the second is, and
when its staged write has begun. Then it is run to completion into the same folder: complete,
and a stage left by ``kill -9`` removed. That run is :func:`cavex.verification.cli.main` in
this process (the same command's ``run``, with the same ``CAVEX_CACHE_DIR``): it checks what
the folder and the cache hold, not a signal or an exit of a process, and in this process it
starts without importing and loading the numerical libraries again (1-1.5 s a subprocess).
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cavex.verification.cli import main

ROOT = Path(__file__).resolve().parents[1]
SHOTS = ROOT / "examples" / "shots_forrestal1994.csv"
COMPLETE = {"keep.txt", "validation.json", "predictions.csv", "report.md", "tables"}
STAGE_PREFIX = ".cavex-partial-"


def two_targets(folder):
    """Two shots of two different concrete targets from the Forrestal file."""
    lines = SHOTS.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("id,"))
    rows, seen = [], set()
    for line in lines[header + 1:]:
        cells = line.split(",")
        if line and not line.startswith("#") and (cells[6], cells[7]) not in seen:
            seen.add((cells[6], cells[7]))
            rows.append(line)
    path = folder / "two.csv"
    path.write_text("\n".join([lines[header], *rows[:2]]) + "\n")
    return path


def wait_for(condition, process, timeout=300.0):
    """Poll ``condition`` until true (True) or the process ends first (False)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        if process.poll() is not None:
            return False
        time.sleep(0.01)
    raise AssertionError("moment not reached in time")


def moments(err_path, cache, out):
    def text():
        return err_path.read_text() if err_path.exists() else ""

    def tables(n):
        return lambda: len(list(cache.glob("table_*.nc"))) >= n

    return {
        "start-up": lambda: True,
        "estimate printed": lambda: "cavex: validate" in text(),
        "first table cached": tables(1),
        "second table cached": tables(2),
        "staged write begun": lambda: any(p.name.startswith(STAGE_PREFIX)
                                          for p in out.iterdir()),
    }


def visible(out):
    return {p.name for p in out.iterdir() if not p.name.startswith(".")}


def check_untouched_or_complete(out, shots_n=2):
    names = visible(out)
    if names == {"keep.txt"}:
        return "untouched"
    assert names == COMPLETE, names
    import json

    result = json.loads((out / "validation.json").read_text())
    assert result["shots_file"]["n"] == shots_n
    assert len(list((out / "tables").glob("table_*.nc"))) == 2
    assert (out / "keep.txt").read_text() == "kept\n"
    return "complete"


CASES = [(sig, moment) for sig in ("SIGKILL",) for moment in
         ("start-up", "estimate printed", "first table cached", "second table cached",
          "staged write begun")] + \
        [(sig, moment) for sig in ("SIGINT", "SIGTERM") for moment in
         ("estimate printed", "first table cached", "second table cached",
          "staged write begun")]


@pytest.mark.parametrize("sig, moment", CASES)
def test_a_signal_leaves_out_untouched_or_complete(tmp_path, sig, moment, capsys,
                                                   monkeypatch):
    shots = two_targets(tmp_path)
    out, cache, err_path = tmp_path / "out", tmp_path / "cache", tmp_path / "stderr.txt"
    out.mkdir()
    (out / "keep.txt").write_text("kept\n")
    env = {**os.environ, "CAVEX_CACHE_DIR": str(cache)}
    command = [sys.executable, "-m", "cavex", "validate", "--shots", str(shots), "--models",
               "table", "--no-figures", "--workers", "1", "--out", str(out)]
    with open(err_path, "w") as err:
        process = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=err)
        try:
            reached = wait_for(moments(err_path, cache, out)[moment], process)
            if reached:
                process.send_signal(getattr(signal, sig))
            code = process.wait(timeout=300)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()
    state = check_untouched_or_complete(out)
    if sig == "SIGKILL":  # no clean-up: a kill just after the moves leaves them complete
        assert code in (0, -9) and (state == "complete" or code != 0), (state, code)
    else:  # the exit code says what --out holds (the program ignores a signal once moved)
        assert (state == "complete") == (code == 0), (state, code, err_path.read_text())
    # the staged write lasts milliseconds: it may be over before the poll sees it
    assert reached or moment == "staged write begun"
    if moment in ("estimate printed", "first table cached"):  # a table still to build
        assert state == "untouched"
    print(f"{sig} at {moment}: {state} (exit {code})")
    if sig != "SIGKILL":  # a clean-up ran: no stage left, one line at most on stderr
        assert not [p for p in out.iterdir() if p.name.startswith(STAGE_PREFIX)]
        assert "Traceback" not in err_path.read_text()
    # the next run completes into the same folder and removes a stage kill -9 left
    monkeypatch.setenv("CAVEX_CACHE_DIR", str(cache))
    assert main(command[3:]) == 0, capsys.readouterr().err
    assert check_untouched_or_complete(out) == "complete"
    assert not [p for p in out.iterdir() if p.name.startswith(STAGE_PREFIX)]
