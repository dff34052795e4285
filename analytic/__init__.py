"""Closed-form layered cavity expansion, nose resistance and the rigid-projectile integrator."""

from cavex.analytic.cavity import (
    CavityState,
    cavity_solution,
    cavity_stress,
    plastic_radius,
    quasi_static_coefficients,
    response_state,
)
from cavex.analytic.geometry import spherical_problem
from cavex.analytic.paper_model import (
    PaperCoefficients,
    PaperModel,
    paper_coefficients,
    paper_phase_depths,
    paper_stress,
)
from cavex.analytic.penetration.integrator import Trajectory, penetrate
from cavex.analytic.penetration.nose import nose_force, ogive_coefficients
from cavex.analytic.penetration.oblique import Strike, fly
from cavex.analytic.penetration.resistance import ClosedFormResistance, make_resistance

__all__ = ["CavityState", "ClosedFormResistance", "PaperCoefficients", "PaperModel", "Strike",
           "Trajectory", "cavity_solution", "cavity_stress", "fly", "make_resistance",
           "nose_force",
           "ogive_coefficients",
           "paper_coefficients", "paper_phase_depths", "paper_stress", "penetrate",
           "plastic_radius", "quasi_static_coefficients", "response_state", "spherical_problem"]
