"""The C step loop's collision policies, through the Core, each against a geometry written down.

What the loop promises (odin_step.c, Core.read_collisions):
* contact policy: a step makes contacts for the pairs that touch and at least one of which can
  move; read_collisions reports the pairs of the *last* step of the last step() call;
* contact-less policy: no contacts at all; read_collisions reports every pair that touched in
  any step since the last read, fixed (kinematic) and static objects included, each once, with
  the deepest penetration seen;
* a pair is a collision only when the collider finds a contact: overlapping bounding boxes are
  not enough;
* the solver parameter picks the solver: QuickStep's iteration count matters to QuickStep only.

Radii and speeds are chosen so that the poses at each step are exact in binary (multiples of
1/64 m and of 1/64 m per step), so a depth reads to rounding.
"""
import itertools

import numpy as np
import pytest

from virtual_world.core import (HINGE, QUICKSTEP, WORLDSTEP, Core, JointSpec, ObjectSpec,
                                WorldParameters)

H = 0.001          # s
R = 0.125          # m, sphere radius


def world(**parameters):
    return Core(WorldParameters(gravity=(0.0, 0.0, 0.0), **parameters))


def pairs(collisions):
    return {(c.first, c.second) for c in collisions}


# ------------------------------------------------------------------ contact policy


@pytest.mark.parametrize("count", [1, 10])
def test_the_contact_policy_reports_the_pairs_of_the_last_step_of_a_call(count):
    """A ball overlapping the ground by 1/64 m leaves it at 2/64 m per step: in the first step
    of a call the pair touches (the pose before the step), after it the ball is 1/64 m clear
    and stays clear. A one-step call reports the pair, with its contact point on the ground
    right below the ball's centre; a ten-step call, whose last step saw no contact, reports
    nothing, and its last step made no contact."""
    core = world()
    try:
        core.build_object(ObjectSpec("ground", [4.0, 4.0, 1.0], position=(0.0, 0.0, -0.5),
                                     geometry_only=True))
        core.build_object(ObjectSpec("ball", [R], mass=1.0, position=(0.25, -0.5, R - 1 / 64)))
        core.set_velocity("ball", linear=(0.0, 0.0, 2 / 64 / H))
        core.step(H, count)
        if count == 1:
            (c,) = core.read_collisions()
            assert (c.first, c.second) == ("ball", "ground")
            assert c.depth == pytest.approx(1 / 64, abs=1e-9)
            ((x, y, z),) = c.points
            assert (x, y) == pytest.approx((0.25, -0.5), abs=1e-12)
            assert -1 / 64 - 1e-12 <= z <= 1e-12
            assert core.last_step_contacts >= 1
        else:
            assert core.read_collisions() == []
            assert core.last_step_contacts == 0
    finally:
        core.close()


def test_a_collision_query_leaves_no_contact_behind_for_the_next_step():
    """check_collision finds two spheres made to overlap, then puts them back apart: the next
    step makes no contact from the query (in zero gravity nothing moves)."""
    core = world()
    core.build_object(ObjectSpec("a", [R], position=(0, 0, 0)))
    core.build_object(ObjectSpec("b", [R], position=(1, 0, 0)))
    found = core.check_collision([("b", (R, 0, 0), (1, 0, 0, 0))])
    assert pairs(found) == {("a", "b")}
    core.step(H, 1)
    for name in ("a", "b"):
        assert not np.any(core.body_state(name)[2]) and not np.any(core.body_state(name)[3])
    assert core.last_step_contacts == 0
    core.close()


def test_the_contact_policy_reports_the_last_call_only_even_when_nobody_read_the_one_before():
    """Two overlapping spheres are stepped, nobody reads the pair, they are moved apart and
    stepped again: the second call touched nothing, so nothing is reported."""
    core = world()
    core.build_object(ObjectSpec("a", [R], position=(0, 0, 0)))
    core.build_object(ObjectSpec("b", [R], position=(1.5 * R, 0, 0)))
    core.step(H, 1)
    assert core.last_step_contacts > 0
    core.set_poses([("b", (1, 0, 0), (1, 0, 0, 0))])
    core.step(H, 1)
    assert core.last_step_contacts == 0
    assert core.read_collisions() == []
    core.close()


def test_objects_that_cannot_move_get_no_contacts_but_contact_less_reports_them():
    """Fixed box a sunk 1/64 m into the static ground, fixed box c sunk 1/32 m into a, and a
    static wall through the ground: nothing there can move, so the contact policy makes no
    contact and reports no pair; the contact-less policy reports a's two pairs (the thesis's
    contact-less experiment moves fixed objects through others). Two static objects never
    pair: both belong to the world."""
    core = world()
    try:
        core.build_object(ObjectSpec("ground", [4.0, 4.0, 1.0], position=(0.0, 0.0, -0.5),
                                     geometry_only=True))
        core.build_object(ObjectSpec("wall", [0.5, 4.0, 1.0], position=(0.0, 0.0, -0.25),
                                     geometry_only=True))
        core.build_object(ObjectSpec("a", [0.5, 0.5, 0.5], position=(1.0, 0.0, 0.25 - 1 / 64),
                                     fixed=True))
        core.build_object(ObjectSpec("c", [0.5, 0.5, 0.5],
                                     position=(1.0, 0.0, 0.75 - 1 / 64 - 1 / 32), fixed=True))
        core.step(H, 3)
        assert core.last_step_contacts == 0
        assert core.read_collisions() == []
        core.set_world_parameters(contact_less=True)
        core.step(H)
        found = {(c.first, c.second): c.depth for c in core.read_collisions()}
        assert set(found) == {("a", "ground"), ("a", "c")}
        assert found[("a", "ground")] == pytest.approx(1 / 64, abs=1e-9)
        assert found[("a", "c")] == pytest.approx(1 / 32, abs=1e-9)
        np.testing.assert_allclose(core.body_state("a")[0], (1.0, 0.0, 0.25 - 1 / 64))
    finally:
        core.close()


# ------------------------------------------------------------------ contact-less policy


def test_contact_less_reports_a_pair_that_touched_only_inside_one_call_at_its_deepest():
    """Ball b flies through ball a at 2 R / 16 per step (the contact-less policy makes no
    contacts, so it keeps its speed): in one 48-step call it starts 3 R to the left and ends
    3 R to the right, both clear of a; in between it passes a's centre, where the penetration
    is 2 R. The read reports the pair once, at its deepest."""
    core = world(contact_less=True)
    try:
        core.build_object(ObjectSpec("a", [R], mass=1.0))
        core.build_object(ObjectSpec("b", [R], mass=1.0, position=(-3 * R, 0.0, 0.0)))
        speed = 2 * R / 16 / H
        core.set_velocity("b", linear=(speed, 0.0, 0.0))
        core.step(H, 48)
        np.testing.assert_allclose(core.body_state("b")[0], (3 * R, 0.0, 0.0), atol=1e-12)
        (c,) = core.read_collisions()
        assert (c.first, c.second) == ("a", "b")
        assert c.depth == pytest.approx(2 * R, abs=1e-9)
        assert core.read_collisions() == []
        np.testing.assert_allclose(core.body_state("a")[2], 0.0)   # no contact pushed a
    finally:
        core.close()


def test_contact_less_keeps_the_deepest_of_the_steps_since_the_last_read():
    """Poses set between one-step calls: 1/64, then 1/16, then 1/32 m of overlap; the read
    reports the pair once with 1/16 m."""
    core = world(contact_less=True)
    try:
        core.build_object(ObjectSpec("a", [R], mass=1.0, fixed=True))
        core.build_object(ObjectSpec("b", [R], mass=1.0, fixed=True))
        for overlap in (1 / 64, 1 / 16, 1 / 32):
            core.set_poses([("b", (2 * R - overlap, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))])
            core.step(H)
        (c,) = core.read_collisions()
        assert c.depth == pytest.approx(1 / 16, abs=1e-9)
    finally:
        core.close()


def test_hundreds_of_pairs_are_each_reported_once():
    """A 20 x 20 grid of spheres 0.1 m apart with radius 0.0625: each sphere overlaps its 2-4
    neighbours along x and y by 0.025 m and none along a diagonal (0.1414 m > 0.125 m), so
    2 * 20 * 19 = 760 pairs touch, more than the record buffer's first 256. Every one is
    reported once, over two steps and two reads."""
    n, spacing, radius = 20, 0.1, 0.0625
    core = world(contact_less=True)
    try:
        for i, j in itertools.product(range(n), range(n)):
            core.build_object(ObjectSpec(f"s{i:02d}{j:02d}", [radius], mass=1.0, fixed=True,
                                         position=(i * spacing, j * spacing, 0.0)))
        expected = {(f"s{i:02d}{j:02d}", f"s{i + 1:02d}{j:02d}")
                    for i, j in itertools.product(range(n - 1), range(n))}
        expected |= {(f"s{i:02d}{j:02d}", f"s{i:02d}{j + 1:02d}")
                     for i, j in itertools.product(range(n), range(n - 1))}
        assert len(expected) == 760
        for _ in range(2):
            core.step(H, 2)
            found = core.read_collisions()
            assert len(found) == 760 and pairs(found) == expected
            assert all(c.depth == pytest.approx(2 * radius - spacing, abs=1e-9) for c in found)
    finally:
        core.close()


# ------------------------------------------------------------------ both policies


@pytest.mark.parametrize("contact_less", [False, True], ids=["contacts", "contact_less"])
def test_spheres_whose_bounding_boxes_overlap_but_do_not_touch_are_no_collision(contact_less):
    """Spheres of radius 0.1 m with centres 0.15 m apart along x and along y: their bounding
    boxes ([-0.1, 0.1] and [0.05, 0.25] on both axes) overlap, the spheres do not (0.212 m
    apart > 0.2 m). Nothing is reported and no contact is made; 0.18 m apart they touch."""
    core = world(contact_less=contact_less)
    try:
        r = 0.1
        core.build_object(ObjectSpec("a", [r], mass=1.0))
        core.build_object(ObjectSpec("b", [r], mass=1.0, position=(0.15, 0.15, 0.0)))
        core.step(H, 2)
        assert core.read_collisions() == []
        assert core.last_step_contacts == 0
        core.set_poses([("b", (0.15, 0.1, 0.0), (1.0, 0.0, 0.0, 0.0))])   # 0.180 m: touching
        core.step(H)
        assert pairs(core.read_collisions()) == {("a", "b")}
    finally:
        core.close()


# ------------------------------------------------------------------ solver


def _swing(solver, iterations):
    """A two-link hinge chain falling from horizontal for 0.2 s; the lower link's pose."""
    core = Core(WorldParameters(gravity=(0.0, 0.0, -9.81), solver=solver,
                                quickstep_iterations=iterations))
    try:
        core.build_object(ObjectSpec("l1", [0.5, 0.05, 0.05], mass=1.0, position=(0.25, 0, 0)))
        core.build_object(ObjectSpec("l2", [0.5, 0.05, 0.05], mass=5.0, position=(0.75, 0, 0)))
        core.add_joint(JointSpec(HINGE, "", "l1", anchor=(0.0, 0.0, 0.0), axis1=(0.0, 1.0, 0.0)))
        core.add_joint(JointSpec(HINGE, "l1", "l2", anchor=(0.5, 0.0, 0.0), axis1=(0.0, 1.0, 0.0)))
        core.step(H, 200)
        position, orientation, _, _ = core.body_state("l2")
        return np.concatenate([position, orientation])
    finally:
        core.close()


def test_quickstep_iterations_change_quickstep_only():
    """dWorldStep solves the constraints exactly and ignores quickstep_iterations; QuickStep
    iterates, and with 1 iteration instead of 20 it ends elsewhere (by 0.2 mm here). So the
    solver parameter really picks the solver."""
    np.testing.assert_array_equal(_swing(WORLDSTEP, 1), _swing(WORLDSTEP, 20))
    assert np.max(np.abs(_swing(QUICKSTEP, 1) - _swing(QUICKSTEP, 20))) > 1e-5
