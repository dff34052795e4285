"""The FE-tabulated resistance (``cavex table``; docs/fem.md): the FE's wall stress
``sigma_r(V, L)`` of the target, interpolated (:mod:`cavex.analytic.penetration.tabulated`);
compressible and at finite strain, which no closed form is. Beside a layered run the first
layer alone flies the derived closed form (``--boundary`` is its convention)."""

from pathlib import Path

from cavex.analytic.models.registry import Model, get, register
from cavex.errors import require


class Table(Model):
    name = "table"
    report_words = ("the FE-tabulated resistance, compressible (nu = {nu:g}) and "
                    "finite-strain, one FE table per distinct target")
    help = "an FE table (--table)"
    flies = flies_3d = predicts_shots = fits_mapping = True
    erodes = True
    takes_table = True
    first_layer = "derived"
    # its 3-D law is the FE's sigma_r at L = z + l - r, with no free-surface reduction
    # (docs/oblique.md): --no-free-surface would change nothing
    free_surface_option = False
    prediction_seconds = 3e-2  # a prediction with an FE table (docs/validation.md)
    compared_with_fe = True  # the reference the closed forms are flown against
    line_styles, line_width = (("k", "-"),), 2.2
    # the FE with the derived-dynamic closed form's calibrated mapping: what compressibility
    # and finite strain change, same material (validate's compressibility column)
    compressible_partner = "derived-dynamic"

    def check(self, boundary=None):
        get(self.first_layer).check(boundary)  # the first layer's convention

    def boundary(self, boundary=None):
        return get(self.first_layer).boundary(boundary)

    def describe(self, boundary=None, epsilon=None, table=None, law=None):
        closed = get(self.first_layer).describe(boundary, epsilon)
        return f"FE table {Path(str(table)).name} (first layer alone: {closed})"

    def settings_text(self, summary):
        return f" ({summary['table']}; first layer alone: {summary['first_layer_model']})"

    def resistance(self, target, projectile, *, table=None, **options):
        from cavex.analytic.penetration.tabulated import TabulatedResistance, read_table

        require(table is not None, "table", "given with resistance 'table'", table)
        data = table if hasattr(table, "attrs") else read_table(table)
        return TabulatedResistance(data, target, projectile)

    def stress_law(self, target, projectile, *, table=None, **options):
        from cavex.analytic.penetration.stress_laws import TableLaw
        from cavex.analytic.penetration.tabulated import TabulatedResistance

        require(table is not None, "table", "given for --resistance table", None)
        return TableLaw(TabulatedResistance(table, target, projectile))

    def shot_depth(self, shot, *, mapping=None, tables=None, erosion=None, **options):
        from cavex.analytic.models.shots import flown_depth

        require(tables is not None, "tables", "an FE-table source for the table model", None)
        return flown_depth(self, shot, mapping, erosion, table=tables.table(shot, mapping))


register(Table())
