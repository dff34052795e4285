"""Spherically symmetric Lagrangian elastoplastic finite-element solver (scikit-fem).

Public entry points: :func:`expand_cavity` (one case), :func:`expand_cavities` (many cases in
one batched assembly), :func:`write_result`, :func:`compare_at_depth`.
"""

from cavex.fem.batch import expand_cavities
from cavex.fem.compare import compare_at_depth
from cavex.fem.expansion import expand_cavity
from cavex.fem.output import write_result
from cavex.fem.result import ExpansionResult
from cavex.fem.settings import Numerics

__all__ = ["ExpansionResult", "Numerics", "compare_at_depth", "expand_cavities", "expand_cavity",
           "write_result"]
