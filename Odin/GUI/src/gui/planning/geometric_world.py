"""The scene of a geometric search (gui.planning.geometric) and its collision queries,
ROS-free: ``GeometricWorld`` builds the problem in a VirtualWorld Core of this process and
answers whether configurations of the control space collide, and whether the straight
segment between two does.

A configuration is valid when no link a control moves touches anything (``valid``: the Core's
motion checker, one C call; ``collisions`` names the pairs and their depths through Check
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
is the classic discrete check at the resolution, for the links that are near. Before the
walk, the segment's end and, on a long segment, its middle and quarters are checked (most
motions that fail end inside something or cross it). A motion whose links only translate
(no revolute joint or base turn, no DOF clamped at either end, no robot link pair that may
touch) is instead split in halves until the box each link sweeps over a piece touches
nothing, or the piece is within the resolution and its ends are valid.

The walk runs in C, kinematics included, one call per motion (the Core's motion checker:
virtual_world.core.motion, odin_motion.c), on the tables ``PlannedRobot.kinematics`` gives;
``motion_points`` lists the configurations a resolution apart along a segment (the tests'
finer check).
"""
from __future__ import annotations

import math
from typing import Callable, List, Optional, Sequence

import numpy as np

from gui.core.plan import BuildPlan
from gui.planning.geometric_robots import control_size, planned_robots

RESOLUTION = 0.002
"""m: the largest motion of any link point between two configurations checked exactly: no
link goes deeper than half of it into anything along a valid motion (module docstring)."""
CLEARANCE_TIERS = 0.002 * 2.0 ** np.arange(8, -1, -1)
"""m, descending (0.512 ... 0.002): the growths a clearance is found among (the largest each
capsule can grow by without touching anything; a binary search over them, about four probes
per link)."""
SWEEP_GAP = 1e-6
"""m: a translating link's sweep is free when it can grow by this and touch nothing."""


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
        self.checks = 0
        self.clearance_checks = 0

    def _ask_core(self) -> None:
        """The Core's names of what moves and its motion checker (single configurations and
        whole motions, the walk of the module docstring, in C)."""
        core = self.world.core
        self.size = control_size(self.robots)
        self.moved = {name for r in self.robots for body in r.moved_bodies
                      for name in core.geometry_names(body)}
        self.checker = core.motion_checker([r.kinematics(self.size) for r in self.robots],
                                           self.size, CLEARANCE_TIERS, SWEEP_GAP,
                                           self.resolution)

    def close(self) -> None:
        self.world.close()

    def configurations(self, controls: Sequence[float]) -> "Placement":
        """Each robot's (base pose, joints) for the control vector."""
        c = np.asarray(controls, dtype=float)
        return Placement(r.configuration(c) for r in self.robots)

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
        configuration (the pairs ``collisions`` reports, asked through the Core's motion
        checker: one C call, kinematics included, stopping at the first)."""
        self.checks += 1
        return self.world.core.configuration_valid(self.checker, controls)

    def _bounds(self, a: list, b: list) -> np.ndarray:
        """(robot links,) m: how far each link of every robot moves at most from
        configurations ``a`` to ``b`` (PlannedRobot.link_bounds)."""
        return np.concatenate([r.link_bounds(ca, cb) for r, ca, cb in zip(self.robots, a, b)])

    def motion_valid(self, a: Sequence[float], b: Sequence[float],
                     over: Callable[[], bool] = lambda: False,
                     deadline: Optional[float] = None) -> bool:
        """Whether the straight segment of the control space from ``a`` (a valid
        configuration) to ``b`` is (module docstring): one call to the Core's motion checker
        (virtual_world.core.motion: the walk, kinematics included, in C); False without a
        check when ``over()`` is true, and False once time.monotonic() passes ``deadline``
        on the way (the search is over: the motion is not taken)."""
        if over():
            return False
        valid, checks, clearances = self.world.core.motion_valid(self.checker, a, b, deadline)
        self.checks += checks
        self.clearance_checks += clearances
        return valid

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


class Placement(list):
    """Each robot's (base pose (4, 4), joints) for one control vector."""
