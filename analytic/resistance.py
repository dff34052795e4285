"""Penetration resistance at nose depth ``L`` and velocity ``V`` from a cavity-expansion model.

A resistance model answers two questions for the integrator: the axial nose force ``F(L, V)``
(N) and the response-state label of the phase it is in. ``crater_force(V)`` is the force of the
single-medium (first layer) model that the crater stage uses (paper Eq. 34).
"""

from cavex.analytic.cavity import quasi_static_coefficients, solve_checked, wall_stress
from cavex.analytic.geometry import spherical_problem, wall_layer
from cavex.analytic.nose import nose_force, ogive_coefficients
from cavex.analytic.paper_model import paper_coefficients
from cavex.errors import require, require_choice

MODELS = ("derived", "paper")


def check_model(model, boundary):
    """The model is known, and the paper model is only offered with its quasi-static boundary."""
    require_choice(model, MODELS, "model")
    require(model != "paper" or boundary == "quasi-static", "boundary",
            "'quasi-static' for the paper model", boundary)


class ClosedFormResistance:
    """Resistance from the derived closed forms or the paper's printed model.

    Parameters
    ----------
    target, projectile : Target, Projectile
    model : {"derived", "paper"}
    boundary : {"quasi-static", "dynamic"}
        Yield-at-boundary convention of the derived model (the paper's is quasi-static).
    switch : {"cavity", "nose-tip"}, optional
        When a layer stops surrounding the cavity (see ``geometry``); default "cavity" for
        "derived" and "nose-tip" for "paper", as the paper does.
    epsilon : str
        The paper model's reading of epsilon (see ``paper_model``).
    """

    def __init__(self, target, projectile, model="derived", boundary="quasi-static",
                 switch=None, epsilon="quasi-static"):
        check_model(model, boundary)
        self.target, self.projectile = target, projectile
        self.model, self.boundary, self.epsilon = model, boundary, epsilon
        self.switch = switch or ("cavity" if model == "derived" else "nose-tip")
        self._single = None if target.layers[1:] == () else ClosedFormResistance(
            target.single(0), projectile, model, boundary, switch, epsilon)

    def force(self, depth, velocity):
        """Axial nose force (N) at nose-tip depth ``depth`` and velocity ``velocity``."""
        if self.model == "paper":
            return self._paper_force(depth, velocity)
        layers, interfaces = spherical_problem(self.target, self.projectile, depth, self.switch)
        if self.boundary == "quasi-static":
            return self._quadratic_force(layers, interfaces, velocity)
        r = self.projectile.r

        def stress(v):
            return wall_stress(layers, interfaces, v, r, self.boundary)[0]

        return nose_force(self.projectile, stress, velocity)

    def _quadratic_force(self, layers, interfaces, velocity):
        static, per_v2 = quasi_static_coefficients(layers, interfaces, self.projectile.r)
        c_a, c_b = ogive_coefficients(self.projectile, static, per_v2, 1.0, 1.0)
        return c_a + c_b * velocity ** 2

    def _paper_force(self, depth, velocity):
        c = paper_coefficients(self.target, self.projectile, depth, epsilon=self.epsilon)
        c_a, c_b = ogive_coefficients(self.projectile, c.A, c.B, c.tau, c.rho)
        return c_a + c_b * velocity ** 2

    def label(self, depth, velocity):
        """Phase label: wall layer name and response state (or the paper's equation)."""
        if self.model == "paper":
            c = paper_coefficients(self.target, self.projectile, depth, epsilon=self.epsilon)
            return f"Eq. {c.equation} ({c.state})"
        layers, interfaces = spherical_problem(self.target, self.projectile, depth, self.switch)
        state = solve_checked(layers, interfaces, velocity, self.projectile.r, self.boundary).state
        index = wall_layer(self.target, self.projectile, depth, self.switch)
        return f"{self.target.layers[index].name or f'layer {index + 1}'} ({state})"

    def crater_force(self, velocity):
        """Force of the single-medium model of the first layer (used by the crater stage)."""
        return (self._single or self).force(0.0, velocity)
