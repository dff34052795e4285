"""The 3-D oblique-penetration model (cavex.analytic.penetration.oblique): reductions to the 1-D
model,
symmetry, energy, discretisation convergence (docs/oblique.md)."""


import numpy as np
import pytest

from cavex.analytic.cavity import cavity_stress
from cavex.analytic.models import fly, make_law
from cavex.analytic.penetration.body import build_body
from cavex.analytic.penetration.integrator import penetrate
from cavex.analytic.penetration.nose import QUADRATURE_POINTS, ogive_coefficients
from cavex.analytic.penetration.oblique import ObliqueModel, Strike
from cavex.analytic.penetration.resistance import ClosedFormResistance
from cavex.analytic.penetration.stress_laws import DerivedLaw
from cavex.analytic.penetration.surface_force import rotation_matrix
from cavex.config import load_config


@pytest.fixture(scope="module")
def runway():
    return load_config()


def test_surface_quadrature_reproduces_eqs_12_14(runway):
    target, projectile = runway
    body = build_body(projectile)
    A, B, tau, rho, V = 7.3, 1.4, 25e6, 2500.0, 800.0
    nose = body.nose
    vn = V * body.normals[nose, 0]  # axial motion: V_n = V cos(phi)
    sigma = tau * A + B * rho * vn ** 2
    force = -(sigma * body.areas[nose])[:, None] * body.normals[nose]
    c_a, c_b = ogive_coefficients(projectile, A, B, tau, rho)
    exact = c_a + c_b * V ** 2
    # measured 2.7e-16 relative; lateral components 1e-17 of the axial
    assert abs(-force[:, 0].sum() / exact - 1.0) < 1e-10
    assert np.abs(force[:, 1:].sum(axis=0)).max() < 1e-12 * exact


def test_mass_properties_of_a_cylinder_limit(runway):
    """Uniform solid: cg and inertia against the closed forms of a cylinder plus ogive."""
    _, projectile = runway
    body = build_body(projectile)
    # the steel default length, and a centre of mass behind the nose's centroid
    assert body.length == pytest.approx(0.149836, abs=1e-6)
    assert body.nose_length < body.cg < body.length
    # transverse inertia between that of the shank cylinder alone and of a rod of the length
    m, L, r = projectile.m, body.length, projectile.r
    assert m * (3 * r * r + (L - body.nose_length) ** 2) / 12 < body.inertia_transverse
    assert body.inertia_transverse < m * L ** 2 / 3


def _ray_problem(target, radius, z, nz, free_surface=True):
    """The spherical problem whose wall is an element at depth ``z`` with normal ``n_z``,
    derived here independently of the compiled law: the layers met along the normal (own
    layer first), each interface plane at ``radius +`` its distance along the normal, the
    free surface (upward normals) as the traction-free sphere."""
    layers, depths = target.layers, target.interface_depths
    own = target.layer_at(z)
    if nz > 1e-12:
        sequence = layers[own:]
        distances = [(H - z) / nz for H in depths[own:]]
        free = None
    elif nz < -1e-12:
        sequence = layers[own::-1]
        distances = [(z - H) / -nz for H in reversed(depths[:own])]
        free = radius + z / -nz if free_surface else None
    else:
        sequence, distances, free = (layers[own],), [], None
    return tuple(sequence), [radius + min(d, 1e6) for d in distances], free


@pytest.mark.parametrize("boundary", ["dynamic", "quasi-static"])
def test_derived_law_is_cavity_stress_element_by_element(runway, boundary):
    target, projectile = runway
    law = DerivedLaw(target, projectile.r, boundary, free_surface=True)
    rng = np.random.default_rng(3)
    n = 400
    z = rng.uniform(0.001, 1.6, n)
    normals = rng.normal(size=(n, 3))
    normals[:20, 2] = 0.0  # horizontal normals: own layer alone
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    vn = rng.uniform(0.0, 900.0, n)
    sigma = law.stress(z, normals, vn)
    for i in range(n):
        layers, radii, free = _ray_problem(target, projectile.r, z[i], normals[i, 2])
        ref = cavity_stress(layers, radii, vn[i], projectile.r, boundary=boundary,
                            free_radius=free)
        assert sigma[i] == pytest.approx(ref, rel=1e-14)  # measured: equal


def _one_layer_normal(runway, boundary, method="DOP853", rtol=1e-10):
    target, projectile = runway
    single = target.single(0)
    # 8 shank rings: the shank carries no load here; with the default 16 the round-off lateral
    # velocity near the end (omega ~2e-8 rad/s) crosses the 1e-9 round-off guard of V_n and,
    # without a contact ramp (which this comparison needs), shank elements switch on and off:
    # the same answer (final depth equal to 3e-14) but 6 132 DOP853 steps (23 s) instead of 30
    # (56 053 and 525 with omega's former absolute tolerance, atol rad/s). The 1-D
    # nose force's 8-point rule (the 3-D default is 16 since issue 30): the two models' nose
    # forces then agree to round-off, and this comparison is of the integrators
    body = build_body(projectile, QUADRATURE_POINTS, shank_rings=8)
    start = body.nose_length + body.axial_half_extent + 1e-4  # nose fully embedded
    law = make_law(single, projectile, "derived", boundary=boundary, free_surface=False)
    model = ObliqueModel(single, projectile, law, body=body, rtol=rtol, atol=1e-3 * rtol,
                         method=method, contact_ramp=0.0)
    result = model.run(Strike(projectile.V0, tip_depth=start))
    one_d = penetrate(single, projectile, ClosedFormResistance(single, projectile, "derived",
                                                                boundary), crater=None)
    return start, result, one_d


@pytest.mark.parametrize("boundary, method, rtol", [("dynamic", "DOP853", 1e-10),
                                                     ("quasi-static", "DOP853", 1e-10),
                                                     ("dynamic", "ROS2", 1e-6)])
def test_normal_incidence_one_layer_is_the_1d_tunnel(runway, boundary, method, rtol):
    """The 1-D tunnel phase, with the reference DOP853 and with the compiled default ROS2 (a
    smooth problem here: its global error falls as rtol, measured depth error 3.3e-7, 3.3e-8,
    3.3e-9 at rtol 1e-6, 1e-7, 1e-8 with 1626, 5121, 16174 steps: second order)."""
    start, result, one_d = _one_layer_normal(runway, boundary, method, rtol)
    _, projectile = runway
    h = result.history
    # no lateral motion or rotation (round-off of sums of ~10^5 N); measured <= 1e-8 rad/s
    # and the lateral displacement printed below
    print(boundary, "lateral", np.abs(h["cg_x_m"]).max(), np.abs(h["cg_y_m"]).max(),
          "omega", max(np.abs(h[f"omega_{c}_rad_s"]).max() for c in "xyz"),
          "pitch", np.abs(h["pitch_deg"]).max())
    assert np.abs(h["cg_x_m"]).max() < 1e-10 and np.abs(h["cg_y_m"]).max() < 1e-10
    for c in "xyz":
        assert np.abs(h[f"omega_{c}_rad_s"]).max() < 1e-7
    assert np.abs(h["pitch_deg"]).max() < 1e-7
    keep = one_d.velocity > 1e-3 * projectile.V0
    depth_error = velocity_error = 0.0
    for t, L, V in zip(one_d.t[keep], one_d.depth[keep], one_d.velocity[keep], strict=True):
        y = result.state(t)
        tip = result.model.tip(y)[2] - start
        depth_error = max(depth_error, abs(tip - L) / one_d.depth[-1])
        velocity_error = max(velocity_error, abs(np.linalg.norm(y[7:10]) - V) / projectile.V0)
    print(boundary, "depth error", depth_error, "velocity error", velocity_error)
    # measured: see the printed errors (docs/oblique.md); both integrators at rtol 1e-9/1e-10
    assert depth_error < 1e-6 and velocity_error < 1e-6
    final = result.model.tip(result.solutions[-1].y[:, -1])[2] - start
    # the 3-D run stops at 1e-6 of its kinetic energy (1 m/s): the remaining travel at the
    # static resistance C_A is ~2e-6 relative (measured 2.3e-6)
    assert final == pytest.approx(one_d.depth[-1], rel=5e-6)


STRIKE = Strike(600.0, obliquity=20.0, attack=2.0)


def test_plane_symmetric_shot_stays_in_its_plane_and_mirrors(runway):
    target, projectile = runway
    a = fly(target, projectile, STRIKE, "law", law_A=2e8, law_B=2500.0,
            contact_ramp=1.0)
    b = fly(target, projectile, Strike(600.0, obliquity=-20.0, attack=2.0), "law", law_A=2e8,
            law_B=2500.0, contact_ramp=1.0)
    h = a.history
    # out-of-plane (round-off): measured y 0 m, omega_x, omega_z 2.5e-8 rad/s
    assert np.abs(h["cg_y_m"]).max() < 1e-12 and np.abs(h["tip_y_m"]).max() < 1e-12
    assert np.abs(h["omega_x_rad_s"]).max() < 1e-6 and np.abs(h["omega_z_rad_s"]).max() < 1e-6
    assert np.abs(h["yaw_deg"]).max() < 1e-8
    assert abs(h["pitch_deg"][-1] - h["pitch_deg"][0]) > 1.0  # it does turn
    # mirror: the same code on mirrored data (the element pairs theta, -theta are summed
    # first; docs/oblique.md) gives the mirrored trajectory to the last bit
    ha, hb = a.history, b.history
    assert np.array_equal(ha["t_s"], hb["t_s"])
    for key in ha:
        # vectors: x flips; pseudovectors (omega, moment): y and z flip
        flip = key.startswith(("cg_x", "tip_x", "v_x", "pitch", "force_x", "omega_y",
                               "omega_z", "moment_y", "moment_z"))
        assert np.array_equal(hb[key], -ha[key] if flip else ha[key]), key
    assert b.end["nose_tip_m"] == [-a.end["nose_tip_m"][0], *a.end["nose_tip_m"][1:]]


def test_mirror_shot_with_spin_and_attack_plane_is_exact(runway):
    """Out of plane and spinning: the mirror shot (obliquity -> -obliquity, spin -> -spin)
    is the mirror image of the shot to the last bit, state by state at every step."""
    target, projectile = runway
    options = {"law_A": 2e8, "law_B": 2500.0, "contact_ramp": 1.0}
    a = fly(target, projectile, Strike(650.0, obliquity=35.0, attack=4.0, attack_plane=60.0,
                                     spin=300.0), "law", **options)
    b = fly(target, projectile, Strike(650.0, obliquity=-35.0, attack=4.0, attack_plane=60.0,
                                     spin=-300.0), "law", **options)
    from cavex.analytic.penetration.surface_force import mirror_state
    ya = np.concatenate([s.y for s in a.solutions], axis=1)
    yb = np.concatenate([s.y for s in b.solutions], axis=1)
    assert ya.shape == yb.shape
    assert np.abs(ya[1]).max() > 1e-3  # genuinely out of plane
    for k in range(ya.shape[1]):
        assert np.array_equal(mirror_state(ya[:, k]), yb[:, k])


def test_work_of_surface_forces_is_the_kinetic_energy_lost(runway):
    from dataclasses import replace
    target, projectile = runway
    projectile = replace(projectile, mu=0.1)
    strike = Strike(700.0, obliquity=30.0, attack=3.0, attack_plane=40.0, spin=500.0)
    # the reference integrator (the compiled default's energy balance: the next test)
    result = fly(target.single(0), projectile, strike, "law", law_A=2e8, law_B=2500.0,
                 contact_ramp=1.0, method="RK45", rtol=1e-6, atol=1e-9)
    # measured 3.6e-10 relative (RK45, rtol 1e-6: the work is integrated with the state)
    assert abs(_work_mismatch(result)) < 1e-6
    assert abs(result.history["yaw_deg"]).max() > 0.1  # a genuinely 3-D shot


def _work_mismatch(result):
    """Work of the surface forces over the kinetic energy lost, minus 1."""
    y0, y1 = result.solutions[0].y[:, 0], result.solutions[-1].y[:, -1]
    return -y1[13] / (result.model.energy(y0) - result.model.energy(y1)) - 1.0


def test_compiled_integrator_energy_balance_converges(runway):
    """The default ROS2 integrator on the same 3-D shot with friction, spin and the default
    contact ramp: the work-energy mismatch is its global error, and it falls with the
    tolerance. Measured with omega's absolute tolerance of ``omega_tolerance``: 3.67e-5,
    8.89e-6, 2.11e-6, 4.96e-7, 1.45e-7 at rtol 1e-3, 3e-4, 1e-4, 3e-5, 1e-5 (fitted order 1.20
    on 1e-3, 1e-4, 1e-5), the same digits under the CPU emulation of results/regenerate.sh.
    With the former ``atol`` rad/s it did not fall smoothly (6.5e-4, 8.9e-4, 5.6e-5 at 1e-3,
    1e-4, 1e-5: the step error of omega's chatter), and the test then bounded 2e-3 and 5e-4
    only. Bounds: 3 times the measured at each tolerance, and the order above 1."""
    from dataclasses import replace
    target, projectile = runway
    projectile = replace(projectile, mu=0.1)
    strike = Strike(700.0, obliquity=30.0, attack=3.0, attack_plane=40.0, spin=500.0)
    tolerances = np.array([1e-3, 1e-4, 1e-5])
    mismatch = np.array([abs(_work_mismatch(fly(target.single(0), projectile, strike, "law",
                                                 law_A=2e8, law_B=2500.0, rtol=r,
                                                 atol=1e-3 * r)))
                         for r in tolerances])
    print("work-energy mismatch at rtol 1e-3, 1e-4, 1e-5:", mismatch)
    assert np.all(mismatch < 3.0 * np.array([3.67e-5, 2.11e-6, 1.45e-7]))
    assert np.polyfit(np.log(tolerances), np.log(mismatch), 1)[0] > 1.0


def test_compiled_integrator_agrees_with_the_reference(runway):
    """The default ROS2 against ``solve_ivp``'s RK45 at rtol 1e-6 (the reference, converged to
    2e-5 in the final depth: docs/oblique.md) on an oblique shot into concrete alone, plain
    law, contact ramp 0.1 m/s (at smaller ramps RK45 needs 1/ramp more steps). Measured:
    depth -7.7e-5 relative and pitch -0.0041 deg against RK45 at rtol 1e-6 and at 1e-7 alike
    (448 and 1 054 steps against 329)."""
    target, projectile = runway
    strike = Strike(600.0, obliquity=20.0)
    law = {"law_A": 2e8, "law_B": 2500.0, "contact_ramp": 0.1}
    compiled = fly(target.single(0), projectile, strike, "law", **law)
    reference = fly(target.single(0), projectile, strike, "law", method="RK45", rtol=1e-6,
                    atol=1e-9, **law)
    depth = compiled.end["nose_tip_m"][2] / reference.end["nose_tip_m"][2] - 1.0
    pitch = compiled.end["pitch_deg"] - reference.end["pitch_deg"]
    print("compiled - reference: depth", depth, "pitch", pitch)
    assert abs(depth) < 1e-3 and abs(pitch) < 0.02
    assert compiled.end["state"] == reference.end["state"] == "stopped"


@pytest.mark.parametrize("contact_ramp", [0.1, 0.01])
def test_surface_discretisation_converges(runway, contact_ramp):
    """Force and moment of the surface on a body crossing the free surface (oblique, yawed,
    rotating), for refinements of all three element counts by 2: errors against a 4x finer
    level (262 144 elements). Every step of the force law (the free surface, the line where
    the contact opens) is integrated over the element (surface_force "Fractions"), so the
    moment converges at second order: measured p = 2.11 at both ramps (errors 9.9e-3, 2.1e-3,
    5.4e-4, 1.2e-4 of |M| at 256 to 65 536 elements); the force's errors are smaller than the
    former centroid rule's at every level (2.7e-3, 4.0e-4, 2.8e-4, 1.4e-4 of |F|, against
    5.8e-3, 1.1e-3, 3.2e-4 at 4 096 to 65 536 elements) but fall irregularly past 1 024
    elements (fitted p = 1.34 over the four levels), so the force is bounded, the moment's
    order asserted."""
    target, projectile = runway
    law = make_law(target, projectile, "derived")
    strike = Strike(800.0, obliquity=30.0, attack=3.0, attack_plane=30.0)
    levels = (4, 8, 16, 32, 128)
    loads = []
    for f in levels:
        body = build_body(projectile, nose_points=2 * f, azimuths=4 * f, shank_rings=2 * f)
        model = ObliqueModel(target, projectile, law, body=body, contact_ramp=contact_ramp)
        y = model.initial_state(strike)
        y[2] += 0.07  # nose tip 7 cm deep: the body crosses the free surface
        y[10:13] = [50.0, 200.0, -100.0]
        force, moment = model.loads(y)[:2]
        loads.append(np.concatenate([force, moment]))
    loads = np.array(loads)
    force, moment = (np.linalg.norm(loads[:-1, part] - loads[-1, part], axis=1)
                     / np.linalg.norm(loads[-1, part]) for part in (slice(0, 3), slice(3, 6)))
    rate = np.polyfit(np.log(1.0 / np.array(levels[:-1])), np.log(moment), 1)[0]
    print("force errors", force, "moment errors", moment, "moment's fitted order", rate)
    assert rate > 1.9
    assert moment[-1] < 2e-4 and force[-1] < 2e-4  # measured 1.2e-4, 1.4e-4
    assert np.all(force[1:] < np.array([1.1e-3, 3.2e-4, 3.2e-4]))  # the centroid rule's


def test_default_runway_at_normal_incidence_against_the_1d_integrator(runway):
    """The difference docs/oblique.md reports and explains, at 400 m/s (the shot stops in
    concrete, so the layering plays no part): the 3-D nose enters element by element, so it
    ends deeper than the 1-D tunnel phase (which loads the whole nose from a tip depth of 0) by
    less than one nose length (measured 0.0157 m); the 1-D default, with the paper's crater
    stage (reduced resistance), ends deeper than both (measured 0.463 against 0.418 m). No
    element of a nose at normal incidence faces up: the free surface changes nothing."""
    from dataclasses import replace

    target, projectile = runway
    projectile = replace(projectile, V0=400.0)
    three_d = fly(target, projectile, Strike(400.0)).end["nose_tip_m"][2]
    without = fly(target, projectile, Strike(400.0), free_surface=False).end["nose_tip_m"][2]
    resistance = ClosedFormResistance(target, projectile, "derived", "dynamic")
    crater = penetrate(target, projectile, resistance).depth[-1]
    tunnel = penetrate(target, projectile, resistance, crater=None).depth[-1]
    body = build_body(projectile)
    print("3-D", three_d, "no free surface", without, "1-D crater", crater, "tunnel", tunnel)
    assert three_d == without
    assert 0.0 < three_d - tunnel < body.nose_length
    assert crater > three_d


def test_events_end_each_phase_where_they_say(runway):
    """Interface crossings, axis parallel to the surface, ricochet and perforation stop the
    integration exactly on their event surfaces (to the root finder's tolerance)."""
    target, projectile = runway
    law = {"law_A": 2e8, "law_B": 2500.0, "contact_ramp": 1.0}
    deep = fly(target, projectile, Strike(900.0, obliquity=10.0), "law", **law)
    crossings = [ph for ph in deep.phases if ph["end_reason"].startswith("nose tip crossed")]
    assert len(crossings) == 2
    for phase, H in zip(crossings, target.interface_depths, strict=True):
        assert phase["end_nose_tip_m"][2] == pytest.approx(H, abs=1e-9)
    assert [ph["label"] for ph in deep.phases] == ["concrete", "macadam", "soil"]
    assert deep.end["state"] == "stopped"

    grazing = fly(target.single(0), projectile, Strike(300.0, obliquity=75.0), "law", **law)
    reasons = [ph["end_reason"] for ph in grazing.phases]
    assert reasons == ["axis parallel to the surface",
                       "ricochet: left the target through the entry face"]
    assert grazing.phases[0]["end_pitch_deg"] == pytest.approx(90.0, abs=1e-6)
    end = grazing.solutions[-1].y[:, -1]
    assert grazing.end["state"] == "ricochet"
    assert _extreme_depths(grazing.model, end)[0] == pytest.approx(0.0, abs=1e-9)

    through = fly(target.single(0), projectile, Strike(600.0, obliquity=20.0), "law",
                  bottom=0.3, **law)
    end = through.solutions[-1].y[:, -1]
    assert through.end["state"] == "perforation"
    assert _extreme_depths(through.model, end)[1] == pytest.approx(0.3, abs=1e-9)


def _extreme_depths(model, y):
    """Deepest and shallowest depth of the body's surface points and tip (numpy)."""
    rot = rotation_matrix(y[3:7])
    z = y[2] + (np.vstack([model.body.points, model.body.tip]) @ rot.T)[:, 2]
    return z.max(), z.min()


def test_paper_law_is_the_printed_model_at_the_mapped_depth(runway):
    """At its grid nodes the paper law is the paper's printed sigma_r at the 1-D nose depth
    L = z + l - r (exactly: the same coefficients), between them linear."""
    from cavex.analytic.paper_model import paper_stress
    from cavex.analytic.penetration.stress_laws import PaperLaw

    target, projectile = runway
    law = PaperLaw(target, projectile)
    offset = projectile.l - projectile.r
    nodes = np.array([0.1, 0.3, 0.6502, 0.9, 1.2])  # on the 0.2 mm grid
    vn = np.array([0.0, 150.0, 400.0, 650.0, 900.0])
    z = nodes - offset
    sigma = law.stress(z, np.tile([0.0, 0.0, 1.0], (z.size, 1)), vn)
    printed = np.array([paper_stress(target, projectile, L, v) for L, v in zip(nodes, vn,
                                                                             strict=True)])
    np.testing.assert_allclose(sigma, printed, rtol=1e-12)  # measured: equal to round-off


def test_table_law_survives_integrator_stages_beyond_the_table(runway):
    """The stiff contact makes some rejected RK stages try wild states (here |omega| ~ 2e4
    rad/s, V_n ~ 1500 m/s against a table to 1200 m/s). Such a stage gets the table's largest
    velocity; only accepted states are checked against the table. (It aborted a valid 600 m/s
    shot with "the table must reach 1522.83 m/s".)"""
    from pathlib import Path

    from cavex.analytic.penetration.tabulated import load_table

    target, projectile = runway
    grid = Path(__file__).resolve().parents[1] / "results" / "verification" / "grid.nc"
    result = fly(target, projectile, Strike(600.0, obliquity=20.0), "table",
                 table=load_table(grid), contact_ramp=1.0)
    assert result.end["state"] == "stopped"
    # the accepted states: every surface element's normal velocity within the table (the
    # history sampling raises otherwise); and the shot ends in macadam like the closed form
    assert 0.65 < result.end["nose_tip_m"][2] < 0.85


def test_a_model_run_twice_gives_the_same_bits(runway):
    """The compiled integrator keeps its step across phases, not across runs."""
    target, projectile = runway
    model = ObliqueModel(target, projectile, make_law(target, projectile, "law", law_A=2e8,
                                                      law_B=2500.0))
    first = model.run(Strike(600.0, obliquity=20.0))
    model.run(Strike(900.0, obliquity=40.0))
    again = model.run(Strike(600.0, obliquity=20.0))
    assert np.array_equal(first.history["t_s"], again.history["t_s"])
    assert first.end == again.end
