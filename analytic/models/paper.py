"""The paper's printed model (She 2020, as printed; docs/paper_model.md): its own quasi-static
boundary and a reading of epsilon (``--epsilon``); bonded interfaces only."""

from cavex.analytic.models.registry import Model, register


class Paper(Model):
    name = "paper"
    report_words = ("cavex's incompressible closed forms with the penetration integrator "
                    "(crater 4.5 r from the nose base)")
    help = "the paper's printed model"
    flies = flies_3d = closed_form = predicts_shots = fits_mapping = True
    erodes = True
    default_boundary = "quasi-static"  # its own, and no other
    takes_epsilon = True
    compared_with_fe = True
    line_styles = (("C2", ":"),)

    def describe(self, boundary=None, epsilon=None, table=None, law=None):
        return f"paper model (She 2020), epsilon: {epsilon}"

    def settings_text(self, summary):
        return f", epsilon {summary['epsilon']}"

    def wall_stress(self, target, projectile, depth, velocity, *, epsilon="quasi-static",
                    **options):
        """The printed coefficients at nose depth ``depth``: the wall stress at ``velocity``,
        ``A``, ``B``, the equation and its state (``cavex stress``; JSON-able)."""
        from cavex.analytic.paper_model import paper_coefficients
        from cavex.analytic.states import state_meaning

        c = paper_coefficients(target, projectile, depth, epsilon=epsilon)
        return {"model": self.name, "resistance": self.name, "epsilon": epsilon,
                "depth_m": depth, "velocity_m_s": velocity,
                "sigma_r_Pa": c.stress(velocity), "S": c.S(velocity),
                "S_normalised_by": f"tau as the paper's Eq. {c.equation}", "tau_Pa": c.tau,
                "A": c.A, "B": c.B, "equation": c.equation, "response_state": c.state,
                "response_state_meaning": state_meaning(c.state, target.layer_names())}

    def resistance(self, target, projectile, *, boundary=None, epsilon="quasi-static",
                   **options):
        from cavex.analytic.penetration.resistance import ClosedFormResistance

        return ClosedFormResistance(target, projectile, "paper", boundary, epsilon=epsilon)

    def stress_law(self, target, projectile, *, epsilon="quasi-static", **options):
        from cavex.analytic.penetration.stress_laws import PaperLaw

        return PaperLaw(target, projectile, epsilon)

    def shot_depth(self, shot, *, mapping=None, erosion=None, **options):
        from cavex.analytic.models.shots import flown_depth

        return flown_depth(self, shot, mapping, erosion)


register(Paper())
