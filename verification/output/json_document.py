"""The JSON documents the commands write or print (``--json``, trajectory's ``summary.json``,
validate's ``validation.json``): each opens with ``cavex_version``, the version of the cavex
that wrote it (:data:`cavex.__version__`), so that a result names what made it."""

import json

from cavex import __version__

VERSION_KEY = "cavex_version"


def versioned(document):
    """``document`` (a dict) with ``cavex_version`` as its first key (replacing one it has)."""
    return {VERSION_KEY: __version__, **{k: v for k, v in document.items() if k != VERSION_KEY}}


def json_text(document, indent=2):
    """:func:`versioned` ``document`` as JSON text, ``indent`` spaces a level."""
    return json.dumps(versioned(document), indent=indent)
