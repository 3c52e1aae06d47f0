"""Joint servos: a motor that tracks a position target, before every step setting its speed
to clamp(rate + gain (target - q), +-max_speed) under its force limit. Checked against the
closed forms: the error decays as exp(-gain t); a saturated servo moves at its speed limit; a
servo too weak for its load stops where the load's torque equals its force limit."""
import math

import numpy as np
import pytest

from odin_common.defaults import SERVO_MAX_SPEED
from virtual_world.core import (HINGE, HINGE2, SLIDER, UNIVERSAL, Core, JointSpec, MotorSpec,
                                ObjectSpec, WorldParameters)
from virtual_world.errors import InvalidArgument, UnknownName, Unsupported

H = 0.001


def rotor(gravity=(0.0, 0.0, 0.0), max_force=100.0):
    """A rod on a hinge about y at the origin (mass 1 kg, its centre 0.25 m out along x)."""
    core = Core(WorldParameters(gravity=gravity, solver=1))
    core.build_object(ObjectSpec("rod", [0.5, 0.05, 0.05], mass=1.0, position=(0.25, 0, 0)))
    joint = core.add_joint(JointSpec(HINGE, "rod", "", anchor=(0, 0, 0), axis1=(0, 1, 0)))
    motor = core.add_motor(MotorSpec(joint=joint, max_forces=[max_force]))
    return core, joint, motor


def angle(core, joint):
    return {s.id: s for s in core.joint_states()}[joint].positions[0]


def test_the_error_decays_as_exp_of_minus_gain_t():
    core, joint, motor = rotor()
    core.set_servo([motor], [0.3], gains=[10.0], max_speeds=[100.0])
    core.step(H, 100)
    # the motor's speed follows the error step by step: e(n) = e0 (1 - gain h)^n
    assert 0.3 - angle(core, joint) == pytest.approx(0.3 * (1 - 10.0 * H) ** 100, rel=0.02)
    core.step(H, 1900)
    assert angle(core, joint) == pytest.approx(0.3, abs=1e-6)
    (state,) = core.servo_states()
    assert state.targets == (0.3,) and abs(state.errors[0]) < 1e-6
    core.close()


def test_the_feed_forward_rate_moves_the_rest_point_by_rate_over_gain():
    """A servo told its target moves at 1 rad/s while the target stays at 0: the speed
    rate + gain (0 - q) is zero at q = rate / gain, where the joint settles."""
    core, joint, motor = rotor()
    core.set_servo([motor], [0.0], rates=[1.0], gains=[20.0])
    core.step(H, 1000)
    assert angle(core, joint) == pytest.approx(1.0 / 20.0, rel=1e-4)
    core.close()


@pytest.mark.parametrize("target", [-2.0, 2.0])
def test_a_far_target_is_reached_at_the_speed_limit_with_the_defaults(target):
    """Either way: the bound holds above as well as below."""
    core, joint, motor = rotor()
    core.set_servo([motor], [target])
    core.step(H, 200)
    rate = {s.id: s for s in core.joint_states()}[joint].rates[0]
    assert rate == pytest.approx(math.copysign(SERVO_MAX_SPEED, target), rel=1e-6)
    core.step(H, 1500)
    assert angle(core, joint) == pytest.approx(target, abs=1e-5)
    core.close()


def test_a_servo_too_weak_for_its_load_gives_way_at_its_force_limit():
    torque, limit = 2.0, 1.5                      # N m: the load beats the servo by 0.5
    core, joint, motor = rotor(max_force=limit)
    core.set_servo([motor], [0.0])
    core.add_joint_force(joint, [torque])
    core.step(H, 500)
    # the servo pushes back with all it has: the rod turns at (torque - limit) / I about the
    # hinge, I = m (a^2 + b^2) / 12 + m d^2 for the 0.5 x 0.05 box 0.25 m out
    inertia = 1.0 * (0.5 ** 2 + 0.05 ** 2) / 12 + 1.0 * 0.25 ** 2
    rate = {s.id: s for s in core.joint_states()}[joint].rates[0]
    assert rate == pytest.approx((torque - limit) / inertia * 0.5, rel=1e-3)
    core.close()


def test_a_slider_servo_and_a_universal_servo_reach_their_targets():
    core = Core(WorldParameters(gravity=(0, 0, 0), solver=1))
    core.build_object(ObjectSpec("cart", [0.2, 0.2, 0.2], position=(0, 0, 0)))
    slider = core.add_joint(JointSpec(SLIDER, "cart", "", axis1=(1, 0, 0)))
    linear = core.add_motor(MotorSpec(joint=slider, kind=1, max_forces=[100.0]))
    core.build_object(ObjectSpec("head", [0.1], position=(3, 0, 0)))
    universal = core.add_joint(JointSpec(UNIVERSAL, "head", "", anchor=(3, 0, 0), axis1=(1, 0, 0),
                                         axis2=(0, 1, 0)))
    both = core.add_motor(MotorSpec(joint=universal, max_forces=[100.0, 100.0]))
    # the universal's servo keeps the default speed limit
    core.set_servo([linear, both], [0.4, 0.2, -0.3],
                   max_speeds=[1.0, SERVO_MAX_SPEED, SERVO_MAX_SPEED])
    core.step(H, 2000)
    states = {s.id: s for s in core.joint_states()}
    assert states[slider].positions[0] == pytest.approx(0.4, abs=1e-5)
    np.testing.assert_allclose(states[universal].positions, (0.2, -0.3), atol=1e-4)
    core.close()


def test_a_servo_on_a_hinge2s_second_axis_pulls_the_right_way():
    core = Core(WorldParameters(gravity=(0, 0, 0), solver=1))
    core.build_object(ObjectSpec("chassis", [1, 1, 0.2], position=(0, 0, 0)))
    core.add_joint(JointSpec(8, "chassis", ""))      # fixed to the world
    core.build_object(ObjectSpec("wheel", [0.2, 0.1], position=(1, 0, 0)))
    hinge2 = core.add_joint(JointSpec(HINGE2, "chassis", "wheel", anchor=(1, 0, 0), axis1=(0, 0, 1),
                                      axis2=(0, 1, 0)))
    motor = core.add_motor(MotorSpec(joint=hinge2, max_forces=[50.0, 50.0]))
    core.set_servo([motor], [0.1, 0.5])
    core.step(H, 2000)
    state = {s.id: s for s in core.joint_states()}[hinge2]
    assert state.positions == pytest.approx((0.1, 0.5), abs=1e-4)
    core.close()


def test_a_servo_holds_its_joint_where_set_position_put_it():
    """Under gravity, a rod held at 0 by its servo is turned to 0.5 rad by Set Position: the
    servo now holds 0.5 rad (it does not pull the rod back to 0)."""
    core, joint, motor = rotor(gravity=(0.0, 0.0, -9.81))
    core.set_servo([motor], [0.0])
    core.step(H, 100)
    half = (math.cos(0.25), 0.0, math.sin(0.25), 0.0)      # 0.5 rad about +y
    core.set_poses([("rod", (0.25 * math.cos(0.5), 0.0, -0.25 * math.sin(0.5)), half)],
                   reset_velocity=True)
    (state,) = core.servo_states()
    assert state.targets[0] == pytest.approx(angle(core, joint), abs=1e-9)
    assert angle(core, joint) == pytest.approx(0.5, abs=1e-6)
    core.step(H, 1000)
    assert angle(core, joint) == pytest.approx(0.5, abs=1e-3)
    core.close()


def test_a_goal_speed_takes_a_motor_out_of_servo_mode():
    core, joint, motor = rotor()
    core.set_servo([motor], [0.0])
    core.set_velocity(motors=[motor], velocities=[1.0])
    assert core.servo_states() == []
    core.step(H, 200)
    assert angle(core, joint) == pytest.approx(0.2, rel=1e-3)
    core.close()


def test_a_released_servo_holds_still_and_a_snapshot_brings_the_servo_back():
    core, joint, motor = rotor(gravity=(0, 0, -9.81))
    core.set_servo([motor], [0.5])
    core.step(H, 50)
    core.save_state("tracking")
    core.step(H, 500)
    tracked = angle(core, joint)
    core.release_servos([motor])
    assert core.servo_states() == [] and core.motor_goals()[motor] == [0.0]
    core.step(H, 500)
    assert {s.id: s for s in core.joint_states()}[joint].rates[0] == pytest.approx(0, abs=1e-4)
    core.restore_state("tracking")
    core.step(H, 500)
    assert angle(core, joint) == tracked
    core.close()


@pytest.mark.parametrize("motors,lists,error", [
    (["motor:1:rod&"], dict(targets=[]), InvalidArgument),
    (["motor:1:rod&"], dict(targets=[0.1, 0.2]), InvalidArgument),
    (["motor:1:rod&"], dict(targets=[0.1], gains=[-1.0]), InvalidArgument),
    (["motor:1:rod&"], dict(targets=[0.1], rates=[1.0, 2.0]), InvalidArgument),
    (["motor:1:rod&"], dict(targets=[math.nan]), InvalidArgument),
    (["motor:1:rod&", "motor:rod&"], dict(targets=[1.0, 0.1]), Unsupported),
    (["motor:1:rod&", "nope"], dict(targets=[1.0, 0.1]), UnknownName),
])
def test_bad_servo_requests_are_refused_and_change_nothing(motors, lists, error):
    core, joint, motor = rotor()
    core.add_motor(MotorSpec(body1="rod", axes=[0, 0, 1]))   # a motor without a joint
    with pytest.raises(error):
        core.set_servo(motors, **lists)
    assert core.servo_states() == []
    core.close()


def _rod_angle(core) -> float:
    """rad: the rod's turn about y from where it was built (its x axis in the x-z plane), in
    (-pi, pi]: what ODE's hinge angle reads."""
    _, quaternion, _, _ = core.body_state("rod")
    w, x, y, z = quaternion
    return math.atan2(2 * (w * y - x * z), 1 - 2 * (y * y + z * z))


def test_a_servo_follows_a_path_through_a_half_turn_without_unwinding():
    """A hinge without stops (a joint whose range passes +-pi: its stops are left unset,
    gui.core.translate.joints) tracked from 2.6 to 4.0 rad, as a path's servo targets
    arrive: ODE reads 4.0 rad as -2.28, and a servo that believed it would turn the rod
    most of a turn back. It takes the turn of each reading nearest the last one."""
    core, joint, motor = rotor()
    core.set_servo([motor], [2.6], gains=[20.0], max_speeds=[10.0])
    core.step(H, 1000)
    for k in range(1, 141):                         # 1 rad/s for 1.4 s, a target per 10 ms
        core.set_servo([motor], [2.6 + 0.01 * k], rates=[1.0], gains=[20.0])
        core.step(H, 10)
        (state,) = core.servo_states()
        assert abs(state.errors[0]) < 0.01, (k, state)      # never a turn away
    core.set_servo([motor], [4.0], gains=[20.0])             # the path's end: held there
    core.step(H, 1000)
    (state,) = core.servo_states()
    assert state.positions[0] == pytest.approx(4.0, abs=1e-3)
    assert _rod_angle(core) == pytest.approx(4.0 - 2 * math.pi, abs=1e-3)   # the same place
    core.close()


def test_a_servo_set_once_far_past_a_half_turn_goes_the_short_way_to_the_same_place():
    """Only the turn nearest the target can be told from a reading in [-pi, pi]: a target of
    4.0 rad from 0 is reached at -2.28 rad, the same place, turning 2.28 rad, not 4."""
    core, joint, motor = rotor()
    core.set_servo([motor], [4.0], gains=[20.0], max_speeds=[10.0])
    core.step(H, 2000)
    (state,) = core.servo_states()
    assert state.positions[0] == pytest.approx(4.0, abs=1e-4)
    assert _rod_angle(core) == pytest.approx(4.0 - 2 * math.pi, abs=1e-4)
    core.close()


def test_a_hinge_with_both_stops_within_a_half_turn_is_read_as_ode_reads_it():
    """Stops at +-2.5 rad: the reading is unique, and a target 4.8 rad away is reached the
    long way round, as the stops allow, never through them (the nearest turn would have
    sent it 1.48 rad the other way, into a stop)."""
    from virtual_world.core import HI_STOP, LO_STOP
    core, joint, motor = rotor()
    core.set_joint_parameters(joint, [(LO_STOP, 1, -2.5), (HI_STOP, 1, 2.5)])
    core.set_servo([motor], [-2.4], gains=[20.0], max_speeds=[10.0])
    core.step(H, 1000)
    core.set_servo([motor], [2.4], gains=[20.0], max_speeds=[10.0])
    core.step(H, 2000)
    assert angle(core, joint) == pytest.approx(2.4, abs=1e-4)
    core.close()
