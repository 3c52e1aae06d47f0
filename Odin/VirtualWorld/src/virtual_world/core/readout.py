"""What the world tells: geometry poses, body states, mass properties and collisions.

World frame, SI units, quaternions (w, x, y, z). An object's position is its frame's origin;
its linear velocity is that of its centre of mass.

Collisions: the C loop records colliding geom pairs by address; before a geom is freed its
records move into Python under names (``carry_collisions``), so a removal never loses, nor
misnames, what the next read reports.
"""
from __future__ import annotations

from typing import List, Set, Tuple

import numpy as np

from odin_common.rotations import quaternion_to_matrix
from virtual_world.core.records import Collision
from virtual_world.core.scene import Scene
from virtual_world.ode import bodies


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
    for address1, address2, depth, points, first_step in scene.c.records():
        first = scene.geometry_names[address1]
        second = scene.geometry_names[address2]
        if second < first:
            first, second = second, first
        result.append((Collision(first, second, depth, points), first_step))
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
