"""Motors (thesis 5.3.1): angular (dAMotor) and linear (dLMotor) motors on a joint or between
two bodies, and their goal speeds, which the C step loop sets before every step.

A motor starts with zero goal speed and infinite maximum force unless told otherwise, so a
robot held by its motors keeps its pose. Goal speeds: rad/s (angular) or m/s (linear).
"""
from __future__ import annotations

import math
from typing import List, Mapping, Sequence, Set

import numpy as np

from odin_common import limits
from odin_common.defaults import SERVO_GAIN, SERVO_MAX_SPEED
from odin_common.interface import JOINT_AXIS2_ON_BODY2, AxisFrame, JointParameter, MotorKind
from odin_common.limits import shown
from odin_common.specs import MotorSpec
from virtual_world.core import kinematic, validation as check
from virtual_world.core.records import MotorRecord, Servo, ServoState
from virtual_world.core.scene import Scene
from virtual_world.errors import DuplicateName, InvalidArgument, Unsupported
from virtual_world.ode import handles
from virtual_world.ode import joints as ode_joints


def create_motor(scene: Scene, spec: MotorSpec) -> str:
    """Creates the motor of ``spec`` (see MotorSpec); returns its id."""
    kind = spec.kind
    if isinstance(kind, bool) or kind not in set(MotorKind):
        raise InvalidArgument(f"motor kind {shown(kind)} is not ANGULAR (0) or LINEAR (1)")
    kind = MotorKind(kind)
    motor_id, joint_id, body1, body2 = (check.text(what, value) for what, value in (
        ("motor_id", spec.id), ("joint", spec.joint), ("body1", spec.body1),
        ("body2", spec.body2)))
    axes_values = check.flat_vector("axes", spec.axes) if len(spec.axes) else np.zeros(0)
    joint = None
    ode_frames = None   # frames in ODE's terms, when the joint decides them
    on_joint_axes = False
    if joint_id:
        joint = scene.joint(joint_id)
        if (body1 or body2) and (body1, body2) != joint.bodies:
            raise InvalidArgument(f"bodies {shown(body1)}, {shown(body2)} differ from joint "
                                  f"{shown(joint_id)}'s {joint.bodies}")
        body1, body2 = joint.bodies
        if axes_values.size == 0:
            found = ode_joints.joint_axes(joint.owner.ptr, joint.type, kind)
            if not found:
                raise Unsupported(f"joint {shown(joint_id)} ({joint.type.label}) has no "
                                  f"{kind.name.lower()} axis; give axes")
            axes_values = np.concatenate(found)
            on_joint_axes = True
            if len(found) == 2 and joint.type in JOINT_AXIS2_ON_BODY2 and \
                    not len(spec.axis_frames):
                # axis 1 turns with ODE's body 1, axis 2 with body 2 (or the world): as the
                # joint holds them, so the goals stay the joint's rates
                ode_frames = [1, 2 if body1 and body2 else 0]
    if not body1 and not body2:
        raise InvalidArgument("a motor needs a joint or at least one body")
    if body1 == body2:
        raise InvalidArgument(f"a motor cannot join {shown(body1)} to itself")
    objects = [scene.body_object(b, "motor") if b else None for b in (body1, body2)]
    if axes_values.size % 3 or not 3 <= axes_values.size <= 9:
        raise InvalidArgument(f"axes {shown(list(spec.axes))}: need 1..3 axes of 3 numbers each")
    naxes = axes_values.size // 3
    unit_axes = [check.axis(f"motor axis {i + 1}", axes_values[3 * i:3 * i + 3])
                 for i in range(naxes)]
    frames = _axis_frames(spec.axis_frames, naxes, objects)
    max_forces = [check.number("max force", f, allow_inf=True) for f in spec.max_forces] \
        if len(spec.max_forces) else [-1.0] * naxes
    for force in max_forces:
        if math.isfinite(force):
            check.at_most("max force", force, limits.MAX_FORCE, "N or N m (negative: infinite)")
    if len(max_forces) != naxes:
        raise InvalidArgument(f"max_forces {shown(list(spec.max_forces))}: need one per axis "
                              f"({naxes})")
    motor_id = check.name("motor id", motor_id, allow_marker=True) if motor_id else \
        spec.default_id
    if motor_id in scene.motors or motor_id in scene.joints:
        raise DuplicateName(f"motor id {shown(motor_id)} is already taken")
    # ---- ODE
    owner = handles.new_motor(scene.c.world, kind, [o.body for o in objects if o is not None])
    if ode_frames is not None:
        frames = ode_frames
    elif objects[0] is None:  # the body is ODE's body 1 (handles._attached): swap body frames
        frames = [{AxisFrame.GLOBAL: 0, AxisFrame.FIRST_BODY: 2,
                   AxisFrame.SECOND_BODY: 1}[f] for f in frames]
    ode_joints.configure_motor(owner.ptr, kind, unit_axes, frames, max_forces)
    motor = MotorRecord(motor_id, owner, kind, naxes, joint_id or None, (body1, body2),
                        on_joint_axes)
    scene.motors[motor_id] = motor
    if joint is not None:
        joint.motors.add(motor_id)
    for o in objects:
        if o is not None:
            o.motors.add(motor_id)
    rebuild_goals(scene)
    return motor_id


def _axis_frames(given: Sequence[int], naxes: int, objects) -> List[AxisFrame]:
    """Per axis: the frame it stays fixed in (default: the first body, or the second when the
    first is the world)."""
    default = AxisFrame.FIRST_BODY if objects[0] is not None else AxisFrame.SECOND_BODY
    frames = list(given) if len(given) else [default] * naxes
    if len(frames) != naxes:
        raise InvalidArgument(f"axis_frames {shown(list(given))}: need one per axis ({naxes})")
    for frame in frames:
        if isinstance(frame, bool) or frame not in set(AxisFrame):
            raise InvalidArgument(f"axis frame {shown(frame)} is not 0 (world), 1 or 2")
        if frame and objects[frame - 1] is None:
            raise InvalidArgument(f"axis frame {frame} names the world ('' body)")
    return [AxisFrame(f) for f in frames]


def remove_motor(scene: Scene, motor_id: str) -> None:
    motor = scene.motor(motor_id)
    del scene.motors[motor_id]
    if motor.joint and motor.joint in scene.joints:
        scene.joints[motor.joint].motors.discard(motor_id)
    for body in motor.bodies:
        if body:
            scene.objects[body].motors.discard(motor_id)
    rebuild_goals(scene)  # before the handle goes: C must never see a freed motor
    motor.owner.close()


def axis_counts(scene: Scene, motor_ids: Sequence[str]) -> List[int]:
    """Number of axes of each motor (how many goal speeds it takes); unknown ids raise."""
    return [scene.motor(motor_id).naxes for motor_id in motor_ids]


def set_velocities(scene: Scene, velocities: Mapping[str, Sequence[float]]) -> None:
    """Goal speeds (rad/s or m/s) per motor axis; all checked before any is set. A servo
    given a speed leaves servo mode (the speed is what was asked for)."""
    checked = []
    for motor_id, values in dict(velocities).items():
        motor = scene.motor(motor_id)
        vector = check.flat_vector(f"velocities of {shown(motor_id)}", values) \
            if hasattr(values, "__len__") else None
        if vector is None or vector.size != motor.naxes:
            raise InvalidArgument(f"motor {shown(motor_id)} has {motor.naxes} axes; got "
                                  f"{shown(values)}")
        check.at_most(f"goal speed of {shown(motor_id)}", float(np.max(np.abs(vector))),
                      limits.MAX_MOTOR_SPEED, "rad/s or m/s")
        checked.append((motor, vector.tolist()))
    for motor, values in checked:
        motor.velocity = values
        slot = scene.motor_slots[motor.id]
        if motor.servo is not None:     # a goal speed given: the motor leaves servo mode
            motor.servo = None
            scene.c.update_servo(slot, None)
        scene.c.update_motor_goal(slot, values)


def split_per_axis(scene: Scene, motor_ids: Sequence[str], values: Sequence[float],
                   what: str = "velocities") -> dict:
    """{motor id: its values} from one flat list, each motor taking as many values as it has
    axes, in order (Set Velocity's velocities, Set Servo's lists)."""
    counts = axis_counts(scene, motor_ids)
    if sum(counts) != len(values):
        raise InvalidArgument(f"{len(values)} {what} for motors with {sum(counts)} axes in all")
    split, cursor = {}, 0
    for motor_id, count in zip(motor_ids, counts):
        split[motor_id] = tuple(values[cursor:cursor + count])
        cursor += count
    return split


def set_parameters(scene: Scene, motor: MotorRecord, checked: list) -> None:
    """Checked (JointParameter, axis, value) triples on a motor; VELOCITY is its goal."""
    for parameter, axis, value in checked:
        ode_joints.set_motor_parameter(motor.owner.ptr, motor.kind, parameter, axis, value)
        if parameter == JointParameter.VELOCITY:
            motor.velocity[axis - 1] = value
    scene.c.update_motor_goal(scene.motor_slots[motor.id], motor.velocity)


def rebuild_goals(scene: Scene) -> None:
    """Hands C the goal array of every motor, in creation order, servos included."""
    motors = list(scene.motors.values())
    scene.motor_slots = {m.id: i for i, m in enumerate(motors)}
    scene.c.set_motor_goals([(m.owner.ptr, m.kind, m.velocity) for m in motors])
    for slot, motor in enumerate(motors):
        if motor.servo is not None:
            scene.c.update_servo(slot, _servo_arguments(scene, motor))
    kinematic.refresh(scene)    # the links' motors have new slots; a gone motor's link drops


def _servo_arguments(scene: Scene, motor: MotorRecord) -> tuple:
    joint = scene.joints[motor.joint]
    components = ode_joints.SERVO_COMPONENTS[motor.kind][joint.type]
    signs = [ode_joints.SERVO_SIGNS.get((joint.type, c), 1.0) for c in components]
    servo = motor.servo
    return (joint.owner.ptr, ode_joints.ODE_JOINT_TYPE[joint.type], components, signs,
            servo.targets, servo.rates, servo.gains, servo.max_speeds)


def set_servos(scene: Scene, servos: Mapping[str, Mapping]) -> None:
    """Servo mode for each motor: {motor id: {"targets": per axis (rad or m, the joint's
    reported units), optional "rates" (feed-forward, rad/s or m/s; 0), "gains" (1/s;
    defaults.SERVO_GAIN), "max_speeds" (rad/s or m/s; defaults.SERVO_MAX_SPEED),
    "max_forces" (N m or N; the motor's as it is)}}, as core.actuation.split_servo_lists
    gives them. Before every step the motor's speed on each axis becomes clamp(rate + gain
    (target - q), +-max_speed) with q the joint's value. A servo drives a motor made on a joint
    with the joint's own axes. All checked first."""
    checked = []
    for motor_id, fields in dict(servos).items():
        motor = scene.motor(motor_id)
        if not motor.on_joint_axes or motor.joint not in scene.joints or \
                scene.joints[motor.joint].type not in ode_joints.SERVO_COMPONENTS[motor.kind]:
            raise Unsupported(f"motor {shown(motor_id)} is no servo: a servo drives a motor made "
                              "on a joint with the joint's own axes")
        fields = dict(fields)

        def per_axis(name, default, low, high, unit):
            given = fields.get(name)
            if given is None or len(given) == 0:
                return (default,) * motor.naxes
            if type(given) is tuple and len(given) == motor.naxes and \
                    all(type(v) is float and low <= v <= high for v in given):
                return given    # a planner's, each control: the checks below, without numpy
            values = check.flat_vector(f"{name} of servo {shown(motor_id)}", given)
            if values.size != motor.naxes:
                raise InvalidArgument(f"servo {shown(motor_id)} has {motor.naxes} axes; got "
                                      f"{values.size} {name}")
            for v in values:
                if not low <= v <= high:
                    raise InvalidArgument(f"{name} of servo {shown(motor_id)}: {shown(v)} {unit} "
                                          f"is outside [{low:g}, {high:g}] {unit}")
            return tuple(values.tolist())
        extent = scene.parameters.world_extent
        servo = Servo(per_axis("targets", 0.0, -extent, extent, "rad or m"),
                      per_axis("rates", 0.0, -limits.MAX_MOTOR_SPEED, limits.MAX_MOTOR_SPEED,
                               "rad/s or m/s"),
                      per_axis("gains", SERVO_GAIN, 0.0, 1e6, "1/s"),
                      per_axis("max_speeds", SERVO_MAX_SPEED, 0.0, limits.MAX_MOTOR_SPEED,
                               "rad/s or m/s"))
        forces = fields.get("max_forces")
        max_forces = None if forces is None or len(forces) == 0 else \
            per_axis("max_forces", 0.0, 0.0, limits.MAX_FORCE, "N m or N")
        checked.append((motor, servo, max_forces))
    for motor, servo, max_forces in checked:
        motor.servo = servo
        for axis, force in enumerate(max_forces or (), start=1):
            ode_joints.set_motor_parameter(motor.owner.ptr, motor.kind,
                                           JointParameter.MAX_FORCE, axis, force)
        scene.c.update_servo(scene.motor_slots[motor.id], _servo_arguments(scene, motor))


def retarget_servos(scene: Scene, moved: Set[str]) -> None:
    """Each servo whose joint joins one of the ``moved`` objects targets the joint's present
    values (rates kept): a robot put somewhere by Set Position holds where it was put, not
    where its servos held it before."""
    for motor in scene.motors.values():
        if motor.servo is None or not moved.intersection(motor.bodies):
            continue
        joint = scene.joints[motor.joint]
        positions, _ = ode_joints.joint_state(joint.owner.ptr, joint.type)
        components = ode_joints.SERVO_COMPONENTS[motor.kind][joint.type]
        motor.servo = motor.servo._replace(
            targets=tuple(float(positions[c]) for c in components))
        scene.c.update_servo(scene.motor_slots[motor.id], _servo_arguments(scene, motor))


def release_servos(scene: Scene, motor_ids: Sequence[str]) -> None:
    """Back to speed goals, each at zero (the motor holds where it is)."""
    released = [scene.motor(motor_id) for motor_id in motor_ids]
    for motor in released:
        motor.servo = None
        motor.velocity = [0.0] * motor.naxes
        slot = scene.motor_slots[motor.id]
        scene.c.update_servo(slot, None)
        scene.c.update_motor_goal(slot, motor.velocity)


def servo_states(scene: Scene) -> List[ServoState]:
    """Every servo's targets, the joint's values when the last step began, and the errors."""
    out = []
    for motor in scene.motors.values():
        if motor.servo is None:
            continue
        _, _, components, signs, *_ = _servo_arguments(scene, motor)
        positions = scene.c.servo_positions(scene.motor_slots[motor.id], signs)
        out.append(ServoState(motor.id, motor.servo.targets, positions,
                              tuple(t - q for t, q in zip(motor.servo.targets, positions))))
    return out
