"""Spherically symmetric Lagrangian elastoplastic finite-element solver (scikit-fem, numba).

One solver (:class:`cavex.fem.solver.RadialSolver`) runs every computation on a stack of cases;
public entry points: :func:`expand_cavities` (many problems), :func:`expand_cavity` (one
problem, with its history and fields recorded) and :func:`write_result`.

Layout, one idea per module: ``mesh`` (graded radial meshes), ``discretisation`` (bases,
quadrature, mass), ``constitutive`` (the compiled point kernel: Hencky/Mohr-Coulomb return map),
``element`` (the compiled element kernel: force and tangent), ``stack`` (cases concatenated,
block-banded solve), ``newton`` (per-case Newton, line search), ``solver`` (stepping, cut-backs,
observers), ``estimate`` (error companion and refinement policies), ``expansion`` (the problems
and the public API), ``fields``/``output`` (post-processing, ParaView files).
"""

from cavex.fem.expansion import expand_cavities, expand_cavity
from cavex.fem.output import write_result
from cavex.fem.result import ExpansionResult
from cavex.fem.settings import Numerics

__all__ = ["ExpansionResult", "Numerics", "expand_cavities", "expand_cavity", "write_result"]
