"""Public names of a package imported from its submodules on first use (PEP 562), so that
importing one plain submodule does not load what the others need (numba, scipy, scikit-fem)."""

import importlib
import sys


def lazy_names(package, where):
    """``(__getattr__, __dir__)`` for the module ``package`` (its ``__name__``) whose public
    names are defined in its submodules, ``where`` mapping each name to the submodule's
    relative path; a name is imported on first use and then kept in the package."""

    def __getattr__(name):
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{where[name]}"), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__():
        return sorted([*vars(sys.modules[package]), *where])

    return __getattr__, __dir__
