"""``expand_cavity``: a spherical cavity driven at constant velocity from a seed radius.

The cavity wall (reference radius ``a0 = radius / seed_ratio``) moves outwards at ``velocity``
until the cavity radius is ``radius``; the material starts at rest and unstressed. Time steps
grow with the cavity (``da = growth_per_step * a``), so every step is a fixed fraction of the
self-similar process. With ``velocity = 0`` the run is quasi-static.
"""

import math
import time
from dataclasses import asdict

import numpy as np
from cavex.analytic.cavity import check_problem
from cavex.fem.discretisation import Discretisation
from cavex.fem.fields import cauchy_stresses, current_point_radii, plastic_radius, wall_stress
from cavex.fem.mesh import element_layers, reference_mesh
from cavex.fem.result import ExpansionResult
from cavex.fem.settings import make_numerics
from cavex.fem.solver import RadialSolver

from cavex.errors import CavexNumericalError, require


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
    """Reference mesh and discretisation of the problem; also the interface vertex indices."""
    mesh, iface_vertices = reference_mesh(radius, seed_radius(radius, numerics), interfaces,
                                          outer_radius(radius, interfaces, numerics),
                                          numerics.elements_per_decade)
    disc = Discretisation(mesh, numerics.degree, element_layers(mesh, iface_vertices), layers,
                          numerics.dilatancy_deg, numerics.tension_cutoff)
    return disc, iface_vertices


def run_expansion(layers, interfaces, velocity, radius, numerics):
    """One run at the given settings; returns the result without an error estimate."""
    started = time.perf_counter()
    disc, iface_vertices = build_model(layers, interfaces, radius, numerics)
    dynamic = numerics.dynamic and velocity > 0.0
    solver = RadialSolver(disc, dynamic=dynamic, rho_inf=numerics.rho_inf, outer=numerics.outer,
                          assembly=numerics.assembly, newton_tol=numerics.newton_tol,
                          max_cutbacks=numerics.max_cutbacks,
                          wall_velocity=velocity if dynamic and numerics.start_ramp == 0 else 0.0)
    seed = disc.R_dofs[0]
    radii = radius_schedule(radius, seed, numerics.growth_per_step)
    times = wall_times(radii, seed, velocity, numerics.start_ramp) if dynamic else None
    history = {"time": [0.0], "radius": [seed], "wall_stress": [0.0], "plastic_radius": [seed]}
    keep = set(np.linspace(0, len(radii) - 1, min(numerics.snapshots, len(radii))).astype(int))
    snapshots = []
    for step, a in enumerate(radii):
        dt = times[step] - solver.t if dynamic else 1.0
        try:
            solver.advance(a - seed, dt)
        except CavexNumericalError as exc:
            raise CavexNumericalError(f"V = {velocity:g} m/s, step to cavity radius {a:.6g} m: "
                                      f"{exc}") from None
        history["time"].append(solver.t if dynamic else 0.0)
        history["radius"].append(a)
        history["wall_stress"].append(wall_stress(disc, solver.u, solver.wall_force))
        history["plastic_radius"].append(plastic_radius(disc, solver.u, solver.response,
                                                        solver.state))
        if step in keep:
            snapshots.append(snapshot(disc, solver))
    sigma_r, sigma_t = cauchy_stresses(disc, solver.u, solver.response)
    r_nodes = disc.R_dofs + solver.u
    fields = {"r": current_point_radii(disc, solver.u).ravel(), "sigma_r": sigma_r.ravel(),
              "sigma_theta": sigma_t.ravel(), "plastic_strain": solver.state["eq_p"].ravel(),
              "layer": disc.point_layer.ravel(), "r_nodes": r_nodes, "R_nodes": disc.R_dofs.copy(),
              "u": solver.u.copy(), "snapshots": snapshots}
    ends = tuple(float(r_nodes[disc.degree * v]) for v in iface_vertices)
    settings = {"layers": [asdict(m) for m in layers], "interfaces": [float(h) for h in interfaces],
                "velocity": float(velocity), "radius": float(radius),
                "numerics": numerics.as_dict()}
    energy = {"work": solver.work, "kinetic": solver.kinetic_energy(),
              "stored": solver.stored_energy(), "dissipated": solver.dissipated}
    stats = {"elements": disc.n_elements, "dofs": disc.ndof, "steps": solver.steps,
             "newton_iterations": solver.newton_iterations, "cutbacks": solver.cutbacks,
             "seconds": time.perf_counter() - started}
    return ExpansionResult(cavity_stress=float(history["wall_stress"][-1]),
                           history={k: np.asarray(v) for k, v in history.items()},
                           fields=fields, error_estimate=None,
                           plastic_radius=float(history["plastic_radius"][-1]),
                           interfaces_final=ends, settings=settings, energy=energy, stats=stats)


def snapshot(disc, solver):
    """Element-averaged fields and nodal displacement of the current state (for output)."""
    sigma_r, sigma_t = cauchy_stresses(disc, solver.u, solver.response)
    return {"time": solver.t, "u": solver.u[::disc.degree].copy(),
            "sigma_r": sigma_r.mean(axis=1), "sigma_theta": sigma_t.mean(axis=1),
            "plastic_strain": solver.state["eq_p"].mean(axis=1)}


def richardson_error(fine, coarse, order=2.0, refinement=2.0):
    """Relative error of ``fine`` estimated from ``coarse`` (``refinement``-times coarser)."""
    return abs(fine - coarse) / (refinement ** order - 1.0) / abs(fine)


def richardson_error_from_finer(result, finer, order=2.0, refinement=2.0):
    """Relative error of ``result`` from a ``refinement``-times finer run:
    ``S_h - S_{h/q} = C h^p (1 - q^-p)``, so ``err(S_h) = |S_h - S_{h/q}| q^p / (q^p - 1)``."""
    q = refinement ** order
    return abs(result - finer) * q / (q - 1.0) / abs(result)


def companion_estimate(layers, interfaces, velocity, radius, settings, result):
    """Richardson error estimate of ``result`` and the companion run it came from.

    The companion is the 2x coarser run (space and time); where that one fails numerically
    (a Newton failure that survives the cut-backs and the last-resort line search), a 2x finer
    run is used instead, which over- rather than under-estimates.
    """
    try:
        coarse = run_expansion(layers, interfaces, velocity, radius, settings.coarsened())
        return richardson_error(result.cavity_stress, coarse.cavity_stress), coarse, "coarse"
    except CavexNumericalError:
        finer = run_expansion(layers, interfaces, velocity, radius, settings.coarsened(0.5))
        return (richardson_error_from_finer(result.cavity_stress, finer.cavity_stress), finer,
                "finer")


def expand_cavity(layers, interfaces, velocity, radius, **numerics):
    """Expand a spherical cavity at constant velocity and return the FE solution.

    Parameters
    ----------
    layers : sequence of Material
        ``layers[0]`` surrounds the cavity; the last extends to the outer boundary.
    interfaces : sequence of float
        Interface radii (m) in the current configuration at the final radius, as for
        :func:`cavex.analytic.cavity.cavity_stress`.
    velocity : float
        Constant cavity-wall velocity ``V`` (m/s), >= 0 (0: quasi-static).
    radius : float
        Final cavity radius ``a`` (m).
    **numerics
        Fields of :class:`cavex.fem.settings.Numerics`.

    Returns
    -------
    ExpansionResult

    Raises
    ------
    CavexInputError
        Bad problem or numerics (the message names the parameter and its range).
    CavexNumericalError
        Newton failed even after step cut-backs (the message names V, the step and the radius).
    """
    layers = list(layers)
    interfaces = [float(h) for h in interfaces]
    check_problem(layers, interfaces, float(velocity), float(radius), "dynamic")
    settings = make_numerics(**numerics)
    require(settings.seed_radius is None or settings.seed_radius < radius, "seed_radius",
            f"in (0, radius = {radius})", settings.seed_radius)
    result = run_expansion(layers, interfaces, float(velocity), float(radius), settings)
    if settings.error_estimate:
        estimate, companion, kind = companion_estimate(layers, interfaces, float(velocity),
                                                       float(radius), settings, result)
        result.error_estimate = estimate
        result.stats[f"{kind}_cavity_stress"] = companion.cavity_stress
        result.stats["error_companion"] = kind
        result.stats["seconds"] += companion.stats["seconds"]
    return result
