"""Cavity expansions: a spherical cavity driven at constant velocity from a seed radius.

The cavity wall (reference radius ``a0 = radius / seed_ratio``) moves outwards at ``velocity``
until the cavity radius is ``radius``; the material starts at rest and unstressed. Time steps
grow with the cavity (``da = growth_per_step * a``), so every step is a fixed fraction of the
self-similar process. With ``velocity = 0`` the run is quasi-static.

:func:`expand_problems` runs any number of such problems (each a checked
:class:`cavex.problem.SphericalProblem`) with shared numerical settings (a checked
:class:`cavex.fem.settings.Numerics`) on the one solver (:class:`cavex.fem.solver.RadialSolver`,
stacks of ``batch_size`` cases); :func:`expand_cavities` builds and checks both from plain
values first, and :func:`expand_cavity` is the same on one problem, recording its history and
fields through observers of the run. The error-estimate companion and the refinement of cases
above an error target are policies of :mod:`cavex.fem.estimate`, applied here to every problem
alike.
"""

import dataclasses
import math
import time

import numpy as np

from cavex.errors import CavexInputError, CavexNumericalError, require
from cavex.fem.discretisation import Discretisation
from cavex.fem.estimate import estimate_errors, refine_above
from cavex.fem.fields import cauchy_stresses, current_point_radii, plastic_radius, wall_stress
from cavex.fem.mesh import element_layers, reference_mesh
from cavex.fem.result import ExpansionResult
from cavex.fem.settings import check_seed_radius, make_numerics
from cavex.fem.solver import RadialSolver
from cavex.problem import SphericalProblem

DEFAULT_BATCH = 200     # cases per stack (measured optimum on a 2-core machine: 100-400)
ON_ERROR = ("return", "raise")
MODEL_CACHE = 1024      # discretisations kept per process (a table has 2-3 per depth)
_MODELS = {}            # (layers, interfaces, radius, numerics) -> (Discretisation, vertices)


# ---------------------------------------------------------------------------------- problem set-up
def radius_schedule(radius, seed_radius, growth_per_step):
    """Cavity radii of the step ends, geometric from ``seed_radius`` to ``radius``."""
    n = max(1, math.ceil(math.log(radius / seed_radius) / math.log1p(growth_per_step) - 1e-9))
    return seed_radius * (radius / seed_radius) ** (np.arange(1, n + 1) / n)


def seed_radius(radius, numerics):
    """Seed cavity radius ``a0`` (m) of the settings."""
    if numerics.seed_radius is not None:
        return numerics.seed_radius
    return radius / numerics.seed_ratio


def outer_radius(radius, interfaces, numerics):
    """Outer boundary (final configuration): ``outer_ratio * radius``, and >= 3x every interface."""
    return max(numerics.outer_ratio * radius, 3.0 * max(interfaces, default=0.0))


def wall_times(radii, seed, velocity, ramp):
    """Times at which the wall reaches ``radii`` (m).

    Constant velocity ``V`` from rest position ``seed``; with ``ramp > 0`` the wall velocity
    first rises smoothly, ``V sin^2(pi t / (2 t_r))`` over ``t_r = ramp * seed / V``, so that
    the seed's start does not launch a pressure pulse (a(t) = a0 + V (t/2 - t_r sin(pi t/t_r)
    / (2 pi)) during the ramp, then ``V`` constant).
    """
    if ramp == 0:
        return (np.asarray(radii) - seed) / velocity
    t_r = ramp * seed / velocity
    t = np.linspace(0.0, t_r, 2001)
    a_ramp = seed + velocity * (t / 2 - t_r * np.sin(np.pi * t / t_r) / (2 * np.pi))
    a_end = a_ramp[-1]
    radii = np.asarray(radii)
    return np.where(radii <= a_end, np.interp(radii, a_ramp, t),
                    t_r + (radii - a_end) / velocity)


def build_model(layers, interfaces, radius, numerics):
    """Discretisation of the problem and the mesh vertex index of every interface inside it
    (cached per process: a table reuses one model for every velocity)."""
    key = (tuple(layers), tuple(interfaces), radius, numerics)
    if key not in _MODELS:
        if len(_MODELS) >= MODEL_CACHE:
            _MODELS.clear()
        mesh, vertices = reference_mesh(radius, seed_radius(radius, numerics), interfaces,
                                        outer_radius(radius, interfaces, numerics),
                                        numerics.elements_per_decade)
        disc = Discretisation(mesh, numerics.degree, element_layers(mesh, vertices), layers,
                              numerics.dilatancy_deg, numerics.tension_cutoff)
        _MODELS[key] = (disc, vertices)
    return _MODELS[key]


def is_dynamic(velocity, numerics):
    return numerics.dynamic and velocity > 0.0


# ---------------------------------------------------------------------------------- observers
class Recorder:
    """Observer of one case: the step history and evenly spread field snapshots."""

    def __init__(self, case, n_steps, snapshots, dynamic):
        self.case = case
        self.dynamic = dynamic
        self.keep = set(np.linspace(0, n_steps - 1, min(snapshots, n_steps)).astype(int))
        self.history = None
        self.snapshots = []

    def start(self, solver):
        one = solver.case(self.case)
        a0 = float(one.disc.R_dofs[0])
        self.history = {"time": [0.0], "radius": [a0], "wall_stress": [0.0],
                        "plastic_radius": [a0]}

    def __call__(self, solver, case, step):
        if case != self.case:
            return
        one = solver.case(case)
        disc = one.disc
        self.history["time"].append(one.t if self.dynamic else 0.0)
        self.history["radius"].append(float(disc.R_dofs[0] + one.u[0]))
        self.history["wall_stress"].append(wall_stress(disc, one.u, one.wall_force))
        self.history["plastic_radius"].append(plastic_radius(disc, one.u, one.response,
                                                             one.state))
        if step in self.keep:
            sigma_r, sigma_t = cauchy_stresses(disc, one.u, one.response)
            self.snapshots.append({"time": one.t, "u": one.u[::disc.degree].copy(),
                                   "sigma_r": sigma_r.mean(axis=1),
                                   "sigma_theta": sigma_t.mean(axis=1),
                                   "plastic_strain": one.state["eq_p"].mean(axis=1),
                                   "layer": disc.element_layer.copy()})


# ---------------------------------------------------------------------------------- thin wall layer
#: A wall layer whose shell around the cavity is thinner than this fraction of the cavity
#: radius is not resolved: the mesh gives it one element, which the expansion from the seed
#: must compress radially by a factor of 100-400, and the estimate (refining every element by
#: the same ratio) cannot see it. Measured on Table 1's two wall-layer switches (docs/fem.md
#: "Thin wall layer"): quasi-static runs fail (Newton) at shells up to 1.6e-3 of the radius;
#: at 1000 m/s the wall stress is off the thicker shells' trend by 0.4-3 % below 2.4e-5
#: (estimates 0.4-1.2 %), and at 1000-1200 m/s the plastic radius by 2-17x below 8e-5.
THIN_SHELL = 3e-3
#: A wall-layer shell thinner than this fraction of the radius is the rounding of a depth at a
#: switch (the table's switch node is 1e-9 m past it): the layer is gone, the next one is the
#: wall's (the wall stress is continuous there).
GONE_SHELL = 1e-7


def wall_shell(problem):
    """Thickness (m) of the wall layer's shell around the cavity (inf: a single layer)."""
    return problem.interfaces[0] - problem.radius if problem.interfaces else math.inf


def without_gone_shells(problem):
    """``problem`` without the wall layers thinner than :data:`GONE_SHELL` of the radius, and
    how many were left out."""
    gone = 0
    while wall_shell(problem) <= GONE_SHELL * problem.radius:
        problem = SphericalProblem(problem.layers[1:], problem.interfaces[1:], problem.velocity,
                                   problem.radius)
        gone += 1
    return problem, gone


def unresolved(problem, numerics):
    """The failed result of a problem whose wall layer is thinner than :data:`THIN_SHELL`."""
    shell = wall_shell(problem)
    error = CavexNumericalError(
        f"the wall layer is a shell of {shell:.3g} m around the cavity, thinner than the FE "
        f"resolves ({THIN_SHELL:g} of the cavity radius, {THIN_SHELL * problem.radius:.3g} m; "
        "docs/fem.md 'Thin wall layer'): take a depth where that layer is gone (the wall "
        "stress is continuous there) or one where its shell is thicker")
    stats = {"elements": 0, "dofs": 0, **{name: 0 for name in RUN_COUNTS}, "seconds": 0.0,
             "refinements": 0}
    return ExpansionResult(math.nan, None, math.nan, (), run_settings(problem, numerics),
                           stats=stats, error=error)


#: the counts of one run that a result's ``stats`` carries (:class:`RadialSolver`'s per case)
RUN_COUNTS = ("steps", "newton_iterations", "cutbacks", "line_search_steps",
              "residual_evaluations")


def run_settings(problem, numerics):
    """Everything that reproduces a run of ``problem`` at ``numerics`` (a result's
    ``settings``)."""
    return {"layers": [{f.name: getattr(m, f.name) for f in dataclasses.fields(m)}
                       for m in problem.layers],
            "interfaces": [float(h) for h in problem.interfaces],
            "velocity": float(problem.velocity), "radius": float(problem.radius),
            "numerics": numerics.as_dict()}


# ---------------------------------------------------------------------------------- runs
def run_problems(problems, numerics, batch_size=DEFAULT_BATCH, record=False):
    """One run of every problem (:class:`~cavex.problem.SphericalProblem`) at ``numerics`` (no
    error estimate): stacks of ``batch_size`` cases, dynamic and quasi-static ones apart. A
    wall layer thinner than :data:`GONE_SHELL` of the radius is left out (its interface ends
    at the wall), one thinner than :data:`THIN_SHELL` fails without a run (:func:`unresolved`).
    Returns a list of :class:`ExpansionResult`."""
    out = [None] * len(problems)
    runs = {}  # index -> (the problem run, wall layers left out)
    for i, problem in enumerate(problems):
        kept, gone = without_gone_shells(problem)
        if wall_shell(kept) < THIN_SHELL * kept.radius:
            out[i] = unresolved(kept, numerics)
        else:
            runs[i] = (kept, gone)
    for dynamic in (True, False):
        group = [i for i, (p, _) in runs.items() if is_dynamic(p.velocity, numerics) == dynamic]
        for start in range(0, len(group), batch_size):
            chunk = group[start:start + batch_size]
            for i, result in zip(chunk, _run_stack([runs[i][0] for i in chunk], numerics,
                                                   dynamic, record), strict=True):
                gone = runs[i][1]
                out[i] = result if not gone or not result.ok else dataclasses.replace(
                    result, interfaces_final=(problems[i].radius,) * gone
                    + tuple(result.interfaces_final))
    return out


def _run_stack(problems, numerics, dynamic, record):
    started = time.perf_counter()
    models = [build_model(p.layers, p.interfaces, p.radius, numerics) for p in problems]
    velocity = np.array([p.velocity for p in problems])
    solver = RadialSolver([m[0] for m in models], dynamic=dynamic, rho_inf=numerics.rho_inf,
                          outer=numerics.outer, newton_tol=numerics.newton_tol,
                          max_cutbacks=numerics.max_cutbacks,
                          wall_velocity=velocity if dynamic and numerics.start_ramp == 0
                          else 0.0)
    seeds = [float(m[0].R_dofs[0]) for m in models]
    radii = [radius_schedule(p.radius, s, numerics.growth_per_step)
             for p, s in zip(problems, seeds, strict=True)]
    times = ([wall_times(r, s, v, numerics.start_ramp)
              for r, s, v in zip(radii, seeds, velocity, strict=True)] if dynamic else None)
    recorders = [Recorder(c, len(r), numerics.snapshots, dynamic)
                 for c, r in enumerate(radii)] if record else []
    for recorder in recorders:
        recorder.start(solver)

    def describe(c, step):
        return f"V = {velocity[c]:g} m/s, step to cavity radius {radii[c][step]:.6g} m"

    errors = solver.run([r - s for r, s in zip(radii, seeds, strict=True)], times,
                        observers=recorders, describe=describe)
    seconds = time.perf_counter() - started
    return [_result(solver, c, problems[c], models[c][1], numerics, errors[c], seconds,
                    recorders[c] if record else None) for c in range(len(problems))]


def _result(solver, c, problem, vertices, numerics, error, seconds, recorder):
    one = solver.case(c)
    disc = one.disc
    settings = run_settings(problem, numerics)
    stats = {"elements": disc.n_elements, "dofs": disc.ndof,
             **{name: getattr(one, name) for name in RUN_COUNTS},
             "seconds": seconds, "refinements": 0}
    if error is not None:
        return ExpansionResult(math.nan, None, math.nan, (), settings, stats=stats, error=error)
    r_nodes = disc.R_dofs + one.u
    fields = {"u": one.u.copy(), "r_nodes": r_nodes, "R_nodes": disc.R_dofs.copy()}
    energy = {"work": one.work, "kinetic": solver.kinetic_energy(c),
              "stored": solver.stored_energy(c), "dissipated": one.dissipated}
    history = None
    if recorder is not None:
        sigma_r, sigma_t = cauchy_stresses(disc, one.u, one.response)
        fields.update(r=current_point_radii(disc, one.u).ravel(), sigma_r=sigma_r.ravel(),
                      sigma_theta=sigma_t.ravel(), plastic_strain=one.state["eq_p"].ravel(),
                      layer=disc.point_layer.ravel(), snapshots=recorder.snapshots)
        history = {k: np.asarray(v) for k, v in recorder.history.items()}
    return ExpansionResult(
        cavity_stress=float(wall_stress(disc, one.u, one.wall_force)), error_estimate=None,
        plastic_radius=plastic_radius(disc, one.u, one.response, one.state),
        interfaces_final=tuple(float(r_nodes[disc.degree * v]) for v in vertices),
        settings=settings, fields=fields, history=history, energy=energy, stats=stats)


# ---------------------------------------------------------------------------------- public API
def _problem(i, problem):
    """The :class:`~cavex.problem.SphericalProblem` of one entry (built and checked here, or
    given)."""
    if isinstance(problem, SphericalProblem):
        return problem
    if isinstance(problem, dict):
        unknown = set(problem) - {"layers", "interfaces", "velocity", "radius"}
        require(not unknown, f"problems[{i}]", "a dict with keys layers, interfaces, velocity, "
                "radius", sorted(unknown))
        problem = (problem.get("layers"), problem.get("interfaces", ()),
                   problem.get("velocity"), problem.get("radius"))
    require(isinstance(problem, (tuple, list)) and len(problem) == 4, f"problems[{i}]",
            "(layers, interfaces, velocity, radius) or a dict of those", problem)
    layers, interfaces, velocity, radius = problem
    try:
        require(isinstance(velocity, (int, float)) and not isinstance(velocity, bool),
                "velocity", "a number", velocity)
        require(isinstance(radius, (int, float)) and not isinstance(radius, bool),
                "radius", "a number", radius)
        return SphericalProblem(tuple(layers), interfaces, velocity, radius)
    except (CavexInputError, TypeError) as exc:
        raise CavexInputError(f"problems[{i}]: {exc}") from None


def expand_cavities(problems, *, batch_size=DEFAULT_BATCH, on_error="return", error_target=None,
                    max_refinements=2, record=False, **numerics):
    """Expand many spherical cavities with shared settings on the one FE solver.

    Parameters
    ----------
    problems : sequence
        Each ``(layers, interfaces, velocity, radius)`` (or a dict with those keys):
        ``layers[0]`` surrounds the cavity, the last extends to the outer boundary;
        ``interfaces`` are radii (m) in the current configuration at the final radius, as for
        :func:`cavex.analytic.cavity.cavity_stress`; ``velocity`` the constant wall velocity
        (m/s, >= 0; 0 is quasi-static); ``radius`` the final cavity radius (m).
    batch_size : int
        Cases advanced together in one stack (memory grows linearly with it), >= 1.
    on_error : {"return", "raise"}
        A case whose Newton iteration fails after the cut-backs and the line search comes back
        with ``error`` set (the others are unaffected), or, with ``"raise"``, the first such
        error is raised after the whole list has run.
    error_target : float, optional
        With the error estimate on, a case whose estimate exceeds this relative error is run
        again at twice the space and time resolution, up to ``max_refinements`` times
        (:func:`cavex.fem.estimate.refine_above`). None: every case at the given settings.
    max_refinements : int
        See ``error_target``, >= 0.
    record : bool
        Also keep every case's history, final point fields and snapshots (observers of the run).
    **numerics
        Fields of :class:`cavex.fem.settings.Numerics`, shared by all cases.

    Returns
    -------
    list of ExpansionResult
        In the order of ``problems``.

    Raises
    ------
    CavexInputError
        A bad problem (the message names its index and the parameter) or bad numerics.
    CavexNumericalError
        With ``on_error="raise"``, when some case failed.
    """
    settings = make_numerics(**numerics)
    return expand_problems([_problem(i, p) for i, p in enumerate(problems)], settings,
                           batch_size=batch_size, on_error=on_error, error_target=error_target,
                           max_refinements=max_refinements, record=record)


def expand_problems(problems, numerics, *, batch_size=DEFAULT_BATCH, on_error="return",
                    error_target=None, max_refinements=2, record=False):
    """:func:`expand_cavities` on problems and settings already built (and so checked): a list
    of :class:`~cavex.problem.SphericalProblem` and one :class:`~cavex.fem.settings.Numerics`.
    Only what depends on both (the seed radius, :func:`~cavex.fem.settings.check_seed_radius`)
    and the options are checked here."""
    require(isinstance(batch_size, int) and not isinstance(batch_size, bool) and batch_size >= 1,
            "batch_size", "an integer >= 1", batch_size)
    require(on_error in ON_ERROR, "on_error", " or ".join(map(repr, ON_ERROR)), on_error)
    for i, problem in enumerate(problems):
        try:
            check_seed_radius(numerics, problem.radius)
        except CavexInputError as exc:
            raise CavexInputError(f"problems[{i}]: {exc}") from None
    require(error_target is None or (isinstance(error_target, float) and 0 < error_target < 1),
            "error_target", "None or a float in (0, 1)", error_target)
    require(isinstance(max_refinements, int) and not isinstance(max_refinements, bool)
            and max_refinements >= 0, "max_refinements", "an integer >= 0", max_refinements)

    def run(subset, numerics):
        return run_problems(subset, numerics, batch_size, record)

    def run_estimated(subset, numerics, known=None):
        results = run(subset, numerics)
        if numerics.error_estimate:
            estimate_errors(subset, results, numerics,
                            lambda p, n: run_problems(p, n, batch_size), known)
        return results

    results = run_estimated(problems, numerics)
    if error_target is not None and numerics.error_estimate:
        refine_above(problems, results, numerics, error_target, max_refinements,
                     run_estimated)
    if on_error == "raise":
        for r in results:
            if r.error is not None:
                raise r.error
    return results


def expand_cavity(layers, interfaces, velocity, radius, **numerics):
    """Expand one spherical cavity at constant velocity: :func:`expand_cavities` on one problem
    with its history and fields recorded.

    Parameters
    ----------
    layers, interfaces, velocity, radius
        One problem, as in :func:`expand_cavities`.
    **numerics
        Fields of :class:`cavex.fem.settings.Numerics`, and ``error_target`` /
        ``max_refinements`` of :func:`expand_cavities`.

    Returns
    -------
    ExpansionResult

    Raises
    ------
    CavexInputError
        Bad problem or numerics (the message names the parameter and its range).
    CavexNumericalError
        Newton failed even after step cut-backs and the line search (the message names V, the
        step and the wall radius).
    """
    problem = SphericalProblem(tuple(layers), interfaces, velocity, radius)
    options = {k: numerics.pop(k) for k in ("error_target", "max_refinements") if k in numerics}
    settings = make_numerics(**numerics)
    try:
        result, = expand_problems([problem], settings, on_error="raise", record=True, **options)
    except CavexInputError as exc:  # one problem: its index says nothing
        raise CavexInputError(str(exc).removeprefix("problems[0]: ")) from None
    return result
