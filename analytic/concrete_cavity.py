r"""Dynamic spherical cavity expansion in concrete: elastic, radially cracked and comminuted zones.

After Forrestal and Tzou (1997, Int. J. Solids Struct. 34(31-32), 4127-4146), with the locked
hydrostat of Luk, Forrestal and Amos (1991). A spherical cavity opens from zero radius at the
constant velocity ``V`` in one semi-infinite concrete. Compression is positive; ``f_c`` (the
unconfined compressive strength) normalises every stress, ``s = sigma/f_c``, and the inertia
number is ``phi = rho V^2 / f_c`` (``rho`` the undisturbed density). The solution is
self-similar in ``xi = r/(V t)`` (cavity wall ``xi = 1``); ``U = v/V`` is the particle
velocity and ``R = rho/rho_0`` the density ratio. docs/concrete.md derives every equation below.

Zones, from the wall outward:

- comminuted (plastic), ``1 <= xi <= beta``: exact (Eulerian) balance of mass and momentum,

  .. math:: (U - \xi) R' + R (U' + 2U/\xi) = 0, \qquad
            s' + 2D/\xi = \phi R (\xi - U) U',

  with ``D = s_r - s_theta = min(tau_0 + lam p, tau_max)``, ``p = s_r - 2D/3``,
  ``tau_0 = f_c (1 - lam/3)`` (uniaxial compression yields at ``f_c``), and the hydrostat
  (volumetric strain ``eta = 1 - 1/R``) linear up to the locking strain, then stiff:

  .. math:: \eta = \min(p/K, \eta_l) + \max(0, p - K\eta_l)/K_l

  (``K`` the compaction modulus, ``eta_l`` the locking strain, ``K_l`` the locked modulus;
  ``K = 0`` is the locked hydrostat of Luk et al., compacted to ``eta_l`` at the front;
  ``eta_l = 0, K_l = inf`` is incompressible). Solved for ``U'`` and ``s'``:

  .. math:: U' = -\frac{2 (R U + (\xi - U) R_s D)}{\xi R (1 - \phi R_s (\xi - U)^2)},

  ``R_s = dR/ds = R^2 p_s d eta/dp``; the flow behind the front must stay subsonic
  (``phi R_s (xi - U)^2 < 1``).
- radially cracked, ``beta <= xi <= gamma``: ``sigma_theta = 0``, ``sigma_r = -E eps_r``, small
  strain ``u = V t F(xi)``, ``U = F - xi F'``, density ``rho_0``. The linear momentum balance
  ``(xi^2 s)' = -phi xi^3 F''`` integrates to ``F' = K_1 (1/xi^2 - w_b^2)``,
  ``F = K_0 - K_1 (1/xi + w_b^2 xi)``, ``w_b = V/c_b``, ``c_b^2 = E/rho``.
- elastic, ``xi >= gamma`` (or ``beta``): linear elastodynamics, the wave front at
  ``xi = 1/w``, ``w = V/c_d``; the solution that vanishes with its slope at the front is
  ``F = C (1/xi^2 - 3 w^2 + 2 w^3 xi)``, so ``U = 3C (1/xi^2 - w^2)``,
  ``D = 6 mu C (1/xi^3 - w^2/xi)`` and

  .. math:: s = 4\mu F/\xi + 6 C \phi (1/\xi - w) - \phi U^2/2,

  written so that ``nu -> 1/2`` (``w = 0``) is finite; the last term is the integral of the
  convective acceleration ``U U'`` (second order in the strain; with it the incompressible
  limit is cavex's derived closed form exactly).

Fronts:

- crack front ``gamma``: the elastic hoop stress reaches the tensile strength,
  ``s_theta = -f_t/f_c``; ``F`` is continuous and momentum jumps by the linear Rankine-Hugoniot
  condition ``[s_r] = -phi gamma^2 [F']``;
- plastic front ``beta``: the material ahead is at yield (cracked: uniaxial,
  ``s_r = min(1, tau_max/f_c)``; elastic: ``D = min(tau_0 + lam p, tau_max)``), and mass and
  momentum jump by the exact Rankine-Hugoniot conditions ``R^-(beta - U^-) = R^+(beta - U^+)
  = j``, ``s^- = s^+ + phi j (U^- - U^+)`` (a shock where the hydrostat compacts);
- the state behind a front is the first intersection of the Rayleigh line with the hydrostat
  going up from the state ahead (subsonic behind it); where the flow inside the comminuted zone
  turns sonic (``phi R_s (xi - U)^2 = 1``), a compaction shock is put at the sonic point;
- a plastic front faster than the elastic wave (``beta >= 1/w``) runs into undisturbed concrete.

The wall condition ``U(1) = 1`` closes the problem: one unknown front speed (``beta`` without
cracking, ``gamma`` with it) is found by bracketing and Brent's method; every evaluation
integrates the comminuted zone inward from ``beta`` with classical Runge-Kutta (RK4) at steps
of fixed length in ``tau``, ``d ln xi = m d tau`` (``m = 1 - phi R_s (xi - U)^2`` the subsonic
margin: no singularity where the flow turns sonic, short steps in ``ln xi`` near it), a step
split where it meets a kink of the constitutive law (the cap ``tau_max``, the crush and lock
points), a sonic point (a compaction shock there) or the wall, so that the order stays 4
(``tests/test_concrete_cavity.py`` and ``tests/test_concrete_cavity_sweep.py`` measure it).

Which structure (:data:`STRUCTURES`): the elastic-comminuted solution when its hoop tension at
``beta`` stays within ``f_t``; else the cracked one (crack front slower than the bar wave
``c_b``); else the crack front riding on the comminution front (the cracked zone's limit of zero
width: elastic hoop stress ``-f_t/f_c`` just ahead of ``beta``); a comminuted shock into
undisturbed concrete when no elastic precursor fits.

Public: :class:`ConcreteCavity` (the dimensionless material), :func:`solve` (one ``phi``),
:func:`wall_stress` (arrays of velocities), :func:`resistance_table` and :func:`fit_AB`
(``sigma_r/f_c ~ A + B rho V^2/f_c``). The ``(material, phi)`` answers are cached.
"""

import math
from dataclasses import dataclass, fields
from functools import lru_cache

import numpy as np
from numba import njit

from cavex.errors import CavexNumericalError, is_finite_number, require

# structure codes of a solution
ELASTIC_PLASTIC, CRACKED, JOINT_FRONT, SUPERSEISMIC = 0, 1, 2, 3
STRUCTURES = {ELASTIC_PLASTIC: "elastic-comminuted", CRACKED: "elastic-cracked-comminuted",
              JOINT_FRONT: "elastic-comminuted, cracking at the comminution front",
              SUPERSEISMIC: "comminuted shock into undisturbed concrete"}
EPS = np.finfo(np.float64).eps
DEFAULT_STEPS = 256  # RK4 steps across the comminuted zone (see the convergence test)
# columns of the parameter vector of the compiled functions
(E_, MU, LAM, TAU0, TAU_MAX, BULK, ETA, LOCKED, TENSILE, W, WB, PHI, POWER_B, POWER_N,
 CRUSH, P_LOCK, E_LOCK, OPEN, S_CAP, S_OPEN, S_CRUSH, S_LOCK, Q_OPEN, Q_CRUSH,
 Q_LOCK) = range(25)
NPAR = 25  # S_CAP ... S_LOCK: the kinks (kink_stresses) and Q_OPEN ... Q_LOCK: the pressures
# of the hydrostat's pieces (opening_pressure, crush_pressure, lock_pressure), computed once
# per vector; OPEN: the crack opening the comminuted material carries (set_opening, per front
# tried)


@dataclass(frozen=True)
class ConcreteCavity:
    """Concrete for the cavity expansion, in units of ``f_c`` (dimensionless).

    Parameters
    ----------
    modulus : float
        ``E / f_c`` (> 1).
    nu : float
        Poisson's ratio of the elastic zone, in [0, 0.5] (0.5: incompressible elastic zone).
    lam : float
        Pressure slope of the comminuted strength ``D = tau_0 + lam p``, in [0, 3).
    tau_max : float
        Tresca limit ``tau_max / f_c`` of ``D`` (>= 1; ``inf``: no limit).
    bulk : float
        Compaction modulus ``K / f_c`` of the comminuted hydrostat (>= 0; 0: compacted to
        ``eta_lock`` at the front).
    eta_lock : float
        Locking volumetric strain ``eta_l``, in [0, 0.9].
    bulk_locked : float
        Modulus ``K_l / f_c`` past the locking strain (> 0; ``inf``: rigid).
    tensile : float
        Tensile strength ``f_t / f_c`` (> 0; ``inf``: no cracking).
    crush, lock_pressure, lock_strain : float
        The compaction hydrostat of the FE (:func:`cavex.fem.constitutive.hydrostat`,
        Holmquist, Johnson and Cook's form; docs/concrete.md "Hydrostat"), given all three:
        in the log volumetric strain ``e = ln R`` and the Kirchhoff pressure ``P = p/R``,
        elastic ``P = K e`` (``K`` = :attr:`bulk`, the elastic bulk modulus) up to ``crush``
        (``P_c/f_c > 0``), linear to ``lock_pressure`` (``P_l/f_c``) at ``lock_strain``
        (``e_l``), then ``P_l + K_l (e - e_l)`` (``K_l`` = :attr:`bulk_locked`). Default
        ``nan``: the hydrostat in ``eta`` above (``bulk`` the compaction modulus).
    power_B, power_N : float
        The comminuted (fully damaged) strength as a power law of the pressure,
        ``D = min(B p^N, tau_max)`` (Holmquist, Johnson and Cook 1993: ``B = 1.6``,
        ``N = 0.61``), ``B > 0``, ``N`` in ``(0, 1]``. Default ``power_B = nan``: the straight
        line ``tau_0 + lam p``. The intact material ahead of the comminution front yields on the
        straight line in either case.
    """

    modulus: float
    nu: float
    lam: float
    tau_max: float = math.inf
    bulk: float = math.inf
    eta_lock: float = 0.0
    bulk_locked: float = math.inf
    tensile: float = math.inf
    power_B: float = math.nan
    power_N: float = 1.0
    crush: float = math.nan
    lock_pressure: float = math.nan
    lock_strain: float = math.nan

    def __repr__(self):
        """The fields, the power law's and the compaction hydrostat's only when they are used
        (no ``nan`` in a message)."""
        names = [f.name for f in fields(self)
                 if (self.power_law or f.name not in ("power_B", "power_N"))
                 and (self.compacts or f.name not in HYDROSTAT)]
        return f"ConcreteCavity({', '.join(f'{n}={getattr(self, n)!r}' for n in names)})"

    @property
    def compacts(self):
        """True when the comminuted hydrostat is the FE's compaction hydrostat (:attr:`crush`
        given)."""
        return not math.isnan(self.crush)

    @property
    def power_law(self):
        """True when the comminuted strength is ``B p^N`` (:attr:`power_B` given)."""
        return not math.isnan(self.power_B)

    def __post_init__(self):
        for name in ("modulus", "nu", "lam", "eta_lock"):
            require(is_finite_number(getattr(self, name)), name, "a finite number",
                    getattr(self, name))
        require(self.modulus > 1.0, "modulus", "E/f_c > 1", self.modulus)
        require(0.0 <= self.nu <= 0.5, "nu", "in [0, 0.5]", self.nu)
        require(0.0 <= self.lam < 3.0, "lam", "in [0, 3)", self.lam)
        require(self.tau_max >= 1.0, "tau_max", "tau_max/f_c >= 1 (inf: none)", self.tau_max)
        require(self.bulk >= 0.0, "bulk", "K/f_c >= 0", self.bulk)
        require(self.bulk_locked > 0.0, "bulk_locked", "K_l/f_c > 0 (inf: rigid)",
                self.bulk_locked)
        require(0.0 <= self.eta_lock <= 0.9, "eta_lock", "in [0, 0.9]", self.eta_lock)
        require(self.tensile > 0.0, "tensile", "f_t/f_c > 0 (inf: no cracking)", self.tensile)
        if self.power_law:
            require(is_finite_number(self.power_B) and self.power_B > 0.0, "power_B",
                    "a finite number > 0 (nan: the straight line)", self.power_B)
            require(is_finite_number(self.power_N) and 0.0 < self.power_N <= 1.0, "power_N",
                    "in (0, 1]", self.power_N)
        if any(not math.isnan(getattr(self, name)) for name in HYDROSTAT):
            self._check_hydrostat()

    def _check_hydrostat(self):
        """The compaction hydrostat: all three given, the elastic ``bulk`` and ``bulk_locked``
        finite, ``eta_lock`` 0 (unused), each in the range of :class:`cavex.materials.Material`."""
        for name in HYDROSTAT:
            require(is_finite_number(getattr(self, name)), name, "a finite number (the "
                    "hydrostat: crush, lock_pressure, lock_strain all given)", getattr(self, name))
        require(math.isfinite(self.bulk) and self.bulk > 0.0, "bulk",
                "the elastic K/f_c, finite and > 0, with the compaction hydrostat", self.bulk)
        require(math.isfinite(self.bulk_locked), "bulk_locked",
                "finite with the compaction hydrostat", self.bulk_locked)
        require(self.eta_lock == 0.0, "eta_lock", "0 with the compaction hydrostat",
                self.eta_lock)
        require(self.crush > 0.0, "crush", "P_c/f_c > 0", self.crush)
        require(self.lock_pressure > self.crush, "lock_pressure", f"> crush = {self.crush:g}",
                self.lock_pressure)
        least = self.lock_pressure / self.bulk
        require(least < self.lock_strain < 1.0, "lock_strain",
                f"in ({least:.6g}, 1) (compaction softer than the bulk modulus)",
                self.lock_strain)

    @property
    def shear(self):
        """``mu / f_c = E / (2 (1 + nu) f_c)``."""
        return self.modulus / (2.0 * (1.0 + self.nu))

    def wave_numbers(self, phi):
        """``(w, w_b) = (V/c_d, V/c_b)`` at ``phi = rho V^2/f_c``:
        ``w^2 = phi (1 + nu)(1 - 2 nu)/(e (1 - nu))``, ``w_b^2 = phi/e``."""
        e, nu = self.modulus, self.nu
        return (math.sqrt(phi * (1.0 + nu) * (1.0 - 2.0 * nu) / (e * (1.0 - nu))),
                math.sqrt(phi / e))

    def parameters(self, phi):
        """The parameter vector of the compiled functions."""
        w, wb = self.wave_numbers(phi)
        p = np.empty(NPAR)
        p[E_], p[MU], p[LAM] = self.modulus, self.shear, self.lam
        p[TAU0], p[TAU_MAX], p[BULK] = 1.0 - self.lam / 3.0, self.tau_max, self.bulk
        p[ETA], p[LOCKED], p[TENSILE] = self.eta_lock, self.bulk_locked, self.tensile
        p[W], p[WB], p[PHI] = w, wb, phi
        p[POWER_B], p[POWER_N] = self.power_B, self.power_N
        p[CRUSH], p[P_LOCK], p[E_LOCK] = self.crush, self.lock_pressure, self.lock_strain
        set_opening(p, 0.0)
        return p


#: The compaction hydrostat's fields of :class:`ConcreteCavity` (all or none).
HYDROSTAT = ("crush", "lock_pressure", "lock_strain")


@dataclass(frozen=True)
class CavitySolution:
    """One self-similar solution: wall stress ``S = sigma_r(a)/f_c`` and its structure."""

    S: float
    phi: float
    structure: int
    plastic_front: float  # beta = c_plastic / V
    crack_front: float  # gamma (NaN without a cracked zone)
    amplitude: float  # C of the elastic zone (NaN if none)
    residual: float = 0.0  # U(1) - 1 at the front found (<= RESIDUAL_TOLERANCE in size)

    @property
    def name(self):
        return STRUCTURES[self.structure]


# ------------------------------------------------------------------------------------------
# Compiled pieces
# ------------------------------------------------------------------------------------------

@njit(cache=True, error_model="numpy")
def elastic_state(p, C, x):
    """``(s_r, D, U, F, F', eps_v)`` of the elastic zone at ``xi = x``, amplitude ``C``."""
    w, phi, mu = p[W], p[PHI], p[MU]
    F = C * (1.0 / x ** 2 - 3.0 * w ** 2 + 2.0 * w ** 3 * x)
    dF = C * (-2.0 / x ** 3 + 2.0 * w ** 3)
    U = 3.0 * C * (1.0 / x ** 2 - w ** 2)
    D = 6.0 * mu * C * (1.0 / x ** 3 - w ** 2 / x)
    s = 4.0 * mu * F / x + 6.0 * C * phi * (1.0 / x - w) - 0.5 * phi * U * U
    return s, D, U, F, dF, 6.0 * C * w ** 2 * (w - 1.0 / x)


@njit(cache=True, error_model="numpy")
def _quadratic_root(c2, c1, c0):
    """The smallest positive root of ``c2 C^2 + c1 C + c0 = 0`` (NaN if none); as ``c2 -> 0``
    the root ``-c0/c1`` (the quadratic terms are the small convective ones)."""
    disc = c1 * c1 - 4.0 * c2 * c0
    if disc < 0.0:
        return np.nan
    q = -0.5 * (c1 + math.copysign(math.sqrt(disc), c1))
    best = np.nan
    for root in (c0 / q if q != 0.0 else np.nan, q / c2 if c2 != 0.0 else np.nan):
        if root > 0.0 and not root >= best:
            best = root
    return best


@njit(cache=True, error_model="numpy")
def _elastic_parts(p, x):
    """``s_r``, ``D`` and ``s_theta`` of the elastic zone as ``(linear, quadratic)`` parts in C."""
    w, phi, mu = p[W], p[PHI], p[MU]
    f = 1.0 / x ** 2 - 3.0 * w ** 2 + 2.0 * w ** 3 * x
    s1 = 4.0 * mu * f / x + 6.0 * phi * (1.0 / x - w)
    s2 = -0.5 * phi * 9.0 * (1.0 / x ** 2 - w ** 2) ** 2
    d1 = 6.0 * mu * (1.0 / x ** 3 - w ** 2 / x)
    return s1, s2, d1


@njit(cache=True, error_model="numpy")
def yield_amplitude(p, x):
    """Elastic amplitude ``C`` at which the elastic state at ``xi = x`` first yields:
    ``D = tau_0 + lam (s - 2D/3)`` or ``D = tau_max``, whichever comes first."""
    s1, s2, d1 = _elastic_parts(p, x)
    lam = p[LAM]
    # D (1 + 2 lam/3) - lam s = tau_0
    c_mc = _quadratic_root(-lam * s2, d1 * (1.0 + 2.0 * lam / 3.0) - lam * s1, -p[TAU0])
    c_cap = p[TAU_MAX] / d1 if d1 > 0.0 else np.inf
    if c_cap < c_mc or not c_mc > 0.0:
        return c_cap
    return c_mc


@njit(cache=True, error_model="numpy")
def crack_amplitude(p, x):
    """Elastic amplitude ``C`` with the hoop stress ``s - D = -f_t/f_c`` at ``xi = x``."""
    s1, s2, d1 = _elastic_parts(p, x)
    return _quadratic_root(s2, s1 - d1, p[TENSILE])


@njit(cache=True, error_model="numpy")
def power_pressure(p, s):
    """Pressure ``q >= 0`` with ``q + (2/3) B q^N = s`` (comminuted power law below the cap) and
    ``dq/ds``. The left side is increasing and concave in ``q``: Newton from ``q = s`` lands below
    the root once, then climbs to it monotonically; kept inside the bracket ``[0, s]``."""
    if not s > 0.0:
        return s, 1.0
    B, N = p[POWER_B], p[POWER_N]
    lo, hi = 0.0, s
    q = s
    for _ in range(100):
        g = q + 2.0 * B * q ** N / 3.0 - s
        if g > 0.0:
            hi = q
        else:
            lo = q
        slope = 1.0 + 2.0 * B * N * q ** (N - 1.0) / 3.0 if q > 0.0 else np.inf
        step = g / slope
        q_new = q - step
        if not lo <= q_new <= hi:
            q_new = 0.5 * (lo + hi)
        done = abs(q_new - q) <= 1e-13 * s
        q = q_new
        if done:
            break
    slope = 1.0 + 2.0 * B * N * q ** (N - 1.0) / 3.0 if q > 0.0 else np.inf
    return q, 1.0 / slope


@njit(cache=True, error_model="numpy")
def strength(p, s, capped):
    """``(D, pressure, dpressure/ds)`` of the comminuted zone at radial stress ``s``, on the
    cap (``capped``) or below it: the straight line ``tau_0 + lam p`` or the power law
    ``B p^N`` (:attr:`ConcreteCavity.power_B`)."""
    cap = p[TAU_MAX]
    if capped:
        return cap, s - 2.0 * cap / 3.0, 1.0
    if math.isnan(p[POWER_B]):
        lam, tau0 = p[LAM], p[TAU0]
        scale = 1.0 / (1.0 + 2.0 * lam / 3.0)
        pressure = (s - 2.0 * tau0 / 3.0) * scale
        return tau0 + lam * pressure, pressure, scale
    pressure, dp = power_pressure(p, s)
    return p[POWER_B] * max(pressure, 0.0) ** p[POWER_N], pressure, dp


@njit(cache=True, error_model="numpy")
def constitutive(p, s, branch=np.nan):
    """``(D, R, dR/ds)`` of the comminuted zone at radial stress ``s``; ``R = nan`` if the
    hydrostat is past full compaction. The pieces of the law (below or above the cap and the
    locking pressure) are chosen at ``branch`` (default ``s``), so that a step ending or
    starting at a kink stays on one side of it."""
    b = s if math.isnan(branch) else branch
    capped = b > p[S_CAP]
    D, pressure, dp = strength(p, s, capped)
    b_pressure = pressure if b == s else strength(p, b, capped)[1]
    eta, compliance = hydrostat(p, pressure, b_pressure)
    if eta >= 1.0:
        return D, np.nan, np.nan
    R = 1.0 / (1.0 - eta)
    return D, R, R * R * dp * compliance


@njit(cache=True, error_model="numpy")
def lock_pressure(p):
    """Cauchy pressure at which the hydrostat locks (0 without compaction): ``K eta_l``, or
    ``P_l exp(e_l)`` for the compaction hydrostat."""
    if not math.isnan(p[CRUSH]):
        return p[P_LOCK] * math.exp(p[E_LOCK])
    return p[BULK] * p[ETA] if p[ETA] > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def set_opening(p, opening):
    """Set the crack opening ``theta_o >= 0`` (plastic volumetric strain of the tension
    cut-off) that the comminuted material carries from the cracked zone, and the kinks
    (:func:`kink_stresses`) that move with it."""
    p[OPEN] = max(opening, 0.0)
    p[Q_OPEN], p[Q_CRUSH], p[Q_LOCK] = opening_pressure(p), crush_pressure(p), lock_pressure(p)
    p[S_CAP], p[S_OPEN], p[S_CRUSH], p[S_LOCK] = kink_stresses(p)


@njit(cache=True, error_model="numpy")
def crush_pressure(p):
    """Cauchy pressure at which the compaction hydrostat crushes on its loading curve,
    ``P_c exp(P_c/K)`` (inf without it)."""
    if math.isnan(p[CRUSH]):
        return np.inf
    return p[CRUSH] * math.exp(p[CRUSH] / p[BULK])


@njit(cache=True, error_model="numpy")
def opening_pressure(p):
    """Cauchy pressure at which the crack opening ``theta_o`` starts closing at the crush
    pressure, ``P_c exp(P_c/K - theta_o)`` (inf without the compaction hydrostat)."""
    if math.isnan(p[CRUSH]):
        return np.inf
    return p[CRUSH] * math.exp(p[CRUSH] / p[BULK] - p[OPEN])


@njit(cache=True, error_model="numpy")
def compaction_piece(p, branch):
    """``(a, b)`` of the compaction hydrostat's piece ``P = a + b e`` at the Cauchy pressure
    ``branch``: elastic with the crack opening ``theta_o`` (``P = K (e + theta_o)``), the
    opening closing at the crush pressure (``P = P_c``), compaction, or locked (the FE's
    :func:`cavex.fem.constitutive.hydrostat` on loading from ``theta_p = theta_o``)."""
    K, P_c, P_l, e_l = p[BULK], p[CRUSH], p[P_LOCK], p[E_LOCK]
    if branch < p[Q_OPEN]:
        return K * p[OPEN], K
    if branch < p[Q_CRUSH]:
        return P_c, 0.0
    if branch < p[Q_LOCK]:
        e_0 = P_c / K
        slope = (P_l - P_c) / (e_l - e_0)
        return P_c - slope * e_0, slope
    return P_l - p[LOCKED] * e_l, p[LOCKED]


@njit(cache=True, error_model="numpy")
def compaction_strain(a, b, pressure):
    """The log volumetric strain ``e`` with ``exp(e) (a + b e) = pressure`` (Cauchy: the
    Kirchhoff ``a + b e`` times ``R = exp(e)``), by Newton from ``e = (p - a)/(a + b)`` (the
    root of its linearisation ``(1 + e)(a + b e)``, to the right of the root: the left side is
    increasing and convex there, so the iterates fall to it monotonically); on the closing
    piece (``b = 0``) the root ``ln(p/a)``."""
    if b == 0.0:
        return math.log(pressure / a)
    e = (pressure - a) / (a + b)
    for _ in range(60):
        R = math.exp(e)
        g = R * (a + b * e) - pressure
        step = g / (R * (a + b + b * e))
        e -= step
        if abs(step) <= 1e-16 * (1.0 + abs(e)):
            break
    return e


@njit(cache=True, error_model="numpy")
def hydrostat(p, pressure, branch):
    """``(eta, d eta/dp)`` at the Cauchy ``pressure`` (the piece chosen at the pressure
    ``branch``): linear to the locking strain, then the locked modulus; or the compaction
    hydrostat (``crush`` given): ``e`` from :func:`compaction_strain`, ``eta = 1 - exp(-e)``,
    ``d eta/dp = exp(-2e)/(P + dP/de)``."""
    if not math.isnan(p[CRUSH]):
        a, b = compaction_piece(p, branch)
        e = compaction_strain(a, b, pressure)
        inverse_R = math.exp(-e)
        return 1.0 - inverse_R, inverse_R * inverse_R / (a + b * e + b)
    p_lock = p[Q_LOCK]
    if branch < p_lock:
        return pressure / p[BULK], 1.0 / p[BULK]
    return p[ETA] + (pressure - p_lock) / p[LOCKED], 1.0 / p[LOCKED]


@njit(cache=True, error_model="numpy")
def kink_stresses(p):
    """Radial stresses of the comminuted zone's kinks: where the strength below the cap
    (``tau_0 + lam p`` or ``B p^N``) reaches ``tau_max``, where the compaction hydrostat
    crushes (where the crack opening starts closing and where it has closed) and where the
    hydrostat locks (inf: none)."""
    lam, cap = p[LAM], p[TAU_MAX]
    s_cap = np.inf
    if math.isfinite(cap):
        if not math.isnan(p[POWER_B]):
            s_cap = (cap / p[POWER_B]) ** (1.0 / p[POWER_N]) + 2.0 * cap / 3.0
        elif lam > 0.0:
            s_cap = (cap - p[TAU0]) / lam + 2.0 * cap / 3.0
    return (s_cap, _radial_stress(p, opening_pressure(p)), _radial_stress(p, crush_pressure(p)),
            _radial_stress(p, lock_pressure(p)))


@njit(cache=True, error_model="numpy")
def _radial_stress(p, pressure):
    """The comminuted zone's radial stress ``p + 2D/3`` at the pressure ``pressure`` (inf when
    it is 0 or inf: no kink)."""
    if not (pressure > 0.0 and math.isfinite(pressure)):
        return np.inf
    if math.isnan(p[POWER_B]):
        below = p[TAU0] + p[LAM] * pressure
    else:
        below = p[POWER_B] * pressure ** p[POWER_N]
    return pressure + 2.0 * min(below, p[TAU_MAX]) / 3.0


@njit(cache=True, error_model="numpy")
def _flow(p, t, s, U, floor, ceiling):
    """``(dt, ds, dU)/d tau`` of the comminuted zone at ``t = ln xi``, in the variable ``tau``
    with ``d/d tau = m d/d ln xi``, ``m = 1 - phi R_s (xi - U)^2`` the subsonic margin (the
    Sundman transformation that takes the sonic singularity out of the equations):

    .. math:: \\frac{dU}{d\\tau} = -2 \\left(U + \\frac{(\\xi - U) R_s D}{R}\\right), \\qquad
              \\frac{ds}{d\\tau} = -2 D m + \\phi R (\\xi - U) \\frac{dU}{d\\tau}, \\qquad
              \\frac{dt}{d\\tau} = m,

    smooth where the flow turns sonic (``m = 0``: an event, :func:`integrate`). The law's pieces
    are chosen at ``s`` clamped to ``[floor, ceiling]``."""
    D, R, Rs = constitutive(p, s, min(max(s, floor), ceiling))
    gap = math.exp(t) - U
    margin = 1.0 - p[PHI] * Rs * gap * gap
    dU = -2.0 * (U + gap * Rs * D / R)
    return margin, -2.0 * D * margin + p[PHI] * R * gap * dU, dU


@njit(cache=True, error_model="numpy")
def _rk4(p, t, s, U, h, floor=-np.inf, ceiling=np.inf):
    """One classical RK4 step of length ``h`` in ``tau`` (:func:`_flow`); ``(t, s, U)`` after."""
    k1t, k1s, k1u = _flow(p, t, s, U, floor, ceiling)
    k2t, k2s, k2u = _flow(p, t + 0.5 * h * k1t, s + 0.5 * h * k1s, U + 0.5 * h * k1u, floor,
                          ceiling)
    k3t, k3s, k3u = _flow(p, t + 0.5 * h * k2t, s + 0.5 * h * k2s, U + 0.5 * h * k2u, floor,
                          ceiling)
    k4t, k4s, k4u = _flow(p, t + h * k3t, s + h * k3s, U + h * k3u, floor, ceiling)
    return (t + h * (k1t + 2.0 * k2t + 2.0 * k3t + k4t) / 6.0,
            s + h * (k1s + 2.0 * k2s + 2.0 * k3s + k4s) / 6.0,
            U + h * (k1u + 2.0 * k2u + 2.0 * k3u + k4u) / 6.0)


# the events of the integration (:func:`_event`)
KINK, SONIC, WALL = 0, 1, 2


@njit(cache=True, error_model="numpy")
def _event(p, kind, level, t, s, U, floor, ceiling):
    """The event function, negative before the event and ``>= 0`` at and past it: ``s -
    s_kink`` (a kink at ``level``), ``-m`` (the flow turns sonic, the piece's law), ``-t`` (the
    wall ``xi = 1``)."""
    if kind == KINK:
        return s - level
    if kind == SONIC:
        return -_flow(p, t, s, U, floor, ceiling)[0]
    return -t


@njit(cache=True, error_model="numpy")
def _locate(p, t, s, U, h, kind, level, floor, ceiling):
    """The part of the RK4 step from ``(t, s, U)`` (length ``h`` in ``tau``) that ends at the
    event ``kind`` (:func:`_event`, negative at the start, ``>= 0`` at the step's end); returns
    ``(length, t, s, U)`` there.

    The length ``l`` solves ``g(y_l) = 0``, ``y_l`` the RK4 update over the length ``l`` (a
    polynomial in ``l`` where the law is smooth, so the event is placed to the order of the
    step): Illinois regula falsi on the bracket ``(0, h)``, the end past the event kept
    (``g >= 0``), to ``|bracket| <= 4 eps |h|``; the state is the one at that end."""
    lo, hi = 0.0, h
    f_lo = _event(p, kind, level, t, s, U, floor, ceiling)
    t_hi, s_hi, U_hi = _rk4(p, t, s, U, h, floor, ceiling)
    f_hi = _event(p, kind, level, t_hi, s_hi, U_hi, floor, ceiling)
    kept = 0  # the end kept by the last update: -1 lo, +1 hi
    for _ in range(200):
        if abs(hi - lo) <= 4.0 * EPS * abs(h):
            break
        mid = 0.5 * (lo + hi)
        if f_hi > f_lo:
            secant = hi - f_hi * (hi - lo) / (f_hi - f_lo)
            if min(lo, hi) < secant < max(lo, hi):
                mid = secant
        t_mid, s_mid, U_mid = _rk4(p, t, s, U, mid, floor, ceiling)
        f_mid = _event(p, kind, level, t_mid, s_mid, U_mid, floor, ceiling)
        if f_mid < 0.0:  # before the event (False for NaN)
            lo, f_lo = mid, f_mid
            if kept == 1:
                f_hi *= 0.5
            kept = 1
        else:
            hi, t_hi, s_hi, U_hi, f_hi = mid, t_mid, s_mid, U_mid, f_mid
            if f_mid == 0.0:
                break
            if kept == -1:
                f_lo *= 0.5
            kept = -1
    return hi, t_hi, s_hi, U_hi


@njit(cache=True, error_model="numpy")
def _ceiling(kinks, branch):
    """Just below the first kink above the stress ``branch`` (inf: none): a trial step's law
    pieces are chosen at most there, so that no RK4 stage of a step that ends below the kink
    uses the pieces above it (past the cap the flow can be sonic: a stage that overshoots the
    kink would otherwise stop the step as if the flow turned sonic below it)."""
    kink = np.inf
    for s_kink in kinks:
        if branch < s_kink < kink:
            kink = s_kink
    return kink - 1e-12 * (1.0 + abs(kink)) if math.isfinite(kink) else np.inf


MAX_SHOCKS = 4  # compaction shocks inside the comminuted zone at most
MAX_STEP_FACTOR = 64  # RK4 steps in tau at most, in units of ``steps`` (then no solution)


@njit(cache=True, error_model="numpy")
def integrate(p, beta, s, U, steps):
    """RK4 from ``xi = beta`` to the wall ``xi = 1``; returns ``(s, U)`` there.

    The steps are uniform in ``tau`` (:func:`_flow`: ``d ln xi = m d tau``, ``m`` the subsonic
    margin), of length ``h = -ln(beta)/steps``: ``steps`` steps where the flow is far from sonic
    (``m`` near 1), shorter in ``ln xi`` as it nears sonic, where the solution in ``ln xi``
    turns singular (``s`` like the square root of the distance to the sonic point) or stiff
    (eigenvalues of the Jacobian like ``1/m``) and a step of fixed length in ``ln xi`` loses
    the order. The count is ``int d ln xi / (m |h|)``, finite at a sonic point (``m`` like a
    square root there).

    Events, each located in its step by :func:`_locate` (regula falsi on the step length, to
    the order of the step), the step split there and continued from it:

    - ``s`` reaches a kink (:func:`kink_stresses`): the part before with the law's pieces below
      the kink, the rest with those above, so that RK4 never differentiates across a kink;
    - the flow turns sonic (``m = 0``: the compaction cannot keep up continuously): a
      compaction shock is put there (:func:`jump`, strong root), also where ``m <= 0`` at the
      start of a piece (past a kink whose pieces above are supersonic); at most
      :data:`MAX_SHOCKS`;
    - the wall ``ln xi = 0``: the end.

    NaN where a step is not finite (no admissible state) or the wall is not reached within
    :data:`MAX_STEP_FACTOR` ``steps``.
    """
    t = math.log(beta)
    h = -t / steps
    kinks = (p[S_CAP], p[S_OPEN], p[S_CRUSH], p[S_LOCK])
    ordered = np.sort(np.array(kinks))
    shocks = 0
    for _ in range(MAX_STEP_FACTOR * steps):
        rest = h
        floor = -np.inf
        for _ in range(16):  # pieces of this step: kinks, sonic points
            if rest >= -1e-15 * abs(h):
                break
            ceiling = _ceiling(kinks, max(s, floor))
            if _flow(p, t, s, U, floor, ceiling)[0] <= 0.0:  # sonic: a compaction shock
                shocks += 1
                if shocks > MAX_SHOCKS:
                    return np.nan, np.nan
                s, U = jump(p, math.exp(t), s, U, constitutive(p, s, max(s, floor))[1], True)
                if not math.isfinite(s):
                    return np.nan, np.nan
                continue
            t_new, s_new, U_new = _rk4(p, t, s, U, rest, floor, ceiling)
            if not (math.isfinite(t_new) and math.isfinite(s_new) and math.isfinite(U_new)):
                return np.nan, np.nan
            part, kind, level = rest, -1, 0.0
            end = (t_new, s_new, U_new)
            for s_kink in ordered:  # the first kink met
                if s < s_kink < s_new:
                    part, t_e, s_e, U_e = _locate(p, t, s, U, rest, KINK, s_kink, floor,
                                                  ceiling)
                    kind, level, end = KINK, s_kink, (t_e, s_e, U_e)
                    break
            for other in (SONIC, WALL):  # the sonic point or the wall, if met first
                if _event(p, other, 0.0, t_new, s_new, U_new, floor, ceiling) >= 0.0:
                    length, t_e, s_e, U_e = _locate(p, t, s, U, rest, other, 0.0, floor,
                                                    ceiling)
                    if abs(length) < abs(part) or kind < 0:
                        part, kind, end = length, other, (t_e, s_e, U_e)
            t, s, U = end
            rest -= part
            if kind == WALL:
                return s, U
            if kind == KINK:
                floor = level + 1e-12 * (1.0 + abs(level))
    return np.nan, np.nan


@njit(cache=True, error_model="numpy")
def _jump_balance(p, beta, j, s_ahead, U_ahead, s):
    """Momentum balance across the front, ``s - s^+ - phi j (U^-(s) - U^+)``, with
    ``U^-(s) = beta - j/R(s)`` from the mass balance (NaN past full compaction)."""
    R = constitutive(p, s)[1]
    return s - s_ahead - p[PHI] * j * (beta - j / R - U_ahead)


@njit(cache=True, error_model="numpy")
def jump(p, beta, s_ahead, U_ahead, R_ahead, strong=False):
    """State ``(s, U)`` just behind a front at ``xi = beta`` (Rankine-Hugoniot).

    The mass flux ``j = R^+ (beta - U^+)`` fixes the Rayleigh line; the state behind is its first
    intersection with the comminuted hydrostat going up from ``s^+`` (where the Rayleigh line
    crosses from above, the flow behind is subsonic): the continuous state when the front is
    slower than the compaction wave, else the compaction shock. ``strong``: the ahead state is
    comminuted material at its sonic point (then ``s^+`` itself is a root, tangent); the next
    intersection up is returned.
    """
    j = R_ahead * (beta - U_ahead)
    if not j > 0.0:
        return np.nan, np.nan
    scale = 1.0 + abs(s_ahead)
    lo = s_ahead
    if strong:
        lo += 1e-9 * scale
    f_lo = _jump_balance(p, beta, j, s_ahead, U_ahead, lo)
    if f_lo > 0.0:
        D, R, Rs = constitutive(p, lo)
        if strong and p[PHI] * j * j * Rs < R * R:  # subsonic after all: no shock
            return s_ahead, U_ahead
        step = 1e-9 * scale
        if p[PHI] * j * j * Rs < R * R:  # subsonic: the root lies just below (rarefying)
            while f_lo > 0.0:
                lo -= step
                step *= 2.0
                f_lo = _jump_balance(p, beta, j, s_ahead, U_ahead, lo)
                if not math.isfinite(f_lo) or step > 1e3 * scale:
                    return np.nan, np.nan
        else:  # supersonic: the balance dips below zero further up (compaction shock)
            while f_lo > 0.0:
                lo += step
                step *= 2.0
                f_lo = _jump_balance(p, beta, j, s_ahead, U_ahead, lo)
                if not math.isfinite(f_lo) or step > 1e6 * scale:
                    return np.nan, np.nan
    hi, f_hi = lo, f_lo
    step = 1e-6 * scale
    while f_hi <= 0.0:
        lo, f_lo = hi, f_hi
        hi = lo + step
        step *= 2.0
        f_hi = _jump_balance(p, beta, j, s_ahead, U_ahead, hi)
        if not math.isfinite(f_hi):
            return np.nan, np.nan
    for _ in range(200):  # Illinois regula falsi
        mid = hi - f_hi * (hi - lo) / (f_hi - f_lo)
        f_mid = _jump_balance(p, beta, j, s_ahead, U_ahead, mid)
        if f_mid * f_hi < 0.0:
            lo, f_lo = hi, f_hi
        else:
            f_lo *= 0.5
        hi, f_hi = mid, f_mid
        if f_mid == 0.0 or abs(hi - lo) <= 4e-16 * abs(hi):
            break
    return hi, beta - j / constitutive(p, hi)[1]


@njit(cache=True, error_model="numpy")
def wall_residual(p, beta, s_ahead, U_ahead, R_ahead, steps, opening=0.0):
    """``(U(1) - 1, s(1))``: the front at ``beta`` with the state ahead, then the comminuted
    zone to the wall (:func:`jump`, :func:`integrate`); the comminuted material carries the
    crack opening ``opening`` (:func:`set_opening`)."""
    set_opening(p, opening)
    s0, U0 = jump(p, beta, s_ahead, U_ahead, R_ahead)
    s1, U1 = integrate(p, beta, s0, U0, steps)
    return U1 - 1.0, s1


@njit(cache=True, error_model="numpy")
def _elastic_ahead(p, beta, C, steps):
    """Wall ``(U(1) - 1, s(1), C)`` with the elastic state of amplitude ``C`` ahead of
    ``beta``."""
    s_a, D_a, U_a, F_a, dF_a, ev_a = elastic_state(p, C, beta)
    residual, S = wall_residual(p, beta, s_a, U_a, 1.0 / (1.0 + ev_a), steps)
    return residual, S, C


@njit(cache=True, error_model="numpy")
def elastic_plastic(p, beta, steps):
    """Wall ``(U(1) - 1, s(1), C)`` with the elastic zone, at yield, directly ahead of
    ``beta``."""
    return _elastic_ahead(p, beta, yield_amplitude(p, beta), steps)


@njit(cache=True, error_model="numpy")
def cracking_plastic(p, beta, steps):
    """Wall ``(U(1) - 1, s(1), C)`` with the crack and comminution fronts together at ``beta``:
    the elastic state ahead has the hoop stress ``-f_t/f_c`` (the limit of a cracked zone of
    vanishing width)."""
    C = crack_amplitude(p, beta)
    if not C <= yield_amplitude(p, beta):  # the elastic state would yield before cracking
        return np.nan, np.nan, C
    return _elastic_ahead(p, beta, C, steps)


@njit(cache=True, error_model="numpy")
def superseismic(p, beta, steps):
    """Wall ``(U(1) - 1, s(1))`` of a plastic front into undisturbed concrete."""
    return wall_residual(p, beta, 0.0, 0.0, 1.0, steps)


@njit(cache=True, error_model="numpy")
def cracked_front(p, gamma):
    """``(beta, s, U, eps_v, C)`` at the plastic front of the cracked solution with the crack
    front at ``gamma`` (``beta = nan`` when it does not lie in ``(1, gamma)``)."""
    e, phi, wb, t, nu = p[E_], p[PHI], p[WB], p[TENSILE], 0.5 * p[E_] / p[MU] - 1.0
    C = crack_amplitude(p, gamma)
    s_e, D_e, U_e, F_e, dF_e, ev_e = elastic_state(p, C, gamma)
    stiff = e - phi * gamma * gamma
    if not (0.0 < C <= yield_amplitude(p, gamma) and stiff > 0.0):
        return np.nan, 0.0, 0.0, 0.0, C
    # cracked: s = -e F' - 2 nu t (the hoop stress held at -t), F' = K1 (1/xi^2 - wb^2) + c
    c = t * (1.0 - 2.0 * nu) / e
    dF_c = -(s_e + 2.0 * nu * t + phi * gamma * gamma * dF_e) / stiff
    K1 = (dF_c - c) / (1.0 / gamma ** 2 - wb ** 2)
    K0 = F_e + K1 * (1.0 / gamma + wb ** 2 * gamma) - c * gamma
    s_yield = cracked_yield(p)
    inverse_square = wb ** 2 - (s_yield + t) / (e * K1)
    if not (K1 < 0.0 and inverse_square > 0.0):
        return np.nan, 0.0, 0.0, 0.0, C
    beta = 1.0 / math.sqrt(inverse_square)
    if not (1.0 < beta < gamma):
        return np.nan, 0.0, 0.0, 0.0, C
    F = K0 - K1 * (1.0 / beta + wb ** 2 * beta) + c * beta
    dF = K1 * (1.0 / beta ** 2 - wb ** 2) + c
    return beta, s_yield, K0 - 2.0 * K1 / beta, dF + 2.0 * F / beta, C


@njit(cache=True, error_model="numpy")
def cracked_yield(p):
    """Radial stress at which the cracked material (hoop stress ``-t``) comminutes: on the
    Mohr-Coulomb line, ``s + t = tau_0 + lam (s - 2t)/3``, i.e. ``s = 1 - N t`` with ``N =
    (3 + 2 lam)/(3 - lam)``, or on the cap, ``s + t = tau_max``, whichever is lower."""
    t, lam = p[TENSILE], p[LAM]
    return min(1.0 - t * (3.0 + 2.0 * lam) / (3.0 - lam), p[TAU_MAX] - t)


@njit(cache=True, error_model="numpy")
def cracked(p, gamma, steps):
    """Wall ``(U(1) - 1, s(1), beta, C)`` of the cracked solution with crack front ``gamma``."""
    beta, s_a, U_a, ev_a, C = cracked_front(p, gamma)
    if not beta > 1.0:
        return np.nan, np.nan, beta, C
    residual, S = wall_residual(p, beta, s_a, U_a, 1.0 / (1.0 + ev_a), steps,
                                crack_opening(p, s_a, ev_a))
    return residual, S, beta, C


@njit(cache=True, error_model="numpy")
def crack_opening(p, s, eps_v):
    """The crack opening (plastic volumetric strain, tension positive) of cracked material at
    radial stress ``s`` and volumetric strain ``eps_v``: ``eps_v`` less the elastic part
    ``(1 - 2 nu)(2t - s)/e`` (hoop stress ``-t``)."""
    e, t = p[E_], p[TENSILE]
    nu = 0.5 * e / p[MU] - 1.0
    return eps_v - (1.0 - 2.0 * nu) * (2.0 * t - s) / e


# ------------------------------------------------------------------------------------------
# Root finding (Python: brentq on the compiled residuals)
# ------------------------------------------------------------------------------------------

XTOL = 1e-14
BRACKET_POINTS = 96
EDGE_HALVINGS = 50
REFINE_DEPTH = 8  # NaN pockets cut out of one bracket at most
# |U(1) - 1| accepted at a root. Brent's bracket of 1e-14 leaves ~1e-13 at a root; where the
# residual jumps across zero it stays at the size of the jump: large jumps (measured 0.47-3.97,
# the front's state changing branch) are no root, small ones (measured 2e-3 and 3e-2: 98.8 MPa,
# phi = 40.9, joint front; 139.6 MPa, phi = 26.3, cracked) are kept as the old solver kept
# them, their U(1) - 1 in the solution (CavitySolution.residual)
RESIDUAL_TOLERANCE = 0.1
# The scan's sign tests (grid and edges) run the residual at SCAN_STEPS RK4 steps first and
# take its sign where it lies at least SCAN_MARGIN from zero, else the residual at the
# solution's steps (:func:`_screened`); Brent's method always runs on the latter.
SCAN_STEPS = 64
SCAN_MARGIN = 0.1


class NoSolution(CavexNumericalError):
    """No self-similar solution at this ``phi``: no structure's wall condition ``U(1) = 1`` has
    a root over its admissible front speeds. :attr:`reasons` says, per structure tried, why
    (:func:`_reason`: no admissible front, or ``U(1) - 1`` of one sign over all of them)."""

    def __init__(self, message, reasons):
        super().__init__(message)
        self.reasons = reasons


class _NaNResidual(Exception):
    """The residual is NaN (no admissible state) at a point Brent's method asked for."""


class _ScreenMismatch(Exception):
    """The residual has one sign at both ends of a bracket whose screened values
    (:func:`_screened`) changed sign: the scan is run again unscreened."""


def _finite_edge(residual, finite, beyond, halvings=EDGE_HALVINGS):
    """Bisect between a finite ``(x, value)`` and ``beyond`` (NaN there) for a point of the other
    sign near the edge of the finite part; ``(x, value)`` or None."""
    x0, v0 = finite
    x1 = beyond
    for _ in range(halvings):
        mid = 0.5 * (x0 + x1)
        value = residual(mid)
        if not math.isfinite(value):
            x1 = mid
        elif value * v0 <= 0.0:
            return mid, value
        else:
            x0 = mid
    return None


def _brent(residual, a, b):
    """Brent's method (scipy ``brentq``, ``xtol = rtol = XTOL``) on a sign change; raises
    :class:`_NaNResidual` (with the point) where the residual is NaN and
    :class:`_ScreenMismatch` where it has one sign at both ends."""
    from scipy.optimize import brentq

    def finite(x):
        value = residual(x)
        if not math.isfinite(value):
            raise _NaNResidual(x)
        return value

    try:
        return brentq(finite, a, b, xtol=XTOL, rtol=XTOL, maxiter=200)
    except ValueError as exc:  # f(a) and f(b) of one sign (brentq's only ValueError here)
        raise _ScreenMismatch(a, b) from exc


def _last_finite(residual, finite, nan, halvings=EDGE_HALVINGS):
    """``(x, value)``: the finite point next to the NaN one ``nan``, by bisection between a finite
    ``(x, value)`` and ``nan`` on whether the residual is finite."""
    (x0, v0), x1 = finite, nan
    for _ in range(halvings):
        mid = 0.5 * (x0 + x1)
        value = residual(mid)
        if math.isfinite(value):
            x0, v0 = mid, value
        else:
            x1 = mid
    return x0, v0


def _refine(residual, lower, upper, depth=0):
    """The first root (going outward) in the bracket ``lower = (a, f(a))``, ``upper = (b, f(b))``
    (``f(a) f(b) <= 0``), or None. Brent's method, its root kept where ``|f| <=``
    :data:`RESIDUAL_TOLERANCE` (not at a jump of ``f`` across zero); where it meets a NaN at
    ``c`` inside the bracket, the NaN pocket around ``c`` is cut out (its finite edges
    ``c_-``, ``c_+`` by bisection) and the sign change is refined in ``(a, c_-)`` or
    ``(c_+, b)``; None when it lies inside the pocket (to :data:`REFINE_DEPTH` pockets)."""
    (a, fa), (b, fb) = lower, upper
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    try:
        root = _brent(residual, a, b)
    except _NaNResidual as exc:
        c = exc.args[0]
    else:  # a jump of the residual across zero is no root (the front's state changes branch)
        return root if abs(residual(root)) <= RESIDUAL_TOLERANCE else None
    if depth >= REFINE_DEPTH:
        return None
    left = _last_finite(residual, lower, c)
    if left[1] * fa <= 0.0:
        return _refine(residual, lower, left, depth + 1)
    right = _last_finite(residual, upper, c)
    if right[1] * fb <= 0.0:
        return _refine(residual, right, upper, depth + 1)
    return None


def _screened(residual, coarse):
    """``residual`` for the scan's sign tests: ``coarse(x)`` (the same residual at
    :data:`SCAN_STEPS` RK4 steps, a quarter of the cost) where it is finite and at least
    :data:`SCAN_MARGIN` from zero, else ``residual(x)``. The two differ by the step error
    (measured up to 1e-3 of the value, where ``U(1) - 1`` is large) and by the discrete events
    of the integration (a compaction shock placed at another step: measured up to 0.012 at a
    value of -8.5e-4, where the scan then asks ``residual``)."""
    def value(x):
        v = coarse(x)
        if math.isfinite(v) and abs(v) >= SCAN_MARGIN:
            return v
        return residual(x)
    return value


def _roots(residual, lo, hi, summary=None, points=BRACKET_POINTS, screen=None):
    """The roots of ``residual`` in ``(lo, hi)`` going outward (a generator); the finite values
    met on the grid are appended to the list ``summary`` (if given). ``screen`` (default
    ``residual``) gives the grid's and the edges' values, of which only the sign and
    finiteness are used (:func:`_screened`).

    Scans a grid of ``points`` geometric in ``xi``; each sign change between consecutive finite
    values (across NaN points too) is refined (:func:`_refine`). Where the residual turns NaN
    (no admissible state) or finite again, the edge of the finite part is bisected for a sign
    change hidden between the grid point and the edge (:func:`_finite_edge`).
    """
    screen = residual if screen is None else screen
    previous = None  # last finite (x, value)
    previous_nan = None  # last NaN grid point, if after the last finite one
    for x in np.geomspace(lo, hi, points):
        value = screen(x)
        if not math.isfinite(value):
            if previous is not None and previous_nan is None:  # finite -> NaN
                edge = _finite_edge(screen, previous, x)
                if edge is not None:
                    root = _refine(residual, previous, edge)
                    if root is not None:
                        yield root
            previous_nan = x
            continue
        if summary is not None:
            summary.append(value)
        if previous_nan is not None:  # NaN -> finite
            edge = _finite_edge(screen, (x, value), previous_nan)
            if edge is not None:
                root = _refine(residual, edge, (x, value))
                if root is not None:
                    yield root
                    edge = None
            if edge is None and previous is not None and value * previous[1] <= 0.0:
                root = _refine(residual, previous, (x, value))  # across the NaN points
                if root is not None:
                    yield root
        elif previous is not None and value * previous[1] <= 0.0:
            root = _refine(residual, previous, (x, value))
            if root is not None:
                yield root
        previous, previous_nan = (x, value), None


def _root(structure, p, steps, lo, hi, summary=None):
    """The first front speed ``x`` in ``(lo, hi)``, going outward, at which ``structure``'s
    wall condition holds (:func:`_roots` of ``structure(p, x, steps)[0]``, screened at
    :data:`SCAN_STEPS`): ``(x, structure(p, x, steps))``, or None. Each ``x`` is integrated
    once (Brent's last point is the root, which :func:`_refine` checks again)."""
    memo = {}

    def solution(x):
        if x not in memo:
            memo[x] = structure(p, x, steps)
        return memo[x]

    def residual(x):
        return solution(x)[0]

    if steps > SCAN_STEPS:
        screen = _screened(residual, lambda x: structure(p, x, SCAN_STEPS)[0])
        values = []
        try:
            root = next(_roots(residual, lo, hi, values, screen=screen), None)
        except _ScreenMismatch:  # the scan is run again unscreened
            root = next(_roots(residual, lo, hi, summary), None)
        else:
            if summary is not None:
                summary.extend(values)
    else:
        root = next(_roots(residual, lo, hi, summary), None)
    return None if root is None else (root, solution(root))


def _reason(values):
    """Why a structure's scan found no root, from its finite grid values of ``U(1) - 1``."""
    if not values:
        return "no admissible front speed (no state ahead that the front can satisfy)"
    if max(values) < 0.0:
        return (f"the wall lags the cavity at every admissible front speed "
                f"(U(1) - 1 in [{min(values):.3g}, {max(values):.3g}])")
    if min(values) > 0.0:
        return (f"the wall outruns the cavity at every admissible front speed "
                f"(U(1) - 1 in [{min(values):.3g}, {max(values):.3g}])")
    return "U(1) - 1 changes sign but no root could be evaluated (numerical failure)"


def _upper_front(p):
    """Largest admissible front (the elastic wave front ``1/w``; 1e4 when ``w = 0``)."""
    return (1.0 / p[W]) * (1.0 - 1e-12) if p[W] > 0.0 else 1e4


def solve(material, phi, steps=DEFAULT_STEPS):
    """The self-similar solution at ``phi = rho V^2 / f_c`` (see the module docstring).

    Raises
    ------
    NoSolution
        No structure's wall condition has a root on its scan (the reason per structure in
        ``reasons``).
    CavexNumericalError
        A structure's wall condition changes sign but no root could be evaluated, at ``steps``
        nor at 2 and 4 times as many RK4 steps (tried in turn: the NaN pockets of the residual
        move with the step count).
    """
    require(is_finite_number(phi) and phi >= 0.0, "phi", "rho V^2/f_c, a finite number >= 0", phi)
    try:
        return _solve(material, float(phi), int(steps))
    except NoSolution:
        raise
    except CavexNumericalError as failure:
        # a root inside a NaN pocket of the residual (front speeds without an admissible state
        # or integration, issue 30: a sonic point placed by the step's finiteness, before the
        # integration in tau): such pockets move with the step count, the root does not
        # (within the step tolerance, docs/concrete.md "Root finding"): finer counts are tried
        for finer in (2 * int(steps), 4 * int(steps)):
            try:
                return _solve(material, float(phi), finer)
            except CavexNumericalError:
                continue
        raise failure


@lru_cache(maxsize=65536)
def _solve(material, phi, steps):
    p = material.parameters(phi)
    upper = _upper_front(p)
    reasons = {}
    values = []
    found = _root(elastic_plastic, p, steps, 1.0 + 1e-6, upper, values)
    if found is not None:
        beta, (residual, S, C) = found
        s_a, D_a = elastic_state(p, C, beta)[:2]
        if s_a - D_a >= -p[TENSILE] * (1.0 + 1e-12):
            return CavitySolution(S, phi, ELASTIC_PLASTIC, beta, math.nan, C, residual)
        reasons[ELASTIC_PLASTIC] = "the elastic hoop stress at the front exceeds f_t (cracks)"
    else:
        reasons[ELASTIC_PLASTIC] = _reason(values)
    if math.isfinite(p[TENSILE]):
        gamma_hi = min(upper, (1.0 / p[WB]) * (1.0 - 1e-12) if p[WB] > 0.0 else 1e6)
        values = []
        found = _root(cracked, p, steps, 1.0 + 1e-6, gamma_hi, values)
        if found is not None:
            gamma, (residual, S, beta, C) = found
            return CavitySolution(S, phi, CRACKED, beta, gamma, C, residual)
        reasons[CRACKED] = _reason(values)
        values = []
        found = _root(cracking_plastic, p, steps, 1.0 + 1e-6, upper, values)
        if found is not None:
            beta, (residual, S, C) = found
            return CavitySolution(S, phi, JOINT_FRONT, beta, beta, C, residual)
        reasons[JOINT_FRONT] = _reason(values)
    if p[W] > 0.0:
        values = []
        found = _root(superseismic, p, steps, 1.0 / p[W], 1e4, values)
        if found is not None:
            beta, (residual, S) = found
            return CavitySolution(S, phi, SUPERSEISMIC, beta, math.nan, math.nan, residual)
        reasons[SUPERSEISMIC] = _reason(values)
    text = "; ".join(f"{STRUCTURES[k]}: {v}" for k, v in reasons.items())
    message = (f"no self-similar concrete cavity solution at rho V^2/f_c = {phi:g} ({material}): "
               f"{text}")
    if any("numerical failure" in v for v in reasons.values()):
        raise CavexNumericalError(message)
    raise NoSolution(message, reasons)


def wall_stress(material, phi, steps=DEFAULT_STEPS):
    """``S = sigma_r(a)/f_c`` for an array (or scalar) of ``phi = rho V^2/f_c``."""
    phi = np.asarray(phi, dtype=float)
    out = np.array([solve(material, float(x), steps).S for x in phi.reshape(-1)])
    return float(out[0]) if phi.ndim == 0 else out.reshape(phi.shape)


def resistance_table(material, phi_max, points=17, steps=DEFAULT_STEPS):
    """``(phi, S)`` at ``phi = phi_max (i/(points - 1))^2``, ``i = 0 .. points - 1`` (uniform
    in ``V``)."""
    require(is_finite_number(phi_max) and phi_max > 0.0, "phi_max", "a finite number > 0",
            phi_max)
    phi = phi_max * np.linspace(0.0, 1.0, points) ** 2
    return phi, wall_stress(material, phi, steps)


def fit_AB(phi, S):
    """``(A, B)`` of ``S ~ A + B phi``: ``A = S(0)`` (the quasi-static solution, ``phi[0]``
    must be 0) and ``B`` by least squares of ``S - A`` on ``phi``."""
    phi, S = np.asarray(phi, dtype=float), np.asarray(S, dtype=float)
    require(phi[0] == 0.0, "phi", "a table starting at 0", phi[0])
    A = float(S[0])
    return A, float(np.dot(phi, S - A) / np.dot(phi, phi))
