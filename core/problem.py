"""The concentric spherical problem: layers, interface radii, wall velocity and cavity radius.

One type, checked once where it is built, for the closed forms (:mod:`cavex.analytic.cavity`)
and the FE solver (:mod:`cavex.fem`): a cavity of radius ``a`` expanding at ``V`` in layers
``layers[0]`` (at the wall) ... ``layers[-1]`` (semi-infinite), separated by the spheres of
radii ``interfaces`` (increasing, outside the cavity), optionally cut at a traction-free sphere
of radius ``free_radius``. The checks accept scalars or arrays (broadcast together) and raise
``CavexInputError`` naming the first bad parameter and its accepted range.
"""

import math
from dataclasses import dataclass

import numpy as np

from cavex.errors import require, require_choice
from cavex.materials import MAX_VELOCITY

#: The closed forms' yield-at-boundary conventions (docs/problem.md section 2).
BOUNDARIES = ("dynamic", "quasi-static")


@dataclass(frozen=True)
class SphericalProblem:
    """One checked concentric-layer problem (scalars): built once, then trusted."""

    layers: tuple
    interfaces: tuple
    velocity: float
    radius: float
    free_radius: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "layers", tuple(self.layers))
        object.__setattr__(self, "interfaces", tuple(float(h) for h in self.interfaces))
        object.__setattr__(self, "velocity", float(self.velocity))
        object.__setattr__(self, "radius", float(self.radius))
        check_problem(self.layers, self.interfaces, self.velocity, self.radius, "dynamic",
                      self.free_radius)

    def as_tuple(self):
        """``(layers, interfaces, velocity, radius)``, the FE solver's problem form."""
        return self.layers, self.interfaces, self.velocity, self.radius


def _first_bad(ok, value):
    """The first element of ``value`` where ``ok`` is False, as a Python scalar."""
    return np.broadcast_to(value, ok.shape)[~ok].flat[0].item()


def _refuse(ok, parameter, accepted, value, other=None):
    """Raise for the first element where ``ok`` is False; ``accepted`` may be a function of the
    matching element of ``other`` (broadcast with ``value``)."""
    ok = np.broadcast_to(ok, np.broadcast_shapes(np.shape(ok), np.shape(value),
                                                 np.shape(other)))
    if callable(accepted):
        accepted = accepted(_first_bad(ok, other))
    require(False, parameter, accepted, _first_bad(ok, value))


def arrays(interfaces, velocity, radius, free_radius):
    """Float arrays of the inputs (``free_radius`` None becomes ``inf``)."""
    return (np.asarray(interfaces, dtype=float), np.asarray(velocity, dtype=float),
            np.asarray(radius, dtype=float),
            np.asarray(np.inf if free_radius is None else free_radius, dtype=float))


def check_problem(layers, interfaces, velocity, radius, boundary, free_radius=None):
    """Validate a concentric-layer problem (scalars or arrays, see
    :func:`cavex.analytic.cavity.cavity_solution`);
    raise ``CavexInputError`` naming the parameter and its range."""
    check_arrays(layers, *arrays(interfaces, velocity, radius, free_radius), boundary)


def _holds(ok):
    """Whether a condition holds everywhere (a bool, or an array of them)."""
    return ok if type(ok) is bool else bool(np.all(ok))


def check_arrays(layers, interfaces, velocity, radius, free_radius, boundary):
    require(len(layers) >= 1, "layers", "at least one material", len(layers))
    count = interfaces.shape[-1] if interfaces.ndim else -1
    require(count == len(layers) - 1, "interfaces",
            f"of length len(layers) - 1 = {len(layers) - 1}", count)
    if interfaces.ndim == 1 and velocity.ndim == radius.ndim == free_radius.ndim == 0:
        # one point: the same conditions on Python floats (faster than on 0-d arrays)
        columns = interfaces.tolist()
        velocity, radius, free_radius = velocity.item(), radius.item(), free_radius.item()
    else:
        columns = [interfaces[..., i] for i in range(count)]
    # finite and in range, written so that NaN fails every comparison
    ok = (radius > 0.0) & (radius < math.inf)
    if not _holds(ok):
        _refuse(ok, "radius", "a finite number > 0", radius)
    ok = (velocity >= 0.0) & (velocity <= MAX_VELOCITY)
    if not _holds(ok):
        _refuse(ok, "velocity", f"in [0, {MAX_VELOCITY:g}] m/s", velocity)
    require_choice(boundary, BOUNDARIES, "boundary")
    previous = radius
    for i, h in enumerate(columns):
        ok = (h > previous) & (h < math.inf)
        if not _holds(ok):
            _refuse(ok, f"interfaces[{i}]",
                    lambda inner: f"finite and > {inner} (increasing, outside the cavity)",
                    h, previous)
        previous = h
    ok = free_radius > radius
    if not _holds(ok):
        _refuse(ok, "free_radius", lambda a: f"None or > radius = {a} (m, outside the cavity; "
                "layers beyond it are ignored)", free_radius, radius)
