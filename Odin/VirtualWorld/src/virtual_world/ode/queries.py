"""The geometric planner's collision queries in C (odin_query.c) over one scene's world:
``GeomQuery`` holds, in C arrays, the bodies it places, the geoms it asks about and the geoms
its capsules do not ask against, for as long as the scene holds them (its owner,
``virtual_world.core.probe.CollisionProbe``, checks that before every call: C must never see a
freed handle). Arguments are the caller's to check (finite, within the world): this layer only
converts them.
"""
from __future__ import annotations

from typing import Optional, Sequence, Tuple

import numpy as np

from virtual_world.ode.bindings import ffi, lib
from virtual_world.ode.runtime import drains_ode_messages

POSE_VALUES = 12
"""A placed body's values: centre of mass (3, m, world), rotation matrix row by row (9)."""
BOUND_VALUES = int(lib.ODIN_BOUND_VALUES)
"""A bound's values (odin_step.h): its kind (BOUND_CAPSULE: ends a and b (3 each), radius; or
BOUND_BOX: centre (3), rotation row by row (9), half sides (3); m, world), zeros after."""
BOUND_CAPSULE = int(lib.ODIN_BOUND_CAPSULE)
BOUND_BOX = int(lib.ODIN_BOUND_BOX)


def never_touch(first, second) -> bool:
    """Whether a step never collides geoms ``first`` and ``second`` (C pointers), whatever
    their poses (odin_pair_never_touches)."""
    return bool(lib.odin_pair_never_touches(first, second))


def _doubles(array: np.ndarray):
    return ffi.cast("double *", ffi.from_buffer(array))


class GeomQuery:
    """``bodies`` placed by ``place``; ``geoms`` asked by ``touching``; ``apart`` (geom
    addresses) not asked against by ``clearances``. ``world``: the scene's CWorld struct."""

    def __init__(self, world, bodies: Sequence, geoms: Sequence, apart: Sequence[int]):
        self._world = world
        self._bodies = ffi.new("dBodyID[]", list(bodies) or 1)
        self._body_count = len(bodies)
        self._geoms = ffi.new("dGeomID[]", list(geoms) or 1)
        self._geom_count = len(geoms)
        self._apart = ffi.new("uintptr_t[]", sorted(apart) or 1)
        self._apart_count = len(apart)
        self._hit = ffi.new("dGeomID[2]")
        # where each bound's clearance search starts: the last answer for the same row (a
        # caller asks about the same bounds in the same order, query after query)
        self._hints = np.zeros(0, dtype=np.intc)

    @drains_ode_messages
    def place(self, poses: np.ndarray) -> None:
        """Puts the bodies at ``poses`` (n, POSE_VALUES), in their order."""
        poses = np.ascontiguousarray(poses, dtype=float)
        lib.odin_place_bodies(self._bodies, self._body_count, _doubles(poses))

    @drains_ode_messages
    def touching(self) -> Optional[Tuple[int, int]]:
        """(geom address, geom address) of the first touching pair one of the geoms is in,
        with the step's rules for which pairs may touch; None when none touches."""
        if not lib.odin_geoms_touching(self._world, self._geoms, self._geom_count, self._hit):
            return None
        return (int(ffi.cast("uintptr_t", self._hit[0])),
                int(ffi.cast("uintptr_t", self._hit[1])))

    @drains_ode_messages
    def clearances(self, bounds: np.ndarray, tiers: np.ndarray, firsts: np.ndarray
                   ) -> np.ndarray:
        """Per bound (m, BOUND_VALUES), the first of ``tiers`` (m, descending) from index
        ``firsts`` (one per bound) on it can grow by and touch none of the world's geoms but
        ``apart``, else 0 (m)."""
        bounds = np.ascontiguousarray(bounds, dtype=float)
        tiers = np.ascontiguousarray(tiers, dtype=float)
        firsts = np.ascontiguousarray(firsts, dtype=np.intc)
        out = np.empty(len(bounds))
        if len(bounds) > len(self._hints):
            self._hints = np.zeros(len(bounds), dtype=np.intc)
        if len(bounds):
            lib.odin_bounds_clearance(self._world, _doubles(bounds), len(bounds),
                                      _doubles(tiers), len(tiers), self._apart,
                                      self._apart_count,
                                      ffi.cast("int *", ffi.from_buffer(firsts)),
                                      ffi.cast("int *", ffi.from_buffer(self._hints)),
                                      _doubles(out))
        return out
