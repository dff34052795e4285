"""Materials, layered targets and projectiles (SI units, compression positive)."""

import math
from dataclasses import dataclass, field, fields
from functools import cached_property
from itertools import accumulate

from cavex.errors import is_finite_number, require, require_name

#: Largest velocity accepted (m/s), striking or expansion: far beyond it (hypervelocity impact)
#: a rigid projectile and an elastic-plastic cavity expansion no longer describe the target.
MAX_VELOCITY = 1e4


def _positive(name, value):
    require(is_finite_number(value) and math.isfinite(value) and value > 0,
            name, "a finite number > 0", value)


def _exactly_one(first, second, values):
    given = [v is not None for v in values]
    require(any(given), first, f"given (or {second} given)", None)
    require(not all(given), second, f"omitted when {first} is given (one or the other)",
            values[1])


@dataclass(frozen=True)
class Material:
    """Incompressible-idealised elastic-perfectly plastic Mohr-Coulomb material.

    Yield in the paper's form ``sigma_r - sigma_theta = lam * sigma + tau`` with
    ``tau = (3 - lam) sigma_c / 3`` (docs/problem.md section 1).

    Parameters
    ----------
    E : float
        Young's modulus (Pa), > 0.
    nu : float
        Poisson's ratio in (-1, 0.5); used by the FE solver (the analytic model is incompressible).
    rho : float
        Density (kg/m^3), > 0.
    lam : float
        Pressure sensitivity lambda in [0, 3); 0 is Tresca.
    tau : float, optional
        Shear strength intercept (Pa), > 0. Derived from ``sigma_c`` when omitted; if both are
        given they must agree (``dataclasses.replace`` keeps both).
    name : str, optional
    sigma_c : float, optional
        Unconfined compressive strength (Pa), > 0, from which ``tau`` is derived.
    tau_max : float, optional
        Tresca cap (Pa) on the strength: ``sigma_r - sigma_theta <= min(lam sigma + tau,
        tau_max)``; at least the uniaxial compressive strength ``3 tau/(3 - lam)``. None (the
        default): no cap. Used by the FE only (docs/fem.md "Concrete").
    tensile_strength : float, optional
        Tension cut-off (Pa) on the least compressive principal stress, ``sigma_3 >=
        -tensile_strength``, in (0, 3 tau/(3 - lam)]; None (the default): the FE's
        ``tension_cutoff`` setting (through the cone's apex unless set). FE only.
    crush_pressure, lock_pressure, lock_strain, locked_modulus : float, optional
        The compaction hydrostat (Holmquist, Johnson and Cook 1993; :data:`HYDROSTAT`),
        given all four or none (None, the default: the linear elastic bulk ``K``). In the FE's
        measures, the log volumetric strain ``e = -ln J`` and the Kirchhoff pressure ``P``
        (compression positive): elastic ``P = K e`` up to ``crush_pressure`` (Pa, > 0),
        compaction linear to ``lock_pressure`` (Pa, > ``crush_pressure``) at ``lock_strain``
        (> ``lock_pressure/K``, so that compaction is softer than ``K``; < 1), then locked,
        ``P = lock_pressure + locked_modulus (e - lock_strain)`` (``locked_modulus`` in Pa,
        > 0). Compaction is irreversible; unloading is elastic (docs/fem.md "Compaction").
        FE only (the concrete closed form takes the same four numbers from
        :class:`cavex.concrete.Concrete`).
    """

    E: float = field(metadata={"unit": "Pa"})
    nu: float = field(metadata={"unit": "1"})
    rho: float = field(metadata={"unit": "kg m-3"})
    lam: float = field(metadata={"unit": "1"})
    tau: float | None = field(default=None, metadata={"unit": "Pa"})
    name: str = ""
    sigma_c: float | None = field(default=None, compare=False, metadata={"unit": "Pa"})
    # the FE-only parameters (None: absent; config files and tables write them only when
    # given, so that targets without them keep their tables and fingerprints)
    tau_max: float | None = field(default=None, metadata={"unit": "Pa", "fe_only": True})
    tensile_strength: float | None = field(default=None,
                                           metadata={"unit": "Pa", "fe_only": True})
    crush_pressure: float | None = field(default=None, metadata={"unit": "Pa", "fe_only": True})
    lock_pressure: float | None = field(default=None, metadata={"unit": "Pa", "fe_only": True})
    lock_strain: float | None = field(default=None, metadata={"unit": "1", "fe_only": True})
    locked_modulus: float | None = field(default=None, metadata={"unit": "Pa", "fe_only": True})

    def __post_init__(self):
        require_name(self.name, "name")
        _positive("E", self.E)
        _positive("rho", self.rho)
        require(is_finite_number(self.nu) and -1.0 < self.nu < 0.5, "nu", "in (-1, 0.5)", self.nu)
        require(is_finite_number(self.lam) and 0.0 <= self.lam < 3.0, "lam", "in [0, 3)", self.lam)
        require(self.tau is not None or self.sigma_c is not None, "tau",
                "given (or sigma_c given)", None)
        if self.sigma_c is not None:
            _positive("sigma_c", self.sigma_c)
            derived = (3.0 - self.lam) * self.sigma_c / 3.0
            require(self.tau is None or math.isclose(self.tau, derived, rel_tol=1e-12),
                    "tau", f"(3 - lam) sigma_c / 3 = {derived} when sigma_c is also given",
                    self.tau)
            object.__setattr__(self, "tau", derived)
        _positive("tau", self.tau)
        uniaxial = self.uniaxial_strength
        if self.tau_max is not None:
            _positive("tau_max", self.tau_max)
            require(self.tau_max >= uniaxial * (1.0 - 1e-12), "tau_max",
                    f">= the uniaxial compressive strength 3 tau/(3 - lam) = {uniaxial:.6g} Pa "
                    "(a cap below it)", self.tau_max)
        if self.tensile_strength is not None:
            _positive("tensile_strength", self.tensile_strength)
            require(self.tensile_strength <= uniaxial * (1.0 + 1e-12), "tensile_strength",
                    f"<= the uniaxial compressive strength 3 tau/(3 - lam) = {uniaxial:.6g} Pa",
                    self.tensile_strength)
        self._check_hydrostat()

    def _check_hydrostat(self):
        """The compaction hydrostat's four numbers: all or none, each in its range."""
        values = [getattr(self, name) for name in HYDROSTAT]
        if all(v is None for v in values):
            return
        for name, value in zip(HYDROSTAT, values, strict=True):
            require(value is not None, name, "given with " + ", ".join(
                n for n in HYDROSTAT if n != name) + " (the hydrostat: all four or none)",
                    value)
        _positive("crush_pressure", self.crush_pressure)
        require(is_finite_number(self.lock_pressure) and math.isfinite(self.lock_pressure)
                and self.lock_pressure > self.crush_pressure, "lock_pressure",
                f"a finite number > crush_pressure = {self.crush_pressure:.6g} Pa",
                self.lock_pressure)
        least = self.lock_pressure / self.bulk_modulus
        require(is_finite_number(self.lock_strain) and least < self.lock_strain < 1.0,
                "lock_strain", f"in ({least:.6g}, 1) (lock_pressure/K: compaction softer than "
                "the bulk modulus K)", self.lock_strain)
        _positive("locked_modulus", self.locked_modulus)

    @property
    def compacts(self):
        """True when the layer has a compaction hydrostat (:data:`HYDROSTAT` given)."""
        return self.crush_pressure is not None

    @property
    def uniaxial_strength(self):
        """Unconfined compressive strength ``3 tau / (3 - lam)`` (Pa) of the Mohr-Coulomb
        line (uniaxial compression: ``sigma_r - sigma_theta = sigma_c`` at ``sigma =
        sigma_c/3``)."""
        return 3.0 * self.tau / (3.0 - self.lam)

    @cached_property
    def alpha(self):
        """``alpha = 3 lam / (3 + 2 lam)``: plastic deviator ``alpha (sigma_r + tau/lam)``."""
        return 3.0 * self.lam / (3.0 + 2.0 * self.lam)

    @cached_property
    def yield_intercept(self):
        """``k = alpha tau / lam = 3 tau / (3 + 2 lam)`` (finite as lam -> 0)."""
        return 3.0 * self.tau / (3.0 + 2.0 * self.lam)

    @property
    def shear_modulus(self):
        """``G = E / (2 (1 + nu))``."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def bulk_modulus(self):
        """``K = E / (3 (1 - 2 nu))``."""
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    @cached_property
    def quasi_static_epsilon(self):
        """``epsilon = a/b`` of the quasi-static convention, ``epsilon^3 = 3 tau / (2 E)``."""
        return (1.5 * self.tau / self.E) ** (1.0 / 3.0)


#: The compaction hydrostat's parameters of a :class:`Material` (all four or none).
HYDROSTAT = ("crush_pressure", "lock_pressure", "lock_strain", "locked_modulus")


#: How a layer's bottom face holds to the layer below (``bottom`` of a layer, docs/config.md):
#: "bonded" (the default: the layers are one continuum to the cavity expansion) or "debonded"
#: (the interface opens: a traction-free rear face, a rear zone, a crater in the next layer;
#: docs/analytic.md "Debonded interfaces").
BONDINGS = ("bonded", "debonded")
#: ranges of a layer's plain-law constants ``law_A``, ``law_B`` (``S = A + B rho V^2 / tau``):
#: wide of published numbers (Forrestal's concrete S ~ 4-20 in units of f_c, i.e. A ~ 5-30 in
#: units of tau; B ~ 1; soils B ~ 1-3) and bounded where the stresses stay finite
LAW_A_RANGE = (0.0, 1e3)
LAW_B_RANGE = (0.0, 100.0)


def material_parameters():
    """``{name: unit}`` of a :class:`Material`'s numerical parameters, in order (its config
    keys, the sweep file's ``[materials]`` keys and the units of their tables)."""
    return {f.name: f.metadata["unit"] for f in fields(Material) if "unit" in f.metadata}


def fe_only_parameters():
    """The :class:`Material` parameters that only the FE reads (the closed forms ignore them),
    in order."""
    return tuple(f.name for f in fields(Material) if f.metadata.get("fe_only"))


@dataclass(frozen=True)
class Target:
    """Plane layered target: ``layers[i]`` has ``thicknesses[i]``; the last is semi-infinite.

    ``bottoms[i]`` (one of :data:`BONDINGS`, default all "bonded") is how the bottom face of
    layer ``i`` (interface ``i + 1``) holds; ``scab_depths[i]`` (m, > 0, less than the layer's
    thickness; None: the rule of :func:`cavex.analytic.penetration.zones.scab_depth`) is the
    depth of the rear zone above a debonded interface. ``plain_laws[i]`` (None: not given) is
    layer ``i``'s plain law ``(A, B)`` (``law_A``, ``law_B`` of a layer, dimensionless,
    :data:`LAW_A_RANGE`, :data:`LAW_B_RANGE`): ``S = A + B rho V^2 / tau``, i.e. the wall
    stress ``tau (A + B rho V^2 / tau)``, used by ``cavex trajectory --resistance law``.
    ``tunnel_walls[i]`` (in [0, 1], default 1) scales the load of the 3-D model's shank in
    layer ``i``: a sensitivity setting, uncalibrated (docs/oblique.md "Tunnel wall")."""

    layers: tuple
    thicknesses: tuple
    bottoms: tuple = ()
    scab_depths: tuple = ()
    plain_laws: tuple = ()
    tunnel_walls: tuple = ()

    def __post_init__(self):
        object.__setattr__(self, "layers", tuple(self.layers))
        object.__setattr__(self, "thicknesses", tuple(float(h) for h in self.thicknesses))
        require(len(self.layers) >= 1, "layers", "at least one layer", len(self.layers))
        require(len(self.thicknesses) == len(self.layers) - 1, "thickness",
                "given for every layer but the last (semi-infinite)", len(self.thicknesses))
        n = len(self.thicknesses)
        bottoms = tuple(self.bottoms) or ("bonded",) * n
        scabs = tuple(self.scab_depths) or (None,) * n
        require(len(bottoms) == n, "bottom", "given for every layer but the last (none: "
                "all bonded)", len(bottoms))
        require(len(scabs) == n, "scab_depth", "given for every layer but the last (None: "
                "the default rule)", len(scabs))
        for i, (bottom, scab) in enumerate(zip(bottoms, scabs, strict=True)):
            require(bottom in BONDINGS, f"layers[{i}].bottom", "one of " + ", ".join(BONDINGS),
                    bottom)
            if scab is not None:
                require(is_finite_number(scab) and 0.0 < scab < self.thicknesses[i],
                        f"layers[{i}].scab_depth", f"in (0, {self.thicknesses[i]:g}) m (within "
                        "the layer)", scab)
        laws = tuple(self.plain_laws) or (None,) * len(self.layers)
        require(len(laws) == len(self.layers), "law_A", "given per layer (None: no plain law)",
                len(laws))
        for i, law in enumerate(laws):
            if law is None:
                continue
            require(len(law) == 2, f"layers[{i}].law_A", "given with law_B", law)
            for name, value, (lo, hi) in (("law_A", law[0], LAW_A_RANGE),
                                          ("law_B", law[1], LAW_B_RANGE)):
                require(is_finite_number(value) and lo <= value <= hi, f"layers[{i}].{name}",
                        f"in [{lo:g}, {hi:g}] (dimensionless)", value)
        object.__setattr__(self, "plain_laws", tuple(
            None if law is None else (float(law[0]), float(law[1])) for law in laws))
        walls = tuple(self.tunnel_walls) or (1.0,) * len(self.layers)
        require(len(walls) == len(self.layers), "tunnel_wall", "given per layer", len(walls))
        for i, wall in enumerate(walls):
            require(is_finite_number(wall) and 0.0 <= wall <= 1.0, f"layers[{i}].tunnel_wall",
                    "in [0, 1]", wall)
        object.__setattr__(self, "tunnel_walls", tuple(float(w) for w in walls))
        object.__setattr__(self, "bottoms", bottoms)
        object.__setattr__(self, "scab_depths", tuple(None if s is None else float(s)
                                                      for s in scabs))
        depth = 0.0
        for i, h in enumerate(self.thicknesses):
            _positive(f"layers[{i}].thickness", h)
            # a thickness lost to round-off beside the depth above it is no layer
            require(depth + h > depth and math.isfinite(depth + h), f"layers[{i}].thickness",
                    f"large enough to move the interface below z = {depth:g} m", h)
            depth += h

    @cached_property
    def interface_depths(self):
        """Depths ``H_1 < H_2 < ...`` of the layer interfaces below the free surface (m)."""
        return tuple(accumulate(self.thicknesses))

    @property
    def debonded(self):
        """Indices ``j`` of the debonded interfaces (``interface_depths[j]``), top down."""
        return tuple(j for j, bottom in enumerate(self.bottoms) if bottom == "debonded")

    def with_interfaces(self, bonding):
        """This target with every interface ``bonding`` (:data:`BONDINGS`; None: unchanged):
        what ``--interfaces`` does to the file's ``bottom`` keys."""
        if bonding is None:
            return self
        require(bonding in BONDINGS, "interfaces", "one of " + ", ".join(BONDINGS), bonding)
        return Target(self.layers, self.thicknesses, (bonding,) * len(self.thicknesses),
                      self.scab_depths, self.plain_laws, self.tunnel_walls)

    def with_tunnel_wall(self, factor):
        """This target with every layer's tunnel-wall factor ``factor`` (None: unchanged):
        what ``--tunnel-wall`` does to the file's ``tunnel_wall`` keys."""
        if factor is None:
            return self
        return Target(self.layers, self.thicknesses, self.bottoms, self.scab_depths,
                      self.plain_laws, (factor,) * len(self.layers))

    def layer_at(self, depth):
        """Index of the layer containing ``depth`` (interfaces belong to the deeper layer)."""
        return sum(1 for H in self.interface_depths if depth >= H)

    def single(self, index):
        """The semi-infinite target made of layer ``index`` alone."""
        return Target((self.layers[index],), (), plain_laws=(self.plain_laws[index],),
                      tunnel_walls=(self.tunnel_walls[index],))

    def layer_name(self, index):
        """Display name of layer ``index`` (from 0, top down): its ``name``, else
        ``"layer {index + 1}"``."""
        return self.layers[index].name or f"layer {index + 1}"

    def layer_names(self):
        """:meth:`layer_name` of every layer, top down."""
        return [self.layer_name(index) for index in range(len(self.layers))]


DEFAULT_DENSITY = 7850.0  # kg/m^3, steel: the body's length when ``length`` is absent
MAX_CALIBRES = 1000  # longest body, in shank diameters (long-rod penetrators: ~30)
MAX_FRICTION = 10.0  # largest Coulomb coefficient mu (dry friction: below ~1)
# the projectile's accepted geometry and mass: where the nose quadrature's areas and the
# energies stay finite (a radius near 1e150 m overflows R^2 there) and wide of every real
# penetrator (shank radius ~1 mm to ~0.5 m, CRH ~1 to ~20, mass up to ~1e4 kg)
RADIUS_RANGE = (1e-4, 10.0)  # m, shank radius r
MAX_CRH = 1000.0  # largest calibre-radius-head R / (2 r)
MASS_RANGE = (1e-6, 1e6)  # kg


@dataclass(frozen=True)
class Projectile:
    """Rigid ogive-nosed projectile.

    Parameters
    ----------
    r : float
        Shank radius (m), in :data:`RADIUS_RANGE`.
    l : float
        Nose length used to place the cavity centre (m), as the paper's Table 1; at most
        :data:`MAX_CALIBRES` calibres.
    R : float
        Ogive radius (m), ``r <= R <= 2 MAX_CRH r``; give this or ``crh = R / (2 r)``.
    m : float
        Mass (kg), in :data:`MASS_RANGE`.
    V0 : float
        Striking velocity (m/s), in (0, 1e4].
    length : float, optional
        Overall length, nose tip to tail (m), longer than the tangent ogive
        (:attr:`ogive_length`), at most :data:`MAX_CALIBRES` calibres. Used by the 3-D
        trajectory model only (``docs/oblique.md``);
        absent: :attr:`body_length`, a solid steel body of the given mass.
    inertia : float, optional
        Transverse moment of inertia about the centre of mass (kg m^2), > 0; absent: a solid
        body of uniform density (``cavex.analytic.penetration.body``).
    cg : float, optional
        Centre of mass, m from the nose tip, in (0, length); absent: uniform density.
    mu : float
        Coulomb friction coefficient on the surface, in [0, 10] (default 0).
    """

    r: float
    l: float  # noqa: E741 (the paper's name)
    m: float
    V0: float
    R: float | None = None
    crh: float | None = field(default=None, compare=False)
    length: float | None = None
    inertia: float | None = None
    cg: float | None = None
    mu: float = 0.0

    def __post_init__(self):
        for name in ("r", "l", "m", "V0"):
            _positive(name, getattr(self, name))
        require(self.V0 <= MAX_VELOCITY, "V0",
                f"<= {MAX_VELOCITY:g} m/s (rigid-projectile penetration)", self.V0)
        require(RADIUS_RANGE[0] <= self.r <= RADIUS_RANGE[1], "r",
                f"in [{RADIUS_RANGE[0]:g}, {RADIUS_RANGE[1]:g}] m", self.r)
        require(self.l <= MAX_CALIBRES * 2.0 * self.r, "l",
                f"<= {MAX_CALIBRES} calibres ({MAX_CALIBRES * 2.0 * self.r:g} m)", self.l)
        require(MASS_RANGE[0] <= self.m <= MASS_RANGE[1], "m",
                f"in [{MASS_RANGE[0]:g}, {MASS_RANGE[1]:g}] kg", self.m)
        _exactly_one("R", "crh", (self.R, self.crh))
        if self.R is None:
            _positive("crh", self.crh)
            require(self.crh <= MAX_CRH, "crh", f"<= {MAX_CRH:g}", self.crh)
            object.__setattr__(self, "R", 2.0 * self.r * self.crh)
        _positive("R", self.R)
        require(self.r <= self.R <= 2.0 * MAX_CRH * self.r, "R",
                f">= r = {self.r} (ogive) and <= {2.0 * MAX_CRH:g} r = "
                f"{2.0 * MAX_CRH * self.r:g} m (CRH <= {MAX_CRH:g})", self.R)
        if self.length is not None:
            _positive("length", self.length)
            require(self.ogive_length < self.length <= MAX_CALIBRES * 2.0 * self.r, "length",
                    f"in ({self.ogive_length:.6g}, {MAX_CALIBRES * 2.0 * self.r:g}] m (longer "
                    f"than the tangent ogive, at most {MAX_CALIBRES} calibres)", self.length)
        if self.inertia is not None:
            _positive("inertia", self.inertia)
        if self.cg is not None:
            _positive("cg", self.cg)
            require(self.cg < self.body_length, "cg",
                    f"< the overall length {self.body_length:.6g} m", self.cg)
        require(is_finite_number(self.mu) and 0.0 <= self.mu <= MAX_FRICTION, "mu",
                f"in [0, {MAX_FRICTION:g}]", self.mu)

    @classmethod
    def tangent_ogive(cls, mass, diameter, crh, V0):
        """The projectile of a shot as published: mass (kg), shank ``diameter`` (m), a tangent
        ogive of calibre-radius-head ``crh`` and ``V0`` (m/s): ``r = d/2``, ``R = crh d`` and
        ``l`` the tangent ogive's nose length ``r sqrt(4 crh - 1)`` (it places the cavity
        centre at the nose base)."""
        r = 0.5 * diameter
        return cls(r=r, l=r * math.sqrt(4.0 * crh - 1.0), m=mass, V0=V0, R=crh * diameter)

    @property
    def psi(self):
        """Calibre-radius-head ``psi = R / (2 r)``."""
        return self.R / (2.0 * self.r)

    @property
    def body_length(self):
        """Overall length (m): ``length``, or, absent, that of a solid steel body
        (:data:`DEFAULT_DENSITY`) of mass ``m``: tangent ogive plus shank of the same volume
        (0.1498 m, 6.0 calibres, for the paper's Table 1 projectile)."""
        if self.length is not None:
            return self.length
        r, R, ln = self.r, self.R, self.ogive_length
        s = R - r
        # volume of the tangent ogive: int_0^ln pi (sqrt(R^2 - x^2) - s)^2 dx
        nose = math.pi * ((R * R + s * s) * ln - ln ** 3 / 3.0
                          - s * (ln * math.sqrt(R * R - ln * ln) + R * R * math.asin(ln / R)))
        shank = self.m / DEFAULT_DENSITY - nose
        require(shank > 0.0, "length", "given (a steel body of this mass is shorter than its "
                "nose)", None)
        length = ln + shank / (math.pi * r * r)
        require(length <= MAX_CALIBRES * 2.0 * r, "length", f"given (a steel body of this mass "
                f"is {length:.6g} m long, over {MAX_CALIBRES} calibres)", None)
        return length

    @property
    def ogive_length(self):
        """Geometric nose length of a tangent ogive, ``sqrt(2 R r - r^2)`` (m)."""
        return math.sqrt(2.0 * self.R * self.r - self.r ** 2)
