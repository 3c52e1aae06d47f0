"""A loaded problem -> the VirtualWorld requests that build it, as plain data (ROS-free).

``plan_problem(problem)`` returns a ``BuildPlan``: an ordered list of steps, each wrapping one
odin_common spec (``EntityStep``: EntitySpec, ``ObjectStep``: ObjectSpec, ``CompositeStep``:
CompositeSpec, ``JointStep``: JointSpec, ``MotorStep``: MotorSpec), plus, per robot, what paths
need to drive it (``RobotHandle``). A step knows its one-line ``label()``, its ``describe()``
(problem_info's JSON), the ``entries(answer)`` it adds to a listing of what was built, and how
to ``send(client, ids)`` itself through a ``gui.ros.client.WorldClient``;
``WorldClient.execute(plan)`` sends a whole plan, the Qt window does the same step by step.

How a problem maps to the world:
- A robot with joints -> one Build Entity (one object or composite per link, internal
  collisions off), then per link one Set Joint: revolute -> HINGE, prismatic -> SLIDER (anchor
  and axis from the joint frame at Home, world frame; LO_STOP/HI_STOP from the limits, relative
  to the Home value the joint is built at), a non-movable link -> FIXED joint to its parent;
  the base is a fixed (kinematic) body. Then one Set Motor (angular for hinges, linear for
  sliders; infinite force, zero speed, so the robot holds its pose) per movable joint, id
  "motor:" + joint id.
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
from typing import ClassVar, Dict, List, NamedTuple, Optional, Tuple, Union

import numpy as np

from gui.core.kinematics import pose_to_position_quaternion
from gui.core.model import REVOLUTE, Instance, Problem
from gui.core.shapes import Shape
from odin_common.interface import JointParameter, JointType, MotorKind, default_motor_id
from odin_common.specs import (CompositeSpec, EntitySpec, JointSpec, MotorSpec, ObjectSpec,
                               PartSpec)

BodySpec = Union[ObjectSpec, CompositeSpec]

SCENE_OBJECTS = "Scene objects"
"""The listing section of objects that belong to no robot (``StepEntry.section``)."""


@dataclass(frozen=True)
class BuildDefaults:
    link_mass: float = 1.0          # kg, a link or movable obstacle without a weight/mass
    internal_collisions: bool = False


@dataclass
class BuiltIds:
    """The world's answers so far while a plan is sent: planned body ID -> world ID, joint key
    ("robot/link") -> world joint ID, joint key -> world motor ID."""
    bodies: Dict[str, str] = field(default_factory=dict)
    joints: Dict[str, str] = field(default_factory=dict)
    motors: Dict[str, str] = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {"bodies": self.bodies, "joints": self.joints, "motors": self.motors}


class StepEntry(NamedTuple):
    """One line of a listing of what a step built: under its owner's ``section`` ("Links",
    "Joints", "Motors"; ``SCENE_OBJECTS`` for a step without owner), a short ``name`` and the
    ``world_id``."""
    section: str
    name: str
    world_id: str


# ---------------------------------------------------------------------------------- steps
# Each step wraps one spec. ``send(client, ids)`` calls the client's typed method (a
# gui.ros.client.WorldClient; only its methods are used, so this module needs no ROS), records
# the world's IDs in ``ids`` (BuiltIds) and returns the world's answer (an ID).

def _object_description(spec: ObjectSpec, entity: Optional[str]) -> dict:
    shape = spec.kind
    return dict(name=spec.name, entity=entity, shape=shape, position=list(spec.position),
                quaternion=list(spec.orientation), triangles=spec.triangle_count,
                mass=None if spec.geometry_only else spec.mass, static=spec.geometry_only,
                parameters=list(spec.parameters) if shape != "mesh" else [])


def _composite_description(spec: CompositeSpec, entity: Optional[str]) -> dict:
    return dict(name=spec.id, entity=entity, shape="composite", position=list(spec.position),
                quaternion=list(spec.orientation), triangles=spec.triangle_count,
                mass=None if spec.geometry_only else spec.mass, static=spec.geometry_only,
                parts=[p.name for p in spec.parts])


def _short(name: str, separator: str = "/") -> str:
    return name.rsplit(separator, 1)[-1]


@dataclass(frozen=True, eq=False)
class EntityStep:
    """Build Entity: a robot's (or movable obstacle's) links, all or nothing."""
    spec: EntitySpec

    @property
    def owner(self) -> Optional[str]:
        """The robot or obstacle the step belongs to (None: a scene object)."""
        return self.spec.name

    @property
    def bodies(self) -> Tuple[BodySpec, ...]:
        return self.spec.members

    def label(self) -> str:
        members = self.spec.members
        triangles = sum(m.triangle_count for m in members)
        return f"entity {self.spec.name}: {len(members)} bodies, {triangles} triangles"

    def describe(self) -> dict:
        name = self.spec.name
        return {"bodies": [_object_description(o, name) for o in self.spec.objects]
                + [_composite_description(c, name) for c in self.spec.composites],
                "joints": []}

    def entries(self, answer: str) -> List[StepEntry]:
        return [StepEntry("Links", _short(m.id), m.id) for m in self.spec.members]

    def send(self, client, ids: BuiltIds) -> str:
        built = client.build_entity(self.spec)
        for member, world_id in zip(self.spec.members, built.ids):
            ids.bodies[member.id] = world_id
        return built.name


@dataclass(frozen=True, eq=False)
class ObjectStep:
    """Build Object: a scene object."""
    spec: ObjectSpec
    owner: ClassVar[Optional[str]] = None

    @property
    def bodies(self) -> Tuple[BodySpec, ...]:
        return (self.spec,)

    def label(self) -> str:
        return f"object {self.spec.name} ({self.spec.triangle_count} triangles)"

    def describe(self) -> dict:
        return {"bodies": [_object_description(self.spec, None)], "joints": []}

    def entries(self, answer: str) -> List[StepEntry]:
        return [StepEntry(SCENE_OBJECTS, self.spec.id, str(answer))]

    def send(self, client, ids: BuiltIds) -> str:
        world_id = ids.bodies[self.spec.id] = client.build_object(self.spec)
        return world_id


@dataclass(frozen=True, eq=False)
class CompositeStep:
    """Build Composite: a scene object made of several shapes."""
    spec: CompositeSpec
    owner: ClassVar[Optional[str]] = None

    @property
    def bodies(self) -> Tuple[BodySpec, ...]:
        return (self.spec,)

    def label(self) -> str:
        return f"composite {self.spec.id} ({len(self.spec.parts)} parts)"

    def describe(self) -> dict:
        return {"bodies": [_composite_description(self.spec, None)], "joints": []}

    def entries(self, answer: str) -> List[StepEntry]:
        parts = self.spec.parts
        return [StepEntry(SCENE_OBJECTS, f"{_short(parts[0].name, '#')} ({len(parts)} parts)",
                          str(answer))]

    def send(self, client, ids: BuiltIds) -> str:
        world_id = ids.bodies[self.spec.id] = client.build_composite(self.spec)
        return world_id


@dataclass(frozen=True, eq=False)
class JointStep:
    """Set Joint (create) between two links. ``key`` names it in the plan ("robot/link");
    the spec's bodies are planned IDs, replaced by the world's when sent. ``limits``: the
    joint's range as the robot model states it (rad or m; None: unlimited or a fixed joint),
    for descriptions: the stops sent are relative to the Home value."""
    key: str
    owner: str
    spec: JointSpec
    limits: Optional[Tuple[float, float]] = None

    bodies: ClassVar[Tuple[BodySpec, ...]] = ()

    def label(self) -> str:
        return f"joint {self.key} ({JointType(self.spec.type).label})"

    def kinematic_axis(self) -> list:
        """The joint's axis as the robot model states it (Kautham's sign): a robot's hinges
        and sliders are sent to the world with the axis reversed (see ``plan_problem``)."""
        spec = self.spec
        if spec.type in (JointType.HINGE, JointType.SLIDER) and spec.body1:
            return [-v for v in spec.axis1]
        return list(spec.axis1)

    def describe(self) -> dict:
        spec, limits = self.spec, self.limits
        return {"bodies": [], "joints": [dict(
            name=self.key, type=JointType(spec.type).label, parent=spec.body1 or None,
            child=spec.body2, anchor=list(spec.anchor), axis=self.kinematic_axis(),
            limits=None if limits is None else [limits[0], limits[1]])]}

    def entries(self, answer: str) -> List[StepEntry]:
        return [StepEntry("Joints", _short(self.key), str(answer))]

    def send(self, client, ids: BuiltIds) -> str:
        spec = self.spec
        spec = dataclasses.replace(spec, body1=ids.bodies.get(spec.body1, spec.body1),
                                   body2=ids.bodies.get(spec.body2, spec.body2))
        world_id = ids.joints[self.key] = client.add_joint(spec)
        return world_id


@dataclass(frozen=True, eq=False)
class MotorStep:
    """Set Motor on the joint of the JointStep ``joint_key``; the spec's ``joint`` is the
    predicted joint ID, replaced by the world's when sent."""
    joint_key: str
    owner: str
    spec: MotorSpec

    bodies: ClassVar[Tuple[BodySpec, ...]] = ()

    def label(self) -> str:
        return f"motor on {self.joint_key}"

    def describe(self) -> dict:
        return {"bodies": [], "joints": []}

    def entries(self, answer: str) -> List[StepEntry]:
        return [StepEntry("Motors", _short(self.joint_key), str(answer))]

    def send(self, client, ids: BuiltIds) -> str:
        spec = dataclasses.replace(self.spec, joint=ids.joints[self.joint_key])
        world_id = ids.motors[self.joint_key] = client.add_motor(spec)
        return world_id


PlanStep = Union[EntityStep, ObjectStep, CompositeStep, JointStep, MotorStep]


def body_step(spec: BodySpec) -> PlanStep:
    """The step that builds one scene object (ObjectStep or CompositeStep)."""
    return ObjectStep(spec) if isinstance(spec, ObjectSpec) else CompositeStep(spec)


# ---------------------------------------------------------------------------------- plans

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
    """Steps in the order they must be sent (EntityStep, ObjectStep, CompositeStep,
    JointStep, MotorStep)."""
    problem: Problem
    steps: list
    robots: list                     # RobotHandle per robot (and per movable multi-link obstacle)

    def counts(self) -> dict:
        """{step class name: how many}."""
        out: dict = {}
        for step in self.steps:
            out[type(step).__name__] = out.get(type(step).__name__, 0) + 1
        return out

    def bodies(self) -> List[BodySpec]:
        """Every object and composite the plan builds (entities' members included), in order."""
        return [body for step in self.steps for body in step.bodies]

    def record_world_ids(self, ids: BuiltIds) -> None:
        """Puts the world's IDs (answers to the plan's steps) into the robot handles."""
        for handle in self.robots:
            for body in handle.bodies:
                body.body_id = ids.bodies.get(body.body_id, body.body_id)
            if handle.joint_keys:
                handle.joint_ids = [ids.joints[k] for k in handle.joint_keys]
                handle.motor_ids = [ids.motors[k] for k in handle.joint_keys]


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
                  static: bool) -> Tuple[BodySpec, np.ndarray]:
    """The spec (object or composite) for a shape whose frame is at ``link_pose``, and the
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
        spec = ObjectSpec(name=name, parameters=params, indices=indices, mass=mass,
                          position=position, orientation=quaternion, color=tuple(color),
                          geometry_only=static)
        return spec, offset
    total = sum(p[5] for p in pieces) or 1.0
    parts = []
    for k, (kind, params, indices, offset, color, volume) in enumerate(pieces):
        position, quaternion = pose_to_position_quaternion(offset)
        parts.append(PartSpec(name=f"{name}#{k}", parameters=params, indices=indices,
                              mass=max(mass * volume / total, mass * 1e-6),
                              position=position, orientation=quaternion, color=tuple(color)))
    position, quaternion = pose_to_position_quaternion(link_pose)
    return CompositeSpec(parts=tuple(parts), position=position, orientation=quaternion,
                         geometry_only=static), np.eye(4)


def plan_problem(problem: Problem, defaults: BuildDefaults = BuildDefaults()) -> BuildPlan:
    steps: list = []
    handles: list = []
    for inst in problem.instances:
        model = inst.model
        poses = model.link_poses(inst.base_pose)
        static = inst.role == "obstacle" and not inst.movable
        single = len(model.links) == 1
        specs, bodies = [], []
        for link, pose in zip(model.links, poses):
            name = inst.name if single else f"{inst.name}/{link.name}"
            mass = link.mass if link.mass is not None else defaults.link_mass
            spec, offset = shape_to_body(name, link.shape, pose, mass, static)
            specs.append(spec)
            bodies.append(LinkBody(spec.id, offset))
        if not inst.collision:   # <Collision Enable="false">: the world never pairs it
            specs = [dataclasses.replace(s, no_collisions=True) for s in specs]
        if static or (single and inst.role == "obstacle"):
            steps.extend(body_step(s) for s in specs)
            continue
        if inst.role == "robot" and not single:
            # The base is a fixed (kinematic) body: it never moves, whatever the motors push,
            # where a fixed joint to the environment would give a little under their reaction.
            specs[0] = dataclasses.replace(specs[0], fixed=True)
        steps.append(EntityStep(EntitySpec(
            name=inst.name,
            objects=tuple(s for s in specs if isinstance(s, ObjectSpec)),
            composites=tuple(s for s in specs if isinstance(s, CompositeSpec)),
            internal_collisions=defaults.internal_collisions)))
        if single:
            if inst.role == "robot":
                handles.append(RobotHandle(inst, bodies, [], home=model.home()))
            continue
        frames = model.joint_frames(inst.base_pose)
        joint_keys, joint_ids, motors = [], [], []
        for i, link in enumerate(model.links):
            if link.parent is None:
                continue
            key = f"{inst.name}/{link.name}"
            parent_id = bodies[link.parent].body_id
            if not link.movable:
                steps.append(JointStep(key, inst.name, JointSpec(
                    type=JointType.FIXED, body1=parent_id, body2=bodies[i].body_id)))
                continue
            frame = frames[i]
            # ODE measures a hinge's angle (a slider's position) as body1's motion relative to
            # body2; the parent is body1, so the axis is reversed: the world's joint value, its
            # stops and its motor's goal speed then all have the sign of Kautham's joint value.
            axis = -(frame[:3, :3] @ link.axis)
            params = ()
            if link.limits is not None:
                h = link.home_value()
                params = ((JointParameter.LO_STOP, 1, float(link.limits[0] - h)),
                          (JointParameter.HI_STOP, 1, float(link.limits[1] - h)))
            revolute = link.joint == REVOLUTE
            joint = JointSpec(type=JointType.HINGE if revolute else JointType.SLIDER,
                              body1=parent_id, body2=bodies[i].body_id,
                              anchor=_flat(frame[:3, 3]), axis1=_flat(axis), parameters=params)
            steps.append(JointStep(key, inst.name, joint, limits=link.limits))
            joint_keys.append(key)
            joint_ids.append(joint.default_id)
            motors.append(MotorStep(key, inst.name, MotorSpec(
                joint=joint.default_id,
                kind=MotorKind.ANGULAR if revolute else MotorKind.LINEAR)))
        steps.extend(motors)
        handles.append(RobotHandle(inst, bodies, joint_keys, joint_ids=joint_ids,
                                   motor_ids=[default_motor_id(j) for j in joint_ids],
                                   home=model.home()))
    return BuildPlan(problem=problem, steps=steps, robots=handles)
