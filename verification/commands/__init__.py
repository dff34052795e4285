"""One module per ``cavex`` command, each with ``run(args, target, projectile)``.

Imports: a command refuses bad input before it loads the numerical libraries. A command
module imports at its top only what its parser-side checks need (the standard library, numpy,
cavex's core, the resistance vocabulary ``analytic.penetration.labels``, the output helpers);
whatever loads scipy, numba, matplotlib, xarray, scikit-fem or dask is imported inside the
function that computes or draws, after the checks. ``penetrate``, ``trajectory``, ``stress``,
``fem`` and ``config`` do (``tests/test_interactive.py`` runs a bad input of each kind they
check and finds none of those libraries loaded); ``table``, ``verify``, ``batch``,
``calibrate`` and ``validate`` still check in modules that import them at the top
(``fedata.table``, ``fedata.batch``, ``validation.predict``, ``validation.calibration``;
benchmarks/commands.md).
"""
