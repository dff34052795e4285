"""One module per ``cavex`` command, each with ``run(args, target, projectile)``.

Imports: a command refuses bad input before it loads the numerical libraries. A command
module imports at its top only what its parser-side checks need (the standard library, numpy,
cavex's core, the model registry ``analytic.models``, the output helpers);
whatever loads scipy, numba, matplotlib, xarray, scikit-fem or dask is imported inside the
function that computes or draws, after the checks; the modules the checks live in
(``fedata.table``, ``fedata.batch``, ``fedata.cases``, ``validation.predict``,
``validation.calibration``, ``validation.shots``, ``cavex.fem.settings``) follow the same rule.
Every command does, for the checks it makes before it computes: ``penetrate``, ``trajectory``,
``stress``, ``fem``, ``config``, ``table``, ``verify``, ``batch``, ``calibrate`` and
``validate`` (``tests/test_interactive.py`` runs a bad input of each kind they check, finds
none of those libraries, nor pandas, loaded and nothing written; the times:
benchmarks/commands.md). Not before: a plain law's coefficients (``--law-A -5 --law-B 1``),
checked by the law itself once numba has loaded, and what only computing finds (a
calibration that leaves the models' range).
"""
