"""The scene of a geometric search (gui.planning.geometric) and its collision queries,
ROS-free: ``GeometricWorld`` builds the problem in a VirtualWorld Core of this process and
answers whether configurations of the control space collide, and whether the straight
segment between two does.

A configuration is valid when no link a control moves touches anything (``valid``: the Core's
collision probe, one C call; ``collisions`` names the pairs and their depths through Check
Collision). Pairs of parts no control moves relative to each other (a fixed base on its
table) are not asked about: they are as the problem built them whatever the path does; links
a joint joins never collide in the world.

A motion (``motion_valid``) is valid when every configuration along it is. It is walked from
its start in steps, each as long as two guarantees allow, link by link, from the bounds of
gui.planning.geometric_robots (how far a change of configuration moves any point of a link):

* Clearance: at the step's start, a lower bound of each moved link's distance to everything
  but the robots (its bounding box's or capsule's, gui.planning.geometric_robots: how far it
  can grow before the Core's probe finds it touching anything, among ``CLEARANCE_TIERS``), and
  of the distance between each pair of robot links that may touch (their capsules'). A link that
  moves less than its clearance touches nothing on the way; a pair whose two motions together
  are less than their distance does not touch.
* Resolution: a link (a pair) too near something for a useful step may move no more than
  ``resolution`` (together), and the step's end is then checked exactly. A link at any
  configuration between two valid ones that near is within ``resolution / 2`` of a
  collision-free placement, so it goes no deeper than that into anything (1 mm with the
  default 2 mm).

So a step far from everything is long and checks nothing exactly; near an obstacle the walk
is the classic discrete check at the resolution, for the links that are near.
"""
from __future__ import annotations

import math
from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np

from gui.core.plan import BuildPlan
from gui.planning.geometric_robots import planned_robots

RESOLUTION = 0.002
"""m: the largest motion of any link point between two configurations checked exactly: no
link goes deeper than half of it into anything along a valid motion (module docstring)."""
CLEARANCE_TIERS = 0.002 * 2.0 ** np.arange(8, -1, -1)
"""m, descending (0.512 ... 0.002): the growths a clearance is found among (the largest each
capsule can grow by without touching anything; a binary search over them, about four probes
per link)."""
SWEEP_GAP = 1e-6
"""m: a translating link's sweep (GeometricWorld._sweep_valid) is free when it can grow by
this and touch nothing."""
CHECKS_BETWEEN_CLOCKS = 16
"""A motion's steps between two readings of the search's clock."""
PROBES = (0.5, 0.25, 0.75, 0.125, 0.375, 0.625, 0.875)
"""Fractions of a segment checked before it is walked, in this order (OMPL's
DiscreteMotionValidator's bisection order), as many as the segment holds PROBE_SPACING
resolution steps."""
PROBE_SPACING = 8
SHRINKS = 4
"""How many times a step estimated from the whole segment's rate is halved before the
segment is taken a resolution step at a time (a joint clamped at its limit part of the way)."""


class GeometricWorld:
    """The problem's scene in a Core of this process, asked whether configurations of the
    control space collide (module docstring). ``checks``: configurations checked exactly so
    far; ``clearance_checks``: configurations whose clearance was asked."""

    def __init__(self, plan: BuildPlan, resolution: float = RESOLUTION):
        from gui.planning.core_world import CoreWorld
        self.resolution = resolution
        self.robots = planned_robots(plan)
        self.world = CoreWorld()
        try:
            self.world.execute(plan)
            self._ask_core()
        except Exception:
            self.world.close()
            raise
        # k: a 2012 problem's robots end to end, a current problem's one shared vector
        self.size = max(r.part.stop or r.handle.instance.controls.size for r in self.robots)
        self.checks = 0
        self.clearance_checks = 0

    def _ask_core(self) -> None:
        """The Core's names of what moves, its collision probe and the robot link pairs that
        may touch."""
        core = self.world.core
        self.moved = {name for r in self.robots for body in r.moved_bodies
                      for name in core.geometry_names(body)}
        ids = [body.body_id for r in self.robots for body in r.handle.bodies]
        moved = [body.body_id for r in self.robots for k, body in enumerate(r.handle.bodies)
                 if k in r.moved]
        self.probe = core.collision_probe(moved, apart=ids, tiers=CLEARANCE_TIERS)
        self.sweep_probe = core.collision_probe(moved, apart=ids, tiers=(SWEEP_GAP,))
        self._moved_mask = np.array([i in set(moved) for i in ids])
        index = {body_id: n for n, body_id in enumerate(ids)}
        pairs = [(index[a], index[b]) for a, b in core.pairs_that_may_touch(ids)
                 if self._moved_mask[index[a]] or self._moved_mask[index[b]]]
        self._pairs = np.array(pairs, dtype=int).reshape(-1, 2)    # indices of robot links

    def close(self) -> None:
        self.world.close()

    def configurations(self, controls: Sequence[float]) -> "Placement":
        """Each robot's (base pose, joints) for the control vector."""
        c = np.asarray(controls, dtype=float)
        return Placement(r.configuration(c) for r in self.robots)

    def _frames(self, placement: "Placement") -> List[np.ndarray]:
        """Each robot's (links, 4, 4) object frames at ``placement`` (computed once)."""
        if placement.frames is None:
            placement.frames = [r.object_frames(conf) for r, conf in zip(self.robots, placement)]
        return placement.frames

    def collisions(self, controls: Sequence[float]) -> list:
        """The pairs (first, second, depth m) a control vector's configuration makes that a
        control moves (module docstring), deepest first."""
        self.checks += 1
        poses = [pose for r, conf in zip(self.robots, self.configurations(controls))
                 for pose in r.poses(conf)]
        found = [(c.first, c.second, c.depth) for c in self.world.core.check_collision(poses)
                 if c.first in self.moved or c.second in self.moved]
        return sorted(found, key=lambda pair: -pair[2])

    def valid(self, controls: Sequence[float]) -> bool:
        """Whether no link a control moves touches anything at the control vector's
        configuration (the pairs ``collisions`` reports, asked through the Core's collision
        probe: one C call, stopping at the first)."""
        return self._valid(self.configurations(controls))

    def _valid(self, placement: "Placement") -> bool:
        self.checks += 1
        poses = np.concatenate([frames[r.moved] for r, frames in
                                zip(self.robots, self._frames(placement))])
        return self.world.core.probe_touching(self.probe, poses) is None

    def _bounds(self, a: list, b: list) -> np.ndarray:
        """(robot links,) m: how far each link of every robot moves at most from
        configurations ``a`` to ``b`` (PlannedRobot.link_bounds)."""
        return np.concatenate([r.link_bounds(ca, cb) for r, ca, cb in zip(self.robots, a, b)])

    def clearances(self, placement: "Placement", needed: Optional[np.ndarray] = None
                   ) -> Tuple[np.ndarray, np.ndarray]:
        """(per robot link, m: how far each moved link is at least from everything but the
        robots' links, inf for a link no control moves; per pair of robot links that may
        touch (``_pairs``), m: how far apart they are at least), from their capsules and
        boxes (module docstring). ``needed`` (per robot link, m): a clearance beyond it is of
        no use to the caller, and is not sought."""
        self.clearance_checks += 1
        frames = self._frames(placement)
        bounds = np.concatenate([r.world_bounds(f[r.moved], r.moved)
                                 for r, f in zip(self.robots, frames)])
        grown = self.world.core.probe_clearances(
            self.probe, bounds, None if needed is None else needed[self._moved_mask])
        obstacles = np.full(len(self._moved_mask), np.inf)
        obstacles[self._moved_mask] = grown
        if not len(self._pairs):
            return obstacles, np.empty(0)
        capsules = np.concatenate([r.world_capsules(f, range(len(r.links)))
                                   for r, f in zip(self.robots, frames)])
        first, second = self._pairs[:, 0], self._pairs[:, 1]
        pairs = _segment_distances(capsules[first], capsules[second]) \
            - capsules[first, 6] - capsules[second, 6]
        return obstacles, np.maximum(pairs, 0.0)

    def motion_valid(self, a: Sequence[float], b: Sequence[float],
                     over: Callable[[], bool] = lambda: False) -> bool:
        """Whether the straight segment of the control space from ``a`` (a valid
        configuration) to ``b`` is (module docstring); False too when ``over()`` turns true
        on the way (the search is over: the motion is not taken)."""
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        end = self.configurations(b)
        here = self.configurations(a)
        if self._sweeps(a, b, here, end):
            return self._valid(end) and self._sweep_valid(a, b, here, end, over)
        if not self._probes_valid(a, b, here, end):
            return False
        t, steps, budget = 0.0, 0, None
        while t < 1.0:
            steps += 1
            if steps % CHECKS_BETWEEN_CLOCKS == 0 and over():
                return False
            if budget is None or budget.stale():
                budget = _Budget(*self.clearances(here, self._bounds(here, end)))
            t, there, unproven, moves = self._advance(a, b, t, here, end, budget)
            if unproven and t < 1.0 and not self._valid(there):
                return False
            budget.spend(moves, self._pairs)
            here = there
        return True

    def _sweeps(self, a, b, here: list, end: list) -> bool:
        """Whether the segment's motion is one the sweep walk takes: every link only
        translates, linearly (no DOF clamped at either end), and no pair of robot links may
        touch."""
        return not len(self._pairs) and all(
            not r.turns(ca, cb) and r.unclamped(a) and r.unclamped(b)
            for r, ca, cb in zip(self.robots, here, end))

    def _swept_free(self, start: "Placement", end: "Placement") -> bool:
        """Whether nothing is in what the moved links sweep from ``start`` to ``end``
        (translating along straight lines: PlannedRobot.swept_boxes)."""
        self.clearance_checks += 1
        boxes = np.concatenate([r.swept_boxes(fa[r.moved], fb[r.moved], r.moved) for r, fa, fb
                                in zip(self.robots, self._frames(start), self._frames(end))])
        return bool(np.all(self.world.core.probe_clearances(self.sweep_probe, boxes) > 0.0))

    def _sweep_valid(self, a, b, here: list, end: list, over: Callable[[], bool]) -> bool:
        """The segment of a translating motion split in halves until each piece's sweep is
        free, or moves no link more than the resolution with both its ends valid (module
        docstring); pieces are taken from the start on."""
        pieces = [(0.0, here, 1.0, end)]
        known = {0.0: True, 1.0: True}          # the start is valid, the end was checked
        while pieces:
            if (len(pieces) + self.clearance_checks) % CHECKS_BETWEEN_CLOCKS == 0 and over():
                return False
            t0, start, t1, stop = pieces.pop()
            if self._swept_free(start, stop):
                continue
            if float(np.max(self._bounds(start, stop), initial=0.0)) <= self.resolution:
                for t, placement in ((t0, start), (t1, stop)):
                    if t not in known:
                        known[t] = self._valid(placement)
                    if not known[t]:
                        return False
                continue
            middle = (t0 + t1) / 2
            between = self.configurations(a + middle * (b - a))
            pieces += [(middle, between, t1, stop), (t0, start, middle, between)]
        return True

    def _probes_valid(self, a, b, here: list, end: list) -> bool:
        """Whether the segment's end, and on a long segment its middle and quarters, are
        valid (asked first: most motions that fail end inside something or cross it, and the
        walk from the start would reach that last)."""
        if not self._valid(end):
            return False
        resolutions = float(np.max(self._bounds(here, end), initial=0.0)) / self.resolution
        fractions = PROBES[:int(resolutions // PROBE_SPACING)]
        return all(self._valid(self.configurations(a + f * (b - a))) for f in fractions)

    def _advance(self, a, b, t: float, here: list, end: list, budget: "_Budget"
                 ) -> Tuple[float, list, bool, np.ndarray]:
        """(t', its configurations, whether they must be checked, how far each link moves at
        most to them) of the farthest point t' <= 1 of the segment such that every link stays
        within what is left of its clearance (``budget``), or moves no more than the
        resolution (then t' is checked: module docstring); each pair of robot links likewise
        by their sum."""
        rest = self._bounds(here, end)
        obstacles, pairs = budget.obstacles, budget.pairs
        allowed = np.maximum(obstacles, self.resolution)
        allowed_pairs = np.maximum(pairs, self.resolution)
        first, second = self._pairs[:, 0], self._pairs[:, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            fraction = min(1.0, float(np.min(allowed / rest, initial=np.inf)),
                           float(np.min(allowed_pairs / (rest[first] + rest[second]),
                                        initial=np.inf)))
        for _ in range(SHRINKS + 1):
            t_next = 1.0 if fraction >= 1.0 else t + (1.0 - t) * fraction
            there = end if t_next >= 1.0 else self.configurations(a + t_next * (b - a))
            moves = self._bounds(here, there)
            together = moves[first] + moves[second]
            if np.all(moves <= allowed) and np.all(together <= allowed_pairs):
                return t_next, there, bool(np.any(moves > obstacles)
                                           or np.any(together > pairs)), moves
            fraction /= 2.0
        return self._resolution_step(a, b, t, here)

    def _resolution_step(self, a, b, t: float, here: list
                         ) -> Tuple[float, list, bool, np.ndarray]:
        """The next point of the segment from ``t`` as motion_points places them (each
        within the resolution of the one before), to be checked."""
        start = a + t * (b - a)
        t_next = t + (1.0 - t) * _fraction_along(start, b, self.motion_points(start, b)[0])
        there = self.configurations(a + t_next * (b - a))
        return t_next, there, True, self._bounds(here, there)

    def motion_points(self, a: Sequence[float], b: Sequence[float]) -> List[np.ndarray]:
        """The configurations along the straight segment from ``a`` to ``b`` (``a``
        excluded, ``b`` last) such that consecutive ones move no link point farther than the
        resolution (a finer check of a path than the search's: the tests use it)."""
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        fractions = [0.0, 1.0]
        configurations = {0.0: self.configurations(a), 1.0: self.configurations(b)}
        k = 0
        while k < len(fractions) - 1:
            low, high = fractions[k], fractions[k + 1]
            bound = float(np.max(self._bounds(configurations[low], configurations[high]),
                                 initial=0.0))
            pieces = math.ceil(bound / self.resolution) if bound > self.resolution else 1
            if pieces > 1:
                inner = [low + (high - low) * j / pieces for j in range(1, pieces)]
                for f in inner:
                    configurations[f] = self.configurations(a + f * (b - a))
                fractions[k + 1:k + 1] = inner
                continue
            k += 1
        return [a + f * (b - a) for f in fractions[1:]]


class _Budget:
    """Clearances found at a configuration of a motion (GeometricWorld.clearances), less how
    far the links have moved since: still lower bounds of their distances, so a walk asks
    again only once some link or pair has used half of what it had (asking then may find
    more room; a link found touching, at 0, never asks again)."""

    def __init__(self, obstacles: np.ndarray, pairs: np.ndarray):
        self.found_obstacles, self.found_pairs = obstacles, pairs
        self.obstacles, self.pairs = obstacles.copy(), pairs.copy()

    def spend(self, moves: np.ndarray, pairs: np.ndarray) -> None:
        """``moves`` (per robot link, m) taken; ``pairs``: the robot link pairs' indices."""
        self.obstacles = np.maximum(self.obstacles - moves, 0.0)
        if len(pairs):
            self.pairs = np.maximum(self.pairs - moves[pairs[:, 0]] - moves[pairs[:, 1]], 0.0)

    def stale(self) -> bool:
        return bool(np.any(self.obstacles < self.found_obstacles / 2)
                    or np.any(self.pairs < self.found_pairs / 2))


class Placement(list):
    """Each robot's (base pose (4, 4), joints) for one control vector, with their object
    frames once asked (GeometricWorld._frames)."""
    frames: Optional[List[np.ndarray]] = None


def _fraction_along(a: np.ndarray, b: np.ndarray, point: np.ndarray) -> float:
    span = float(np.linalg.norm(b - a))
    return float(np.linalg.norm(point - a)) / span if span > 0 else 1.0


def _segment_distances(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """(n,) m: the distance between segments p[i] and q[i] ((n, >= 6): ends a then b, m),
    by their closest points (Ericson, Real-Time Collision Detection, 5.1.9)."""
    p1, d1 = p[:, :3], p[:, 3:6] - p[:, :3]
    p2, d2 = q[:, :3], q[:, 3:6] - q[:, :3]
    r = p1 - p2
    a = np.einsum("ij,ij->i", d1, d1)
    e = np.einsum("ij,ij->i", d2, d2)
    f = np.einsum("ij,ij->i", d2, r)
    c = np.einsum("ij,ij->i", d1, r)
    b = np.einsum("ij,ij->i", d1, d2)
    tiny = 1e-18
    denominator = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denominator > tiny, np.clip((b * f - c * e) / denominator, 0.0, 1.0), 0.0)
        t = np.where(e > tiny, (b * s + f) / e, 0.0)
        s = np.where(t < 0.0, np.where(a > tiny, np.clip(-c / a, 0.0, 1.0), 0.0), s)
        s = np.where(t > 1.0, np.where(a > tiny, np.clip((b - c) / a, 0.0, 1.0), 0.0), s)
        # q a point: its nearest point of p
        s = np.where(e <= tiny, np.where(a > tiny, np.clip(-c / a, 0.0, 1.0), 0.0), s)
    t = np.clip(t, 0.0, 1.0)
    closest = (p1 + d1 * s[:, None]) - (p2 + d2 * t[:, None])
    return np.linalg.norm(closest, axis=1)
