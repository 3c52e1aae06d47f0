"""The contact model through the Core: Coulomb friction, restitution and contacts per pair,
each compared with the figure mechanics gives.

ODE's contacts here (odin_step.c) are dContactApprox1: each of the two friction directions is
bounded by mu times that contact's normal force, so a box sliding along one of them (x: ODE's
friction directions for a z normal are x and y) feels mu m g in total and decelerates at mu g
exactly; a slide along a diagonal would feel up to sqrt(2) mu m g (the friction pyramid).
Restitution (dContactBounce) asks the contact for an outgoing normal speed e times the incoming
one when that exceeds bounce_velocity.
"""
import math

import numpy as np
import pytest

from virtual_world.core import Core, FORCE, ObjectSpec, WorldParameters

G = 9.81
# Coulomb's law within 0.2 %: the default auto solver takes a box on the ground (contacts
# only) to QuickStep, whose friction at mu = 1 reads within 0.1 % of mu m g (dWorldStep's,
# which the auto solver took before issue 28, 0.12 % weaker)
FRICTION_REL = 2e-3


def world(**parameters):
    """A Core with a 20 m x 20 m static ground whose top face is z = 0."""
    core = Core(WorldParameters(gravity=(0.0, 0.0, -G), **parameters))
    core.build_object(ObjectSpec("ground", [20.0, 20.0, 1.0], position=(0.0, 0.0, -0.5),
                                 geometry_only=True))
    return core


def quaternion_matrix(q):
    """Rotation matrix of a unit quaternion (w, x, y, z), written out here."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


# ------------------------------------------------------------------ friction

SLAB = [0.4, 0.4, 0.1]   # low and wide: friction at its base cannot tip it
SLAB_MASS = 2.0
H = 0.001


def settled_slab(core):
    core.build_object(ObjectSpec("slab", SLAB, mass=SLAB_MASS, position=(0.0, 0.0, 0.05)))
    core.step(H, 200)
    return core.body_state("slab")[0]


def slide(core, v0, max_steps, stopped_below=0.0):
    """Launches the settled slab along +x at v0; steps until its speed is below stopped_below
    (or max_steps). Returns the times (s) and x velocities of each step and the distance."""
    start = settled_slab(core)
    core.set_velocity("slab", linear=(v0, 0.0, 0.0))
    times, speeds = [], []
    for i in range(1, max_steps + 1):
        core.step(H)
        speeds.append(core.body_state("slab")[2][0])
        times.append(i * H)
        if speeds[-1] < stopped_below:
            break
    distance = core.body_state("slab")[0] - start
    return np.array(times), np.array(speeds), distance


@pytest.mark.parametrize("max_contacts", [3, 4])   # 3 or 4 corners: the total is mu m g
@pytest.mark.parametrize("mu", [0.2, 0.5, 1.0])
def test_a_sliding_box_decelerates_at_mu_g_and_stops_at_v0_squared_over_2_mu_g(mu, max_contacts):
    v0 = 2.0
    core = world(friction=mu, max_contacts=max_contacts)
    try:
        # each step takes mu g h off the speed: below a tenth of that, it has stopped (the
        # soft contact leaves a creep of about 1e-5 m/s)
        times, speeds, distance = slide(core, v0, 3000, stopped_below=0.1 * mu * G * H)
        # while it slides, v(t) = v0 - mu g t: a straight line of slope -mu g
        sliding = speeds > 0.1 * v0
        slope, intercept = np.polyfit(times[sliding], speeds[sliding], 1)
        assert slope == pytest.approx(-mu * G, rel=FRICTION_REL)
        assert intercept == pytest.approx(v0, rel=1e-3)
        # it stops after v0 / (mu g), at v0^2 / (2 mu g). Semi-implicit Euler moves with the
        # velocity at the end of each step, so it covers v0 h / 2 less than the integral:
        # the tolerance is one step's travel, v0 h (2 mm), twice that shortfall.
        assert speeds[-1] < 0.1 * mu * G * H
        assert times[-1] == pytest.approx(v0 / (mu * G), abs=2 * H)
        assert distance[0] == pytest.approx(v0 ** 2 / (2 * mu * G), abs=v0 * H)
        assert abs(distance[1]) < 1e-4   # straight on
        # and then it stays: static friction holds it
        core.step(H, 200)
        assert np.linalg.norm(core.body_state("slab")[2]) < 1e-3
    finally:
        core.close()


def test_without_friction_a_box_slides_on_at_its_speed():
    core = world(friction=0.0)
    try:
        times, speeds, distance = slide(core, 2.0, 1000)
        np.testing.assert_allclose(speeds, 2.0, rtol=1e-9)
        assert distance[0] == pytest.approx(2.0 * times[-1], rel=1e-9)
    finally:
        core.close()


@pytest.mark.parametrize("friction,slides", [(1.0, True), (-1.0, False)], ids=["mu1", "infinite"])
def test_infinite_friction_holds_a_box_a_push_of_2_m_g_would_slide(friction, slides):
    """F = 2 m g at the centre of mass: at mu = 1 the box slides at (F - mu m g) / m = g; with
    infinite friction (world friction < 0) it stays. F h_centre = 2 m g 0.05 < m g 0.2 (half
    the width): it does not tip."""
    core = world(friction=friction)
    try:
        start = settled_slab(core)
        core.add_body_force("slab", FORCE, (2.0 * SLAB_MASS * G, 0.0, 0.0))
        t = 0.5
        core.step(H, round(t / H))
        position, _, velocity, spin = core.body_state("slab")
        if slides:
            assert velocity[0] == pytest.approx(G * t, rel=FRICTION_REL)
            assert position[0] - start[0] == pytest.approx(G * t * t / 2, rel=1e-2)
        else:
            assert np.linalg.norm(position - start) < 1e-3
            assert np.linalg.norm(velocity) < 1e-3 and np.linalg.norm(spin) < 1e-2
    finally:
        core.close()


def test_with_infinite_friction_a_launched_box_stops_sliding_at_once():
    """The base cannot slip: in the first step the contact points stop, and what is left of
    the launch is the box tripping over its front edge (the base's centre moves only with the
    turn, a few mm), where at mu = 1 it would slide 0.2 m."""
    core = world(friction=-1.0)
    try:
        start = settled_slab(core)
        core.set_velocity("slab", linear=(2.0, 0.0, 0.0))
        core.step(H)
        _, q, velocity, spin = core.body_state("slab")
        # the base's corners (slab frame, from the centre of mass) no longer slip: their
        # horizontal speed is a small fraction of the 2 m/s launch (at mu = 1: 1.99 m/s)
        R = quaternion_matrix(q)
        corners = [R @ (sx * SLAB[0] / 2, sy * SLAB[1] / 2, -SLAB[2] / 2)
                   for sx in (-1, 1) for sy in (-1, 1)]
        slip = max(np.linalg.norm((velocity + np.cross(spin, r))[:2]) for r in corners)
        assert slip < 0.05, slip
        core.step(H, 20)
        position = core.body_state("slab")[0]
        assert position[0] - start[0] < 0.01
    finally:
        core.close()


# ------------------------------------------------------------------ restitution

R_BALL = 0.05


def drop(h, **parameters):
    """Drops a 1 kg ball of radius R_BALL with its bottom h above the ground. Returns the
    speed just before the first contact, the vertical velocity after the step that made it,
    and the highest the ball's bottom rose after it (m above the ground)."""
    core = world(**parameters)
    try:
        core.build_object(ObjectSpec("ball", [R_BALL], mass=1.0, position=(0.0, 0.0, h + R_BALL)))
        fall = math.sqrt(2 * h / G)
        total = round((3 * fall + 0.05) / H)
        before, after, peak = None, None, -math.inf
        previous = 0.0
        for _ in range(total):
            core.step(H)
            _, _, v, _ = core.body_state("ball")
            if after is None and core.last_step_contacts:
                before, after = -previous, v[2]
            previous = v[2]
            if after is not None:
                peak = max(peak, core.body_state("ball")[0][2] - R_BALL)
        assert after is not None, "the ball never touched the ground"
        return before, after, peak
    finally:
        core.close()


# The contact's penetration recovery (erp depth / h: up to 0.7 m/s after a 4 mm penetration)
# would lift even a ball that does not bounce; it is capped here so that what rises is
# restitution alone (ODE does not cap bounce by it: contact.cpp). cfm is made tiny so the
# contact is hard: ODE's soft contact gives back (e - k) / (1 + k), k = cfm m / h (see below).
HARD = dict(contact_max_correcting_velocity=0.01, cfm=1e-10, bounce_velocity=0.1)


@pytest.mark.parametrize("e", [0.3, 0.5, 0.8, 1.0])
def test_a_ball_dropped_from_h_rebounds_to_e_squared_h(e):
    h = 1.0
    before, after, peak = drop(h, bounce=e, **HARD)
    assert before == pytest.approx(math.sqrt(2 * G * h), abs=G * H)
    assert after == pytest.approx(e * before, rel=1e-5)   # k = cfm m / h = 1e-7
    # the contact is found up to one step's fall (before h) into the ground, and the peak
    # lies between steps (within after h): the rebound is e^2 h within (before + after) h
    assert peak == pytest.approx(e * e * h, abs=(before + after) * H)


def test_restitution_under_the_default_soft_contact_follows_odes_constraint_mixing():
    """With cfm > 0 the contact yields: the solver's v_out = e v_in - (cfm / h) lambda with the
    impulse lambda h = m (v_out + v_in) gives v_out / v_in = (e - k) / (1 + k), k = cfm m / h."""
    e, cfm = 0.5, WorldParameters().cfm
    before, after, _ = drop(1.0, bounce=e, contact_max_correcting_velocity=0.01)
    k = cfm * 1.0 / H
    assert after / before == pytest.approx((e - k) / (1 + k), rel=1e-4)


def test_a_ball_without_bounce_does_not_rebound():
    before, after, peak = drop(1.0, bounce=0.0, **HARD)
    assert before > 4.0
    assert abs(after) < 0.05   # the capped penetration recovery at most
    assert peak < 1e-4


def test_an_impact_slower_than_bounce_velocity_does_not_bounce():
    h = 0.05   # impact at sqrt(2 g h) = 0.99 m/s
    slow = dict(HARD, bounce_velocity=1.5)
    before, after, peak = drop(h, bounce=0.5, **slow)
    assert before < 1.5
    assert abs(after) < 0.05 and peak < 1e-4
    fast = dict(HARD, bounce_velocity=0.5)   # the same drop, above the threshold, bounces
    before, after, peak = drop(h, bounce=0.5, **fast)
    assert before > 0.5
    assert after == pytest.approx(0.5 * before, rel=1e-5)
    assert peak == pytest.approx(0.25 * h, abs=(before + after) * H)


# ------------------------------------------------------------------ contacts per pair


def test_the_default_is_three_contacts_per_pair():
    assert WorldParameters().max_contacts == 3
    core = world()
    try:
        core.build_object(ObjectSpec("box", [0.4, 0.3, 0.2], mass=3.0, position=(0, 0, 0.1)))
        core.step(H, 100)
        assert core.last_step_contacts == 3
    finally:
        core.close()


def box_resting(max_contacts):
    """(contacts of the last step, points the collision record holds) for a box at rest flat
    on the ground after 0.3 s, with max_contacts per pair."""
    core = world(max_contacts=max_contacts)
    try:
        core.build_object(ObjectSpec("box", [0.4, 0.3, 0.2], mass=3.0, position=(0, 0, 0.1)))
        counts = []
        for _ in range(300):
            core.step(H)
            counts.append(core.last_step_contacts)
        (collision,) = core.read_collisions()
        assert (collision.first, collision.second) == ("box", "ground")
        assert len(set(counts[10:])) == 1, f"contacts changed while resting: {set(counts)}"
        return counts[-1], len(collision.points)
    finally:
        core.close()


def test_the_box_box_collider_gives_four_contacts_for_a_box_flat_on_a_face():
    """ODE clips the box's bottom face against the ground's top: its 4 corners."""
    assert box_resting(64) == (4, 4)


@pytest.mark.parametrize("max_contacts", [1, 3, 4, 8])
def test_a_resting_box_gets_min_of_max_contacts_and_what_the_collider_gives(max_contacts):
    expected = min(max_contacts, 4)
    assert box_resting(max_contacts) == (expected, expected)
