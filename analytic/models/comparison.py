"""The closed forms flown beside the FE table on one target (the analytic-against-FE report's
trajectories, ``cavex verify``): every label of every model that is ``compared_with_fe`` (the
derived quasi-static and dynamic, the paper's, the FE table), in the registry's order."""

from cavex.analytic.models.registry import models
from cavex.analytic.penetration.integrator import penetrate
from cavex.analytic.penetration.tabulated import read_table, trajectory_summary


def comparison_runs(target, projectile, table, crater="nose-base"):
    """The trajectories :func:`compare_trajectories` summarises: ``{label: Trajectory}``; each
    model's 1-D resistance with the boundary convention of its label and the FE table
    ``table`` (a Dataset or a table file)."""
    if not hasattr(table, "attrs"):
        table = read_table(table)
    resistances = {label: model.resistance(target, projectile, boundary=boundary, table=table)
                   for model in models(compared_with_fe=True)
                   for label, boundary in model.variants()}
    return {label: penetrate(target, projectile, r, crater=crater)
            for label, r in resistances.items()}


def compare_trajectories(target, projectile, table, crater="nose-base"):
    """Closed forms (derived quasi-static and dynamic, paper) against the FE table.

    Parameters
    ----------
    target, projectile : Target, Projectile
    table : xarray.Dataset or str or path
        The FE table (a path is loaded).
    crater : {"nose-base", "nose-tip"}

    Returns
    -------
    dict
        Keyed by model label (``derived-quasi-static``, ``derived-dynamic``, ``paper``,
        ``table``): ``phases`` (label, end depth, velocity, time, reason),
        ``final_depth_m``, ``final_time_s`` and ``at_H1`` (velocity and time when the nose tip
        reaches ``H1``: the residual velocity after the concrete; None if it stops before).
    """
    return {name: trajectory_summary(run, target)
            for name, run in comparison_runs(target, projectile, table, crater).items()}
