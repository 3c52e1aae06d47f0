"""The kinematic drive (core.kinematic, Set Servo ``drive``): a joint's link follows its motor's
commanded speed exactly, whatever it meets, pushes what is in its way, and goes back to a
motor-driven link on request. Checked against closed forms: a joint's value after n steps is
n h times its speed; the link's pose is the start pose turned about the joint's axis through
its anchor by that value."""
import math

import numpy as np
import pytest

from odin_common.defaults import SERVO_GAIN, SERVO_MAX_SPEED
from odin_common.interface import MotorKind, ServoDrive
from odin_common.rotations import quaternion_to_matrix
from virtual_world.core import (HINGE, SLIDER, UNIVERSAL, Core, JointSpec, MotorSpec, ObjectSpec,
                                WorldParameters)
from virtual_world.errors import InvalidArgument, Unsupported, UnknownName

H = 0.001
GRAVITY = (0.0, 0.0, -9.81)


def two_link_arm(max_force=0.5):
    """Two 0.5 m rods in a row along x: "upper" on a hinge about y at the origin to the world,
    "fore" on a hinge about z at x = 0.5 m to "upper"; motors too weak (``max_force`` N m) to
    hold them up against gravity."""
    core = Core(WorldParameters(gravity=GRAVITY, solver=1))
    core.build_object(ObjectSpec("upper", [0.5, 0.05, 0.05], mass=1.0, position=(0.25, 0, 0)))
    core.build_object(ObjectSpec("fore", [0.5, 0.05, 0.05], mass=1.0, position=(0.75, 0, 0)))
    shoulder = core.add_joint(JointSpec(HINGE, "upper", "", anchor=(0, 0, 0), axis1=(0, 1, 0)))
    elbow = core.add_joint(JointSpec(HINGE, "upper", "fore", anchor=(0.5, 0, 0), axis1=(0, 0, 1)))
    motors = [core.add_motor(MotorSpec(joint=j, max_forces=[max_force])) for j in (shoulder, elbow)]
    return core, (shoulder, elbow), motors


def values(core, joints):
    states = {s.id: s for s in core.joint_states()}
    return [states[j].positions[0] for j in joints]


def turned(axis, angle):
    """The rotation matrix of ``angle`` rad about the unit ``axis``."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def test_the_links_follow_the_commanded_speeds_exactly_against_gravity():
    core, joints, motors = two_link_arm()
    core.set_drive(motors, ServoDrive.KINEMATIC)
    core.set_velocity(motors=[motors[0], motors[1]], velocities=[0.5, -1.0])
    core.step(H, 1000)
    assert values(core, joints) == pytest.approx([0.5, -1.0], abs=1e-12)
    # the upper rod turned 0.5 rad about +y at the origin: its centre from (0.25, 0, 0)
    upper_R = turned((0, 1, 0), 0.5)
    position, quaternion, _, angular = core.body_state("upper")
    np.testing.assert_allclose(position, upper_R @ [0.25, 0, 0], atol=1e-12)
    np.testing.assert_allclose(quaternion_to_matrix(quaternion), upper_R, atol=1e-12)
    np.testing.assert_allclose(angular, [0, 0.5, 0], atol=1e-9)
    # a hinge's value is body 1's turn relative to body 2 (ODE): the elbow's -1 rad is the
    # forearm (its body 2) turned +1 rad about the elbow's axis (z of the upper rod)
    fore_R = upper_R @ turned((0, 0, 1), 1.0)
    elbow_W = upper_R @ [0.5, 0, 0]
    position, quaternion, *_ = core.body_state("fore")
    np.testing.assert_allclose(position, elbow_W + fore_R @ [0.25, 0, 0], atol=1e-12)
    np.testing.assert_allclose(quaternion_to_matrix(quaternion), fore_R, atol=1e-12)
    core.close()


def test_a_driven_arm_stays_up_with_its_joints_applying_no_force():
    """Dynamic, the shoulder holds the arm up against gravity; kinematic, ODE leaves joints
    between kinematic bodies (or one and the world) out of the step: they apply nothing, and
    the arm stays up all the same."""
    core, joints, motors = two_link_arm(max_force=100.0)
    core.step(H, 1)
    _, (shoulder,), _ = core.state(joints=[joints[0]])
    assert shoulder.force1[2] > 5.0                 # about 2 kg x 9.81 up on the upper rod
    core.close()
    core, joints, motors = two_link_arm(max_force=100.0)
    core.set_drive(motors, ServoDrive.KINEMATIC)
    core.step(H, 100)
    _, reactions, _ = core.state(joints=list(joints))
    for reaction in reactions:
        assert reaction.force1 == reaction.torque1 == (0.0, 0.0, 0.0), reaction
    assert values(core, joints) == [0.0, 0.0]
    core.close()


def test_a_kinematic_servo_follows_its_law_with_no_force_limit():
    """The servo's law alone moves the joint: e(n) = e0 (1 - gain h)^n, exactly, though its
    motor's force limit (0.5 N m) could not even hold the arm up."""
    core, joints, motors = two_link_arm()
    core.set_servo(motors, [0.3, 0.0], gains=[10.0, SERVO_GAIN],
                   max_speeds=[100.0, SERVO_MAX_SPEED], drive=ServoDrive.KINEMATIC)
    core.step(H, 100)
    shoulder, elbow = values(core, joints)
    assert 0.3 - shoulder == pytest.approx(0.3 * (1 - 10.0 * H) ** 100, rel=1e-9)
    assert elbow == pytest.approx(0.0, abs=1e-12)
    core.close()


def test_a_box_in_the_way_is_pushed_and_the_link_does_not_give_way():
    core = Core(WorldParameters(gravity=(0.0, 0.0, 0.0), solver=1))
    core.build_object(ObjectSpec("pusher", [0.1, 0.4, 0.4], mass=1.0, position=(0, 0, 0)))
    core.build_object(ObjectSpec("box", [0.2, 0.2, 0.2], mass=50.0, position=(0.3, 0, 0)))
    rail = core.add_joint(JointSpec(SLIDER, "pusher", "", axis1=(1, 0, 0)))
    # 1 N: far too weak to push 50 kg
    motor = core.add_motor(MotorSpec(joint=rail, kind=MotorKind.LINEAR, max_forces=[1.0]))
    core.set_drive([motor], ServoDrive.KINEMATIC)
    core.set_velocity(motors=[motor], velocities=[0.5])
    core.step(H, 1000)
    assert values(core, [rail]) == pytest.approx([0.5], abs=1e-12)
    pusher_x = core.body_state("pusher")[0][0]
    box_x = core.body_state("box")[0][0]
    assert pusher_x == pytest.approx(0.5, abs=1e-12)
    # the box was pushed ahead of the pusher's face (0.05 m + the box's half size 0.1 m)
    assert box_x >= pusher_x + 0.15 - 0.002
    assert core.body_state("box")[2][0] > 0.4
    core.close()


def test_a_link_driven_out_of_the_world_stops_at_its_extent():
    core = Core(WorldParameters(gravity=(0.0, 0.0, 0.0), world_extent=10.0))
    core.build_object(ObjectSpec("carriage", [0.1, 0.1, 0.1], mass=1.0))
    rail = core.add_joint(JointSpec(SLIDER, "carriage", "", axis1=(1, 0, 0)))
    motor = core.add_motor(MotorSpec(joint=rail, kind=MotorKind.LINEAR))
    core.set_drive([motor], ServoDrive.KINEMATIC)
    core.set_velocity(motors=[motor], velocities=[100.0])
    core.step(0.01, 200)                                   # 200 m asked for
    x = core.body_state("carriage")[0][0]
    assert 9.0 < x <= 10.0 and core.take_divergences() == []
    core.close()


def test_switching_back_to_dynamic_gives_the_motors_the_arm_again():
    core, joints, motors = two_link_arm(max_force=0.5)
    core.set_drive(motors, ServoDrive.KINEMATIC)
    core.step(H, 200)
    assert values(core, joints) == pytest.approx([0.0, 0.0], abs=1e-12)
    core.set_drive(motors, ServoDrive.DYNAMIC)
    assert core.kinematic_links() == {}
    core.step(H, 200)
    # the weak motors no longer hold the arm: it sags under gravity (the shoulder's angle
    # about +y grows as the rods fall towards -z)
    shoulder, _ = values(core, joints)
    assert shoulder > 0.05
    assert core.mass_properties("upper")[0] == pytest.approx(1.0)
    core.close()


def test_the_drive_goes_from_the_world_outwards():
    """Only the forearm: its parent (the upper rod) is dynamic, so it has nothing to follow."""
    core, joints, motors = two_link_arm()
    with pytest.raises(InvalidArgument, match="held by the world"):
        core.set_drive([motors[1]], ServoDrive.KINEMATIC)
    core.set_drive(motors, ServoDrive.KINEMATIC)
    with pytest.raises(InvalidArgument, match="held by the world"):
        core.set_drive([motors[0]], ServoDrive.DYNAMIC)   # would strand the forearm
    assert core.kinematic_links() == {motors[0]: "upper", motors[1]: "fore"}
    core.close()


@pytest.mark.parametrize("motor_ids,drive,error", [
    (["nobody"], ServoDrive.KINEMATIC, UnknownName),
    ([], 7, InvalidArgument),
    ([], True, InvalidArgument),
])
def test_bad_requests_are_refused_and_change_nothing(motor_ids, drive, error):
    core, joints, motors = two_link_arm()
    core.set_velocity(motors=[motors[0]], velocities=[0.5])
    before = core.body_state_vector()
    with pytest.raises(error):
        core.set_servo(motors + motor_ids, [0.1] * len(motors + motor_ids), drive=drive)
    assert core.kinematic_links() == {} and core.servo_states() == []
    assert core.motor_goals()[motors[0]] == [0.5]
    assert core.body_state_vector().tobytes() == before.tobytes()
    core.close()


def test_two_motors_on_one_joint_cannot_both_drive_it():
    core, joints, motors = two_link_arm()
    second = core.add_motor(MotorSpec(id="second", joint=joints[0]))
    with pytest.raises(InvalidArgument, match="both drive"):
        core.set_drive([motors[0], second], ServoDrive.KINEMATIC)
    core.set_drive([motors[0]], ServoDrive.KINEMATIC)
    with pytest.raises(InvalidArgument, match="both drive"):
        core.set_drive([second], ServoDrive.KINEMATIC)
    assert core.kinematic_links() == {motors[0]: "upper"}
    core.close()


def test_a_joint_the_drive_cannot_move_is_refused():
    core = Core(WorldParameters(gravity=GRAVITY))
    core.build_object(ObjectSpec("a", [0.1, 0.1, 0.1], mass=1.0))
    joint = core.add_joint(JointSpec(UNIVERSAL, "a", "", axis1=(1, 0, 0), axis2=(0, 1, 0)))
    motor = core.add_motor(MotorSpec(joint=joint))
    with pytest.raises(Unsupported, match="hinge or a slider"):
        core.set_drive([motor], ServoDrive.KINEMATIC)
    assert core.kinematic_links() == {}
    core.close()


def test_removing_a_joint_returns_the_links_beyond_it_to_dynamic():
    core, joints, motors = two_link_arm()
    core.set_drive(motors, ServoDrive.KINEMATIC)
    core.remove_joint(joints[0])
    assert core.kinematic_links() == {}
    assert core.mass_properties("fore")[0] == pytest.approx(1.0)
    core.step(H, 100)             # both rods now fall freely, the elbow holding them together
    assert core.body_state("upper")[2][2] < -0.5
    core.close()


def test_a_snapshot_puts_the_drive_back_and_replays_bit_for_bit():
    core, joints, motors = two_link_arm()
    core.set_drive(motors, ServoDrive.KINEMATIC)
    core.set_velocity(motors=[motors[0], motors[1]], velocities=[0.5, -1.0])
    core.save_state("moving")
    core.step(H, 300)
    first = core.body_state_vector()
    core.set_drive(motors, ServoDrive.DYNAMIC)
    core.restore_state("moving")
    assert core.kinematic_links() == {motors[0]: "upper", motors[1]: "fore"}
    core.step(H, 300)
    assert core.body_state_vector().tobytes() == first.tobytes()
    core.close()


def _crossing_rails(fixed_wall: bool):
    """Two 0.1 m cubes on rails along x, 0.6 m apart, both under the kinematic drive, driven
    into each other at 0.5 m/s each (gravity off); with ``fixed_wall``, a fixed wall stands
    between them too."""
    core = Core(WorldParameters(gravity=(0.0, 0.0, 0.0), solver=1))
    motors = []
    for name, x, speed in (("left", -0.3, 0.5), ("right", 0.3, -0.5)):
        core.build_object(ObjectSpec(name, [0.1, 0.1, 0.1], mass=1.0, position=(x, 0, 0)))
        rail = core.add_joint(JointSpec(SLIDER, name, "", axis1=(1, 0, 0)))
        motors.append((core.add_motor(MotorSpec(joint=rail, kind=MotorKind.LINEAR)), speed))
    if fixed_wall:
        core.build_object(ObjectSpec("wall", [0.02, 0.5, 0.5], mass=1.0, fixed=True))
    core.set_drive([m for m, _ in motors], ServoDrive.KINEMATIC)
    core.set_velocity(motors=[m for m, _ in motors], velocities=[s for _, s in motors])
    return core


@pytest.mark.parametrize("fixed_wall", [False, True])
def test_links_under_the_kinematic_drive_report_what_they_pass_through(fixed_wall):
    """ODE needs no contact between two bodies the solver cannot move (two driven links, a
    driven link and a fixed body), so none is made; but the pair is met, and a propagation's
    record says so (issue 41, finding 3: two arms driven through each other reported none)."""
    core = _crossing_rails(fixed_wall)
    met = core.propagate(1.0, 0.01, keep=True).collisions
    pairs = {tuple(sorted((c.first, c.second))) for c in met}
    assert ("left", "right") in pairs
    if fixed_wall:
        assert {("left", "wall"), ("right", "wall")} <= pairs
    deepest = max(c.depth for c in met if {c.first, c.second} == {"left", "right"})
    assert deepest > 0.05                      # they passed right through each other
    # and nothing pushed them apart: the drive is exact
    assert core.body_state("left")[0][0] == pytest.approx(0.2, abs=1e-9)
    core.close()
