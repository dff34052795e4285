"""The held contact (``contact_hold``, ``cavex trajectory --contact-hold``): each element's
load is regularised in its push into the wall, not in its normal velocity, so a held couple
carries its load without creeping (issue 20 item 4; docs/oblique.md "Held contact"). Its
mirror and work balances are in tests/test_contact_hold_balances.py."""

import numpy as np
import pytest

from cavex.analytic.models import fly, make_law
from cavex.analytic.penetration.oblique import ObliqueModel, Strike
from cavex.analytic.penetration.surface_force import surface_loads
from cavex.config import load_config


@pytest.fixture(scope="module")
def default():
    return load_config()


def _turn_after(result, interface=1):
    k = next(i for i, p in enumerate(result.phases)
             if p["end_reason"].startswith(f"nose tip crossed interface {interface}"))
    return result.phases[k + 1]["end_pitch_deg"] - result.phases[k]["end_pitch_deg"]


def _added(default, **options):
    """The added turn after the first debonded interface (600 m/s, 20 deg; debonded minus
    bonded, pitch at the stop minus at the crossing), as tests/test_tunnel_wall.py."""
    target, projectile = default
    strike = Strike(600.0, 20.0)
    return (_turn_after(fly(target.with_interfaces("debonded"), projectile, strike, **options))
            - _turn_after(fly(target, projectile, strike, **options)))


def test_added_turn_converges_under_the_held_contact(default):
    """Issue 20 item 4's 3 %, with every step of the force law integrated over the element
    (issue 30): under the held contact (rtol 1e-4, where the integrator's own spread is below
    the gaps) the added turn is 0.0970, 0.0992 deg at 1e-6, 3e-7 m (measured): the gap 2.3 %,
    within the 3 % asked (bound: 3 %). The velocity ramp at 0.001 m/s (same rtol) gives 0.0689
    deg: the two contact models converge to turns 0.03 deg apart, more than the issue's 0.01
    deg, so the contact model is an uncertainty of the added turn (docs/oblique.md "Held
    contact"); with the former centroid rule they had agreed within 0.01 deg. Not asserted:
    it is a difference between two models, not a discretisation error."""
    options = {"rtol": 1e-4, "atol": 1e-7}
    added = {hold: _added(default, contact_hold=hold, **options) for hold in (1e-6, 3e-7)}
    print("added turn (deg) by hold depth:", added)
    assert abs(added[3e-7] / added[1e-6] - 1.0) < 0.03


def test_held_contact_carries_its_load_at_rest(default):
    """What the ramp cannot do: an element pushed into its wall keeps its load when it stops
    (``V_n = 0``), and sheds it when it leaves. A state of the paper's shot mid-run with the
    body's velocities set to zero: the ramp's loads vanish, the held contact's are the
    fractions times the static capacities, element by element (linear in the fractions:
    bound 1e-12 of the total)."""
    target, projectile = default
    law = make_law(target, projectile)
    model = ObliqueModel(target, projectile, law, contact_hold=1e-6)
    result = model.run(Strike(600.0, 20.0))
    y = result.solutions[-1].y[:, result.solutions[-1].t.size // 2].copy()
    y[7:13] = 0.0
    ramp = ObliqueModel(target, projectile, law)
    assert np.all(surface_loads(y[:14], *ramp._surface)[0] == 0.0)
    held = surface_loads(y, *model._surface)
    assert np.abs(held[0]).max() > 1e3  # N: the body is held
    # each element alone at its fraction against each element alone at full fraction
    areas = model.body.areas
    full = y.copy()
    full[14:] = 1.0
    total = np.zeros(3)
    for k in np.flatnonzero(y[14:] > 0.0):
        one = list(model._surface)
        one[2] = np.where(np.arange(areas.size) == k, areas, 0.0)
        at_one = surface_loads(full, *one)[0]
        total += y[14 + k] * at_one
    assert np.allclose(held[0], total, rtol=0, atol=1e-12 * np.abs(held[0]).max())
    assert np.all(held[6][:, 0] == 0.0)  # at rest the fractions do not move


def test_held_normal_incidence_one_layer_is_the_1d_tunnel(default):
    """tests/test_oblique.py's comparison with the 1-D tunnel phase (one layer, no free
    surface, the nose started embedded), with the held contact: the nose elements move
    along their normals from the start, so their fractions are 1 and stay there (the rate
    is clipped), the shank's are 0 (its normal velocity is round-off, inside the guard): the
    same loads as the ramp-free model. Compiled ROS2 at rtol 1e-6, the bound of the ramp-free
    test (1e-6; measured: printed)."""
    from cavex.analytic.penetration.body import build_body
    from cavex.analytic.penetration.integrator import penetrate
    from cavex.analytic.penetration.resistance import ClosedFormResistance

    target, projectile = default
    single = target.single(0)
    body = build_body(projectile, shank_rings=8)
    start = body.nose_length + body.axial_half_extent + 1e-4
    law = make_law(single, projectile, "derived", boundary="dynamic", free_surface=False)
    model = ObliqueModel(single, projectile, law, body=body, rtol=1e-6, atol=1e-9,
                         contact_hold=1e-6)
    result = model.run(Strike(projectile.V0, tip_depth=start))
    one_d = penetrate(single, projectile, ClosedFormResistance(single, projectile, "derived",
                                                                "dynamic"), crater=None)
    fractions = np.concatenate([s.y[14:] for s in result.solutions], axis=1)
    assert np.all(fractions[body.nose] == 1.0) and np.all(fractions[~body.nose] == 0.0)
    keep = one_d.velocity > 1e-3 * projectile.V0
    depth_error = velocity_error = 0.0
    for t, L, V in zip(one_d.t[keep], one_d.depth[keep], one_d.velocity[keep], strict=True):
        y = result.state(t)
        depth_error = max(depth_error, abs(model.tip(y)[2] - start - L) / one_d.depth[-1])
        velocity_error = max(velocity_error, abs(np.linalg.norm(y[7:10]) - V) / projectile.V0)
    print("depth error", depth_error, "velocity error", velocity_error)
    assert depth_error < 1e-6 and velocity_error < 1e-6
