"""A loaded problem -> the VirtualWorld requests that build it, as plain data (ROS-free).

``plan_problem(problem)`` returns a ``BuildPlan``: an ordered list of steps, each wrapping one
request (``WorldStep``: Set World, ``StepSizeStep``: Set Step, ``EntityStep``: EntitySpec,
``ObjectStep``: ObjectSpec, ``CompositeStep``: CompositeSpec, ``JointStep``: JointSpec,
``MotorStep``: MotorSpec), plus, per robot, what paths and controls need to drive it
(``RobotHandle``). A step knows its one-line ``label()``, its ``describe()`` (problem_info's
JSON), the ``entries(answer)`` it adds to a listing of what was built, and how to
``send(client, ids)`` itself through a ``gui.ros.client.WorldClient``;
``WorldClient.execute(plan)`` sends a whole plan, the Qt window does the same step by step.

How a problem maps to the world:
- Kautham's physics (``Problem.physics``: one of its ODE planners; ``BuildDefaults.ground``
  asks for it in any problem): first Set World and Set Step with what Kautham's ODE
  environment uses (``gui.core.world_settings``), then an infinite ground plane at z = 0
  (``GROUND``, static).
- A robot with joints -> one Build Entity (one object or composite per link, internal
  collisions off), then per link one Set Joint: revolute -> HINGE, prismatic -> SLIDER (anchor
  and axis from the joint frame where the robot is built, world frame; LO_STOP/HI_STOP from the
  limits, relative to the value the joint is built at), a non-movable link -> FIXED joint to
  its parent; a car's wheels -> HINGE2 with CarEnvironment's suspension (ERP 0.4 / CFM 0.8):
  for a car of Kautham's car planner CarEnvironment's world axes (steering about +z for the
  first two wheels, -z for the others, spin about +y, whatever the car's pose: a positive
  wheel speed rolls it toward world -x) and its contact friction by body kind
  (``environment.CAR_FRICTION``, the ground's too); for any other car axes from its own frame
  (steering about the base's up, opposite for the wheels ahead of its centre and the others;
  both reversed like a hinge's, so that a positive steering turns left and a positive wheel
  speed rolls the car along its +x). Then one Set Motor per movable joint
  (angular for hinges and hinge-2s, linear for sliders; zero speed, so the robot holds its
  pose; the joint's effort limit as its force limit, infinite without one; the chain of
  Kautham's chain planner gets PlanarChainEnvironment's 7 N m and 1 rad/s for every joint
  instead, whatever its URDF says), id "motor:" + joint id; a joint with friction gets a second
  motor at zero speed whose force limit is the friction ("friction:" + joint id), a joint
  with damping a third at zero speed, unlimited force and CFM 1 / damping, which makes ODE
  apply exactly -damping x the joint's rate ("damping:" + joint id); under Kautham's own
  physics (one of its ODE planners) no joint has either, as in its ODE environment.
- The base by the robot's kind (``gui.core.model``): FIXED_BASE -> in a 2012 problem a fixed
  (kinematic) body that never moves; in a current one a dynamic body held by a FIXED joint to
  the world (Kautham's chain); FREE_BODY, MOBILE, CAR -> a dynamic body, free.
- A robot is built at its start (the query's ``<Init>``) in current problems, at Home in 2012
  ones (``BuildDefaults.start_at_query``); ``RobotHandle.built_at`` keeps the joint values the
  world's joint readings are relative to.
- A robot made of one link (a bare shape or a one-link URDF) is a free-flying body: an entity
  of one object, no joint.
- A static obstacle -> Build Object/Composite with ``geometry_only``. A movable obstacle (a .rob
  scene, a URDF with masses, ``<Scene movable="true">``, any obstacle under Kautham's physics,
  an attached obstacle) -> bodies with masses; a multi-link one is built like a robot but its
  base is left free. ``<InitialAttachedObstacle>`` -> a FIXED joint between the link and the
  obstacle's (base) body, as they are placed.
- Shapes: a mesh -> mesh object (vertices in the link frame); one primitive -> primitive
  object whose body sits at the primitive's pose in the link; anything else -> a composite
  whose frame is the link frame (one part per primitive, one for the mesh), id ">p1>p2...".
- Masses: the file's mass, else ``BuildDefaults.link_mass`` (a .rob ``<Weight>`` is a planner
  weight, not a mass); a composite's mass is shared among its parts in proportion to their
  volumes. Inertia (``gui.core.inertia``): the URDF's tensor about its centre of mass where it
  is a rigid body's and plausible for the link's shape, the shape's at uniform density
  otherwise. Contact surfaces: the link's (URDF contact coefficients) on its object or parts.
- Names (thesis 8.3): links are "robot/link" (Kautham's own .cntr naming), one-link instances
  keep the instance name; instance names come from the robot's name or the obstacle's file
  name, numbered "_2", "_3"... on collision; composite parts are "name#k".
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import ClassVar, Dict, List, NamedTuple, Optional, Tuple, Union

import numpy as np

from gui.core import inertia as inertia_rule
from gui.core.kautham import environment
from gui.core.kautham.problem import PHYSICS_PLANNERS
from gui.core.kinematics import pose_to_position_quaternion
from gui.core.model import (CAR, FIXED_BASE, REVOLUTE, Configuration, Ignored, Instance,
                            Problem, warn_once)
from gui.core.shapes import Shape
from gui.core.world_settings import WorldSettings, kautham_world
from odin_common.interface import (JointParameter, JointType, MotorKind, Shape as ShapeKind,
                                   default_motor_id)
from odin_common.specs import (CompositeSpec, EntitySpec, JointSpec, MotorSpec, ObjectSpec,
                               PartSpec, Surface, WORLD_SURFACE)
from odin_common.step_values import StepValues

BodySpec = Union[ObjectSpec, CompositeSpec]

SCENE_OBJECTS = "Scene objects"
"""The listing section of objects that belong to no robot (``StepEntry.section``)."""


GROUND = "ground"
"""The ground plane's object ID (another name is taken if an instance has it)."""


@dataclass(frozen=True)
class BuildDefaults:
    """How a problem is built. ``ground``: Kautham's physics (Set World, Set Step, a ground
    plane) for every problem (True), none (False), or where Kautham simulates the problem
    (None: ``Problem.physics``). ``start_at_query``: robots built at the query's start (True),
    at Home (False), or the start in current problems and Home in 2012 ones (None).
    ``inertia``: "auto", "file" or "shape" (``gui.core.inertia``). ``max_contact_sink``: m,
    the deepest a body may rest in a contact the planner's CFM softens
    (``gui.core.world_settings``)."""
    link_mass: float = 1.0          # kg, a link or movable obstacle without a mass
    internal_collisions: bool = False
    ground: Optional[bool] = None
    start_at_query: Optional[bool] = None
    inertia: str = inertia_rule.AUTO
    placeholder_factor: float = 10.0
    max_contact_sink: float = 0.01


@dataclass
class BuiltIds:
    """The world's answers so far while a plan is sent: planned body ID -> world ID, joint key
    ("robot/link") -> world joint ID, joint key -> world motor ID (a joint's friction and
    damping motors under "key#friction", "key#damping")."""
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
class WorldStep:
    """Set World with ``parameters`` {name: value} (odin_common.world_parameters names)."""
    parameters: dict
    owner: ClassVar[Optional[str]] = None
    bodies: ClassVar[Tuple[BodySpec, ...]] = ()

    def label(self) -> str:
        return "world " + ", ".join(f"{k}={_short_value(v)}" for k, v in self.parameters.items())

    def describe(self) -> dict:
        return {"bodies": [], "joints": []}

    def entries(self, answer) -> List[StepEntry]:
        return [StepEntry("World", name, _short_value(value))
                for name, value in self.parameters.items()]

    def send(self, client, ids: BuiltIds) -> str:
        client.set_world(**self.parameters)
        return "set"


@dataclass(frozen=True, eq=False)
class StepSizeStep:
    """Set Step: ``step`` s, ``steps_per_cycle``, ``rate`` Hz."""
    step: float
    steps_per_cycle: int
    rate: float
    owner: ClassVar[Optional[str]] = None
    bodies: ClassVar[Tuple[BodySpec, ...]] = ()

    def label(self) -> str:
        return (f"step {self.step:g} s, {self.steps_per_cycle} per cycle, "
                f"{self.rate:.4g} Hz")

    def describe(self) -> dict:
        return {"bodies": [], "joints": []}

    def entries(self, answer) -> List[StepEntry]:
        return [StepEntry("World", "step", f"{self.step:g} s")]

    def send(self, client, ids: BuiltIds) -> str:
        values = client.set_step(step=self.step, steps_per_cycle=self.steps_per_cycle,
                                 rate=self.rate)
        return f"{values.step:g} s"


def _short_value(value) -> str:
    if isinstance(value, (tuple, list)):
        return "(" + ", ".join(f"{v:g}" for v in value) + ")"
    return f"{value:g}" if isinstance(value, float) else str(value)


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
    predicted joint ID, replaced by the world's when sent. ``purpose``: "" for the motor that
    drives the joint, "friction" or "damping" for one that only resists it (its ID then
    starts with the purpose); ``parameters``: (JointParameter, axis, value) set on the motor
    once made (Set Joint SET_PARAMETERS)."""
    joint_key: str
    owner: str
    spec: MotorSpec
    purpose: str = ""
    parameters: Tuple = ()

    bodies: ClassVar[Tuple[BodySpec, ...]] = ()

    @property
    def key(self) -> str:
        """Where BuiltIds.motors records it."""
        return f"{self.joint_key}#{self.purpose}" if self.purpose else self.joint_key

    def label(self) -> str:
        return f"{self.purpose or 'motor'} on {self.joint_key}"

    def describe(self) -> dict:
        return {"bodies": [], "joints": []}

    def entries(self, answer: str) -> List[StepEntry]:
        name = _short(self.joint_key) + (f" ({self.purpose})" if self.purpose else "")
        return [StepEntry("Motors", name, str(answer))]

    def send(self, client, ids: BuiltIds) -> str:
        joint = ids.joints[self.joint_key]
        spec = dataclasses.replace(self.spec, joint=joint, id=self.spec.id and (
            f"{self.purpose}:{joint}" if self.purpose else self.spec.id))
        world_id = ids.motors[self.key] = client.add_motor(spec)
        if self.parameters:
            client.set_joint_parameters(world_id, self.parameters)
        return world_id


PlanStep = Union[WorldStep, StepSizeStep, EntityStep, ObjectStep, CompositeStep, JointStep,
                 MotorStep]


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
    """What drives one robot: its model and where it was built, its links' bodies, its
    movable joints and their motors.

    ``base_pose`` (4, 4) and ``built_at`` (rad / m per movable joint): the configuration the
    robot was built in (the world's joint readings are relative to ``built_at``); ``home``:
    Home's joint values. ``kind``: gui.core.model's robot kind. ``max_forces`` /
    ``max_speeds``: per movable joint, its effort and speed limits (None: none given).
    ``joint_axes``: per movable joint, which of its world joint's values is the joint's (0; a
    car's wheel is its hinge-2's spin, 1). ``base_mass``: kg, the base body's mass."""
    instance: Instance
    bodies: list                     # LinkBody per link, model order
    joint_keys: list                 # per movable joint (model.movable_links() order)
    joint_ids: list = field(default_factory=list)   # world joint IDs (predicted; the client
    motor_ids: list = field(default_factory=list)   # replaces them by the world's answers)
    home: np.ndarray = field(default_factory=lambda: np.zeros(0))
    built_at: Optional[np.ndarray] = None
    base_pose: Optional[np.ndarray] = None
    kind: str = ""
    max_forces: list = field(default_factory=list)
    max_speeds: list = field(default_factory=list)
    joint_axes: list = field(default_factory=list)
    base_mass: float = 0.0

    def __post_init__(self):
        if self.built_at is None:
            self.built_at = np.array(self.home, dtype=float)
        if self.base_pose is None:
            self.base_pose = self.instance.base_pose

    @property
    def name(self) -> str:
        return self.instance.name

    @property
    def start(self) -> Optional[Configuration]:
        return self.instance.start

    @property
    def goal(self) -> Optional[Configuration]:
        return self.instance.goal

    def situations(self, values, base_pose: Optional[np.ndarray] = None) -> list:
        """(body ID, position, quaternion) of every link for joint ``values`` (rad / m), the
        base where the robot was built (or at ``base_pose``)."""
        base = self.base_pose if base_pose is None else base_pose
        poses = self.instance.model.link_poses(base, values)
        out = []
        for T, body in zip(poses, self.bodies):
            position, quaternion = pose_to_position_quaternion(T @ body.offset)
            out.append((body.body_id, position, quaternion))
        return out


@dataclass
class BuildPlan:
    """Steps in the order they must be sent (WorldStep, StepSizeStep, EntityStep, ObjectStep,
    CompositeStep, JointStep, MotorStep). ``world``: the world settings the plan sets (None:
    it leaves the world as it is); ``ignored``: the problem's, and what the plan set aside."""
    problem: Problem
    steps: list
    robots: list                     # RobotHandle per robot (and per movable multi-link obstacle)
    world: Optional[WorldSettings] = None
    ignored: list = field(default_factory=list)

    def counts(self) -> dict:
        """{step class name: how many}."""
        out: dict = {}
        for step in self.steps:
            out[type(step).__name__] = out.get(type(step).__name__, 0) + 1
        return out

    def bodies(self) -> List[BodySpec]:
        """Every object and composite the plan builds (entities' members included), in order."""
        return [body for step in self.steps for body in step.bodies]

    def robot(self, name: Optional[str] = None) -> RobotHandle:
        """The robot called ``name`` (the first robot when None); KeyError naming the robots
        otherwise."""
        robots = [h for h in self.robots if h.instance.role == "robot"]
        for handle in robots:
            if name in (None, handle.name):
                return handle
        raise KeyError(f"no robot named {name!r} (robots: "
                       + ", ".join(h.name for h in robots) + ")")

    def record_world_ids(self, ids: BuiltIds) -> None:
        """Puts the world's IDs (answers to the plan's steps) into the robot handles."""
        for handle in self.robots:
            for body in handle.bodies:
                body.body_id = ids.bodies.get(body.body_id, body.body_id)
            if handle.joint_keys:
                handle.joint_ids = [ids.joints[k] for k in handle.joint_keys]
                handle.motor_ids = [ids.motors[k] for k in handle.joint_keys]


def _volume(part_kind: str, parameters: tuple, vertices=None, triangles=None) -> float:
    if part_kind != "mesh":
        return inertia_rule.primitive_volume(part_kind, parameters)
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


def _with_surface(spec: BodySpec, surface) -> BodySpec:
    """``spec`` with the link's contact surface on its object or on every part."""
    if not surface.is_set:
        return spec
    if isinstance(spec, ObjectSpec):
        return dataclasses.replace(spec, surface=surface)
    return dataclasses.replace(spec, parts=tuple(dataclasses.replace(p, surface=surface)
                                                 for p in spec.parts))


class _Drive(NamedTuple):
    """How a movable joint is driven and resisted: ``effort`` (N m or N) and ``speed`` (rad/s
    or m/s) limits, None where none; ``friction`` (N m or N) and ``damping`` (N m s/rad or
    N s/m), 0 for none."""
    effort: Optional[float]
    speed: Optional[float]
    friction: float
    damping: float


class _Planner:
    """One plan: the problem's instances in order, then attachments."""

    def __init__(self, problem: Problem, defaults: BuildDefaults):
        self.problem, self.defaults = problem, defaults
        self.physics = problem.physics if defaults.ground is None else defaults.ground
        start = defaults.start_at_query
        self.start_at_query = problem.format == "current" if start is None else start
        attached = {a.obstacle for a in problem.attachments}
        # bodies: movable obstacles, attached ones, and every current obstacle under
        # Kautham's physics (its ODE environment makes them all dynamic)
        self.dynamic = {i.name for i in problem.obstacles
                        if i.movable or i.name in attached
                        or (self.physics and problem.format == "current")}
        # Kautham's chain planner drives its chain's joints as PlanarChainEnvironment does,
        # its car planner sets its car's wheel axes as CarEnvironment does
        planned = PHYSICS_PLANNERS.get(problem.planner.name) if problem.physics else None
        self.chain_drive = planned == FIXED_BASE
        self.car_environment = planned == CAR
        self.steps: list = []
        self.handles: list = []
        self.ignored: list = list(problem.ignored)
        self.base_bodies: Dict[str, LinkBody] = {}     # instance name -> its base's body
        self.link_bodies: Dict[Tuple[str, str], LinkBody] = {}
        self.masses: list = []                          # (body ID, kg) of dynamic bodies

    def plan(self) -> BuildPlan:
        for inst in self.problem.instances:
            self._instance(inst)
        self._attachments()
        world = None
        front: list = []
        if self.physics:
            world, ignored = kautham_world(self.problem, self.masses, StepValues().step,
                                           self.defaults.max_contact_sink)
            self.ignored.extend(ignored)
            front.append(WorldStep(world.parameters))
            if world.step is not None:
                front.append(StepSizeStep(world.step, world.steps_per_cycle, world.rate))
            front.append(ObjectStep(self._ground()))
        warn_once(self.ignored[len(self.problem.ignored):], "gui.core.build")
        return BuildPlan(problem=self.problem, steps=front + self.steps, robots=self.handles,
                         world=world, ignored=self.ignored)

    def _ground(self) -> ObjectSpec:
        taken = {i.name for i in self.problem.instances}
        name, n = GROUND, 1
        while name in taken:
            n += 1
            name = f"{GROUND}_{n}"
        surface = Surface(friction=environment.CAR_FRICTION["ground"]) \
            if self.car_environment else WORLD_SURFACE
        return ObjectSpec(name=name, parameters=(), shape=ShapeKind.PLANE, geometry_only=True,
                          color=environment.GROUND_COLOR, surface=surface)

    # -- instances ----------------------------------------------------------------------------
    def _configuration(self, inst: Instance) -> Tuple[np.ndarray, np.ndarray]:
        """(base pose, joint values) the instance is built at."""
        model = inst.model
        if inst.role == "robot" and self.start_at_query and inst.start is not None:
            return inst.start.base_pose, np.asarray(inst.start.joints, dtype=float)
        return inst.base_pose, model.home()

    def _instance(self, inst: Instance) -> None:
        model = inst.model
        base_pose, built_at = self._configuration(inst)
        poses = model.link_poses(base_pose, built_at)
        static = inst.role == "obstacle" and inst.name not in self.dynamic
        single = len(model.links) == 1
        specs, bodies = [], []
        for link, pose in zip(model.links, poses):
            name = inst.name if single else f"{inst.name}/{link.name}"
            mass = link.mass if link.mass is not None else self.defaults.link_mass
            spec, offset = shape_to_body(name, link.shape, pose, mass, static)
            if not static:
                spec = self._mass_properties(spec, link, name, mass, offset)
                self.masses.append((name, mass))
            specs.append(_with_surface(spec, self._surface(inst, link, name)))
            bodies.append(LinkBody(spec.id, offset))
            self.link_bodies[(inst.name, link.name)] = bodies[-1]
        self.base_bodies[inst.name] = bodies[0]
        if not inst.collision:   # <Collision enabled="false">: the world never pairs it
            specs = [dataclasses.replace(s, no_collisions=True) for s in specs]
        if static or (single and inst.role == "obstacle"):
            self.steps.extend(body_step(s) for s in specs)
            return
        robot = inst.role == "robot"
        held_by_joint = robot and inst.kind == FIXED_BASE and not single \
            and self.problem.format == "current"
        if robot and inst.kind == FIXED_BASE and not single and not held_by_joint:
            # A 2012 robot's base is a fixed (kinematic) body, as Odin always built them: it
            # never moves, whatever the motors push.
            specs[0] = dataclasses.replace(specs[0], fixed=True)
        self.steps.append(EntityStep(EntitySpec(
            name=inst.name,
            objects=tuple(s for s in specs if isinstance(s, ObjectSpec)),
            composites=tuple(s for s in specs if isinstance(s, CompositeSpec)),
            internal_collisions=self.defaults.internal_collisions)))
        handle = RobotHandle(inst, bodies, [], home=model.home(), built_at=built_at,
                             base_pose=base_pose, kind=inst.kind, base_mass=specs[0].mass)
        if not single:
            if held_by_joint:   # Kautham's chain: the base held to the world by a fixed joint
                self.steps.append(JointStep(f"{inst.name}/<base>", inst.name, JointSpec(
                    type=JointType.FIXED, body1=bodies[0].body_id, body2="")))
            self._joints(inst, handle, base_pose, built_at)
        if robot or not single:
            self.handles.append(handle)

    def _surface(self, inst: Instance, link, name: str) -> Surface:
        """The contact surface of ``inst``'s ``link`` (body ``name``): its URDF's, with the
        friction Kautham's car environment gives the body's kind in its problems
        (``environment.CAR_FRICTION``; a URDF friction it overrides is listed as ignored)."""
        if not self.car_environment:
            return link.surface
        kind = "robot" if inst.role == "robot" else \
            "manipulable" if inst.name in environment.MANIPULABLE else "fixed"
        if link.surface.friction is not None:
            self.ignored.append(Ignored(
                link.source, link.line, f'contact friction {link.surface.friction:g} of '
                f'{name}', "Kautham's car environment sets every contact's friction "
                f"({kind}: {environment.CAR_FRICTION[kind]:g})"))
        return dataclasses.replace(link.surface, friction=environment.CAR_FRICTION[kind])

    def _mass_properties(self, spec: BodySpec, link, name: str, mass: float,
                         offset: np.ndarray) -> BodySpec:
        given, ignored = inertia_rule.choose(link, name, mass, offset, self.defaults.inertia,
                                             self.defaults.placeholder_factor)
        if ignored is not None:
            self.ignored.append(ignored)
        if given is None:
            return spec
        return dataclasses.replace(spec, inertia=given.inertia,
                                   center_of_mass=given.center_of_mass)

    # -- joints and motors ---------------------------------------------------------------------
    def _joints(self, inst: Instance, handle: RobotHandle, base_pose: np.ndarray,
                built_at: np.ndarray) -> None:
        model = inst.model
        frames = model.joint_frames(base_pose, built_at)
        value = dict(zip(model.movable_links(), built_at))
        bodies = handle.bodies
        motors, wheels = [], 0
        for i, link in enumerate(model.links):
            if link.parent is None:
                continue
            key = f"{inst.name}/{link.name}"
            parent_id = bodies[link.parent].body_id
            if not link.movable:
                self.steps.append(JointStep(key, inst.name, JointSpec(
                    type=JointType.FIXED, body1=parent_id, body2=bodies[i].body_id)))
                continue
            frame = frames[i]
            if inst.kind == CAR and link.parent == 0 and link.joint == REVOLUTE:
                steering, spin = self._wheel_axes(link, frame, base_pose, wheels)
                joint = _wheel(frame, steering, spin, parent_id, bodies[i].body_id)
                motor_kind, wheels = MotorKind.ANGULAR, wheels + 1
                handle.joint_axes.append(1)         # the URDF's wheel joint is the spin
            else:
                joint = self._joint(link, frame, value[i], parent_id, bodies[i].body_id)
                motor_kind = MotorKind.ANGULAR if link.joint == REVOLUTE else MotorKind.LINEAR
                handle.joint_axes.append(0)
            self.steps.append(JointStep(key, inst.name, joint, limits=link.limits))
            handle.joint_keys.append(key)
            handle.joint_ids.append(joint.default_id)
            drive = self._drive(inst, link)
            handle.max_forces.append(drive.effort)
            handle.max_speeds.append(drive.speed)
            motors.extend(self._motors(key, inst.name, joint, drive, motor_kind))
        self.steps.extend(motors)
        handle.motor_ids = [default_motor_id(j) for j in handle.joint_ids]

    @staticmethod
    def _joint(link, frame: np.ndarray, value: float, parent_id: str, child_id: str
               ) -> JointSpec:
        # ODE measures a hinge's angle (a slider's position) as body1's motion relative to
        # body2; the parent is body1, so the axis is reversed: the world's joint value, its
        # stops and its motor's goal speed then all have the sign of Kautham's joint value.
        axis = -(frame[:3, :3] @ link.axis)
        params = ()
        if link.limits is not None:
            params = ((JointParameter.LO_STOP, 1, float(link.limits[0] - value)),
                      (JointParameter.HI_STOP, 1, float(link.limits[1] - value)))
        return JointSpec(type=JointType.HINGE if link.joint == REVOLUTE else JointType.SLIDER,
                         body1=parent_id, body2=child_id, anchor=_flat(frame[:3, 3]),
                         axis1=_flat(axis), parameters=params)

    def _wheel_axes(self, link, frame: np.ndarray, base_pose: np.ndarray, index: int
                    ) -> Tuple[np.ndarray, np.ndarray]:
        """(steering axis, spin axis), world frame, of the ``index``-th wheel of a car (in its
        link order), as its hinge-2 is sent (module docstring).

        For Kautham's car planner, CarEnvironment's: it sets world axes whatever the car's
        pose or URDF (steering about +z for the first two wheels, -z for the others, spin
        about +y), so a positive wheel speed turns the chassis about +y relative to its wheels
        and rolls the car toward world -x. Otherwise axes the car's own frame gives: steering
        along the base's z, opposite for the wheels ahead of the base's origin along its x and
        for the others (the rear wheels steer against the front ones, as Kautham's four do);
        spin about the wheel joint's axis; both reversed, as a robot's hinges are (a
        hinge-2's angles and rates are body1's turn relative to body2), so a positive
        steering turns the front wheels left (counter-clockwise seen from above) and a
        positive wheel speed turns a wheel about its joint's axis (a car whose wheels turn
        about its y rolls along its +x)."""
        if self.car_environment:
            return np.array((0.0, 0.0, 1.0 if index < 2 else -1.0)), np.array((0.0, 1.0, 0.0))
        ahead = (np.linalg.inv(base_pose) @ np.append(frame[:3, 3], 1.0))[0] > 0.0
        return base_pose[:3, 2] * (-1.0 if ahead else 1.0), -(frame[:3, :3] @ link.axis)

    def _drive(self, inst: Instance, link) -> "_Drive":
        """How a movable joint is driven and resisted: its URDF's limits and ``<dynamics>``;
        under Kautham's own physics no ``<dynamics>`` (its ODE environment never reads it;
        warned), and for the chain of Kautham's chain planner the limits PlanarChainEnvironment
        drives it with, whatever its URDF's."""
        effort, speed, friction, damping = link.effort, link.velocity, link.friction, \
            link.damping
        if self.problem.physics and (friction > 0 or damping > 0):
            self.ignored.append(Ignored(
                link.source, link.line, f'<dynamics> of joint "{link.name}"',
                "Kautham's ODE environment applies no joint friction or damping"))
            friction = damping = 0.0
        if self.chain_drive and inst.kind == FIXED_BASE:
            effort, speed = environment.CHAIN_JOINT_TORQUE, environment.CHAIN_JOINT_SPEED
        return _Drive(effort, speed, friction, damping)

    @staticmethod
    def _motors(key: str, owner: str, joint: JointSpec, drive: "_Drive",
                kind: MotorKind) -> list:
        """The joint's driving motor (``drive.effort`` as its force limit), and the motors
        that give it its friction and damping."""
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

    # -- attachments ---------------------------------------------------------------------------
    def _attachments(self) -> None:
        for a in self.problem.attachments:
            link = self.link_bodies[(a.robot, a.link)]
            obstacle = self.base_bodies[a.obstacle]
            self.steps.append(JointStep(f"{a.robot}/{a.link}+{a.obstacle}", a.robot, JointSpec(
                type=JointType.FIXED, body1=link.body_id, body2=obstacle.body_id)))


def _wheel(frame: np.ndarray, steering: np.ndarray, spin: np.ndarray, parent_id: str,
           child_id: str) -> JointSpec:
    """A car's wheel on a hinge-2 at the wheel joint's origin: the chassis body1, the axes
    (world frame) as given, CarEnvironment's soft suspension along the steering axis."""
    return JointSpec(type=JointType.HINGE2, body1=parent_id, body2=child_id,
                     anchor=_flat(frame[:3, 3]), axis1=_flat(steering), axis2=_flat(spin),
                     parameters=((JointParameter.SUSPENSION_ERP, 1, environment.SUSPENSION_ERP),
                                 (JointParameter.SUSPENSION_CFM, 1, environment.SUSPENSION_CFM)))


def plan_problem(problem: Problem, defaults: BuildDefaults = BuildDefaults()) -> BuildPlan:
    """The plan that builds ``problem`` (module docstring)."""
    return _Planner(problem, defaults).plan()
