"""The model registry: a toy model in one module (examples/toy_model.py) is offered and run by
``penetrate``, ``trajectory`` and ``validate`` with no other change, and the registry is the one
vocabulary of model names (labels, choices, columns)."""

import ast
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
    assert names(recommended=True) == ("concrete",)
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


# --- no other code compares model names ------------------------------------------------------

#: the folders of the package (pyproject.toml maps them under ``cavex``)
PACKAGE_FOLDERS = ("core", "analytic", "fem", "verification")
#: where model names may be compared: the registry itself and the command line's choices
REGISTRY_AND_CLI = ("analytic/models/", "verification/cli.py", "verification/commands/options.py")
#: a model's name where it decides nothing about a model (a word of another vocabulary, or a
#: legend's text), each with what it is there: ``(file, enclosing function or "<module>",
#: word) -> what it is`` (what a scan cannot tell)
NOT_SWITCHES = {
    ("core/concrete.py", "<module>", "concrete"): "the concrete layer's name",
    ("core/config.py", "parse_target", "concrete"): "a layer's key concrete = {fc, rho}",
    ("analytic/penetration/erosion.py", "ErodingNose.summary", "law"):
        "the JSON key of the erosion law's name",
    ("verification/commands/penetrate.py", "penetration_job", "law"): "the JSON key of the law",
    ("verification/commands/penetrate.py", "penetration_job", "table"): "the JSON key of --table",
    ("verification/commands/table.py", "job", "table"): "the command's result, an FE table",
    ("verification/commands/trajectory.py", "trajectory_job", "table"): "the option --table",
    ("verification/report/html.py", "_blocks", "table"): "a Markdown block kind",
    ("verification/report/html.py", "_render", "table"): "a Markdown block kind",
    ("verification/report/analysis.py", "<module>", "paper"):
        "the FE report grid's key of the paper's column (its variables ``*_paper``)",
    ("verification/report/plots.py", "plastic_radius_plot", "derived-dynamic"):
        "the legend's text of the closed form's plastic radius (first velocity only)",
    ("verification/report/plots.py", "plastic_radius_plot", "derived-quasi-static"):
        "the legend's text of the closed form's plastic radius (first velocity only)",
    ("verification/studies/table2.py", "table2_comparison", "paper"): "the paper's printed row",
    ("verification/studies/table2_study.py", "_compare", "paper"): "the paper's printed row",
    ("verification/studies/table2_study.py", "eq29_reading", "derived"):
        "a reading of the paper's Eq. (29) (printed or derived)",
    ("verification/studies/table2_study.py", "ReadingResistance.crater_force", "concrete"):
        "a reading's crater medium (concrete or soil)",
}


def _strings(node):
    """The string literals of ``node``: a constant, or the items of a tuple, list or set."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return {node.value}
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return set().union(set(), *(_strings(e) for e in node.elts))
    return set()


def _aliases(tree, vocabulary):
    """Module-level names bound to a model name or a tuple of them only (``EMPIRICAL =
    "forrestal-1994"``): ``{name: (line, model names)}``."""
    found = {}
    for node in tree.body:
        value = getattr(node, "value", None)
        items = value.elts if isinstance(value, (ast.Tuple, ast.List, ast.Set)) else [value]
        if isinstance(node, ast.Assign) and all(
                isinstance(i, ast.Constant) and _strings(i) & vocabulary for i in items):
            for target in node.targets:
                for name in ast.walk(target):
                    if isinstance(name, ast.Name):
                        found[name.id] = (node.lineno, _strings(value))
    return found


def _named(node, aliases):
    """The aliases ``node`` is (a name, or an attribute of that name)."""
    key = node.id if isinstance(node, ast.Name) else (
        node.attr if isinstance(node, ast.Attribute) else None)
    return {key} if key in aliases else set()


def _enclosing(tree):
    """``{node: qualified name of the function it is in, or "<module>"}``."""
    owner = {}

    def visit(node, name):
        for child in ast.iter_child_nodes(node):
            inner = name
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                inner = child.name if name == "<module>" else f"{name}.{child.name}"
            owner[child] = inner
            visit(child, inner)

    visit(tree, "<module>")
    return owner


def switch_sites(source, vocabulary, imported=()):
    """``[(line, function, kind, words)]``: where ``source`` decides on a model name: ``==``,
    ``!=``, ``in``, ``not in`` against a model name (a literal, a tuple or set of them, or a
    module-level alias of one), a dict keyed by one, ``choices=`` offering one, a conditional
    expression choosing one, and the aliases themselves (``imported``: the names of aliases
    bound in other modules)."""
    tree = ast.parse(source)
    bound = _aliases(tree, vocabulary)
    aliases = set(bound) | set(imported)
    owner = _enclosing(tree)
    sites = [(line, "<module>", "alias", words) for line, words in dict(bound.values()).items()]
    for node in ast.walk(tree):
        words = set()
        if isinstance(node, ast.Compare):
            for op, right in zip(node.ops, node.comparators, strict=True):
                if isinstance(op, (ast.Eq, ast.NotEq, ast.In, ast.NotIn)):
                    words |= (_strings(node.left) | _strings(right)) & vocabulary
                    words |= _named(node.left, aliases) | _named(right, aliases)
            kind = "compare"
        elif isinstance(node, ast.Dict):
            words = set().union(set(), *(_strings(k) for k in node.keys if k is not None))
            words &= vocabulary
            kind = "dict"
        elif isinstance(node, ast.keyword) and node.arg == "choices":
            words, kind = _strings(node.value) & vocabulary, "choices"
        elif isinstance(node, ast.IfExp):
            words, kind = (_strings(node.body) | _strings(node.orelse)) & vocabulary, "if"
        if words:
            sites.append((node.lineno, owner.get(node, "<module>"), kind, words))
    return sites


def scanned_sites(root=ROOT):
    """Every switch site on a model name in the package outside the registry and the command
    line: ``[(file, line, function, kind, words)]``."""
    vocabulary = set(names()) | set(labels())
    sources = {path.relative_to(root).as_posix(): path.read_text()
               for folder in PACKAGE_FOLDERS for path in sorted((root / folder).rglob("*.py"))}
    aliases = set().union(*(_aliases(ast.parse(text), vocabulary) for text in sources.values()))
    return [(rel, line, function, kind, words)
            for rel, text in sources.items() if not rel.startswith(REGISTRY_AND_CLI)
            for line, function, kind, words in switch_sites(text, vocabulary, aliases)]


def model_name_switches(root=ROOT):
    """:func:`scanned_sites` less the words of :data:`NOT_SWITCHES`."""
    found = []
    for rel, line, function, kind, words in scanned_sites(root):
        words = {w for w in words if (rel, function, w) not in NOT_SWITCHES}
        if words:
            found.append((rel, line, function, kind, sorted(words)))
    return found


def test_the_scan_finds_each_kind_of_switch():
    """The scan sees a comparison, a membership test, an alias compared, a dict key,
    ``choices=`` and a conditional choice, and not a name merely passed on."""
    source = '''
EMPIRICAL = "forrestal-1994"
def f(model, label, base, p):
    if model == "paper" or label in ("derived-dynamic", "x"):
        pass
    styles = {"table": 1}
    p.add_argument("--m", choices=("law", "y"))
    size = 10 if base == EMPIRICAL else 7
    partner = "derived-dynamic" if base else "other"
    return make_resistance(model, "derived")
'''
    sites = switch_sites(source, set(names()) | set(labels()))
    assert sorted((line, kind) for line, _, kind, _ in sites) == [
        (2, "alias"), (4, "compare"), (4, "compare"), (6, "dict"), (7, "choices"),
        (8, "compare"), (9, "if")]


def test_no_other_code_compares_model_names():
    """Outside the registry (``analytic/models/``) and the command line's choices, no module
    decides on a model's name: what differs between models is declared by the model."""
    assert model_name_switches() == []


def test_every_word_listed_as_no_switch_is_still_there():
    """Each entry of :data:`NOT_SWITCHES` is a site the scan finds (no stale entry)."""
    found = {(rel, function, w) for rel, _, function, _, words in scanned_sites()
             for w in words}
    assert set(NOT_SWITCHES) <= found
