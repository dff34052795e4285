"""Closed-form layered cavity expansion, nose resistance and the rigid-projectile integrator."""

from cavex.analytic.cavity import CavityState, cavity_solution, cavity_stress, plastic_radius

__all__ = ["CavityState", "cavity_solution", "cavity_stress", "plastic_radius"]
