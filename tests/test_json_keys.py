"""One JSON key convention across every command (README "Commands", "JSON output").

Every key whose value is a number (or a list of numbers) ends in an SI unit suffix of
:data:`UNIT_SUFFIXES` or names a dimensionless quantity of :data:`DIMENSIONLESS`; a map keyed
by labels (model names, boundary conventions) carries the unit on its own key, so its label keys
are not checked. No key spells a unit another way (``ms``, ``mps``, ``MPa``, ``m/s``, ...).
Each command runs once, in process, with cheap options (~40 s on 2 cores in all).
"""

import functools
import json
import numbers
import re
from pathlib import Path

import pytest

from cavex.verification.cli import build_parser, main

#: The one spelling of every unit in a JSON key (SI; velocity m/s as ``_m_s``, overload in g).
UNIT_SUFFIXES = ("_m", "_s", "_Pa", "_m_s", "_m_s2", "_kg", "_kg_m3", "_J", "_N", "_deg",
                 "_deg_s", "_rad", "_rad_s", "_g")
#: Dimensionless quantities: a key that is one of these words or ends in ``_<word>``.
DIMENSIONLESS = (
    "S", "A", "B",  # S = sigma_r / tau = A + B rho V^2 / tau
    "lam", "nu", "ratio", "factor",  # material constants, ratios (mean_ratio, outer_ratio, ...)
    "error_estimate", "relative_difference",  # relative errors
    "n", "phase", "equation", "cases", "cells", "failed", "run", "loaded", "sizes",  # counts
    "refinements", "evaluations", "px",  # pixels (the pictures of cavex view)
    # FE numerics (cavex.fem.Numerics; docs/fem.md)
    "degree", "per_decade", "per_step", "rho_inf", "tol", "cutbacks", "snapshots", "ramp",
)
#: Units spelled otherwise (a key word, compared in lower case) and characters no key contains.
OTHER_SPELLINGS = {"ms", "mps", "kmh", "mpa", "kpa", "gpa", "mm", "cm", "km", "kn", "kj", "sec",
                   "secs", "seconds", "msec", "degrees", "rads", "kgm3", "mpers"}
BAD_CHARACTERS = re.compile(r"[/\[\]()^]")
SHOTS = "examples/shots_forrestal1994.csv"


def _number(value):
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _numeric(value):
    """A number or a (nested) non-empty list of numbers and nulls."""
    if isinstance(value, list):
        items = [v for v in value if v is not None]
        return bool(items) and all(_numeric(v) for v in items)
    return _number(value)


def carries_unit(key):
    """``key`` names its SI unit or a dimensionless quantity."""
    return key.endswith(UNIT_SUFFIXES) or any(key == w or key.endswith("_" + w)
                                              for w in DIMENSIONLESS)


def bad_spelling(key):
    words = key.split("_")
    return bool(BAD_CHARACTERS.search(key)) or any(
        w.lower() in OTHER_SPELLINGS or (w.lower() == "pa" and w != "Pa") for w in words)


def offending_keys(document, path="", labels=False):
    """Paths of the keys of ``document`` that break the convention. ``labels``: ``document``
    is a map keyed by labels under a key that carries the unit."""
    found = []
    if isinstance(document, dict):
        for key, value in document.items():
            where = f"{path}/{key}"
            if bad_spelling(str(key)):
                found.append(f"{where} (unit spelled otherwise)")
            if _numeric(value) and not (labels or carries_unit(str(key))):
                found.append(where)
            found += offending_keys(value, where, isinstance(value, dict)
                                    and carries_unit(str(key)))
    elif isinstance(document, list):
        for i, item in enumerate(document):
            found += offending_keys(item, f"{path}[{i}]")
    return found


def run_json(capsys, *argv):
    code = main([*argv, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_the_checker_catches_what_it_should():
    good = {"depth_m": 1.0, "S": 2.0, "phases": [{"end_velocity_m_s": 3.0, "phase": 1}],
            "analytic_sigma_r_Pa": {"dynamic": 1e8, "quasi-static": 1.1e8},
            "mean_abs_log_ratio": 0.1, "interface_radii_m": [0.4, 0.8], "flag": True,
            "label": "a", "estimate_or_null": None, "max_axial_g": 3.0, "spin_rad_s": 1.0}
    assert offending_keys(good) == []
    bad = {"depth": 1.0, "time_ms": 2.0, "stress_MPa": 3.0, "v": [1.0, 2.0],
           "rows": [{"velocity": 1.0}], "sigma_pa": 1.0, "speed_m/s": 1.0,
           "summary": {"paper": 1.0}}
    assert offending_keys(bad) == ["/depth", "/time_ms (unit spelled otherwise)", "/time_ms",
                                   "/stress_MPa (unit spelled otherwise)", "/stress_MPa", "/v",
                                   "/rows[0]/velocity", "/sigma_pa (unit spelled otherwise)",
                                   "/sigma_pa", "/speed_m/s (unit spelled otherwise)",
                                   "/speed_m/s", "/summary/paper"]


def test_every_command_has_json():
    parser = build_parser()
    commands = parser._subparsers._group_actions[0].choices  # argparse keeps them only here
    missing = [name for name, sub in commands.items()
               if "--json" not in sub._option_string_actions
               and name != "config"]  # `cavex config` prints the input file itself (TOML)
    assert missing == []


@pytest.mark.parametrize("argv", [
    ("stress", "--velocity", "800", "--depth", "0.3"),
    ("stress", "--velocity", "800", "--depth", "0.3", "--resistance", "paper"),
])
def test_stress(capsys, argv):
    assert offending_keys(run_json(capsys, *argv)) == []


@pytest.mark.parametrize("resistance", ["derived", "paper"])
def test_penetrate(capsys, tmp_path, resistance):
    document = run_json(capsys, "penetrate", "--resistance", resistance, "--out", str(tmp_path))
    assert document["table2"] and offending_keys(document) == []


def test_penetrate_plain_law(capsys, tmp_path):
    document = run_json(capsys, "penetrate", "--resistance", "law", "--law-A", "2e8",
                        "--law-B", "2500", "--out", str(tmp_path), "--no-figures")
    assert document["law"] == {"A_Pa": 2e8, "B_kg_m3": 2500.0}
    assert offending_keys(document) == []


def test_fem(capsys):
    document = run_json(capsys, "fem", "--velocity", "300", "--depth", "0.3")
    assert "fe_sigma_r_Pa" in document and offending_keys(document) == []


def test_table(capsys, tmp_path):
    document = run_json(capsys, "table", "--velocities", "0", "300", "--depths", "0.3", "0.5",
                        "-o", str(tmp_path / "t.nc"), "--workers", "1")
    assert document["cases"] == 6 and offending_keys(document) == []


def test_verify(capsys, tmp_path, monkeypatch):
    """``cavex verify --quick --json`` on a smaller grid (the command path is the same)."""
    from cavex.verification.report import build as report

    monkeypatch.setattr(report, "verify", functools.partial(
        report.verify, velocities=[0.0, 1000.0], depths=[0.3, 0.8]))
    document = run_json(capsys, "verify", "--quick", "--no-figures", "--out", str(tmp_path),
                        "--workers", "1")
    assert document["cells"] > 0 and offending_keys(document) == []


def test_batch_and_its_case_results(capsys, tmp_path):
    """The summary ``--json`` prints and the case results of the store (``cases/<id>.json``,
    the ``result`` part: the FE comparison, with a dimensional numerics setting given)."""
    sweep = tmp_path / "s.toml"
    sweep.write_text('[sweep]\nname = "keys"\n[grid]\nvelocities = [300.0]\ndepths = [0.3]\n'
                     "[numerics]\nelements_per_decade = 8\ngrowth_per_step = [0.15, 0.2]\n"
                     "seed_radius = 0.002\nerror_estimate = false\nsnapshots = 1\n")
    out = tmp_path / "out"
    document = run_json(capsys, "batch", str(sweep), "--out", str(out), "--workers", "1")
    assert document["cases"] == 2 and offending_keys(document) == []
    stored = [json.loads(p.read_text())["result"] for p in sorted((out / "cases").iterdir())]
    assert len(stored) == 2 and stored[0]["numerics"]["seed_radius_m"] == 0.002
    assert [offending_keys(result) for result in stored] == [[], []]


def test_calibrate(capsys, tmp_path):
    document = run_json(capsys, "calibrate", "--shots", SHOTS, "--out",
                        str(tmp_path / "c.toml"), "--ids", "F94-52", "--params",
                        "strength_factor")
    assert document["model"] == "derived-dynamic" and offending_keys(document) == []


def test_validate_document():
    """``validation.json`` is the document ``cavex validate --json`` prints (running it builds
    an FE table per shot; ``tests/test_validation.py`` runs it): the committed one."""
    document = json.loads(Path("results/validation/validation.json").read_text())
    assert document["shots"][0]["predicted_m"] and offending_keys(document) == []


def test_trajectory(capsys, tmp_path):
    document = run_json(capsys, "trajectory", "--velocity", "300", "--out", str(tmp_path))
    assert offending_keys(document) == []
