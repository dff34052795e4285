"""mkdocs hooks of the documentation site (mkdocs.yml ``hooks``).

- ``on_config``: the nav's "Notebooks" section gets every ``docs/notebooks/*.ipynb``, sorted by
  file name, so that a new notebook needs no edit of mkdocs.yml (its title is its first
  ``# heading``); the section is dropped when there is none.
- ``on_config`` also shows griffe (mkdocstrings' reader of the source) the package as it is
  laid out when installed: the checkout has no ``cavex/`` folder (``core/`` is ``cavex``,
  ``analytic/`` is ``cavex.analytic``..., pyproject.toml's ``package-dir``), so a folder of
  symbolic links in a temporary directory, put first in ``sys.path``, makes that layout from
  the checkout's own files, the same for an installed and an editable cavex.
  It also takes the scripts folder (``bin/``) out of ``sys.path``: run as the ``mkdocs``
  program, Python puts it first, and griffe would find the ``cavex`` console script there.
- ``on_post_build``: MathJax (the ``django-static-mathjax`` package, a docs dependency) copied
  into ``site/assets/mathjax``, its SVG output: the site renders its equations offline, with
  no CDN and no web font to load.
"""

import os
import shutil
import sys
import sysconfig
import tempfile
import tomllib
from pathlib import Path

from mkdocs.plugins import event_priority

NOTEBOOKS_SECTION = "Notebooks"
# the SVG output: its glyphs are paths in the page, so no web font has to load
MATHJAX_FILES = ("tex-svg.js", "input/tex/extensions")


def notebook_pages(docs_dir):
    """The notebooks under ``docs_dir/notebooks`` as nav entries (paths relative to docs)."""
    folder = Path(docs_dir) / "notebooks"
    return [f"notebooks/{path.name}" for path in sorted(folder.glob("*.ipynb"))]


REPOSITORY = Path(__file__).resolve().parents[2]
_layout = {}


def package_layout(repository):
    """A temporary folder holding ``cavex/`` as installed, made of links to ``repository``'s
    folders (pyproject.toml's ``[tool.setuptools.package-dir]``)."""
    with open(repository / "pyproject.toml", "rb") as file:
        package_dir = tomllib.load(file)["tool"]["setuptools"]["package-dir"]
    root = Path(tempfile.mkdtemp(prefix="cavex-docs-"))
    for package, folder in sorted(package_dir.items(), key=lambda item: item[0].count(".")):
        where = root.joinpath(*package.split("."))
        if "." in package:
            where.symlink_to(repository / folder, target_is_directory=True)
            continue
        where.mkdir()
        for entry in (repository / folder).iterdir():
            if entry.name != "__pycache__":
                (where / entry.name).symlink_to(entry)
    return root


def drop_scripts_folder():
    """``sys.path`` without the scripts folder that holds the ``cavex`` program."""
    scripts = os.path.realpath(sysconfig.get_path("scripts"))
    sys.path[:] = [path for path in sys.path if os.path.realpath(path or ".") != scripts]


@event_priority(100)  # before mkdocstrings makes its Python handler (and its search paths)
def on_config(config):
    drop_scripts_folder()
    if "root" not in _layout:
        _layout["root"] = package_layout(REPOSITORY)
        sys.path.insert(0, str(_layout["root"]))
    pages = notebook_pages(config.docs_dir)
    nav = []
    for entry in config.nav:
        if isinstance(entry, dict) and NOTEBOOKS_SECTION in entry:
            if pages:
                nav.append({NOTEBOOKS_SECTION: pages})
        else:
            nav.append(entry)
    config.nav = nav
    return config


def on_shutdown():
    root = _layout.pop("root", None)
    if root is not None:
        sys.path[:] = [path for path in sys.path if path != str(root)]
        shutil.rmtree(root, ignore_errors=True)


def mathjax_folder():
    """The ``es5`` folder of the installed MathJax 3 package."""
    import mathjax

    return Path(mathjax.__file__).parent / "static" / "mathjax" / "es5"


def on_post_build(config):
    source = mathjax_folder()
    target = Path(config.site_dir) / "assets" / "mathjax"
    for name in MATHJAX_FILES:
        if (source / name).is_dir():
            shutil.copytree(source / name, target / name, dirs_exist_ok=True)
        else:
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source / name, target / name)
