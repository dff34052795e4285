r"""The FE's material record: a layer's constants as the compiled kernels read them.

Every element of a model carries one record of :data:`MATERIAL` (a numpy structured array,
which numba compiles to a struct: ``material[e].K``). :func:`pack_layers` is the one place where
a :class:`cavex.materials.Material` becomes kernel data; the stack concatenates the records of
its cases without naming a field, the element kernel hands an element's record to the point
kernel (:func:`cavex.fem.constitutive.return_point`), which alone reads the constitutive fields.
A new constant of the constitutive law (a hydrostat, another strength surface) is a field here,
its value in :func:`pack_layers`, and its use in :mod:`cavex.fem.constitutive`.

Fields (SI units):

- ``K = E/(3(1 - 2 nu))``, ``G = E/(2(1 + nu))``: the Hencky bulk and shear moduli (Pa);
- ``rho``: the density (kg/m^3), for the mass matrix;
- ``lam``, ``tau``: the Mohr-Coulomb line ``sigma_r - sigma_theta = lam sigma + tau``;
- ``lam_psi = 6 sin psi / (3 - sin psi)``: the flow coefficient of the dilatancy angle ``psi``;
- ``tension``: the tension cut-off ``T`` on ``sigma_3 >= -T`` (Pa): the layer's
  ``tensile_strength`` where given, else the FE setting ``tension_cutoff``, else
  ``tau/lam`` (through the cone's apex; ``inf`` for Tresca, ``lam = 0``);
- ``cap``: the Tresca cap ``tau_max`` on ``|sigma_r - sigma_theta|`` (Pa); ``inf``: none;
- ``crush``, ``lock_pressure``, ``lock_strain``, ``locked_modulus``: the compaction
  hydrostat (the layer's ``crush_pressure`` and the others of
  :data:`cavex.materials.HYDROSTAT`; :func:`cavex.fem.constitutive.hydrostat`); ``crush =
  inf`` (the others ``inf``, ``inf``, ``K``): none, the linear bulk ``K``.
"""

import numpy as np

#: One element's material constants (module docstring), aligned so that numba reads a struct.
MATERIAL = np.dtype([("K", np.float64), ("G", np.float64), ("rho", np.float64),
                     ("lam", np.float64), ("tau", np.float64), ("lam_psi", np.float64),
                     ("tension", np.float64), ("cap", np.float64), ("crush", np.float64),
                     ("lock_pressure", np.float64), ("lock_strain", np.float64),
                     ("locked_modulus", np.float64)], align=True)


def _hydrostat(m):
    """``(crush, lock_pressure, lock_strain, locked_modulus)`` of layer ``m`` (no compaction:
    ``(inf, inf, inf, K)``)."""
    if getattr(m, "crush_pressure", None) is None:
        return np.inf, np.inf, np.inf, m.bulk_modulus
    return m.crush_pressure, m.lock_pressure, m.lock_strain, m.locked_modulus


def pack_layers(layers, element_layer, dilatancy_deg=0.0, tension_cutoff=None):
    """The :data:`MATERIAL` records of elements whose layer index is ``element_layer`` (an int
    array of any shape; the result has its shape).

    ``layers`` are :class:`cavex.materials.Material`. ``tension_cutoff`` is ``None`` (through
    the apex, ``tau/lam``), a number (Pa) applied to every layer, or a sequence with one value
    per layer; a layer's own ``tensile_strength`` takes its place in that layer, and its
    ``tau_max`` (None: no cap) is the Tresca cap and its compaction hydrostat (None: none)
    the volumetric law. ``dilatancy_deg`` is the dilatancy angle
    ``psi`` of every layer.
    """
    if tension_cutoff is None:
        cut = [m.tau / m.lam if m.lam > 0 else np.inf for m in layers]
    elif np.ndim(tension_cutoff) == 0:
        cut = [float(tension_cutoff)] * len(layers)
    else:
        cut = list(tension_cutoff)
    sin_psi = np.sin(np.radians(dilatancy_deg))
    lam_psi = 6.0 * sin_psi / (3.0 - sin_psi)
    records = np.empty(len(layers), dtype=MATERIAL)
    for i, m in enumerate(layers):
        records[i] = (m.bulk_modulus, m.shear_modulus, m.rho, m.lam, m.tau, lam_psi,
                      cut[i] if getattr(m, "tensile_strength", None) is None
                      else m.tensile_strength,
                      np.inf if getattr(m, "tau_max", None) is None else m.tau_max,
                      *_hydrostat(m))
    return records[np.asarray(element_layer)]
