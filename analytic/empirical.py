r"""The empirical penetration model of Forrestal, Altman, Cargile and Hanchak (1994).

Forrestal, M.J., Altman, B.S., Cargile, J.D., Hanchak, S.J. (1994), "An empirical equation for
penetration depth of ogive-nose projectiles into concrete targets", Int. J. Impact Eng. 15(4),
395-405; in the dimensionless form of Li, Q.M., Chen, X.W. (2003), "Dimensionless formulae for
penetration depth of concrete target impacted by a non-deformable projectile", Int. J. Impact
Eng. 28, 93-116.

A rigid projectile of mass ``m``, shank radius ``a = d/2`` and a tangent-ogive nose of
calibre-radius-head ``psi`` strikes a semi-infinite concrete target (strength ``f_c``, density
``rho``) normally at ``V_s``. The axial force is

- crater, ``0 <= z <= k d`` (``k = 2``: two calibres, ``4a``): ``F = c z``;
- tunnel, ``z > k d``: ``F = pi a^2 (S f_c + N* rho V^2)``, the normal stress
  ``sigma_n = S f_c + rho V_n^2`` integrated over the ogive, ``N* = (8 psi - 1)/(24 psi^2)``;

with the empirical strength factor ``S = 82.6 f_c^-0.544`` (``f_c`` in MPa; Forrestal et al.
fitted it to their shots). ``c`` and the velocity ``V_1`` at ``z = k d`` follow from continuity
of the force, ``c k d = pi a^2 (S f_c + N* rho V_1^2)``, and energy,
``m (V_s^2 - V_1^2) = c (k d)^2``:

.. math:: V_1^2 = \frac{m V_s^2 - k d\, \pi a^2 S f_c}{m + k d\, \pi a^2 N^* \rho},\qquad
          P = \frac{m}{2\pi a^2 \rho N^*}\ln\Big(1 + \frac{N^*\rho V_1^2}{S f_c}\Big) + k d .

With ``I = m V_s^2 / (S f_c d^3)`` (impact function) and ``N = m / (N* rho d^3)`` (geometry
function) this is Li and Chen's (2003) Eq. for ``X/d > k``,
``X/d = (2N/pi) ln[(1 + I/N)/(1 + k pi/(4N))] + k``, and a projectile that stops inside the
crater (``V_1^2 <= 0``) reaches ``X/d = sqrt(I (4k/pi)(1 + k pi/(4N))/(1 + I/N))`` (the same
``c``, continuous at ``X = k d``). Li and Chen's worked example (their Table, Forrestal's shot
of 0.906 kg, 26.9 mm, CRH 2, 277 m/s into 35.2 MPa, 2370 kg/m^3 concrete) prints
``X/d = 6.21`` with ``S = 12``; ``tests/test_validation.py`` reproduces it.
"""

import numpy as np

from cavex.errors import require

S_COEFFICIENT = 82.6  # S = 82.6 f_c^-0.544, f_c in MPa (Forrestal et al. 1994)
S_EXPONENT = -0.544
CRATER_CALIBRES = 2.0  # crater depth k d with k = 2 (4 shank radii), Forrestal et al. 1994
LI_CHEN_COEFFICIENT = 72.0  # S = 72 f_c^-0.5, f_c in MPa (Li and Chen 2003)


def _require_all(values, name, accepted, lower, inclusive=False):
    """:func:`~cavex.errors.require` on a number or an array: every element finite and above
    ``lower`` (or at it, ``inclusive``)."""
    array = np.asarray(values, dtype=float)
    above = array >= lower if inclusive else array > lower
    require(bool(np.all(np.isfinite(array) & above)), name, accepted, values)


def _number_or_array(value):
    """A float for a 0-d result (the scalar API), the array otherwise."""
    return float(value) if np.ndim(value) == 0 else value


def strength_factor(fc):
    """Forrestal et al.'s empirical ``S = 82.6 f_c^-0.544`` for ``fc`` in Pa (fitted in MPa)."""
    _require_all(fc, "fc", "a finite number > 0 (Pa)", 0.0)
    return S_COEFFICIENT * (np.asarray(fc, dtype=float) / 1e6) ** S_EXPONENT


def ogive_factor(crh):
    """Nose factor ``N* = (8 psi - 1)/(24 psi^2)`` of a tangent ogive, ``psi`` = CRH."""
    _require_all(crh, "crh", "a finite number >= 0.5", 0.5, inclusive=True)
    crh = np.asarray(crh, dtype=float)
    return (8.0 * crh - 1.0) / (24.0 * crh ** 2)


def li_chen_functions(mass, diameter, crh, velocity, fc, rho, S=None):
    """Li and Chen's impact function ``I`` and geometry function ``N`` (dimensionless)."""
    S = strength_factor(fc) if S is None else S
    I = mass * velocity ** 2 / (S * fc * diameter ** 3)  # noqa: E741 (Li and Chen's name)
    N = mass / (ogive_factor(crh) * rho * diameter ** 3)
    return I, N


def penetration_calibres(mass, diameter, crh, velocity, fc, rho, *, S=None,
                         crater_calibres=CRATER_CALIBRES):
    """Depth over diameter ``X/d`` (Li and Chen's dimensionless form of Forrestal et al. 1994),
    elementwise on numbers or arrays (a float for numbers).

    Parameters
    ----------
    mass, diameter, crh, velocity, fc, rho : float or array
        kg, m, 1, m/s, Pa, kg/m^3.
    S : float or array, optional
        Strength factor; default :func:`strength_factor` of ``fc``.
    crater_calibres : float or array
        Crater depth ``k`` in calibres (Forrestal et al.: 2).
    """
    for name, value in (("mass", mass), ("diameter", diameter), ("velocity", velocity),
                        ("rho", rho), ("crater_calibres", crater_calibres)):
        _require_all(value, name, "a finite number > 0", 0.0)
    I, N = li_chen_functions(mass, diameter, crh, velocity, fc, rho, S)  # noqa: E741
    k = np.asarray(crater_calibres, dtype=float)
    crater = 1.0 + k * np.pi / (4.0 * N)
    in_crater = I / N <= crater - 1.0  # V_1^2 <= 0: stops inside the crater
    stopped = np.sqrt(I * (4.0 * k / np.pi) * crater / (1.0 + I / N))
    tunnel = 2.0 * N / np.pi * np.log(np.maximum((1.0 + I / N) / crater, 1.0)) + k
    return _number_or_array(np.where(in_crater, stopped, tunnel))


def forrestal_depth(mass, diameter, crh, velocity, fc, rho, *, S=None,
                    crater_calibres=CRATER_CALIBRES):
    """Penetration depth (m) of Forrestal et al. (1994); see :func:`penetration_calibres`."""
    return diameter * penetration_calibres(mass, diameter, crh, velocity, fc, rho, S=S,
                                           crater_calibres=crater_calibres)


def shot_depth(shot, S=None):
    """Forrestal et al.'s depth (m) for a shot (any object with ``mass, diameter, crh, V0, fc,
    rho``, e.g. a :class:`~cavex.verification.validation.shots.Shot`)."""
    return forrestal_depth(shot.mass, shot.diameter, shot.crh, shot.V0, shot.fc, shot.rho, S=S)


def crater_calibres(crh):
    """Li and Chen's (2003) crater depth ``k = 0.707 + h/d``, ``h/d = sqrt(4 CRH - 1)/2``."""
    return 0.707 + 0.5 * np.sqrt(4.0 * crh - 1.0)  # numbers or arrays


def li_chen_depth(shot):
    """Li and Chen (2003): Forrestal's form with ``S = 72 f_c^-0.5`` and ``k = 0.707 + h/d``."""
    S = LI_CHEN_COEFFICIENT * (shot.fc / 1e6) ** -0.5
    return shot.diameter * penetration_calibres(
        shot.mass, shot.diameter, shot.crh, shot.V0, shot.fc, shot.rho, S=S,
        crater_calibres=crater_calibres(shot.crh))
