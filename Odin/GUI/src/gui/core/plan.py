"""A build plan: the VirtualWorld requests that build a scene, as plain data (ROS-free).

A ``BuildPlan`` is an ordered list of steps, each wrapping one request (``WorldStep``: Set
World, ``StepSizeStep``: Set Step, ``EntityStep``: EntitySpec, ``ObjectStep``: ObjectSpec,
``CompositeStep``: CompositeSpec, ``JointStep``: JointSpec, ``MotorStep``: MotorSpec), plus, per
robot, what paths and controls need to drive it (``RobotHandle``). ``gui.core.translate``
makes the plan of a loaded Kautham problem.

Every step answers the same calls:
- ``owner``: the robot or obstacle it belongs to (None: a scene object or the world);
- ``bodies``: the object and composite specs it builds;
- ``label()``: one line for a progress listing;
- ``describe()``: {"bodies": [...], "joints": [...]}, problem_info's JSON;
- ``entries(answer)``: the ``StepEntry`` lines it adds to a listing of what was built, given
  the world's answer to it;
- ``send(world, ids)``: makes its request through ``world`` (a
  ``gui.core.world_port.WorldPort``: a world node's or a Core's), records the world's IDs in
  ``ids`` (``BuiltIds``) and returns the world's answer (an ID).
``gui.core.world_port.build(world, plan)`` sends a whole plan.

Units are SI (m, rad, kg, s); positions and quaternions (w, x, y, z) are world frame unless
said otherwise; a pose is a (4, 4) homogeneous array (``gui.core.kinematics``).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar, Dict, List, NamedTuple, Optional, Tuple, Union

import numpy as np

from gui.core.kinematics import pose_to_position_quaternion
from gui.core.model import Configuration, Instance, Problem
from odin_common.interface import JointType
from odin_common.specs import CompositeSpec, EntitySpec, JointSpec, MotorSpec, ObjectSpec

if TYPE_CHECKING:
    # only a type: the plan carries the settings its maker chose, and the module that makes
    # them reads Kautham's environment, which the plan's vocabulary must not depend on
    from gui.core.world_settings import WorldSettings

BodySpec = Union[ObjectSpec, CompositeSpec]

SCENE_OBJECTS = "Scene objects"
"""The listing section of objects that belong to no robot (``StepEntry.section``)."""


@dataclass
class BuiltIds:
    """The world's answers so far while a plan is sent: planned body ID -> world ID, joint key
    ("robot/link") -> world joint ID, joint key -> world motor ID (a joint's friction and
    damping motors under "key#friction", "key#damping")."""
    bodies: Dict[str, str] = field(default_factory=dict)
    joints: Dict[str, str] = field(default_factory=dict)
    motors: Dict[str, str] = field(default_factory=dict)

    def as_dict(self) -> dict:
        """{"bodies": {...}, "joints": {...}, "motors": {...}} (for JSON)."""
        return {"bodies": self.bodies, "joints": self.joints, "motors": self.motors}


class StepEntry(NamedTuple):
    """One line of a listing of what a step built: under its owner's ``section`` ("Links",
    "Joints", "Motors"; ``SCENE_OBJECTS`` for a step without owner), a short ``name`` and the
    ``world_id``."""
    section: str
    name: str
    world_id: str


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


def _short_value(value) -> str:
    if isinstance(value, (tuple, list)):
        return "(" + ", ".join(f"{v:g}" for v in value) + ")"
    return f"{value:g}" if isinstance(value, float) else str(value)


@dataclass(frozen=True)
class ServoCommand:
    """Set Servo's lists, one value per motor axis (motors in order)."""
    motors: Tuple[str, ...]
    targets: Tuple[float, ...]
    rates: Tuple[float, ...] = ()
    gains: Tuple[float, ...] = ()
    max_speeds: Tuple[float, ...] = ()
    max_forces: Tuple[float, ...] = ()

    def request_fields(self) -> dict:
        """The Set Servo request's fields (lists)."""
        return dict(motors=list(self.motors), targets=list(self.targets),
                    rates=list(self.rates), gains=list(self.gains),
                    max_speeds=list(self.max_speeds), max_forces=list(self.max_forces))


# ---------------------------------------------------------------------------------- steps

@dataclass(frozen=True, eq=False)
class WorldStep:
    """Set World with ``parameters`` {name: value} (odin_common.world_parameters names, SI);
    ``own``: the names the problem sets itself (the others are defaults)."""
    parameters: dict
    own: Tuple[str, ...] = ()
    owner: ClassVar[Optional[str]] = None
    bodies: ClassVar[Tuple[BodySpec, ...]] = ()

    def label(self) -> str:
        """"world name=value, ... (n more at their defaults)": the problem's own values."""
        own = [k for k in self.parameters if k in self.own]
        rest = len(self.parameters) - len(own)
        if not own:
            return f"world: all {rest} parameters at their defaults"
        shown = ", ".join(f"{k}={_short_value(self.parameters[k])}" for k in own)
        return f"world {shown}" + (f" ({rest} more at their defaults)" if rest else "")

    def describe(self) -> dict:
        """No bodies, no joints."""
        return {"bodies": [], "joints": []}

    def entries(self, answer) -> List[StepEntry]:
        """One "World" line per parameter the problem sets, with its value (the defaults
        are not listed)."""
        return [StepEntry("World", name, _short_value(value))
                for name, value in self.parameters.items() if name in self.own]

    def send(self, world, ids: BuiltIds) -> str:
        """Pauses the world, then sets the parameters; answers "set". A problem is built,
        and left, at its start: a running world would let links fall while the requests that
        join them are still on their way, and a plan replays from the state it started from
        (the Sphere's, landed after the seconds between the load and the replay, ended 0.69 m
        from a goal its plan reached within 0.25 m)."""
        world.pause()
        world.set_world(**self.parameters)
        return "set"


@dataclass(frozen=True, eq=False)
class StepSizeStep:
    """Set Step: ``step`` s, ``steps_per_cycle``, ``rate`` Hz; ``own``: the problem's values
    (False: the defaults)."""
    step: float
    steps_per_cycle: int
    rate: float
    own: bool = True
    owner: ClassVar[Optional[str]] = None
    bodies: ClassVar[Tuple[BodySpec, ...]] = ()

    def label(self) -> str:
        """"step h s, n per cycle, r Hz"."""
        return (f"step {self.step:g} s, {self.steps_per_cycle} per cycle, "
                f"{self.rate:.4g} Hz")

    def describe(self) -> dict:
        """No bodies, no joints."""
        return {"bodies": [], "joints": []}

    def entries(self, answer) -> List[StepEntry]:
        """One "World" line: the step, when it is the problem's."""
        return [StepEntry("World", "step", f"{self.step:g} s")] if self.own else []

    def send(self, world, ids: BuiltIds) -> str:
        """Sets the step; answers the step the world took ("h s")."""
        values = world.set_step(step=self.step, steps_per_cycle=self.steps_per_cycle,
                                 rate=self.rate)
        return f"{values.step:g} s"


@dataclass(frozen=True, eq=False)
class EntityStep:
    """Build Entity: a robot's (or movable obstacle's) links, all or nothing."""
    spec: EntitySpec

    @property
    def owner(self) -> Optional[str]:
        """The robot or obstacle the step belongs to (the entity's name)."""
        return self.spec.name

    @property
    def bodies(self) -> Tuple[BodySpec, ...]:
        """The entity's objects, then its composites."""
        return self.spec.members

    def label(self) -> str:
        """"entity name: n bodies, t triangles"."""
        members = self.spec.members
        triangles = sum(m.triangle_count for m in members)
        return f"entity {self.spec.name}: {len(members)} bodies, {triangles} triangles"

    def describe(self) -> dict:
        """Every member body, with the entity's name."""
        name = self.spec.name
        return {"bodies": [_object_description(o, name) for o in self.spec.objects]
                + [_composite_description(c, name) for c in self.spec.composites],
                "joints": []}

    def entries(self, answer: str) -> List[StepEntry]:
        """One "Links" line per member (its planned ID)."""
        return [StepEntry("Links", _short(m.id), m.id) for m in self.spec.members]

    def send(self, world, ids: BuiltIds) -> str:
        """Builds the entity, records its members' world IDs; answers the entity's name."""
        built = world.build_entity(self.spec)
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
        """The object."""
        return (self.spec,)

    def label(self) -> str:
        """"object name (t triangles)"."""
        return f"object {self.spec.name} ({self.spec.triangle_count} triangles)"

    def describe(self) -> dict:
        """The object, in no entity."""
        return {"bodies": [_object_description(self.spec, None)], "joints": []}

    def entries(self, answer: str) -> List[StepEntry]:
        """One ``SCENE_OBJECTS`` line."""
        return [StepEntry(SCENE_OBJECTS, self.spec.id, str(answer))]

    def send(self, world, ids: BuiltIds) -> str:
        """Builds the object; records and answers its world ID."""
        world_id = ids.bodies[self.spec.id] = world.build_object(self.spec)
        return world_id


@dataclass(frozen=True, eq=False)
class CompositeStep:
    """Build Composite: a scene object made of several shapes."""
    spec: CompositeSpec
    owner: ClassVar[Optional[str]] = None

    @property
    def bodies(self) -> Tuple[BodySpec, ...]:
        """The composite."""
        return (self.spec,)

    def label(self) -> str:
        """"composite ID (n parts)"."""
        return f"composite {self.spec.id} ({len(self.spec.parts)} parts)"

    def describe(self) -> dict:
        """The composite, in no entity."""
        return {"bodies": [_composite_description(self.spec, None)], "joints": []}

    def entries(self, answer: str) -> List[StepEntry]:
        """One ``SCENE_OBJECTS`` line, named after its first part."""
        parts = self.spec.parts
        return [StepEntry(SCENE_OBJECTS, f"{_short(parts[0].name, '#')} ({len(parts)} parts)",
                          str(answer))]

    def send(self, world, ids: BuiltIds) -> str:
        """Builds the composite; records and answers its world ID."""
        world_id = ids.bodies[self.spec.id] = world.build_composite(self.spec)
        return world_id


@dataclass(frozen=True, eq=False)
class JointStep:
    """Set Joint (create) between two links. ``key`` names it in the plan ("robot/link");
    the spec's bodies are planned IDs, replaced by the world's when sent; its anchor (m) and
    axes are world frame. ``limits``: the joint's range as the robot model states it (rad or
    m; None: unlimited or a fixed joint), for descriptions: the stops sent are relative to the
    value the joint is built at."""
    key: str
    owner: str
    spec: JointSpec
    limits: Optional[Tuple[float, float]] = None

    bodies: ClassVar[Tuple[BodySpec, ...]] = ()

    def label(self) -> str:
        """"joint key (type)"."""
        return f"joint {self.key} ({JointType(self.spec.type).label})"

    def kinematic_axis(self) -> list:
        """The joint's axis (world frame) as the robot model states it (Kautham's sign): a
        robot's hinges and sliders are sent to the world with the axis reversed
        (``gui.core.translate.joints.link_joint``)."""
        spec = self.spec
        if spec.type in (JointType.HINGE, JointType.SLIDER) and spec.body1:
            return [-v for v in spec.axis1]
        return list(spec.axis1)

    def describe(self) -> dict:
        """The joint: type, parent and child bodies, anchor, axis (Kautham's sign), limits."""
        spec, limits = self.spec, self.limits
        return {"bodies": [], "joints": [dict(
            name=self.key, type=JointType(spec.type).label, parent=spec.body1 or None,
            child=spec.body2, anchor=list(spec.anchor), axis=self.kinematic_axis(),
            limits=None if limits is None else [limits[0], limits[1]])]}

    def entries(self, answer: str) -> List[StepEntry]:
        """One "Joints" line."""
        return [StepEntry("Joints", _short(self.key), str(answer))]

    def send(self, world, ids: BuiltIds) -> str:
        """Creates the joint between the bodies' world IDs; records and answers its ID."""
        spec = self.spec
        spec = dataclasses.replace(spec, body1=ids.bodies.get(spec.body1, spec.body1),
                                   body2=ids.bodies.get(spec.body2, spec.body2))
        world_id = ids.joints[self.key] = world.add_joint(spec)
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
        """"motor on key" (or "friction on key", "damping on key")."""
        return f"{self.purpose or 'motor'} on {self.joint_key}"

    def describe(self) -> dict:
        """No bodies, no joints."""
        return {"bodies": [], "joints": []}

    def entries(self, answer: str) -> List[StepEntry]:
        """One "Motors" line."""
        name = _short(self.joint_key) + (f" ({self.purpose})" if self.purpose else "")
        return [StepEntry("Motors", name, str(answer))]

    def send(self, world, ids: BuiltIds) -> str:
        """Adds the motor on the joint's world ID and sets its parameters; records and answers
        its ID."""
        joint = ids.joints[self.joint_key]
        spec = dataclasses.replace(self.spec, joint=joint, id=self.spec.id and (
            f"{self.purpose}:{joint}" if self.purpose else self.spec.id))
        world_id = ids.motors[self.key] = world.add_motor(spec)
        if self.parameters:
            world.set_joint_parameters(world_id, self.parameters)
        return world_id


@dataclass(frozen=True, eq=False)
class HoldStep:
    """Set Servo that holds robot ``owner`` where it was built: each joint's driving motor
    (the MotorSteps of ``joint_keys``) a servo toward 0, the value the world reads at the
    built pose, at no feed-forward rate, ``max_speeds`` rad/s or m/s. A motor at zero speed
    alone lets an arm creep (its position error is never corrected: 3.3 mm in 10 s for the
    KUKA LWR); a servo holds it. A Set Velocity of a motor, or a Set Position of the robot,
    then takes over (docs/INTERFACE.md)."""
    owner: str
    joint_keys: Tuple[str, ...]
    max_speeds: Tuple[float, ...]
    bodies: ClassVar[Tuple[BodySpec, ...]] = ()

    def label(self) -> str:
        """"hold robot: n servos at the built pose"."""
        return f"hold {self.owner}: {len(self.joint_keys)} servos at the built pose"

    def describe(self) -> dict:
        """No bodies, no joints."""
        return {"bodies": [], "joints": []}

    def entries(self, answer) -> List[StepEntry]:
        """Nothing new to list (the motors are listed)."""
        return []

    def send(self, world, ids: BuiltIds) -> str:
        """Sets the servos on the world's motor IDs; answers "held"."""
        zeros = (0.0,) * len(self.joint_keys)
        world.set_servo(ServoCommand(tuple(ids.motors[k] for k in self.joint_keys), zeros,
                                      rates=zeros, max_speeds=self.max_speeds))
        return "held"


PlanStep = Union[WorldStep, StepSizeStep, EntityStep, ObjectStep, CompositeStep, JointStep,
                 MotorStep, HoldStep]


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

    ``base_pose`` (4, 4, world frame) and ``built_at`` (rad / m per movable joint): the
    configuration the robot was built in (the world's joint readings are relative to
    ``built_at``); ``home``: Home's joint values. ``kind``: gui.core.model's robot kind.
    ``max_forces`` / ``max_speeds``: per movable joint, its effort (N m or N) and speed
    (rad/s or m/s) limits (None: none given). ``joint_axes``: per movable joint, which of its
    world joint's values is the joint's (0; a car's wheel is its hinge-2's spin, 1).
    ``base_mass``: kg, the base body's mass. ``base_held``: the base is built kinematic where
    it stands (a free-flying or mobile robot without Kautham's physics): its velocity moves
    it, forces do not."""
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
    base_held: bool = False

    def __post_init__(self):
        if self.built_at is None:
            self.built_at = np.array(self.home, dtype=float)
        if self.base_pose is None:
            self.base_pose = self.instance.base_pose

    @property
    def name(self) -> str:
        """The robot's instance name."""
        return self.instance.name

    @property
    def start(self) -> Optional[Configuration]:
        """The query's start (None: no query)."""
        return self.instance.start

    @property
    def goal(self) -> Optional[Configuration]:
        """The query's goal (None: no query)."""
        return self.instance.goal

    def situations(self, values, base_pose: Optional[np.ndarray] = None) -> list:
        """(body ID, position m, quaternion (w, x, y, z)), world frame, of every link for joint
        ``values`` (rad / m), the base where the robot was built (or at ``base_pose``)."""
        base = self.base_pose if base_pose is None else base_pose
        poses = self.instance.model.link_poses(base, values)
        out = []
        for T, body in zip(poses, self.bodies):
            position, quaternion = pose_to_position_quaternion(T @ body.offset)
            out.append((body.body_id, position, quaternion))
        return out


HOLD = "<hold>"
"""The last part of the key of a JointStep that holds an obstacle's body to the world where the
problem puts it (``BuildPlan.holds``)."""


@dataclass
class BuildPlan:
    """Steps in the order they must be sent (WorldStep, StepSizeStep, EntityStep, ObjectStep,
    CompositeStep, JointStep, MotorStep). ``world``: the world settings the plan sets (every
    world parameter and step value); ``physics``: whether they and a ground plane are
    Kautham's physics; ``ignored``: the problem's, and what the plan set aside
    (``gui.core.model.Ignored``)."""
    problem: Problem
    steps: list
    robots: list                     # RobotHandle per robot (and per movable multi-link obstacle)
    world: "WorldSettings"
    physics: bool = False
    ignored: list = field(default_factory=list)

    def set_world(self, world: "WorldSettings") -> None:
        """The plan sets ``world`` instead (its Set World and Set Step steps replaced)."""
        self.world = world
        replaced = {WorldStep: WorldStep(world.parameters, world.own_parameters),
                    StepSizeStep: StepSizeStep(world.step, world.steps_per_cycle, world.rate,
                                               "step" in world.own)}
        self.steps = [replaced.get(type(s), s) for s in self.steps]

    def counts(self) -> dict:
        """{step class name: how many}."""
        out: dict = {}
        for step in self.steps:
            out[type(step).__name__] = out.get(type(step).__name__, 0) + 1
        return out

    def bodies(self) -> List[BodySpec]:
        """Every object and composite the plan builds (entities' members included), in order."""
        return [body for step in self.steps for body in step.bodies]

    def holds(self) -> Dict[str, str]:
        """{obstacle body ID: world ID of the FIXED joint that holds it where the problem puts
        it} (``HOLD``: a geometric problem's obstacle body, which only an attachment moves)."""
        return {s.spec.body1: s.spec.default_id for s in self.steps
                if isinstance(s, JointStep) and s.key.endswith("/" + HOLD)}

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
