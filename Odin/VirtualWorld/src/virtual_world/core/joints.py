"""Joints (thesis 4.2.2, 5.3): created between two bodies or a body and the static world,
their parameters, their removal and their state.

One joint per pair of bodies. A body joined to the world is ODE's body 1, so angles, rates,
joint forces and motors describe that body's motion about (along) the axes as given. ODE's sign
convention: a positive joint force acts on body1 along +axis, the reaction on body2.
"""
from __future__ import annotations

from typing import List, Sequence, Tuple

from odin_common import limits
from odin_common.interface import (JOINT_AXES_USED, JOINT_NEEDS_TWO_BODIES,
                                   JOINT_PARAMETER_AXES, JOINT_PARAMETERS,
                                   MOTOR_PARAMETERS, NON_NEGATIVE_PARAMETERS, UNIT_PARAMETERS,
                                   JointParameter, JointType, joint_type)
from odin_common.limits import shown
from odin_common.specs import JointSpec
from virtual_world.core import forces, motors, validation as check
from virtual_world.core.records import JointRecord, JointState, Removed
from virtual_world.core.scene import Scene
from virtual_world.errors import DuplicateName, InvalidArgument, Unsupported
from virtual_world.ode import handles
from virtual_world.ode import joints as ode_joints

#: the joint types whose first two axes must not be parallel
_TWO_AXES = frozenset({JointType.UNIVERSAL, JointType.HINGE2, JointType.PU, JointType.PR})


def create_joint(scene: Scene, spec: JointSpec) -> str:
    """Creates the joint of ``spec`` and sets its parameters, all or nothing; returns its id
    (default "<type>:<body1>&<body2>")."""
    kind = check.shared(joint_type, spec.type)
    body1 = check.text("body1", spec.body1)
    body2 = check.text("body2", spec.body2)
    if not body1 and not body2:
        raise InvalidArgument("a joint needs at least one body (both are '')")
    if body1 == body2:
        raise InvalidArgument(f"a joint cannot join {shown(body1)} to itself")
    objects = [scene.body_object(b, "joint") if b else None for b in (body1, body2)]
    if kind in JOINT_NEEDS_TWO_BODIES and not (body1 and body2):
        raise Unsupported(f"a {kind.label} joint needs two bodies (ODE cannot attach it to "
                          "the static world)")
    if kind == JointType.PLANE2D and (not body1 or body2):
        raise Unsupported("a plane-2D joint takes body1 only (body2 must be '')")
    pair = frozenset((body1, body2))
    if pair in scene.pairs:
        raise DuplicateName(
            f"bodies {shown(body1)} and {shown(body2)} are already joined by "
            f"{shown(scene.pairs[pair])}")
    joint_id = check.text("joint id", spec.id)
    joint_id = check.name("joint id", joint_id, allow_marker=True) if joint_id else \
        spec.default_id
    if joint_id in scene.joints or joint_id in scene.motors:
        raise DuplicateName(f"joint id {shown(joint_id)} is already taken")
    anchor = check.within_extent("anchor", check.vector("anchor", spec.anchor),
                                 scene.parameters.world_extent)
    # only the axes the type uses are checked: a request leaves the others at zero
    uses = JOINT_AXES_USED[kind]
    axes = [check.axis(name, value) if name in uses else None
            for name, value in (("axis1", spec.axis1), ("axis2", spec.axis2),
                                ("axis3", spec.axis3))]
    if kind in _TWO_AXES and abs(float(axes[0] @ axes[1])) > 1 - 1e-6:
        raise InvalidArgument(f"axis1 {tuple(spec.axis1)} and axis2 {tuple(spec.axis2)} are "
                              "parallel")
    parameters = _checked_parameters(kind, joint_id, spec.parameters) if spec.parameters else []
    # ---- ODE
    owner = handles.new_joint(scene.c.world, kind, [o.body for o in objects if o is not None])
    ode_joints.configure_joint(owner.ptr, kind, anchor.tolist(),
                               *[a.tolist() if a is not None else None for a in axes])
    for parameter, axis, value in parameters:
        ode_joints.set_joint_parameter(owner.ptr, kind, parameter, axis, value)
    scene.joints[joint_id] = JointRecord(joint_id, kind, owner, (body1, body2))
    scene.pairs[pair] = joint_id
    for o in objects:
        if o is not None:
            o.joints.add(joint_id)
    return joint_id


def set_joint_parameters(scene: Scene, joint_id: str,
                         parameters: Sequence[Tuple[int, int, float]]) -> None:
    """Sets (parameter, axis 1..3, value) triples on a joint or a motor, all or nothing.

    Ranges: ERP-like, BOUNCE and FUDGE_FACTOR in [0, 1]; CFM-like >= 0; stops may be +-inf;
    MAX_FORCE negative means infinite. Ball and fixed joints take CFM and ERP only;
    suspension parameters need a hinge2; plane-2D joints take none. On a motor, VELOCITY
    sets its goal speed (as Core.set_velocity does)."""
    motor = scene.motors.get(joint_id)
    if motor is not None:
        checked = _check_parameters(parameters, MOTOR_PARAMETERS, motor.naxes, "motor",
                                    joint_id)
        motors.set_parameters(scene, motor, checked)
        return
    joint = scene.joint(joint_id)
    checked = _checked_parameters(joint.type, joint_id, parameters)
    for parameter, axis, value in checked:
        ode_joints.set_joint_parameter(joint.owner.ptr, joint.type, parameter, axis, value)


def _checked_parameters(kind: JointType, joint_id: str, parameters) -> list:
    if kind not in JOINT_PARAMETERS:
        raise Unsupported(f"joint {shown(joint_id)} ({kind.label}) takes no parameters")
    return _check_parameters(parameters, JOINT_PARAMETERS[kind], JOINT_PARAMETER_AXES[kind],
                             kind.label, joint_id)


def _check_parameters(parameters, allowed, axes: int, kind: str, joint_id: str) -> list:
    """[(JointParameter, axis, value)] with values in range; MAX_FORCE < 0 (unlimited) ->
    math.inf (what ODE is given for it: ode.joints.set_joint_parameter)."""
    checked = []
    for item in parameters:
        try:
            parameter, axis, value = item
        except (TypeError, ValueError):
            raise InvalidArgument(f"{shown(item)} is not a (parameter, axis, value) triple") \
                from None
        if isinstance(parameter, bool) or parameter not in set(JointParameter):
            raise InvalidArgument(f"joint parameter {shown(parameter)} is not one of 0..11")
        parameter = JointParameter(parameter)
        label = parameter.label
        if parameter not in allowed:
            raise Unsupported(f"parameter {label} does not fit {kind} {shown(joint_id)}")
        if isinstance(axis, bool) or axis not in range(1, axes + 1):
            raise InvalidArgument(f"axis {shown(axis)} for {label} of {kind} {shown(joint_id)} "
                                  f"must be in 1..{axes}")
        value = check.number(f"{label} value", value, allow_inf=parameter in (
            JointParameter.LO_STOP, JointParameter.HI_STOP))
        if parameter in UNIT_PARAMETERS and not 0 <= value <= 1:
            raise InvalidArgument(f"{label}={shown(value)} must be in [0, 1]")
        if parameter in NON_NEGATIVE_PARAMETERS and value < 0:
            raise InvalidArgument(f"{label}={shown(value)} must be >= 0")
        if parameter == JointParameter.MAX_FORCE and value < 0:
            value = ode_joints.unlimited_force(value)
        elif parameter == JointParameter.MAX_FORCE:
            check.at_most(f"{label} of {kind} {shown(joint_id)}", value, limits.MAX_FORCE,
                          "N or N m (negative: infinite)")
        if parameter == JointParameter.VELOCITY:
            check.at_most(f"{label} of {kind} {shown(joint_id)}", abs(value),
                          limits.MAX_MOTOR_SPEED, "rad/s or m/s")
        checked.append((parameter, int(axis), value))
    return checked


def remove_joint(scene: Scene, joint_id: str) -> Removed:
    """Removes a joint with its motors and joint forces."""
    joint = scene.joint(joint_id)
    del scene.joints[joint_id]
    removed_motors = sorted(joint.motors)
    for motor_id in removed_motors:
        motors.remove_motor(scene, motor_id)
    removed_forces = sorted(joint.forces)
    if removed_forces:
        forces.drop_joint_forces(scene, removed_forces)
    del scene.pairs[frozenset(joint.bodies)]
    for body in joint.bodies:
        if body:
            scene.objects[body].joints.discard(joint_id)
    joint.owner.close()
    return Removed((joint_id,), tuple(removed_motors), tuple(removed_forces), ())


def joint_states(scene: Scene) -> List[JointState]:
    """Positions and rates of every joint, per axis (see JointState)."""
    return [JointState(joint.id, int(joint.type), *ode_joints.joint_state(joint.owner.ptr,
                                                                         joint.type))
            for joint in scene.joints.values()]
