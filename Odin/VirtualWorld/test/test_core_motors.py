"""Motors through the Core: the frame each axis stays fixed in, the maximum force, and the
ranges of joint and motor parameters, each against a figure written down.

A motor's axes are given in the world frame at creation; ``axis_frames`` says what each axis
turns with afterwards: the world (0), the first body (1) or the second (2). A body joined to
the world is ODE's body 1 whichever slot names it, so a positive goal speed turns it about
+axis in both slots. The body here is a sphere (isotropic inertia: no gyroscopic coupling), so
with an unlimited motor force one step gives it the goal speed about the axis, softened by the
world's constraint force mixing as ODE mixes it: omega = goal / (1 + cfm I / h).
"""
import math

import numpy as np
import pytest

from virtual_world.core import (ANGULAR, CFM, ERP, HI_STOP, HINGE, LO_STOP, MAX_FORCE,
                                JointSpec, MotorSpec, ObjectSpec, WorldParameters)
from virtual_world.errors import InvalidArgument

H = 0.001
TURN_Z = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))   # 90 deg about z: x -> y
I_BALL = 0.4 * 1.0 * 0.1 ** 2                                         # kg m^2, 1 kg, r = 0.1 m
SOFT = 1.0 / (1.0 + WorldParameters().cfm * I_BALL / H)              # 0.99996


@pytest.mark.parametrize("slot", [1, 2])
@pytest.mark.parametrize("frame", ["world", "body"])
def test_a_motor_axis_turns_with_the_frame_it_is_fixed_in(core, slot, frame):
    """Axis x given at creation; the ball is then turned 90 degrees about z. An axis fixed in
    the ball now points along world y, one fixed in the world still along x: the goal speed
    2 rad/s is reached about that axis, with the ball in either slot."""
    core.build_object(ObjectSpec("ball", [0.1], mass=1.0))
    bodies = ("ball", "") if slot == 1 else ("", "ball")
    axis_frame = 0 if frame == "world" else slot
    motor = core.add_motor(MotorSpec(body1=bodies[0], body2=bodies[1], kind=ANGULAR,
                                     axes=[1.0, 0.0, 0.0], axis_frames=[axis_frame]))
    core.set_poses([("ball", (0.0, 0.0, 0.0), TURN_Z)])
    core.set_velocity(motors=[motor], velocities=[2.0])
    core.step(H)
    expected = (2.0, 0.0, 0.0) if frame == "world" else (0.0, 2.0, 0.0)
    np.testing.assert_allclose(core.body_state("ball")[3], np.multiply(expected, SOFT),
                               atol=1e-9)


def test_a_motor_without_force_cannot_move_the_body_and_an_unlimited_one_reaches_its_goal(core):
    """Max force 0 N m: the goal 1 rad/s stays a wish; max force < 0 (unlimited): the goal
    is the speed after one step."""
    core.build_object(ObjectSpec("wheel", [0.1], mass=1.0))   # I = I_BALL about any axis
    joint = core.add_joint(JointSpec(HINGE, "", "wheel", axis1=(0.0, 0.0, 1.0)))
    motor = core.add_motor(MotorSpec(joint=joint, max_forces=[0.0]))
    core.set_velocity(motors=[motor], velocities=[1.0])
    core.step(H, 10)
    assert core.joint_states()[0].rates[0] == 0.0
    core.set_joint_parameters(motor, [(MAX_FORCE, 1, -1.0)])
    core.step(H)
    assert core.joint_states()[0].rates[0] == pytest.approx(SOFT, rel=1e-9)
    core.set_joint_parameters(motor, [(MAX_FORCE, 1, 0.0)])
    core.set_velocity(motors=[motor], velocities=[-1.0])
    core.step(H, 10)
    assert core.joint_states()[0].rates[0] == pytest.approx(SOFT, rel=1e-9)   # coasts on


def test_parameter_ranges_include_their_bounds_and_axes_start_at_1(core):
    """ERP-like values in [0, 1] and CFM-like values >= 0 are accepted at their bounds; axis
    0 (axes count from 1) and values just outside are refused, and refused calls change
    nothing."""
    core.build_object(ObjectSpec("a", [0.1], mass=1.0))
    joint = core.add_joint(JointSpec(HINGE, "", "a", axis1=(0.0, 0.0, 1.0)))
    core.set_joint_parameters(joint, [(ERP, 1, 0.0), (ERP, 1, 1.0), (CFM, 1, 0.0)])
    for bad in ([(ERP, 0, 0.5)], [(ERP, 1, -1e-9)], [(ERP, 1, 1 + 1e-9)], [(CFM, 1, -1e-9)]):
        with pytest.raises(InvalidArgument):
            core.set_joint_parameters(joint, bad)


def test_a_motor_on_a_joint_takes_the_joints_bodies_and_no_others(core):
    """Naming one body of a joint that is not the joint's is refused, as naming both is."""
    for name in ("a", "b", "c"):
        core.build_object(ObjectSpec(name, [0.1], mass=1.0, position=(hash(name) % 7, 0, 0)))
    joint = core.add_joint(JointSpec(HINGE, "a", "b", anchor=(0.0, 0.0, 0.0),
                                     axis1=(0.0, 0.0, 1.0)))
    for bodies in (("c", ""), ("", "c"), ("a", "c")):
        with pytest.raises(InvalidArgument):
            core.add_motor(MotorSpec(joint=joint, body1=bodies[0], body2=bodies[1]))
    assert core.motor_ids() == []
    assert core.add_motor(MotorSpec(joint=joint, body1="a", body2="b")) == f"motor:{joint}"


def test_set_velocity_splits_one_flat_list_among_motors_by_their_axes(core):
    """Set Velocity's list (1.5) + (0.5, -0.25): the one-axis motor takes the first value,
    the two-axis motor the next two; each ball turns at its goals (softened as above). A list
    of the wrong length is refused and changes nothing."""
    core.build_object(ObjectSpec("one", [0.1], mass=1.0))
    core.build_object(ObjectSpec("two", [0.1], mass=1.0, position=(1.0, 0.0, 0.0)))
    m1 = core.add_motor(MotorSpec(id="m1", body1="one", axes=[0.0, 0.0, 1.0], axis_frames=[0]))
    m2 = core.add_motor(MotorSpec(id="m2", body1="two", axes=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
                                  axis_frames=[0, 0]))
    with pytest.raises(InvalidArgument):
        core.set_velocity(motors=[m1, m2], velocities=[1.5, 0.5])
    assert core.motor_goals() == {m1: [0.0], m2: [0.0, 0.0]}
    core.set_velocity(motors=[m1, m2], velocities=[1.5, 0.5, -0.25])
    assert core.motor_goals() == {m1: [1.5], m2: [0.5, -0.25]}
    core.step(H)
    np.testing.assert_allclose(core.body_state("one")[3], np.multiply((0.0, 0.0, 1.5), SOFT),
                               atol=1e-9)
    np.testing.assert_allclose(core.body_state("two")[3], np.multiply((0.5, -0.25, 0.0), SOFT),
                               atol=1e-9)


def test_a_motors_max_force_may_be_given_as_infinite(core):
    core.build_object(ObjectSpec("ball", [0.1], mass=1.0))
    motor = core.add_motor(MotorSpec(body1="ball", axes=[0.0, 0.0, 1.0], max_forces=[math.inf]))
    core.set_velocity(motors=[motor], velocities=[3.0])
    core.step(H)
    assert core.body_state("ball")[3][2] == pytest.approx(3.0 * SOFT, rel=1e-9)


def test_joint_parameters_given_at_creation_act(core):
    """Stops at +-0.2 rad given with the hinge: a 1 N m torque on a ball (I = I_BALL) would
    turn it 0.5 * 250 * 1^2 = 125 rad in 1 s; the stop holds it near 0.2 rad."""
    core.build_object(ObjectSpec("arm", [0.1], mass=1.0))
    joint = core.add_joint(JointSpec(HINGE, "", "arm", axis1=(0.0, 0.0, 1.0),
                                     parameters=[(LO_STOP, 1, -0.2), (HI_STOP, 1, 0.2)]))
    core.add_joint_force(joint, [1.0])
    core.step(H, 1000)
    assert core.joint_states()[0].positions[0] == pytest.approx(0.2, abs=0.02)
