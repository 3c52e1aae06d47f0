"""The VirtualWorld Core (thesis chapter 5): ROS-free rigid-body simulation over ODE.

The Core owns every ODE handle (through ``virtual_world.handles``), validates every argument
before any ODE call (ODE ends the process on bad input: an error raised here means nothing
changed), and runs the per-step hot work in C (``odin_step.c``): collisions with the
near-callback, persistent forces, joint forces and motor goals, the step, emptying contacts.

Conventions: SI units; positions and vectors in the world frame unless said; quaternions
(w, x, y, z) as ODE orders them. A quaternion whose norm is within 1e-4 of 1 is accepted and
normalised; a zero, non-finite or farther-off one is an error.

Frames: an object's frame is the one its ObjectSpec/CompositeSpec pose gives (its geometry's
origin). ODE's body sits at the centre of mass, so "body frame" in this API means the object's
frame (same axes; points are shifted by the centre of mass for ODE). Linear velocities are those
of the centre of mass.

Fixed bodies are ODE kinematic bodies (dBodySetKinematic): infinite mass for contacts and joints,
never moved by forces; they stay where set_poses puts them, so no reset after the step is needed.

Thread safety: every public method holds one re-entrant lock (rospy runs service callbacks in
their own threads).
"""
from __future__ import annotations

import functools
import logging
import math
import threading
from dataclasses import dataclass, field
from typing import (Dict, List, Mapping, NamedTuple, Optional, Sequence, Set, Tuple)

import numpy as np

from odin_common.meshes import cluster_vertices
from virtual_world import handles
from virtual_world.errors import (Closed, CoreError, DuplicateName, InvalidArgument,
                                  OdeConfigurationError, Unsupported, UnknownName)
from virtual_world.mass import mesh_mass
from virtual_world.ode.bindings import ffi, lib
from virtual_world.parameters import QUICKSTEP, WORLDSTEP, WorldParameters

__all__ = [
    "Core", "ObjectSpec", "PartSpec", "CompositeSpec", "Removed", "JointState", "Collision",
    "WorldParameters", "QUICKSTEP", "WORLDSTEP",
    "BALL", "HINGE", "SLIDER", "PISTON", "UNIVERSAL", "HINGE2", "PR", "PU", "FIXED", "PLANE2D",
    "LO_STOP", "HI_STOP", "BOUNCE", "CFM", "ERP", "STOP_ERP", "STOP_CFM", "SUSPENSION_ERP",
    "SUSPENSION_CFM", "FUDGE_FACTOR", "VELOCITY", "MAX_FORCE", "ANGULAR", "LINEAR", "FORCE",
    "TORQUE",
]

log = logging.getLogger("virtual_world.core")

# joint types (the service interface's numbering)
BALL, HINGE, SLIDER, PISTON, UNIVERSAL, HINGE2, PR, PU, FIXED, PLANE2D = range(10)
JOINT_TYPE_NAMES = ("ball", "hinge", "slider", "piston", "universal", "hinge2", "pr", "pu",
                    "fixed", "plane2d")
# joint parameters
(LO_STOP, HI_STOP, BOUNCE, CFM, ERP, STOP_ERP, STOP_CFM, SUSPENSION_ERP, SUSPENSION_CFM,
 FUDGE_FACTOR, VELOCITY, MAX_FORCE) = range(12)
PARAMETER_NAMES = ("lo_stop", "hi_stop", "bounce", "cfm", "erp", "stop_erp", "stop_cfm",
                   "suspension_erp", "suspension_cfm", "fudge_factor", "velocity", "max_force")
# motors and forces
ANGULAR, LINEAR = 0, 1
FORCE, TORQUE = 0, 1

_ODE_PARAM = {  # Odin parameter -> ODE dParam* (values from ODE's header via cffi)
    LO_STOP: lib.dParamLoStop, HI_STOP: lib.dParamHiStop, BOUNCE: lib.dParamBounce,
    CFM: lib.dParamCFM, ERP: lib.dParamERP, STOP_ERP: lib.dParamStopERP,
    STOP_CFM: lib.dParamStopCFM, SUSPENSION_ERP: lib.dParamSuspensionERP,
    SUSPENSION_CFM: lib.dParamSuspensionCFM, FUDGE_FACTOR: lib.dParamFudgeFactor,
    VELOCITY: lib.dParamVel, MAX_FORCE: lib.dParamFMax,
}
_ODE_JOINT_TYPE = {
    BALL: lib.dJointTypeBall, HINGE: lib.dJointTypeHinge, SLIDER: lib.dJointTypeSlider,
    PISTON: lib.dJointTypePiston, UNIVERSAL: lib.dJointTypeUniversal,
    HINGE2: lib.dJointTypeHinge2, PR: lib.dJointTypePR, PU: lib.dJointTypePU,
    FIXED: lib.dJointTypeFixed, PLANE2D: lib.dJointTypePlane2D,
}
_CREATE = {
    BALL: lib.dJointCreateBall, HINGE: lib.dJointCreateHinge, SLIDER: lib.dJointCreateSlider,
    PISTON: lib.dJointCreatePiston, UNIVERSAL: lib.dJointCreateUniversal,
    HINGE2: lib.dJointCreateHinge2, PR: lib.dJointCreatePR, PU: lib.dJointCreatePU,
    FIXED: lib.dJointCreateFixed, PLANE2D: lib.dJointCreatePlane2D,
}
_AXES_USED = {  # which of axis1..axis3 each joint type reads
    BALL: (), HINGE: ("axis1",), SLIDER: ("axis1",), PISTON: ("axis1",),
    UNIVERSAL: ("axis1", "axis2"), HINGE2: ("axis1", "axis2"), PR: ("axis1", "axis2"),
    PU: ("axis1", "axis2", "axis3"), FIXED: (), PLANE2D: (),
}
_SET_PARAM = {
    BALL: lib.dJointSetBallParam, HINGE: lib.dJointSetHingeParam,
    SLIDER: lib.dJointSetSliderParam, PISTON: lib.dJointSetPistonParam,
    UNIVERSAL: lib.dJointSetUniversalParam, HINGE2: lib.dJointSetHinge2Param,
    PR: lib.dJointSetPRParam, PU: lib.dJointSetPUParam, FIXED: lib.dJointSetFixedParam,
}
# parameter groups (axes) per joint type, and the parameters each accepts
_LIMIT_PARAMS = frozenset({LO_STOP, HI_STOP, BOUNCE, CFM, ERP, STOP_ERP, STOP_CFM, FUDGE_FACTOR,
                           VELOCITY, MAX_FORCE})
_JOINT_PARAM_AXES = {BALL: 1, HINGE: 1, SLIDER: 1, PISTON: 2, UNIVERSAL: 2, HINGE2: 2, PR: 2,
                     PU: 3, FIXED: 1}
_JOINT_PARAMS = {
    BALL: frozenset({CFM, ERP}), FIXED: frozenset({CFM, ERP}),
    HINGE: _LIMIT_PARAMS, SLIDER: _LIMIT_PARAMS, PISTON: _LIMIT_PARAMS,
    UNIVERSAL: _LIMIT_PARAMS, PR: _LIMIT_PARAMS, PU: _LIMIT_PARAMS,
    HINGE2: _LIMIT_PARAMS | {SUSPENSION_ERP, SUSPENSION_CFM},
}
# magnitudes a joint force takes per type (see add_joint_force)
_JOINT_FORCE_AXES = {BALL: 3, HINGE: 1, SLIDER: 1, PISTON: 1, UNIVERSAL: 2, HINGE2: 2, PR: 2,
                     PU: 2}

QUATERNION_TOLERANCE = 1e-4
"""A quaternion is accepted (and normalised) when | |q| - 1 | <= this."""


# ---------------------------------------------------------------------------------- results


@dataclass(frozen=True)
class ObjectSpec:
    """One object: a body with one geometry (or a body-less static geometry).

    parameters: the shape, by count: 1 sphere radius; 2 cylinder radius, length (along z);
        3 box sides x, y, z; >= 9 and a multiple of 3: mesh vertices (x, y, z, ...), m, with
        `indices` (3 per triangle). Anything else is an error.
    mass: kg > 0. inertia: () for the shape's own, or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] kg m^2
        about the object's origin, object axes (then the centre of mass is the origin).
    position (m, world), orientation (wxyz): the object's frame. color: RGBA in [0, 1].
    fixed: a kinematic body that never moves by itself. geometry_only: no body (static).
    no_collisions: its geometry collides with nothing (Kautham's <Collision Enable="false">).
    """
    name: str
    parameters: Sequence[float]
    indices: Sequence[int] = ()
    mass: float = 1.0
    inertia: Sequence[float] = ()
    position: Sequence[float] = (0.0, 0.0, 0.0)
    orientation: Sequence[float] = (1.0, 0.0, 0.0, 0.0)
    color: Sequence[float] = (0.0, 0.0, 0.0, 0.0)
    fixed: bool = False
    geometry_only: bool = False
    no_collisions: bool = False


@dataclass(frozen=True)
class PartSpec:
    """One geometry of a composite; pose in the composite's frame; shape as in ObjectSpec."""
    name: str
    parameters: Sequence[float]
    indices: Sequence[int] = ()
    mass: float = 1.0
    position: Sequence[float] = (0.0, 0.0, 0.0)
    orientation: Sequence[float] = (1.0, 0.0, 0.0, 0.0)
    color: Sequence[float] = (0.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class CompositeSpec:
    """Parts on one body; the composite's id is ">part1>part2...". Pose of its frame, world.
    no_collisions: none of its parts collides with anything."""
    parts: Sequence[PartSpec]
    position: Sequence[float] = (0.0, 0.0, 0.0)
    orientation: Sequence[float] = (1.0, 0.0, 0.0, 0.0)
    fixed: bool = False
    geometry_only: bool = False
    no_collisions: bool = False


class Removed(NamedTuple):
    """Every id that went away with a removal (the Viewer drops the geometry names)."""
    joints: Tuple[str, ...] = ()
    motors: Tuple[str, ...] = ()
    forces: Tuple[str, ...] = ()
    geometries: Tuple[str, ...] = ()


class JointState(NamedTuple):
    """positions (rad or m) and rates (rad/s or m/s) per joint axis; none for ball/fixed/plane2d.
    hinge: angle; slider: position; piston: position, angle; universal/hinge2: angle1, angle2;
    PR: position, angle; PU: position, angle1, angle2."""
    id: str
    type: int
    positions: Tuple[float, ...]
    rates: Tuple[float, ...]


class Collision(NamedTuple):
    """Two colliding geometries (names), the deepest penetration depth (m) and up to 8 contact
    points (world, m)."""
    first: str
    second: str
    depth: float
    points: Tuple[Tuple[float, float, float], ...]


# ---------------------------------------------------------------------------------- ODE init

_ODE_READY = False


def _init_ode() -> None:
    """Checks the library's precision, initialises ODE once and routes its messages."""
    global _ODE_READY
    if _ODE_READY:
        return
    if not lib.dCheckConfiguration(b"ODE_double_precision"):
        raise OdeConfigurationError(
            "libode is not built with double precision (dCheckConfiguration"
            "('ODE_double_precision') is false); Odin needs Debian's double-precision libode")
    lib.odin_install_handlers()
    if not lib.dInitODE2(0):
        raise OdeConfigurationError("dInitODE2 failed")
    _ODE_READY = True


_MESSAGE_BUFFER = ffi.new("char[]", 512)
_MESSAGE_NUM = ffi.new("int *")


def drain_ode_messages() -> List[str]:
    """Moves ODE's buffered messages into logging (warning level) and returns them."""
    messages = []
    while True:
        level = lib.odin_drain_message(_MESSAGE_BUFFER, 512, _MESSAGE_NUM)
        if level < 0:
            return messages
        text = ffi.string(_MESSAGE_BUFFER).decode("utf-8", "replace")
        messages.append(text)
        log.warning("ODE %s %d: %s", ("message", "debug", "error")[level], _MESSAGE_NUM[0], text)


# ---------------------------------------------------------------------------------- validation


def _number(what: str, value, allow_inf: bool = False) -> float:
    if isinstance(value, bool):
        raise InvalidArgument(f"{what}={value!r} is not a number")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}={value!r} is not a number") from None
    if math.isnan(number) or (not allow_inf and math.isinf(number)):
        raise InvalidArgument(f"{what}={value!r} is not finite")
    return number


def _vector(what: str, value, n: int = 3) -> np.ndarray:
    try:
        array = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}={value!r} is not a vector of {n} numbers") from None
    if array.shape != (n,):
        raise InvalidArgument(f"{what}={value!r} has {array.size} values, expected {n}")
    if not np.all(np.isfinite(array)):
        raise InvalidArgument(f"{what}={value!r} is not finite")
    return array


def _axis(what: str, value) -> np.ndarray:
    axis = _vector(what, value)
    norm = float(np.linalg.norm(axis))
    if norm < 1e-9:
        raise InvalidArgument(f"{what}={value!r} is a zero axis")
    return axis / norm


def _quaternion(what: str, value) -> np.ndarray:
    q = _vector(what, value, 4)
    norm = float(np.linalg.norm(q))
    if norm == 0.0:
        raise InvalidArgument(f"{what}={value!r} is a zero quaternion")
    if abs(norm - 1.0) > QUATERNION_TOLERANCE:
        raise InvalidArgument(f"{what}={value!r} is not a unit quaternion (norm {norm:.6g})")
    return q / norm


def _name(what: str, value, allow_marker: bool = False) -> str:
    if not isinstance(value, str) or not value:
        raise InvalidArgument(f"{what}={value!r} must be a non-empty string")
    if not allow_marker and ">" in value:
        raise InvalidArgument(f"{what}={value!r} must not contain '>'")
    return value


def _bool(what: str, value) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidArgument(f"{what}={value!r} is not a bool")
    return bool(value)


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def _rotation(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


# ---------------------------------------------------------------------------------- shapes


@dataclass
class _Shape:
    """A validated shape: kind "sphere" | "cylinder" | "box" | "mesh"."""
    kind: str
    dims: Tuple[float, ...] = ()
    vertices: Optional[np.ndarray] = None   # (n,3) float64, m
    triangles: Optional[np.ndarray] = None  # (m,3) uint32


def _prepare_shape(what: str, parameters, indices) -> _Shape:
    try:
        values = np.array(parameters, dtype=float).reshape(-1)
        index_values = np.array(indices, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}: parameters/indices are not numbers") from None
    if not np.all(np.isfinite(values)):
        raise InvalidArgument(f"{what}: parameters {list(parameters)!r} are not finite")
    n = values.size
    if n in (1, 2, 3):
        if index_values.size:
            raise InvalidArgument(f"{what}: indices given for a primitive ({n} parameters)")
        if np.any(values <= 0):
            raise InvalidArgument(f"{what}: sizes {values.tolist()} must be positive")
        return _Shape(("sphere", "cylinder", "box")[n - 1], tuple(values.tolist()))
    if n < 9 or n % 3:
        raise InvalidArgument(
            f"{what}: {n} parameters fit no shape (1 sphere, 2 cylinder, 3 box, a multiple of 3"
            " >= 9 mesh vertices)")
    vertices = values.reshape(-1, 3)
    if index_values.size == 0 or index_values.size % 3:
        raise InvalidArgument(
            f"{what}: a mesh needs indices, 3 per triangle; got {index_values.size}")
    if not np.all(index_values == np.round(index_values)):
        raise InvalidArgument(f"{what}: mesh indices must be integers")
    low, high = index_values.min(), index_values.max()
    if low < 0 or high >= len(vertices):
        bad = low if low < 0 else high
        raise InvalidArgument(
            f"{what}: mesh index {int(bad)} out of range [0, {len(vertices) - 1}]")
    triangles = index_values.astype(np.uint32).reshape(-1, 3)
    corners = vertices[triangles]
    areas = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                           axis=1)
    if not np.any(areas > 1e-12 * max(float(np.ptp(vertices)), 1e-12) ** 2):
        raise InvalidArgument(f"{what}: every mesh triangle is degenerate")
    return _Shape("mesh", (), np.ascontiguousarray(vertices), np.ascontiguousarray(triangles))


#: a mesh fewer cells across than this (its bounding box's longest side) collides as given:
#: clustered, it would keep too little of its shape to be worth the saving
MIN_CELLS_ACROSS = 6


def _collision_mesh(shape: _Shape, tolerance: float) -> Tuple[np.ndarray, np.ndarray]:
    """The (vertices (n,3) m, triangles (m,3)) ODE collides with: the given mesh, or its
    vertices clustered at ``tolerance`` m (WorldParameters.collision_mesh_tolerance) when the
    mesh is at least MIN_CELLS_ACROSS cells across."""
    extent = float(np.ptp(shape.vertices, axis=0).max())
    if tolerance <= 0 or extent < MIN_CELLS_ACROSS * tolerance:
        return shape.vertices, shape.triangles
    vertices, indices = cluster_vertices(shape.vertices, shape.triangles, tolerance)
    if indices.size == 0:
        return shape.vertices, shape.triangles
    return vertices, indices.astype(np.uint32).reshape(-1, 3)


_MESH_MASS_CACHE: Dict[Tuple[bytes, bytes], object] = {}
"""LRU of unit-mass mesh properties (the same robot's meshes come back on every New Scene)."""


def _shape_mass(what: str, shape: _Shape, mass: float):
    """dMass of `shape` with total `mass`, in the shape's frame (centre may be off the origin)."""
    m = ffi.new("dMass *")
    if shape.kind == "sphere":
        lib.dMassSetSphereTotal(m, mass, shape.dims[0])
    elif shape.kind == "cylinder":
        lib.dMassSetCylinderTotal(m, mass, 3, shape.dims[0], shape.dims[1])
    elif shape.kind == "box":
        lib.dMassSetBoxTotal(m, mass, *shape.dims)
    else:
        key = (shape.vertices.tobytes(), shape.triangles.tobytes())
        unit = _MESH_MASS_CACHE.pop(key, None)
        if unit is None:  # mass properties of a unit mass scale linearly with the mass
            unit = mesh_mass(shape.vertices, shape.triangles, 1.0)
            if unit.rule != "closed":
                log.info("%s: open mesh, inertia from its %s", what, unit.rule)
        _MESH_MASS_CACHE[key] = unit  # most recently used last
        while len(_MESH_MASS_CACHE) > 256:
            del _MESH_MASS_CACHE[next(iter(_MESH_MASS_CACHE))]
        props = unit._replace(mass=mass, inertia=unit.inertia * mass)
        i = props.inertia
        lib.dMassSetParameters(m, mass, 0.0, 0.0, 0.0, i[0, 0], i[1, 1], i[2, 2], i[0, 1],
                               i[0, 2], i[1, 2])
        lib.dMassTranslate(m, *props.center.tolist())
    return m


def _check_mass(what: str, m) -> None:
    matrix = np.array([[m.I[4 * r + c] for c in range(3)] for r in range(3)])
    if not np.all(np.isfinite(matrix)) or np.min(np.linalg.eigvalsh(matrix)) <= 0:
        raise InvalidArgument(f"{what}: inertia {matrix.tolist()} is not positive definite")
    principal = np.linalg.eigvalsh(matrix)
    if principal[0] + principal[1] < principal[2] * (1 - 1e-9):
        raise InvalidArgument(f"{what}: principal moments {principal.tolist()} break the "
                              "triangle inequality (no rigid body has them)")
    if not lib.dMassCheck(m):
        drain_ode_messages()
        raise InvalidArgument(f"{what}: ODE rejects the mass parameters (dMassCheck)")


# ---------------------------------------------------------------------------------- records


class _Geometry:
    __slots__ = ("name", "owner", "object_id", "position", "orientation", "shape", "color")

    def __init__(self, name, owner, object_id, position, orientation, shape, color):
        self.name = name
        self.owner = owner
        self.object_id = object_id
        self.position = position        # (3,) in the object frame
        self.orientation = orientation  # (4,) in the object frame
        self.shape = shape
        self.color = color


class _Object:
    __slots__ = ("id", "spec", "body", "geometries", "com", "fixed", "joints", "motors",
                 "forces", "entity")

    def __init__(self, object_id, spec, body, com, fixed):
        self.id = object_id
        self.spec = spec
        self.body = body                  # Owner or None (geometry only)
        self.geometries: List[_Geometry] = []
        self.com = com                    # (3,) centre of mass in the object frame
        self.fixed = fixed
        self.joints: Set[str] = set()
        self.motors: Set[str] = set()
        self.forces: Set[str] = set()
        self.entity: Optional[str] = None


class _Joint:
    __slots__ = ("id", "type", "owner", "bodies", "motors", "forces")

    def __init__(self, joint_id, joint_type, owner, bodies):
        self.id = joint_id
        self.type = joint_type
        self.owner = owner
        self.bodies = bodies              # (body1 id or "", body2 id or "")
        self.motors: Set[str] = set()
        self.forces: Set[str] = set()


class _Motor:
    __slots__ = ("id", "owner", "kind", "naxes", "joint", "bodies", "velocity")

    def __init__(self, motor_id, owner, kind, naxes, joint, bodies):
        self.id = motor_id
        self.owner = owner
        self.kind = kind
        self.naxes = naxes
        self.joint = joint
        self.bodies = bodies
        self.velocity = [0.0] * naxes


@dataclass
class _PreparedPart:
    name: str
    shape: _Shape
    mass: float
    position: np.ndarray
    orientation: np.ndarray
    color: Tuple[float, ...]


def _locked(method):
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        with self._lock:
            if self._closed:
                raise Closed(f"Core is closed ({method.__name__})")
            return method(self, *args, **kwargs)
    return wrapper


# ---------------------------------------------------------------------------------- Core


class Core:
    """The virtual world: objects, joints, motors, forces, collisions and the step."""

    def __init__(self, parameters: Optional[WorldParameters] = None):
        _init_ode()
        parameters = WorldParameters() if parameters is None else parameters
        if not isinstance(parameters, WorldParameters):
            raise InvalidArgument(f"parameters={parameters!r} is not a WorldParameters")
        parameters.validate()
        self._lock = threading.RLock()
        self._closed = False
        self._parameters = parameters
        self._cworld = ffi.new("OdinWorld *")  # memory owned by Python; records by C
        self._open_scene()

    # ------------------------------------------------------------------ scene lifetime

    def _open_scene(self) -> None:
        self._world = handles.new_world()
        self._space = handles.new_space()
        self._contacts = handles.new_joint_group(self._world)
        w = self._cworld
        w.world, w.space, w.contact_group = self._world.ptr, self._space.ptr, self._contacts.ptr
        self._objects: Dict[str, _Object] = {}
        self._geometries: Dict[str, _Geometry] = {}
        self._geom_names: Dict[int, str] = {}          # C address -> geometry name
        self._joints: Dict[str, _Joint] = {}
        self._pairs: Dict[frozenset, str] = {}         # {body1, body2} -> joint id
        self._motors: Dict[str, _Motor] = {}
        self._body_forces: Dict[str, tuple] = {}       # id -> (object id, OdinBodyForce fields)
        self._joint_forces: Dict[str, tuple] = {}      # id -> (joint id, type, magnitudes)
        self._entities: Dict[str, List[str]] = {}
        self._entity_tags: Dict[str, int] = {}
        self._next_tag = 1
        self._entity_counter = 0
        self._carry: Dict[Tuple[str, str], Collision] = {}
        self._geom_array = None
        self._pose_names: List[str] = []
        self._forces_array = self._joint_forces_array = self._motors_array = None
        self._motor_slots: Dict[str, int] = {}
        self._sim_time = 0.0
        self._apply_parameters(self._parameters)

    def _close_scene(self) -> None:
        w = self._cworld
        w.n_forces = w.n_joint_forces = w.n_motors = 0
        w.forces = w.joint_forces = w.motors = ffi.NULL
        lib.odin_world_clear_records(w)
        for motor in self._motors.values():
            motor.owner.close()
        for joint in self._joints.values():
            joint.owner.close()
        for geometry in self._geometries.values():
            geometry.owner.close()
        for obj in self._objects.values():
            if obj.body is not None:
                obj.body.close()
        self._space.close()
        self._contacts.close()
        self._world.close()   # closes anything left (owners are idempotent)
        w.world = w.space = w.contact_group = ffi.NULL
        self._forces_array = self._joint_forces_array = self._motors_array = None
        self._geom_array = None
        drain_ode_messages()

    @_locked
    def new_scene(self) -> None:
        """Frees every object, joint, motor and force and starts an empty world with the
        same world parameters; sim_time restarts at 0."""
        self._close_scene()
        lib.odin_world_free_buffers(self._cworld)
        self._open_scene()

    def close(self) -> None:
        """Frees everything; idempotent. Any later call but close() raises Closed."""
        with self._lock:
            if self._closed:
                return
            self._close_scene()
            lib.odin_world_free_buffers(self._cworld)
            self._closed = True

    def __enter__(self) -> "Core":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: modules may be gone
            pass

    # ------------------------------------------------------------------ world parameters

    @property
    def world_parameters(self) -> WorldParameters:
        return self._parameters

    @_locked
    def set_world_parameters(self, **changes) -> WorldParameters:
        """Validates every change, then applies them all; returns the new parameters.
        Switching the collision policy forgets the recorded collisions."""
        new = self._parameters.replace(**changes)
        if new.contact_less != self._parameters.contact_less:
            self._forget_collisions()
        self._apply_parameters(new)
        self._parameters = new
        return new

    def _apply_parameters(self, p: WorldParameters) -> None:
        world = self._world.ptr
        inf = lib.dInfinity
        lib.dWorldSetGravity(world, *p.gravity)
        lib.dWorldSetERP(world, p.erp)
        lib.dWorldSetCFM(world, p.cfm)
        lib.dWorldSetMaxAngularSpeed(world, p.max_angular_speed or inf)
        lib.dWorldSetContactMaxCorrectingVel(world, p.contact_max_correcting_velocity or inf)
        lib.dWorldSetContactSurfaceLayer(world, p.contact_surface_layer)
        lib.dWorldSetLinearDamping(world, p.linear_damping)
        lib.dWorldSetLinearDampingThreshold(world, p.linear_damping_threshold)
        lib.dWorldSetAngularDamping(world, p.angular_damping)
        lib.dWorldSetAngularDampingThreshold(world, p.angular_damping_threshold)
        lib.dWorldSetQuickStepNumIterations(world, p.quickstep_iterations)
        w = self._cworld
        w.max_contacts = p.max_contacts
        w.mu = inf if p.friction < 0 else p.friction
        w.bounce = p.bounce
        w.bounce_vel = p.bounce_velocity
        w.contact_less = int(p.contact_less)
        w.solver = p.solver

    # ------------------------------------------------------------------ objects

    def _check_new_names(self, object_ids: Sequence[str], geometry_names: Sequence[str]) -> None:
        seen: Set[str] = set()
        for name in geometry_names:
            if name in self._geometries or name in seen:
                raise DuplicateName(f"geometry name {name!r} is already taken")
            seen.add(name)
        seen = set()
        for object_id in object_ids:
            if object_id in self._objects or object_id in seen:
                raise DuplicateName(f"object id {object_id!r} is already taken")
            seen.add(object_id)

    def _prepare_object(self, spec: ObjectSpec):
        if not isinstance(spec, ObjectSpec):
            raise InvalidArgument(f"{spec!r} is not an ObjectSpec")
        name = _name("object name", spec.name)
        what = f"object {name!r}"
        shape = _prepare_shape(what, spec.parameters, spec.indices)
        geometry_only = _bool(f"{what}: geometry_only", spec.geometry_only)
        _bool(f"{what}: no_collisions", spec.no_collisions)
        mass = _number(f"{what}: mass", spec.mass)
        if mass <= 0 and not geometry_only:  # a body-less geometry has no mass to check
            raise InvalidArgument(f"{what}: mass {spec.mass!r} must be positive")
        position = _vector(f"{what}: position", spec.position)
        orientation = _quaternion(f"{what}: orientation", spec.orientation)
        color = tuple(_vector(f"{what}: color", spec.color, 4).tolist())
        fixed = _bool(f"{what}: fixed", spec.fixed)
        part = _PreparedPart(name, shape, mass, np.zeros(3), np.array([1.0, 0, 0, 0]), color)
        inertia = None
        if len(spec.inertia):
            inertia = _vector(f"{what}: inertia", spec.inertia, 6)
        dmass = None
        if not geometry_only:
            if inertia is not None:
                dmass = ffi.new("dMass *")
                lib.dMassSetParameters(dmass, mass, 0.0, 0.0, 0.0, *inertia.tolist())
            else:
                dmass = _shape_mass(what, shape, mass)
        return name, [part], position, orientation, fixed, geometry_only, dmass

    def _prepare_composite(self, spec: CompositeSpec):
        if not isinstance(spec, CompositeSpec):
            raise InvalidArgument(f"{spec!r} is not a CompositeSpec")
        if len(spec.parts) == 0:
            raise InvalidArgument("a composite needs at least one part")
        parts = []
        for part in spec.parts:
            if not isinstance(part, PartSpec):
                raise InvalidArgument(f"{part!r} is not a PartSpec")
            name = _name("part name", part.name)
            what = f"part {name!r}"
            shape = _prepare_shape(what, part.parameters, part.indices)
            mass = _number(f"{what}: mass", part.mass)
            if mass <= 0:
                raise InvalidArgument(f"{what}: mass {part.mass!r} must be positive")
            parts.append(_PreparedPart(
                name, shape, mass, _vector(f"{what}: position", part.position),
                _quaternion(f"{what}: orientation", part.orientation),
                tuple(_vector(f"{what}: color", part.color, 4).tolist())))
        object_id = ">" + ">".join(p.name for p in parts)
        position = _vector(f"composite {object_id!r}: position", spec.position)
        orientation = _quaternion(f"composite {object_id!r}: orientation", spec.orientation)
        fixed = _bool("composite fixed", spec.fixed)
        geometry_only = _bool("composite geometry_only", spec.geometry_only)
        _bool("composite no_collisions", spec.no_collisions)
        dmass = None
        if not geometry_only:
            dmass = ffi.new("dMass *")
            lib.dMassSetZero(dmass)
            R = ffi.new("dMatrix3")
            for part in parts:
                m = _shape_mass(f"part {part.name!r}", part.shape, part.mass)
                lib.dRfromQ(R, part.orientation.tolist())
                lib.dMassRotate(m, R)
                lib.dMassTranslate(m, *part.position.tolist())
                lib.dMassAdd(dmass, m)
        return object_id, parts, position, orientation, fixed, geometry_only, dmass

    def _build_prepared(self, prepared, spec, tag: int = 0) -> str:
        object_id, parts, position, orientation, fixed, geometry_only, dmass = prepared
        no_collisions = bool(spec.no_collisions)   # checked by _prepare_*
        com = np.zeros(3)
        if dmass is not None:
            com = np.array([dmass.c[0], dmass.c[1], dmass.c[2]])
            lib.dMassTranslate(dmass, *(-com).tolist())
            _check_mass(f"object {object_id!r}", dmass)
        # ---- everything validated: ODE calls from here on
        body = None
        if not geometry_only:
            body = handles.new_body(self._world)
            lib.dBodySetMass(body.ptr, dmass)
            R = _rotation(orientation)
            lib.dBodySetPosition(body.ptr, *(position + R @ com).tolist())
            lib.dBodySetQuaternion(body.ptr, orientation.tolist())
            if fixed:
                lib.dBodySetKinematic(body.ptr)
        obj = _Object(object_id, spec, body, com, fixed)
        for part in parts:
            shape = part.shape
            space = self._space.ptr
            if shape.kind == "mesh":
                collide_vertices, collide_triangles = _collision_mesh(
                    shape, self._parameters.collision_mesh_tolerance)
                vertices = ffi.new("double[]", collide_vertices.reshape(-1).tolist())
                indices = ffi.new("dTriIndex[]", collide_triangles.reshape(-1).tolist())
                geom = handles.new_trimesh(self._space, vertices, indices, body)
            else:
                if shape.kind == "sphere":
                    ptr = lib.dCreateSphere(space, shape.dims[0])
                elif shape.kind == "cylinder":
                    ptr = lib.dCreateCylinder(space, shape.dims[0], shape.dims[1])
                else:
                    ptr = lib.dCreateBox(space, *shape.dims)
                geom = handles.new_geom(ptr, self._space, body)
            if body is not None:
                lib.dGeomSetBody(geom.ptr, body.ptr)
                offset = part.position - com
                if np.any(offset != 0):
                    lib.dGeomSetOffsetPosition(geom.ptr, *offset.tolist())
                if np.any(part.orientation != (1.0, 0.0, 0.0, 0.0)):
                    lib.dGeomSetOffsetQuaternion(geom.ptr, part.orientation.tolist())
            else:
                self._place_static(geom.ptr, position, orientation, part.position,
                                   part.orientation)
            lib.odin_set_geom_tag(geom.ptr, tag)
            if no_collisions:  # the hash space never pairs a geom whose bits are all clear
                lib.dGeomSetCategoryBits(geom.ptr, 0)
                lib.dGeomSetCollideBits(geom.ptr, 0)
            geometry = _Geometry(part.name, geom, object_id, part.position, part.orientation,
                                 shape, part.color)
            obj.geometries.append(geometry)
            self._geometries[part.name] = geometry
            self._geom_names[int(ffi.cast("uintptr_t", geom.ptr))] = part.name
        self._objects[object_id] = obj
        self._geom_array = None
        drain_ode_messages()
        return object_id

    @staticmethod
    def _place_static(geom, position, orientation, part_position, part_orientation) -> None:
        R = _rotation(orientation)
        lib.dGeomSetPosition(geom, *(position + R @ part_position).tolist())
        lib.dGeomSetQuaternion(geom, _qmul(orientation, part_orientation).tolist())

    @_locked
    def build_object(self, spec: ObjectSpec) -> str:
        """Creates one object (see ObjectSpec); returns its id (the name)."""
        prepared = self._prepare_object(spec)
        self._check_new_names([prepared[0]], [p.name for p in prepared[1]])
        return self._build_prepared(prepared, spec)

    @_locked
    def build_composite(self, spec: CompositeSpec) -> str:
        """Creates a composite: its parts are geometries on one body placed at the centre of
        mass (part masses rotated, translated and added). Returns ">part1>part2..."."""
        prepared = self._prepare_composite(spec)
        self._check_new_names([prepared[0]], [p.name for p in prepared[1]])
        return self._build_prepared(prepared, spec)

    @_locked
    def build_entity(self, name: str, objects: Sequence[ObjectSpec] = (),
                     composites: Sequence[CompositeSpec] = (),
                     internal_collisions: bool = True) -> Tuple[str, List[str]]:
        """Builds objects and composites as one entity, all or nothing. Without internal
        collisions, no two of its geometries ever collide. name "" gives "entity<n>".
        Returns (entity name, object ids in order: objects, then composites)."""
        internal_collisions = _bool("internal_collisions", internal_collisions)
        if not isinstance(name, str):
            raise InvalidArgument(f"entity name {name!r} is not a string")
        if name == "":
            self._entity_counter += 1
            while f"entity{self._entity_counter}" in self._entities:
                self._entity_counter += 1
            name = f"entity{self._entity_counter}"
        if name in self._entities:
            raise DuplicateName(f"entity {name!r} already exists")
        prepared = [(self._prepare_object(s), s) for s in objects]
        prepared += [(self._prepare_composite(s), s) for s in composites]
        if not prepared:
            raise InvalidArgument(f"entity {name!r} has no objects")
        self._check_new_names([p[0] for p, _ in prepared],
                              [part.name for p, _ in prepared for part in p[1]])
        tag = 0
        if not internal_collisions:
            tag = self._next_tag
            self._next_tag += 1
        ids: List[str] = []
        try:
            for p, spec in prepared:
                ids.append(self._build_prepared(p, spec, tag))
        except Exception:
            for object_id in ids:
                self._remove_object(object_id)
            raise
        for object_id in ids:
            self._objects[object_id].entity = name
        self._entities[name] = ids
        return name, list(ids)

    @_locked
    def entities(self) -> Dict[str, List[str]]:
        """Entity name -> ids of its objects still alive."""
        return {name: list(ids) for name, ids in self._entities.items()}

    def _object(self, object_id: str) -> _Object:
        try:
            return self._objects[object_id]
        except (KeyError, TypeError):
            raise UnknownName(f"no object {object_id!r}") from None

    def _body_object(self, object_id: str, what: str) -> _Object:
        obj = self._object(object_id)
        if obj.body is None:
            raise Unsupported(f"{what}: object {object_id!r} is geometry only (no body)")
        return obj

    @_locked
    def geometry_names(self, object_id: str) -> List[str]:
        """Names of the object's geometries (one, or a composite's parts)."""
        return [g.name for g in self._object(object_id).geometries]

    @_locked
    def collision_triangle_count(self, geometry_name: str) -> int:
        """Triangles ODE collides with for a mesh geometry (fewer than given when it was built
        under a collision_mesh_tolerance); 0 for a primitive."""
        geometry = self._geometries.get(geometry_name)
        if geometry is None:
            raise UnknownName(f"no geometry named {geometry_name!r}")
        if geometry.shape.kind != "mesh":
            return 0
        return int(lib.dGeomTriMeshGetTriangleCount(geometry.owner.ptr))

    @_locked
    def object_ids(self) -> List[str]:
        return list(self._objects)

    @_locked
    def object_spec(self, object_id: str):
        """The ObjectSpec or CompositeSpec the object was built from."""
        return self._object(object_id).spec

    @_locked
    def remove_object(self, object_id: str) -> Removed:
        """Removes an object with its joints, motors and forces; returns every removed id."""
        self._object(object_id)
        return self._remove_object(object_id)

    def _remove_object(self, object_id: str) -> Removed:
        obj = self._objects[object_id]
        joints, motors, forces = [], [], []
        for joint_id in sorted(obj.joints):
            removed = self._remove_joint(joint_id)
            joints += removed.joints
            motors += removed.motors
            forces += removed.forces
        for motor_id in sorted(obj.motors):
            motors.append(motor_id)
            self._remove_motor(motor_id)
        for force_id in sorted(obj.forces):
            forces.append(force_id)
            del self._body_forces[force_id]
        if obj.forces:
            self._rebuild_body_forces()
        names = tuple(g.name for g in obj.geometries)
        self._carry_collisions(set(names))
        for geometry in obj.geometries:
            del self._geom_names[int(ffi.cast("uintptr_t", geometry.owner.ptr))]
            geometry.owner.close()
            del self._geometries[geometry.name]
        if obj.body is not None:
            obj.body.close()
        del self._objects[object_id]
        if obj.entity is not None:
            members = self._entities[obj.entity]
            members.remove(object_id)
            if not members:
                del self._entities[obj.entity]
        self._geom_array = None
        drain_ode_messages()
        return Removed(tuple(joints), tuple(motors), tuple(forces), names)

    # ------------------------------------------------------------------ joints

    @_locked
    def create_joint(self, joint_type: int, body1: str, body2: str, anchor=(0.0, 0.0, 0.0),
                     axis1=(0.0, 0.0, 1.0), axis2=(1.0, 0.0, 0.0), axis3=(0.0, 1.0, 0.0),
                     joint_id: str = "") -> str:
        """Joins two bodies, or a body and the static world (an id ""), with a joint.

        joint_type: BALL HINGE SLIDER PISTON UNIVERSAL HINGE2 PR PU FIXED PLANE2D.
        anchor (m, world) is used by ball, hinge, piston, universal, hinge2, PR and PU; axes
        (world, normalised here): hinge/slider/piston axis1; universal and hinge2 axis1,
        axis2 (not parallel); PR axis1 prismatic, axis2 rotoide; PU axis1, axis2 universal,
        axis3 prismatic. PLANE2D keeps body1 in the plane z = 0 (body2 must be "").
        FIXED keeps the bodies' current relative pose. One joint per pair of bodies.
        The default id is f"{joint_type}:{body1}&{body2}".
        """
        if isinstance(joint_type, bool) or joint_type not in _CREATE:
            raise InvalidArgument(f"joint type {joint_type!r} is not one of 0..9")
        for what, value in (("body1", body1), ("body2", body2)):
            if not isinstance(value, str):
                raise InvalidArgument(f"{what}={value!r} is not a string")
        if not body1 and not body2:
            raise InvalidArgument("a joint needs at least one body (both are '')")
        if body1 == body2:
            raise InvalidArgument(f"a joint cannot join {body1!r} to itself")
        objects = [self._body_object(b, "joint") if b else None for b in (body1, body2)]
        if joint_type == PLANE2D and (not body1 or body2):
            raise Unsupported("a plane-2D joint takes body1 only (body2 must be '')")
        pair = frozenset((body1, body2))
        if pair in self._pairs:
            raise DuplicateName(
                f"bodies {body1!r} and {body2!r} are already joined by {self._pairs[pair]!r}")
        if not isinstance(joint_id, str):
            raise InvalidArgument(f"joint id {joint_id!r} is not a string")
        joint_id = joint_id or f"{joint_type}:{body1}&{body2}"
        if joint_id in self._joints or joint_id in self._motors:
            raise DuplicateName(f"joint id {joint_id!r} is already taken")
        anchor = _vector("anchor", anchor)
        # only the axes the type uses are checked: a request leaves the others at zero
        uses = _AXES_USED[joint_type]
        a1, a2, a3 = (_axis(name, value) if name in uses else None
                      for name, value in (("axis1", axis1), ("axis2", axis2), ("axis3", axis3)))
        if joint_type in (UNIVERSAL, HINGE2, PU, PR) and abs(float(a1 @ a2)) > 1 - 1e-6:
            raise InvalidArgument(f"axis1 {tuple(axis1)} and axis2 {tuple(axis2)} are parallel")
        # ---- ODE
        bodies = [o.body for o in objects if o is not None]
        ptr = _CREATE[joint_type](self._world.ptr, ffi.NULL)
        owner = handles.new_joint(ptr, self._world, bodies)
        j = owner.ptr
        # a body joined to the world is ODE's body 1 (body 2 NULL): angles, rates, joint
        # forces and motors then all describe that body's motion with the axes as given
        lib.dJointAttach(j, bodies[0].ptr, bodies[1].ptr if len(bodies) > 1 else ffi.NULL)
        a = anchor.tolist()
        if joint_type == BALL:
            lib.dJointSetBallAnchor(j, *a)
        elif joint_type == HINGE:
            lib.dJointSetHingeAnchor(j, *a)
            lib.dJointSetHingeAxis(j, *a1.tolist())
        elif joint_type == SLIDER:
            lib.dJointSetSliderAxis(j, *a1.tolist())
        elif joint_type == PISTON:
            lib.dJointSetPistonAnchor(j, *a)
            lib.dJointSetPistonAxis(j, *a1.tolist())
        elif joint_type == UNIVERSAL:
            lib.dJointSetUniversalAnchor(j, *a)
            lib.dJointSetUniversalAxis1(j, *a1.tolist())
            lib.dJointSetUniversalAxis2(j, *a2.tolist())
        elif joint_type == HINGE2:
            lib.dJointSetHinge2Anchor(j, *a)
            lib.dJointSetHinge2Axes(j, a1.tolist() + [0.0], a2.tolist() + [0.0])
        elif joint_type == PR:
            lib.dJointSetPRAnchor(j, *a)
            lib.dJointSetPRAxis1(j, *a1.tolist())
            lib.dJointSetPRAxis2(j, *a2.tolist())
        elif joint_type == PU:
            lib.dJointSetPUAnchor(j, *a)
            lib.dJointSetPUAxis1(j, *a1.tolist())
            lib.dJointSetPUAxis2(j, *a2.tolist())
            lib.dJointSetPUAxis3(j, *a3.tolist())
        elif joint_type == FIXED:
            lib.dJointSetFixed(j)
        self._joints[joint_id] = _Joint(joint_id, joint_type, owner, (body1, body2))
        self._pairs[pair] = joint_id
        for o in objects:
            if o is not None:
                o.joints.add(joint_id)
        drain_ode_messages()
        return joint_id

    def _joint(self, joint_id: str) -> _Joint:
        try:
            return self._joints[joint_id]
        except (KeyError, TypeError):
            raise UnknownName(f"no joint {joint_id!r}") from None

    @_locked
    def joint_ids(self) -> List[str]:
        return list(self._joints)

    @_locked
    def set_joint_parameters(self, joint_id: str,
                             parameters: Sequence[Tuple[int, int, float]]) -> None:
        """Sets (parameter, axis 1..3, value) triples on a joint or a motor, all or nothing.

        Ranges: ERP-like and BOUNCE and FUDGE_FACTOR in [0, 1]; CFM-like >= 0; stops may be
        +-inf; MAX_FORCE negative means infinite. Ball and fixed joints take CFM and ERP only;
        suspension parameters need a hinge2; plane-2D joints take none. On a motor, VELOCITY
        sets its goal speed (as set_motor_velocities does).
        """
        motor = self._motors.get(joint_id)
        if motor is not None:
            allowed, axes, kind = _LIMIT_PARAMS, motor.naxes, "motor"
            setter = lib.dJointSetAMotorParam if motor.kind == ANGULAR else lib.dJointSetLMotorParam
            ptr = motor.owner.ptr
        else:
            joint = self._joint(joint_id)
            if joint.type not in _JOINT_PARAMS:
                raise Unsupported(f"joint {joint_id!r} ({JOINT_TYPE_NAMES[joint.type]}) takes"
                                  " no parameters")
            allowed, axes = _JOINT_PARAMS[joint.type], _JOINT_PARAM_AXES[joint.type]
            kind = JOINT_TYPE_NAMES[joint.type]
            setter, ptr = _SET_PARAM[joint.type], joint.owner.ptr
        calls = []
        for item in parameters:
            try:
                parameter, axis, value = item
            except (TypeError, ValueError):
                raise InvalidArgument(f"{item!r} is not a (parameter, axis, value) triple") \
                    from None
            if isinstance(parameter, bool) or parameter not in _ODE_PARAM:
                raise InvalidArgument(f"joint parameter {parameter!r} is not one of 0..11")
            pname = PARAMETER_NAMES[parameter]
            if parameter not in allowed:
                raise Unsupported(f"parameter {pname} does not fit {kind} {joint_id!r}")
            if isinstance(axis, bool) or axis not in range(1, axes + 1):
                raise InvalidArgument(f"axis {axis!r} for {pname} of {kind} {joint_id!r} must be"
                                      f" in 1..{axes}")
            value = _number(f"{pname} value", value, allow_inf=parameter in (LO_STOP, HI_STOP))
            if parameter in (ERP, STOP_ERP, SUSPENSION_ERP, BOUNCE, FUDGE_FACTOR) and \
                    not 0 <= value <= 1:
                raise InvalidArgument(f"{pname}={value!r} must be in [0, 1]")
            if parameter in (CFM, STOP_CFM, SUSPENSION_CFM) and value < 0:
                raise InvalidArgument(f"{pname}={value!r} must be >= 0")
            if parameter == MAX_FORCE and value < 0:
                value = lib.dInfinity
            calls.append((_ODE_PARAM[parameter] + (axis - 1) * lib.dParamGroup, value,
                          parameter, axis))
        for ode_parameter, value, parameter, axis in calls:
            setter(ptr, ode_parameter, value)
            if motor is not None and parameter == VELOCITY:
                motor.velocity[axis - 1] = value
        if motor is not None:
            self._update_motor_slot(motor)
        drain_ode_messages()

    @_locked
    def remove_joint(self, joint_id: str) -> Removed:
        """Removes a joint with its motors and joint forces."""
        self._joint(joint_id)
        return self._remove_joint(joint_id)

    def _remove_joint(self, joint_id: str) -> Removed:
        joint = self._joints.pop(joint_id)
        motors = sorted(joint.motors)
        for motor_id in motors:
            self._remove_motor(motor_id)
        forces = sorted(joint.forces)
        for force_id in forces:
            del self._joint_forces[force_id]
        if forces:
            self._rebuild_joint_forces()
        del self._pairs[frozenset(joint.bodies)]
        for body in joint.bodies:
            if body:
                self._objects[body].joints.discard(joint_id)
        joint.owner.close()
        return Removed((joint_id,), tuple(motors), tuple(forces), ())

    @_locked
    def joint_states(self) -> List[JointState]:
        """Positions and rates of every joint, per axis (see JointState)."""
        states = []
        for joint in self._joints.values():
            j, t = joint.owner.ptr, joint.type
            if t == HINGE:
                p, r = (lib.dJointGetHingeAngle(j),), (lib.dJointGetHingeAngleRate(j),)
            elif t == SLIDER:
                p, r = (lib.dJointGetSliderPosition(j),), (lib.dJointGetSliderPositionRate(j),)
            elif t == PISTON:
                p = (lib.dJointGetPistonPosition(j), lib.dJointGetPistonAngle(j))
                r = (lib.dJointGetPistonPositionRate(j), lib.dJointGetPistonAngleRate(j))
            elif t == UNIVERSAL:
                p = (lib.dJointGetUniversalAngle1(j), lib.dJointGetUniversalAngle2(j))
                r = (lib.dJointGetUniversalAngle1Rate(j), lib.dJointGetUniversalAngle2Rate(j))
            elif t == HINGE2:
                p = (lib.dJointGetHinge2Angle1(j), lib.dJointGetHinge2Angle2(j))
                r = (lib.dJointGetHinge2Angle1Rate(j), lib.dJointGetHinge2Angle2Rate(j))
            elif t == PR:
                p = (lib.dJointGetPRPosition(j), lib.dJointGetPRAngle(j))
                r = (lib.dJointGetPRPositionRate(j), lib.dJointGetPRAngleRate(j))
            elif t == PU:
                p = (lib.dJointGetPUPosition(j), lib.dJointGetPUAngle1(j),
                     lib.dJointGetPUAngle2(j))
                r = (lib.dJointGetPUPositionRate(j), lib.dJointGetPUAngle1Rate(j),
                     lib.dJointGetPUAngle2Rate(j))
            else:
                p, r = (), ()
            states.append(JointState(joint.id, t, tuple(p), tuple(r)))
        return states

    # ------------------------------------------------------------------ motors

    def _joint_axes(self, joint: _Joint, kind: int) -> List[np.ndarray]:
        j, t = joint.owner.ptr, joint.type
        v = ffi.new("dVector3")
        getters = {
            ANGULAR: {HINGE: [lib.dJointGetHingeAxis], PISTON: [lib.dJointGetPistonAxis],
                      UNIVERSAL: [lib.dJointGetUniversalAxis1, lib.dJointGetUniversalAxis2],
                      HINGE2: [lib.dJointGetHinge2Axis1, lib.dJointGetHinge2Axis2],
                      PR: [lib.dJointGetPRAxis2],
                      PU: [lib.dJointGetPUAxis1, lib.dJointGetPUAxis2]},
            LINEAR: {SLIDER: [lib.dJointGetSliderAxis], PISTON: [lib.dJointGetPistonAxis],
                     PR: [lib.dJointGetPRAxis1], PU: [lib.dJointGetPUAxis3]},
        }[kind].get(t, [])
        axes = []
        for getter in getters:
            getter(j, v)
            axes.append(np.array([v[0], v[1], v[2]]))
        return axes

    @_locked
    def create_motor(self, motor_id: str = "", joint: str = "", body1: str = "",
                     body2: str = "", kind: int = ANGULAR, axes: Sequence[float] = (),
                     axis_frames: Sequence[int] = (), max_forces: Sequence[float] = ()) -> str:
        """An angular (dAMotor) or linear (dLMotor) motor between two bodies or a body and the
        world, with zero goal speed and infinite maximum force unless max_forces says
        otherwise (per axis; negative = infinite).

        With `joint`, the bodies are the joint's and, if `axes` is empty, the axes are the
        joint's rotational (ANGULAR) or sliding (LINEAR) axes. axes: flat, 3 per axis, 1..3
        axes, given in world coordinates now; axis_frames per axis: 0 world, 1 first body,
        2 second body (the frame the axis stays fixed in; default 1, or 2 when body1 is the
        world). Default id "motor:<joint>" or "motor:<body1>&<body2>".
        """
        if kind not in (ANGULAR, LINEAR) or isinstance(kind, bool):
            raise InvalidArgument(f"motor kind {kind!r} is not ANGULAR (0) or LINEAR (1)")
        for what, value in (("motor_id", motor_id), ("joint", joint), ("body1", body1),
                            ("body2", body2)):
            if not isinstance(value, str):
                raise InvalidArgument(f"{what}={value!r} is not a string")
        axes_values = _vector("axes", axes, len(axes)) if len(axes) else np.zeros(0)
        joint_record = None
        if joint:
            joint_record = self._joint(joint)
            if body1 or body2:
                if (body1, body2) != joint_record.bodies:
                    raise InvalidArgument(f"bodies {body1!r}, {body2!r} differ from joint "
                                          f"{joint!r}'s {joint_record.bodies}")
            body1, body2 = joint_record.bodies
            if axes_values.size == 0:
                found = self._joint_axes(joint_record, kind)
                if not found:
                    raise Unsupported(f"joint {joint!r} ({JOINT_TYPE_NAMES[joint_record.type]})"
                                      f" has no {('angular', 'linear')[kind]} axis; give axes")
                axes_values = np.concatenate(found)
        if not body1 and not body2:
            raise InvalidArgument("a motor needs a joint or at least one body")
        if body1 == body2:
            raise InvalidArgument(f"a motor cannot join {body1!r} to itself")
        objects = [self._body_object(b, "motor") if b else None for b in (body1, body2)]
        if axes_values.size % 3 or not 3 <= axes_values.size <= 9:
            raise InvalidArgument(f"axes {list(axes)!r}: need 1..3 axes of 3 numbers each")
        naxes = axes_values.size // 3
        unit_axes = [_axis(f"motor axis {i + 1}", axes_values[3 * i:3 * i + 3])
                     for i in range(naxes)]
        default_frame = 1 if body1 else 2
        frames = list(axis_frames) if len(axis_frames) else [default_frame] * naxes
        if len(frames) != naxes:
            raise InvalidArgument(f"axis_frames {list(axis_frames)!r}: need one per axis ({naxes})")
        for frame in frames:
            if isinstance(frame, bool) or frame not in (0, 1, 2):
                raise InvalidArgument(f"axis frame {frame!r} is not 0 (world), 1 or 2")
            if frame and objects[frame - 1] is None:
                raise InvalidArgument(f"axis frame {frame} names the world ('' body)")
        forces = [_number("max force", f, allow_inf=True) for f in max_forces] if \
            len(max_forces) else [-1.0] * naxes
        if len(forces) != naxes:
            raise InvalidArgument(f"max_forces {list(max_forces)!r}: need one per axis ({naxes})")
        motor_id = motor_id or (f"motor:{joint}" if joint else f"motor:{body1}&{body2}")
        if motor_id in self._motors or motor_id in self._joints:
            raise DuplicateName(f"motor id {motor_id!r} is already taken")
        # ---- ODE
        create = lib.dJointCreateAMotor if kind == ANGULAR else lib.dJointCreateLMotor
        bodies = [o.body for o in objects if o is not None]
        owner = handles.new_joint(create(self._world.ptr, ffi.NULL), self._world, bodies)
        m = owner.ptr
        if objects[0] is None:  # the body is ODE's body 1, as for joints (see create_joint)
            frames = [{0: 0, 1: 2, 2: 1}[f] for f in frames]
        lib.dJointAttach(m, bodies[0].ptr, bodies[1].ptr if len(bodies) > 1 else ffi.NULL)
        if kind == ANGULAR:
            lib.dJointSetAMotorMode(m, lib.dAMotorUser)
            lib.dJointSetAMotorNumAxes(m, naxes)
        else:
            lib.dJointSetLMotorNumAxes(m, naxes)
        set_axis = lib.dJointSetAMotorAxis if kind == ANGULAR else lib.dJointSetLMotorAxis
        set_param = lib.dJointSetAMotorParam if kind == ANGULAR else lib.dJointSetLMotorParam
        for i, (axis, frame, force) in enumerate(zip(unit_axes, frames, forces)):
            set_axis(m, i, frame, *axis.tolist())
            set_param(m, lib.dParamFMax + i * lib.dParamGroup,
                      lib.dInfinity if force < 0 else force)
            set_param(m, lib.dParamVel + i * lib.dParamGroup, 0.0)
        motor = _Motor(motor_id, owner, kind, naxes, joint or None, (body1, body2))
        self._motors[motor_id] = motor
        if joint_record is not None:
            joint_record.motors.add(motor_id)
        for o in objects:
            if o is not None:
                o.motors.add(motor_id)
        self._rebuild_motors()
        drain_ode_messages()
        return motor_id

    def _motor(self, motor_id: str) -> _Motor:
        try:
            return self._motors[motor_id]
        except (KeyError, TypeError):
            raise UnknownName(f"no motor {motor_id!r}") from None

    @_locked
    def motor_ids(self) -> List[str]:
        return list(self._motors)

    @_locked
    def motor_axis_counts(self, motor_ids: Sequence[str]) -> List[int]:
        """Number of axes of each motor (how many goal speeds it takes); unknown ids raise."""
        return [self._motor(motor_id).naxes for motor_id in motor_ids]

    @_locked
    def remove_motor(self, motor_id: str) -> None:
        self._motor(motor_id)
        self._remove_motor(motor_id)

    def _remove_motor(self, motor_id: str) -> None:
        motor = self._motors.pop(motor_id)
        if motor.joint and motor.joint in self._joints:
            self._joints[motor.joint].motors.discard(motor_id)
        for body in motor.bodies:
            if body:
                self._objects[body].motors.discard(motor_id)
        self._rebuild_motors()  # before the handle goes: C must never see a freed motor
        motor.owner.close()

    @_locked
    def set_motor_velocities(self, velocities: Mapping[str, Sequence[float]]) -> None:
        """Goal speeds (rad/s or m/s) per motor axis; all validated before any is set."""
        checked = []
        for motor_id, values in dict(velocities).items():
            motor = self._motor(motor_id)
            vector = _vector(f"velocities of {motor_id!r}", values, len(values)) \
                if hasattr(values, "__len__") else None
            if vector is None or vector.size != motor.naxes:
                raise InvalidArgument(f"motor {motor_id!r} has {motor.naxes} axes; got "
                                      f"{values!r}")
            checked.append((motor, vector.tolist()))
        for motor, values in checked:
            motor.velocity = values
            self._update_motor_slot(motor)

    def _rebuild_motors(self) -> None:
        motors = list(self._motors.values())
        array = ffi.new("OdinMotorGoal[]", max(len(motors), 1))
        self._motor_slots = {}
        for i, motor in enumerate(motors):
            array[i].motor = motor.owner.ptr
            array[i].kind = motor.kind
            array[i].naxes = motor.naxes
            for k, v in enumerate(motor.velocity):
                array[i].velocity[k] = v
            self._motor_slots[motor.id] = i
        self._cworld.motors = array
        self._cworld.n_motors = len(motors)
        self._motors_array = array

    def _update_motor_slot(self, motor: _Motor) -> None:
        slot = self._motors_array[self._motor_slots[motor.id]]
        for k, v in enumerate(motor.velocity):
            slot.velocity[k] = v

    # ------------------------------------------------------------------ forces

    @_locked
    def add_body_force(self, object_id: str, kind: int, vector, vector_in_body_frame: bool = False,
                       at_point: bool = False, point=(0.0, 0.0, 0.0),
                       point_in_body_frame: bool = False) -> str:
        """A persistent force (N) or torque (N m) on an object's body, re-applied before every
        step until removed. vector in the world or the object's frame; a force acts at the
        centre of mass or at `point` (m, world or object frame: a torque appears).
        Returns "force:<object>:<n>" or "torque:<object>:<n>", n the first free number."""
        if isinstance(kind, bool) or kind not in (FORCE, TORQUE):
            raise InvalidArgument(f"force kind {kind!r} is not FORCE (0) or TORQUE (1)")
        obj = self._body_object(object_id, "force")
        vector = _vector("force vector", vector)
        vector_in_body_frame = _bool("vector_in_body_frame", vector_in_body_frame)
        at_point = _bool("at_point", at_point)
        point = _vector("force point", point)
        point_in_body_frame = _bool("point_in_body_frame", point_in_body_frame)
        if kind == TORQUE and at_point:
            raise InvalidArgument("a torque has no point of application (at_point=True)")
        if at_point and point_in_body_frame:
            point = point - obj.com  # object frame -> ODE body frame (centre of mass)
        prefix = ("force", "torque")[kind]
        n = 0
        while f"{prefix}:{object_id}:{n}" in self._body_forces:
            n += 1
        force_id = f"{prefix}:{object_id}:{n}"
        self._body_forces[force_id] = (object_id, kind, vector_in_body_frame, at_point,
                                       point_in_body_frame, vector, point)
        obj.forces.add(force_id)
        self._rebuild_body_forces()
        return force_id

    @_locked
    def remove_body_force(self, force_id: str) -> None:
        if force_id not in self._body_forces:
            raise UnknownName(f"no body force {force_id!r}")
        object_id = self._body_forces.pop(force_id)[0]
        self._objects[object_id].forces.discard(force_id)
        self._rebuild_body_forces()

    @_locked
    def body_force_ids(self) -> List[str]:
        return list(self._body_forces)

    def _rebuild_body_forces(self) -> None:
        forces = list(self._body_forces.values())
        array = ffi.new("OdinBodyForce[]", max(len(forces), 1))
        for i, (object_id, kind, v_body, at_point, p_body, vector, point) in enumerate(forces):
            f = array[i]
            f.body = self._objects[object_id].body.ptr
            f.torque, f.vector_in_body, f.at_point, f.point_in_body = kind, v_body, at_point, p_body
            f.vector = vector.tolist()
            f.point = point.tolist()
        self._cworld.forces = array
        self._cworld.n_forces = len(forces)
        self._forces_array = array

    @_locked
    def add_joint_force(self, joint_id: str, magnitudes: Sequence[float]) -> str:
        """A persistent force/torque on a joint, applied before every step until removed.

        magnitudes per joint type: hinge [torque]; slider [force]; piston [force];
        universal, hinge2 [torque1, torque2]; PR [force along axis1, torque about axis2];
        PU [torque about axis1, torque about axis2]; ball [tx, ty, tz] a world-frame torque on
        body1 (and its opposite on body2). Fixed and plane-2D joints take none (Unsupported).
        Returns "jointforce:<joint>:<n>"."""
        joint = self._joint(joint_id)
        if joint.type not in _JOINT_FORCE_AXES:
            raise Unsupported(f"ODE has no force or torque for {JOINT_TYPE_NAMES[joint.type]}"
                              f" joint {joint_id!r}")
        count = _JOINT_FORCE_AXES[joint.type]
        try:
            n_values = len(magnitudes)
        except TypeError:
            raise InvalidArgument(f"magnitudes {magnitudes!r} is not a sequence") from None
        if n_values != count:
            raise InvalidArgument(f"a {JOINT_TYPE_NAMES[joint.type]} joint force takes {count} "
                                  f"magnitude(s); got {list(magnitudes)!r}")
        values = _vector("joint force magnitudes", magnitudes, count)
        n = 0
        while f"jointforce:{joint_id}:{n}" in self._joint_forces:
            n += 1
        force_id = f"jointforce:{joint_id}:{n}"
        self._joint_forces[force_id] = (joint_id, joint.type, values)
        joint.forces.add(force_id)
        self._rebuild_joint_forces()
        return force_id

    @_locked
    def remove_joint_force(self, force_id: str) -> None:
        if force_id not in self._joint_forces:
            raise UnknownName(f"no joint force {force_id!r}")
        joint_id = self._joint_forces.pop(force_id)[0]
        self._joints[joint_id].forces.discard(force_id)
        self._rebuild_joint_forces()

    def _rebuild_joint_forces(self) -> None:
        forces = list(self._joint_forces.values())
        array = ffi.new("OdinJointForce[]", max(len(forces), 1))
        for i, (joint_id, joint_type, values) in enumerate(forces):
            array[i].joint = self._joints[joint_id].owner.ptr
            array[i].type = _ODE_JOINT_TYPE[joint_type]
            for k, v in enumerate(values.tolist()):
                array[i].magnitude[k] = v
        self._cworld.joint_forces = array
        self._cworld.n_joint_forces = len(forces)
        self._joint_forces_array = array

    # ------------------------------------------------------------------ state

    @_locked
    def set_poses(self, poses: Sequence[Tuple[str, Sequence[float], Sequence[float]]],
                  reset_velocity: bool = False) -> None:
        """Moves objects: (object id, position m world, orientation wxyz) each, all or
        nothing. reset_velocity zeroes the bodies' linear and angular velocities."""
        reset_velocity = _bool("reset_velocity", reset_velocity)
        checked = []
        for item in poses:
            try:
                object_id, position, orientation = item
            except (TypeError, ValueError):
                raise InvalidArgument(f"{item!r} is not (id, position, orientation)") from None
            obj = self._object(object_id)
            checked.append((obj, _vector(f"position of {object_id!r}", position),
                            _quaternion(f"orientation of {object_id!r}", orientation)))
        for obj, position, orientation in checked:
            if obj.body is not None:
                body = obj.body.ptr
                lib.dBodySetPosition(body, *(position + _rotation(orientation) @ obj.com).tolist())
                lib.dBodySetQuaternion(body, orientation.tolist())
                if reset_velocity:
                    lib.dBodySetLinearVel(body, 0.0, 0.0, 0.0)
                    lib.dBodySetAngularVel(body, 0.0, 0.0, 0.0)
            else:
                for g in obj.geometries:
                    self._place_static(g.owner.ptr, position, orientation, g.position,
                                       g.orientation)

    @_locked
    def set_velocity(self, object_id: str, linear=None, angular=None) -> None:
        """Sets the linear velocity of the centre of mass (m/s, world) and/or the angular
        velocity (rad/s, world) of a body; None keeps the current one. A fixed (kinematic)
        body then moves at that velocity."""
        obj = self._body_object(object_id, "set_velocity")
        linear = None if linear is None else _vector("linear velocity", linear)
        angular = None if angular is None else _vector("angular velocity", angular)
        if linear is not None:
            lib.dBodySetLinearVel(obj.body.ptr, *linear.tolist())
        if angular is not None:
            lib.dBodySetAngularVel(obj.body.ptr, *angular.tolist())

    @_locked
    def body_state(self, object_id: str) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(position of the object origin m, orientation wxyz, linear velocity of the centre of
        mass m/s, angular velocity rad/s), world frame."""
        obj = self._body_object(object_id, "body_state")
        b = obj.body.ptr
        p, q = lib.dBodyGetPosition(b), lib.dBodyGetQuaternion(b)
        v, w = lib.dBodyGetLinearVel(b), lib.dBodyGetAngularVel(b)
        quat = np.array([q[0], q[1], q[2], q[3]])
        com_W = np.array([p[0], p[1], p[2]])
        return (com_W - _rotation(quat) @ obj.com, quat, np.array([v[0], v[1], v[2]]),
                np.array([w[0], w[1], w[2]]))

    @_locked
    def mass_properties(self, object_id: str) -> Tuple[float, np.ndarray, np.ndarray]:
        """(mass kg, centre of mass (3,) m in the object frame, inertia (3,3) kg m^2 about the
        centre of mass, object axes) as ODE holds them."""
        obj = self._body_object(object_id, "mass_properties")
        m = ffi.new("dMass *")
        lib.dBodyGetMass(obj.body.ptr, m)
        inertia = np.array([[m.I[4 * r + c] for c in range(3)] for r in range(3)])
        return float(m.mass), obj.com.copy(), inertia

    # ------------------------------------------------------------------ step and read-out

    @_locked
    def step(self, step_size: float, count: int = 1) -> None:
        """Runs `count` steps of `step_size` s, all in one C call: collide (contacts or
        recording), body forces, joint forces and motor goals, (Quick)Step, empty contacts."""
        step_size = _number("step_size", step_size)
        if step_size <= 0:
            raise InvalidArgument(f"step_size={step_size!r} must be positive")
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
            raise InvalidArgument(f"count={count!r} must be a positive integer")
        if not self._parameters.contact_less:
            self._carry = {}
        lib.odin_world_step(self._cworld, step_size, int(count))
        self._sim_time += step_size * int(count)
        drain_ode_messages()

    @_locked
    def detect_collisions(self) -> None:
        """Contact-less policy: collision detection on the present poses without a step, so
        that read_collisions() reports what touches now in a paused world whose objects were
        moved (Set Position). Does nothing under the contact policy."""
        lib.odin_world_detect(self._cworld)
        drain_ode_messages()

    @property
    def sim_time(self) -> float:
        """Simulated seconds since the scene began."""
        return self._sim_time

    @property
    def last_step_contacts(self) -> int:
        """Contact joints created in the last step."""
        return int(self._cworld.last_step_contacts)

    @_locked
    def poses(self) -> Tuple[List[str], np.ndarray, np.ndarray]:
        """Every geometry (composite parts one by one, static ones too): names, positions
        (n,3) m and quaternions (n,4) wxyz, world frame; read in one C call."""
        if self._geom_array is None:
            self._pose_names = list(self._geometries)
            self._geom_array = ffi.new("dGeomID[]", [self._geometries[n].owner.ptr
                                                    for n in self._pose_names] or 1)
        n = len(self._pose_names)
        positions = np.empty((n, 3))
        quaternions = np.empty((n, 4))
        if n:
            lib.odin_read_poses(self._geom_array, n,
                                ffi.cast("double *", ffi.from_buffer(positions)),
                                ffi.cast("double *", ffi.from_buffer(quaternions)))
        return list(self._pose_names), positions, quaternions

    def _c_collisions(self) -> List[Collision]:
        w = self._cworld
        result = []
        for i in range(w.n_records):
            r = w.records[i]
            first = self._geom_names[int(ffi.cast("uintptr_t", r.g1))]
            second = self._geom_names[int(ffi.cast("uintptr_t", r.g2))]
            if second < first:
                first, second = second, first
            points = tuple((r.points[k][0], r.points[k][1], r.points[k][2])
                           for k in range(r.npoints))
            result.append(Collision(first, second, float(r.depth), points))
        return result

    def _carry_collisions(self, removed_names: Set[str]) -> None:
        """Before geoms go: move the C records to Python (names), dropping `removed_names`."""
        for c in self._c_collisions():
            key = (c.first, c.second)
            old = self._carry.get(key)
            if old is None or c.depth > old.depth:
                self._carry[key] = c
        lib.odin_world_clear_records(self._cworld)
        for key in [k for k in self._carry if k[0] in removed_names or k[1] in removed_names]:
            del self._carry[key]

    def _forget_collisions(self) -> None:
        lib.odin_world_clear_records(self._cworld)
        self._carry = {}

    @_locked
    def read_collisions(self) -> List[Collision]:
        """Colliding geometry pairs (names sorted within a pair), deepest depth and points.

        Contact-less policy: every pair seen since the last read (deepest occurrence); reading
        clears the set. Contact policy: the pairs that had contacts in the last step."""
        self._carry_collisions(set())
        result = sorted(self._carry.values())
        if self._parameters.contact_less:
            self._carry = {}
        return result
