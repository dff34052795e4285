"""The four kinds of input file (target config, sweep, calibration: TOML; shots: CSV) are read by
one reader (``cavex.input_files``) and refused in one form (docs/config.md, "Input files and
their errors"): through the real commands, exit code 2 and one line on stderr
``cavex: error: '<path>': <where> <what>``, nothing on stdout, no traceback, nothing written.

The same kinds of fault in each: a missing file, a folder, an unreadable file, bytes that are
not UTF-8, a syntax error (a CSV row with too few cells), an unknown or missing key (column),
a wrong type and a value out of range; a UTF-8 byte-order mark is accepted (a fault after it is
reported at the same line and column as without it).
"""

import dataclasses
import os
import re
from pathlib import Path

import pytest

from cavex.concrete import Mapping
from cavex.config import default_config_text, load_config
from cavex.verification.cli import main
from cavex.verification.fedata.batch import parse_sweep
from cavex.verification.validation.calibration import (
    Calibration,
    calibration_text,
    read_calibration,
)
from cavex.verification.validation.shots import read_shots

SHOTS = Path(__file__).resolve().parents[1] / "examples" / "shots_forrestal1994.csv"
BOM = b"\xef\xbb\xbf"
SWEEP = '[sweep]\nname = "s"\n[grid]\nvelocities = [300.0]\ndepths = [0.3]\n'
TOML_SYNTAX = re.compile(r"line \d+, column \d+ is not valid TOML \(.+\)")


def calibration_file_text():
    reference = read_shots(SHOTS).by_id(["F94-52"])[0]
    calibration = Calibration("derived-dynamic", Mapping(strength_factor=1.5),
                              ("strength_factor",), ("F94-52",),
                              statistics=(("n", 1), ("evaluations", 3)))
    return calibration_text(calibration, SHOTS, reference)


def line_of(text, start):
    """1-based number of the first line of ``text`` starting with ``start``."""
    return next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith(start))


def config_faults(text):
    return {
        "syntax": (text.replace("E = 25e9", "E = 25 GPa"),
                   f"line {line_of(text, 'E = 25e9')}, column 8 is not valid TOML (Expected "
                   "newline or end of document after a statement)"),
        "unknown key": (text.replace("tau = 6e6", "tau = 6e6\ncolour = 1"),
                        "layers[2].colour is not a known key (accepted: E, bottom, concrete, "
                        "crush_pressure, lam, law_A, law_B, lock_pressure, lock_strain, "
                        "locked_modulus, name, nu, rho, scab_depth, sigma_c, tau, tau_max, "
                        "tensile_strength, thickness, tunnel_wall)"),
        "missing key": (text.replace("lam = 0.50\n", ""), "layers[2].lam is missing (required)"),
        "wrong type": (text.replace("E = 25e9", 'E = "x"'),
                       "layers[0].E must be a number (got 'x')"),
        "out of range": (text.replace("V0 = 1000.0", "V0 = 2e4"),
                         "projectile.V0 must be <= 10000 m/s (rigid-projectile penetration) "
                         "(got 20000.0)"),
    }


def sweep_faults(text):
    return {
        "syntax": (text.replace("velocities = [300.0]", "velocities = [300.0,,]"), TOML_SYNTAX),
        "unknown key": (text + "velocity = 1\n",
                        "grid.velocity is not a known key (accepted: depths, nu, velocities)"),
        "missing key": (text.replace("depths = [0.3]\n", ""), "grid.depths is missing (required)"),
        "wrong type": (text.replace("depths = [0.3]", 'depths = "x"'),
                       "grid.depths must be a non-empty array of numbers (got 'x')"),
        "out of range": (text.replace("velocities = [300.0]", "velocities = [2e4]"),
                         "grid.velocities[0] must be <= 10000 m/s (got 20000.0)"),
    }


def calibration_faults(text):
    return {
        "syntax": (text.replace("[calibration]", "[calibration"),
                   f"line {line_of(text, '[calibration]')}, column 13 is not valid TOML "
                   "(Expected ']' at the end of a table declaration)"),
        "unknown key": (text.replace("reference_shot = ", "reference = "),
                        "calibration.reference is not a known key (accepted: evaluations, lam, "
                        "mean_abs_log_ratio, model, modulus_factor, n, nu, outliers, params, "
                        "reference_shot, rms_log_ratio, shots, shots_file, skipped, "
                        "strength_factor)"),
        "missing key": (text.replace("\nshots = ", "\n# shots = "),
                        "calibration.shots is missing (required)"),
        "wrong type": (text.replace("\nnu = ", '\nnu = "x" # ', 1),
                       "calibration.nu must be a number in [-0.99, 0.4999] (got 'x')"),
        "out of range": (text.replace("\nlam = ", "\nlam = 5.0 # ", 1),
                         "calibration.lam must be a number in [0, 2.9] (got 5.0)"),
    }


def shot_faults(text):
    header, row = line_of(text, "id,"), line_of(text, "F94-39,")
    shot = f"line {row} (shot 'F94-39'), column V0_m_s must be a number in [1, 10000] " \
           "(rigid-projectile penetration)"
    return {
        "syntax": (text.replace("F94-39,0.904,", "F94-39,"),
                   f"line {row} must have 9 cells, as the header (got 8)"),
        "unknown key": (text.replace(",fc_Pa,", ",fc_MPa,"),
                        f"line {header} (header) has no column fc_Pa (required: id, mass_kg, "
                        "diameter_m, crh, V0_m_s, fc_Pa, rho_kg_m3, depth_m)"),
        "missing key": (text.replace("F94-39,", ","),
                        f"line {row}, column id must be a non-empty shot name (got '')"),
        "wrong type": (text.replace(",2.0,800.0,", ",2.0,fast,", 1), f"{shot} (got 'fast')"),
        "out of range": (text.replace(",2.0,800.0,", ",2.0,2e4,", 1), f"{shot} (got '2e4')"),
    }


# kind: (file name, good text, its faults, the command reading it, the reader)
KINDS = {
    "config": ("target.toml", default_config_text, config_faults,
               lambda path, out: ["penetrate", "--config", path, "--out", out], load_config),
    "sweep": ("sweep.toml", lambda: SWEEP, sweep_faults,
              lambda path, out: ["batch", path, "--out", out], parse_sweep),
    "calibration": ("calibration.toml", calibration_file_text, calibration_faults,
                    lambda path, out: ["validate", "--shots", SHOTS, "--calibration", path,
                                       "--out", out], read_calibration),
    "shots": ("shots.csv", lambda: SHOTS.read_text(encoding="utf-8"), shot_faults,
              lambda path, out: ["validate", "--shots", path, "--out", out],
              lambda path: read_shots(path).shots),
}
FAULTS = ("syntax", "unknown key", "missing key", "wrong type", "out of range")


def refusal(capsys, tmp_path, kind, path):
    """Run the command reading ``path``; check exit 2, one line, nothing written; return the
    message after ``cavex: error: '<path>': ``."""
    before = sorted(tmp_path.rglob("*"))
    argv = KINDS[kind][3](path, tmp_path / "out")
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert (code, out) == (2, ""), err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    prefix = f"cavex: error: '{path}': "
    assert err.startswith(prefix), err
    assert sorted(tmp_path.rglob("*")) == before, "a refused command wrote something"
    return err[len(prefix):-1]


def check(message, expected):
    if isinstance(expected, re.Pattern):
        assert expected.fullmatch(message), message
    else:
        assert message == expected


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("fault", FAULTS)
@pytest.mark.parametrize("bom", [False, True], ids=["plain", "bom"])
def test_a_fault_in_a_file_is_one_line_naming_where(capsys, tmp_path, kind, fault, bom):
    name, good, faults, _, _ = KINDS[kind]
    text, expected = faults(good())[fault]
    assert text != good(), "the fault was not made"
    path = tmp_path / name
    path.write_bytes((BOM if bom else b"") + text.encode())
    check(refusal(capsys, tmp_path, kind, path), expected)


@pytest.mark.parametrize("kind", KINDS)
def test_a_missing_file_or_a_folder_is_refused(capsys, tmp_path, kind):
    name = KINDS[kind][0]
    assert refusal(capsys, tmp_path, kind, tmp_path / name) == \
        "cannot be read (No such file or directory)"
    folder = tmp_path / "folder"
    folder.mkdir()
    assert refusal(capsys, tmp_path, kind, folder) == "cannot be read (Is a directory)"


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads every file")
@pytest.mark.parametrize("kind", KINDS)
def test_an_unreadable_file_is_refused(capsys, tmp_path, kind):
    name, good = KINDS[kind][:2]
    path = tmp_path / name
    path.write_text(good())
    path.chmod(0)
    try:
        assert refusal(capsys, tmp_path, kind, path) == "cannot be read (Permission denied)"
    finally:
        path.chmod(0o600)


@pytest.mark.parametrize("kind", KINDS)
def test_bytes_that_are_not_utf8_are_refused_at_their_line_and_column(capsys, tmp_path, kind):
    name, good = KINDS[kind][:2]
    lines = good().encode().split(b"\n")
    path = tmp_path / name
    path.write_bytes(b"\n".join([lines[0], b"\xff" + lines[1], *lines[2:]]))
    assert refusal(capsys, tmp_path, kind, path) == \
        "line 2, column 1 is not UTF-8 text (byte 0xff)"
    lines[2] = "é".encode() + lines[2][:2] + "é".encode("latin-1") + lines[2][2:]
    path.write_bytes(b"\n".join(lines))
    assert refusal(capsys, tmp_path, kind, path) == \
        "line 3, column 4 is not UTF-8 text (byte 0xe9)"


@pytest.mark.parametrize("kind", KINDS)
def test_a_byte_order_mark_is_accepted(tmp_path, kind):
    """A file saved with a UTF-8 byte-order mark (Windows editors, spreadsheets' "CSV UTF-8")
    reads exactly as without one."""
    name, good, _, _, reader = KINDS[kind]
    plain, marked = tmp_path / "plain" / name, tmp_path / "marked" / name
    for path, start in ((plain, b""), (marked, BOM)):
        path.parent.mkdir()
        path.write_bytes(start + good().encode())
    read_plain, read_marked = reader(plain), reader(marked)
    if kind == "calibration":  # it remembers its file
        read_marked = dataclasses.replace(read_marked, source=str(plain))
    assert read_marked == read_plain
