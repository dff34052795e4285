r"""A concrete of strength ``f_c`` and density ``rho``, described once from published correlations:
the Mohr-Coulomb layer of the closed forms and the FE (:func:`concrete_material`, under a
:class:`Mapping`), and the constants of the concrete cavity model (:class:`Constants`,
:func:`tensile_strength`; :func:`cavex.analytic.penetration.concrete_table.concrete_cavity`).

A published test reports the unconfined compressive strength ``f_c`` and the density ``rho``;
cavex's models need ``E, nu, rho, lam, tau`` (:class:`cavex.materials.Material`). The mapping
(``docs/validation.md``) and its sources:

- ``E = e * 0.043 rho^1.5 sqrt(f_c)`` (MPa, ``rho`` in kg/m^3, ``f_c`` in MPa): ACI 318-19,
  19.2.2.1(a) (``w_c`` 1440-2560 kg/m^3); ``e`` = ``modulus_factor`` (1 unless calibrated).
- ``nu = 0.2``: EN 1992-1-1 (2004), 3.1.3(4), uncracked concrete. Only the FE solver uses it
  (the closed forms are incompressible): a realistic ``nu`` is what the FE-tabulated
  resistance adds.
- ``lam`` (pressure sensitivity of the paper's Mohr-Coulomb ``sigma_r - sigma_theta =
  lam sigma + tau``) from the triaxial strength of concrete, ``f_cc = f_c + 4.1 f_l`` (Richart,
  Brandtzaeg and Brown 1928, Univ. Illinois Eng. Exp. Station Bull. 185): the Mohr-Coulomb
  ``N_phi = (1 + sin phi)/(1 - sin phi) = 4.1`` (``phi`` = 37.4 deg) and, with
  ``N_phi = (3 + 2 lam)/(3 - lam)`` (docs/problem.md), ``lam = 3 (N_phi - 1)/(N_phi + 2) = 1.525``.
- ``sigma_c = s * f_c``, ``tau = (3 - lam) sigma_c / 3``: the yield line passes through the
  uniaxial compressive strength (``s`` = ``strength_factor``, 1 unless calibrated; a fitted
  ``s`` absorbs what the idealisation leaves out: rate and size effects, the curvature of the
  real failure envelope at the cavity pressures, compaction).
- tension cut-off: none in the closed forms; the Mohr-Coulomb line implies a uniaxial tensile
  strength ``f_c / N_phi`` (0.24 ``f_c``, three times the usual 0.08 ``f_c``). The FE solver
  can cut tension off (``Numerics.tension_cutoff``); the validation keeps the FE at the
  Mohr-Coulomb apex so that FE and closed forms differ only by compressibility and finite
  strain.

The free parameters of a calibration are ``lam``, ``strength_factor`` and ``modulus_factor``
(:data:`FREE_PARAMETERS`).
"""

import math
from dataclasses import dataclass, field, fields, replace

from cavex.errors import CavexInputError, require
from cavex.materials import Material

RICHART_CONFINEMENT = 4.1  # f_cc = f_c + 4.1 f_l (Richart, Brandtzaeg and Brown 1928)
DEFAULT_NU = 0.2  # EN 1992-1-1, 3.1.3(4)
LAYER_NAME = "concrete"
FREE_PARAMETERS = ("lam", "strength_factor", "modulus_factor")
# accepted ranges (lower, upper) of the parameters; lam < 3 is the material's own limit
BOUNDS = {"lam": (0.0, 2.9), "strength_factor": (0.05, 20.0), "modulus_factor": (0.05, 20.0),
          "nu": (-0.99, 0.4999)}


def mohr_coulomb_lambda(confinement=RICHART_CONFINEMENT):
    """``lam`` of the paper's Mohr-Coulomb with ``N_phi = confinement``:
    ``lam = 3 (N_phi - 1)/(N_phi + 2)`` (inverse of docs/problem.md's
    ``N_phi = (3 + 2 lam)/(3 - lam)``)."""
    return 3.0 * (confinement - 1.0) / (confinement + 2.0)


def aci_modulus(fc, rho):
    """ACI 318-19 19.2.2.1(a): ``E_c = 0.043 w_c^1.5 sqrt(f_c')`` (MPa) in Pa, ``fc`` in Pa."""
    return 0.043 * rho ** 1.5 * math.sqrt(fc / 1e6) * 1e6


@dataclass(frozen=True)
class Mapping:
    """Parameters of the ``(f_c, rho)`` -> material mapping (defaults: the sources above)."""

    lam: float = mohr_coulomb_lambda()
    strength_factor: float = 1.0
    modulus_factor: float = 1.0
    nu: float = DEFAULT_NU

    def __post_init__(self):
        for item in fields(self):
            lower, upper = BOUNDS[item.name]
            value = getattr(self, item.name)
            require(isinstance(value, (int, float)) and not isinstance(value, bool)
                    and math.isfinite(value) and lower <= value <= upper, item.name,
                    f"a number in [{lower:g}, {upper:g}]", value)

    def with_values(self, names, values):
        """A copy with the parameters ``names`` set to ``values``."""
        return replace(self, **{n: float(v) for n, v in zip(names, values, strict=True)})

    def as_dict(self):
        return {item.name: getattr(self, item.name) for item in fields(self)}


def concrete_material(fc, rho, mapping=None):
    """The :class:`~cavex.materials.Material` of a concrete of strength ``fc`` (Pa) and density
    ``rho`` (kg/m^3) under ``mapping`` (default :class:`Mapping`)."""
    mapping = mapping or Mapping()
    try:
        return Material(E=mapping.modulus_factor * aci_modulus(fc, rho), nu=mapping.nu, rho=rho,
                        lam=mapping.lam, sigma_c=mapping.strength_factor * fc, name=LAYER_NAME)
    except CavexInputError as exc:
        raise CavexInputError(f"concrete f_c = {fc:g} Pa, rho = {rho:g} kg/m^3: {exc}") from None


@dataclass(frozen=True)
class Constants:
    """The global constants of the mapping (defaults: the published values in the docstring).

    ``cap`` is ``S_max = tau_max/f_c``, ``crush`` HJC's crush pressure over ``f_c`` (``p_c =
    f_c/3``), ``lock_pressure`` ``p_l`` (Pa), ``lock_strain`` HJC's ``mu_l``, ``locked_modulus``
    ``K_1`` (Pa), ``confinement`` Richart's ``k``.
    """

    cap: float = 7.0
    crush: float = 1.0 / 3.0
    lock_pressure: float = 0.8e9
    lock_strain: float = 0.1
    locked_modulus: float = 85e9
    confinement: float = 4.1
    nu: float = DEFAULT_NU
    power_B: float = math.nan
    power_N: float = 1.0

    def with_values(self, names, values):
        return replace(self, **{n: float(v) for n, v in zip(names, values, strict=True)})

    def as_dict(self):
        return {item.name: getattr(self, item.name) for item in fields(self)}


def tensile_strength(fc):
    """fib Model Code 2010 mean tensile strength (Pa) of a concrete of mean strength ``fc`` (Pa):
    ``0.3 (f_c - 8)^(2/3)`` MPa up to 58 MPa, ``2.12 ln(1 + f_c/10)`` MPa above."""
    f = fc / 1e6
    if f <= 58.0:
        return 0.3 * max(f - 8.0, 1.0) ** (2.0 / 3.0) * 1e6
    return 2.12 * math.log(1.0 + 0.1 * f) * 1e6


#: the strengths (Pa) and densities (kg/m^3) a concrete may have: a shot file's ranges
#: (:mod:`cavex.verification.validation.shots`); outside them the correlations are far from
#: their data, and a strength in MPa or a density in g/cm^3 is caught
FC_RANGE = (1e6, 1e9)
RHO_RANGE = (1000.0, 4000.0)


@dataclass(frozen=True)
class Concrete:
    """One concrete, described once: mean strength ``fc`` (Pa), density ``rho`` (kg/m^3) and
    the :class:`Constants` of its description. The closed forms and the FE take their material
    from it:

    - :meth:`layer`: the Mohr-Coulomb layer of the layered closed forms, the FE and the FE
      tables (:func:`concrete_material` under a :class:`Mapping`);
    - :meth:`fe_layer`: that layer with the cap ``tau_max = S_max f_c`` and the tension
      cut-off ``f_t`` that the FE carries (docs/fem.md "Concrete");
    - :meth:`cavity_parameters`: the dimensionless constants of the concrete cavity model
      (:class:`cavex.analytic.concrete_cavity.ConcreteCavity`, stresses over ``f_c``).
    """

    fc: float
    rho: float
    constants: Constants = field(default_factory=Constants)

    def __post_init__(self):
        for name, (low, high), hint in (("fc", FC_RANGE, " (is it in MPa?)"),
                                        ("rho", RHO_RANGE, " (is it in g/cm^3?)")):
            value = getattr(self, name)
            require(isinstance(value, (int, float)) and not isinstance(value, bool)
                    and math.isfinite(value) and low <= value <= high, name,
                    f"a number in [{low:g}, {high:g}]{hint}", value)

    @property
    def modulus(self):
        """Young's modulus (Pa), ACI 318-19 (:func:`aci_modulus`)."""
        return aci_modulus(self.fc, self.rho)

    @property
    def tensile_strength(self):
        """Mean tensile strength (Pa), fib Model Code 2010 (:func:`tensile_strength`)."""
        return tensile_strength(self.fc)

    def layer(self, mapping=None):
        """The Mohr-Coulomb layer of this concrete under ``mapping`` (default
        :class:`Mapping`)."""
        return concrete_material(self.fc, self.rho, mapping)

    def hydrostat(self):
        """HJC's hydrostat (Holmquist, Johnson and Cook 1993) in the FE's measures, the
        :data:`cavex.materials.HYDROSTAT` keys of a layer (Pa; ``lock_strain`` 1): crush at
        ``P_c = crush f_c`` (Kirchhoff; the Cauchy pressure differs by ``exp(-P_c/K)``, ~1e-3),
        HJC's lock point ``(mu_l, p_l)`` exactly (``e_l = ln(1 + mu_l)``, Kirchhoff ``P_l =
        p_l/(1 + mu_l)``), and the locked modulus ``dP/de`` of HJC's ``p = p_l + K_1 (mu -
        mu_l)/(1 + mu_l)`` there, ``(K_1 - p_l)/(1 + mu_l)``."""
        c = self.constants
        J_lock = 1.0 / (1.0 + c.lock_strain)
        return {"crush_pressure": c.crush * self.fc, "lock_pressure": c.lock_pressure * J_lock,
                "lock_strain": math.log1p(c.lock_strain),
                "locked_modulus": (c.locked_modulus - c.lock_pressure) * J_lock}

    def fe_layer(self, mapping=None, cracking=True):
        """:meth:`layer` with the cap ``tau_max = cap f_c``, the compaction :meth:`hydrostat`
        and, if ``cracking``, the tension cut-off at :attr:`tensile_strength`: the concrete
        the FE carries."""
        try:
            return replace(self.layer(mapping), tau_max=self.constants.cap * self.fc,
                           tensile_strength=self.tensile_strength if cracking else None,
                           **self.hydrostat())
        except CavexInputError as exc:
            raise CavexInputError(f"concrete f_c = {self.fc:g} Pa, rho = {self.rho:g} kg/m^3: "
                                  f"{exc}") from None

    def cavity_parameters(self):
        """The concrete cavity model's constants, stresses over ``f_c``: ``modulus = E/f_c``,
        ``nu``, ``lam`` (Richart's ``k``), ``tau_max = S_max``, the FE's compaction
        :meth:`hydrostat` (``bulk`` the elastic ``K/f_c``, ``crush``, ``lock_pressure`` over
        ``f_c``, ``lock_strain``, ``bulk_locked`` the locked modulus over ``f_c``) and
        ``tensile = f_t/f_c``."""
        c, fc = self.constants, self.fc
        E = aci_modulus(fc, self.rho)
        h = self.hydrostat()
        return {"modulus": E / fc, "nu": c.nu,
                "lam": mohr_coulomb_lambda(c.confinement), "tau_max": c.cap,
                "bulk": E / (3.0 * (1.0 - 2.0 * c.nu)) / fc, "crush": h["crush_pressure"] / fc,
                "lock_pressure": h["lock_pressure"] / fc, "lock_strain": h["lock_strain"],
                "bulk_locked": h["locked_modulus"] / fc, "tensile": tensile_strength(fc) / fc,
                "power_B": c.power_B, "power_N": c.power_N}
