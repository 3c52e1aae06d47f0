"""ODE's joints and motors, by type: setting anchors and axes, parameters, reading positions,
rates and axes. The per-type tables of ODE's C functions live here and nowhere else.

Conventions: world frame; a body joined to the static world is ODE's body 1 (body 2 NULL), so
angles, rates, joint forces and motors describe that body's motion about (along) the axes as
given. Arguments are already checked.
"""
from __future__ import annotations

import math
from typing import List, Sequence, Tuple

import numpy as np

from odin_common import limits
from odin_common.interface import JointParameter, JointType, MotorKind
from virtual_world.ode.bindings import ffi, lib
from virtual_world.ode.runtime import drains_ode_messages

T = JointType

ODE_JOINT_TYPE = {
    T.BALL: lib.dJointTypeBall, T.HINGE: lib.dJointTypeHinge, T.SLIDER: lib.dJointTypeSlider,
    T.PISTON: lib.dJointTypePiston, T.UNIVERSAL: lib.dJointTypeUniversal,
    T.HINGE2: lib.dJointTypeHinge2, T.PR: lib.dJointTypePR, T.PU: lib.dJointTypePU,
    T.FIXED: lib.dJointTypeFixed, T.PLANE2D: lib.dJointTypePlane2D,
}
"""Odin's joint type -> ODE's dJointType (what odin_step.c switches on)."""

_ODE_PARAMETER = {
    JointParameter.LO_STOP: lib.dParamLoStop, JointParameter.HI_STOP: lib.dParamHiStop,
    JointParameter.BOUNCE: lib.dParamBounce, JointParameter.CFM: lib.dParamCFM,
    JointParameter.ERP: lib.dParamERP, JointParameter.STOP_ERP: lib.dParamStopERP,
    JointParameter.STOP_CFM: lib.dParamStopCFM,
    JointParameter.SUSPENSION_ERP: lib.dParamSuspensionERP,
    JointParameter.SUSPENSION_CFM: lib.dParamSuspensionCFM,
    JointParameter.FUDGE_FACTOR: lib.dParamFudgeFactor, JointParameter.VELOCITY: lib.dParamVel,
    JointParameter.MAX_FORCE: lib.dParamFMax,
}

_PARAMETER_NAME = {  # per joint type and motor kind: <Name> in ODE's dJoint{Set,Get}<Name>Param
    T.BALL: "Ball", T.HINGE: "Hinge", T.SLIDER: "Slider", T.PISTON: "Piston",
    T.UNIVERSAL: "Universal", T.HINGE2: "Hinge2", T.PR: "PR", T.PU: "PU", T.FIXED: "Fixed",
}
_MOTOR_PARAMETER_NAME = {MotorKind.ANGULAR: "AMotor", MotorKind.LINEAR: "LMotor"}


def _parameter_functions(names: dict, verb: str) -> dict:
    """{kind: lib.dJoint<verb><Name>Param} for ``names`` {kind: Name}; verb "Set" or "Get"."""
    return {kind: getattr(lib, f"dJoint{verb}{name}Param") for kind, name in names.items()}


_SET_PARAMETER = _parameter_functions(_PARAMETER_NAME, "Set")
_SET_MOTOR_PARAMETER = _parameter_functions(_MOTOR_PARAMETER_NAME, "Set")
_GET_PARAMETER = _parameter_functions(_PARAMETER_NAME, "Get")
_GET_MOTOR_PARAMETER = _parameter_functions(_MOTOR_PARAMETER_NAME, "Get")

_STATE = {  # per joint type: (position getters, rate getters), one per reported axis
    T.HINGE: ((lib.dJointGetHingeAngle,), (lib.dJointGetHingeAngleRate,)),
    T.SLIDER: ((lib.dJointGetSliderPosition,), (lib.dJointGetSliderPositionRate,)),
    T.PISTON: ((lib.dJointGetPistonPosition, lib.dJointGetPistonAngle),
               (lib.dJointGetPistonPositionRate, lib.dJointGetPistonAngleRate)),
    T.UNIVERSAL: ((lib.dJointGetUniversalAngle1, lib.dJointGetUniversalAngle2),
                  (lib.dJointGetUniversalAngle1Rate, lib.dJointGetUniversalAngle2Rate)),
    T.HINGE2: ((lib.dJointGetHinge2Angle1, lib.dJointGetHinge2Angle2),
               (lib.dJointGetHinge2Angle1Rate, lib.dJointGetHinge2Angle2Rate)),
    T.PR: ((lib.dJointGetPRPosition, lib.dJointGetPRAngle),
           (lib.dJointGetPRPositionRate, lib.dJointGetPRAngleRate)),
    T.PU: ((lib.dJointGetPUPosition, lib.dJointGetPUAngle1, lib.dJointGetPUAngle2),
           (lib.dJointGetPUPositionRate, lib.dJointGetPUAngle1Rate,
            lib.dJointGetPUAngle2Rate)),
}

_PLACE = {  # per joint type: ODE's setters of its anchor and axes, each with what it takes
    T.BALL: ((lib.dJointSetBallAnchor, "anchor"),),
    T.HINGE: ((lib.dJointSetHingeAnchor, "anchor"), (lib.dJointSetHingeAxis, "axis1")),
    T.SLIDER: ((lib.dJointSetSliderAxis, "axis1"),),
    T.PISTON: ((lib.dJointSetPistonAnchor, "anchor"), (lib.dJointSetPistonAxis, "axis1")),
    T.UNIVERSAL: ((lib.dJointSetUniversalAnchor, "anchor"),
                  (lib.dJointSetUniversalAxis1, "axis1"), (lib.dJointSetUniversalAxis2, "axis2")),
    T.HINGE2: ((lib.dJointSetHinge2Anchor, "anchor"),),
    T.PR: ((lib.dJointSetPRAnchor, "anchor"), (lib.dJointSetPRAxis1, "axis1"),
           (lib.dJointSetPRAxis2, "axis2")),
    T.PU: ((lib.dJointSetPUAnchor, "anchor"), (lib.dJointSetPUAxis1, "axis1"),
           (lib.dJointSetPUAxis2, "axis2"), (lib.dJointSetPUAxis3, "axis3")),
}

_AXES = {  # the axes a motor on a joint of this type drives, by motor kind
    MotorKind.ANGULAR: {
        T.HINGE: (lib.dJointGetHingeAxis,), T.PISTON: (lib.dJointGetPistonAxis,),
        T.UNIVERSAL: (lib.dJointGetUniversalAxis1, lib.dJointGetUniversalAxis2),
        T.HINGE2: (lib.dJointGetHinge2Axis1, lib.dJointGetHinge2Axis2),
        T.PR: (lib.dJointGetPRAxis2,),
        T.PU: (lib.dJointGetPUAxis1, lib.dJointGetPUAxis2)},
    MotorKind.LINEAR: {
        T.SLIDER: (lib.dJointGetSliderAxis,), T.PISTON: (lib.dJointGetPistonAxis,),
        T.PR: (lib.dJointGetPRAxis1,), T.PU: (lib.dJointGetPUAxis3,)},
}


SERVO_COMPONENTS = {  # which JointState value each motor axis moves (the order of _AXES)
    MotorKind.ANGULAR: {T.HINGE: (0,), T.PISTON: (1,), T.UNIVERSAL: (0, 1), T.HINGE2: (0, 1),
                        T.PR: (1,), T.PU: (1, 2)},
    MotorKind.LINEAR: {T.SLIDER: (0,), T.PISTON: (0,), T.PR: (0,), T.PU: (0,)},
}
"""For a servo: per motor kind and joint type, the component of the joint's state (its
positions, interface.JOINT_STATE_AXES) that each of the motor's axes drives."""

SERVO_SIGNS = {(T.HINGE2, 1): -1.0}
"""Components whose reported value moves against the motor's speed: ODE 0.16's hinge-2 angle2
decreases while its rate (and a motor on that axis) is positive. A servo there tracks the
negated value, so that a target in reported units still pulls the right way."""


@drains_ode_messages
def configure_joint(joint, kind: JointType, anchor: Sequence[float], axis1: Sequence[float],
                    axis2: Sequence[float], axis3: Sequence[float]) -> None:
    """Sets the anchor (m, world) and the axes (unit, world) ``kind`` uses; a fixed joint
    keeps the bodies' present relative pose."""
    given = {"anchor": list(anchor), "axis1": axis1, "axis2": axis2, "axis3": axis3}
    for setter, name in _PLACE.get(kind, ()):
        setter(joint, *given[name])
    if kind == T.HINGE2:     # ODE sets a hinge-2's axes in one call, as 4-vectors
        lib.dJointSetHinge2Axes(joint, list(axis1) + [0.0], list(axis2) + [0.0])
    elif kind == T.FIXED:
        lib.dJointSetFixed(joint)


def ode_parameter(parameter: JointParameter, axis: int) -> int:
    """ODE's parameter number for ``parameter`` on axis 1..3 (dParamX, dParamX2, dParamX3)."""
    return _ODE_PARAMETER[parameter] + (axis - 1) * lib.dParamGroup


@drains_ode_messages
def set_joint_parameter(joint, kind: JointType, parameter: JointParameter, axis: int,
                        value: float) -> None:
    """Sets ``parameter`` of ``axis`` (1..3) on a joint; an unlimited MAX_FORCE as
    ``_set_parameter`` says."""
    _set_parameter(_SET_PARAMETER[kind], _GET_PARAMETER[kind], joint, parameter, axis, value)


@drains_ode_messages
def set_motor_parameter(motor, kind: MotorKind, parameter: JointParameter, axis: int,
                        value: float) -> None:
    """Sets ``parameter`` of ``axis`` (1..3) on a motor; an unlimited MAX_FORCE as
    ``_set_parameter`` says."""
    _set_parameter(_SET_MOTOR_PARAMETER[kind], _GET_MOTOR_PARAMETER[kind], motor, parameter,
                   axis, value)


_STOPS = (JointParameter.LO_STOP, JointParameter.HI_STOP)


def _set_parameter(set_, get, handle, parameter: JointParameter, axis: int,
                   value: float) -> None:
    """Sets a parameter so that ODE never holds an infinite maximum force on an axis with a
    stop: there, on a powered axis resting on the stop, ODE applies the whole maximum force
    to the bodies, and an infinite one made their velocities NaN and ended the process in its
    quaternion normalisation. An unlimited force (negative, infinite, or UNLIMITED_FORCE read
    back) is ODE's infinity on an axis without stops, as it always was (an unbounded row of
    the solver: what every scene without stops steps, bit for bit), and UNLIMITED_FORCE on an
    axis with a finite stop; a stop set later moves an unlimited force from one to the
    other."""
    max_force = ode_parameter(JointParameter.MAX_FORCE, axis)
    if parameter == JointParameter.MAX_FORCE and (value < 0 or value >= UNLIMITED_FORCE):
        value = _unlimited_for(get, handle, axis)
    set_(handle, ode_parameter(parameter, axis), value)
    if parameter in _STOPS and float(get(handle, max_force)) >= UNLIMITED_FORCE:
        set_(handle, max_force, _unlimited_for(get, handle, axis))


def _unlimited_for(get, handle, axis: int) -> float:
    """What ODE is given for an unlimited force on ``axis``: its infinity unless a stop of the
    axis is finite, else UNLIMITED_FORCE."""
    stops = [float(get(handle, ode_parameter(stop, axis))) for stop in _STOPS]
    return UNLIMITED_FORCE if any(math.isfinite(stop) for stop in stops) else INFINITY


def reactions(joint_owner) -> Tuple[Tuple[float, ...], ...]:
    """(force on body 1 (N), torque on body 1 (N m), force on body 2, torque on body 2), world
    frame: what the joint applied in the last step (ODE's joint feedback; zeros before a
    step, and for the static world's side)."""
    f = joint_owner.data
    return tuple(tuple(v[k] for k in range(3)) for v in (f.f1, f.t1, f.f2, f.t2))


def joint_parameter(joint, kind: JointType, parameter: JointParameter, axis: int) -> float:
    return float(_GET_PARAMETER[kind](joint, ode_parameter(parameter, axis)))


def motor_parameter(motor, kind: MotorKind, parameter: JointParameter, axis: int) -> float:
    return float(_GET_MOTOR_PARAMETER[kind](motor, ode_parameter(parameter, axis)))


def joint_state(joint, kind: JointType) -> Tuple[Tuple[float, ...], Tuple[float, ...]]:
    """(positions, rates) per reported axis (interface.JOINT_STATE_AXES); () for ball, fixed
    and plane-2D joints."""
    getters = _STATE.get(kind)
    if getters is None:
        return (), ()
    return (tuple(get(joint) for get in getters[0]), tuple(get(joint) for get in getters[1]))


def joint_axes(joint, kind: JointType, motor_kind: MotorKind) -> List[np.ndarray]:
    """The joint's rotational (ANGULAR) or sliding (LINEAR) axes now, world frame."""
    v = ffi.new("dVector3")
    axes = []
    for get in _AXES[motor_kind].get(kind, ()):
        get(joint, v)
        axes.append(np.array([v[0], v[1], v[2]]))
    return axes


@drains_ode_messages
def configure_motor(motor, kind: MotorKind, axes: Sequence[np.ndarray], frames: Sequence[int],
                    max_forces: Sequence[float]) -> None:
    """Sets a motor's axes (unit, world) anchored in ODE's frames (0 world, 1 ODE's body 1,
    2 body 2), each with its maximum force (negative: infinite) and a zero goal speed."""
    if kind == MotorKind.ANGULAR:
        lib.dJointSetAMotorMode(motor, lib.dAMotorUser)
        lib.dJointSetAMotorNumAxes(motor, len(axes))
        set_axis = lib.dJointSetAMotorAxis
    else:
        lib.dJointSetLMotorNumAxes(motor, len(axes))
        set_axis = lib.dJointSetLMotorAxis
    for i, (axis, frame, force) in enumerate(zip(axes, frames, max_forces)):
        set_axis(motor, i, frame, *axis.tolist())
        set_motor_parameter(motor, kind, JointParameter.MAX_FORCE, i + 1,
                            unlimited_force(force))
        set_motor_parameter(motor, kind, JointParameter.VELOCITY, i + 1, 0.0)


INFINITY = lib.dInfinity
"""ODE's infinity (an open stop)."""

UNLIMITED_FORCE = math.nextafter(limits.MAX_FORCE, math.inf)
"""N or N m: what ODE holds for an unlimited force (negative or infinite) on an axis with a
finite stop (``_set_parameter``), never its infinity there; just above the strongest force a
request may set (limits.MAX_FORCE), so that it reads back as infinite again and nothing else
does."""


def unlimited_force(force: float) -> float:
    """``force`` (N or N m) as the setters take it: math.inf when it is negative or infinite
    ("unlimited"; ``_set_parameter`` decides what ODE is given), else ``force``."""
    return math.inf if force < 0 or math.isinf(force) else force
