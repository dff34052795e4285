"""The Python API in one script: closed form, FE, penetration and an oblique shot, default runway.

Run it as ``python examples/api_example.py``; ``tests/test_examples.py`` runs it and checks its
numbers. SI units (Pa, m, s, kg), compression positive.
"""

from cavex import load_config
from cavex.analytic import (
    Strike,
    cavity_stress,
    fly,
    make_resistance,
    penetrate,
    spherical_problem,
)
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

    # 4. The rigid projectile through the runway with the derived dynamic resistance (model
    #    "derived-dynamic"; resistance="paper" is the paper's printed model, resistance="table"
    #    with table=PATH an FE table from `cavex table`)
    trajectory = penetrate(target, projectile, make_resistance(
        target, projectile, resistance="derived", boundary="dynamic"))

    print(f"wall stress at L = {depth} m, V = {velocity} m/s:")
    print(f"  closed form, dynamic      {dynamic / 1e6:9.2f} MPa")
    print(f"  closed form, quasi-static {quasi_static / 1e6:9.2f} MPa")
    print(f"  FE                        {fe.cavity_stress / 1e6:9.2f} MPa "
          f"(estimated error {fe.error_estimate:.2%})")
    print(f"projectile stops at {trajectory.depth[-1]:.3f} m after "
          f"{trajectory.t[-1] * 1e3:.2f} ms")

    # 5. An oblique shot in 3-D (docs/oblique.md): 600 m/s at 20 deg, derived dynamic law
    #    along each surface element's normal, the default contact regularisation and
    #    integrator (about 0.2 s once the kernels are compiled)
    shot = fly(target, projectile, Strike(600.0, obliquity=20.0))
    x, _, z = shot.end["nose_tip_m"]
    print(f"oblique shot: {shot.end['state']} with the nose tip at x = {x:.3f} m, "
          f"z = {z:.3f} m, pitch {shot.end['pitch_deg']:.2f} deg "
          f"({len(shot.phases)} phases: {', '.join(p['label'] for p in shot.phases)})")
    return {"dynamic": dynamic, "quasi_static": quasi_static, "fe": fe.cavity_stress,
            "fe_error_estimate": fe.error_estimate, "final_depth": float(trajectory.depth[-1]),
            "oblique": shot.end}


if __name__ == "__main__":
    main()
