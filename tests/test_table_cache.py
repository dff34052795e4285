"""The FE-table cache shared by commands and runs (verification/fedata/table_cache.py): its
folder, reuse by a second `cavex validate` into another folder, and a damaged entry rebuilt."""

import json
from pathlib import Path

import pytest

from cavex.verification.cli import main
from cavex.verification.fedata import table as fe_table
from cavex.verification.fedata.table_cache import (
    CACHE_ENV,
    SIZE_ENV,
    cache_dir,
    entry_path,
    load_entry,
    max_bytes,
    prune,
)
from cavex.verification.validation.predict import TableCache, table_velocities
from cavex.verification.validation.shots import read_shots, shot_projectile, shot_target

SHOTS = Path(__file__).resolve().parents[1] / "examples" / "shots_forrestal1994.csv"


def test_cache_folder_from_the_environment(tmp_path):
    home = Path.home() / ".cache" / "cavex" / "tables"
    assert cache_dir({CACHE_ENV: str(tmp_path / "c")}) == tmp_path / "c"
    assert cache_dir({CACHE_ENV: str(tmp_path / "c"), "XDG_CACHE_HOME": "/x"}) == tmp_path / "c"
    assert cache_dir({"XDG_CACHE_HOME": str(tmp_path)}) == tmp_path / "cavex" / "tables"
    assert cache_dir({CACHE_ENV: "", "XDG_CACHE_HOME": ""}) == home
    assert cache_dir({}) == home


def test_the_test_suite_never_uses_the_users_cache(table_cache_dir):
    assert cache_dir() == table_cache_dir
    assert TableCache().cache == table_cache_dir


def two_shot_file(tmp_path):
    """The committed Forrestal file cut to two shots of two targets (two FE tables)."""
    lines = SHOTS.read_text(encoding="utf-8").splitlines()
    rows = [line for line in lines if line[:1] not in ("#", "") and not line.startswith("id,")]
    targets = {}
    for row in rows:
        shot = read_one(lines, row, tmp_path)
        targets.setdefault((shot.fc, shot.rho), row)
    assert len(targets) >= 2
    keep = list(targets.values())[:2]
    path = tmp_path / "two.csv"
    path.write_text("\n".join(line for line in lines if line.startswith("#")
                              or line.startswith("id,") or line in keep) + "\n")
    return path


def read_one(lines, row, tmp_path):
    one = tmp_path / "one.csv"
    one.write_text("\n".join([line for line in lines if line.startswith("id,")] + [row]) + "\n")
    return read_shots(one).shots[0]


def counting_builds(monkeypatch):
    """Replace ``build_table`` by a wrapper counting its calls; returns the counter."""
    real, calls = fe_table.build_table, []

    def counted(*args, **kwargs):
        calls.append(args[2])
        return real(*args, **kwargs)

    monkeypatch.setattr(fe_table, "build_table", counted)
    return calls


def test_second_validate_into_another_folder_builds_no_table(capsys, tmp_path, monkeypatch,
                                                             table_cache_dir):
    """Only the FE-table model (``--models table``): the other models use no FE table, so
    they would add time (the concrete model's cavity tables, 1 s each), not a check of the
    cache."""
    shots = two_shot_file(tmp_path)
    builds = counting_builds(monkeypatch)
    assert main(["validate", "--shots", str(shots), "--models", "table", "--no-figures",
                 "--out", str(tmp_path / "a")]) == 0
    first = capsys.readouterr().out
    assert len(builds) == 2 and "FE tables built 2, reused 0" in first
    cached = sorted(p.name for p in table_cache_dir.glob("table_*.nc"))
    assert len(cached) == 2
    assert sorted(p.name for p in (tmp_path / "a" / "tables").iterdir()) == cached
    assert main(["validate", "--shots", str(shots), "--models", "table", "--no-figures",
                 "--out", str(tmp_path / "b")]) == 0
    second = capsys.readouterr().out
    assert len(builds) == 2 and "FE tables built 0, reused 2" in second
    for name in cached:  # the copy in each results folder is the cache entry, byte for byte
        assert (tmp_path / "b" / "tables" / name).read_bytes() == \
            (table_cache_dir / name).read_bytes()
    results = [json.loads((tmp_path / d / "validation.json").read_text()) for d in "ab"]
    for result in results:  # the command names its own --out folder; everything else is equal
        result.pop("command")
    assert results[0] == results[1]
    assert not list(table_cache_dir.glob("*.tmp"))


@pytest.mark.parametrize("damage", ["truncated", "other target"])
def test_damaged_entry_is_rebuilt(tmp_path, monkeypatch, table_cache_dir, damage):
    shot = read_shots(two_shot_file(tmp_path)).shots[0]
    first = TableCache()
    table = first.table(shot)
    key = first.key(shot_target(shot), shot_projectile(shot), table_velocities([shot]))
    entry = entry_path(key)
    assert entry.parent == table_cache_dir and entry.exists() and first.built == 1
    good = entry.read_bytes()
    if damage == "truncated":
        entry.write_bytes(good[: len(good) // 2])
    else:  # a readable table of another target under this key
        other = read_shots(two_shot_file(tmp_path)).shots[1]
        other_table = TableCache(cache=tmp_path / "other").table(other)
        fe_table.write_table(other_table, entry)
    target, projectile = shot_target(shot), shot_projectile(shot)
    assert load_entry(entry, target, projectile, table_velocities([shot])) is None
    builds = counting_builds(monkeypatch)
    again = TableCache()
    rebuilt = again.table(shot)
    assert (len(builds), again.built, again.reused) == (1, 1, 0)
    assert entry.read_bytes() == good  # the same reproducible file as the first build
    assert float(abs(rebuilt["sigma_r"] - table["sigma_r"]).max()) == 0.0
    assert load_entry(entry, target, projectile, table_velocities([shot])) is not None


def test_entry_of_other_solver_settings_or_version_is_not_trusted(tmp_path, table_cache_dir):
    shot = read_shots(two_shot_file(tmp_path)).shots[0]
    cache = TableCache()
    table = cache.table(shot)
    target, projectile, velocities = shot_target(shot), shot_projectile(shot), \
        table_velocities([shot])
    entry = next(table_cache_dir.glob("table_*.nc"))
    assert load_entry(entry, target, projectile, velocities) is not None
    assert load_entry(entry, target, projectile, velocities[:-1]) is None
    old = table.copy()
    old.attrs["versions"] = json.dumps({"cavex": "0.0.0"})
    fe_table.write_table(old, entry)
    assert load_entry(entry, target, projectile, velocities) is None
    other = table.copy()
    other.attrs["solver_settings"] = "{}"
    fe_table.write_table(other, entry)
    assert load_entry(entry, target, projectile, velocities) is None


def test_prune_deletes_the_least_recently_used_entries_first(tmp_path):
    """Five 1000-byte entries, modified at t = 1 ... 5, limit 2500 bytes: the three oldest go
    except the one just stored (t = 1 here), which is kept even though it is the oldest."""
    import os

    paths = []
    for k in range(1, 6):
        path = tmp_path / f"table_{k:016x}.nc"
        path.write_bytes(b"x" * 1000)
        os.utime(path, (k, k))
        paths.append(path)
    (tmp_path / "other.txt").write_bytes(b"y" * 5000)  # not a table: never counted or deleted
    deleted = prune(tmp_path, paths[0], 2500)
    assert deleted == [paths[1], paths[2], paths[3]]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [paths[0].name, paths[4].name, "other.txt"])
    assert prune(tmp_path, paths[0], 2500) == []


def test_size_limit_from_the_environment(capsys, tmp_path, monkeypatch):
    assert max_bytes({}) == 500e6
    assert max_bytes({SIZE_ENV: "0.25"}) == 0.25e6
    for bad in ("0", "-3", "inf", "nan", "lots"):
        monkeypatch.setenv(SIZE_ENV, bad)
        code = main(["validate", "--shots", str(SHOTS), "--models", "table", "--out",
                     str(tmp_path / "v")])
        out, err = capsys.readouterr()
        assert (code, out) == (2, "") and err.count("\n") == 1 and f"'{SIZE_ENV}'" in err
        assert not (tmp_path / "v").exists()
