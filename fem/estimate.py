r"""Error estimate and refinement policies, the same for every run of :mod:`cavex.fem`.

*Companion.* The discretisation error of a run's wall stress ``S_h`` is estimated by
Richardson extrapolation from a companion run at half the space and time resolution
(``elements_per_decade / 2``, ``growth_per_step * 2``), assuming second order (measured,
docs/fem.md):

.. math:: e(S_h) = \frac{|S_h - S_{2h}|}{2^2 - 1}\,/\,|S_h| .

Where that coarser run would leave the accepted numerics (:meth:`cavex.fem.settings.Numerics.
can_coarsen`: it would not be a meaningful discretisation, so it cannot certify anything) or
fails numerically (a Newton failure that survives the cut-backs and the line search), a 2x finer
companion is used instead, ``S_h - S_{h/2} = C h^p (1 - 2^{-p})``, so

.. math:: e(S_h) = |S_h - S_{h/2}|\,\frac{2^p}{2^p - 1}\,/\,|S_h| ,

which over- rather than under-estimates.

*Refinement.* With an error target, every case whose estimate exceeds it is run again at twice
the space and time resolution (its estimate then comes from that run's own companion), up to a
number of refinements; cases at or below the target keep their first run.
"""

from dataclasses import replace

DEFAULT_ERROR_TARGET = 0.005  # what the commands promise for every FE cell (0.5 %)
MAX_REFINEMENTS = 2           # ... reached by at most this many doublings of the resolution
ORDER = 2.0        # observed convergence order of the wall stress (docs/fem.md)
REFINEMENT = 2.0   # resolution ratio of a companion run


def richardson_error(fine, coarse, order=ORDER, refinement=REFINEMENT):
    """Relative error of ``fine`` estimated from ``coarse`` (``refinement``-times coarser)."""
    return abs(fine - coarse) / (refinement ** order - 1.0) / abs(fine)


def richardson_error_from_finer(result, finer, order=ORDER, refinement=REFINEMENT):
    """Relative error of ``result`` from a ``refinement``-times finer run."""
    q = refinement ** order
    return abs(result - finer) * q / (q - 1.0) / abs(result)


def estimate_errors(problems, results, numerics, run, known=None):
    """Set ``error_estimate`` and the companion's ``stats`` on every successful result.

    ``run(problems, numerics)`` runs problems without estimates (a list of results). A case
    whose companions both fail gets the companion's error; where neither companion is in the
    accepted numerics (a run at the finest settings accepted), the estimate stays None.
    ``known`` (optional, per problem): a successful run at ``numerics.coarsened()`` already
    made (the run a refinement starts from, :func:`refine_above`), used as the coarse
    companion instead of running it again (the same bits: a case computes the same alone and
    in any stack); None where there is none.
    """
    known = [None] * len(problems) if known is None else known
    todo = [i for i, r in enumerate(results) if r.ok]
    if numerics.can_coarsen():
        missing = [i for i in todo if known[i] is None]
        ran = dict(zip(missing, run([problems[i] for i in missing], numerics.coarsened())
                       if missing else [], strict=True))
        coarse = [known[i] if known[i] is not None else ran[i] for i in todo]
    else:
        coarse = [None] * len(todo)
    retry = [i for i, c in zip(todo, coarse, strict=True) if c is None or not c.ok]
    if not numerics.can_coarsen(0.5):
        retry = []
    finer = dict(zip(retry, run([problems[i] for i in retry], numerics.coarsened(0.5)),
                     strict=True))
    for i, c in zip(todo, coarse, strict=True):
        if i not in finer and (c is None or not c.ok):
            results[i].stats["error_companion"] = None
            continue
        kind, companion = ("coarse", c) if c is not None and c.ok else ("finer", finer[i])
        result = results[i]
        result.stats[f"{kind}_cavity_stress"] = companion.cavity_stress
        result.stats["error_companion"] = kind
        if companion is not known[i]:  # a known companion cost nothing here
            result.stats["seconds"] += companion.stats["seconds"]
        if not companion.ok:
            result.error = companion.error
            result.cavity_stress = result.plastic_radius = float("nan")
        elif kind == "coarse":
            result.error_estimate = richardson_error(result.cavity_stress, c.cavity_stress)
        else:
            result.error_estimate = richardson_error_from_finer(result.cavity_stress,
                                                                companion.cavity_stress)


def refined(numerics, factor=REFINEMENT):
    """The settings at ``factor`` times the space and time resolution."""
    return replace(numerics, elements_per_decade=factor * numerics.elements_per_decade,
                   growth_per_step=numerics.growth_per_step / factor)


def refine_above(problems, results, numerics, target, max_refinements, run_estimated):
    """Re-run (in place in ``results``) the cases estimated above ``target`` at twice the
    resolution, up to ``max_refinements`` times; ``stats["refinements"]`` counts them.

    ``run_estimated(problems, numerics, known)`` runs with error estimates; ``known`` are the
    runs being refined, which are the refined runs' coarse companions (the refined settings
    coarsened are the settings refined, to the bit: the factors are powers of 2)."""
    for refinement in range(1, max_refinements + 1):
        redo = [i for i, r in enumerate(results) if r.ok and r.error_estimate is not None
                and r.error_estimate > target]
        if not redo or not numerics.can_coarsen(1.0 / REFINEMENT):
            return
        previous, numerics = numerics, refined(numerics)
        companions = numerics.coarsened() == replace(previous, error_estimate=False)
        known = [results[i] for i in redo] if companions else None
        for i, r in zip(redo, run_estimated([problems[i] for i in redo], numerics, known),
                        strict=True):
            r.stats["refinements"] = refinement
            results[i] = r
