r"""The paper's printed cavity-wall stress, Eqs. (19)-(29) of She (2020), as the model ``"paper"``.

The derived model (:mod:`cavex.analytic.cavity`) solves the layered cavity-expansion problem of
docs/problem.md from first principles. This module instead implements the closed forms *as the paper
prints them*, so that the paper's own numbers (its Table 2) can be reproduced and the effect of
each of its choices measured. Every departure from the printed text is listed in
``docs/paper_model.md``; the comments marked ``CORRECTION (i)`` are OCR/typesetting fixes and the
ones marked ``PRINTED (ii)`` keep a genuine error of the paper on purpose.

Notation (as the paper): ``p_i = alpha_i lam_i = 6 lam_i/(3 + 2 lam_i)`` (twice the ``alpha``
of docs/problem.md), ``eps_i = a/b`` when the elastic-plastic boundary ``b`` lies in layer
``i``, cavity radius ``a = r`` (the projectile radius; the paper's ``Vt`` and ``a``), interface
radii ``h_i = H_i - L + l`` (Eq. 16). The wall stress is ``sigma_r = tau A + B rho V^2``, i.e.
``S = A + B rho V^2 / tau`` with the ``tau`` and ``rho`` that the equation itself uses (Eqs. 23-25
and 28 normalise by the *outermost yielded* layer, not by the layer at the wall).

Case selection (the paper's text): with the nose tip above ``H1`` the three-layer Eqs. (19)-(25)
apply by comparing ``L`` with ``L1``-``L4`` (Eqs. 18, 20, 22, 24), in that order; from ``H1`` to
``H2`` the two-layer Eqs. (26)-(28); below ``H2`` the single-medium Eq. (29). The layers switch
when the nose *tip* crosses an interface (paper's choice). Targets with one or two layers use the
same equations with the layers relabelled (Eqs. 26-28 for two, Eq. 29 for one).
"""

import math
from dataclasses import dataclass

import numpy as np

from cavex.errors import require, require_choice

# Readings of the paper's undefined eps: (2E/3) eps^k = Y -> (k, Y). k = 3 spherical
# (docs/problem.md, consistent with the printed A), k = 2 the incompressible cylindrical cavity;
# Y is tau or the uniaxial strength sigma_c = 3 tau/(3 - lam) of Eq. 2 (docs/table2.md:
# "cylindrical-sigma_c" is the only reading that puts Table 2's L1 at its printed 0.40 m).
EPSILON_FORMS = {
    "quasi-static": (3.0, "tau"),
    "cylindrical": (2.0, "tau"),
    "quasi-static-sigma_c": (3.0, "sigma_c"),
    "cylindrical-sigma_c": (2.0, "sigma_c"),
}
EPSILON_READINGS = tuple(EPSILON_FORMS)
MAX_LAYERS = 3

# (equation, state) for the concentric problem, by number of layers and response index.
THREE_LAYER_EQUATIONS = ((19, "a"), (21, "b"), (23, "c"), (24, "d"), (25, "e"))
TWO_LAYER_EQUATIONS = ((26, "f"), (27, "g"), (28, "h"))


@dataclass(frozen=True)
class PaperCoefficients:
    """Coefficients of the paper's ``S = A + B rho V^2 / tau`` at one nose depth.

    Attributes
    ----------
    A, B : float
        Dimensionless coefficients of the printed equation.
    tau : float
        Shear strength (Pa) that normalises ``S`` in that equation.
    rho : float
        Density (kg/m^3) multiplying ``V^2`` in that equation.
    equation : int
        Paper equation used: 19, 21, 23, 24, 25, 26, 27, 28 or 29.
    state : str
        Paper's Fig. 2 response state ``a``-``h``, or ``"single"`` (Eq. 29).
    """

    A: float
    B: float
    tau: float
    rho: float
    equation: int
    state: str

    def stress(self, velocity):
        """Cavity-wall radial stress ``tau A + B rho V^2`` (Pa, compression positive)."""
        return self.tau * self.A + self.B * self.rho * velocity ** 2

    def S(self, velocity):
        """Dimensionless wall stress ``A + B rho V^2 / tau`` (normalised by :attr:`tau`)."""
        return self.stress(velocity) / self.tau


def alpha_lambda(material):
    """The paper's ``alpha_i lam_i = 6 lam/(3 + 2 lam)`` (``2 alpha`` of docs/problem.md)."""
    return 6.0 * material.lam / (3.0 + 2.0 * material.lam)


def uniaxial_strength(material):
    """``sigma_c = 3 tau/(3 - lam)`` (paper Eq. 2)."""
    return 3.0 * material.tau / (3.0 - material.lam)


def layer_epsilon(material, epsilon="quasi-static"):
    """``eps = a/b`` of a layer under a reading of the paper's undefined ``eps_i = V/c_i``.

    Parameters
    ----------
    material : Material
    epsilon : str
        One of :data:`EPSILON_READINGS`: ``(2E/3) eps^k = Y`` with ``k = 3`` (``"quasi-static"``,
        the spherical elastic zone's yield of docs/problem.md; the only reading consistent with the
        ``2/3`` of the printed ``A``) or ``k = 2`` (``"cylindrical"``, the incompressible
        cylindrical cavity), and ``Y = tau`` or, with the ``-sigma_c`` suffix, ``sigma_c``.
    """
    require_choice(epsilon, EPSILON_READINGS, "epsilon")
    exponent, strength = EPSILON_FORMS[epsilon]
    y = material.tau if strength == "tau" else uniaxial_strength(material)
    return (1.5 * y / material.E) ** (1.0 / exponent)


def check_target(target):
    """The paper's equations cover at most three layers."""
    require(len(target.layers) <= MAX_LAYERS, "target.layers",
            f"at most {MAX_LAYERS} layers for the paper model", len(target.layers))


def check_paper_material(material, index):
    """Reject ``lam`` where the printed formulas divide by zero (``1/lam``, ``1/(p - 1)``)."""
    require(material.lam > 0.0, f"layers[{index}].lam",
            "> 0 for the paper model (its formulas contain 1/lam)", material.lam)
    require(alpha_lambda(material) != 1.0, f"layers[{index}].lam",
            "!= 0.75 for the paper model (its formulas contain 1/(alpha lam - 1))", material.lam)


def paper_phase_depths(target, projectile, epsilon="quasi-static"):
    """Nose depths at which the paper's response state changes (Eqs. 18, 20, 22, 24).

    For every interface ``k`` (depth ``H_k``) the elastic-plastic boundary reaches it at
    ``L_{2k-1} = H_k + l - r/eps_k`` and the layer below yields at
    ``L_{2k} = H_k + l - r/eps_{k+1}``. For the three-layer runway these are
    ``L1 = H1 + l - r/eps1``, ``L2 = H1 + l - r/eps2``, ``L3 = H2 + l - r/eps2``,
    ``L4 = H2 + l - r/eps3``.

    Parameters
    ----------
    target : Target
        At most three layers.
    projectile : Projectile
    epsilon : {"quasi-static", "cylindrical"}
        Reading of ``eps_i`` (see :func:`layer_epsilon`).

    Returns
    -------
    dict
        ``{"L1": ..., "L2": ..., "H1": ..., ...}`` (m); empty for a single layer.
    """
    check_target(target)
    eps = [layer_epsilon(m, epsilon) for m in target.layers]
    depths = {}
    for k, H in enumerate(target.interface_depths):
        depths[f"L{2 * k + 1}"] = H + projectile.l - projectile.r / eps[k]
        depths[f"L{2 * k + 2}"] = H + projectile.l - projectile.r / eps[k + 1]
        depths[f"H{k + 1}"] = H
    return depths


def response_index(depth, boundary_reached, next_yields):
    """Position of ``depth`` among the paper's conditions ``L <= L_b < L < L_y <= ...``.

    ``boundary_reached`` and ``next_yields`` are the depths ``L_{2k-1}`` and ``L_{2k}`` of each
    interface of the concentric problem, innermost first. Returns ``2k`` when the boundary lies in
    layer ``k`` and ``2k + 1`` when it is held at interface ``k`` (the paper's ``L1 < L < L2``).
    """
    index = 0
    for reached, yields in zip(boundary_reached, next_yields, strict=True):
        if depth <= reached:
            return index
        if depth < yields:
            return index + 1
        index += 2
    return index


class PaperModel:
    """The paper's case selection and equations for one target, projectile and ``epsilon``
    reading, with everything that does not depend on the depth computed once.

    :func:`paper_coefficients` is this model's :meth:`coefficients`; the penetration
    integrator holds one model and calls :meth:`terms` at every force evaluation.
    """

    def __init__(self, target, projectile, epsilon="quasi-static"):
        check_target(target)
        self.target, self.projectile = target, projectile
        self.eps = [layer_epsilon(m, epsilon) for m in target.layers]
        # per wall layer ``first``: the layers around the cavity, their eps, interface depths
        # and case thresholds, and whether their materials passed the checks
        self._segments = [
            (target.layers[first:], self.eps[first:], target.interface_depths[first:],
             case_thresholds(self.eps[first:], projectile.r, projectile.l,
                             target.interface_depths[first:]))
            for first in range(len(target.layers))]
        self._checked = set()

    def coefficients(self, depth):
        """:class:`PaperCoefficients` at nose-tip depth ``depth`` (m), >= 0."""
        A, B, tau, rho, equation, state = self.terms(depth)
        return PaperCoefficients(A=A, B=B, tau=tau, rho=rho, equation=equation, state=state)

    def terms(self, depth):
        """``(A, B, tau, rho, equation, state)`` at nose-tip depth ``depth`` (m), >= 0: the
        fields of :meth:`coefficients` as a tuple (the integrator's hot path)."""
        if not (isinstance(depth, (int, float)) and math.isfinite(depth) and depth >= 0.0):
            require(False, "depth", "a finite number >= 0", depth)
        first = self.target.layer_at(depth)  # nose-tip switch: interfaces go to the deeper layer
        layers, eps, interface_depths, thresholds = self._segments[first]
        if first not in self._checked:
            for offset, material in enumerate(layers):
                check_paper_material(material, first + offset)
            self._checked.add(first)
        r, nose = self.projectile.r, self.projectile.l
        if interface_depths and not interface_depths[0] - depth + nose > r:  # nearest interface
            h = interface_depths[0] - depth + nose
            require(False, "depth", f"such that the next interface is beyond the cavity "
                    f"(h = {h} m <= r = {r} m: nose length l shorter than r)", depth)
        return apply_equation(layers, eps, r, nose, depth, interface_depths, thresholds)


def paper_coefficients(target, projectile, depth, epsilon="quasi-static"):
    """Coefficients ``A``, ``B`` of the paper's wall stress at nose depth ``depth``.

    Parameters
    ----------
    target : Target
        At most three layers; every ``lam`` used must be > 0 and != 0.75.
    projectile : Projectile
        ``r`` is the cavity radius, ``l`` places the cavity centre.
    depth : float
        Nose-tip depth ``L`` (m), >= 0.
    epsilon : {"quasi-static", "cylindrical"}
        Reading of ``eps_i`` (see :func:`layer_epsilon`).

    Returns
    -------
    PaperCoefficients
    """
    return PaperModel(target, projectile, epsilon).coefficients(depth)


def select_equation(layers, eps, r, nose, depth, interface_depths, forms=None):
    """The paper's case selection: ``(A, B, tau, rho, equation, state)`` at nose depth ``depth``.

    ``layers`` and their ``eps`` surround the cavity (innermost first), ``interface_depths`` are
    their interface depths ``H_i``; ``forms`` overrides printed equations by number (readings of
    the Table 2 study).
    """
    thresholds = case_thresholds(eps, r, nose, interface_depths)
    return apply_equation(layers, eps, r, nose, depth, interface_depths, thresholds, forms)


def case_thresholds(eps, r, nose, interface_depths):
    """The depths ``(L_b, L_y)`` of each interface (innermost first) that
    :func:`response_index` compares the nose depth with; they do not depend on the depth."""
    reached = [H + nose - r / eps[k] for k, H in enumerate(interface_depths)]
    yields = [H + nose - r / eps[k + 1] for k, H in enumerate(interface_depths)]
    return reached, yields


def apply_equation(layers, eps, r, nose, depth, interface_depths, thresholds, forms=None):
    """:func:`select_equation` with the :func:`case_thresholds` given."""
    forms = {**FORMS, **forms} if forms else FORMS
    if len(layers) == 1:
        return (*forms[29](layers[0], eps[0]), 29, "single")
    heights = [H - depth + nose for H in interface_depths]
    index = response_index(depth, *thresholds)
    equations = TWO_LAYER_EQUATIONS if len(layers) == 2 else THREE_LAYER_EQUATIONS
    equation, state = equations[index]
    return (*forms[equation](*layers, *eps, r, *heights), equation, state)


def paper_stress(target, projectile, depth, velocity, epsilon="quasi-static"):
    """The paper's cavity-wall radial stress ``sigma_r`` (Pa) at nose depth ``depth``.

    See :func:`paper_coefficients`; ``velocity`` is the cavity expansion velocity (m/s), >= 0.
    ``depth`` and ``velocity`` may be arrays (broadcast together): the coefficients are computed
    once per distinct depth and applied to all its velocities. Float for scalar input.
    """
    velocity_array = np.asarray(velocity, dtype=float)
    ok = np.isfinite(velocity_array) & (velocity_array >= 0.0)
    if not ok.all():
        require(False, "velocity", "a finite number >= 0",
                np.broadcast_to(velocity, ok.shape)[~ok].flat[0].item())
    model = PaperModel(target, projectile, epsilon)
    depth_array = np.asarray(depth, dtype=float)
    if depth_array.ndim == 0 and velocity_array.ndim == 0:
        return model.coefficients(float(depth)).stress(float(velocity))
    depths, velocities = np.broadcast_arrays(depth_array, velocity_array)
    out = np.empty(depths.shape)
    unique, inverse = np.unique(depths, return_inverse=True)
    inverse = inverse.reshape(depths.shape)
    for j, L in enumerate(unique):
        at = inverse == j
        out[at] = model.coefficients(float(L)).stress(velocities[at])
    return out


def paper_single_coefficients(material, epsilon="quasi-static"):
    """Eq. (29) for one semi-infinite medium (the paper also uses it for the crater, Eq. 34)."""
    check_paper_material(material, 0)
    return single_medium_coefficients(material, layer_epsilon(material, epsilon))


# --------------------------------------------------------------------------------------------
# The printed equations. Arguments: materials innermost first, their eps, cavity radius r and
# interface radii h (innermost first). Each returns (A, B, tau, rho) of ``tau A + B rho V^2``.
# --------------------------------------------------------------------------------------------

def eq19(m1, m2, m3, eps1, eps2, eps3, r, h1, h2):
    """State (a): ``b`` in layer 1 (``L <= L1``); normalised by ``tau1``, ``rho1``."""
    p1 = alpha_lambda(m1)
    A = -1 / m1.lam + eps1 ** -p1 * (
        1 / m1.lam + 2 / 3
        + 2 / (3 * m1.E) * (r / (eps1 * h1)) ** 3 * (m2.E - m1.E)
        + 2 / (3 * m1.E) * (r / (eps1 * h2)) ** 3 * (m3.E - m2.E))
    # CORRECTION (i): printed 3 tau01/(rho_i E1) lacks the eps1^2 that Eqs. 23, 25, 26, 28 have;
    # rho_i is rho1 (the equation is normalised by layer 1).
    elastic_inertia = 3 * m1.tau / (m1.rho * eps1 ** 2 * m1.E) * (
        m1.rho + r / (eps1 * h1) * (m2.rho - m1.rho) + r / (eps1 * h2) * (m3.rho - m2.rho))
    B = (-2 / (p1 - 1) + 2 / (p1 - 4)
         + (2 * eps1 / (p1 - 1) - 2 * eps1 ** 4 / (p1 - 4) + elastic_inertia) * eps1 ** -p1)
    return A, B, m1.tau, m1.rho


def eq21(m1, m2, m3, eps1, eps2, eps3, r, h1, h2):
    """State (b): ``b`` held at ``h1``, layer 2 elastic (``L1 < L < L2``); ``tau1``, ``rho1``."""
    p1 = alpha_lambda(m1)
    x1 = (h1 / r) ** p1
    A = -1 / m1.lam + x1 * (
        1 / m1.lam + 4 * m2.E / (9 * m1.tau) * (r / h1) ** 3
        + 4 / (9 * m1.tau) * (r / h2) ** 3 * (m3.E - m2.E))
    B = -2 / (p1 - 1) + 2 / (p1 - 4) + x1 * (
        1 / (p1 - 1) * 2 * r / h1 - 2 / (p1 - 4) * (r / h1) ** 4
        + m2.rho / m1.rho * 2 * r / h1 + 1 / m1.rho * 2 * r / h2 * (m3.rho - m2.rho))
    return A, B, m1.tau, m1.rho


def eq23(m1, m2, m3, eps1, eps2, eps3, r, h1, h2):
    """State (c): ``b = r/eps2`` in layer 2 (``L2 < L < L3``); normalised by ``tau2``, ``rho2``."""
    p1, p2 = alpha_lambda(m1), alpha_lambda(m2)
    b = r / eps2
    t12, q12 = m1.tau / m2.tau, m1.rho / m2.rho
    x1 = (h1 / (eps2 * b)) ** p1
    A = -1 / m1.lam * t12 + x1 * (
        -1 / m2.lam + 1 / m1.lam * t12
        + (2 / 3 + 2 / (3 * m2.E) * (b / h2) ** 3 * (m3.E - m2.E) + 1 / m2.lam)
        * (h1 / b) ** -p2)
    B = -2 * q12 / (p1 - 1) + 2 * q12 / (p1 - 4) + x1 * (
        b / h1 * (2 * q12 * eps2 / (p1 - 1) - 2 * eps2 / (p2 - 1))
        # CORRECTION (i): printed 2 rho1 eps2^4/(rho2 (alpha2 lam2 - 4)); layer 1's term has p1.
        + (b / h1) ** 4 * (2 * eps2 ** 4 / (p2 - 4) - 2 * q12 * eps2 ** 4 / (p1 - 4))
        + (h1 / b) ** -p2 * (
            3 * m2.tau / (eps2 ** 2 * m2.E)
            + 3 * m2.tau * b / (m2.E * eps2 ** 2 * h2) / m2.rho * (m3.rho - m2.rho)
            + 2 * eps2 / (p2 - 1) - 2 * eps2 ** 4 / (p2 - 4)))
    return A, B, m2.tau, m2.rho


def eq24(m1, m2, m3, eps1, eps2, eps3, r, h1, h2):
    """State (d): ``b`` held at ``h2``, layer 3 elastic (``L3 < L < L4``); ``tau2``, ``rho2``."""
    p1, p2 = alpha_lambda(m1), alpha_lambda(m2)
    t12 = m1.tau / m2.tau
    x1, x2 = (h1 / r) ** p1, (h2 / h1) ** p2  # CORRECTION (i): the paper's Vt and a are r
    A = -1 / m1.lam * t12 + x1 * (
        1 / m1.lam * t12 - 1 / m2.lam
        + x2 * (1 / m2.lam + 4 * m3.E / (9 * m2.tau) * (r / h2) ** 3))
    # PRINTED (ii): the first term has + (Eqs. 24 and 25); the derivation gives -.
    # CORRECTION (i): a '+' is missing before (h1/a)^(alpha1 lam1) in the print.
    B = 2 * m1.rho / (m2.rho * (p1 - 1)) + 2 * m1.rho / (m2.rho * (p1 - 4)) + x1 * (
        2 / m2.rho * r / h1 * (m1.rho / (p1 - 1) - m2.rho / (p2 - 1))
        + 2 / m2.rho * (r / h1) ** 4 * (m2.rho / (p2 - 4) - m1.rho / (p1 - 4))
        + x2 * (2 / m2.rho * r / h2 * (m3.rho + m2.rho / (p2 - 1))
                - 2 / (p2 - 4) * (r / h2) ** 4))
    return A, B, m2.tau, m2.rho


def eq25(m1, m2, m3, eps1, eps2, eps3, r, h1, h2):
    """State (e): ``b = r/eps3`` in layer 3 (``L4 < L < H1``); normalised by ``tau3``, ``rho3``."""
    p1, p2, p3 = alpha_lambda(m1), alpha_lambda(m2), alpha_lambda(m3)
    b = r / eps3
    t13, t23 = m1.tau / m3.tau, m2.tau / m3.tau
    x1, x2, x3 = (h1 / (b * eps3)) ** p1, (h2 / h1) ** p2, (b / h2) ** p3
    A = -1 / m1.lam * t13 + x1 * (
        1 / m1.lam * t13 - 1 / m2.lam * t23
        + x2 * (1 / m2.lam * t23 - 1 / m3.lam + x3 * (2 / 3 + 1 / m3.lam)))
    # PRINTED (ii): the first term has + (as in Eq. 24); the derivation gives -.
    B = 2 * m1.rho / (m3.rho * (p1 - 1)) + 2 * m1.rho / (m3.rho * (p1 - 4)) + x1 * (
        2 * eps3 / m3.rho * b / h1 * (m1.rho / (p1 - 1) - m2.rho / (p2 - 1))
        + 2 * eps3 ** 4 / m3.rho * (b / h1) ** 4 * (m2.rho / (p2 - 4) - m1.rho / (p1 - 4))
        + x2 * (2 * eps3 / m3.rho * b / h2 * (m2.rho / (p2 - 1) - m3.rho / (p3 - 1))
                + 2 * eps3 ** 4 / m3.rho * (b / h2) ** 4 * (m3.rho / (p3 - 4) - m2.rho / (p2 - 4))
                + x3 * (3 * m3.tau / (eps3 ** 2 * m3.E) + 2 * eps3 / (p3 - 1)
                        - 2 * eps3 ** 4 / (p3 - 4))))
    return A, B, m3.tau, m3.rho


def eq26(m2, m3, eps2, eps3, r, h2):
    """State (f): ``b = r/eps2`` in layer 2 (``H1 <= L < L3``); normalised by ``tau2``, ``rho2``."""
    p2 = alpha_lambda(m2)
    b = r / eps2
    A = -1 / m2.lam + eps2 ** -p2 * (
        2 / 3 + 2 / (3 * m2.E) * (b / h2) ** 3 * (m3.E - m2.E) + 1 / m2.lam)
    B = -2 / (p2 - 1) + 2 / (p2 - 4) + eps2 ** -p2 * (
        3 * m2.tau / (eps2 ** 2 * m2.E)
        + 3 * m2.tau * b / (eps2 ** 2 * m2.rho * m2.E * h2) * (m3.rho - m2.rho)
        + 2 * eps2 / (p2 - 1) - 2 * eps2 ** 4 / (p2 - 4))
    return A, B, m2.tau, m2.rho


def eq27(m2, m3, eps2, eps3, r, h2):
    """State (g): ``b`` held at ``h2``, layer 3 elastic (``L3 < L < L4``); ``tau2``, ``rho2``."""
    p2 = alpha_lambda(m2)
    x2 = (h2 / r) ** p2  # CORRECTION (i): the paper's Vt is r
    A = -1 / m2.lam + x2 * (1 / m2.lam + 4 * m3.E / (9 * m2.tau) * (r / h2) ** 3)
    B = -2 / (p2 - 1) + 2 / (p2 - 4) + x2 * (
        2 / m2.rho * r / h2 * (m3.rho + m2.rho / (p2 - 1)) - 2 / (p2 - 4) * (r / h2) ** 4)
    return A, B, m2.tau, m2.rho


def eq28(m2, m3, eps2, eps3, r, h2):
    """State (h): ``b = r/eps3`` in layer 3 (``L4 < L < H2``); normalised by ``tau3``, ``rho3``."""
    p2, p3 = alpha_lambda(m2), alpha_lambda(m3)
    b = r / eps3
    t23, q23 = m2.tau / m3.tau, m2.rho / m3.rho
    x2, x3 = (h2 / (b * eps3)) ** p2, (b / h2) ** p3
    # CORRECTION (i): printed -(1/lam1)(tau02/tau03); the layer of tau02 is layer 2 (lam2).
    A = -1 / m2.lam * t23 + x2 * (1 / m2.lam * t23 - 1 / m3.lam + x3 * (2 / 3 + 1 / m3.lam))
    B = -2 * q23 / (p2 - 1) + 2 * q23 / (p2 - 4) + x2 * (
        2 * eps3 / m3.rho * b / h2 * (m2.rho / (p2 - 1) - m3.rho / (p3 - 1))
        + 2 * eps3 ** 4 / m3.rho * (b / h2) ** 4 * (m3.rho / (p3 - 4) - m2.rho / (p2 - 4))
        + x3 * (3 * m3.tau / (eps3 ** 2 * m3.E) + 2 * eps3 / (p3 - 1) - 2 * eps3 ** 4 / (p3 - 4)))
    return A, B, m3.tau, m3.rho


def eq29(m3, eps3):
    """Single medium (``L >= H2``); normalised by ``tau3``, ``rho3``."""
    p3 = alpha_lambda(m3)
    A = 2 / p3 * eps3 ** -p3 - 1 / m3.lam
    # PRINTED (ii): the lone + eps3^(-p3) term is not in the derivation (nor in Eq. 19 with
    # identical layers); it adds rho V^2 eps^(-p) to the wall stress.
    B = (6 / ((1 - p3) * (4 - p3)) + eps3 ** -p3
         - 2 * p3 / (1 - p3) * eps3 ** (1 - p3) + 2 * eps3 ** (4 - p3) / (4 - p3))
    return A, B, m3.tau, m3.rho


def single_medium_coefficients(material, eps):
    """Eq. (29) packed as :class:`PaperCoefficients`."""
    A, B, tau, rho = eq29(material, eps)
    return PaperCoefficients(A=A, B=B, tau=tau, rho=rho, equation=29, state="single")


THREE_LAYER_FORMS = {19: eq19, 21: eq21, 23: eq23, 24: eq24, 25: eq25}
TWO_LAYER_FORMS = {26: eq26, 27: eq27, 28: eq28}
FORMS = {**THREE_LAYER_FORMS, **TWO_LAYER_FORMS, 29: eq29}
