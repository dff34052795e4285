"""The Python API in one script: closed form, FE and penetration for the default runway.

Run it as ``python examples/api_example.py``; ``tests/test_examples.py`` runs it and checks its
numbers. SI units (Pa, m, s, kg), compression positive.
"""

from cavex import load_config
from cavex.analytic import ClosedFormResistance, cavity_stress, penetrate, spherical_problem
from cavex.fem import expand_cavity


def main():
    target, projectile = load_config()  # the paper's Table 1 (core/data/runway.toml)

    # 1. The spherical problem of the nose at depth L: layers around the cavity, interface radii
    depth, velocity = 0.5, 500.0
    layers, interfaces = spherical_problem(target, projectile, depth)

    # 2. The layered closed form, both yield-at-boundary conventions
    dynamic = cavity_stress(layers, interfaces, velocity, projectile.r, boundary="dynamic")
    quasi_static = cavity_stress(layers, interfaces, velocity, projectile.r,
                                 boundary="quasi-static")

    # 3. The FE solution of the same problem (compressible, finite strain), with its estimate
    fe = expand_cavity(layers, interfaces, velocity, projectile.r)

    # 4. The rigid projectile through the runway with the derived dynamic resistance
    trajectory = penetrate(target, projectile,
                           ClosedFormResistance(target, projectile, boundary="dynamic"))

    print(f"wall stress at L = {depth} m, V = {velocity} m/s:")
    print(f"  closed form, dynamic      {dynamic / 1e6:9.2f} MPa")
    print(f"  closed form, quasi-static {quasi_static / 1e6:9.2f} MPa")
    print(f"  FE                        {fe.cavity_stress / 1e6:9.2f} MPa "
          f"(estimated error {fe.error_estimate:.2%})")
    print(f"projectile stops at {trajectory.depth[-1]:.3f} m after "
          f"{trajectory.t[-1] * 1e3:.2f} ms")
    return {"dynamic": dynamic, "quasi_static": quasi_static, "fe": fe.cavity_stress,
            "fe_error_estimate": fe.error_estimate, "final_depth": float(trajectory.depth[-1])}


if __name__ == "__main__":
    main()
