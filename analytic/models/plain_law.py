"""The plain law ``sigma_n = A + B V_n^2`` (the global ``--law-A``/``--law-B``) or each
layer's own ``tau_k A_k + B_k rho_k V_n^2`` (its ``law_A``, ``law_B`` keys; docs/analytic.md
"Plain law"): flown by ``penetrate`` and ``trajectory`` only; no boundary convention."""

from cavex.analytic.models.registry import Model, register


def law_echo(target, law_A, law_B):
    """The plain law as the JSON settings of ``penetrate`` and ``trajectory`` give it: the
    global ``{"A_Pa", "B_kg_m3"}``, or each layer's ``{"layer", "law_A", "law_B"}``."""
    if law_A is not None:
        return {"A_Pa": law_A, "B_kg_m3": law_B}
    return [{"layer": name, "law_A": A, "law_B": B}
            for name, (A, B) in zip(target.layer_names(), target.plain_laws, strict=True)]


def law_text(law):
    """The plain law (:func:`law_echo`) in words: ``sigma_n = A + B V_n^2, A 2e+08 Pa, B 2500
    kg/m^3`` (global) or ``sigma_n = tau_k A_k + B_k rho_k V_n^2; concrete A 20, B 1; ...``
    (each layer's keys, by the layer's name)."""
    if isinstance(law, dict):
        return f"sigma_n = A + B V_n^2, A {law['A_Pa']:g} Pa, B {law['B_kg_m3']:g} kg/m^3"
    return "sigma_n = tau_k A_k + B_k rho_k V_n^2; " + "; ".join(
        f"{k['layer']} A {k['law_A']:g}, B {k['law_B']:g}" for k in law)


class PlainLaw(Model):
    name = "law"
    help = "sigma_n = A + B V_n^2 (--law-A, --law-B)"
    flies = flies_3d = True
    takes_law = True

    def describe(self, boundary=None, epsilon=None, table=None, law=None):
        return "plain law " + law_text(law)

    def settings_text(self, summary):
        return f" ({law_text(summary['law'])})" if "law" in summary else ""

    def resistance(self, target, projectile, *, law_A=None, law_B=None, **options):
        from cavex.analytic.penetration.plain_law import PlainLawResistance

        return PlainLawResistance(target, projectile, law_A, law_B)

    def stress_law(self, target, projectile, *, law_A=None, law_B=None, **options):
        from cavex.analytic.penetration.stress_laws import plain_law

        return plain_law(target, law_A, law_B)


register(PlainLaw())
