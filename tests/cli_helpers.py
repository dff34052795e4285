"""Running a command in the test process and checking a refusal (bad input: exit 2, one line
on stderr naming the parameter, nothing written)."""

from cavex.verification.cli import main


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def refused(capsys, tmp_path, argv, name, untouched=()):
    """The command exits 2 with one line naming ``name`` and leaves ``tmp_path`` as it was."""
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    code, out, err = run(capsys, *argv)
    assert code == 2, (out, err)
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("cavex: error: "), err
    assert name in lines[0], lines[0]
    after = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    assert after == before, "a refused command wrote something"
    return lines[0]
