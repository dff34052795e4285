r"""Concrete at the cavity's pressures (0.1-2 GPa) as functions of ``f_c``: the shear limit on
the compressive meridian and the constants of the compaction hydrostat, each from a published
source (issue 31, item 2; docs/concrete.md "Strength and hydrostat at high confinement").
The data used are in ``core/data/concrete_confinement.csv`` (:func:`load_data`), one row a
datum with its citation. Nothing here is fitted to penetration shots. The porosity lock strain
(:func:`hydrostat`) is an option of the concrete model (``"porosity lock"``,
:mod:`cavex.analytic.models.concrete`), cross-validated on the development shots and chosen
there; the meridians are cross-validated beside it
(:mod:`cavex.verification.studies.confinement_selection`) and are not options of a model.

Stresses in Pa, compression positive. On the compressive meridian (one principal stress above
two equal ones: a triaxial compression test, and the comminuted zone of a spherical cavity,
``s_r > s_theta = s_phi``) the shear limit is the principal stress difference
``q = sigma_1 - sigma_3`` (the cavity model's ``D = s_r - s_theta``, HJC's and RHT's equivalent
stress) at the mean stress ``p = (sigma_1 + 2 sigma_3)/3``. A triaxial test at confinement
``sigma_3`` fails at ``sigma_1 = sigma_3 + q`` with ``p = sigma_3 + q/3``
(:func:`triaxial_strength` solves it).

Shear limit: the published flattening meridians (:data:`MERIDIANS`)

- ``"hjc"``: ``q = f_c min(B (p/f_c)^N, S_max)``, ``B = 1.6``, ``N = 0.61``, ``S_max = 7``:
  the fully damaged surface and the cap of Holmquist, Johnson and Cook (1993) for one 48 MPa
  concrete (the constants cavex uses today, docs/concrete.md).
- ``"rht"``: ``q = f_c A (p/f_c)^N``, ``A = 2.0``, ``N = 0.7``, no cap (maximum fracture
  strength ratio 1e20): the RHT failure surface's compressive meridian as set by Leppänen
  (2004, Chalmers Publ. 04:4, Table C.2, "calculated with a model proposed by Attard and
  Setunge (1996)"; his Fig. 4.6 draws it over Bažant et al.'s (1996) data of a 46 MPa
  concrete up to ``p/f_c`` = 10). RHT's shift of ``p/f_c`` by its spall pressure (of the
  order of ``f_t/f_c``, 0.1 or less) is left out: at ``p/f_c >= 1`` it changes ``q`` by under
  ``N x 0.1`` = 7 %.

Each meridian is used with one of two ``f_c`` scalings (:func:`shear_limit`):

- ``"fc"``, the published use: the constants are normalised by the concrete's own ``f_c``, so
  that at a given pressure ``q`` grows as ``f_c^(1 - N)`` (``f_c^0.39`` for HJC, ``f_c^0.3``
  for RHT);
- ``"none"``: the surface of the concrete the constants were set for (``f_ref``: 48 MPa for
  HJC, 46 MPa for RHT, the concrete of the data it was drawn over), in absolute units, the same
  for every ``f_c``. This is what the high-confinement tests report for normal-strength
  concretes: Malecot, Vu and Daudeville (2009, DYMAT 2009, 187: three concretes of 21, 29 and
  57 MPa to about 1 GPa, "no more effect of the cement matrix strength" under high confinement,
  the saturation ratio governs) and Piotrowska, Malecot and Ke (2014, Mech. Mater. 79, 45-57:
  a non-cohesive granular stacking at high confinement). Those papers' numbers are not in the
  stored literature, so the two scalings cannot be told apart here by data: the choice is left
  to the cross-validation on shots once the hydrostat has landed (docs/concrete.md).

At low confinement two published laws of the strength are kept for comparison:
:func:`mohr_coulomb_strength` (Richart, Brandtzaeg and Brown 1928, the cavity model's line
today) and :func:`attard_setunge_strength` (Attard and Setunge 1996, ACI Mater. J. 93(5),
432-442: ``f_cc = f_c (1 + f_l/f_t)^k``, ``k = 1.25 (1 + 0.062 f_l/f_c) f_c^-0.21``,
``f_t = 0.9 x 0.32 f_c^0.67`` in MPa, a law fitted to tests of several strengths at
confinements up to about 20 MPa; it is not meant for the cavity's pressures and grows
without bound there).

Hydrostat (:func:`hydrostat`; HJC's form: elastic to ``p_crush``, compaction to ``p_lock``,
then locked with the modulus ``K_lock``; ``mu = rho/rho_0 - 1``)

- ``p_crush = f_c/3``: the mean stress of the uniaxial test at failure, HJC's 16 MPa for their
  48 MPa concrete;
- ``mu_crush = p_crush/K``, ``K = E/(3 (1 - 2 nu))`` with ACI 318's ``E`` and ``nu = 0.2``
  (:mod:`cavex.concrete`): continuous at the crush point;
- ``mu_lock = phi/(1 - phi)``: at the lock the pores are closed, ``rho = rho_grain``,
  ``phi`` the porosity (the solid's own compression at ``p_lock``, ``p_lock/K_lock`` = 0.009,
  is left out). ``phi = a (f_c/MPa)^b`` with
  ``a`` = :data:`POROSITY_A`, ``b`` = :data:`POROSITY_B`, the least-squares line in logs
  through the porosities ``v_c`` that Imran and Pantazopoulou (2001, J. Eng. Mech. 127(3),
  Table 1) list for six concretes of Ansari and Li (1998) and Xie et al. (1995), 47-119 MPa
  (``load_data``). It is not extrapolated: below 47.23 MPa and above 119 MPa the porosity of
  the nearest end is kept. HJC's ``mu_lock = 0.1`` at 48 MPa, not in the fit, is within the
  data's scatter of it (tests/test_concrete_confinement.py);
- ``p_lock = 0.8 GPa`` and ``K_lock = 85 GPa``: HJC's (1993), for every ``f_c``: no hydrostat of
  another strength is in the stored literature. Bažant, Bishop and Chang (1986, ACI J. 83(4)):
  pores still open at 300 ksi of uniaxial strain, so full compaction lies above
  ``p = 2068/3 = 689 MPa``; HJC's 0.8 GPa is not below that bound.
"""

import csv
import math
from dataclasses import dataclass
from importlib import resources

import numpy as np

from cavex.concrete import DEFAULT_NU, RICHART_CONFINEMENT, aci_modulus
from cavex.errors import require, require_choice

MPA = 1e6
DATA_FILE = "concrete_confinement.csv"
SCALINGS = ("fc", "none")
#: the porosity law ``phi = POROSITY_A (f_c/MPa)^POROSITY_B`` (least squares in logs through
#: the six porosities of Imran and Pantazopoulou 2001, Table 1; tests refit it from the data)
POROSITY_A = 4.2794
POROSITY_B = -0.97823
#: the f_c range (Pa) of those porosities: the law is held at its ends outside it
POROSITY_FC_RANGE = (47.23 * MPA, 119.0 * MPA)
LOCK_PRESSURE = 0.8e9  # HJC 1993
LOCKED_MODULUS = 85e9  # HJC 1993, K_1


@dataclass(frozen=True)
class Meridian:
    """A flattening meridian ``q/f = min(B (p/f)^N, S_max)``, ``f`` the strength it is
    normalised by (:func:`shear_limit`): its constants, the strength of the concrete they were
    set for (``f_ref``, Pa) and the source."""

    name: str
    B: float
    N: float
    S_max: float
    f_ref: float
    source: str


MERIDIANS = {
    "hjc": Meridian("hjc", 1.6, 0.61, 7.0, 48.0 * MPA,
                    "Holmquist, Johnson and Cook (1993), 14th Int. Symp. Ballistics, 591-600: "
                    "fully damaged surface and cap of a 48 MPa concrete"),
    "rht": Meridian("rht", 2.0, 0.7, math.inf, 46.0 * MPA,
                    "Leppanen (2004), Chalmers Publ. 04:4, Table C.2 (RHT, from Attard and "
                    "Setunge 1996), drawn over Bazant et al. (1996), 46 MPa concrete"),
}


def _check_strength(fc):
    require(isinstance(fc, (int, float)) and not isinstance(fc, bool) and math.isfinite(fc)
            and fc > 0.0, "fc", "a finite number > 0 (Pa)", fc)


def shear_limit(p, fc, meridian="rht", scaling="fc"):
    """The shear limit ``q`` (Pa) at mean stress ``p >= 0`` (Pa, a number or a NumPy array) of
    a concrete of strength ``fc`` (Pa): ``q = f min(B (p/f)^N, S_max)`` with ``f = fc``
    (``scaling="fc"``) or the meridian's ``f_ref`` (``scaling="none"``)."""
    require_choice(meridian, tuple(MERIDIANS), "meridian")
    require_choice(scaling, SCALINGS, "scaling")
    _check_strength(fc)
    m = MERIDIANS[meridian]
    f = fc if scaling == "fc" else m.f_ref
    return f * _capped(m.B * (p / f) ** m.N, m.S_max)


def cavity_power_law(fc, meridian="rht", scaling="fc"):
    """The meridian in the cavity model's units (stresses over ``f_c``,
    :class:`cavex.concrete.Constants`): ``(power_B, power_N, cap)`` with
    ``D/f_c = min(power_B (p/f_c)^power_N, cap)``; not normalised by ``f_c``,
    ``power_B = B (f_ref/f_c)^(1 - N)`` and ``cap = S_max f_ref/f_c``."""
    require_choice(meridian, tuple(MERIDIANS), "meridian")
    require_choice(scaling, SCALINGS, "scaling")
    _check_strength(fc)
    m = MERIDIANS[meridian]
    ratio = 1.0 if scaling == "fc" else m.f_ref / fc
    return m.B * ratio ** (1.0 - m.N), m.N, m.S_max * ratio


def _capped(value, cap):
    """``min(value, cap)`` for a number or an array (``inf``: no cap)."""
    return value if not math.isfinite(cap) else np.minimum(value, cap)


def triaxial_strength(sigma3, fc, meridian="rht", scaling="fc"):
    """Axial strength ``sigma_1`` (Pa) of a triaxial compression test at confinement
    ``sigma3 >= 0`` (Pa): the root of ``q(sigma3 + q/3) = q`` on the meridian
    (:func:`shear_limit`), found by bisection on ``q`` in ``[0, q_hi]``; ``q(p)/p`` falls
    below 3 as ``p`` grows (``N < 1``), so the root exists and is unique."""
    require(sigma3 >= 0.0, "sigma3", ">= 0 (Pa)", sigma3)

    def excess(q):
        return shear_limit(sigma3 + q / 3.0, fc, meridian, scaling) - q

    lo, hi = 0.0, max(fc, 1.0)
    while excess(hi) > 0.0:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) > 0.0 else (lo, mid)
        if hi - lo <= 1e-12 * hi:
            break
    return sigma3 + 0.5 * (lo + hi)


def mohr_coulomb_strength(sigma3, fc, confinement=RICHART_CONFINEMENT):
    """Richart, Brandtzaeg and Brown (1928): ``sigma_1 = f_c + k sigma_3``, ``k = 4.1``
    (Pa): the straight line of the cavity model (:func:`cavex.concrete.mohr_coulomb_lambda`)."""
    _check_strength(fc)
    return fc + confinement * sigma3


def attard_setunge_strength(sigma3, fc):
    """Attard and Setunge (1996): ``f_cc = f_c (1 + f_l/f_t)^k``,
    ``k = 1.25 (1 + 0.062 f_l/f_c) (f_c/MPa)^-0.21``, ``f_t = 0.9 x 0.32 (f_c/MPa)^0.67`` MPa
    (concrete without silica fume), with ``f_l = sigma3``; Pa in, Pa out."""
    _check_strength(fc)
    f, fl = fc / MPA, sigma3 / MPA
    ft = 0.9 * 0.32 * f ** 0.67
    k = 1.25 * (1.0 + 0.062 * fl / f) * f ** -0.21
    return f * (1.0 + fl / ft) ** k * MPA


def porosity(fc):
    """Porosity of a concrete of strength ``fc`` (Pa): ``POROSITY_A (f_c/MPa)^POROSITY_B``,
    held at its value at the ends of :data:`POROSITY_FC_RANGE` outside it."""
    _check_strength(fc)
    lo, hi = POROSITY_FC_RANGE
    return POROSITY_A * (min(max(fc, lo), hi) / MPA) ** POROSITY_B


@dataclass(frozen=True)
class Hydrostat:
    """HJC's hydrostat of one concrete (Pa; ``mu = rho/rho_0 - 1``): elastic with the bulk
    modulus ``bulk`` to ``(mu_crush, p_crush)``, compaction on a straight line to
    ``(mu_lock, p_lock)``, then locked with ``locked_modulus``."""

    bulk: float
    p_crush: float
    mu_crush: float
    p_lock: float
    mu_lock: float
    locked_modulus: float

    @property
    def compaction_modulus(self):
        """Slope of the compaction line ``(p_lock - p_crush)/(mu_lock - mu_crush)`` (Pa)."""
        return (self.p_lock - self.p_crush) / (self.mu_lock - self.mu_crush)


def hydrostat(fc, rho, nu=DEFAULT_NU):
    """The :class:`Hydrostat` of a concrete of strength ``fc`` (Pa) and density ``rho``
    (kg/m^3): ``p_crush = f_c/3``, ``mu_crush = p_crush/K`` (``K`` from ACI 318's ``E``),
    ``mu_lock = phi/(1 - phi)`` (:func:`porosity`), HJC's ``p_lock`` and ``K_lock``."""
    _check_strength(fc)
    require(isinstance(rho, (int, float)) and math.isfinite(rho) and rho > 0.0, "rho",
            "a finite number > 0 (kg/m^3)", rho)
    bulk = aci_modulus(fc, rho) / (3.0 * (1.0 - 2.0 * nu))
    p_crush = fc / 3.0
    phi = porosity(fc)
    return Hydrostat(bulk=bulk, p_crush=p_crush, mu_crush=p_crush / bulk,
                     p_lock=LOCK_PRESSURE, mu_lock=phi / (1.0 - phi),
                     locked_modulus=LOCKED_MODULUS)


def load_data():
    """The data rows of ``core/data/concrete_confinement.csv`` as dicts: numbers as floats
    (``None`` where empty), ``id``, ``kind``, ``reference`` and ``note`` as text."""
    text = resources.files("cavex").joinpath("data", DATA_FILE).read_text(encoding="utf-8")
    rows = []
    for row in csv.DictReader(text.splitlines()):
        rows.append({key: (value if key in ("id", "kind", "reference", "note")
                           else (float(value) if value else None))
                     for key, value in row.items()})
    return rows
