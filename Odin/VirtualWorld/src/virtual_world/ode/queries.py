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


ROBOT_ARRAYS = {
    # field of OdinKinematicRobot -> C type of its array
    "offset": "double", "matrix": "double", "dof_of_joint": "int", "joint_low": "double",
    "joint_span": "double", "joint_link": "int", "base_pose": "double", "base_box": "double",
    "base_rotation": "double", "fixed_part": "double", "first_part": "double",
    "second_part": "double", "rotational": "int", "parent": "int", "offsets": "double",
    "arms": "double", "reaches": "double", "capsules": "double", "boxes": "double",
    "boxed": "int", "moved": "int",
}
"""The arrays of one robot's kinematics in odin_motion.c (odin_step.h's OdinKinematicRobot,
row by row)."""
ROBOT_COUNTS = ("n_links", "n_joints", "n_dofs", "part_start", "part_len", "moves_base",
                "base_turns", "n_moved")


class MotionQuery:
    """One OdinMotionChecker (odin_motion.c) over the scene's ``world`` struct: ``robots``
    (per robot a mapping of ROBOT_COUNTS to ints and ROBOT_ARRAYS to arrays), the moved
    links' ``bodies`` with their centres of mass ``com`` (n, 3) and ``geoms``, the geoms
    ``apart`` (addresses), the robot link ``pairs`` (n, 2) that may touch, ``tiers`` (m,
    descending), ``sweep_gap`` and ``resolution`` (m). Every array is kept here for as long as
    C may read it; the caller has checked them (virtual_world.core.motion)."""

    def __init__(self, world, size: int, robots: Sequence[dict], bodies: Sequence,
                 com: np.ndarray, geoms: Sequence, apart: Sequence[int], pairs: np.ndarray,
                 tiers: np.ndarray, sweep_gap: float, resolution: float):
        self._keep = []
        self._robots = ffi.new("OdinKinematicRobot[]", max(len(robots), 1))
        for struct, robot in zip(self._robots, robots):
            for name in ROBOT_COUNTS:
                setattr(struct, name, int(robot[name]))
            for name, kind in ROBOT_ARRAYS.items():
                setattr(struct, name, self._array(robot[name], kind))
        m = self._struct = ffi.new("OdinMotionChecker *")
        m.world, m.n_robots, m.robots, m.size = world, len(robots), self._robots, int(size)
        m.bodies = self._kept(ffi.new("dBodyID[]", list(bodies) or 1))
        m.com = self._array(com, "double")
        m.geoms = self._kept(ffi.new("dGeomID[]", list(geoms) or 1))
        m.n_geoms = len(geoms)
        m.apart = self._kept(ffi.new("uintptr_t[]", sorted(apart) or 1))
        m.n_apart = len(apart)
        m.tiers, m.n_tiers = self._array(tiers, "double"), len(tiers)
        m.hints = self._kept(ffi.new("int[]", max(len(bodies), 1)))
        m.sweep_gap = float(sweep_gap)
        m.sweep_hints = self._kept(ffi.new("int[]", max(len(bodies), 1)))
        m.pairs, m.n_pairs = self._array(pairs, "int"), len(pairs)
        m.resolution = float(resolution)
        self._counts = ffi.new("int[2]")
        self._size = int(size)
        self._a = ffi.new("double[]", max(self._size, 1))
        self._b = ffi.new("double[]", max(self._size, 1))

    def _kept(self, cdata):
        self._keep.append(cdata)
        return cdata

    def _array(self, values, kind: str):
        dtype = np.intc if kind == "int" else np.float64
        array = np.ascontiguousarray(np.asarray(values, dtype=dtype).reshape(-1))
        if not array.size:
            array = np.zeros(1, dtype=dtype)
        self._keep.append(array)
        return ffi.cast(f"{kind} *", ffi.from_buffer(array))

    @drains_ode_messages
    def motion_valid(self, a: Sequence[float], b: Sequence[float], deadline: float = 0.0
                     ) -> Tuple[int, int, int]:
        """(odin_motion_valid's answer: 1 free, 0 not, -1 a frame not fit for ODE, -2 out of
        memory, -3 a control not finite; configurations checked exactly; clearance queries)
        for the segment a-b (``size`` floats each: TypeError, ValueError otherwise), given up
        (answered 0) once time.monotonic() passes ``deadline`` (0: never)."""
        self._set(self._a, a)
        self._set(self._b, b)
        self._counts[0] = self._counts[1] = 0
        answer = lib.odin_motion_valid(self._struct, self._a, self._b, float(deadline),
                                       self._counts)
        return int(answer), int(self._counts[0]), int(self._counts[1])

    @drains_ode_messages
    def configuration_valid(self, controls: Sequence[float]) -> int:
        """odin_configuration_valid's answer for one control vector (as motion_valid's)."""
        self._set(self._a, controls)
        return int(lib.odin_configuration_valid(self._struct, self._a, self._counts))

    def _set(self, target, values: Sequence[float]) -> None:
        """Copies ``values`` (a list, tuple or array of ``size`` numbers) into ``target``:
        a planner asks thousands of times a second, so no array is made on the way."""
        if isinstance(values, np.ndarray):
            values = values.tolist()
        if len(values) != self._size:
            raise ValueError(f"{len(values)} controls, not {self._size}")
        target[0:self._size] = values
