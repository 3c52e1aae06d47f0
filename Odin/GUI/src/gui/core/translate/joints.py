"""A link's joint and the motors on it: a hinge or a slider where the robot is built, a motor
that drives it, and motors that give it its friction and damping (ROS-free).

Anchors and axes are world frame, joint values rad (hinge) or m (slider), forces N m or N.
"""
from __future__ import annotations

import math
from typing import List, NamedTuple, Optional, Tuple

import numpy as np

from gui.core.model import REVOLUTE, Ignored, LinkModel
from gui.core.plan import MotorStep
from odin_common.interface import JointParameter, JointType, MotorKind
from odin_common.specs import JointSpec, MotorSpec


def floats(a) -> tuple:
    """The values of array ``a`` as a flat tuple of floats (what a spec's fields take)."""
    return tuple(float(v) for v in np.asarray(a, dtype=float).ravel())


HALF_TURN = math.pi + 1e-9
"""rad: a revolute joint's stops are set when both lie within this of where it is built
(link_joint); +-180 degrees read from a file is within it."""


def fixed_joint(body1: str, body2: str) -> JointSpec:
    """A FIXED joint between two bodies (planned IDs; "" for the static world)."""
    return JointSpec(type=JointType.FIXED, body1=body1, body2=body2)


def link_joint(link: LinkModel, frame: np.ndarray, value: float, parent_id: str,
               child_id: str) -> JointSpec:
    """The hinge (revolute) or slider (prismatic) of a movable ``link`` whose joint frame is
    ``frame`` ((4, 4), world) with the joint at ``value`` (rad or m): the parent body1, the
    child body2, stops from the link's limits relative to ``value``: none for a revolute joint
    whose range passes +-pi from there (ODE reads a hinge's angle in [-pi, pi]; a stop inside
    that range would be met again a turn later, where the joint is free to go, and one
    outside it is not honoured: the servos keep such a joint to its path, odin_step.h)."""
    # ODE measures a hinge's angle (a slider's position) as body1's motion relative to
    # body2; the parent is body1, so the axis is reversed: the world's joint value, its
    # stops and its motor's goal speed then all have the sign of Kautham's joint value.
    axis = -(frame[:3, :3] @ link.axis)
    params = ()
    if link.limits is not None:
        low, high = float(link.limits[0] - value), float(link.limits[1] - value)
        if link.joint != REVOLUTE or (low >= -HALF_TURN and high <= HALF_TURN):
            params = ((JointParameter.LO_STOP, 1, low), (JointParameter.HI_STOP, 1, high))
    return JointSpec(type=JointType.HINGE if link.joint == REVOLUTE else JointType.SLIDER,
                     body1=parent_id, body2=child_id, anchor=floats(frame[:3, 3]),
                     axis1=floats(axis), parameters=params)


def motor_kind(link: LinkModel) -> MotorKind:
    """ANGULAR for a revolute joint, LINEAR for a prismatic one."""
    return MotorKind.ANGULAR if link.joint == REVOLUTE else MotorKind.LINEAR


class Drive(NamedTuple):
    """How a movable joint is driven and resisted: ``effort`` (N m or N) and ``speed`` (rad/s
    or m/s) limits, None where none; ``friction`` (N m or N) and ``damping`` (N m s/rad or
    N s/m), 0 for none."""
    effort: Optional[float]
    speed: Optional[float]
    friction: float
    damping: float


def link_drive(link: LinkModel, kautham_physics: bool) -> Tuple[Drive, Optional[Ignored]]:
    """The drive the link's URDF gives its joint (limits and ``<dynamics>``), and what of it
    is set aside: under Kautham's own physics (``kautham_physics``: one of its ODE planners)
    no ``<dynamics>``, as its ODE environment never reads it."""
    friction, damping = link.friction, link.damping
    ignored = None
    if kautham_physics and (friction > 0 or damping > 0):
        ignored = Ignored(link.source, link.line, f'<dynamics> of joint "{link.name}"',
                          "Kautham's ODE environment applies no joint friction or damping")
        friction = damping = 0.0
    return Drive(link.effort, link.velocity, friction, damping), ignored


def joint_motors(key: str, owner: str, joint: JointSpec, drive: Drive,
                 kind: MotorKind) -> List[MotorStep]:
    """The steps of the joint's driving motor (zero speed, so the robot holds its pose;
    ``drive.effort`` as its force limit, infinite without one), and of the motors that give it
    its friction and damping (``MotorStep.purpose``), on the JointStep ``key`` of ``owner``."""
    axes = 2 if joint.type == JointType.HINGE2 else 1
    forces = (drive.effort,) * axes if drive.effort else ()
    out = [MotorStep(key, owner, MotorSpec(joint=joint.default_id, kind=kind,
                                           max_forces=forces))]
    if drive.friction > 0:
        out.append(MotorStep(key, owner, MotorSpec(
            joint=joint.default_id, kind=kind, max_forces=(drive.friction,) * axes,
            id=f"friction:{joint.default_id}"), purpose="friction"))
    if drive.damping > 0:
        # a motor at zero speed whose constraint has CFM c gives a force -(rate) / c
        # (ODE solves J v = goal - CFM lambda): viscous damping of 1 / c
        out.append(MotorStep(key, owner, MotorSpec(
            joint=joint.default_id, kind=kind, id=f"damping:{joint.default_id}"),
            purpose="damping", parameters=tuple(
                (JointParameter.CFM, axis, 1.0 / drive.damping)
                for axis in range(1, axes + 1))))
    return out
