"""What the Core keeps about each thing it built (records, private to the Core) and what it
answers (results, frozen).

Frames: an object's frame is the pose its spec gives (its geometry's origin); ODE's body sits
at the centre of mass ``com`` (in the object frame), with the object's axes.
"""
from __future__ import annotations

from typing import List, NamedTuple, Optional, Sequence, Set, Tuple

import numpy as np

from odin_common.interface import JointType, MotorKind
from virtual_world.core.shapes import Shape
from virtual_world.ode.handles import Owner


# ---------------------------------------------------------------------------------- results

class BuiltGeometry(NamedTuple):
    """One geometry as built: name, the shape's Object/Part parameters and indices (m, its
    own frame: flat tuples, or read-only flat float64 and uint32 arrays when they were given
    as such), colour (RGBA), its world pose (m; quaternion (w, x, y, z)) right after the
    build, and the shape as asked (odin_common.interface.Shape). What a Viewer needs."""
    name: str
    parameters: Sequence[float]
    indices: Sequence[int]
    color: Tuple[float, ...]
    position: Tuple[float, float, float]
    orientation: Tuple[float, float, float, float]
    shape: int = 0


class Built(NamedTuple):
    """What one build made: the object's id and its geometries."""
    id: str
    geometries: Tuple[BuiltGeometry, ...]


class BuiltEntity(NamedTuple):
    """What Build Entity made: the entity's name and its members, objects first."""
    name: str
    members: Tuple[Built, ...]

    @property
    def ids(self) -> List[str]:
        return [member.id for member in self.members]

    @property
    def geometries(self) -> Tuple[BuiltGeometry, ...]:
        return tuple(g for member in self.members for g in member.geometries)


class Removed(NamedTuple):
    """Every id that went away with a removal (the Viewer drops the geometry names)."""
    joints: Tuple[str, ...] = ()
    motors: Tuple[str, ...] = ()
    forces: Tuple[str, ...] = ()
    geometries: Tuple[str, ...] = ()

    def __add__(self, other: "Removed") -> "Removed":
        return Removed(*(a + b for a, b in zip(self, other)))


class JointState(NamedTuple):
    """positions (rad or m) and rates (rad/s or m/s) per joint axis, as
    odin_common.interface.JOINT_STATE_AXES lists them; none for ball/fixed/plane2d."""
    id: str
    type: int
    positions: Tuple[float, ...]
    rates: Tuple[float, ...]


class Collision(NamedTuple):
    """Two colliding geometries (names, sorted), the deepest penetration depth (m), up to 8
    contact points (world, m) of the deepest occurrence and, where the Core knows it, the
    simulated time (s) the pair was first seen (NaN otherwise). Per point: the contact normal
    (unit, world: the direction the contact pushes ``first``) and, under the contact policy,
    the contact's force on ``first`` (N, world; empty when no contact joint was made)."""
    first: str
    second: str
    depth: float
    points: Tuple[Tuple[float, float, float], ...]
    first_time: float = float("nan")
    normals: Tuple[Tuple[float, float, float], ...] = ()
    forces: Tuple[Tuple[float, float, float], ...] = ()


class ObjectState(NamedTuple):
    """An object's state and mass: BodyState's fields, then mass (kg), centre of mass (m, the
    object's frame) and inertia (3 x 3 kg m^2 about the centre of mass, object axes, row by
    row)."""
    id: str
    position: Tuple[float, float, float]
    orientation: Tuple[float, float, float, float]
    linear: Tuple[float, float, float]
    angular: Tuple[float, float, float]
    mass: float
    center_of_mass: Tuple[float, float, float]
    inertia: Tuple[float, ...]


class JointReaction(NamedTuple):
    """A joint's state (JointState's positions and rates) and what it applied in the last
    step: force (N) and torque (N m) on its first and second body, world frame."""
    id: str
    type: int
    positions: Tuple[float, ...]
    rates: Tuple[float, ...]
    force1: Tuple[float, float, float]
    torque1: Tuple[float, float, float]
    force2: Tuple[float, float, float]
    torque2: Tuple[float, float, float]


class MotorState(NamedTuple):
    """A motor's goal speeds (rad/s or m/s) and maximum forces (N m or N; inf: unlimited),
    per axis, and the joint it drives ("" for none)."""
    id: str
    joint: str
    goals: Tuple[float, ...]
    max_forces: Tuple[float, ...]


class Divergence(NamedTuple):
    """A body the divergence guard found gone wrong after a step and parked: the object, why,
    the value that broke the bound (NaN when a value was not finite), its position (m),
    velocity (m/s) and angular velocity (rad/s) as the step left them (world frame, centre of
    mass), and the simulated time of that step (s)."""
    id: str
    reason: str
    value: float
    position: Tuple[float, float, float]
    velocity: Tuple[float, float, float]
    angular: Tuple[float, float, float]
    time: float


class BodyState(NamedTuple):
    """An object's state: position of its frame's origin (m), orientation (w, x, y, z),
    linear velocity of its centre of mass (m/s), angular velocity (rad/s); world frame."""
    id: str
    position: Tuple[float, float, float]
    orientation: Tuple[float, float, float, float]
    linear: Tuple[float, float, float]
    angular: Tuple[float, float, float]


class Propagation(NamedTuple):
    """What a propagation did: it ran ``steps`` steps of ``step_size`` s from ``start_time``
    (simulated s), ended in ``states`` (every object with a body), met ``collisions`` (each
    pair once, deepest, with the time first seen), in ``wall_time`` s of this machine; ``kept``
    says whether the world stayed in the final state; ``state``: the final state as
    ``Core.body_state_vector`` gives it (float64 vector)."""
    start_time: float
    step_size: float
    steps: int
    states: Tuple[BodyState, ...]
    collisions: Tuple[Collision, ...]
    wall_time: float
    kept: bool
    state: np.ndarray


class StatePropagation(NamedTuple):
    """What a planner's propagation (``Core.propagate_state``) did: ``state`` the body state
    vector reached (float64, ``Core.body_state_vector``'s layout); ``pairs`` the geometry pairs
    (names, sorted within and between pairs) that collided on the way; ``steps`` the steps
    taken."""
    state: np.ndarray
    pairs: Tuple[Tuple[str, str], ...]
    steps: int


# ---------------------------------------------------------------------------------- records

class GeometryRecord:
    """One ODE geom: its owner, the object it belongs to and its pose in the object frame."""
    __slots__ = ("name", "owner", "object_id", "position", "orientation", "shape",
                 "parameters", "indices", "color", "shape_asked", "surface")

    def __init__(self, name: str, owner: Owner, object_id: str, position: np.ndarray,
                 orientation: np.ndarray, shape: Shape, parameters, indices, color,
                 shape_asked: int = 0, surface=None):
        self.name = name
        self.owner = owner
        self.object_id = object_id
        self.position = position        # (3,) m, object frame
        self.orientation = orientation  # (4,) wxyz, object frame
        self.shape = shape
        self.parameters = parameters    # as given (the Viewer draws the given mesh)
        self.indices = indices
        self.color = color
        self.shape_asked = shape_asked  # odin_common.interface.Shape, as the spec gave it
        self.surface = surface          # odin_common.specs.Surface


class ObjectRecord:
    """One object: its body (None for geometry only), geometries and what hangs on it."""
    __slots__ = ("id", "spec", "body", "geometries", "com", "fixed", "joints", "motors",
                 "forces", "entity")

    def __init__(self, object_id: str, spec, body: Optional[Owner], com: np.ndarray,
                 fixed: bool):
        self.id = object_id
        self.spec = spec
        self.body = body
        self.geometries: List[GeometryRecord] = []
        self.com = com                    # (3,) m, centre of mass in the object frame
        self.fixed = fixed
        self.joints: Set[str] = set()
        self.motors: Set[str] = set()
        self.forces: Set[str] = set()
        self.entity: Optional[str] = None


class JointRecord:
    __slots__ = ("id", "type", "owner", "bodies", "motors", "forces")

    def __init__(self, joint_id: str, joint_type: JointType, owner: Owner,
                 bodies: Tuple[str, str]):
        self.id = joint_id
        self.type = joint_type
        self.owner = owner
        self.bodies = bodies              # (body1 id or "", body2 id or "")
        self.motors: Set[str] = set()
        self.forces: Set[str] = set()


class Servo(NamedTuple):
    """A motor's servo (core.motors.set_servos): per axis, the target (rad or m, the driven
    joint's reported units), a feed-forward rate (rad/s or m/s), the gain (1/s) and the speed
    limit (rad/s or m/s)."""
    targets: Tuple[float, ...]
    rates: Tuple[float, ...]
    gains: Tuple[float, ...]
    max_speeds: Tuple[float, ...]


class ServoState(NamedTuple):
    """A servo's targets, the joint's values when the last step began, and the errors (target
    minus value), per axis (rad or m)."""
    id: str
    targets: Tuple[float, ...]
    positions: Tuple[float, ...]
    errors: Tuple[float, ...]


class MotorRecord:
    __slots__ = ("id", "owner", "kind", "naxes", "joint", "bodies", "velocity",
                 "on_joint_axes", "servo")

    def __init__(self, motor_id: str, owner: Owner, kind: MotorKind, naxes: int,
                 joint: Optional[str], bodies: Tuple[str, str], on_joint_axes: bool = False):
        self.id = motor_id
        self.owner = owner
        self.kind = kind
        self.naxes = naxes
        self.joint = joint
        self.bodies = bodies
        self.velocity: List[float] = [0.0] * naxes   # goal speeds, rad/s or m/s
        self.on_joint_axes = on_joint_axes           # its axes are its joint's own
        self.servo: Optional[Servo] = None           # position targets instead of speeds


class BodyForceRecord(NamedTuple):
    """A persistent force or torque on an object's body (see forces.add_body_force)."""
    object_id: str
    kind: int
    vector_in_body_frame: bool
    at_point: bool
    point_in_body_frame: bool
    vector: np.ndarray
    point: np.ndarray               # ODE body frame (centre of mass) when point_in_body_frame


class JointForceRecord(NamedTuple):
    joint_id: str
    magnitudes: np.ndarray
