"""Removing forces, joints, motors and objects through the Core: what goes with what, what is
reported, and that what was removed stops acting (a body then keeps its velocity: Newton's
first law), while what was kept goes on acting."""
import numpy as np
import pytest

from virtual_world.core import FORCE, HINGE, Core, JointSpec, MotorSpec, ObjectSpec, WorldParameters

H = 0.001
N = 100


def test_a_removed_joint_torque_stops_and_the_joint_keeps_its_rate(core):
    """A 1 N m hinge torque on a box with I_zz = 2 kg m^2 turns it at 0.5 rad/s^2: 0.05 rad/s
    after 0.1 s; removed, the rate stays 0.05 rad/s."""
    core.build_object(ObjectSpec("wheel", [1.0, 1.0, 1.0], mass=12.0))   # I = 12 * 2 / 12
    joint = core.add_joint(JointSpec(HINGE, "", "wheel", axis1=(0.0, 0.0, 1.0)))
    torque = core.add_joint_force(joint, [1.0])
    core.step(H, N)
    assert core.joint_states()[0].rates[0] == pytest.approx(0.05, rel=1e-9)
    core.remove_joint_force(torque)
    assert core.joint_force_ids() == []
    core.step(H, N)
    assert core.joint_states()[0].rates[0] == pytest.approx(0.05, rel=1e-9)


def test_removing_an_object_removes_its_forces_and_the_others_go_on(core):
    """Two 2 kg balls pushed by 1 N each; the first is removed with its force (reported), the
    second keeps accelerating at 0.5 m/s^2."""
    core.build_object(ObjectSpec("a", [0.1], mass=2.0))
    core.build_object(ObjectSpec("b", [0.1], mass=2.0, position=(5.0, 0.0, 0.0)))
    fa = core.add_body_force("a", FORCE, (1.0, 0.0, 0.0))
    fb = core.add_body_force("b", FORCE, (0.0, 1.0, 0.0))
    core.step(H, N)
    removed = core.remove_object("a")
    assert removed.forces == (fa,) and removed.geometries == ("a",)
    assert core.body_force_ids() == [fb]
    core.step(H, N)
    np.testing.assert_allclose(core.body_state("b")[2], (0.0, 0.5 * 2 * N * H, 0.0), rtol=1e-9)


def test_a_removed_joint_is_forgotten_by_its_bodies_and_takes_its_motors(core):
    """Removing a joint removes its motor (reported) and frees both bodies: removing them later
    reports no joint, no motor; removing a motor first leaves nothing for its joint to take."""
    for name, x in (("a", 0.0), ("b", 1.0), ("c", 2.0)):
        core.build_object(ObjectSpec(name, [0.1], mass=1.0, position=(x, 0.0, 0.0)))
    ab = core.add_joint(JointSpec(HINGE, "a", "b", anchor=(0.5, 0.0, 0.0), axis1=(0.0, 0.0, 1.0)))
    bc = core.add_joint(JointSpec(HINGE, "b", "c", anchor=(1.5, 0.0, 0.0), axis1=(0.0, 0.0, 1.0)))
    m_ab = core.add_motor(MotorSpec(joint=ab))
    m_bc = core.add_motor(MotorSpec(joint=bc))
    removed = core.remove_joint(ab)
    assert removed.joints == (ab,) and removed.motors == (m_ab,)
    assert core.motor_ids() == [m_bc] and core.joint_ids() == [bc]
    assert core.remove_object("a") == type(removed)(geometries=("a",))
    core.remove_motor(m_bc)
    removed = core.remove_object("c")
    assert removed.joints == (bc,) and removed.motors == () and removed.geometries == ("c",)
    assert core.joint_ids() == [] and core.motor_ids() == []
    removed = core.remove_object("b")
    assert removed.joints == () and removed.motors == ()
    core.step(H, 10)


def test_a_removal_between_contact_less_reads_keeps_each_pairs_deepest_and_drops_its_own():
    """Contact-less: a and b overlap by 1/16 m, then c is removed, then a and b overlap by
    only 1/64 m: the read reports a-b at 1/16 m, the deepest since the last read. Removing a
    (the first name of its pairs) drops every pair that names it."""
    core = Core(WorldParameters(gravity=(0.0, 0.0, 0.0), contact_less=True))
    try:
        r = 0.125
        for name, x in (("a", 0.0), ("b", 2 * r - 1 / 16), ("c", -2 * r + 1 / 32)):
            core.build_object(ObjectSpec(name, [r], mass=1.0, position=(x, 0.0, 0.0),
                                         fixed=True))
        core.step(H)
        core.remove_object("c")
        core.set_poses([("b", (2 * r - 1 / 64, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))])
        core.step(H)
        (ab,) = core.read_collisions()
        assert (ab.first, ab.second) == ("a", "b")
        assert ab.depth == pytest.approx(1 / 16, abs=1e-9)
        core.step(H)
        core.remove_object("a")
        assert core.read_collisions() == []
    finally:
        core.close()


def test_removing_an_object_reports_every_joint_motor_and_force_that_went_with_it(core):
    """The middle ball of three has two joints, a motor of its own to the first ball and a
    force: all four go with it, and the outer balls, now free, keep their velocities."""
    for name, x in (("a", 0.0), ("b", 1.0), ("c", 2.0)):
        core.build_object(ObjectSpec(name, [0.1], mass=1.0, position=(x, 0.0, 0.0)))
    ab = core.add_joint(JointSpec(HINGE, "a", "b", anchor=(0.5, 0.0, 0.0), axis1=(0.0, 0.0, 1.0)))
    bc = core.add_joint(JointSpec(HINGE, "b", "c", anchor=(1.5, 0.0, 0.0), axis1=(0.0, 0.0, 1.0)))
    motor = core.add_motor(MotorSpec(id="spin", body1="b", body2="a", axes=[1.0, 0.0, 0.0]))
    force = core.add_body_force("b", FORCE, (0.0, 1.0, 0.0))
    removed = core.remove_object("b")
    assert set(removed.joints) == {ab, bc} and removed.motors == (motor,)
    assert removed.forces == (force,) and removed.geometries == ("b",)
    assert core.joint_ids() == [] and core.motor_ids() == [] and core.body_force_ids() == []
    core.set_velocity("a", linear=(0.0, 1.0, 0.0))
    core.step(H, N)
    np.testing.assert_allclose(core.body_state("a")[2], (0.0, 1.0, 0.0))


def test_an_entity_lists_its_living_members_and_goes_with_the_last(core):
    from virtual_world.core import EntitySpec
    core.build_entity(EntitySpec("robot", [ObjectSpec("l1", [0.1]),
                                           ObjectSpec("l2", [0.1], position=(1.0, 0.0, 0.0))]))
    core.build_entity(EntitySpec("", [ObjectSpec("x", [0.1], position=(3.0, 0.0, 0.0))]))
    assert core.entities() == {"robot": ["l1", "l2"], "entity1": ["x"]}
    core.remove_object("l1")
    assert core.entities() == {"robot": ["l2"], "entity1": ["x"]}
    core.remove_object("l2")
    assert core.entities() == {"entity1": ["x"]}
    assert core.build_entity(EntitySpec("", [ObjectSpec("y", [0.1])])).name == "entity2"
