"""What a cavity-expansion run returns."""

from dataclasses import dataclass, field


@dataclass
class ExpansionResult:
    """Outcome of one problem of :func:`cavex.fem.expand_cavities` (or
    :func:`cavex.fem.expand_cavity`).

    Attributes
    ----------
    cavity_stress : float
        ``sigma_r`` at the cavity wall at the final radius (Pa, compression positive), from the
        consistent nodal reaction divided by the current wall area ``4 pi a^2``; NaN when the
        run failed.
    error_estimate : float or None
        Relative discretisation error of ``cavity_stress`` (Richardson, from the companion run,
        see ``stats``); None if not requested or the run failed.
    plastic_radius : float
        Current radius of the outermost yielded material at the end (m).
    interfaces_final : tuple of float
        Where the mesh vertices placed on the requested interfaces actually ended (m).
    settings : dict
        Everything that reproduces the run: ``layers``, ``interfaces``, ``velocity``,
        ``radius``, ``numerics`` (the settings of this run: those given, or refined ones).
    fields : dict of ndarray
        Final nodal ``u``, ``r_nodes``, ``R_nodes`` (current/reference radii, cavity outwards);
        with ``record=True`` also, per quadrature point, ``r``, ``sigma_r``, ``sigma_theta``
        (Pa, compression positive), ``plastic_strain``, ``layer``, and ``snapshots``.
    history : dict of ndarray or None
        With ``record=True``: ``time`` (s), ``radius`` (m), ``wall_stress`` (Pa),
        ``plastic_radius`` (m) per step, the initial state first.
    energy : dict
        ``work`` at the wall, ``kinetic``, ``stored`` (elastic), ``dissipated`` (J).
    stats : dict
        ``elements``, ``dofs``, ``steps``, ``newton_iterations``, ``cutbacks``,
        ``line_search_steps``, ``residual_evaluations`` (kernel passes of plain Newton, failed
        attempts included: the run's work), ``seconds`` (of the stack the run was part of,
        shared),
        ``refinements``, and with an error estimate ``error_companion`` (``"coarse"``, or
        ``"finer"`` where the coarse run failed) with that run's ``coarse_cavity_stress`` or
        ``finer_cavity_stress``.
    error : CavexNumericalError or None
        Why the run failed (it names V, the step's cavity radius and the wall radius).
    """

    cavity_stress: float
    error_estimate: float | None
    plastic_radius: float
    interfaces_final: tuple
    settings: dict
    fields: dict = field(default_factory=dict)
    history: dict | None = None
    energy: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)
    error: Exception | None = None

    @property
    def ok(self):
        return self.error is None

    @property
    def velocity(self):
        return self.settings["velocity"]

    @property
    def radius(self):
        return self.settings["radius"]

    @property
    def numerics(self):
        return self.settings["numerics"]

    @property
    def u(self):
        return self.fields.get("u")

    @property
    def S(self):
        """``cavity_stress / tau`` of the layer at the wall."""
        return self.cavity_stress / self.settings["layers"][0]["tau"]
