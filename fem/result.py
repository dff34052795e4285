"""What a cavity-expansion run returns."""

from dataclasses import dataclass, field

import numpy as np


@dataclass
class ExpansionResult:
    """Outcome of :func:`cavex.fem.expand_cavity`.

    Attributes
    ----------
    cavity_stress : float
        ``sigma_r`` at the cavity wall at the final radius (Pa, compression positive), from the
        consistent nodal reaction divided by the current wall area ``4 pi a^2``.
    history : dict of ndarray
        ``time`` (s), ``radius`` (m), ``wall_stress`` (Pa), ``plastic_radius`` (m) per step
        (the initial state first).
    fields : dict of ndarray
        Final state: ``r`` (current radius of each quadrature point, m), ``sigma_r``,
        ``sigma_theta`` (Pa, compression positive), ``plastic_strain`` (accumulated equivalent
        plastic log strain), ``layer``; and ``r_nodes``, ``R_nodes`` (current/reference nodal
        radii, cavity outwards), ``u``.
    error_estimate : float or None
        Relative discretisation error of ``cavity_stress`` (Richardson, from a run at half the
        space and time resolution); None if not requested.
    plastic_radius : float
        Current radius of the outermost yielded material at the end (m).
    interfaces_final : tuple of float
        Where the mesh vertices placed on the requested interfaces actually ended (m).
    settings : dict
        Everything that reproduces the run: layers, interfaces, velocity, radius, numerics.
    energy : dict
        ``work`` at the wall, ``kinetic``, ``stored`` (elastic), ``dissipated`` (J).
    stats : dict
        ``elements``, ``dofs``, ``steps``, ``newton_iterations``, ``cutbacks``, ``seconds``,
        and with an error estimate ``error_companion`` (``"coarse"``, or ``"finer"`` where the
        coarse run failed) with that run's ``coarse_cavity_stress`` or ``finer_cavity_stress``.
    """

    cavity_stress: float
    history: dict
    fields: dict
    error_estimate: float | None
    plastic_radius: float
    interfaces_final: tuple
    settings: dict
    energy: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)

    @property
    def S(self):
        """``cavity_stress / tau`` of the layer at the wall."""
        return self.cavity_stress / self.settings["layers"][0]["tau"]

    def summary(self):
        """Plain JSON-able digest (scalars only)."""
        return {"cavity_stress": float(self.cavity_stress),
                "error_estimate": None if self.error_estimate is None
                else float(self.error_estimate),
                "plastic_radius": float(self.plastic_radius),
                "interfaces_final": [float(h) for h in self.interfaces_final],
                "final_time": float(np.asarray(self.history["time"])[-1]),
                **{k: float(v) for k, v in self.energy.items()},
                **{k: v for k, v in self.stats.items()}}
