"""An FE-table cache that cannot be poisoned (issue 32, verification/fedata/table_cache.py):
every entry checked when read and a bad one rebuilt with one line on stderr; an unusable
folder (a file in its place, read-only, full) found before any FE work and the run goes on
without the cache; stale temporary files removed and live ones counted; two concurrent runs
build a table once.

One real table is built per module (3-4 s); the damaged entries are made from it, and the
rebuilds return it (``build_table`` replaced by a counting stand-in: what is tested is the
cache, not the FE)."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from tmpfs_helpers import fill, small_tmpfs, unmount

from cavex.netcdf3 import PlainDataset, read_netcdf3
from cavex.verification.fedata import table as fe_table
from cavex.verification.fedata import table_cache
from cavex.verification.fedata.table import write_table
from cavex.verification.validation.predict import TableCache
from cavex.verification.validation.shots import read_shots

ROOT = Path(__file__).resolve().parents[1]
SHOTS = ROOT / "examples" / "shots_forrestal1994.csv"


def one_shot_file(folder, index=0):
    lines = SHOTS.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("id,"))
    path = Path(folder) / f"shot{index}.csv"
    path.write_text("\n".join([lines[header], lines[header + 1 + index]]) + "\n")
    return path


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """``(shot, cache folder, entry path, the good table as a Dataset)``, built for real."""
    folder = tmp_path_factory.mktemp("built")
    shot = read_shots(one_shot_file(folder)).shots[0]
    cache = TableCache(cache=folder / "cache", workers=1)
    cache.velocities_for([shot])
    good = cache.table(shot)
    entries = list((folder / "cache").glob("table_*.nc"))
    assert cache.built == 1 and len(entries) == 1
    return shot, folder / "cache", entries[0], good


@pytest.fixture
def fake_builds(monkeypatch, built):
    """``build_table`` replaced by a stand-in returning the good table; returns its calls."""
    calls = []

    def build(*args, **kwargs):
        calls.append(args[2])
        return built[3]

    monkeypatch.setattr(fe_table, "build_table", build)
    return calls


def damaged(entry, destination, change):
    """A copy of ``entry`` at ``destination`` with ``change(data, attrs)`` applied."""
    table = read_netcdf3(entry)
    data = {k: (d, np.array(v), dict(a)) for k, (d, v, a) in table.data.items()}
    attrs = dict(table.attrs)
    change(data, attrs)
    write_table(PlainDataset(data, table.coords, attrs, table.order), destination,
                reproducible=False)


def set_values(name, value, where=None):
    def change(data, attrs):
        dims, values, a = data[name]
        values = values.astype(values.dtype)
        if where is None:
            values[...] = value
        else:
            values.flat[where] = value
        data[name] = (dims, values, a)
    return change


def set_attr(name, value):
    def change(data, attrs):
        attrs[name] = value
    return change


DAMAGES = {
    "versions not JSON": set_attr("versions", "{not json"),
    "versions a JSON list": set_attr("versions", "[1, 2]"),
    "versions of another cavex": set_attr("versions", json.dumps({"cavex": "0.0.0"})),
    "fingerprint data not JSON": lambda d, a: (a.update(fingerprint="x",
                                                        fingerprint_data="{bad")),
    "solver settings changed": set_attr("solver_settings", "{}"),
    "a NaN stress": set_values("sigma_r", np.nan, 0),
    "a negative stress": set_values("sigma_r", -1e8, 1),
    "a stress of 1e300": set_values("sigma_r", 1e300, 2),
    "an infinite first-layer stress": set_values("sigma_r_first_layer", np.inf, 0),
    "a zero stress": set_values("sigma_r_first_layer", 0.0, 1),
    "failed flags": set_values("failed", 1, 0),
    "failed first-layer flags": set_values("failed_first_layer", 1, 0),
}


def fresh_cache(tmp_path, built):
    shot, _, entry, _ = built
    folder = tmp_path / "cache"
    folder.mkdir()
    return shot, folder, folder / entry.name, entry


@pytest.mark.parametrize("damage", sorted(DAMAGES))
def test_a_damaged_entry_is_rebuilt_with_one_line(tmp_path, capsys, built, fake_builds,
                                                  damage):
    shot, folder, path, entry = fresh_cache(tmp_path, built)
    damaged(entry, path, DAMAGES[damage])
    cache = TableCache(cache=folder)
    cache.velocities_for([shot])
    assert cache.plan([shot], [None]) == (1, 0)  # the estimate counts it as to build
    table = cache.table(shot)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(fake_builds) == 1 and cache.built == 1 and cache.reused == 0
    assert len(err) == 1 and "is rebuilt" in err[0] and path.name in err[0]
    assert np.isfinite(table["sigma_r"].values).all()
    # the rebuilt entry replaced the damaged one and is trusted by the next run
    again = TableCache(cache=folder)
    again.velocities_for([shot])
    assert again.plan([shot], [None]) == (0, 1)
    again.table(shot)
    assert again.reused == 1 and len(fake_builds) == 1


@pytest.mark.parametrize("damage", ["truncated", "empty", "not netCDF", "a folder",
                                    "a symlink"])
def test_an_unreadable_entry_is_rebuilt_with_one_line(tmp_path, capsys, built, fake_builds,
                                                      damage):
    shot, folder, path, entry = fresh_cache(tmp_path, built)
    outside = tmp_path / "outside.nc"
    if damage == "truncated":
        path.write_bytes(entry.read_bytes()[:200])
    elif damage == "empty":
        path.write_bytes(b"")
    elif damage == "not netCDF":
        path.write_text("hello\n")
    elif damage == "a folder":
        path.mkdir()
    else:
        shutil.copyfile(entry, outside)
        path.symlink_to(outside)
    cache = TableCache(cache=folder)
    cache.velocities_for([shot])
    table = cache.table(shot)
    err = capsys.readouterr().err.strip().splitlines()
    assert np.isfinite(table["sigma_r"].values).all()
    if damage == "a folder":  # cannot be replaced by a file: the run goes on without the cache
        assert len(fake_builds) == 1 and len(err) == 2 and "is rebuilt" in err[0]
        assert "unusable" in err[1] and cache.cache is None and path.is_dir()
        return
    assert len(fake_builds) == 1 and len(err) == 1 and "is rebuilt" in err[0]
    assert path.is_file() and not path.is_symlink()
    if damage == "a symlink":  # replaced, never written through
        assert outside.read_bytes() == entry.read_bytes()


def test_a_file_where_the_cache_folder_should_be(tmp_path, capsys, built, fake_builds):
    shot = built[0]
    blocker = tmp_path / "blocker"
    blocker.write_text("x")
    cache = TableCache(cache=blocker / "tables")
    second = TableCache(cache=blocker / "tables")  # the warning is given once
    err = capsys.readouterr().err.strip().splitlines()
    assert cache.cache is None and second.cache is None
    assert len(err) == 1 and "unusable" in err[0] and "without the cache" in err[0]
    assert fake_builds == []  # found before any FE work
    cache.velocities_for([shot])
    assert cache.plan([shot], [None]) == (1, 0)
    table = cache.table(shot)
    assert len(fake_builds) == 1 and np.isfinite(table["sigma_r"].values).all()
    assert blocker.read_text() == "x"


def test_a_read_only_cache_folder(tmp_path, capsys, built, fake_builds):
    shot = built[0]
    folder = small_tmpfs(tmp_path / "ro", "ro,size=1m")
    try:
        cache = TableCache(cache=folder)
        err = capsys.readouterr().err.strip().splitlines()
        assert cache.cache is None and len(err) == 1 and "unusable" in err[0]
        assert fake_builds == []
        cache.velocities_for([shot])
        cache.table(shot)
        assert len(fake_builds) == 1
    finally:
        unmount(folder)


def test_a_full_cache_folder(tmp_path, capsys, built, fake_builds):
    shot = built[0]
    folder = small_tmpfs(tmp_path / "full", "size=64k")
    try:
        fill(folder / "filler")
        cache = TableCache(cache=folder)  # an empty file can still be made
        cache.velocities_for([shot])
        table = cache.table(shot)
        err = capsys.readouterr().err.strip().splitlines()
        assert len(fake_builds) == 1 and np.isfinite(table["sigma_r"].values).all()
        assert len(err) == 1 and "unusable" in err[0] and cache.cache is None
        # no temporary left (the empty lock file stays: claims are made on it)
        assert sorted(p.name for p in folder.iterdir() if not p.name.endswith(".lock")) == \
            ["filler"]
    finally:
        unmount(folder)


def test_stale_temporaries_removed_and_live_ones_counted(tmp_path, built):
    _, _, entry, _ = built
    folder = tmp_path / "cache"
    folder.mkdir()
    kept = folder / entry.name
    shutil.copyfile(entry, kept)
    older = folder / "table_0000000000000000.nc"
    shutil.copyfile(entry, older)
    os.utime(older, (1.0, 1.0))  # the least recently used
    stale = [folder / ".table_1111111111111111.nc.999999999.abcdefgh.tmp",  # no such process
             folder / "table_2222222222222222.nc.999999999.tmp"]  # an older cavex's name
    for path in stale:
        path.write_bytes(b"\0" * 1000)
    live = folder / f".table_3333333333333333.nc.{os.getpid()}.abcdefgh.tmp"
    live.write_bytes(b"\0" * 10_000)
    size = entry.stat().st_size
    # room for the two entries, not for them and the live temporary: the older entry goes
    deleted = table_cache.prune(folder, kept, 2 * size + 5_000)
    assert deleted == [older]
    assert not any(p.exists() for p in stale) and live.exists() and kept.exists()


def test_two_concurrent_runs_build_a_table_once(tmp_path):
    """Two ``cavex validate`` processes on one cold cache: one builds, the other waits and
    reads (or, started late, reuses): one table built in all."""
    shots = one_shot_file(tmp_path, 1)
    env = {**os.environ, "CAVEX_CACHE_DIR": str(tmp_path / "cache")}
    runs = [subprocess.Popen([sys.executable, "-m", "cavex", "validate", "--shots", str(shots),
                              "--models", "table", "--no-figures", "--workers", "1",
                              "--out", str(tmp_path / f"out{i}")], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            for i in range(2)]
    outputs = [run.communicate(timeout=600) for run in runs]
    assert [run.returncode for run in runs] == [0, 0], outputs
    built = [json.loads((tmp_path / f"out{i}" / "validation.json").read_text()) for i in (0, 1)]
    stdout = "".join(out for out, _ in outputs)
    assert stdout.count("FE tables built 1, reused 0") == 1, outputs
    assert stdout.count("FE tables built 0, reused 1") == 1, outputs
    assert len(list((tmp_path / "cache").glob("table_*.nc"))) == 1
    assert built[0]["shots"] == built[1]["shots"]
    waited = sum("cavex: waiting for another run" in err for _, err in outputs)
    print(f"runs that waited for the other's claim: {waited}")


def test_without_a_usable_cache_the_tables_are_written_from_memory(tmp_path, capsys, built,
                                                                   fake_builds):
    """The run's copies in ``--out/tables/`` come from memory when there is no cache, never
    from another cache folder (the default one)."""
    shot = built[0]
    blocker = tmp_path / "blocker"
    blocker.write_text("x")
    cache = TableCache(cache=blocker / "tables")
    cache.velocities_for([shot])
    cache.table(shot)
    written = cache.write_used(tmp_path / "out" / "tables")
    capsys.readouterr()
    assert [p.name for p in written] == [built[2].name]
    copy = read_netcdf3(written[0])
    assert np.array_equal(copy["sigma_r"], read_netcdf3(built[2])["sigma_r"])
