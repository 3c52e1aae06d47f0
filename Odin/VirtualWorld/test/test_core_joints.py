"""Every joint type through the Core, signed and analytic: joint forces, motors, stops, the
fixed and plane-2D constraints, and the angles and positions joint_states reports.

Sign convention (ODE's, kept by the Core). A joint joins body1 to body2, or a body to the
static world. A positive joint force or torque acts on body1 along +axis, and its reaction,
the same along -axis, on body2 (dJointAddHingeTorque and the others; the Core's ball, PR-force
and PU torques do the same in odin_step.c). A joint's rate is the velocity of body1 relative to
body2 along or about the axis, axis . (v1 - v2) or axis . (w1 - w2), and its angle or position
grows with that rate. A body joined to the world is ODE's body1 whichever slot names it, so a
joint with the world moves its body along +axis, as motors' goal speeds do. ODE's one exception,
kept here because the Core passes it through: hinge-2 angle2 (dJointGetHinge2Angle2) is minus
the integral of its rate (dJointGetHinge2Angle2Rate); it grows when body2 turns about +axis2.

How the figures are exact. Gravity is off. Every body is joined at its centre of mass with
joint axes along its principal axes (or is a sphere), so a force or torque along a free axis
needs no constraint force and is a constant acceleration a = F / m or tau / I_axis; ODE's
semi-implicit Euler is exact for it: after n steps of h, rate = n h a and displacement =
h^2 a n (n + 1) / 2. Rates and linear motion then agree to rounding (RATE_TOL); angles also
carry ODE's quaternion update, which turns by 2 atan(h w / 2) instead of h w per step, a
relative error below (h w)^2 / 12 < 1e-6 here (ANGLE_TOL).

What each test pins down:
* test_block_has_the_closed_form_mass_and_inertia: the constants the figures below use.
* test_joint_force_to_the_world_moves_the_body_along_plus_axis: hinge, slider, piston,
  universal, PR and PU forces/torques, and the ball torque, on a body joined to the world in
  either slot: signed joint rates and positions, and the body's velocity, angular velocity,
  position and orientation.
* test_ball_torque_turns_a_body_about_the_world_torque: the ball's torque is a world vector.
* test_joint_torque_between_two_bodies_turns_body1_forward_and_body2_back and
  test_joint_force_between_two_bodies_pushes_body1_forward_and_body2_back: body1 gets +axis,
  body2 the reaction; angular or linear momentum stays zero; the joint's rate is the
  relative motion (every type with a force, hinge-2 included).
* test_motor_on_a_joint_holds_the_signed_goal_speed_of_every_axis: create_motor on a joint,
  angular and linear, every type with motor axes; the goals hold while body1 turns far.
* test_motor_short_of_force_accelerates_at_max_force_over_inertia_toward_the_goal.
* test_stops_hold_the_joint_at_its_signed_limits: free motion between lo and hi stops, then
  each stop holds against a push into it (every axis that takes stops).
* test_fixed_joint_keeps_two_bodies_0_3_m_apart_under_forces,
  test_fixed_joint_moves_the_pair_as_one_body, test_fixed_joint_to_the_world_holds_the_body.
* test_plane_2d_keeps_the_body_in_z_0_while_pushed_out_of_it: z, and no turning out of the
  plane, while the in-plane motion stays free.
* test_joint_states_report_the_imposed_geometry_with_signs and
  test_hinge2_states_report_steering_of_body1_and_spin_of_body2: set_poses against every
  type's angles and positions.
* test_a_hinge2_joint_to_the_world_is_refused_not_a_crash: ODE's hinge-2 needs two bodies and
  ends the process when given one; the Core must refuse it first (a forked test).
"""
import math

import numpy as np
import pytest

from odin_common.rotations import quaternion_multiply
from virtual_world.core import (ANGULAR, BALL, Core, FIXED, FORCE, HI_STOP, HINGE, HINGE2,
                                JointSpec, LINEAR, LO_STOP, MotorSpec, ObjectSpec, PISTON, PLANE2D,
                                PR, PU, SLIDER, TORQUE, UNIVERSAL)
from virtual_world.errors import InvalidArgument, Unsupported

H = 0.001          # s, step
N = 200            # steps of the constant-acceleration checks
RATE_TOL = 1e-9    # relative: rates and linear motion are exact to rounding
ANGLE_TOL = 1e-6   # relative: ODE's quaternion update (module docstring)

X, Y, Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
MINUS_Y = (0.0, -1.0, 0.0)
SLANT = (0.0, 0.6, -0.8)   # a unit axis off the coordinate axes, for sliding

# the block: a box 0.2 x 0.4 x 0.6 m of 2 kg, its principal axes along x, y, z
BLOCK_SIDES, BLOCK_MASS = (0.2, 0.4, 0.6), 2.0
IXX = BLOCK_MASS * (0.4 ** 2 + 0.6 ** 2) / 12   # 0.0867 kg m^2
IYY = BLOCK_MASS * (0.2 ** 2 + 0.6 ** 2) / 12   # 0.0667
IZZ = BLOCK_MASS * (0.2 ** 2 + 0.4 ** 2) / 12   # 0.0333
BLOCK_INERTIA = np.array([IXX, IYY, IZZ])
# two spheres of radius 0.1 m: 1 kg and 3 kg, I = 2/5 m r^2
RADIUS, M1, M3 = 0.1, 1.0, 3.0
I1, I3 = 0.4 * M1 * RADIUS ** 2, 0.4 * M3 * RADIUS ** 2   # 0.004, 0.012 kg m^2

LIN, ANG = "linear", "angular"


@pytest.fixture
def core():
    c = Core()
    c.set_world_parameters(gravity=(0.0, 0.0, 0.0))
    yield c
    c.close()


# ------------------------------------------------------------------ helpers


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def quaternion(axis, angle):
    """(w, x, y, z) of the rotation by `angle` about `axis`."""
    return np.array([math.cos(angle / 2), *(math.sin(angle / 2) * unit(axis))])


def rotate(q, v):
    """v turned by the unit quaternion q: v + 2w (u x v) + 2 u x (u x v)."""
    w, u = q[0], np.asarray(q[1:], dtype=float)
    v = np.asarray(v, dtype=float)
    return v + 2 * w * np.cross(u, v) + 2 * np.cross(u, np.cross(u, v))


def rotation_vector_quaternion(r):
    """The quaternion of the rotation by |r| about r (identity for r = 0)."""
    angle = float(np.linalg.norm(r))
    return np.array([1.0, 0, 0, 0]) if angle == 0 else quaternion(r, angle)


def rate_after(a, n=N):
    """Semi-implicit Euler under a constant acceleration a: the rate after n steps."""
    return n * H * np.asarray(a, dtype=float)


def travel_after(a, n=N):
    """... and the displacement after n steps."""
    return H * H * n * (n + 1) / 2 * np.asarray(a, dtype=float)


def block(core, name="block", position=(0.0, 0.0, 0.0)):
    core.build_object(ObjectSpec(name, list(BLOCK_SIDES), mass=BLOCK_MASS, position=position,
                                 no_collisions=True))


def sphere(core, name, mass, position=(0.0, 0.0, 0.0)):
    core.build_object(ObjectSpec(name, [RADIUS], mass=mass, position=position,
                                 no_collisions=True))


def joint_state(core, joint_id):
    (state,) = [s for s in core.joint_states() if s.id == joint_id]
    return state


def assert_moving_uniformly(core, name, accel, alpha, start=(0.0, 0.0, 0.0), n=N):
    """The body's linear and angular velocity, position and orientation after n steps from
    rest under constant world accelerations accel (m/s^2) and alpha (rad/s^2, one fixed
    axis), all signed."""
    position, q, v, w = core.body_state(name)
    np.testing.assert_allclose(v, rate_after(accel, n), rtol=RATE_TOL, atol=1e-15)
    np.testing.assert_allclose(position, np.asarray(start) + travel_after(accel, n),
                               rtol=RATE_TOL, atol=1e-15)
    np.testing.assert_allclose(w, rate_after(alpha, n), rtol=RATE_TOL, atol=1e-15)
    expected_q = rotation_vector_quaternion(travel_after(alpha, n))
    np.testing.assert_allclose(q, expected_q, rtol=ANGLE_TOL, atol=1e-12)


# ------------------------------------------------------------------ the constants


def test_block_has_the_closed_form_mass_and_inertia(core):
    block(core)
    sphere(core, "s1", M1, position=(1, 0, 0))
    sphere(core, "s3", M3, position=(2, 0, 0))
    mass, com, inertia = core.mass_properties("block")
    assert mass == BLOCK_MASS
    np.testing.assert_allclose(com, 0.0, atol=1e-15)
    np.testing.assert_allclose(inertia, np.diag(BLOCK_INERTIA), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(core.mass_properties("s1")[2], I1 * np.eye(3), rtol=1e-12)
    np.testing.assert_allclose(core.mass_properties("s3")[2], I3 * np.eye(3), rtol=1e-12)


# ------------------------------------------------------------------ joint forces, world

# Each case: joint type, axes, magnitudes for add_joint_force, the force (N) and torque (N m)
# they put on the body (world), and what joint_states index k measures: (LIN or ANG, axis).
WORLD_FORCES = [
    pytest.param(HINGE, dict(axis1=Y), [-0.05], (0, 0, 0), (0, -0.05, 0), [(ANG, Y)],
                 id="hinge"),
    pytest.param(HINGE, dict(axis1=MINUS_Y), [0.05], (0, 0, 0), (0, -0.05, 0),
                 [(ANG, MINUS_Y)], id="hinge-about-minus-y"),
    pytest.param(SLIDER, dict(axis1=SLANT), [3.0], 3.0 * np.array(SLANT), (0, 0, 0),
                 [(LIN, SLANT)], id="slider"),
    pytest.param(PISTON, dict(axis1=X), [-1.5], (-1.5, 0, 0), (0, 0, 0),
                 [(LIN, X), (ANG, X)], id="piston"),
    pytest.param(UNIVERSAL, dict(axis1=X, axis2=Y), [0.04, 0.0], (0, 0, 0), (0.04, 0, 0),
                 [(ANG, X), (ANG, Y)], id="universal-torque1"),
    pytest.param(UNIVERSAL, dict(axis1=X, axis2=Y), [0.0, -0.04], (0, 0, 0), (0, -0.04, 0),
                 [(ANG, X), (ANG, Y)], id="universal-torque2"),
    pytest.param(PR, dict(axis1=X, axis2=Z), [2.0, 0.0], (2.0, 0, 0), (0, 0, 0),
                 [(LIN, X), (ANG, Z)], id="pr-force"),
    pytest.param(PR, dict(axis1=X, axis2=Z), [0.0, -0.03], (0, 0, 0), (0, 0, -0.03),
                 [(LIN, X), (ANG, Z)], id="pr-torque"),
    pytest.param(PU, dict(axis1=X, axis2=Y, axis3=Z), [0.04, 0.0], (0, 0, 0), (0.04, 0, 0),
                 [(LIN, Z), (ANG, X), (ANG, Y)], id="pu-torque1"),
    pytest.param(PU, dict(axis1=X, axis2=Y, axis3=Z), [0.0, 0.04], (0, 0, 0), (0, 0.04, 0),
                 [(LIN, Z), (ANG, X), (ANG, Y)], id="pu-torque2"),
    pytest.param(BALL, {}, [0.0, 0.0, -0.02], (0, 0, 0), (0, 0, -0.02), [], id="ball"),
]


@pytest.mark.parametrize("bodies", [("block", ""), ("", "block")],
                         ids=["body-first", "world-first"])
@pytest.mark.parametrize("joint_type,axes,magnitudes,force,torque,measures", WORLD_FORCES)
def test_joint_force_to_the_world_moves_the_body_along_plus_axis(core, bodies, joint_type, axes,
                                                                 magnitudes, force, torque,
                                                                 measures):
    block(core)
    core.add_joint(JointSpec(joint_type, *bodies, anchor=(0, 0, 0), id="j", **axes))
    core.add_joint_force("j", magnitudes)
    core.step(H, N)
    accel = np.asarray(force, dtype=float) / BLOCK_MASS          # a = F / m
    alpha = np.asarray(torque, dtype=float) / BLOCK_INERTIA      # principal axes: tau_i / I_i
    assert_moving_uniformly(core, "block", accel, alpha)
    state = joint_state(core, "j")
    assert len(state.rates) == len(measures)
    for k, (kind, axis) in enumerate(measures):
        a = float(unit(axis) @ (accel if kind == LIN else alpha))
        tol = RATE_TOL if kind == LIN else ANGLE_TOL
        assert state.rates[k] == pytest.approx(rate_after(a), rel=RATE_TOL, abs=1e-15)
        assert state.positions[k] == pytest.approx(travel_after(a), rel=tol, abs=1e-15)


@pytest.mark.parametrize("bodies", [("s1", ""), ("", "s1")], ids=["body-first", "world-first"])
def test_ball_torque_turns_a_body_about_the_world_torque(core, bodies):
    # a sphere, so that any direction is principal: alpha = tau / I along tau
    sphere(core, "s1", M1)
    core.set_poses([("s1", (0, 0, 0), quaternion((1, 2, 3), 0.7))])   # turned: tau stays world
    core.add_joint(JointSpec(BALL, *bodies, anchor=(0, 0, 0), id="ball"))
    tau = np.array([0.003, -0.004, 0.012])
    core.add_joint_force("ball", tau.tolist())
    core.step(H, N)
    position, q, v, w = core.body_state("s1")
    np.testing.assert_allclose(w, rate_after(tau / I1), rtol=RATE_TOL)
    np.testing.assert_allclose(v, 0.0, atol=1e-12)
    np.testing.assert_allclose(position, 0.0, atol=1e-12)
    turned = quaternion_multiply(rotation_vector_quaternion(travel_after(tau / I1)),
                                 quaternion((1, 2, 3), 0.7))
    np.testing.assert_allclose(q, turned, rtol=ANGLE_TOL, atol=1e-9)
    assert joint_state(core, "ball").positions == ()


# ------------------------------------------------------------------ joint forces, two bodies

# Two spheres at the same point (body1 1 kg, body2 3 kg), joined there: each case's torque
# on body1 (world), the axis each joint_states index measures (None: a sliding index, still),
# and the sign its angle has against its rate (-1: ODE's hinge-2 angle2, module docstring).
TWO_BODY_TORQUES = [
    pytest.param(HINGE, dict(axis1=Z), [0.002], (0, 0, 0.002), [(Z, 1)], id="hinge"),
    pytest.param(BALL, {}, [0.001, -0.002, 0.0015], (0.001, -0.002, 0.0015), [], id="ball"),
    pytest.param(UNIVERSAL, dict(axis1=X, axis2=Y), [-0.002, 0.0], (-0.002, 0, 0),
                 [(X, 1), (Y, 1)], id="universal-torque1"),
    pytest.param(UNIVERSAL, dict(axis1=X, axis2=Y), [0.0, 0.002], (0, 0.002, 0),
                 [(X, 1), (Y, 1)], id="universal-torque2"),
    pytest.param(HINGE2, dict(axis1=Z, axis2=Y), [0.002, 0.0], (0, 0, 0.002),
                 [(Z, 1), (Y, -1)], id="hinge2-torque1"),
    pytest.param(HINGE2, dict(axis1=Z, axis2=Y), [0.0, 0.002], (0, 0.002, 0),
                 [(Z, 1), (Y, -1)], id="hinge2-torque2"),
    pytest.param(PR, dict(axis1=X, axis2=Z), [0.0, -0.002], (0, 0, -0.002),
                 [(None, 1), (Z, 1)], id="pr-torque"),
    pytest.param(PU, dict(axis1=X, axis2=Y, axis3=Z), [0.002, 0.0], (0.002, 0, 0),
                 [(None, 1), (X, 1), (Y, 1)], id="pu-torque1"),
    pytest.param(PU, dict(axis1=X, axis2=Y, axis3=Z), [0.0, -0.002], (0, -0.002, 0),
                 [(None, 1), (X, 1), (Y, 1)], id="pu-torque2"),
]


@pytest.mark.parametrize("joint_type,axes,magnitudes,torque,measures", TWO_BODY_TORQUES)
def test_joint_torque_between_two_bodies_turns_body1_forward_and_body2_back(
        core, joint_type, axes, magnitudes, torque, measures):
    sphere(core, "s1", M1)
    sphere(core, "s3", M3)
    core.add_joint(JointSpec(joint_type, "s1", "s3", anchor=(0, 0, 0), id="j", **axes))
    core.add_joint_force("j", magnitudes)
    core.step(H, N)
    torque = np.asarray(torque, dtype=float)
    w1, w3 = core.body_state("s1")[3], core.body_state("s3")[3]
    np.testing.assert_allclose(w1, rate_after(torque / I1), rtol=RATE_TOL, atol=1e-15)
    np.testing.assert_allclose(w3, rate_after(-torque / I3), rtol=RATE_TOL, atol=1e-15)
    np.testing.assert_allclose(I1 * w1 + I3 * w3, 0.0, atol=1e-15)   # angular momentum
    for name in ("s1", "s3"):
        np.testing.assert_allclose(core.body_state(name)[0], 0.0, atol=1e-12)
    state = joint_state(core, "j")
    assert len(state.rates) == len(measures)
    for k, (axis, sign) in enumerate(measures):
        # relative angular acceleration about the axis: tau . axis (1/I1 + 1/I3)
        a = 0.0 if axis is None else float(unit(axis) @ torque) * (1 / I1 + 1 / I3)
        assert state.rates[k] == pytest.approx(rate_after(a), rel=RATE_TOL, abs=1e-15)
        assert state.positions[k] == pytest.approx(sign * travel_after(a), rel=ANGLE_TOL,
                                                   abs=1e-15)


# Body1 (1 kg) at the origin, body2 (3 kg) 0.3 m further along the sliding axis: the force on
# body1 along +axis and, for each joint_states index, whether it measures the sliding.
TWO_BODY_FORCES = [
    pytest.param(SLIDER, dict(axis1=SLANT), [0.5], SLANT, [True], id="slider"),
    pytest.param(PISTON, dict(axis1=X), [-0.5], X, [True, False], id="piston"),
    pytest.param(PR, dict(axis1=X, axis2=Z), [0.5, 0.0], X, [True, False], id="pr-force"),
]


@pytest.mark.parametrize("joint_type,axes,magnitudes,axis,measures", TWO_BODY_FORCES)
def test_joint_force_between_two_bodies_pushes_body1_forward_and_body2_back(
        core, joint_type, axes, magnitudes, axis, measures):
    axis = unit(axis)
    sphere(core, "s1", M1)
    sphere(core, "s3", M3, position=0.3 * axis)
    core.add_joint(JointSpec(joint_type, "s1", "s3", anchor=0.15 * axis, id="j", **axes))
    core.add_joint_force("j", magnitudes)
    core.step(H, N)
    force = magnitudes[0] * axis
    assert_moving_uniformly(core, "s1", force / M1, (0, 0, 0))
    assert_moving_uniformly(core, "s3", -force / M3, (0, 0, 0), start=0.3 * axis)
    v1, v3 = core.body_state("s1")[2], core.body_state("s3")[2]
    np.testing.assert_allclose(M1 * v1 + M3 * v3, 0.0, atol=1e-15)   # linear momentum
    state = joint_state(core, "j")
    assert len(state.rates) == len(measures)
    for k, sliding in enumerate(measures):
        a = magnitudes[0] * (1 / M1 + 1 / M3) if sliding else 0.0   # relative acceleration
        assert state.rates[k] == pytest.approx(rate_after(a), rel=RATE_TOL, abs=1e-15)
        assert state.positions[k] == pytest.approx(travel_after(a), rel=RATE_TOL, abs=1e-15)


# ------------------------------------------------------------------ motors

# Each case: joint type, axes, motor kind, goal speeds per motor axis, the joint_states index
# each motor axis drives and the sign of that position against its rate (ODE's hinge-2
# angle2: -1). Hinge-2 joins the block to the 3 kg sphere; the others join the block to the
# world.
MOTORS = [
    pytest.param(HINGE, dict(axis1=Y), ANGULAR, [-2.0], [(0, 1)], id="hinge"),
    pytest.param(SLIDER, dict(axis1=SLANT), LINEAR, [0.7], [(0, 1)], id="slider"),
    pytest.param(PISTON, dict(axis1=X), LINEAR, [-0.4], [(0, 1)], id="piston-linear"),
    pytest.param(PISTON, dict(axis1=X), ANGULAR, [1.5], [(1, 1)], id="piston-angular"),
    pytest.param(UNIVERSAL, dict(axis1=X, axis2=Y), ANGULAR, [1.0, -0.5], [(0, 1), (1, 1)],
                 id="universal"),
    pytest.param(HINGE2, dict(axis1=Z, axis2=Y), ANGULAR, [1.0, -0.5], [(0, 1), (1, -1)],
                 id="hinge2"),
    pytest.param(PR, dict(axis1=X, axis2=Z), LINEAR, [0.3], [(0, 1)], id="pr-linear"),
    pytest.param(PR, dict(axis1=X, axis2=Z), ANGULAR, [-1.2], [(1, 1)], id="pr-angular"),
    pytest.param(PU, dict(axis1=X, axis2=Y, axis3=Z), LINEAR, [-0.3], [(0, 1)],
                 id="pu-linear"),
    pytest.param(PU, dict(axis1=X, axis2=Y, axis3=Z), ANGULAR, [1.0, -0.5], [(1, 1), (2, 1)],
                 id="pu-angular"),
]


def in_both_slots(cases):
    """Each case with the block joined to the world in either slot (hinge-2: to the sphere)."""
    result = []
    for case in cases:
        if case.values[0] == HINGE2:
            slots = [(("block", "s3"), "two-bodies")]
        else:
            slots = [(("block", ""), "body-first"), (("", "block"), "world-first")]
        for bodies, label in slots:
            result.append(pytest.param(*case.values, bodies, id=f"{case.id}-{label}"))
    return result


@pytest.mark.parametrize("joint_type,axes,kind,goals,drives,bodies", in_both_slots(MOTORS))
def test_motor_on_a_joint_holds_the_signed_goal_speed_of_every_axis(core, joint_type, axes,
                                                                    kind, goals, drives, bodies):
    block(core)
    if "s3" in bodies:
        sphere(core, "s3", M3)
    core.add_joint(JointSpec(joint_type, *bodies, anchor=(0, 0, 0), id="j", **axes))
    # The joint's axes, unlimited force. Each motor axis must stay fixed in the body (or the
    # world) its joint axis is fixed in: axis2 of a universal, hinge-2 or PU joint is fixed in
    # body2, so a motor that kept it in body1 would drive axis2 cos(angle1) . (w1 - w2) and
    # its joint rate would run away as goal / cos(angle1) while body1 turns.
    core.add_motor(MotorSpec(id="m", joint="j", kind=kind))
    core.set_velocity(motors=["m"], velocities=goals)
    # An unlimited motor closes the gap to its goal in a few steps: the world's CFM (1e-5)
    # softens its row, so that each step leaves c = (CFM / h) / (CFM / h + 1 / inertia) of it,
    # at most 0.02 here (the 2 kg block's slide); after 5 steps c^5 < 1e-8.
    core.step(H, 5)
    state = joint_state(core, "j")
    for goal, (k, _) in zip(goals, drives):
        assert state.rates[k] == pytest.approx(goal, rel=1e-6)
    # 1 s later body1 has turned or slid far (1 rad at 1 rad/s): every axis still holds its
    # goal, and each position is goal * time, short by the first steps' gap: c / (1 - c) of
    # one step's travel out of n, a relative 2e-5 at most. Turning about two axes at once,
    # ODE's first-order orientation update lets the joint drift and its ERP correction moves
    # the rates by a relative 3e-5 at most (hinge-2) over the second: rel 1e-4 for both.
    n = 1000
    core.step(H, n - 5)
    state = joint_state(core, "j")
    for goal, (k, sign) in zip(goals, drives):
        assert state.rates[k] == pytest.approx(goal, rel=1e-4)
        assert state.positions[k] == pytest.approx(sign * goal * n * H, rel=1e-4)
    # the other axes of the joint do not move
    driven = {k for _, (k, _) in zip(goals, drives)}
    for k in set(range(len(state.rates))) - driven:
        assert state.rates[k] == pytest.approx(0.0, abs=1e-9)
        assert state.positions[k] == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("goal_sign", [1.0, -1.0], ids=["forward", "backward"])
@pytest.mark.parametrize("joint_type,axes,kind,goal,max_force,inertia", [
    pytest.param(HINGE, dict(axis1=Y), ANGULAR, 2.0, 0.1, IYY, id="hinge-angular"),
    pytest.param(SLIDER, dict(axis1=SLANT), LINEAR, 0.5, 1.0, BLOCK_MASS, id="slider-linear"),
])
def test_motor_short_of_force_accelerates_at_max_force_over_inertia_toward_the_goal(
        core, joint_type, axes, kind, goal, max_force, inertia, goal_sign):
    block(core)
    core.add_joint(JointSpec(joint_type, "block", "", anchor=(0, 0, 0), id="j", **axes))
    core.add_motor(MotorSpec(id="m", joint="j", kind=kind, max_forces=[max_force]))
    goal = goal_sign * goal
    core.set_velocity(motors=["m"], velocities=[goal])
    a = math.copysign(max_force / inertia, goal)   # the whole max force, toward the goal
    core.step(H, N)
    state = joint_state(core, "j")
    assert abs(rate_after(a)) < abs(goal)   # still short of it
    assert state.rates[0] == pytest.approx(rate_after(a), rel=RATE_TOL)
    assert state.positions[0] == pytest.approx(travel_after(a), rel=ANGLE_TOL)
    u = unit(axes["axis1"])
    _, _, v, w = core.body_state("block")
    np.testing.assert_allclose(v if kind == LINEAR else w, rate_after(a) * u, rtol=RATE_TOL,
                               atol=1e-15)
    core.step(H, round(abs(goal / a) / H) + 300)   # reached: held there
    assert joint_state(core, "j").rates[0] == pytest.approx(goal, rel=1e-9)


# ------------------------------------------------------------------ stops

# A joint row under a steady load gives like a spring of stiffness ERP / (h CFM) (2e7 N/m or
# N m/rad with the world's ERP 0.2 and CFM 1e-5): a stop pushed with 2 N holds 1e-7 m past its
# limit, and a fixed joint pulled with 2 N stretches by as much. Ten times that:
STOP_TOL = 1e-6   # m or rad

# Each case: joint type, axes, the body joined to the block ("" the world), the parameter axis
# the stops go on, the joint_states index they limit, the push on the block (a body force or
# torque, world) and the free acceleration it gives that index (closed form), lo, hi. The
# parameter axes are ODE's groups: piston and PR 1 position, 2 angle (as joint_states lists
# them); PU 1 angle1, 2 angle2, 3 position (joint_states lists the position first); hinge-2
# has stops on axis 1 only. The push is a body force, not a joint force, so that these
# cases do not depend on the joint forces' signs.
STOPS = [
    pytest.param(HINGE, dict(axis1=Y), "", 1, 0, TORQUE, (0, 0.05, 0), 0.05 / IYY, -0.3, 0.2,
                 id="hinge"),
    pytest.param(SLIDER, dict(axis1=Z), "", 1, 0, FORCE, (0, 0, 2.0), 2.0 / BLOCK_MASS, -0.05,
                 0.1, id="slider"),
    pytest.param(PISTON, dict(axis1=X), "", 1, 0, FORCE, (2.0, 0, 0), 2.0 / BLOCK_MASS, -0.05,
                 0.1, id="piston-position"),
    pytest.param(PISTON, dict(axis1=X), "", 2, 1, TORQUE, (0.05, 0, 0), 0.05 / IXX, -0.3, 0.2,
                 id="piston-angle"),
    pytest.param(UNIVERSAL, dict(axis1=X, axis2=Y), "", 1, 0, TORQUE, (0.05, 0, 0), 0.05 / IXX,
                 -0.3, 0.2, id="universal-angle1"),
    pytest.param(UNIVERSAL, dict(axis1=X, axis2=Y), "", 2, 1, TORQUE, (0, 0.05, 0), 0.05 / IYY,
                 -0.3, 0.2, id="universal-angle2"),
    pytest.param(HINGE2, dict(axis1=Z, axis2=Y), "s3", 1, 0, TORQUE, (0, 0, 0.05), 0.05 / IZZ,
                 -0.3, 0.2, id="hinge2-angle1"),
    pytest.param(PR, dict(axis1=X, axis2=Z), "", 1, 0, FORCE, (2.0, 0, 0), 2.0 / BLOCK_MASS,
                 -0.05, 0.1, id="pr-position"),
    pytest.param(PR, dict(axis1=X, axis2=Z), "", 2, 1, TORQUE, (0, 0, 0.05), 0.05 / IZZ, -0.3,
                 0.2, id="pr-angle"),
    pytest.param(PU, dict(axis1=X, axis2=Y, axis3=Z), "", 1, 1, TORQUE, (0.05, 0, 0),
                 0.05 / IXX, -0.3, 0.2, id="pu-angle1"),
    pytest.param(PU, dict(axis1=X, axis2=Y, axis3=Z), "", 2, 2, TORQUE, (0, 0.05, 0),
                 0.05 / IYY, -0.3, 0.2, id="pu-angle2"),
    pytest.param(PU, dict(axis1=X, axis2=Y, axis3=Z), "", 3, 0, FORCE, (0, 0, 2.0),
                 2.0 / BLOCK_MASS, -0.05, 0.1, id="pu-position"),
]


@pytest.mark.parametrize("joint_type,axes,body2,parameter_axis,k,kind,push,free,lo,hi", STOPS)
def test_stops_hold_the_joint_at_its_signed_limits(core, joint_type, axes, body2,
                                                   parameter_axis, k, kind, push, free, lo, hi):
    block(core)
    if body2:
        sphere(core, body2, M3)
    core.add_joint(JointSpec(joint_type, "block", body2, anchor=(0, 0, 0), id="j", **axes))
    core.set_joint_parameters("j", [(LO_STOP, parameter_axis, lo), (HI_STOP, parameter_axis, hi)])
    pushing = core.add_body_force("block", kind, push)
    # between the stops the joint moves freely: the closed form, short of hi
    core.step(H, N)
    state = joint_state(core, "j")
    assert 0 < travel_after(free) < hi
    assert state.rates[k] == pytest.approx(rate_after(free), rel=RATE_TOL)
    assert state.positions[k] == pytest.approx(travel_after(free), rel=ANGLE_TOL)
    # pushed on into hi: it stops there and stays
    core.step(H, 2000)
    state = joint_state(core, "j")
    assert state.positions[k] == pytest.approx(hi, abs=STOP_TOL)
    assert state.rates[k] == pytest.approx(0.0, abs=1e-9)
    # pushed back the other way: it crosses to lo and stays there
    core.remove_body_force(pushing)
    core.add_body_force("block", kind, -np.asarray(push, dtype=float))
    core.step(H, 3000)
    state = joint_state(core, "j")
    assert state.positions[k] == pytest.approx(lo, abs=STOP_TOL)
    assert state.rates[k] == pytest.approx(0.0, abs=1e-9)


# ------------------------------------------------------------------ fixed joints

FIXED_TOL = STOP_TOL   # m, rad, m/s, rad/s: the same give of a joint row under load


def test_fixed_joint_keeps_two_bodies_0_3_m_apart_under_forces(core):
    sphere(core, "s1", M1)
    sphere(core, "s3", M3, position=(0.3, 0, 0))
    turned = quaternion((0, 0, 1), 0.4)
    core.set_poses([("s3", (0.3, 0, 0), turned)])
    core.add_joint(JointSpec(FIXED, "s1", "s3", id="fixed"))
    # pulling them apart along the line of centres and twisting them about x and z, with no
    # net force or torque on the pair: joined, they stay put; unjoined, each would move.
    # (Pulling, not pressing: world-fixed forces pressing a pair together would tip it over at
    # the least rotation, while pulling keeps it aligned.)
    core.add_body_force("s1", FORCE, (-2.0, 0, 0))
    core.add_body_force("s3", FORCE, (2.0, 0, 0))
    core.add_body_force("s1", TORQUE, (0.01, 0, 0.02))
    core.add_body_force("s3", TORQUE, (-0.01, 0, -0.02))
    core.step(H, 1000)
    p1, q1, v1, w1 = core.body_state("s1")
    p3, q3, v3, w3 = core.body_state("s3")
    assert np.linalg.norm(p3 - p1) == pytest.approx(0.3, abs=FIXED_TOL)
    np.testing.assert_allclose(p1, (0, 0, 0), atol=FIXED_TOL)
    np.testing.assert_allclose(p3, (0.3, 0, 0), atol=FIXED_TOL)
    np.testing.assert_allclose(q1, (1, 0, 0, 0), atol=FIXED_TOL)
    np.testing.assert_allclose(q3, turned, atol=FIXED_TOL)
    for velocity in (v1, w1, v3, w3):
        np.testing.assert_allclose(velocity, 0.0, atol=FIXED_TOL)


def test_fixed_joint_moves_the_pair_as_one_body(core):
    sphere(core, "s1", M1)
    sphere(core, "s3", M3, position=(0.3, 0, 0))
    core.add_joint(JointSpec(FIXED, "s1", "s3", id="fixed"))
    # along the line of centres: no torque about the pair's centre of mass, a = F / (m1 + m3)
    core.add_body_force("s1", FORCE, (-2.0, 0, 0))
    core.step(H, N)
    a = np.array([-2.0 / (M1 + M3), 0, 0])
    p1, q1, v1, w1 = core.body_state("s1")
    p3, q3, v3, w3 = core.body_state("s3")
    np.testing.assert_allclose(v1, rate_after(a), rtol=RATE_TOL, atol=1e-15)
    np.testing.assert_allclose(v3, rate_after(a), rtol=RATE_TOL, atol=1e-15)
    # positions: within the joint's give (s1 pulls s3 with 1.5 N: 7.5e-8 m)
    np.testing.assert_allclose(p1, travel_after(a), atol=FIXED_TOL)
    np.testing.assert_allclose(p3, (0.3, 0, 0) + travel_after(a), atol=FIXED_TOL)
    np.testing.assert_allclose(np.concatenate([w1, w3]), 0.0, atol=FIXED_TOL)


def test_fixed_joint_to_the_world_holds_the_body(core):
    block(core, position=(0.5, -0.2, 0.3))
    core.add_joint(JointSpec(FIXED, "", "block", id="fixed"))
    core.add_body_force("block", FORCE, (1.0, -2.0, 3.0))
    core.add_body_force("block", TORQUE, (0.02, 0.03, -0.01))
    core.step(H, 1000)
    position, q, v, w = core.body_state("block")
    np.testing.assert_allclose(position, (0.5, -0.2, 0.3), atol=FIXED_TOL)
    np.testing.assert_allclose(q, (1, 0, 0, 0), atol=FIXED_TOL)
    np.testing.assert_allclose(np.concatenate([v, w]), 0.0, atol=FIXED_TOL)


# ------------------------------------------------------------------ plane 2D

def test_plane_2d_keeps_the_body_in_z_0_while_pushed_out_of_it(core):
    block(core)
    core.add_joint(JointSpec(PLANE2D, "block", "", id="plane"))
    force, torque = np.array([1.0, -2.0, 5.0]), np.array([0.03, -0.02, 0.01])
    core.add_body_force("block", FORCE, force)
    core.add_body_force("block", TORQUE, torque)
    core.step(H, N)
    position, q, v, w = core.body_state("block")
    # out of the plane: held (free, z would reach 5 N / 2 kg * 0.02 s^2 = 0.05 m and it would
    # tip over x and y). Held within STOP_TOL: z gives 5 N h CFM / ERP = 2.5e-7 m; the rows
    # against turning over x, y have no drift correction in ODE, and let w creep at CFM tau
    # = 3e-7 rad/s, 6e-8 rad in 0.2 s
    assert position[2] == pytest.approx(0.0, abs=STOP_TOL)
    assert v[2] == pytest.approx(0.0, abs=STOP_TOL)
    np.testing.assert_allclose(w[:2], 0.0, atol=STOP_TOL)
    np.testing.assert_allclose(q[1:3], 0.0, atol=STOP_TOL)
    # in the plane: free, x and y under F / m and the turn about z under tau_z / Izz
    accel = force[:2] / BLOCK_MASS
    np.testing.assert_allclose(position[:2], travel_after(accel), rtol=RATE_TOL)
    np.testing.assert_allclose(v[:2], rate_after(accel), rtol=RATE_TOL)
    assert w[2] == pytest.approx(rate_after(torque[2] / IZZ), rel=RATE_TOL)
    np.testing.assert_allclose(q, quaternion(Z, travel_after(torque[2] / IZZ)), rtol=ANGLE_TOL,
                               atol=STOP_TOL)
    assert joint_state(core, "plane").positions == ()


# ------------------------------------------------------------------ angles and positions

def turn(*rotations):
    """The quaternion of rotations (axis, angle) applied one after the other (world axes)."""
    q = np.array([1.0, 0, 0, 0])
    for axis, angle in rotations:
        q = quaternion_multiply(quaternion(axis, angle), q)
    return q


# Each case: joint type, axes, the pose set on body1 (position, orientation; body2 and the
# world stay put) and what joint_states must then report, signs included. Where the sliding
# axis is fixed in body1 (PR, PU), the displacement is along the turned axis.
_PR_TURN = turn((Z, -0.6))
_PU_TURN = turn((X, 0.3), (Y, -0.2))
GEOMETRY = [
    pytest.param(HINGE, dict(axis1=Y), ((0, 0, 0), turn((Y, -0.4))), (-0.4,), id="hinge"),
    pytest.param(HINGE, dict(axis1=MINUS_Y), ((0, 0, 0), turn((Y, -0.4))), (0.4,),
                 id="hinge-about-minus-y"),
    pytest.param(SLIDER, dict(axis1=SLANT), (-0.12 * np.array(SLANT), turn()), (-0.12,),
                 id="slider"),
    pytest.param(PISTON, dict(axis1=X), ((0.07, 0, 0), turn((X, -0.5))), (0.07, -0.5),
                 id="piston"),
    pytest.param(UNIVERSAL, dict(axis1=X, axis2=Y), ((0, 0, 0), turn((X, 0.3), (Y, -0.2))),
                 (0.3, -0.2), id="universal"),
    pytest.param(PR, dict(axis1=X, axis2=Z), (-0.1 * rotate(_PR_TURN, X), _PR_TURN),
                 (-0.1, -0.6), id="pr"),
    pytest.param(PU, dict(axis1=X, axis2=Y, axis3=Z), (0.08 * rotate(_PU_TURN, Z), _PU_TURN),
                 (0.08, 0.3, -0.2), id="pu"),
]


@pytest.mark.parametrize("joint_type,axes,pose,expected", GEOMETRY)
def test_joint_states_report_the_imposed_geometry_with_signs(core, joint_type, axes, pose,
                                                             expected):
    block(core)
    core.add_joint(JointSpec(joint_type, "block", "", anchor=(0, 0, 0), id="j", **axes))
    assert joint_state(core, "j").positions == pytest.approx((0.0,) * len(expected), abs=1e-12)
    core.set_poses([("block", *pose)])
    assert joint_state(core, "j").positions == pytest.approx(expected, abs=1e-12)


def test_hinge2_states_report_steering_of_body1_and_spin_of_body2(core):
    block(core)
    sphere(core, "s3", M3)
    core.add_joint(JointSpec(HINGE2, "block", "s3", anchor=(0, 0, 0), axis1=Z, axis2=Y, id="j"))
    # body1 steered by 0.25 about axis1: angle1 = +0.25 (body1 relative to body2)
    core.set_poses([("block", (0, 0, 0), turn((Z, 0.25)))])
    assert joint_state(core, "j").positions == pytest.approx((0.25, 0.0), abs=1e-12)
    # body2 instead steered by 0.25: angle1 = -0.25
    core.set_poses([("block", (0, 0, 0), turn()), ("s3", (0, 0, 0), turn((Z, 0.25)))])
    assert joint_state(core, "j").positions == pytest.approx((-0.25, 0.0), abs=1e-12)
    # body2 spun by -0.7 about axis2: ODE's angle2 follows body2's own turn, -0.7 (its rate,
    # axis2 . (w1 - w2), has the opposite sign: the module docstring)
    core.set_poses([("s3", (0, 0, 0), turn((Y, -0.7)))])
    assert joint_state(core, "j").positions == pytest.approx((0.0, -0.7), abs=1e-12)


@pytest.mark.forked   # ODE ends the process (dDebug, abort) when a hinge-2 gets one body
@pytest.mark.parametrize("bodies", [("s1", ""), ("", "s1")], ids=["body-first", "world-first"])
def test_a_hinge2_joint_to_the_world_is_refused_not_a_crash(core, bodies):
    sphere(core, "s1", M1)
    with pytest.raises((Unsupported, InvalidArgument)):
        core.add_joint(JointSpec(HINGE2, *bodies, axis1=Z, axis2=Y, id="j"))
    assert core.joint_ids() == []
