"""ODE's bodies, geoms and mass records, as the Core uses them: poses, velocities, kinematic
bodies, geom offsets and collision bits, and dMass arithmetic.

Frames: an ODE body sits at its centre of mass with the object's axes; positions and velocities
here are ODE's (centre of mass, world frame), quaternions (w, x, y, z). The Core converts
between an object's frame and its centre of mass. Arguments are already checked.
"""
from __future__ import annotations

import math
from typing import Sequence, Tuple

import numpy as np

from odin_common import interface
from virtual_world.ode.bindings import ffi, lib
from virtual_world.ode.runtime import drains_ode_messages

IDENTITY = (1.0, 0.0, 0.0, 0.0)


# ---------------------------------------------------------------------------------- bodies

@drains_ode_messages
def configure_body(body, dmass, com_position: Sequence[float], quaternion: Sequence[float],
                   kinematic: bool) -> None:
    """Sets a new body's mass (centred: its centre of mass at the body origin), pose, and makes
    it kinematic (infinite mass for contacts and joints, moved only by its velocity)."""
    lib.dBodySetMass(body, dmass)
    set_body_pose(body, com_position, quaternion)
    if kinematic:
        lib.dBodySetKinematic(body)


@drains_ode_messages
def set_body_pose(body, com_position: Sequence[float], quaternion: Sequence[float]) -> None:
    lib.dBodySetPosition(body, *com_position)
    lib.dBodySetQuaternion(body, list(quaternion))


@drains_ode_messages
def set_body_velocity(body, linear: Sequence[float] = None,
                      angular: Sequence[float] = None) -> None:
    """Linear velocity of the centre of mass (m/s) and/or angular velocity (rad/s), world;
    None keeps the current one."""
    if linear is not None:
        lib.dBodySetLinearVel(body, *linear)
    if angular is not None:
        lib.dBodySetAngularVel(body, *angular)


def body_state(body) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(centre of mass (3,) m, quaternion (4,), linear velocity (3,) m/s, angular velocity
    (3,) rad/s), world frame."""
    p, q = lib.dBodyGetPosition(body), lib.dBodyGetQuaternion(body)
    v, w = lib.dBodyGetLinearVel(body), lib.dBodyGetAngularVel(body)
    return (np.array([p[0], p[1], p[2]]), np.array([q[0], q[1], q[2], q[3]]),
            np.array([v[0], v[1], v[2]]), np.array([w[0], w[1], w[2]]))


def is_awake(body) -> bool:
    """False while ODE's auto-disabling keeps the body asleep."""
    return bool(lib.dBodyIsEnabled(body))


@drains_ode_messages
def unpark(body, collide: bool) -> None:
    """Undoes the divergence guard's parking (odin_step.c): the body dynamic again, its geoms
    colliding again unless ``collide`` is False (an object without collisions)."""
    lib.dBodySetDynamic(body)
    bits = 0 if not collide else ffi.cast("unsigned long", -1)
    geom = lib.dBodyGetFirstGeom(body)
    while geom != ffi.NULL:
        lib.dGeomSetCategoryBits(geom, bits)
        lib.dGeomSetCollideBits(geom, bits)
        geom = lib.dBodyGetNextGeom(geom)


@drains_ode_messages
def park(body) -> None:
    """Parks a body as the divergence guard does: kinematic, still, colliding with nothing."""
    lib.dBodySetKinematic(body)
    set_body_velocity(body, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    geom = lib.dBodyGetFirstGeom(body)
    while geom != ffi.NULL:
        lib.dGeomSetCategoryBits(geom, 0)
        lib.dGeomSetCollideBits(geom, 0)
        geom = lib.dBodyGetNextGeom(geom)


def body_mass(body) -> Tuple[float, np.ndarray]:
    """(mass kg, inertia (3, 3) kg m^2 about the centre of mass, body axes)."""
    m = ffi.new("dMass *")
    lib.dBodyGetMass(body, m)
    return float(m.mass), inertia_matrix(m)


BODY_STATE_SIZE = lib.ODIN_BODY_STATE_SIZE
"""Doubles per body in read_states/write_states (odin_step.h: position, quaternion, rotation
matrix, linear and angular velocity, enabled; odin_common.interface.BODY_STATE_FIELDS names
them for the clients of Propagate's state vectors)."""
assert BODY_STATE_SIZE == interface.BODY_STATE_SIZE, "odin_step.h and BODY_STATE_FIELDS differ"


def read_states(bodies: Sequence) -> np.ndarray:
    """(n, BODY_STATE_SIZE) float64: the dynamic state of each body, bit for bit."""
    out = np.empty((len(bodies), BODY_STATE_SIZE))
    if len(bodies):
        array = ffi.new("dBodyID[]", list(bodies))
        lib.odin_read_body_states(array, len(bodies), ffi.cast("double *", ffi.from_buffer(out)))
    return out


def state_vector_fault(vector: np.ndarray, flags: int = 0) -> int:
    """-1 when a body state vector (contiguous float64) can be put back: a 32-bit integer
    generator state, finite values, its last ``flags`` values (exempt pairs' states) 0.0 or
    1.0; else the index of the first value that is not."""
    return int(lib.odin_state_vector_fault(ffi.from_buffer("double[]", vector), vector.size,
                                           flags))


@drains_ode_messages
def write_states(bodies: Sequence, states: np.ndarray) -> None:
    """Puts back states read by read_states, bit for bit (odin_state.c says how)."""
    if len(bodies):
        states = np.ascontiguousarray(states, dtype=np.float64)
        array = ffi.new("dBodyID[]", list(bodies))
        lib.odin_write_body_states(array, len(bodies),
                                   ffi.cast("double *", ffi.from_buffer(states)))


# ---------------------------------------------------------------------------------- geoms

@drains_ode_messages
def set_geom_offset(geom, position: Sequence[float], quaternion: Sequence[float]) -> None:
    """Places a geom attached to a body relative to the body (centre of mass, body axes)."""
    if any(v != 0 for v in position):
        lib.dGeomSetOffsetPosition(geom, *position)
    if tuple(quaternion) != IDENTITY:
        lib.dGeomSetOffsetQuaternion(geom, list(quaternion))


@drains_ode_messages
def set_geom_pose(geom, position: Sequence[float], quaternion: Sequence[float]) -> None:
    """Places a static (body-less) geom, world frame."""
    lib.dGeomSetPosition(geom, *position)
    lib.dGeomSetQuaternion(geom, list(quaternion))


def is_plane(geom) -> bool:
    """ODE's planes are not placeable: asking one for its position ends the process."""
    return lib.dGeomGetClass(geom) == lib.dPlaneClass


def static_geom_pose(geom) -> np.ndarray:
    """(15,) a static geom's position (3) and rotation matrix (12), bit for bit; a plane's
    parameters a, b, c, d (then zeros)."""
    if is_plane(geom):
        abcd = ffi.new("dVector4")
        lib.dGeomPlaneGetParams(geom, abcd)
        return np.array([abcd[0], abcd[1], abcd[2], abcd[3]] + [0.0] * 11)
    p, R = lib.dGeomGetPosition(geom), lib.dGeomGetRotation(geom)
    return np.array([p[0], p[1], p[2]] + [R[k] for k in range(12)])


@drains_ode_messages
def set_static_geom_pose(geom, pose: np.ndarray) -> None:
    """Puts back a pose read by static_geom_pose (ODE copies both as given)."""
    if is_plane(geom):
        lib.dGeomPlaneSetParams(geom, *pose[:4].tolist())
        return
    lib.dGeomSetPosition(geom, *pose[:3].tolist())
    lib.dGeomSetRotation(geom, pose[3:].tolist())


@drains_ode_messages
def place_plane(geom, normal: Sequence[float], offset: float) -> None:
    """Moves a plane: normal . x = offset (m), world frame."""
    lib.dGeomPlaneSetParams(geom, *normal, offset)


def set_surface(geom_owner, surface) -> None:
    """The geom's contact properties (odin_common.specs.Surface, already checked), which
    odin_step.c mixes with the other geom's for each contact."""
    info = geom_owner.data
    info.has_friction = surface.friction is not None
    info.mu = lib.dInfinity if info.has_friction and math.isinf(surface.friction) else \
        (surface.friction or 0.0)
    info.has_friction2 = surface.friction2 is not None
    info.mu2 = surface.friction2 or 0.0
    info.fdir = list(surface.friction_direction)
    info.has_bounce = surface.bounce is not None
    info.bounce = surface.bounce or 0.0
    info.bounce_vel = surface.bounce_velocity
    info.has_softness = surface.stiffness is not None
    info.kp = surface.stiffness or 0.0
    info.kd = surface.damping


def set_geom_tag(geom_owner, tag: int) -> None:
    """Two geoms with the same non-zero tag never collide (an entity without internal
    collisions; odin_step.c's near-callback reads it from the geom's OdinGeomInfo)."""
    geom_owner.data.tag = tag


@drains_ode_messages
def exclude_from_collisions(geom) -> None:
    """The space never pairs a geom whose category and collide bits are all clear."""
    lib.dGeomSetCategoryBits(geom, 0)
    lib.dGeomSetCollideBits(geom, 0)


def triangle_count(geom) -> int:
    return int(lib.dGeomTriMeshGetTriangleCount(geom))


# ---------------------------------------------------------------------------------- mass

@drains_ode_messages
def primitive_mass(kind: str, dims: Sequence[float], mass: float):
    """dMass of a sphere, cylinder (along z) or box of total ``mass`` kg about its centre."""
    m = ffi.new("dMass *")
    if kind == "sphere":
        lib.dMassSetSphereTotal(m, mass, dims[0])
    elif kind == "cylinder":
        lib.dMassSetCylinderTotal(m, mass, 3, dims[0], dims[1])
    elif kind == "capsule":
        lib.dMassSetCapsuleTotal(m, mass, 3, dims[0], dims[1])
    elif kind == "box":
        lib.dMassSetBoxTotal(m, mass, *dims)
    else:
        raise ValueError(f"no primitive mass for {kind!r}")
    return m


@drains_ode_messages
def mass_from_parameters(mass: float, center: Sequence[float], inertia: np.ndarray):
    """dMass of ``mass`` kg with ``inertia`` (3, 3) kg m^2 about ``center`` (m), which is
    then where the dMass's centre lies."""
    m = ffi.new("dMass *")
    i = inertia
    lib.dMassSetParameters(m, mass, 0.0, 0.0, 0.0, i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2],
                           i[1, 2])
    lib.dMassTranslate(m, *center)
    return m


@drains_ode_messages
def zero_mass():
    m = ffi.new("dMass *")
    lib.dMassSetZero(m)
    return m


@drains_ode_messages
def add_mass(total, part, position: Sequence[float], quaternion: Sequence[float]) -> None:
    """Adds ``part`` (a dMass in the part's frame), rotated by ``quaternion`` and moved to
    ``position``, to ``total``."""
    R = ffi.new("dMatrix3")
    lib.dRfromQ(R, list(quaternion))
    lib.dMassRotate(part, R)
    lib.dMassTranslate(part, *position)
    lib.dMassAdd(total, part)


def mass_center(m) -> np.ndarray:
    return np.array([m.c[0], m.c[1], m.c[2]])


@drains_ode_messages
def center_mass(m) -> None:
    """Moves a dMass so that its centre of mass is its origin (ODE's bodies need that)."""
    lib.dMassTranslate(m, *(-mass_center(m)).tolist())


def inertia_matrix(m) -> np.ndarray:
    return np.array([[m.I[4 * r + c] for c in range(3)] for r in range(3)])


@drains_ode_messages
def mass_is_valid(m) -> bool:
    """ODE's own check (dMassCheck); it reports through ODE's message handler when false."""
    return bool(lib.dMassCheck(m))


def set_kinematic_link(body, on: bool) -> None:
    """Makes a body a link of the kinematic drive (kinematic, finite rotation, never
    auto-disabled, awake) or dynamic again (its mass back; odin_kinematic.c)."""
    lib.odin_kinematic_set(body, int(bool(on)))
