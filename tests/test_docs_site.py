"""The documentation site (mkdocs.yml, README "Documentation") builds in strict mode: a broken
link or anchor, a docstring mkdocstrings cannot read, a notebook cell that raises, each fails it.

The build runs as the README gives it, ``mkdocs build --strict``, into a temporary folder and
from another working directory; it executes every ``docs/notebooks/*.ipynb``. Measured
2026-11-27 with the getting-started notebook alone, this module in one process with an empty
numba cache: 11.6 s CPU (the notebook's kernel and numba's compilation included), 45 s wall at
load average 16.
"""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
# a mkdocs log line at warning level or above (the kernel's own "[IPKernelApp] WARNING" about
# its local TCP transport is not one)
MKDOCS_WARNING = re.compile(r"^(WARNING|ERROR)\s+-", re.M)


def mkdocs_build(config, site, cwd):
    """``mkdocs build --strict`` of ``config`` into ``site``: (exit code, its log)."""
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config), "-d", str(site)],
        cwd=cwd, env=env, capture_output=True, text=True, timeout=900)
    return done.returncode, done.stdout + done.stderr


def docs_files():
    return {p for p in DOCS.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    folder = tmp_path_factory.mktemp("docs-site")
    before = docs_files()
    code, log = mkdocs_build(ROOT / "mkdocs.yml", folder / "site", cwd=folder)
    assert code == 0 and not MKDOCS_WARNING.search(log), log
    # the notebooks run in docs/notebooks/: what they write goes to scratch folders, not there
    assert docs_files() == before, sorted(map(str, docs_files() - before))
    return folder / "site"


def test_every_page_is_built(site):
    pages = [p.relative_to(DOCS).with_suffix(".html") for p in DOCS.rglob("*.md")
             if "_hooks" not in p.parts]
    assert pages and all((site / page).is_file() for page in pages)
    # nothing was left in the checkout (mkdocs-jupyter's cache is off)
    assert not (ROOT / ".cache" / "mkdocs-jupyter").exists()


def test_every_notebook_is_executed_and_in_the_nav(site):
    home = (site / "index.html").read_text(encoding="utf-8")
    notebooks = sorted((DOCS / "notebooks").glob("*.ipynb"))
    assert notebooks
    for notebook in notebooks:
        page = site / "notebooks" / f"{notebook.stem}.html"
        html = page.read_text(encoding="utf-8")
        assert f'href="notebooks/{notebook.stem}.html"' in home
        # every code cell has run, in order: each input prompt carries its execution count
        cells = json.loads(notebook.read_text(encoding="utf-8"))["cells"]
        code_cells = sum(cell["cell_type"] == "code" for cell in cells)
        counts = [int(n) for n in re.findall(r"In(?:\s|&nbsp;)*\[(\d+)\]:", html)]
        assert counts == list(range(1, code_cells + 1)), notebook.name


def test_the_getting_started_notebook_shows_its_computed_depths(site):
    html = (site / "notebooks" / "getting_started.html").read_text(encoding="utf-8")
    depths = re.findall(r"(derived|paper) +stops at (\d+\.\d+) m", html)
    assert [name for name, _ in depths] == ["derived", "paper"]
    assert all(float(depth) > 0 for _, depth in depths)
    assert "<img" in html  # the velocity-depth figure


def test_the_api_reference_is_rendered_from_the_docstrings(site):
    models = (site / "reference" / "models.html").read_text(encoding="utf-8")
    for name in ("make_resistance", "make_law", "fly", "register"):
        assert f'id="cavex.analytic.models.{name}"' in models or \
            f'id="cavex.analytic.models.registry.{name}"' in models, name
    commands = (site / "reference" / "commands.html").read_text(encoding="utf-8")
    for command in ("penetrate", "trajectory", "stress", "fem", "table", "verify", "batch",
                    "calibrate", "validate", "config"):
        assert f'id="cavex.verification.commands.{command}.run"' in commands, command
    # the docstrings' reStructuredText is read as Markdown: no role is left, equations are
    # handed to MathJax (docs/_hooks/griffe_roles.py)
    penetration = (site / "reference" / "penetration.html").read_text(encoding="utf-8")
    assert ":func:" not in penetration and ".. math::" not in penetration
    assert 'class="arithmatex"' in penetration


def test_the_equations_render_offline(site):
    """MathJax is copied into the site, and every page loads it from there, not from a CDN."""
    assert (site / "assets" / "mathjax" / "tex-svg.js").is_file()
    for page in (site / "index.html", site / "reference" / "penetration.html"):
        html = page.read_text(encoding="utf-8")
        assert 'src="assets/mathjax/tex-svg.js"' in html or \
            'src="../assets/mathjax/tex-svg.js"' in html


def test_a_broken_link_fails_the_strict_build(tmp_path):
    """The project's ``validation`` settings make a link to a missing page, or to a missing
    heading of a page, a warning, which strict mode turns into a failed build."""
    import yaml

    settings = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "other.md").write_text("# Other\n\n## A heading\n")
    for link, complaint in (("missing.md", "missing.md"), ("other.md#no-such-heading",
                                                           "no-such-heading")):
        (docs / "index.md").write_text(f"# Home\n\n[a link]({link}) [fine](other.md#a-heading)\n")
        config = tmp_path / "mkdocs.yml"
        config.write_text(yaml.safe_dump({"site_name": "t", "docs_dir": str(docs),
                                          "validation": settings["validation"]}))
        code, log = mkdocs_build(config, tmp_path / "site", cwd=tmp_path)
        assert code != 0 and complaint in log, log
