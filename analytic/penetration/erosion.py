r"""Nose erosion by abrasion: the mass a penetrating projectile loses and its blunted nose.

The law is the frictional-work form of Silling and Forrestal (2007), "Mass loss from abrasion
on rigid projectiles during penetration", Int. J. Impact Eng. 34, 1814-1820 (and Jones, Jones
and Toness 1998 before them): the projectile loses mass at the rate the sliding friction on
its nose does work, over the heat that melts (ablates) a unit mass of it,

.. math:: \dot m = -\frac{V F_f}{Q}, \qquad F_f = \mu \int_{nose} \sigma_n \sin\phi \, dA ,

``mu`` the Coulomb friction coefficient, ``Q`` (J/kg) the heat of ablation, ``V F_f`` the
sliding power (the target slides along the nose at ``V sin(phi)``). For a rigid projectile
whose friction is a fixed fraction ``mu g`` of the axial force ``F`` this gives
``Delta m = (mu g / Q) int F dx = mu g m V0^2 / (2 Q)``: the mass lost is proportional to the
striking kinetic energy (:func:`rigid_mass_loss`), the result the source is known for
(recalled: its text is not here to check).

**Constants (flagged).** The source's text and constants are not in the stored literature
this project could search (docs/erosion.md says what was searched). The values below are
not the source's: ``mu = 0.1``, a steel-on-concrete sliding coefficient (the order used in
Forrestal-type friction terms), and ``Q = 1.31 MJ/kg``, the enthalpy that takes iron from
298 K to liquid at its melting point (about 59.3 kJ/mol sensible plus 13.8 kJ/mol of fusion,
55.85 g/mol; thermochemical tables). Neither is fitted to any shot. The law has no velocity
threshold of its own (the loss is proportional to ``V0^2`` from 0); :attr:`ErosionLaw.onset`
is the explicit switch, 0 m/s for this law: at or below it the integrator flies the rigid
projectile, bit for bit.

**Nose stress.** The wall stress on the nose is taken as ``sigma_n = a + b (V cos phi)^2``
(Forrestal's form; the paper's Eqs. 12-14), ``a`` and ``b`` read from the rigid resistance
itself: ``F_s = F(L, 0)`` and ``F_d = F(L, V) - F_s``. Then, in units of ``pi r^2``
(:func:`nose_integrals`, closed forms over a tangent ogive of CRH ``psi``):

- axial force ``F = F_s + F_d c(psi)/c(psi_0)``, ``c = int (cos phi)^3 dA`` (``c/(pi r^2)``
  is ``(8 psi - 1)/(24 psi^2)``, Eq. 14's nose factor; the static part does not depend on the
  shape);
- friction ``F_f = mu [F_s s(psi) + F_d k(psi)/c(psi_0)]``, ``s = int sin phi dA``,
  ``k = int sin phi (cos phi)^2 dA``.

Exact for a quadratic law (the quasi-static closed form, the paper's model, the plain law);
for a wall stress that is not quadratic in ``V`` (the dynamic closed form, the concrete
cavity) the shape's effect is this law's approximation. The friction heats the nose; it is
not added to the axial force (the rigid models it erodes are frictionless).

**Blunting.** The mass lost comes off the nose, which stays a tangent ogive of the shank
radius ``r`` with a smaller CRH: ``psi`` solves ``v(psi) = v(psi_0) - Delta m / rho_p``
(:func:`nose_volume`), down to a hemisphere (``psi = 1/2``), after which the shape stays
hemispherical. The nose tip recedes by ``l(psi_0) - l(psi)``, ``l = r sqrt(4 psi - 1)``, and
past the hemisphere by the further lost volume over the shank's section, ``(v(1/2) - v)/(pi
r^2)``: the hemispherical nose moves back into the shank. A body that loses all but the
hemisphere's own mass ``rho_p v(1/2)`` is eroded through: a numerical failure, not a depth.
"""

import math
from dataclasses import dataclass

from cavex.errors import CavexNumericalError, require
from cavex.materials import DEFAULT_DENSITY

HEMISPHERE = 0.5  # the bluntest tangent ogive (CRH 1/2)


@dataclass(frozen=True)
class ErosionLaw:
    """A mass-abrasion law: ``mu`` (friction coefficient), ``heat`` ``Q`` (J/kg), ``onset``
    (m/s: at or below this striking velocity the law is off), ``blunting`` (False: the mass
    goes but the nose keeps its shape; for the rigid-limit check only), ``source`` (words)."""

    name: str
    friction: float
    heat: float
    onset: float = 0.0
    blunting: bool = True
    source: str = ""

    def __post_init__(self):
        require(self.friction > 0.0, "friction", "> 0", self.friction)
        require(self.heat > 0.0, "heat", "> 0 J/kg", self.heat)
        require(self.onset >= 0.0, "onset", ">= 0 m/s", self.onset)


SILLING_FORRESTAL = ErosionLaw(
    "silling-forrestal", friction=0.1, heat=1.31e6, onset=0.0,
    source="Silling and Forrestal (2007), Int. J. Impact Eng. 34, 1814-1820: mass-loss rate = "
           "frictional power / heat of ablation; mu = 0.1 and Q = 1.31 MJ/kg are not the "
           "source's (flagged, docs/erosion.md)")
#: name -> law (``--erosion``); "none" is the rigid projectile
LAWS = {SILLING_FORRESTAL.name: SILLING_FORRESTAL}
CHOICES = ("none", *LAWS)


def law_named(name):
    """The law of ``name`` (None for "none"); an unknown name is refused naming the choices."""
    from cavex.errors import require_choice

    require_choice(name, CHOICES, "erosion")
    return None if name == "none" else LAWS[name]


def nose_integrals(psi):
    r"""``(s, c, k)``: ``int sin(phi) dA``, ``int cos(phi)^3 dA`` and
    ``int sin(phi) cos(phi)^2 dA`` over a tangent ogive of CRH ``psi`` (>= 1/2), in units of
    ``pi r^2``. With ``R = 2 psi r``, ``s_0 = sin(phi_0) = 1 - 1/(2 psi)`` and
    ``dA = 2 pi R^2 (sin phi - s_0) d phi`` on ``[phi_0, pi/2]``:

    - ``s = 8 psi^2 [pi/4 - phi_0/2 + sin(2 phi_0)/4 - s_0 cos phi_0]``,
    - ``c = 8 psi^2 [cos^4 phi_0 / 4 - s_0 (2/3 - s_0 + s_0^3/3)]`` (``= (8 psi - 1)/(24 psi^2)``),
    - ``k = 8 psi^2 [pi/16 - phi_0/8 + sin(4 phi_0)/32 - s_0 cos^3 phi_0 / 3]``.
    """
    s0 = 1.0 - 0.5 / psi
    phi0 = math.asin(s0)
    cos0 = math.cos(phi0)
    scale = 8.0 * psi * psi
    s = scale * (0.25 * math.pi - 0.5 * phi0 + 0.25 * math.sin(2.0 * phi0) - s0 * cos0)
    c = (8.0 * psi - 1.0) / (24.0 * psi * psi)
    k = scale * (math.pi / 16.0 - phi0 / 8.0 + math.sin(4.0 * phi0) / 32.0
                 - s0 * cos0 ** 3 / 3.0)
    return s, c, k


def nose_volume(r, psi):
    """Volume (m^3) of a tangent ogive nose of shank radius ``r`` and CRH ``psi``:
    ``pi [(R^2 + s^2) l - l^3/3 - s (l s + R^2 asin(l/R))]``, ``R = 2 psi r``, ``s = R - r``,
    ``l = r sqrt(4 psi - 1)`` (2 pi r^3/3 for the hemisphere)."""
    R = 2.0 * psi * r
    s, length = R - r, r * math.sqrt(4.0 * psi - 1.0)
    return math.pi * ((R * R + s * s) * length - length ** 3 / 3.0
                      - s * (length * s + R * R * math.asin(length / R)))


def nose_length(r, psi):
    """Tangent-ogive nose length ``r sqrt(4 psi - 1)`` (m)."""
    return r * math.sqrt(4.0 * psi - 1.0)


def rigid_mass_loss(law, projectile, A, B):
    r"""Mass lost (kg) by a projectile that stops from ``V0`` under ``F = A + B V^2`` (N) with
    no crater, its nose and mass held fixed in the motion (the limit of a small loss):
    ``Delta m = (mu/Q) [s A P + (k/c) (m V0^2/2 - A P)]`` with the rigid depth
    ``P = (m/(2B)) ln(1 + B V0^2/A)`` (``int F_s dx = A P``, ``int F_d dx`` the rest of the
    kinetic energy). For ``B = 0``: ``mu s m V0^2/(2Q)``, proportional to the kinetic energy."""
    s, c, k = nose_integrals(projectile.psi)
    m, v0 = projectile.m, projectile.V0
    energy = 0.5 * m * v0 * v0
    static_work = energy if B == 0.0 else A * m / (2.0 * B) * math.log1p(B * v0 * v0 / A)
    return law.friction / law.heat * (s * static_work + k / c * (energy - static_work))


class ErodingNose:
    """The eroding nose of ``projectile`` under ``law``: the current CRH from the mass lost,
    the axial force and the mass-loss rate the integrator needs (module docstring).

    ``density``: the projectile's (kg/m^3; default steel). ``lost``: mass already lost (kg)
    when the integration starts (a crater flown apart, as the concrete model does)."""

    def __init__(self, law, projectile, density=DEFAULT_DENSITY, lost=0.0):
        require(density > 0.0, "density", "> 0 kg/m^3", density)
        self.law, self.density, self.lost = law, float(density), float(lost)
        self.m0, self.r, self.psi0 = float(projectile.m), float(projectile.r), projectile.psi
        self.volume0 = nose_volume(self.r, self.psi0)
        self.blunt_volume = nose_volume(self.r, HEMISPHERE)
        self.c0 = nose_integrals(self.psi0)[1]
        self.active = projectile.V0 > law.onset
        self._last = (None, None)

    def psi(self, mass):
        """Current CRH for the projectile's current ``mass`` (kg)."""
        if not self.law.blunting or mass >= self.m0:
            return self.psi0
        if mass == self._last[0]:
            return self._last[1]
        volume = self.nose_volume_left(mass)
        psi = HEMISPHERE if volume <= self.blunt_volume else self._solve_psi(volume)
        self._last = (mass, psi)
        return psi

    def _solve_psi(self, volume):
        """``psi`` in ``[1/2, psi_0]`` with ``nose_volume(r, psi) = volume``: Newton's method
        from the last answer (forward-difference slope), to ``1e-13 v(psi_0)``; bisection
        (``brentq``) where it does not converge in 6 steps."""
        psi = self.psi0 if self._last[1] is None else self._last[1]
        for _ in range(6):
            residual = nose_volume(self.r, psi) - volume
            if abs(residual) <= 1e-13 * self.volume0:
                return psi
            step = 1e-7 * psi
            slope = (nose_volume(self.r, psi + step) - nose_volume(self.r, psi)) / step
            psi = min(max(psi - residual / slope, HEMISPHERE), self.psi0)
        from scipy.optimize import brentq

        return brentq(lambda p: nose_volume(self.r, p) - volume, HEMISPHERE, self.psi0,
                      xtol=1e-14, rtol=1e-14)

    def tip_setback(self, mass):
        """How far (m) the eroded nose tip sits behind the original one: the shorter ogive,
        and past the hemisphere the volume lost beyond it over the shank's section."""
        setback = nose_length(self.r, self.psi0) - nose_length(self.r, self.psi(mass))
        if not self.law.blunting or mass >= self.m0:
            return setback
        beyond = self.blunt_volume - self.nose_volume_left(mass)
        return setback + max(beyond, 0.0) / (math.pi * self.r * self.r)

    def nose_volume_left(self, mass):
        """The original nose's volume less the volume lost at ``mass`` (m^3; below the
        hemisphere's once the loss reaches the shank)."""
        return self.volume0 - (self.m0 - mass) / self.density

    def forces(self, resistance, depth, velocity, mass):
        """``(F, F_f)``: the axial force on the current nose and the sliding friction (N)."""
        static = resistance.force(depth, 0.0)
        dynamic = resistance.force(depth, velocity) - static
        s, c, k = nose_integrals(self.psi(mass))
        return (static + dynamic * c / self.c0,
                self.law.friction * (static * s + dynamic * k / self.c0))

    def mass_rate(self, friction, velocity):
        """``dm/dt = -V F_f / Q`` (kg/s)."""
        return -velocity * friction / self.law.heat

    def crater_loss(self, projectile, work):
        """Mass (kg) the nose loses over a crater stage that takes ``work`` (J) from the
        projectile, friction a fixed ``mu s(psi_0)`` of the crater's axial force (the crater
        stage is the rigid closed form; its loss is applied at its end)."""
        s = nose_integrals(self.psi0)[0]
        return self.law.friction * s * work / self.law.heat

    def summary(self, mass, depth):
        """What a run reports: the mass lost, the nose's CRH and length, the eroded tip's
        depth given the integrator's (original-tip) ``depth``."""
        psi = self.psi(mass)
        if mass < self.m0 and mass <= self.density * self.blunt_volume:
            raise CavexNumericalError(
                f"the nose eroded through the whole body ({self.m0 - mass:.4g} of "
                f"{self.m0:.4g} kg lost, {mass:.3g} kg left, less than its hemispherical nose):"
                " a projectile eroded this far is beyond the erosion model")
        return {"law": self.law.name, "mass_lost_kg": self.m0 - mass,
                "mass_loss_fraction": (self.m0 - mass) / self.m0, "crh_final": psi,
                "nose_length_final_m": nose_length(self.r, psi),
                "tip_setback_m": self.tip_setback(mass),
                "tip_depth_m": depth - self.tip_setback(mass)}
