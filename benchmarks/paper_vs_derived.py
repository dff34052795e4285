"""Print the tables of docs/paper_model.md: the paper's printed model against the derived one.

Run: ``python benchmarks/paper_vs_derived.py`` (the embedded default target, the paper's Table 1).

1. The phase depths ``L1``-``L4`` of the paper.
2. The effect of every correction (and of every kept error) on ``S`` at a representative depth
   and velocity.
3. The cavity-wall stress of the paper model against the derived model, quasi-static and dynamic,
   with the paper's nose-tip layer switch and with the derived cavity switch.
4. The paper's penetration calculation (crater Eq. 34 with Eq. 29 concrete coefficients, then
   Eq. 15 with the paper's C_A(L), C_B(L)), run by the project's integrator
   (``cavex.analytic.penetration.integrator.penetrate``), against its Table 2, for both readings
   of eps (``docs/table2.md`` runs every reading).
"""

from cavex.analytic.cavity import cavity_solution
from cavex.analytic.geometry import spherical_problem
from cavex.analytic.paper_model import (
    alpha_lambda,
    eq23,
    eq24,
    layer_epsilon,
    paper_coefficients,
    paper_phase_depths,
)
from cavex.analytic.penetration.integrator import penetrate
from cavex.analytic.penetration.resistance import ClosedFormResistance
from cavex.config import load_config
from cavex.materials import Material, Projectile, Target
from cavex.verification.studies.table2 import PAPER_TABLE2, table2_rows

DEPTHS = (0.20, 0.45, 0.60, 0.63, 0.67, 0.90, 1.07, 1.12, 1.30)
VELOCITIES = (300.0, 600.0, 1000.0)
DERIVED_VARIANTS = (("quasi-static", "nose-tip"), ("quasi-static", "cavity"),
                    ("dynamic", "nose-tip"), ("dynamic", "cavity"))
LAYER_NAMES = ("concrete", "macadam", "soil")
LABELS = {"quasi-static": "qs", "dynamic": "dyn"}


def coverage_target():
    """A runway with a thin middle layer in which every state a-h occurs (as the tests)."""
    layers = (Material(E=25e9, nu=0.3, rho=2500.0, lam=0.15, tau=25e6),
              Material(E=10e9, nu=0.3, rho=1800.0, lam=0.35, tau=20e6),
              Material(E=1e9, nu=0.3, rho=1600.0, lam=0.5, tau=5e6))
    return Target(layers, (0.5, 0.03)), Projectile(r=0.0125, l=0.03, m=0.5, V0=800.0, R=0.075)


def derived_stress(target, projectile, depth, velocity, boundary, switch):
    layers, radii = spherical_problem(target, projectile, depth, switch=switch)
    return cavity_solution(layers, radii, velocity, projectile.r, boundary=boundary).stress


def print_phase_depths(target, projectile):
    depths = paper_phase_depths(target, projectile)
    eps = [layer_epsilon(m) for m in target.layers]
    print("Phase depths (quasi-static eps^3 = 3 tau/(2E)), default target")
    print("  eps = " + ", ".join(f"{name} {e:.4f}" for name, e in zip(LAYER_NAMES, eps,
                                                                       strict=True)))
    print("  " + ", ".join(f"{k} = {v:.4f} m" for k, v in depths.items()))
    implied = projectile.r / (depths["H1"] + projectile.l - 0.40)
    print(f"  Table 2 ends phase 2 at L1 = 0.40 m, implying eps1 = {implied:.4f} "
          f"(quasi-static {eps[0]:.4f})")
    print()


def correction_effects():
    """``(equation, what, depth, V, S as implemented, S as printed)`` rows."""
    target, projectile = load_config()
    cover, cover_projectile = coverage_target()
    rows = []
    m1, m2, m3 = target.layers
    e1, e2 = layer_epsilon(m1), layer_epsilon(m2)
    p1, p2 = alpha_lambda(m1), alpha_lambda(m2)
    r, velocity = projectile.r, 600.0

    depth = 0.45  # Eq. 19: printed 3 tau/(rho E) lacks eps1^2
    c = paper_coefficients(target, projectile, depth)
    h1, h2 = (H - depth + projectile.l for H in target.interface_depths)
    inertia = 3 * m1.tau / (m1.rho * e1 ** 2 * m1.E) * (
        m1.rho + r / (e1 * h1) * (m2.rho - m1.rho) + r / (e1 * h2) * (m3.rho - m2.rho))
    printed_b = c.B + inertia * (e1 ** 2 - 1) * e1 ** -p1
    rows.append(("19", "eps1^2 missing in 3tau/(rho E)", "default", depth, c, printed_b, c.A))

    depth = 0.63  # Eq. 23: (alpha2 lam2 - 4) printed where layer 1's (alpha1 lam1 - 4) belongs
    c = paper_coefficients(target, projectile, depth)
    h1, h2 = (H - depth + projectile.l for H in target.interface_depths)
    _, implemented_b, _, _ = eq23(m1, m2, m3, e1, e2, None, r, h1, h2)
    b = r / e2
    q12 = m1.rho / m2.rho
    printed_b = implemented_b + (h1 / r) ** p1 * (b / h1) ** 4 * (-2 * q12 * e2 ** 4) * (
        1 / (p2 - 4) - 1 / (p1 - 4))
    rows.append(("23", "(a2 l2 - 4) for (a1 l1 - 4)", "default", depth, c, printed_b, c.A))

    depths = paper_phase_depths(cover, cover_projectile)
    depth = 0.5 * (depths["L3"] + depths["L4"])  # Eq. 24: missing '+' before (h1/a)^(a1 l1)
    c = paper_coefficients(cover, cover_projectile, depth)
    q1, q2, _ = cover.layers
    cp1 = alpha_lambda(q1)
    t1 = 2 * q1.rho / (q2.rho * (cp1 - 1))
    t2 = 2 * q1.rho / (q2.rho * (cp1 - 4))
    h1, h2 = (H - depth + cover_projectile.l for H in cover.interface_depths)
    _, b24, _, _ = eq24(*cover.layers, None, None, None, cover_projectile.r, h1, h2)
    printed_b = t1 + t2 * (b24 - t1 - t2)
    rows.append(("24", "'+' missing before (h1/a)^(a1 l1)", "coverage", depth, c, printed_b, c.A))
    rows.append(("24,25", "KEPT: +2rho1/(rho_n(a1 l1-1)), derivation -", "coverage", depth, c,
                 c.B - 2 * t1, c.A))

    depth = 0.5 * (depths["H1"] + depths["H2"])  # Eq. 28: 1/lam1 printed for 1/lam2
    c = paper_coefficients(cover, cover_projectile, depth)
    _, q2, q3 = cover.layers
    printed_a = c.A - (1 / q1.lam - 1 / q2.lam) * q2.tau / q3.tau
    rows.append(("28", "-(1/lam1)(tau2/tau3) for -(1/lam2)(..)", "coverage", depth, c, c.B,
                 printed_a))

    depth = 1.30  # Eq. 29: stray + eps^(-alpha lam) (kept)
    c = paper_coefficients(target, projectile, depth)
    e3, p3 = layer_epsilon(m3), alpha_lambda(m3)
    rows.append(("29", "KEPT: stray + eps3^(-a3 l3) in B", "default", depth, c, c.B - e3 ** -p3,
                 c.A))
    return rows, velocity


def print_corrections():
    rows, velocity = correction_effects()
    print(f"Effect of each fix / kept error on S (own tau), V = {velocity:.0f} m/s")
    print(f"  {'eq':6s} {'what':42s} {'target':9s} {'L (m)':>6s} {'state':>5s} "
          f"{'S paper':>9s} {'S other':>9s} {'other/paper-1':>13s}")
    for equation, what, where, depth, c, other_b, other_a in rows:
        s_paper = c.S(velocity)
        s_other = other_a + other_b * c.rho * velocity ** 2 / c.tau
        print(f"  {equation:6s} {what:42s} {where:9s} {depth:6.3f} {c.state:>5s} "
              f"{s_paper:9.2f} {s_other:9.2f} {100 * (s_other / s_paper - 1):+12.3g}%")
    print("  (rows 19, 23, 24, 28: 'other' = as printed, model uses the fix; KEPT rows: "
          "'other' = derivation, model keeps the print)")
    print()


def print_comparison(target, projectile):
    print("Cavity-wall stress: paper model vs derived model, default target")
    print("  rel = paper/derived - 1; derived (boundary, switch); S_w = sigma_r/tau of wall layer")
    header = "  ".join(f"{LABELS[b] + '/' + s:>13s}" for b, s in DERIVED_VARIANTS)
    print(f"  {'L (m)':>5s} {'wall':8s} {'eq':>3s} {'st':>6s} {'V':>5s} {'sigma (MPa)':>11s} "
          f"{'S_w':>7s}  {header}")
    for depth in DEPTHS:
        c = paper_coefficients(target, projectile, depth)
        wall = target.layer_at(depth)
        for velocity in VELOCITIES:
            stress = c.stress(velocity)
            rel = [stress / derived_stress(target, projectile, depth, velocity, b, s) - 1
                   for b, s in DERIVED_VARIANTS]
            cells = "  ".join(f"{100 * x:+12.3g}%" for x in rel)
            print(f"  {depth:5.2f} {LAYER_NAMES[wall]:8s} {c.equation:3d} {c.state:>6s} "
                  f"{velocity:5.0f} {stress / 1e6:11.1f} {stress / target.layers[wall].tau:7.2f}"
                  f"  {cells}")
    print()


def penetration_phases(target, projectile, epsilon):
    """``{"depth_m", "velocity_m_s", "time_s"}`` at the crater end, at ``L1``, at ``H1`` and
    at rest: the paper model (crater Lc = 4.5 r + l from the nose base) through the project's
    integrator."""
    resistance = ClosedFormResistance(target, projectile, "paper", epsilon=epsilon)
    return table2_rows(penetrate(target, projectile, resistance, crater="nose-base"))


def format_ends(rows):
    """``(L m, V m/s, t ms)`` of each row."""
    return "  ".join(f"({row['depth_m']:.3f}, {row['velocity_m_s']:6.1f}, "
                     f"{1e3 * row['time_s']:.2f})" for row in rows)


def print_table_2(target, projectile):
    print("Paper's penetration against its Table 2: (L m, V m/s, t ms) at phase ends")
    print("  Table 2     : " + format_ends(PAPER_TABLE2))
    for epsilon in ("quasi-static", "cylindrical"):
        print(f"  {epsilon:12s}: " + format_ends(penetration_phases(target, projectile, epsilon)))
    print("  (phase ends: crater Lc = 4.5 r + l; b reaches H1 at L1; nose at H1; rest)")
    print()


def main():
    target, projectile = load_config()
    print_phase_depths(target, projectile)
    print_corrections()
    print_comparison(target, projectile)
    print_table_2(target, projectile)


if __name__ == "__main__":
    main()
