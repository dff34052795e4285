"""The striking conditions of one 3-D shot (:class:`Strike`), checked when made.

Kept apart from the model (:mod:`cavex.analytic.penetration.oblique`, which loads scipy and the
compiled kernels) so that ``cavex trajectory`` refuses bad striking conditions before it loads
the numerical libraries; ``oblique.Strike`` is the same class.
"""

import math
from dataclasses import dataclass

import numpy as np

from cavex.errors import require
from cavex.materials import MAX_VELOCITY


@dataclass(frozen=True)
class Strike:
    """Striking conditions of one shot (a measured test is
    :class:`cavex.verification.validation.shots.Shot`). Angles in degrees: ``obliquity``
    between the velocity and the target normal (+z; negative: the mirror shot, velocity toward
    -x), ``attack`` between the axis and the velocity, turned in the plane at ``attack_plane``
    about the velocity (0: in the plane of obliquity, nose toward the surface, +x, and -x for
    a negative obliquity, whose shot is the mirror image; 90: toward +y). ``spin`` (rad/s)
    about the axis. ``tip_depth``: initial nose-tip depth (m); None: the body's deepest point
    just touches the surface."""

    speed: float
    obliquity: float = 0.0
    attack: float = 0.0
    attack_plane: float = 0.0
    spin: float = 0.0
    tip_depth: float | None = None

    def __post_init__(self):
        require(math.isfinite(self.speed) and 0.0 < self.speed <= MAX_VELOCITY, "velocity",
                f"in (0, {MAX_VELOCITY:g}] m/s", self.speed)
        require(math.isfinite(self.obliquity) and abs(self.obliquity) < 90.0, "obliquity",
                "in (-90, 90) degrees", self.obliquity)
        require(math.isfinite(self.attack) and 0.0 <= self.attack < 90.0, "attack",
                "in [0, 90) degrees", self.attack)
        require(math.isfinite(self.attack_plane), "attack_plane", "finite (degrees)",
                self.attack_plane)
        require(math.isfinite(self.spin), "spin", "finite (rad/s)", self.spin)

    def initial_axes(self):
        """``(velocity direction, axis, body e2, body e3)`` in the target frame, for
        ``obliquity >= 0`` (:meth:`ObliqueModel.initial_state` builds a negative obliquity as
        the mirror image of the positive one)."""
        require(self.obliquity >= 0.0, "obliquity", ">= 0 here (mirror the shot)",
                self.obliquity)
        th = math.radians(self.obliquity)
        d = np.array([math.sin(th), 0.0, math.cos(th)])
        ep = np.array([math.cos(th), 0.0, -math.sin(th)])  # toward the surface
        ey = np.array([0.0, 1.0, 0.0])
        al, ps = math.radians(self.attack), math.radians(self.attack_plane)
        turn = math.cos(ps) * ep + math.sin(ps) * ey
        axis = math.cos(al) * d + math.sin(al) * turn
        e2 = math.cos(al) * turn - math.sin(al) * d  # unit, orthogonal to the axis
        # e2 stays in the plane of obliquity for in-plane shots, e3 = axis x e2
        e3 = np.cross(axis, e2)
        return d, axis, e2, e3
