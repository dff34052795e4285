"""Penetration resistance at nose depth ``L`` and velocity ``V`` from a cavity-expansion model.

A resistance model answers two questions for the integrator: the axial nose force ``F(L, V)``
(N) and the response-state label of the phase it is in. ``crater_force(V)`` is the force of the
single-medium (first layer) model that the crater stage uses (paper Eq. 34).

Both answers at one ``(L, V)`` come from one evaluation of the closed form through its array
form (:func:`cavex.analytic.cavity.nose_walk`, the compiled walk over the points of one
depth): the derived dynamic model solves the cavity at the nose quadrature's velocities
``V cos(phi_k)`` and at ``V`` itself (the label) in one call; the quasi-static one gets
``sigma_r = sigma_0 + sigma_2 V^2`` and the label from one point, and the force exactly as
``C_A + C_B V^2``; the paper model computes its coefficients once. The last few answers are
kept: the integrator asks for the label at points where it has asked for the force.
"""

import math
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from cavex.analytic.cavity import material_table, nose_walk, state_label
from cavex.analytic.geometry import spherical_problem, surrounding
from cavex.analytic.paper_model import PaperModel
from cavex.analytic.penetration.nose import nose_rule, ogive_coefficients
from cavex.errors import CavexNumericalError, require, require_choice
from cavex.problem import BOUNDARIES

RECENT = 32  # (depth, velocity) answers kept


@dataclass(frozen=True)
class ClosedForm:
    """One closed form :class:`ClosedFormResistance` evaluates, and what it accepts.

    ``printed``: the paper's printed coefficients (:class:`~cavex.analytic.paper_model.
    PaperModel`), else the derived cavity solution (:func:`~cavex.analytic.cavity.nose_walk`);
    ``boundaries``: the yield-at-boundary conventions it takes, its default first;
    ``switch``: when a layer stops surrounding the cavity by default (``geometry``);
    ``debonded``: it models a debonded interface (the derived form's traction-free sphere).
    """

    name: str
    printed: bool
    boundaries: tuple
    switch: str
    debonded: bool


#: the two closed forms this module evaluates, by the name of the model that flies each
CLOSED_FORMS = {form.name: form for form in (
    ClosedForm("derived", printed=False, boundaries=("dynamic", "quasi-static"),
               switch="cavity", debonded=True),
    ClosedForm("paper", printed=True, boundaries=("quasi-static",), switch="nose-tip",
               debonded=False))}


@runtime_checkable
class Resistance(Protocol):
    r"""What the 1-D integrator (:mod:`cavex.analytic.penetration.integrator`) asks a resistance.

    The motion is ``m dV/dt = -F(L, V)``, ``dL/dt = V`` at nose-tip depth ``L`` (m, >= 0) and
    velocity ``V`` (m/s, >= 0; the integrator clips negative trial values to 0).

    - ``force(depth, velocity)``: the axial nose force ``F(L, V)`` (N) against the motion; a
      function of ``(L, V)`` alone, with no history (the integrator evaluates trial points in
      any order and repeats some).
    - ``label(depth, velocity)``: the response-state label (str) of the phase ``(L, V)`` is in.
      A tunnel phase ends where the label changes (a terminal event of the integrator, located
      to round-off), so equal labels must mean the same law of ``F``.
    - ``crater_force(velocity)``: the force ``F_1(V)`` (N) of the crater medium alone (in the
      paper the first layer as a single medium), which sets the crater stage:
      ``K L_c = F_1(V_c)`` and ``m (V_0^2 - V_c^2) = L_c F_1(V_c)`` (Eqs. 31-34).

    Input outside the model's range raises :class:`~cavex.errors.CavexInputError`, a closed
    form that fails to converge :class:`~cavex.errors.CavexNumericalError`.
    """

    def force(self, depth, velocity):
        """Axial nose force ``F(L, V)`` (N)."""
        ...

    def label(self, depth, velocity):
        """Response-state label of the phase at ``(L, V)``."""
        ...

    def crater_force(self, velocity):
        """Force ``F_1(V)`` (N) of the crater medium alone."""
        ...


class ClosedFormResistance(Resistance):
    """Resistance from the derived closed forms or the paper's printed model.

    Parameters
    ----------
    target, projectile : Target, Projectile
    model : {"derived", "paper"}
    boundary : {"dynamic", "quasi-static"}, optional
        Yield-at-boundary convention of the derived model; default (None) "dynamic" for the
        derived model and the paper's own quasi-static for the paper model (which accepts
        no other).
    switch : {"cavity", "nose-tip"}, optional
        When a layer stops surrounding the cavity (see ``geometry``); default "cavity" for
        "derived" and "nose-tip" for "paper", as the paper does.
    epsilon : str
        The paper model's reading of epsilon (see ``paper_model``).
    """

    def __init__(self, target, projectile, model="derived", boundary=None,
                 switch=None, epsilon="quasi-static"):
        require_choice(model, tuple(CLOSED_FORMS), "model")
        form = CLOSED_FORMS[model]
        if boundary is not None:
            require_choice(boundary, BOUNDARIES, "boundary")
        require(boundary is None or boundary in form.boundaries, "boundary",
                f"'{form.boundaries[0]}' for the {form.name} model", boundary)
        require(form.debonded or not target.debonded, "interfaces",
                f"'bonded' for the {form.name} model (a debonded interface needs the derived "
                "closed form's traction-free sphere)", "debonded")
        boundary = boundary or form.boundaries[0]
        self.target, self.projectile = target, projectile
        self.model, self.boundary, self.epsilon = model, boundary, epsilon
        self.switch = switch or form.switch
        spherical_problem(target, projectile, 0.0, self.switch)  # validates the switch
        self._single = None if target.layers[1:] == () else ClosedFormResistance(
            target.single(0), projectile, model, boundary, switch, epsilon)
        self._paper = PaperModel(target, projectile, epsilon) if form.printed else None
        n = len(target.layers)
        # the layers the cavity in layer i sees: down to the first debonded interface below
        # (its radius is then a traction-free sphere), else all (docs/analytic.md)
        self._ends = [next((j for j in target.debonded if j >= i), None) for i in range(n)]
        self._tables = [material_table(tuple(target.layers[i:(n if end is None else end + 1)]))
                        for i, end in enumerate(self._ends)]
        self._layer_forces = {}
        self._names = target.layer_names()
        self._cosines, self._weights = nose_rule(projectile)
        self._dynamic = boundary == "dynamic"
        self._r = float(projectile.r)
        # C_A + C_B V^2 per unit sigma_0 and sigma_2 (Eqs. 13-14 with tau = rho = 1)
        self._per_static, self._per_v2 = ogive_coefficients(projectile, 1.0, 1.0, 1.0, 1.0)
        self._codes = np.empty(3, dtype=np.int64)
        self._recent = {}  # (depth, velocity) -> (force, label or its parts)

    def force(self, depth, velocity):
        """Axial nose force (N) at nose-tip depth ``depth`` and velocity ``velocity``."""
        return self.evaluate(depth, velocity)[0]

    def label(self, depth, velocity):
        """Phase label: wall layer name and response state (or the paper's equation)."""
        label = self.evaluate(depth, velocity)[1]
        if len(label) == 2:
            return f"Eq. {label[0]} ({label[1]})"
        first, position, flags, active = label
        return f"{self._names[first]} ({state_label(position, flags, active)})"

    def crater_force(self, velocity):
        """Force of the single-medium model of the first layer (used by the crater stage)."""
        return (self._single or self).force(0.0, velocity)

    def layer_force(self, index, velocity):
        """Force of the single-medium model of layer ``index`` (the crater stage below a
        debonded interface; layer 0: :meth:`crater_force`)."""
        if index == 0:
            return self.crater_force(velocity)
        if index not in self._layer_forces:
            self._layer_forces[index] = ClosedFormResistance(
                self.target.single(index), self.projectile, self.model, self.boundary,
                self.switch, self.epsilon)
        return self._layer_forces[index].force(0.0, velocity)

    def evaluate(self, depth, velocity):
        """``(force, label parts)`` at ``(depth, velocity)``: the derived model's label as the
        codes ``(wall layer, position, flags, active layers)`` of :func:`state_label`, the
        paper's as ``(equation, state)`` (:meth:`label` writes them out).

        The answers of the last few points are kept: the integrator asks for the label where
        it asked for the force a few evaluations before (DOP853's dense-output stages come
        in between).
        """
        key = (depth, velocity)
        value = self._recent.get(key)
        if value is None:
            if len(self._recent) >= RECENT:
                self._recent.clear()
            value = (self._paper_evaluate(depth, velocity) if self._paper is not None
                     else self._derived_evaluate(depth, velocity))
            self._recent[key] = value
        return value

    def _paper_evaluate(self, depth, velocity):
        A, B, tau, rho, equation, state = self._paper.terms(depth)
        c_a, c_b = ogive_coefficients(self.projectile, A, B, tau, rho)
        return c_a + c_b * velocity ** 2, (equation, state)

    def _derived_evaluate(self, depth, velocity):
        if not (math.isfinite(depth) and depth >= 0.0):
            spherical_problem(self.target, self.projectile, depth, self.switch)  # raises
        first, interfaces = surrounding(self.target.interface_depths, self.projectile, depth,
                                        self.switch)
        codes = self._codes
        end, free_radius = self._ends[first], np.inf
        if end is not None:  # a debonded interface below: a traction-free sphere there
            free_radius = interfaces[end - first]
            interfaces = interfaces[:end - first]
        first_part, second_part, failed = nose_walk(
            self._tables[first], np.array([interfaces]).reshape(1, len(interfaces)),
            float(velocity), self._cosines, self._weights, self._r, self._dynamic, codes,
            free_radius)
        if failed:
            raise CavexNumericalError("dynamic elastic-plastic boundary did not converge "
                                      f"(V <= {velocity} m/s, depth {depth} m)")
        if self._dynamic:
            force = first_part
        else:
            force = self._per_static * first_part + self._per_v2 * second_part * velocity ** 2
        return force, (first, *codes.tolist())
