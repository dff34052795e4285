"""One module per ``cavex`` command; :data:`cavex.verification.cli.COMMANDS` lists them.

The shape of a command module (``cli`` calls only these):

- ``HELP``: the one line ``cavex --help`` lists it with (and its own ``--help`` opens with);
- ``add_arguments(parser)``: adds the command's own options to its subparser (the options
  several commands share: :mod:`~cavex.verification.commands.options`, the resistance, and
  :mod:`~cavex.verification.commands.shared_options`, ``--config``, the execution options,
  ``--figures``);
- ``run(args, target, projectile) -> result``: checks the parsed options (``target`` and
  ``projectile``: the ``--config`` file's, None for a command without one), computes through
  the module's job function (``penetration_job``, ``trajectory_job``, ``stress_at_depth``, else
  ``job``: plain arguments, the Python API), writes the files (every file or none) and returns
  the result, with the paths written under ``outputs`` where it writes files;
- ``summary(result) -> dict``: what ``--json`` prints (every command with ``--json``);
- ``text(result) -> str``: what is printed without ``--json``;
- ``write_outputs(result, out[, draw=True]) -> [path]``: the files of a command that writes
  some (``penetrate``, ``trajectory``, ``validate``, ``table``, ``calibrate``) into ``out``
  (their folder, or the file for ``table`` and ``calibrate``), the figures only with ``draw``
  (drawn by :mod:`cavex.verification.report`'s ``penetration_figures``, ``trajectory_figures``,
  ``validation_figures``; ``validate``'s report.md by ``validation_markdown``).

Imports: a command refuses bad input before it loads the numerical libraries. A command
module imports at its top only what its parser-side checks need (the standard library, numpy,
cavex's core, the model registry ``analytic.models``, the output helpers,
the ``report`` modules of its figures and markdown, which load matplotlib only in the functions
that draw); whatever loads scipy, numba, matplotlib, xarray, scikit-fem or dask is imported
inside the function that computes or draws, after the checks; the modules the checks live in
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
