"""What the world tells: geometry poses, body states, mass properties and collisions.

World frame, SI units, quaternions (w, x, y, z). An object's position is its frame's origin;
its linear velocity is that of its centre of mass.

Collisions: the C loop records colliding geom pairs by address; before a geom is freed its
records move into Python under names (``carry_collisions``), so a removal never loses, nor
misnames, what the next read reports.
"""
from __future__ import annotations

import math
from typing import List, Set, Tuple

import numpy as np

from odin_common.rotations import quaternion_to_matrix
from odin_common.interface import JointParameter
from virtual_world.core.records import (Collision, JointReaction, MotorState,
                                        ObjectState)
from virtual_world.core.scene import Scene
from virtual_world.ode import bodies
from virtual_world.ode import joints as ode_joints


def poses(scene: Scene) -> Tuple[List[str], np.ndarray, np.ndarray]:
    """Every geometry (composite parts one by one, static ones too): names, positions (n, 3)
    m and quaternions (n, 4), read in one C call."""
    names, reader = scene.pose_reader()
    positions, quaternions = reader.read()
    return list(names), positions, quaternions


def body_state(scene: Scene, object_id: str
               ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(position of the object's origin m, orientation, linear velocity of the centre of mass
    m/s, angular velocity rad/s)."""
    obj = scene.body_object(object_id, "body_state")
    com_W, quaternion, linear, angular = bodies.body_state(obj.body.ptr)
    return com_W - quaternion_to_matrix(quaternion) @ obj.com, quaternion, linear, angular


def mass_properties(scene: Scene, object_id: str) -> Tuple[float, np.ndarray, np.ndarray]:
    """(mass kg, centre of mass (3,) m in the object frame, inertia (3, 3) kg m^2 about the
    centre of mass, object axes) as ODE holds them."""
    obj = scene.body_object(object_id, "mass_properties")
    mass, inertia = bodies.body_mass(obj.body.ptr)
    return mass, obj.com.copy(), inertia


def named_records(scene: Scene) -> List[Tuple[Collision, int]]:
    """C's collision records under geometry names (sorted within a pair), each with the step
    count when it was first seen."""
    result = []
    for address1, address2, depth, points, first_step, normals, forces in scene.c.records():
        first = scene.geometry_names[address1]
        second = scene.geometry_names[address2]
        if second < first:   # named in order: normals and forces then act on the other one
            first, second = second, first
            normals = tuple(tuple(-v for v in n) for n in normals)
            forces = tuple(tuple(-v for v in f) for f in forces)
        result.append((Collision(first, second, depth, points, normals=normals, forces=forces),
                       first_step))
    return result


def carry_collisions(scene: Scene, removed_names: Set[str]) -> None:
    """Moves the C records into Python (deepest occurrence per pair), dropping the pairs of
    ``removed_names`` (geometries about to be freed)."""
    for c, _ in named_records(scene):
        key = (c.first, c.second)
        old = scene.carried.get(key)
        if old is None or c.depth > old.depth:
            scene.carried[key] = c
    scene.c.clear_records()
    for key in [k for k in scene.carried if k[0] in removed_names or k[1] in removed_names]:
        del scene.carried[key]


def touching_now(scene: Scene) -> List[Collision]:
    """The pairs touching on the present poses (names, deepest depth, points), found without
    stepping or contacts whatever the collision policy (a collision query); the records not
    yet read are kept for the next read, and the query leaves none of its own."""
    carry_collisions(scene, set())
    try:
        scene.c.detect(any_policy=True)
        return sorted(c for c, _ in named_records(scene))
    finally:
        scene.c.clear_records()


def forget_collisions(scene: Scene) -> None:
    scene.c.clear_records()
    scene.carried = {}


def read_collisions(scene: Scene) -> List[Collision]:
    """Colliding geometry pairs (names sorted within a pair), deepest depth and points.

    Contact-less policy: every pair seen since the last read (deepest occurrence); reading
    clears the set. Contact policy: the pairs that had contacts in the last step."""
    carry_collisions(scene, set())
    result = sorted(scene.carried.values())
    if scene.parameters.contact_less:
        scene.carried = {}
    return result


def object_states(scene: Scene, object_ids) -> List[ObjectState]:
    """ObjectState of each object asked for (all with a body when none), checked first."""
    ids = list(object_ids) or [i for i, o in scene.objects.items() if o.body is not None]
    for object_id in ids:
        scene.body_object(object_id, "state")
    out = []
    for object_id in ids:
        position, orientation, linear, angular = body_state(scene, object_id)
        mass, center, inertia = mass_properties(scene, object_id)
        out.append(ObjectState(object_id, *(tuple(v.tolist()) for v in (
            position, orientation, linear, angular)), mass, tuple(center.tolist()),
            tuple(inertia.reshape(-1).tolist())))
    return out


def joint_reactions(scene: Scene, joint_ids) -> List[JointReaction]:
    """JointReaction of each joint asked for (all when none), checked first."""
    ids = list(joint_ids) or list(scene.joints)
    records = [scene.joint(j) for j in ids]
    return [JointReaction(r.id, int(r.type), *ode_joints.joint_state(r.owner.ptr, r.type),
                          *ode_joints.reactions(r.owner)) for r in records]


def motor_states(scene: Scene, motor_ids) -> List[MotorState]:
    """MotorState of each motor asked for (all when none), checked first."""
    ids = list(motor_ids) or list(scene.motors)
    records = [scene.motor(m) for m in ids]
    return [MotorState(m.id, m.joint or "", tuple(m.velocity), tuple(
        _reported_force(ode_joints.motor_parameter(m.owner.ptr, m.kind,
                                                   JointParameter.MAX_FORCE, axis))
        for axis in range(1, m.naxes + 1))) for m in records]


def _reported_force(fmax: float) -> float:
    """A motor's maximum force as ODE holds it -> as a client reads it: ODE holds its
    infinity for an unlimited one, or ode.joints.UNLIMITED_FORCE on an axis with a stop:
    both read as math.inf."""
    return math.inf if fmax >= ode_joints.UNLIMITED_FORCE else fmax
