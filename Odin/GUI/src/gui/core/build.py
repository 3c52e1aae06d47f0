"""A loaded problem -> the VirtualWorld requests that build it, as plain data (ROS-free).

``plan_problem(problem)`` returns a ``BuildPlan``: an ordered list of requests whose fields
mirror Messages/Object, Messages/Composite and the Set Joint / Set Motor services, plus, per
robot, what paths need to drive it (``RobotHandle``). ``gui.ros.client.WorldClient.execute`` sends
a plan; the Qt window can do the same step by step.

How a problem maps to the world:
- A robot with joints -> one Build Entity (one object or composite per link, internal
  collisions off), then per link one Set Joint: revolute -> HINGE, prismatic -> SLIDER (anchor
  and axis from the joint frame at Home, world frame; LO_STOP/HI_STOP from the limits, relative
  to the Home value the joint is built at), a non-movable link -> FIXED joint to its parent;
  the base is held by a FIXED joint to the static environment (body1 ""). Then one Set Motor
  (angular for hinges, linear for sliders; infinite force, zero speed, so the robot holds its
  pose) per movable joint, id "motor:" + joint id.
- A robot made of one link (a bare shape or a one-link URDF) is a free-flying body: an entity
  of one object, no joint.
- A static obstacle -> Build Object/Composite with ``geometry_only``. A movable obstacle (a .rob
  scene, or a URDF with masses) -> bodies with masses; a multi-link one is built like a robot
  but its base is left free.
- Shapes: a mesh -> mesh object (vertices in the link frame); one primitive -> primitive
  object whose body sits at the primitive's pose in the link; anything else -> a composite
  whose frame is the link frame (one part per primitive, one for the mesh), id ">p1>p2...".
- Masses: the file's weight/mass, else ``BuildDefaults.link_mass``; a composite's mass is shared
  among its parts in proportion to their volumes. Inertia is left empty (the world computes it
  from the shape at uniform density): Object.msg has no centre-of-mass field, and the corpus's
  URDF inertias are placeholders inconsistent with their shapes.
- Names (thesis 8.3): links are "robot/link" (Kautham's own .cntr naming), one-link instances
  keep the instance name; instance names come from the robot's name or the obstacle's file
  name, numbered "_2", "_3"... on collision; composite parts are "name#k".
"""
from __future__ import annotations

import dataclasses

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from gui.core.kinematics import pose_to_position_quaternion
from gui.core.model import FIXED, PRISMATIC, REVOLUTE, Instance, Problem
from gui.core.shapes import Shape

# Messages/Joint and Messages/JointParameter constants (kept here so the Core needs no ROS).
JOINT_HINGE, JOINT_SLIDER, JOINT_FIXED = 1, 2, 8
PARAM_LO_STOP, PARAM_HI_STOP = 0, 1
MOTOR_ANGULAR, MOTOR_LINEAR = 0, 1


@dataclass(frozen=True)
class BuildDefaults:
    link_mass: float = 1.0          # kg, a link or movable obstacle without a weight/mass
    internal_collisions: bool = False


@dataclass(frozen=True, eq=False)
class ObjectRequest:
    """Messages/Object. ``parameters`` and ``indices`` are tuples for primitives and flat
    numpy arrays (float64, uint32) for meshes."""
    name: str
    parameters: tuple
    indices: tuple
    mass: float
    position: tuple
    orientation: tuple
    color: tuple
    fixed: bool = False
    geometry_only: bool = False
    inertia: tuple = ()
    triangle_count: int = 0
    no_collisions: bool = False

    @property
    def id(self) -> str:
        return self.name


@dataclass(frozen=True, eq=False)
class PartRequest:
    """Messages/Part (pose relative to the composite's frame)."""
    name: str
    parameters: tuple
    indices: tuple
    mass: float
    position: tuple
    orientation: tuple
    color: tuple


@dataclass(frozen=True, eq=False)
class CompositeRequest:
    """Messages/Composite."""
    parts: tuple
    position: tuple
    orientation: tuple
    fixed: bool = False
    geometry_only: bool = False
    no_collisions: bool = False

    @property
    def id(self) -> str:
        return ">" + ">".join(p.name for p in self.parts)

    @property
    def mass(self) -> float:
        return float(sum(p.mass for p in self.parts))

    @property
    def triangle_count(self) -> int:
        return sum(len(p.indices) // 3 for p in self.parts)


@dataclass(frozen=True, eq=False)
class EntityRequest:
    """Services/BuildEntity."""
    name: str
    objects: tuple
    composites: tuple
    internal_collisions: bool = False


@dataclass(frozen=True)
class JointRequest:
    """Services/SetJoint, action CREATE. ``key`` names it inside the plan ("robot/link")."""
    key: str
    type: int
    body1: str
    body2: str
    anchor: tuple = (0.0, 0.0, 0.0)
    axis1: tuple = (0.0, 0.0, 1.0)   # FIXED ignores it (the world refuses a zero axis)
    axis2: tuple = (1.0, 0.0, 0.0)   # unused by hinge/slider/fixed; non-zero for the same reason
    axis3: tuple = (0.0, 1.0, 0.0)
    parameters: tuple = ()           # ((parameter, axis, value), ...)

    @property
    def default_id(self) -> str:
        return f"{self.type}:{self.body1}&{self.body2}"


@dataclass(frozen=True)
class MotorRequest:
    """Services/SetMotor driving the joint built by the JointRequest ``joint_key``."""
    joint_key: str
    kind: int


@dataclass
class LinkBody:
    """Where a link's body is: its world ID and the body's pose in the link frame."""
    body_id: str
    offset: np.ndarray               # (4, 4) body frame in the link frame


@dataclass
class RobotHandle:
    """What drives one robot: its model and base, its links' bodies, its movable joints."""
    instance: Instance
    bodies: list                     # LinkBody per link, model order
    joint_keys: list                 # per movable joint (model.movable_links() order)
    joint_ids: list = field(default_factory=list)   # world joint IDs (predicted; the client
    motor_ids: list = field(default_factory=list)   # replaces them by the world's answers)
    home: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def name(self) -> str:
        return self.instance.name

    def situations(self, values) -> list:
        """(body ID, position, quaternion) of every link for joint ``values`` (rad / m)."""
        poses = self.instance.model.link_poses(self.instance.base_pose, values)
        out = []
        for T, body in zip(poses, self.bodies):
            position, quaternion = pose_to_position_quaternion(T @ body.offset)
            out.append((body.body_id, position, quaternion))
        return out


@dataclass
class BuildPlan:
    """Requests in the order they must be sent: EntityRequest, ObjectRequest,
    CompositeRequest, JointRequest, MotorRequest."""
    problem: Problem
    steps: list
    robots: list                     # RobotHandle per robot (and per movable multi-link obstacle)

    def counts(self) -> dict:
        out: dict = {}
        for step in self.steps:
            out[type(step).__name__] = out.get(type(step).__name__, 0) + 1
        return out


def _volume(part_kind: str, parameters: tuple, vertices=None, triangles=None) -> float:
    if part_kind == "sphere":
        return 4.0 / 3.0 * np.pi * parameters[0] ** 3
    if part_kind == "cylinder":
        return np.pi * parameters[0] ** 2 * parameters[1]
    if part_kind == "box":
        return float(np.prod(parameters))
    tri = vertices[triangles]
    signed = float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6)
    if abs(signed) > 0:
        return abs(signed)
    extent = vertices.max(0) - vertices.min(0)
    return float(np.prod(np.maximum(extent, 1e-6)))


def _flat(a) -> tuple:
    return tuple(float(v) for v in np.asarray(a, dtype=float).ravel())


def shape_to_body(name: str, shape: Shape, link_pose: np.ndarray, mass: float,
                  static: bool):
    """The request (object or composite) for a shape whose frame is at ``link_pose``, and the
    body's pose in that frame (identity but for a lone primitive)."""
    pieces = []
    if shape.mesh is not None:
        mesh = shape.mesh
        pieces.append(("mesh", np.ascontiguousarray(mesh.vertices, dtype=np.float64).ravel(),
                       np.ascontiguousarray(mesh.triangles, dtype=np.uint32).ravel(),
                       np.eye(4), mesh.color, _volume("mesh", (), mesh.vertices, mesh.triangles)))
    for prim in shape.primitives:
        pieces.append((prim.kind, tuple(prim.parameters), (), prim.pose, prim.color,
                       _volume(prim.kind, prim.parameters)))
    if len(pieces) == 1:
        kind, params, indices, offset, color, _ = pieces[0]
        position, quaternion = pose_to_position_quaternion(link_pose @ offset)
        request = ObjectRequest(name=name, parameters=params, indices=indices, mass=mass,
                                position=position, orientation=quaternion, color=tuple(color),
                                geometry_only=static, triangle_count=len(indices) // 3)
        return request, offset
    total = sum(p[5] for p in pieces) or 1.0
    parts = []
    for k, (kind, params, indices, offset, color, volume) in enumerate(pieces):
        position, quaternion = pose_to_position_quaternion(offset)
        parts.append(PartRequest(name=f"{name}#{k}", parameters=params, indices=indices,
                                 mass=max(mass * volume / total, mass * 1e-6),
                                 position=position, orientation=quaternion, color=tuple(color)))
    position, quaternion = pose_to_position_quaternion(link_pose)
    return CompositeRequest(parts=tuple(parts), position=position, orientation=quaternion,
                            geometry_only=static), np.eye(4)


def plan_problem(problem: Problem, defaults: BuildDefaults = BuildDefaults()) -> BuildPlan:
    steps: list = []
    handles: list = []
    for inst in problem.instances:
        model = inst.model
        poses = model.link_poses(inst.base_pose)
        static = inst.role == "obstacle" and not inst.movable
        single = len(model.links) == 1
        requests, bodies = [], []
        for link, pose in zip(model.links, poses):
            name = inst.name if single else f"{inst.name}/{link.name}"
            mass = link.mass if link.mass is not None else defaults.link_mass
            request, offset = shape_to_body(name, link.shape, pose, mass, static)
            requests.append(request)
            bodies.append(LinkBody(request.id, offset))
        if not inst.collision:   # <Collision Enable="false">: the world never pairs it
            requests = [dataclasses.replace(r, no_collisions=True) for r in requests]
        if static or (single and inst.role == "obstacle"):
            steps.extend(requests)
            continue
        if inst.role == "robot" and not single:
            # The base is a fixed (kinematic) body: it never moves, whatever the motors push,
            # where a fixed joint to the environment would give a little under their reaction.
            requests[0] = dataclasses.replace(requests[0], fixed=True)
        steps.append(EntityRequest(
            name=inst.name,
            objects=tuple(r for r in requests if isinstance(r, ObjectRequest)),
            composites=tuple(r for r in requests if isinstance(r, CompositeRequest)),
            internal_collisions=defaults.internal_collisions))
        if single:
            if inst.role == "robot":
                handles.append(RobotHandle(inst, bodies, [], home=model.home()))
            continue
        frames = model.joint_frames(inst.base_pose)
        joint_keys, motors = [], []
        for i, link in enumerate(model.links):
            if link.parent is None:
                continue
            key = f"{inst.name}/{link.name}"
            parent_id = bodies[link.parent].body_id
            if not link.movable:
                steps.append(JointRequest(key=key, type=JOINT_FIXED, body1=parent_id,
                                          body2=bodies[i].body_id))
                continue
            frame = frames[i]
            # ODE measures a hinge's angle (a slider's position) as body1's motion relative to
            # body2; the parent is body1, so the axis is reversed: the world's joint value, its
            # stops and its motor's goal speed then all have the sign of Kautham's joint value.
            axis = -(frame[:3, :3] @ link.axis)
            params = ()
            if link.limits is not None:
                h = link.home_value()
                params = ((PARAM_LO_STOP, 1, float(link.limits[0] - h)),
                          (PARAM_HI_STOP, 1, float(link.limits[1] - h)))
            steps.append(JointRequest(
                key=key, type=JOINT_HINGE if link.joint == REVOLUTE else JOINT_SLIDER,
                body1=parent_id, body2=bodies[i].body_id, anchor=_flat(frame[:3, 3]),
                axis1=_flat(axis), parameters=params))
            joint_keys.append(key)
            motors.append(MotorRequest(joint_key=key, kind=MOTOR_ANGULAR
                                       if link.joint == REVOLUTE else MOTOR_LINEAR))
        steps.extend(motors)
        by_key = {s.key: s for s in steps if isinstance(s, JointRequest)}
        joint_ids = [by_key[k].default_id for k in joint_keys]
        handles.append(RobotHandle(inst, bodies, joint_keys, joint_ids=joint_ids,
                                   motor_ids=["motor:" + j for j in joint_ids],
                                   home=model.home()))
    return BuildPlan(problem=problem, steps=steps, robots=handles)
