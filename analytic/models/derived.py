"""The derived layered closed form (docs/analytic.md): incompressible Mohr-Coulomb layers, the
cavity's wall stress by either yield-at-boundary convention (``--boundary``, default dynamic:
the closed form closest to the FE in every layer of the default target,
results/verification/report.md). The one model that flies debonded interfaces (their
traction-free sphere)."""

from cavex.analytic.models.registry import Model, register


class Derived(Model):
    name = "derived"
    report_words = ("cavex's incompressible closed forms with the penetration integrator "
                    "(crater 4.5 r from the nose base)")
    help = "the derived closed form (--boundary)"
    flies = flies_3d = closed_form = predicts_shots = fits_mapping = True
    erodes = True
    boundaries = ("quasi-static", "dynamic")  # the order of its labels
    default_boundary = "dynamic"
    debonded = True
    free_surface_option = True
    compared_with_fe = True
    line_styles = (("C0", "--"), ("C1", "-"))  # quasi-static, dynamic

    def describe(self, boundary=None, epsilon=None, table=None, law=None):
        return f"derived model, {self.boundary(boundary)} boundary"

    def wall_stress(self, target, projectile, depth, velocity, *, boundary="dynamic",
                    **options):
        """The cavity wall's stress at nose depth ``depth`` and velocity ``velocity``, its
        response state and plastic zones (``cavex stress``; JSON-able)."""
        # loaded once the input is checked: bad input answers before numba loads
        from cavex.analytic.cavity import cavity_solution
        from cavex.analytic.geometry import spherical_problem, wall_layer
        from cavex.analytic.states import state_meaning

        layers, interfaces = spherical_problem(target, projectile, depth)
        state = cavity_solution(layers, interfaces, velocity, projectile.r, boundary=boundary)
        index = wall_layer(target, projectile, depth)
        return {"model": self.label(boundary), "resistance": self.name,
                "boundary": boundary, "depth_m": depth,
                "velocity_m_s": velocity, "sigma_r_Pa": state.stress, "S": state.S,
                "S_normalised_by": f"tau of {target.layer_name(index)}",
                "tau_Pa": layers[0].tau, "response_state": state.state,
                "response_state_meaning": state_meaning(state.state, target.layer_names()),
                "plastic_radius_m": state.plastic_radius,
                "wall_layer": target.layer_name(index), "interface_radii_m": list(interfaces),
                "plastic_zones": [{"layer": target.layer_name(index + i), "r_inner_m": r0,
                                   "r_outer_m": r1} for i, r0, r1 in state.plastic_zones]}

    def resistance(self, target, projectile, *, boundary=None, **options):
        from cavex.analytic.penetration.resistance import ClosedFormResistance

        return ClosedFormResistance(target, projectile, "derived", boundary)

    def stress_law(self, target, projectile, *, boundary="dynamic", free_surface=True,
                   bottom=None, **options):
        from cavex.analytic.penetration.stress_laws import DerivedLaw

        return DerivedLaw(target, projectile.r, boundary, free_surface, bottom)

    def shot_depth(self, shot, *, boundary=None, mapping=None, erosion=None, **options):
        from cavex.analytic.models.shots import flown_depth

        return flown_depth(self, shot, mapping, erosion, boundary=boundary)


register(Derived())
