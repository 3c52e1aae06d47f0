"""Collision queries for a geometric planner (gui.planning.geometric), ROS-free: a
``CollisionProbe`` is made once for a scene's robots and then asked, thousands of times a
second, whether their links touch anything at given poses, and how far capsules or boxes
bounding them are from everything else. Each call costs one C call (odin_query.c), not a
Check Collision request's: the poses are checked as arrays, and nothing is put back (the links
stay where the last call put them; a planner's world is its own).

Which pairs may touch is the step's rule (odin_pair_never_touches: not two geoms of one entity
without internal collisions, of one body, or of bodies a joint joins). A probe is bound to the
objects the scene held when it was made: once any is removed or added (or the scene is new), it
refuses every call.
"""
from __future__ import annotations

from typing import List, Optional, Sequence, Tuple

import numpy as np

from odin_common.limits import shown
from virtual_world.core.scene import Scene
from virtual_world.errors import InvalidArgument
from virtual_world.ode.queries import (BOUND_BOX, BOUND_CAPSULE, BOUND_VALUES, GeomQuery,
                                       never_touch)

MAX_TIERS = 64
"""The most growths a clearance query takes (each costs a probe per bound at most)."""
ORTHONORMAL_TOLERANCE = 1e-6
"""How far a pose's rotation may be from orthonormal (largest entry of R R^T - I)."""


class CollisionProbe:
    """The objects ``moved`` (with bodies) placed and asked about; the objects ``apart``
    (their geometries) not asked against by ``clearances`` (a robot's own links, whose pairs
    the planner bounds itself); ``tiers`` (m, descending, at most MAX_TIERS): the growths
    ``clearances`` finds the largest clear one among."""

    def __init__(self, scene: Scene, moved: Sequence[str], apart: Sequence[str] = (),
                 tiers: Sequence[float] = (0.1,)):
        moved, apart = _object_ids("moved", scene, moved), _object_ids("apart", scene, apart)
        self.tiers = _tiers(tiers, scene.parameters.world_extent)
        records = [scene.object(object_id) for object_id in moved]
        static = [r.id for r in records if r.body is None]
        if static:
            raise InvalidArgument(f"moved: {shown(static[0])} has no body to move")
        self.moved: Tuple[str, ...] = tuple(moved)
        self._scene = scene
        self._revision = scene.revision
        self._com = np.array([r.com for r in records], dtype=float).reshape(-1, 3)
        self._query = GeomQuery(
            scene.c.struct, [r.body.ptr for r in records],
            [g.owner.ptr for r in records for g in r.geometries],
            [g.owner.address for i in apart for g in scene.object(i).geometries])

    def _same_scene(self, scene: Scene) -> None:
        if scene is not self._scene or scene.revision != self._revision:
            raise InvalidArgument("the world's objects changed since this collision probe "
                                  "was made: make a new one")

    def touching(self, scene: Scene, poses) -> Optional[Tuple[str, str]]:
        """Puts the moved objects at ``poses`` ((n, 4, 4): each object's frame, m, world, in
        ``moved``'s order) and answers the first pair (geometry names) touching one of them,
        or None."""
        self._same_scene(scene)
        poses = _poses(poses, len(self.moved), scene.parameters.world_extent)
        rotations = poses[:, :3, :3]
        centres = poses[:, :3, 3] + np.einsum("nij,nj->ni", rotations, self._com)
        self._query.place(np.hstack([centres, rotations.reshape(-1, 9)]))
        hit = self._query.touching()
        if hit is None:
            return None
        return scene.geometry_names[hit[0]], scene.geometry_names[hit[1]]

    def clearances(self, scene: Scene, bounds, needed=None) -> np.ndarray:
        """Per bound ((m, BOUND_VALUES): a capsule or a box, m, world:
        virtual_world.ode.queries), the first of the probe's ``tiers`` (m, descending) by
        which it can grow without touching any geometry but those of ``apart``, else 0: a
        lower bound of its distance to them (m). ``needed`` (m, per bound; None: all inf):
        the most of use to the caller: no tier beyond the smallest one that reaches it is
        asked (a larger growth meets more of a large mesh, and costs more)."""
        self._same_scene(scene)
        extent = scene.parameters.world_extent
        bounds = _bounds(_finite_array("bounds", bounds, (-1, BOUND_VALUES), extent))
        needed = np.full(len(bounds), np.inf) if needed is None else \
            np.asarray(needed, dtype=float).reshape(-1)
        if len(needed) != len(bounds) or np.any(np.isnan(needed)):
            raise InvalidArgument(f"needed: one value (m, not NaN) per bound, {len(bounds)}")
        # the index of the smallest tier >= needed (tiers descend); 0 when none reaches it
        reaching = len(self.tiers) - np.searchsorted(self.tiers[::-1], needed, side="left")
        return self._query.clearances(bounds, self.tiers, np.maximum(reaching - 1, 0))


def _tiers(tiers, extent: float) -> np.ndarray:
    tiers = _finite_array("tiers", tiers, (-1,), extent)
    if not 1 <= len(tiers) <= MAX_TIERS or np.any(tiers <= 0.0) or np.any(
            np.diff(tiers) >= 0.0):
        raise InvalidArgument(f"tiers: 1 to {MAX_TIERS} positive values, descending")
    return np.ascontiguousarray(tiers)


def _bounds(bounds: np.ndarray) -> np.ndarray:
    """Capsules and boxes, checked: a known kind, sizes not negative, a box's rotation
    orthonormal."""
    box = bounds[:, 0] == BOUND_BOX
    if not np.all(box | (bounds[:, 0] == BOUND_CAPSULE)):
        raise InvalidArgument(f"bounds: a kind is neither {BOUND_CAPSULE} (capsule) nor "
                              f"{BOUND_BOX} (box)")
    boxes = bounds[box]
    if np.any(bounds[~box, 7] < 0.0) or np.any(boxes[:, 13:16] < 0.0):
        raise InvalidArgument("bounds: a radius or a half side is negative")
    _orthonormal("bounds", boxes[:, 4:13].reshape(-1, 3, 3))
    return bounds


_IDENTITY = np.eye(3)


def _orthonormal(what: str, rotations: np.ndarray) -> None:
    if not len(rotations):
        return
    error = np.einsum("nij,nkj->nik", rotations, rotations) - _IDENTITY
    if not float(np.max(np.abs(error))) <= ORTHONORMAL_TOLERANCE:
        raise InvalidArgument(f"{what}: a rotation is not orthonormal")


def pairs_that_may_touch(scene: Scene, object_ids: Sequence[str]) -> List[Tuple[str, str]]:
    """The pairs of the objects ``object_ids`` (in that order within a pair) that a step may
    collide: some geometry of one and some of the other are not of one body, one entity
    without internal collisions, or bodies a joint joins."""
    records = [scene.object(i) for i in _object_ids("objects", scene, object_ids)]
    return [(a.id, b.id) for n, a in enumerate(records) for b in records[n + 1:]
            if any(not never_touch(g.owner.ptr, h.owner.ptr)
                   for g in a.geometries for h in b.geometries)]


def _object_ids(what: str, scene: Scene, ids: Sequence[str]) -> Tuple[str, ...]:
    ids = tuple(ids)
    if len(ids) > len(scene.objects) or len(set(ids)) != len(ids):
        raise InvalidArgument(f"{what}: each of the world's objects at most once")
    for object_id in ids:
        scene.object(object_id)         # InvalidArgument naming an unknown one
    return ids


def _finite_array(what: str, values, shape, extent: float) -> np.ndarray:
    try:
        array = np.asarray(values, dtype=float).reshape(shape)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}: not an array of shape {shape}") from None
    largest = float(np.max(np.abs(array))) if array.size else 0.0
    if not largest <= extent:       # NaN and inf too
        raise InvalidArgument(f"{what}: every value finite and within the world's extent "
                              f"({extent:g} m)")
    return array


def _poses(poses, count: int, extent: float) -> np.ndarray:
    poses = _finite_array("poses", poses, (-1, 4, 4), extent)
    if len(poses) != count:
        raise InvalidArgument(f"poses: {len(poses)} given for {count} moved objects")
    _orthonormal("poses", poses[:, :3, :3])
    return poses


