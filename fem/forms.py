"""The inertia term of the weak form as a scikit-fem form (assembled once per model).

``int rho_0 u'' du dV`` with ``dV = 4 pi R^2 dR`` in the reference configuration; the internal
force and tangent are in :mod:`cavex.fem.element`.
"""

import numpy as np
from skfem import BilinearForm

FOUR_PI = 4.0 * np.pi


@BilinearForm
def mass(u, v, w):
    """``rho_0 u v 4 pi R^2`` (reference density)."""
    return w.rho * u * v * FOUR_PI * w.x[0] ** 2
