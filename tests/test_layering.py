"""The house stays layered: every import of every package module (function-level ones included,
read from the source with ``ast``) runs down or sideways within its floor, never up.

Floors, bottom to top (README "Where things are"):

- ``core/`` (``cavex``): errors, input files, materials, config, the spherical problem, lazy
  package names, the netCDF-3 format; imports no other part of cavex;
- ``analytic/`` and ``fem/`` side by side, each on ``core/`` only; inside ``analytic/`` the
  closed forms (``cavity``, ``paper_model``, ``geometry``, ``concrete_cavity``,
  ``empirical``) sit below the penetration feature (``analytic/penetration/``), and the model
  registry (``analytic/models/``: one module a model) above both;
- ``verification/``: ``output/`` (file formats) at the bottom, then ``fedata/`` (FE data
  production), then ``validation/`` (which uses ``fedata/``), then ``report/`` (the reports'
  words and figures, which may use ``validation/``: the validation's figures and markdown) and
  ``studies/`` (which may use ``validation/``: a study of the validation data), which do not
  use each other, then ``commands/`` (one module per command), then ``cli``;
- on top, beside ``cli``: ``cavex.api`` (``core/api.py``, the Python API in xarray and pandas
  over the commands' job functions and figure panels), which nothing in cavex imports.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = {"core": "cavex", "analytic": "cavex.analytic", "fem": "cavex.fem",
           "verification": "cavex.verification"}
CORE = ("cavex.__init__", "cavex.errors", "cavex.input_files", "cavex.materials", "cavex.config",
        "cavex.problem", "cavex.lazy", "cavex.netcdf3", "cavex.concrete",
        "cavex.concrete_confinement")
#: analytic's floors below the model registry: the closed forms, then the penetration feature
CLOSED_FORMS = ("cavex.analytic.cavity", "cavex.analytic.geometry", "cavex.analytic.paper_model",
                "cavex.analytic.concrete_cavity", "cavex.analytic.empirical",
                "cavex.analytic.states")
V = "cavex.verification."

# module prefix -> prefixes it may import (the first matching rule, longest prefix first)
ALLOWED = {
    "cavex.analytic.__init__": CORE + ("cavex.analytic",),  # the floor's public API
    # the registry of models: one module a model, above the code it runs
    "cavex.analytic.models": CORE + ("cavex.analytic",),
    "cavex.analytic.penetration": CORE + CLOSED_FORMS + ("cavex.analytic.penetration",),
    "cavex.analytic": CORE + CLOSED_FORMS,
    "cavex.fem": CORE + ("cavex.fem",),
    V + "output": CORE + (V + "output",),
    V + "fedata": CORE + ("cavex.analytic", "cavex.fem", V + "output", V + "fedata"),
    V + "report": CORE + ("cavex.analytic", "cavex.fem", V + "output", V + "fedata",
                          V + "validation", V + "report"),
    V + "validation": CORE + ("cavex.analytic", "cavex.fem", V + "output", V + "fedata",
                              V + "validation"),
    V + "studies": CORE + ("cavex.analytic", "cavex.fem", V + "output", V + "fedata",
                           V + "validation", V + "studies"),
    V + "commands": CORE + ("cavex.analytic", "cavex.fem", V + "output", V + "fedata",
                            V + "report", V + "validation", V + "studies", V + "commands"),
    V + "cli": ("cavex",),
    # the Python API: the commands' jobs and the reports' panels, on the top floor with cli
    "cavex.api": CORE + ("cavex.analytic", "cavex.fem", V + "output", V + "fedata",
                         V + "report", V + "validation", V + "studies", V + "commands"),
    "cavex.__main__": (V + "cli",),  # `python -m cavex`: the command line, nothing else
    "cavex": CORE,
}


def package_modules():
    """``(module name, path)`` of every module of the package, from the folders it maps."""
    for folder, package in FOLDERS.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            parts = path.relative_to(ROOT / folder).with_suffix("").parts
            yield ".".join((package, *parts)), path


def cavex_imports(module, path):
    """Every cavex module ``module`` imports (``from cavex.x import y`` names ``cavex.x.y`` when
    ``y`` is a module, else ``cavex.x``; the package ``cavex`` itself stands for its
    ``__init__``)."""
    modules = {name for name, _ in package_modules()}
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = module.split(".")[:-node.level]
                base = ".".join(parent + ([node.module] if node.module else []))
            if base != "cavex" and not base.startswith("cavex."):
                continue
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                found.add(sub if sub in modules or f"{sub}.__init__" in modules else base)
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names
                      if a.name == "cavex" or a.name.startswith("cavex.")}
    return {"cavex.__init__" if name == "cavex" else name for name in found}


def rule(module):
    """The ALLOWED entry of ``module``: the longest prefix that matches it."""
    matches = [p for p in ALLOWED if module == p or module.startswith(p + ".")]
    return max(matches, key=len)


def permitted(target, prefixes):
    return any(target == p or target.startswith(p + ".") for p in prefixes)


MODULES = list(package_modules())


def test_the_walk_sees_the_whole_package():
    names = {name for name, _ in MODULES}
    assert {"cavex.config", "cavex.problem", "cavex.analytic.cavity", "cavex.fem.expansion",
            "cavex.analytic.penetration.integrator", "cavex.verification.cli",
            "cavex.verification.commands.penetrate"} <= names
    assert len(names) > 60


@pytest.mark.parametrize(("module", "path"), MODULES, ids=[m for m, _ in MODULES])
def test_no_import_runs_upward(module, path):
    prefixes = ALLOWED[rule(module)]
    upward = sorted(t for t in cavex_imports(module, path) if not permitted(t, prefixes))
    assert not upward, f"{module} imports {upward}"


def test_nothing_imports_the_api():
    """``cavex.api`` is the top floor: no module of the package imports it."""
    importers = sorted(module for module, path in MODULES
                       if module != "cavex.api" and "cavex.api" in cavex_imports(module, path))
    assert importers == []


def test_the_rule_catches_an_upward_import(tmp_path):
    """The checker itself: a core module that reaches into verification is caught."""
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from cavex.verification.fedata import table\n")
    prefixes = ALLOWED[rule("cavex.config")]
    assert not all(permitted(t, prefixes) for t in cavex_imports("cavex.config", bad))


def import_graph(modules=MODULES):
    """module -> the cavex modules it imports (function-level imports included)."""
    return {module: cavex_imports(module, path) for module, path in modules}


def import_circles(graph):
    """The strongly connected components of ``graph`` with more than one module (or a module
    that imports itself): every import circle (Tarjan's algorithm, iterative)."""
    index, low, on_stack, stack, circles, counter = {}, {}, set(), [], [], [0]
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph.get(root, ()))))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1 or node in graph.get(node, ()):
                        circles.append(sorted(component))
                continue
            if child not in graph:
                continue
            if child not in index:
                index[child] = low[child] = counter[0]
                counter[0] += 1
                stack.append(child)
                on_stack.add(child)
                work.append((child, iter(sorted(graph[child]))))
            elif child in on_stack:
                low[node] = min(low[node], index[child])
    return circles


def test_no_import_circle():
    """No module reaches itself through imports, function-level ones included (a lazy import
    hides a circle from the interpreter, not from this walk)."""
    assert import_circles(import_graph()) == []


def test_the_walk_finds_a_circle():
    """The checker itself: a -> b -> c -> a and d -> d are circles, e -> a is not."""
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"d"}, "e": {"a"}}
    assert sorted(import_circles(graph)) == [["a", "b", "c"], ["d"]]


def test_every_package_folder_is_installed():
    """Every folder of the package with an ``__init__.py`` is listed in pyproject.toml's
    ``packages`` (a plain ``pip install .`` installs only those: an unlisted folder works in an
    editable install and fails on a user's)."""
    import tomllib

    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
                 ["packages"])
    folders = {name.removesuffix(".__init__") for name, _ in MODULES
               if name.endswith(".__init__")}
    assert folders - {"cavex"} <= listed and "cavex" in listed, folders - listed
