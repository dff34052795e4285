"""The package imports from its installed location with every part mapped under ``cavex``."""

import cavex.analytic
import cavex.fem
import cavex.verification


def test_parts_import_under_cavex():
    assert cavex.analytic.cavity_stress.__module__ == "cavex.analytic.cavity"
    assert cavex.fem.__name__ == "cavex.fem"
    assert cavex.verification.__name__ == "cavex.verification"
