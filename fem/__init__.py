"""Spherically symmetric Lagrangian elastoplastic finite-element solver (scikit-fem, numba).

One solver (:class:`cavex.fem.solver.RadialSolver`) runs every computation on a stack of cases;
public entry points: :func:`expand_cavities` (many problems), :func:`expand_cavity` (one
problem, with its history and fields recorded) and :func:`write_result`.

Layout, one idea per module: ``mesh`` (graded radial meshes), ``discretisation`` (bases,
quadrature, mass), ``material_records`` (a layer packed into the kernels' material record: the
one place), ``records`` (the named records the kernels take), ``constitutive`` (the compiled
point kernel: Hencky/Mohr-Coulomb return map), ``element`` (the compiled element kernel: force
and tangent), ``stack`` (cases concatenated,
block-banded solve), ``newton`` (per-case Newton, line search), ``solver`` (stepping, cut-backs,
observers), ``estimate`` (error companion and refinement policies), ``expansion`` (the problems
and the public API), ``fields``/``output`` (post-processing, ParaView files).

The names below are imported on first use (PEP 562), as in :mod:`cavex.analytic`, so that
importing a plain submodule (``settings``, ``estimate``: what the commands check their input
with) does not load scikit-fem, numba or scipy.
"""

from cavex.lazy import lazy_names

#: public name -> the submodule that defines it
_WHERE = {"expand_cavities": "expansion", "expand_cavity": "expansion",
          "write_result": "output", "ExpansionResult": "result", "Numerics": "settings"}

__all__ = sorted(_WHERE)
__getattr__, __dir__ = lazy_names(__name__, _WHERE)
