"""One module per ``cavex`` command, each with ``run(args, target, projectile)``.

Imports: a command refuses bad input before it loads the numerical libraries. A command
module imports at its top only what its parser-side checks need (the standard library, numpy,
cavex's core, the resistance vocabulary ``analytic.penetration.labels``, the output helpers);
whatever loads scipy, numba, matplotlib, xarray, scikit-fem or dask is imported inside the
function that computes or draws, after the checks. ``tests/test_interactive.py`` runs a bad
input of every command and checks that none of them was loaded.
"""
