"""Numerical settings of a cavity-expansion run, with their accepted ranges."""

from dataclasses import asdict, dataclass, fields, replace

from cavex.errors import is_finite_number as _finite
from cavex.errors import require, require_choice

OUTER_BOUNDARIES = ("fixed", "free")


@dataclass(frozen=True)
class Numerics:
    """Discretisation and solver settings (all have defaults; see docs/fem.md for the study).

    Attributes
    ----------
    degree : {1, 2}
        Polynomial degree of the displacement (P1 or P2 Lagrange).
    elements_per_decade : float
        Elements per factor 10 in current radius (the final mesh is log-spaced), > 0.
    outer_ratio : float
        Outer boundary at ``outer_ratio`` times the final cavity radius (final configuration),
        > 1 and beyond every interface that matters.
    seed_ratio : float
        Final over seed cavity radius ``a/a0``, > 1.
    seed_radius : float or None
        Seed cavity radius ``a0`` (m), in (0, radius); overrides ``seed_ratio`` when given.
    growth_per_step : float
        Relative growth of the cavity radius per time step, ``da/a``, in (0, 1].
    rho_inf : float
        Generalized-alpha spectral radius at infinite frequency, in [0, 1].
    dynamic : bool
        Inertia on (True) or quasi-static load stepping (False).
    outer : {"fixed", "free"}
        Outer boundary condition.
    dilatancy_deg : float
        Dilatancy angle (degrees), in [0, 45); 0 is volume-preserving plastic flow.
    tension_cutoff : float or None
        Tensile strength (Pa) > 0; None puts the cut-off through the Mohr-Coulomb apex.
    newton_tol : float
        Relative Newton residual tolerance, in (0, 1e-3].
    max_cutbacks : int
        Step halvings allowed before a Newton failure is reported, >= 0.
    error_estimate : bool
        Also run at half resolution (space and time) and Richardson-estimate the error.
    snapshots : int
        Number of field snapshots kept for output (evenly spread over the steps), >= 1.
    start_ramp : float
        Duration of a smooth velocity start, in units of ``a0/V`` (>= 0; 0 = sudden start).
    """

    degree: int = 2
    elements_per_decade: float = 30.0
    outer_ratio: float = 1000.0
    seed_ratio: float = 20.0
    seed_radius: float | None = None
    growth_per_step: float = 0.03
    rho_inf: float = 0.0
    dynamic: bool = True
    outer: str = "fixed"
    dilatancy_deg: float = 0.0
    tension_cutoff: float | None = None
    newton_tol: float = 1e-8
    max_cutbacks: int = 10
    error_estimate: bool = True
    snapshots: int = 20
    start_ramp: float = 0.0

    def __post_init__(self):
        check_numerics(self)

    def coarsened(self, factor=2.0):
        """The same settings at ``1/factor`` of the space and time resolution, no estimate."""
        return replace(self, elements_per_decade=self.elements_per_decade / factor,
                       growth_per_step=min(1.0, self.growth_per_step * factor),
                       error_estimate=False)

    def as_dict(self):
        return asdict(self)


def check_numerics(n):
    """Raise ``CavexInputError`` naming the first setting outside its accepted range."""
    require(n.degree in (1, 2) and not isinstance(n.degree, bool), "degree", "1 or 2", n.degree)
    require(_finite(n.elements_per_decade) and n.elements_per_decade > 0,
            "elements_per_decade", "a finite number > 0", n.elements_per_decade)
    require(_finite(n.outer_ratio) and n.outer_ratio > 1, "outer_ratio", "a finite number > 1",
            n.outer_ratio)
    require(_finite(n.seed_ratio) and n.seed_ratio > 1, "seed_ratio",
            "a finite number > 1 (seed radius a0 = radius/seed_ratio < radius)", n.seed_ratio)
    require(_finite(n.growth_per_step) and 0 < n.growth_per_step <= 1, "growth_per_step",
            "in (0, 1]", n.growth_per_step)
    require(_finite(n.rho_inf) and 0 <= n.rho_inf <= 1, "rho_inf", "in [0, 1]", n.rho_inf)
    require(isinstance(n.dynamic, bool), "dynamic", "True or False", n.dynamic)
    require_choice(n.outer, OUTER_BOUNDARIES, "outer")
    require(_finite(n.dilatancy_deg) and 0 <= n.dilatancy_deg < 45, "dilatancy_deg",
            "in [0, 45)", n.dilatancy_deg)
    require(n.tension_cutoff is None or (_finite(n.tension_cutoff) and n.tension_cutoff > 0),
            "tension_cutoff", "None or a finite number > 0", n.tension_cutoff)
    require(_finite(n.newton_tol) and 0 < n.newton_tol <= 1e-3, "newton_tol", "in (0, 1e-3]",
            n.newton_tol)
    require(isinstance(n.max_cutbacks, int) and not isinstance(n.max_cutbacks, bool)
            and n.max_cutbacks >= 0, "max_cutbacks", "an integer >= 0", n.max_cutbacks)
    require(isinstance(n.error_estimate, bool), "error_estimate", "True or False",
            n.error_estimate)
    require(n.seed_radius is None or (_finite(n.seed_radius) and n.seed_radius > 0),
            "seed_radius", "None or a finite number > 0 and < radius", n.seed_radius)
    require(_finite(n.start_ramp) and n.start_ramp >= 0, "start_ramp", "a finite number >= 0",
            n.start_ramp)
    require(isinstance(n.snapshots, int) and not isinstance(n.snapshots, bool)
            and n.snapshots >= 1, "snapshots", "an integer >= 1", n.snapshots)


def make_numerics(**overrides):
    """``Numerics`` from keyword overrides; unknown names are input errors."""
    known = {f.name for f in fields(Numerics)}
    for name in overrides:
        require(name in known, name, "one of " + ", ".join(sorted(known)), "unknown setting")
    return Numerics(**overrides)
