"""Numerical settings of a cavity-expansion run, with their accepted ranges."""

from dataclasses import dataclass, fields, replace

from cavex.errors import CavexInputError, require, require_choice
from cavex.errors import is_finite_number as _finite

OUTER_BOUNDARIES = ("fixed", "free")


@dataclass(frozen=True)
class Numerics:
    """Discretisation and solver settings (all have defaults; see docs/fem.md for the study).

    Attributes
    ----------
    degree : {1, 2}
        Polynomial degree of the displacement (P1 or P2 Lagrange).
    elements_per_decade : float
        Elements per factor 10 in current radius (the final mesh is log-spaced), in [4, 2000].
    outer_ratio : float
        Outer boundary at ``outer_ratio`` times the final cavity radius (final configuration),
        in [100, 1e6] and beyond every interface that matters.
    seed_ratio : float
        Final over seed cavity radius ``a/a0``, in [5, 1e4].
    seed_radius : float or None
        Seed cavity radius ``a0`` (m), in (0, radius/5]; overrides ``seed_ratio`` when given.
    growth_per_step : float
        Relative growth of the cavity radius per time step, ``da/a``, in (0, 0.5].
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
        Relative Newton residual tolerance, in (0, 1e-6].
    max_cutbacks : int
        Step halvings allowed before a Newton failure is reported, in [0, 30].
    error_estimate : bool
        Also run at half resolution (space and time) and Richardson-estimate the error.
    snapshots : int
        Number of field snapshots kept for output (evenly spread over the steps), in
        [1, 10000].
    start_ramp : float
        Duration of a smooth velocity start, in units of ``a0/V``, in [0, 10] (0 = sudden
        start).

    The ranges are those in which a run is a meaningful discretisation of the cavity-expansion
    problem (measured, docs/fem.md "Accepted numerics"): below 4 elements per decade the wall
    stress errs by up to 2000 % (0.6 per decade: +1981 %, with a coarse-companion estimate of
    32 %); 4 per decade errs by <= 2.1 % on the layered default target. A run's coarse error
    companion must itself lie in these ranges (:meth:`can_coarsen`), otherwise the estimate
    comes from a 2x finer companion.
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
        """The same settings at ``1/factor`` of the space and time resolution, no estimate
        (raises ``CavexInputError`` where that leaves the accepted ranges)."""
        return replace(self, elements_per_decade=self.elements_per_decade / factor,
                       growth_per_step=self.growth_per_step * factor, error_estimate=False)

    def can_coarsen(self, factor=2.0):
        """Whether :meth:`coarsened` (``factor < 1``: refined) stays in the accepted ranges, a
        real and meaningful discretisation that an error estimate may rest on."""
        try:
            self.coarsened(factor)
        except CavexInputError:
            return False
        return True

    def as_dict(self):
        """The settings as a plain dict (every field is a scalar: ``dataclasses.asdict``'s deep
        copy is not needed, and costs a table run's workers ~2 % of their time)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


RANGES = {  # closed intervals of the numeric settings (growth_per_step excludes 0)
    "elements_per_decade": (4.0, 2000.0),
    "outer_ratio": (100.0, 1e6),
    "seed_ratio": (5.0, 1e4),
    "growth_per_step": (0.0, 0.5),
    "rho_inf": (0.0, 1.0),
    "newton_tol": (0.0, 1e-6),
    "max_cutbacks": (0, 30),
    "snapshots": (1, 10000),
    "start_ramp": (0.0, 10.0),
}


def _in(name, value, open_low=False):
    low, high = RANGES[name]
    ok = _finite(value) and (low < value if open_low else low <= value) and value <= high
    require(ok, name, f"in {'(' if open_low else '['}{low:g}, {high:g}]", value)


def _integer(name, value):
    low, high = RANGES[name]
    require(isinstance(value, int) and not isinstance(value, bool) and low <= value <= high,
            name, f"an integer in [{low}, {high}]", value)


def check_numerics(n):
    """Raise ``CavexInputError`` naming the first setting outside its accepted range."""
    require(n.degree in (1, 2) and not isinstance(n.degree, bool), "degree", "1 or 2", n.degree)
    _in("elements_per_decade", n.elements_per_decade)
    _in("outer_ratio", n.outer_ratio)
    _in("seed_ratio", n.seed_ratio)
    _in("growth_per_step", n.growth_per_step, open_low=True)
    _in("rho_inf", n.rho_inf)
    require(isinstance(n.dynamic, bool), "dynamic", "True or False", n.dynamic)
    require_choice(n.outer, OUTER_BOUNDARIES, "outer")
    require(_finite(n.dilatancy_deg) and 0 <= n.dilatancy_deg < 45, "dilatancy_deg",
            "in [0, 45)", n.dilatancy_deg)
    require(n.tension_cutoff is None or (_finite(n.tension_cutoff) and n.tension_cutoff > 0),
            "tension_cutoff", "None or a finite number > 0", n.tension_cutoff)
    _in("newton_tol", n.newton_tol, open_low=True)
    _integer("max_cutbacks", n.max_cutbacks)
    require(isinstance(n.error_estimate, bool), "error_estimate", "True or False",
            n.error_estimate)
    require(n.seed_radius is None or (_finite(n.seed_radius) and n.seed_radius > 0),
            "seed_radius", "None or a finite number > 0 and <= radius/5", n.seed_radius)
    _in("start_ramp", n.start_ramp)
    _integer("snapshots", n.snapshots)


def make_numerics(**overrides):
    """``Numerics`` from keyword overrides; unknown names are input errors."""
    known = {f.name for f in fields(Numerics)}
    for name in overrides:
        require(name in known, name, "one of " + ", ".join(sorted(known)), "unknown setting")
    return Numerics(**overrides)


def check_seed_radius(numerics, radius):
    """Raise ``CavexInputError`` unless the seed cavity fits a problem of cavity radius
    ``radius``: ``seed_radius`` (when given) at most ``radius / 5`` (the smallest
    ``seed_ratio``)."""
    require(numerics.seed_radius is None or numerics.seed_radius <= radius / 5.0,
            "seed_radius", f"in (0, radius/5 = {radius / 5.0:g}]", numerics.seed_radius)
