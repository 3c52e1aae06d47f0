"""The facts of Odin's ROS interface, written once, for every node and tool (ROS-free).

The constants of the .msg and .srv files as ``IntEnum``s (a test pins each one to the
generated message classes), what each joint type takes, the thesis's shape-by-parameter-count
rule, the composite-ID rule, tf frame and namespace rules, the body state vector's layout,
and the services each node offers with their types. Values that are choices rather than
facts of the interface (solver thresholds, servo defaults, colours) are in
``odin_common.defaults``.
"""
from __future__ import annotations

import itertools
import re
from enum import IntEnum
from typing import Any, Dict, NamedTuple, Sequence, Tuple

from odin_common.errors import InvalidArgument


class _Labelled(IntEnum):
    """An IntEnum whose members have a ``label`` for messages."""

    @property
    def label(self) -> str:
        """Lower-case name for messages ("hinge2", "plane2d")."""
        return self.name.lower()


class JointType(_Labelled):
    """Messages/Joint: the joint types of Set Joint, JointData and joint IDs."""
    BALL = 0
    HINGE = 1
    SLIDER = 2
    PISTON = 3
    UNIVERSAL = 4
    HINGE2 = 5
    PR = 6
    PU = 7
    FIXED = 8
    PLANE2D = 9


class JointParameter(_Labelled):
    """Messages/JointParameter: ODE joint (and motor) parameters, set per axis 1..3."""
    LO_STOP = 0          # rad or m
    HI_STOP = 1          # rad or m
    BOUNCE = 2           # restitution of the stops, [0, 1]
    CFM = 3              # >= 0
    ERP = 4              # [0, 1]
    STOP_ERP = 5         # [0, 1]
    STOP_CFM = 6         # >= 0
    SUSPENSION_ERP = 7   # hinge2 only, [0, 1]
    SUSPENSION_CFM = 8   # hinge2 only, >= 0
    FUDGE_FACTOR = 9     # [0, 1]
    VELOCITY = 10        # motor goal: rad/s or m/s
    MAX_FORCE = 11       # motor limit: N m or N; negative means infinite


class SetJointAction(IntEnum):
    """Services/SetJoint ``action``."""
    CREATE = 0
    SET_PARAMETERS = 1
    REMOVE = 2


class MotorKind(IntEnum):
    """Services/SetMotor ``kind``: dAMotor (rad/s, N m) or dLMotor (m/s, N)."""
    ANGULAR = 0
    LINEAR = 1


class AxisFrame(IntEnum):
    """Services/SetMotor ``axis_frames``: the frame a motor axis stays fixed in."""
    GLOBAL = 0
    FIRST_BODY = 1
    SECOND_BODY = 2


class ServoDrive(IntEnum):
    """Services/SetServo ``drive``: how the motors' joints move (docs/SERVOS.md)."""
    UNCHANGED = 0        # as they do now (a new motor: DYNAMIC)
    DYNAMIC = 1          # the motors push the joints under their maximum force (the default)
    KINEMATIC = 2        # the links beyond the joints follow the commanded speed exactly


class ForceKind(IntEnum):
    """Services/SetExternalForce ``kind``."""
    FORCE = 0            # N
    TORQUE = 1           # N m


class Solver(IntEnum):
    """Services/SetWorld ``solver``."""
    QUICKSTEP = 0        # dWorldQuickStep: iterative, handles piles
    WORLDSTEP = 1        # dWorldStep: the thesis's exact "big matrix" solver
    AUTO = 2             # per step: dWorldStep while the whole step is small or an island
    #                      is articulated (joints, motors) and the largest island small enough
    #                      (a robot held by its motors, a grasp: exact; the bounds are
    #                      odin_common.defaults.AUTO_SOLVER_*), QuickStep otherwise (piles,
    #                      many bodies at rest); the default


class DivergencePolicy(IntEnum):
    """Services/SetWorld ``divergence_policy``: what follows a divergence (world parameter
    ``divergence_policy``; the .srv names the values in its comments only)."""
    PARK = 0             # the body is parked (kinematic, still, no collisions); the world goes on
    PARK_AND_PAUSE = 1   # parked, and the simulation paused (the world keeps answering)


# ---------------------------------------------------------------------------------- joints

JOINT_AXES_USED: Dict[JointType, Tuple[str, ...]] = {
    JointType.BALL: (), JointType.HINGE: ("axis1",), JointType.SLIDER: ("axis1",),
    JointType.PISTON: ("axis1",), JointType.UNIVERSAL: ("axis1", "axis2"),
    JointType.HINGE2: ("axis1", "axis2"), JointType.PR: ("axis1", "axis2"),
    JointType.PU: ("axis1", "axis2", "axis3"), JointType.FIXED: (), JointType.PLANE2D: (),
}
"""Which of Set Joint's axis1..axis3 each joint type reads (world frame)."""

JOINT_USES_ANCHOR = frozenset(set(JointType) - {JointType.SLIDER, JointType.FIXED,
                                                JointType.PLANE2D})
"""Joint types whose ``anchor`` (m, world) is used."""

JOINT_NEEDS_TWO_BODIES = frozenset({JointType.HINGE2})
"""Joint types ODE cannot attach to one body and the static world (it aborts)."""

JOINT_AXIS2_ON_BODY2 = frozenset({JointType.UNIVERSAL, JointType.HINGE2, JointType.PU})
"""Joint types whose second rotation axis is fixed in body2 (or the world), not in body1:
a motor on their two rotation axes anchors its second axis there."""

JOINT_FORCE_MAGNITUDES: Dict[JointType, Tuple[str, ...]] = {
    JointType.HINGE: ("torque",), JointType.SLIDER: ("force",),
    JointType.PISTON: ("force",), JointType.UNIVERSAL: ("torque1", "torque2"),
    JointType.HINGE2: ("torque1", "torque2"),
    JointType.PR: ("force along axis1", "torque about axis2"),
    JointType.PU: ("torque about axis1", "torque about axis2"),
    JointType.BALL: ("torque x (world)", "torque y (world)", "torque z (world)"),
}
"""The magnitudes Set Joint Force takes per joint type, in order (N for forces, N m for
torques). ODE's sign convention: a positive magnitude acts on body1 along (about) +axis and the
reaction on body2. Fixed and plane-2D joints take none."""

JOINT_STATE_AXES: Dict[JointType, Tuple[str, ...]] = {
    JointType.HINGE: ("angle",), JointType.SLIDER: ("position",),
    JointType.PISTON: ("position", "angle"), JointType.UNIVERSAL: ("angle1", "angle2"),
    JointType.HINGE2: ("angle1", "angle2"), JointType.PR: ("position", "angle"),
    JointType.PU: ("position", "angle1", "angle2"),
}
"""What JointData's positions/rates hold per joint type (rad or m; rad/s or m/s); ball, fixed
and plane-2D joints report none."""

_LIMIT_PARAMETERS = frozenset({JointParameter.LO_STOP, JointParameter.HI_STOP,
                               JointParameter.BOUNCE, JointParameter.CFM, JointParameter.ERP,
                               JointParameter.STOP_ERP, JointParameter.STOP_CFM,
                               JointParameter.FUDGE_FACTOR, JointParameter.VELOCITY,
                               JointParameter.MAX_FORCE})
MOTOR_PARAMETERS = _LIMIT_PARAMETERS
"""Parameters a motor takes on each of its axes."""

JOINT_PARAMETERS: Dict[JointType, frozenset] = {
    JointType.BALL: frozenset({JointParameter.CFM, JointParameter.ERP}),
    JointType.FIXED: frozenset({JointParameter.CFM, JointParameter.ERP}),
    JointType.HINGE: _LIMIT_PARAMETERS, JointType.SLIDER: _LIMIT_PARAMETERS,
    JointType.PISTON: _LIMIT_PARAMETERS, JointType.UNIVERSAL: _LIMIT_PARAMETERS,
    JointType.PR: _LIMIT_PARAMETERS, JointType.PU: _LIMIT_PARAMETERS,
    JointType.HINGE2: _LIMIT_PARAMETERS | {JointParameter.SUSPENSION_ERP,
                                           JointParameter.SUSPENSION_CFM},
}
"""Parameters each joint type takes (plane-2D takes none)."""

JOINT_PARAMETER_AXES: Dict[JointType, int] = {
    JointType.BALL: 1, JointType.HINGE: 1, JointType.SLIDER: 1, JointType.PISTON: 2,
    JointType.UNIVERSAL: 2, JointType.HINGE2: 2, JointType.PR: 2, JointType.PU: 3,
    JointType.FIXED: 1,
}
"""Parameter groups (axes 1..n) each joint type has."""

UNIT_PARAMETERS = frozenset({JointParameter.ERP, JointParameter.STOP_ERP,
                             JointParameter.SUSPENSION_ERP, JointParameter.BOUNCE,
                             JointParameter.FUDGE_FACTOR})
"""Parameters whose values lie in [0, 1]."""
NON_NEGATIVE_PARAMETERS = frozenset({JointParameter.CFM, JointParameter.STOP_CFM,
                                     JointParameter.SUSPENSION_CFM})
"""Parameters whose values are >= 0."""


def joint_type(value) -> JointType:
    """The JointType of ``value`` (an int 0..9); InvalidArgument otherwise."""
    if isinstance(value, bool):
        raise InvalidArgument(f"joint type {value!r} is not one of 0..9")
    try:
        return JointType(value)
    except (ValueError, TypeError):
        raise InvalidArgument(f"joint type {value!r} is not one of 0..9") from None


def default_joint_id(kind: int, body1: str, body2: str) -> str:
    """The thesis's joint ID: "<type>:<body1>&<body2>" (a body "" is the static world)."""
    return f"{int(kind)}:{body1}&{body2}"


MOTOR_PREFIX = "motor:"


def default_motor_id(joint_id: str = "", body1: str = "", body2: str = "") -> str:
    """A motor's default ID: "motor:<joint id>", or "motor:<body1>&<body2>" without a joint."""
    return MOTOR_PREFIX + (joint_id if joint_id else f"{body1}&{body2}")


def motor_joint(motor_id: str) -> str:
    """What a default motor ID names after its prefix (its joint's ID for a motor on a joint);
    "" for an ID of one's own."""
    return motor_id[len(MOTOR_PREFIX):] if motor_id.startswith(MOTOR_PREFIX) else ""


# ---------------------------------------------------------------------------------- shapes

class Shape(_Labelled):
    """Messages/Object, Part and View Object ``shape``. BY_COUNT (0, the default) keeps the
    thesis's rule: the number of ``parameters`` decides the shape (1 sphere, 2 cylinder, 3 box,
    a multiple of 3 >= 9 mesh). The others name it; their parameters (m, the object's frame):
    SPHERE radius; CYLINDER radius, length along z; BOX sides x, y, z; MESH vertices (with
    ``indices``); CAPSULE radius, length of its cylinder along z (hemispheres at both ends);
    PLANE none: an infinite plane through the object's position with the object's z axis as
    its normal (static only: geometry_only, never a part of a composite)."""
    BY_COUNT = 0
    SPHERE = 1
    CYLINDER = 2
    BOX = 3
    MESH = 4
    CAPSULE = 5
    PLANE = 6


SHAPE_BY_PARAMETER_COUNT = {1: Shape.SPHERE, 2: Shape.CYLINDER, 3: Shape.BOX}
"""The thesis's rule (Shape.BY_COUNT): a multiple of 3 that is at least 9 is a mesh."""

SHAPE_PARAMETERS: Dict[Shape, Tuple[str, ...]] = {
    Shape.SPHERE: ("radius",), Shape.CYLINDER: ("radius", "length"),
    Shape.BOX: ("x", "y", "z"), Shape.CAPSULE: ("radius", "length"), Shape.PLANE: (),
}
"""What each primitive's parameters are (all m, > 0); a mesh takes vertices."""


def shape_of(parameter_count: int, shape: int = Shape.BY_COUNT) -> Shape:
    """The Shape of ``parameter_count`` parameters asked for as ``shape``; InvalidArgument for
    an unknown shape or a count that does not fit it."""
    if isinstance(shape, bool) or shape not in set(Shape):
        raise InvalidArgument(f"shape {shape!r} is not one of 0..{len(Shape) - 1} "
                              f"({', '.join(f'{s.value} {s.label}' for s in Shape)})")
    shape = Shape(shape)
    is_mesh = parameter_count >= 9 and parameter_count % 3 == 0
    if shape == Shape.BY_COUNT:
        found = SHAPE_BY_PARAMETER_COUNT.get(parameter_count, Shape.MESH if is_mesh else None)
        if found is None:
            raise InvalidArgument(f"{parameter_count} parameters fit no shape (1 sphere, "
                                  "2 cylinder, 3 box, a multiple of 3 >= 9 mesh vertices)")
        return found
    if shape == Shape.MESH:
        if not is_mesh:
            raise InvalidArgument(f"a mesh takes a multiple of 3 >= 9 parameters (vertices), "
                                  f"got {parameter_count}")
    elif parameter_count != len(SHAPE_PARAMETERS[shape]):
        names = ", ".join(SHAPE_PARAMETERS[shape]) or "none"
        raise InvalidArgument(f"a {shape.label} takes {len(SHAPE_PARAMETERS[shape])} "
                              f"parameter(s) ({names}), got {parameter_count}")
    return shape


def shape_kind(parameter_count: int, shape: int = Shape.BY_COUNT) -> str:
    """"sphere", "cylinder", "box", "mesh", "capsule" or "plane" (see shape_of)."""
    return shape_of(parameter_count, shape).label


# ---------------------------------------------------------------------------------- IDs

COMPOSITE_MARK = ">"
"""Starts a composite's ID and separates its parts' names; no other name may hold it."""


def composite_id(part_names: Sequence[str]) -> str:
    """A composite's ID: ">part1>part2..." (thesis 4.2.1)."""
    return COMPOSITE_MARK + COMPOSITE_MARK.join(part_names)


def is_composite_id(object_id: str) -> bool:
    return object_id.startswith(COMPOSITE_MARK)


# ---------------------------------------------------------------------------------- ROS names

WORLD_FRAME = "world"
"""The fixed tf frame every pose is given in (REP 103: x forward, y left, z up)."""

_NAME_CHARACTER = re.compile(r"[A-Za-z0-9_]")


def name_segment(text: str) -> str:
    """``text`` with every character other than a letter, a digit or '_' replaced by '_' (one
    segment of a ROS name or tf frame; the rule robot_namespace and generated robot
    descriptions use)."""
    return "".join(c if _NAME_CHARACTER.fullmatch(c) else "_" for c in text)


def frame_id(object_id: str) -> str:
    """The tf frame of a world object (Odin's rule, docs/ROS.md): the object's ID with every
    character other than a letter, a digit, '_' or '/' replaced by '_', and every '/' that
    would start or end the name or follow another '/' replaced by '_' too; so "TX90 SAHand
    Right/Palm" is "TX90_SAHand_Right/Palm" and the composite ">table#0>table#1" is
    "_table_0_table_1". The result is a valid tf frame ID (non-empty, no leading '/', no
    empty segment, only ROS name characters). A frame already taken in the world (by another
    object, a robot's link or ``WORLD_FRAME``) gets the first free suffix "_2", "_3"... (the
    world then answers the frame it chose in Get World's ``frames``)."""
    if not isinstance(object_id, str) or not object_id:
        raise InvalidArgument(f"object ID {object_id!r} must be a non-empty string")
    last = len(object_id) - 1
    return "".join(
        c if _NAME_CHARACTER.fullmatch(c) or (c == "/" and 0 < i < last
                                               and object_id[i - 1] != "/") else "_"
        for i, c in enumerate(object_id))


def unique_frame(frame: str, taken) -> str:
    """``frame``, or ``frame`` + "_2", "_3"... the first that is not in ``taken``."""
    if frame not in taken:
        return frame
    n = 2
    while f"{frame}_{n}" in taken:
        n += 1
    return f"{frame}_{n}"


def robot_namespace(robot_name: str) -> str:
    """A robot's ROS namespace (its robot_description, joint_states and link frames live
    under it): the robot's name with every character other than a letter, a digit or '_'
    replaced by '_', and "robot_" put before a name that does not start with a letter (ROS
    graph names must); "TX90 SAHand Right" is "TX90_SAHand_Right", "2DRR" is "robot_2DRR"."""
    if not isinstance(robot_name, str) or not robot_name:
        raise InvalidArgument(f"robot name {robot_name!r} must be a non-empty string")
    name = name_segment(robot_name)
    return name if name[0].isalpha() and name[0].isascii() else "robot_" + name


def robot_link_frame(namespace: str, link: str) -> str:
    """The tf frame of a robot's link: "<namespace>/<link>" (what RViz's RobotModel and
    robot_state_publisher look up with the namespace as their tf prefix)."""
    return f"{namespace}/{link}"


# ------------------------------------------------------------------ body state vectors

BODY_STATE_FIELDS: Tuple[Tuple[str, int], ...] = (
    ("position", 3), ("quaternion", 4), ("rotation", 12), ("linear", 3), ("angular", 3),
    ("enabled", 1))
"""One body's record in a body state vector (Propagate's ``start_state`` and ``state``, GetState's
``state_vector``; the C world's odin_step.h): centre of mass position m, quaternion (w, x, y, z),
ODE's 3x4 rotation matrix, linear velocity m/s, angular velocity rad/s (world frame), enabled
(1.0 or 0.0). A vector is ODE's random generator state, then one record per object with a body,
in the world's object order (Propagate's ``states`` order), then one value per exempt pair
(Exempt Overlaps: 1.0 still exempt, 0.0 parted; none in a world without exempt pairs)."""
BODY_STATE_SIZE = sum(size for _, size in BODY_STATE_FIELDS)
#: where each field (BODY_STATE_FIELDS) lies in a body's record: {name: slice}
BODY_STATE_SLICES: Dict[str, slice] = {
    name: slice(start - size, start) for (name, size), start in zip(
        BODY_STATE_FIELDS, itertools.accumulate(size for _, size in BODY_STATE_FIELDS))}


def body_record(vector: Sequence[float], index: int) -> Dict[str, Sequence[float]]:
    """The fields (BODY_STATE_FIELDS) of the ``index``-th body of a body state vector."""
    offset = 1 + index * BODY_STATE_SIZE
    if index < 0 or offset + BODY_STATE_SIZE > len(vector):
        raise InvalidArgument(f"a body state vector of {len(vector)} values has no body "
                              f"{index}")
    return {name: vector[offset + field.start:offset + field.stop]
            for name, field in BODY_STATE_SLICES.items()}


# ---------------------------------------------------------------------------------- services

WORLD_NAMESPACE = "/virtual_world"
VIEWER_NAMESPACE = "/viewer"

WORLD_SERVICES: Dict[str, str] = {
    "new_scene": "NewScene", "set_world": "SetWorld", "set_step": "SetStep",
    "step_once": "StepOnce", "start": "Start", "build_object": "BuildObject",
    "build_composite": "BuildComposite", "build_entity": "BuildEntity",
    "remove_object": "RemoveObject", "set_joint": "SetJoint", "set_motor": "SetMotor",
    "set_position": "SetPosition", "set_velocity": "SetVelocity",
    "set_external_force": "SetExternalForce", "set_joint_force": "SetJointForce",
    "get_world": "GetWorld", "get_state": "GetState", "save_state": "SaveState",
    "restore_state": "RestoreState",
    "reset": "Reset", "propagate": "Propagate", "check_collision": "CheckCollision",
    "set_surface": "SetSurface", "set_servo": "SetServo", "set_robot": "SetRobot",
    "exempt_overlaps": "ExemptOverlaps",
}
"""The VirtualWorld's services: name under ``~`` -> type in the Services package (the
thesis's 15, then Odin's own)."""

VIEWER_SERVICES: Dict[str, str] = {
    "view_object": "ViewObject", "remove_object": "ViewerRemoveObject",
    "new_scene": "ViewerNewScene", "save_snapshot": "SaveSnapshot", "set_camera": "SetCamera",
}
"""The Viewer's services: the three the world calls, then the Viewer's own extras."""


class NodeParameter(NamedTuple):
    """One ``~parameter`` a node reads at start: its default, unit and meaning (each node's
    table of them is what it reads and what docs/parameters.md shows)."""
    name: str
    default: Any
    unit: str
    what: str


__all__ = ["NodeParameter", "JointType", "JointParameter", "SetJointAction", "MotorKind",
           "AxisFrame", "ServoDrive", "ForceKind", "Solver", "DivergencePolicy", "JOINT_AXES_USED",
           "JOINT_USES_ANCHOR", "JOINT_NEEDS_TWO_BODIES", "JOINT_AXIS2_ON_BODY2",
           "JOINT_FORCE_MAGNITUDES", "JOINT_STATE_AXES", "JOINT_PARAMETERS", "JOINT_PARAMETER_AXES",
           "MOTOR_PARAMETERS", "UNIT_PARAMETERS", "NON_NEGATIVE_PARAMETERS", "joint_type",
           "default_joint_id", "MOTOR_PREFIX", "default_motor_id", "motor_joint", "Shape",
           "SHAPE_BY_PARAMETER_COUNT", "SHAPE_PARAMETERS", "shape_of", "shape_kind",
           "COMPOSITE_MARK", "composite_id", "is_composite_id", "WORLD_NAMESPACE",
           "VIEWER_NAMESPACE", "WORLD_SERVICES", "VIEWER_SERVICES", "WORLD_FRAME", "frame_id",
           "unique_frame", "name_segment", "robot_namespace", "robot_link_frame"]
