r"""Predicted penetration depth into thick concrete from the concrete cavity expansion.

From a shot's columns (``f_c``, ``rho``, projectile mass, diameter, CRH, ``V0``) to a depth:

1. **Material** (:func:`concrete_cavity`), every parameter from a published correlation with
   ``f_c`` (and ``rho``), none fitted to the shots unless :class:`Constants` says so:

   - ``E = 0.043 rho^1.5 sqrt(f_c)`` (MPa; ACI 318-19, 19.2.2.1a), ``nu = 0.2`` (EN 1992-1-1);
   - ``f_t = 0.3 (f_c - 8)^(2/3)`` for ``f_c <= 58`` MPa, ``2.12 ln(1 + f_c/10)`` above (fib
     Model Code 2010, Eq. 5.1-3, with ``f_ck = f_cm - 8`` MPa);
   - comminuted strength ``D = tau_0 + lam p`` with ``lam = 3 (k - 1)/(k + 2)``, ``k = 4.1``
     (Richart, Brandtzaeg and Brown 1928: ``f_cc = f_c + 4.1 f_l``) and ``tau_0 = f_c (1 -
     lam/3)`` (the line passes through the uniaxial strength), capped at ``tau_max = S_max f_c``,
     ``S_max = 7`` (Holmquist, Johnson and Cook 1993, HJC);
   - hydrostat of HJC (1993): compaction linear to the locking strain ``mu_l = 0.1``
     (``eta_l = mu_l/(1 + mu_l)``) at the locking pressure ``p_l = 0.8`` GPa, so ``K = p_l/eta_l``;
     then the solid's ``K_1 = 85`` GPa (the ``concrete`` model of ``cavex validate`` takes the
     locking strain from the porosity law instead, its option chosen on the development shots:
     :mod:`cavex.analytic.models.concrete`).
2. **Resistance** (:class:`TableResistance`): the wall stress ``sigma_r(V) = f_c S(rho V^2/f_c)``
   of :mod:`cavex.analytic.concrete_cavity`, tabulated once per concrete (``f_c``, ``rho``) at
   33 velocities uniform in ``V`` up to ``phi = 16 2^n`` (:func:`material_table`, shared by all
   the shots into that concrete), the smallest such top above the fastest wall the nose
   meets (:func:`fastest_wall`, ``V0 cos phi_0``: the wall stress at ``V0`` itself is never
   asked) and interpolated (PCHIP in ``V``), integrated over the tangent
   ogive by cavex's nose quadrature (:func:`cavex.analytic.penetration.nose.nose_rule`); the
   fitted ``A, B`` (:func:`cavex.analytic.concrete_cavity.fit_AB`) are reported, the depth uses
   the table. Reused: the table per (concrete, top) here, the cavity solution per
   (material, ``phi``) in :mod:`~cavex.analytic.concrete_cavity`.
3. **Depth**: a crater of ``k d`` with Li and Chen's (2003) ``k = 0.707 + h/d`` (``h`` the nose
   length; ``k = 2.03`` at CRH 2, Forrestal's two calibres), force ``c z`` continuous with the
   tunnel force at ``z = k d`` (:func:`cavex.analytic.penetration.integrator.crater_exit`),
   then cavex's tunnel integrator (:func:`cavex.analytic.penetration.integrator.penetrate`)
   from ``V_1``; a projectile that stops in the crater reaches ``sqrt(m V0^2 k d / F(0))``.

Li and Chen's (2003) empirical model (Forrestal's form with ``S = 72 f_c^-0.5``, the same
crater) is :func:`li_chen_depth`. Rigid-regime flag (:func:`rigid_flag`): a shot is flagged
``non-rigid`` when the mean nose pressure at impact ``F(V0)/(pi a^2)`` of the model exceeds the
projectile's listed yield strength (the nose then deforms, which no model here covers; its
abrasion is :mod:`cavex.analytic.penetration.erosion`, with :func:`table_depth`'s
``erosion``); flagged shots stay in every table.
"""

import math
from functools import lru_cache

import numpy as np
from scipy.interpolate import PchipInterpolator

from cavex.analytic.concrete_cavity import ConcreteCavity, NoSolution, fit_AB, wall_stress
from cavex.analytic.empirical import crater_calibres
from cavex.analytic.penetration.integrator import ATOL, RTOL, crater_exit, penetrate
from cavex.analytic.penetration.nose import QUADRATURE_POINTS, nose_rule
from cavex.concrete import Concrete, Constants
from cavex.errors import CavexNumericalError
from cavex.materials import Material, Projectile, Target

TABLE_POINTS = 33
PHI_TOP = 16.0  # smallest table top (rho V^2/f_c)


def concrete_cavity(fc, rho, constants=None):
    """The :class:`~cavex.analytic.concrete_cavity.ConcreteCavity` of ``(f_c, rho)``
    (:meth:`cavex.concrete.Concrete.cavity_parameters`)."""
    return ConcreteCavity(**Concrete(fc, rho, constants or Constants()).cavity_parameters())


def _ogive(shot):
    """The shot's tangent-ogive projectile (``cavex.analytic.models.shots.shot_projectile``,
    one floor up)."""
    return Projectile.tangent_ogive(shot.mass, shot.diameter, shot.crh, shot.V0)


def fastest_wall(shot):
    """The fastest cavity wall the nose can meet (m/s): the normal velocity at the tip of the
    tangent ogive at ``V0``, ``V0 cos phi_0``, ``sin phi_0 = (R - r)/R = 1 - 1/(2 psi)``
    (0.661 ``V0`` at CRH 2). Every element of the nose rule is less steep, so its table
    reaches every wall velocity the flight asks for, at any number of nose points."""
    return shot.V0 * math.sqrt(1.0 - (1.0 - 0.5 / shot.crh) ** 2)


def shot_table_top(shot):
    """The table top ``shot`` uses (:func:`table_top` of ``rho`` :func:`fastest_wall`
    ``^2/f_c``)."""
    return table_top(shot.rho * fastest_wall(shot) ** 2 / shot.fc)


def table_top(phi):
    """Top of the table that covers ``phi``: ``PHI_TOP 2^n``, the smallest such >= ``phi``
    (so that shots into one concrete share a few tables)."""
    return PHI_TOP * 2.0 ** max(0, math.ceil(math.log2(max(phi, 1e-300) / PHI_TOP)))


#: a table node in the band without a self-similar solution moves up by this fraction of its
#: phi at a time, at most BAND_STEPS times (the bands are 0.9-1.5 % of phi wide:
#: results/concrete/no_solution_band.md)
BAND_STEP = 0.0025
BAND_STEPS = 20


@lru_cache(maxsize=4096)
def material_table(material, top, points=TABLE_POINTS):
    """``(phi, S)`` of ``material`` at ``phi = top (i/(points - 1))^2`` (uniform in ``V``),
    computed once per material and top and shared by every shot that uses it.

    A node that falls in the narrow band of ``phi`` where the cavity has no self-similar
    solution (where the comminution front reaches the elastic wave: docs/concrete.md "What is
    left") moves up past it, to the first ``phi (1 + k BAND_STEP)`` that has one (still below
    the next node; the top node may move above ``top``, so the table still covers it); the
    interpolant then bridges the band, across which ``S`` continues its line to 0.11 %
    (``results/concrete/no_solution_band.md``). A node that cannot move past it raises
    :class:`~cavex.analytic.concrete_cavity.NoSolution`."""
    phi = top * np.linspace(0.0, 1.0, points) ** 2
    S = np.empty_like(phi)
    for i, node in enumerate(phi):
        phi[i], S[i] = _solved_node(material, float(node),
                                    phi[i + 1] if i + 1 < points else np.inf)
    phi.setflags(write=False)
    S.setflags(write=False)
    return phi, S


def _solved_node(material, node, below):
    """``(phi, S)`` at ``node``, or at the first ``node (1 + k BAND_STEP) < below`` with a
    self-similar solution (:func:`material_table`)."""
    try:
        return node, wall_stress(material, node)
    except NoSolution as exc:
        first = exc
    for k in range(1, BAND_STEPS + 1):
        moved = node * (1.0 + k * BAND_STEP)
        if moved >= below:
            break
        try:
            return moved, wall_stress(material, moved)
        except NoSolution:
            continue
    raise first


class TableResistance:
    """Nose force of a one-layer concrete target from the tabulated cavity wall stress.

    Has the integrator's interface (``force``, ``label``, ``crater_force``); the force does not
    depend on the depth (thick target). ``A, B`` are :func:`fit_AB` over the table up to the
    fastest wall the nose meets, ``phi_max = rho`` :func:`fastest_wall` ``^2/f_c`` (at least
    its first three points).
    """

    def __init__(self, shot, constants=None, *, table_points=TABLE_POINTS,
                 nose_points=QUADRATURE_POINTS):
        self.shot = shot
        self.material = concrete_cavity(shot.fc, shot.rho, constants)
        self._cosines, self._weights = nose_rule(_ogive(shot), nose_points)
        self.top_velocity = fastest_wall(shot)
        self.phi_max = shot.rho * self.top_velocity ** 2 / shot.fc
        try:
            phi, self.S = material_table(self.material, table_top(self.phi_max), table_points)
        except CavexNumericalError as exc:  # a failed node: every shot into this concrete
            raise CavexNumericalError(
                f"concrete f_c = {shot.fc / 1e6:g} MPa, rho = {shot.rho:g} kg/m^3: its cavity "
                f"table fails, so does every shot into it: {exc}") from exc
        used = max(3, int(np.searchsorted(phi, self.phi_max, side="right")))
        self.A, self.B = fit_AB(phi[:used], self.S[:used])
        self._stress = PchipInterpolator(np.sqrt(phi * shot.fc / shot.rho), shot.fc * self.S)

    def wall_stress(self, velocity):
        """``sigma_r`` (Pa) at expansion velocity ``velocity`` (<= :attr:`top_velocity`, the
        fastest the nose meets; clipped to it)."""
        return self._stress(np.minimum(velocity, self.top_velocity))

    def force(self, depth, velocity):
        return float(np.dot(self._weights, self.wall_stress(velocity * self._cosines)))

    def crater_force(self, velocity):
        return self.force(0.0, velocity)

    def label(self, depth, velocity):
        return "concrete"


def _target(shot):
    """A placeholder one-layer target for the integrator (the resistance ignores it)."""
    return Target((Material(E=1.0, nu=0.2, rho=shot.rho, lam=0.0, tau=1.0),), ())


def table_depth(shot, resistance, erosion=None, *, rtol=RTOL, atol=ATOL):
    """Depth (m) with the crater of :func:`crater_calibres` and cavex's tunnel integrator
    (its tolerances ``rtol``, ``atol``).

    ``erosion``: an :class:`~cavex.analytic.penetration.erosion.ErosionLaw` (None: rigid).
    Where it is on for the shot, the crater's loss
    (:meth:`~cavex.analytic.penetration.erosion.ErodingNose.crater_loss`) is taken at the
    crater's end and the tunnel flies the eroding nose; the depth is then the eroded nose
    tip's (:func:`table_flight`)."""
    return table_flight(shot, resistance, erosion, rtol=rtol, atol=atol)[0]


def table_flight(shot, resistance, erosion=None, *, rtol=RTOL, atol=ATOL):
    """``(depth, eroded)``: :func:`table_depth` and the flight's erosion summary
    (:meth:`~cavex.analytic.penetration.erosion.ErodingNose.summary`; None where the
    projectile flew rigid: no law, a law off at ``V0``, or a crater that stops it)."""
    crater = crater_calibres(shot.crh) * shot.diameter
    projectile = _ogive(shot)
    energy = shot.mass * shot.V0 ** 2
    static = resistance.force(0.0, 0.0)
    if energy <= crater * static:
        return math.sqrt(energy * crater / static), None
    v1, _ = crater_exit(projectile, resistance.crater_force, crater)
    tunnel = Projectile(r=projectile.r, l=projectile.l, m=projectile.m, V0=v1, R=projectile.R)
    nose = eroding_nose(erosion, shot, projectile)
    if nose is None:
        return crater + float(penetrate(_target(shot), tunnel, resistance, crater=None,
                                        rtol=rtol, atol=atol).depth[-1]), None
    nose.lost = nose.crater_loss(projectile, 0.5 * shot.mass * (shot.V0 ** 2 - v1 ** 2))
    eroded = penetrate(_target(shot), tunnel, resistance, crater=None, erosion=nose,
                       rtol=rtol, atol=atol).erosion
    return crater + eroded["tip_depth_m"], eroded


def eroding_nose(law, shot, projectile):
    """The :class:`~cavex.analytic.penetration.erosion.ErodingNose` of ``shot`` under
    ``law`` (its listed ``proj_density``, else steel's), None where ``law`` is None or off
    for the shot's striking velocity."""
    from cavex.analytic.penetration.erosion import ErodingNose
    from cavex.materials import DEFAULT_DENSITY

    if law is None or shot.V0 <= law.onset:
        return None
    try:
        density = float(getattr(shot, "extra", {}).get("proj_density", ""))
    except ValueError:
        density = DEFAULT_DENSITY
    return ErodingNose(law, projectile, density)


def model_depth(shot, constants=None, erosion=None):
    """Predicted depth (m) of the concrete cavity-expansion model for ``shot`` (``erosion``:
    :func:`table_depth`). ``constants`` default to :class:`~cavex.concrete.Constants`, HJC's
    lock strain; the registry's ``concrete`` model (``cavex validate``) passes those of its
    chosen option, the porosity lock strain (:mod:`cavex.analytic.models.concrete`)."""
    return table_depth(shot, TableResistance(shot, constants), erosion)
