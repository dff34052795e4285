"""Closed-form layered cavity expansion, nose resistance and the rigid-projectile integrator.

The names below are imported on first use (PEP 562), so that importing one submodule (e.g. the
resistance vocabulary the command line's parser needs) does not compile or load the others
(numba, scipy)."""

from cavex.lazy import lazy_names

#: public name -> the submodule that defines it
_WHERE = {
    "CavityState": "cavity", "cavity_solution": "cavity", "cavity_stress": "cavity",
    "plastic_radius": "cavity", "quasi_static_coefficients": "cavity",
    "response_state": "cavity",
    "spherical_problem": "geometry",
    "PaperCoefficients": "paper_model", "PaperModel": "paper_model",
    "paper_coefficients": "paper_model", "paper_phase_depths": "paper_model",
    "paper_stress": "paper_model",
    "Trajectory": "penetration.integrator", "penetrate": "penetration.integrator",
    "nose_force": "penetration.nose", "ogive_coefficients": "penetration.nose",
    "Strike": "penetration.oblique", "fly": "models",
    "ClosedFormResistance": "penetration.resistance",
    "make_resistance": "models", "make_law": "models",
}

__all__ = sorted(_WHERE)
__getattr__, __dir__ = lazy_names(__name__, _WHERE)
