"""The model registry: a toy model in one module (examples/toy_model.py) is offered and run by
``penetrate``, ``trajectory`` and ``validate`` with no other change, and the registry is the one
vocabulary of model names (labels, choices, columns)."""

import importlib.util
import json
from pathlib import Path

import pytest

from cavex.analytic.models import get, labels, names, parse_label, registry
from cavex.analytic.penetration.zones import crater_depth
from cavex.config import load_config
from cavex.verification.cli import main

ROOT = Path(__file__).resolve().parents[1]
TOY = ROOT / "examples" / "toy_model.py"
SHOTS = ROOT / "examples" / "shots_forrestal1994.csv"
RTOL = 1e-9  # the 1-D integrator's relative tolerance (integrator.RTOL)


@pytest.fixture
def toy():
    """The toy module, imported afresh (it registers its model), unregistered afterwards."""
    spec = importlib.util.spec_from_file_location("toy_model", TOY)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    yield module
    registry.unregister(module.MODEL.name)


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_the_registry_is_the_vocabulary():
    """cavex's own models, in the order of validate's columns; each label parses back to its
    model; capabilities select the commands' choices."""
    assert names() == ("derived", "paper", "table", "law", "concrete", "li-chen-2003",
                       "li-chen-concrete", "forrestal-1994")
    assert labels(predicts_shots=True) == (
        "derived-quasi-static", "derived-dynamic", "paper", "table", "concrete",
        "li-chen-2003", "li-chen-concrete", "forrestal-1994")
    assert names(flies=True) == ("derived", "paper", "table", "law")
    assert names(closed_form=True) == ("derived", "paper")
    assert names(recommended=True) == ("li-chen-concrete",)
    for label in labels():
        model, boundary = parse_label(label)
        assert model.label(boundary) == label
    with pytest.raises(ValueError, match="already registered"):
        registry.register(get("derived"))


def test_toy_model_flies_in_penetrate(toy, capsys, tmp_path):
    """``penetrate --resistance toy-constant-pressure`` on a one-layer target: the depth of the
    constant force's closed form, ``L = m V0^2/(2F) + L_c/2`` (module docstring of the toy)."""
    assert "toy-constant-pressure" in names(flies=True)
    target, projectile = load_config()
    config = tmp_path / "one_layer.toml"
    text = (ROOT / "core" / "data" / "runway.toml").read_text()
    config.write_text(text)
    code, out, err = run(capsys, "penetrate", "--resistance", "toy-constant-pressure",
                         "--json", "--no-figures", "--out", tmp_path / "p")
    assert code == 0, err
    result = json.loads(out)
    assert result["model"] == "toy-constant-pressure"
    resistance = toy.MODEL.resistance(target, projectile)
    force = resistance.force(1.0, 0.0)  # every ring in the target
    # the nose rule integrates a constant stress to the projected area (Eqs. 13-14 with B = 0)
    assert force == pytest.approx(toy.PRESSURE * 3.141592653589793 * projectile.r ** 2,
                                  rel=1e-12)
    depth = projectile.m * projectile.V0 ** 2 / (2.0 * force) + crater_depth(projectile) / 2.0
    assert result["phases"][-1]["end_depth_m"] == pytest.approx(depth, rel=1e-6)


def test_toy_model_flies_in_trajectory(toy, capsys, tmp_path):
    """``trajectory --resistance toy-constant-pressure`` at normal incidence: the 3-D shot
    stops, with its resistance named in the summary."""
    code, out, err = run(capsys, "trajectory", "--resistance", "toy-constant-pressure",
                         "--velocity", "300", "--json", "--no-figures", "--out",
                         tmp_path / "t")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["settings"]["resistance"] == "toy-constant-pressure"
    assert (tmp_path / "t" / "summary.json").exists()


def test_toy_model_predicts_in_validate(toy, capsys, tmp_path):
    """``validate --models toy-constant-pressure forrestal-1994``: the toy's column after
    Forrestal's (the registry's order: the toy registered last), each depth the toy's own
    ``shot_depth``; the figures drawn (the toy gets the registry's next marker)."""
    from cavex.verification.validation.shots import read_shots

    code, out, err = run(capsys, "validate", "--shots", SHOTS, "--models",
                         "toy-constant-pressure", "forrestal-1994", "--json", "--out",
                         tmp_path / "v", "--no-progress")
    assert code == 0, err
    result = json.loads(out)
    assert result["models"] == ["forrestal-1994", "toy-constant-pressure"]
    assert (tmp_path / "v" / "predicted_vs_measured.png").exists()
    for row, shot in zip(result["shots"], read_shots(SHOTS).shots, strict=True):
        assert row["predicted_m"]["toy-constant-pressure"] == pytest.approx(
            toy.MODEL.shot_depth(shot), rel=1e-5)


def test_unknown_model_is_refused_with_the_registry_choices(capsys):
    code, out, err = run(capsys, "penetrate", "--resistance", "toy-constant-pressure")
    assert code == 2 and out == ""
    assert "derived, paper, table, law" in err and len(err.strip().splitlines()) == 1
