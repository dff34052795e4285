"""cavex: checks closed-form layered spherical cavity-expansion resistance.

Parts: ``cavex.analytic`` (closed forms, nose force, penetration integrator), ``cavex.fem``
(spherically symmetric Lagrangian elastoplastic FE solver) and ``cavex.verification``.
"""

from cavex.config import load_config
from cavex.errors import CavexInputError, CavexNumericalError
from cavex.materials import Material, Projectile, Target

__all__ = ["CavexInputError", "CavexNumericalError", "Material", "Projectile", "Target",
           "load_config"]
__version__ = "0.1.0"
