"""Kautham's geometric queries solved with OMPL's geometric planners over Odin's own geometry
(ROS-free; OMPL 2 from PyPI).

The space is Kautham's: the problem's control space [0, 1]^k (the query's ``<Init>`` and
``<Goal>``), each vector mapped through every robot's controls to its joints and base
(``gui.core.kautham.controls``; a 2012 problem's robots each take their own slice of it, a
current problem's robots the whole vector). Distances are Euclidean there, as in Kautham.

A state is valid when no link the controls move touches anything, a motion when every
configuration along it is, with no link deeper than half the resolution (1 mm by default) into
anything: the problem's scene is built in a VirtualWorld Core of this process and asked by
ODE's collision detection, no contacts made, nothing stepped (gui.planning.geometric_world,
which says how clearances and the resolution guarantee it; the robots and their bounds:
gui.planning.geometric_robots).

The problem's planner runs as OMPL runs it, with one difference a user can turn off
(``GeometricSettings.restarts``): a tree planner that finds no path (RESTARTED_PLANNERS) is
cleared and started again, in rounds. An RRT's goal bias keeps extending the tree's node
nearest the goal; when that node sits behind an obstacle, the tree can grow for ever without
reaching the goal (Kautham's UR5 demo: 4 seeds in 10 never solved in 30 s, the others in a
fifth of a second). RRT's solve times are heavy-tailed, and restarts cut the tail (Wedge and
Branicky, "On heavy-tailed runtimes and restarts in rapidly-exploring random trees", 2008).
Round r ends after RESTART_MOTIONS x luby(r) motion checks (Luby's sequence 1 1 2 1 1 2 4 ...,
within a logarithmic factor of the best fixed budget whatever the problem), so a seed's rounds
are the same on any machine: only the time limit depends on the machine's speed. The next round
draws from the same random stream.

``solve(plan, settings)`` answers a ``GeometricResult``; ``solve_file(problem_file, ...)``
loads and plans a Kautham file first.
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, replace
from enum import IntEnum
from typing import Callable, List, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from gui.core.kinematics import pose_to_position_quaternion
from gui.core.plan import BuildPlan
from gui.errors import PlanningError
from gui.planning.geometric_robots import (control_scales, control_size, planned_robots,
                                           robot_parts)
from gui.planning.geometric_world import RESOLUTION, GeometricWorld

GEOMETRIC_PLANNERS = {
    "omplRRTConnect": "RRTConnect", "omplRRT": "RRT", "omplPRM": "PRM",
    "omplRRTStar": "RRTstar", "omplKPIECE": "KPIECE1", "omplKPIECE1": "KPIECE1",
    "omplBKPIECE": "BKPIECE1", "omplLBKPIECE": "LBKPIECE1", "omplPRMstar": "PRMstar",
    "omplFMT": "FMT", "omplBITstar": "BITstar", "PRM": "PRM",
}
"""Kautham's geometric planners and the OMPL planner that runs each (the same algorithm)."""
NEAREST_PLANNERS = {
    "omplRRTStarPMD": "RRTstar", "omplLazyRRT": "RRT", "omplpRRT": "RRT", "omplEST": "KPIECE1",
    "omplSBL": "LBKPIECE1", "omplpSBL": "LBKPIECE1", "omplLazyPRM": "PRM",
    "omplTRRT": "RRT", "omplRRTConnectPMD": "RRTConnect",
    # Kautham's own samplers and costs (synergies, PCA, "first-order synergy" upstream
    # criteria) over OMPL's trees, and Kautham 2012's roadmaps: the same family of planner
    "omplFOSRRTStar": "RRTstar", "omplFOSVFRRT": "RRT",
    "PRMPCA HandArm": "PRM", "PRMAURO HandArm": "PRM", "PRM RobotHand ICRA J": "PRM",
    "DRM": "PRM",
}
"""Kautham's geometric planners that OMPL's Python wheel lacks, and the nearest it has (said in
one warning)."""
OMPL_PLANNERS = ("RRTConnect", "RRT", "RRTstar", "PRM", "PRMstar", "KPIECE1", "BKPIECE1",
                 "LBKPIECE1", "FMT", "BITstar")
"""The geometric planners ``--planner`` may name (OMPL's class names)."""
RESTARTED_PLANNERS = ("RRTConnect", "RRT", "KPIECE1", "BKPIECE1", "LBKPIECE1")
"""The planners a search restarts (module docstring): trees for one query that stop at their
first path. A roadmap (PRM) is kept for the queries after, an optimizing planner (RRT*, FMT,
BIT*) improves its path until the time limit: neither is restarted."""
RESTART_MOTIONS = 3000
"""Motion checks of a search's round per unit of Luby's sequence (module docstring): about what
Kautham's UR5 demo takes when it solves."""
DEFAULT_TIME_LIMIT = 10.0
"""s: a search's time when the problem gives none (Kautham's default _Max Planning Time)."""
RESOLUTION_RANGE = (1e-4, 0.1)
"""m: the resolutions a search takes (finer: a motion of a metre would be 10,000 checks)."""

SHORTCUT_ROUNDS = 20
"""At most this many rounds of OMPL's reduceVertices shorten a path (each tries as many
shortcuts as the path has states; Kautham's simplifyMax goes on while any round helps, which
from Python would take the rest of the search's time)."""
SHORTER_ENOUGH = 0.99
"""A round that leaves the path longer than this fraction of its length before is the last."""

log = logging.getLogger("gui.planning.geometric")


class Simplification(IntEnum):
    """What is done to a path found, by Kautham's ``_Simplify Solution`` values (omplplanner's
    trySolve): nothing; B-spline smoothing (OMPL's smoothBSpline, 5 steps); shortening (its
    simplifySolution: here OMPL's reduceVertices until it finds no shortcut, in what is left
    of the search's time)."""
    NONE = 0
    SMOOTH = 1
    SHORTEN = 2

    @classmethod
    def of_kautham(cls, value: Optional[float]) -> "Simplification":
        """Kautham's reading: 0 none, 1 smooth, anything else (or none given) shorten."""
        return cls.NONE if value == 0 else cls.SMOOTH if value == 1 else cls.SHORTEN


@dataclass(frozen=True)
class GeometricSettings:
    """How one search runs: ``planner`` (an OMPL class name of ``OMPL_PLANNERS``),
    ``time_limit`` s of wall clock for the planner (the solution's simplification comes after,
    as in Kautham), ``range`` (Kautham's Range: the longest motion a tree
    extends by, in control-space units; None: OMPL's default), ``goal_bias`` (None: OMPL's),
    ``simplify`` (Kautham's Simplify Solution: ``Simplification``),
    ``resolution`` m (module docstring), ``restarts``: a planner of RESTARTED_PLANNERS that
    finds no path is started again (module docstring; False: one round, as OMPL runs it).
    A PRM's neighbour settings (None: OMPL's): ``max_neighbours`` (Kautham's
    MaxNearestNeighbors, 2012's Max. Neighs: the k nearest milestones a new one is connected
    to), ``neighbour_distance`` (DistanceThreshold, 2012's Neigh Thresshold: no connection
    or roadmap expansion longer than this, in the search's metric), ``max_samples`` (2012's
    Max. Samples: the search ends, unsolved, once it has tried this many samples)."""
    planner: str = "RRTConnect"
    time_limit: float = DEFAULT_TIME_LIMIT
    range: Optional[float] = None
    goal_bias: Optional[float] = None
    simplify: int = 2           # Simplification.SHORTEN, Kautham's default
    resolution: float = RESOLUTION
    restarts: bool = True
    max_neighbours: Optional[int] = None
    neighbour_distance: Optional[float] = None
    max_samples: Optional[int] = None

    @classmethod
    def of_problem(cls, plan: BuildPlan) -> "GeometricSettings":
        """The problem's planner and parameters as Kautham would run them."""
        planner = plan.problem.planner
        if planner is None or not planner.name:
            return cls()
        name = GEOMETRIC_PLANNERS.get(planner.name)
        if name is None and planner.name in NEAREST_PLANNERS:
            name = NEAREST_PLANNERS[planner.name]
            log.warning("planner %s: OMPL's Python wheel has no such planner; %s, the nearest, "
                        "plans instead", planner.name, name)
        if name is None:
            raise PlanningError(f"planner {planner.name!r} is not one of Kautham's geometric "
                                f"planners Odin runs ({', '.join(sorted(GEOMETRIC_PLANNERS))})")
        given = dict(planner.geometric)
        return cls(planner=name, time_limit=given.get("time_limit", DEFAULT_TIME_LIMIT),
                   range=given.get("range"), goal_bias=given.get("goal_bias"),
                   simplify=Simplification.of_kautham(given.get("simplify")),
                   max_neighbours=given.get("max_neighbours"),
                   neighbour_distance=given.get("neighbour_distance"),
                   max_samples=given.get("max_samples"))

    def roadmap(self) -> Tuple[float, float]:
        """(the longest motion a PRM search tries, in the search's metric; the samples it
        may try): inf for what is not given, and for a planner other than PRM."""
        if self.planner != "PRM":
            return math.inf, math.inf
        return (self.neighbour_distance if self.neighbour_distance is not None else math.inf,
                self.max_samples if self.max_samples is not None else math.inf)

    def check(self) -> None:
        if self.planner not in OMPL_PLANNERS:
            raise PlanningError(f"unknown geometric planner {self.planner!r}: one of "
                                f"{', '.join(OMPL_PLANNERS)}")
        if not (math.isfinite(self.time_limit) and self.time_limit > 0):
            raise PlanningError(f"time {self.time_limit!r} s must be positive")
        if self.range is not None and not (math.isfinite(self.range) and self.range > 0):
            raise PlanningError(f"Range {self.range!r} must be positive")
        for name in ("max_neighbours", "max_samples"):
            value = getattr(self, name)
            if value is not None and not (isinstance(value, int) and value >= 1):
                raise PlanningError(f"{name} {value!r} must be a whole number >= 1")
        if self.neighbour_distance is not None and not (
                math.isfinite(self.neighbour_distance) and self.neighbour_distance > 0):
            raise PlanningError(f"neighbour distance {self.neighbour_distance!r} must be "
                                "positive")
        low, high = RESOLUTION_RANGE
        if not (math.isfinite(self.resolution) and low <= self.resolution <= high):
            raise PlanningError(f"resolution {self.resolution!r} m must be in [{low:g}, "
                                f"{high:g}] m")


@dataclass(frozen=True)
class GeometricResult:
    """What a search found. ``solved``: a path from the query's start to its goal exactly;
    ``path``: its states (n, k) in the control space ([0, 1]^k, empty when none);
    ``configurations``: per state, each robot's (base pose (4, 4), joints (rad or m));
    ``time_s``: wall-clock seconds of the search; ``states``: the states of the path;
    ``checks``: configurations checked for collision during the search; ``length``: the
    path's length in the search's metric (``scales``); ``status``: OMPL's planner status;
    ``unsimplified_length``: the length of the path the planner found, before simplification;
    ``simplify_s``: wall seconds of the simplification (part of ``time_s``); ``graph_states``:
    the states of the planner's graph or trees when it stopped; ``clearance_checks``: the
    clearance and sweep queries of its motion checks (gui.planning.geometric_world), apart
    from ``checks``, the configurations checked exactly; ``unsimplified_states``: the states
    of the path the planner found, before simplification (OMPL's solution segments + 1);
    ``scales``: per control, the search's scale (Kautham's metric: control_scales; None: 1),
    which its lengths, Range and interpolation are measured in; ``rounds``: the planner's
    rounds (module docstring: restarts), the last one's graph and status reported;
    ``samples``: the configurations the planner asked about (each a sample tried);
    ``out_of_samples``: the search ended at its Max. Samples (GeometricSettings)."""
    planner: str
    seed: Optional[int]
    solved: bool
    path: np.ndarray
    time_s: float
    checks: int
    length: float
    status: str
    unsimplified_length: float = 0.0
    simplify_s: float = 0.0
    graph_states: int = 0
    clearance_checks: int = 0
    unsimplified_states: int = 0
    scales: Optional[np.ndarray] = None
    rounds: int = 1
    samples: int = 0
    out_of_samples: bool = False

    @property
    def states(self) -> int:
        return len(self.path)

    def statistics(self) -> dict:
        """The result as JSON values (``rosrun GUI plan``'s statistics)."""
        return {"planner": self.planner, "seed": self.seed, "solved": self.solved,
                "exact": self.solved, "time_s": round(self.time_s, 6),
                "states": self.states, "collision_checks": self.checks,
                "collision_checks_per_s": round(self.checks / self.time_s, 1)
                if self.time_s > 0 else None,
                "path_length": round(self.length, 9), "status": self.status,
                "unsimplified_path_length": round(self.unsimplified_length, 9),
                "simplify_s": round(self.simplify_s, 6), "graph_states": self.graph_states,
                "clearance_checks": self.clearance_checks,
                "unsimplified_states": self.unsimplified_states,
                "control_scales": None if self.scales is None else
                [round(float(x), 9) for x in self.scales], "rounds": self.rounds,
                "samples": self.samples, "out_of_samples": self.out_of_samples}


def query(plan: BuildPlan) -> Tuple[np.ndarray, np.ndarray]:
    """The query's start and goal in the control space (k,): PlanningError without one."""
    parts = robot_parts(plan)
    if any(h.start is None or h.goal is None or h.start.controls is None
           or h.goal.controls is None for h, _ in parts):
        raise PlanningError("the problem has no query (<Init> and <Goal>) to plan")
    if parts[0][1] == slice(None):
        handle = parts[0][0]
        return np.array(handle.start.controls, float), np.array(handle.goal.controls, float)
    return (np.concatenate([np.array(h.start.controls, float) for h, _ in parts]),
            np.concatenate([np.array(h.goal.controls, float) for h, _ in parts]))


# -- the search ---------------------------------------------------------------------------------
def _ompl():
    from ompl import base as ob, geometric as og, util as ou
    return ob, og, ou


class _Checks:
    """OMPL's callbacks of one search: a state's and a motion's validity. A callback's
    exception is kept and raised after the search (it must not cross into C++). They hold the
    world and the search's clock (``over``), never the OMPL objects: OMPL holds them, and a
    cycle through C++ would keep every object of the search alive to the interpreter's end
    (nanobind reporting them leaked after the tool's last line); only while the planner runs,
    ``end_search`` ends it (its termination condition's ``terminate``).

    The planner's termination condition is OMPL's own clock, never a Python callable: a
    planner that checks it on a thread of its own (PRM's solution thread) would wait for the
    interpreter's lock, which the thread that runs the planner holds while it waits for that
    thread to end (a deadlock). So the search's end by Ctrl-C or a callback's error is asked
    here, on the planner's own thread, at every callback."""

    def __init__(self, world: GeometricWorld, over: Callable[[], bool], scales: np.ndarray,
                 deadline: Callable[[], float] = lambda: math.inf):
        self.world = world
        self.over = over
        self.deadline = deadline
        self.scales = [float(x) for x in scales]
        self.inverse_scales = [1.0 / x for x in self.scales]
        self.error: Optional[BaseException] = None
        self.end_search: Callable[[], None] = _nothing
        self.motions = 0
        self.budget = math.inf
        self.samples = 0
        self.max_samples = math.inf
        self.longest = math.inf

    def _ended(self) -> bool:
        """Whether the search, or its round (``budget`` motion checks), is over, or it has
        tried ``max_samples`` samples (then its planner is told to end)."""
        if self.over() or self.motions >= self.budget or self.samples >= self.max_samples:
            self.end_search()
            return True
        return False

    def controls(self, state) -> List[float]:
        """The control vector of an OMPL state (its coordinates over the search's scales:
        _Search)."""
        inverse = self.inverse_scales
        return [state[i] * inverse[i] for i in range(len(inverse))]

    def vector(self, state) -> np.ndarray:
        return np.array(self.controls(state))

    def _length(self, s1, s2) -> float:
        """A motion's length in the search's metric (OMPL's coordinates are scaled)."""
        return math.sqrt(sum((s1[i] - s2[i]) ** 2 for i in range(len(self.scales))))

    def valid(self, state) -> bool:
        try:
            if self._ended():
                return False
            self.samples += 1
            return self.world.valid(self.controls(state))
        except BaseException as error:      # noqa: B902 - raised by solve()
            self.error = self.error or error
            return False

    def motion(self, s1, s2) -> bool:
        self.motions += 1
        if self.longest < math.inf and self._length(s1, s2) > self.longest:
            return False            # a PRM's neighbour distance: not tried (GeometricSettings)
        try:
            return not self._ended() and self.world.motion_valid(
                self.controls(s1), self.controls(s2), self.over, self.deadline())
        except BaseException as error:      # noqa: B902 - raised by solve()
            self.error = self.error or error
            return False


def _nothing() -> None:
    """What ``_Checks.end_search`` does when no planner runs."""


class _Search:
    """The OMPL objects of one search, kept together (OMPL holds raw pointers between them),
    with its callbacks (``checks``)."""

    def __init__(self, checks: _Checks, settings: GeometricSettings,
                 start: np.ndarray, goal: np.ndarray):
        ob, og, ou = _ompl()
        ou.setLogLevel(ou.LOG_WARN)
        self.checks = checks
        size = checks.world.size
        self.space = ob.RealVectorStateSpace(size)
        bounds = ob.RealVectorBounds(size)
        scales = checks.scales
        for i in range(size):           # control i in [0, 1], scaled
            bounds.setLow(i, 0.0)
            bounds.setHigh(i, scales[i])
        self.space.setBounds(bounds)
        self.setup = og.SimpleSetup(self.space)
        self.si = self.setup.getSpaceInformation()
        self.setup.setStateValidityChecker(checks.valid)
        self.validator = _motion_validator(ob, self.si, checks)
        self.si.setMotionValidator(self.validator)
        self.start, self.goal = self.si.allocState(), self.si.allocState()
        for i in range(size):
            self.start[i], self.goal[i] = float(start[i]) * scales[i], float(goal[i]) * scales[i]
        self.setup.setStartAndGoalStates(self.start, self.goal)
        self.planner = getattr(og, settings.planner)(self.si)
        if settings.range is not None and hasattr(self.planner, "setRange"):
            self.planner.setRange(settings.range)
        if settings.goal_bias is not None and hasattr(self.planner, "setGoalBias"):
            self.planner.setGoalBias(settings.goal_bias)
        if settings.max_neighbours is not None and settings.planner == "PRM":
            self.planner.setMaxNearestNeighbors(settings.max_neighbours)
        self.setup.setPlanner(self.planner)
        self.setup.setup()


def _motion_validator(ob, si, checks: _Checks):
    class Motions(ob.MotionValidator):
        """Every configuration along the motion checked at the world's resolution."""

        def __init__(self, si):
            super().__init__(si)

        def checkMotion(self, s1, s2, *last_valid) -> bool:
            return checks.motion(s1, s2)

    return Motions(si)


def check_query(world: GeometricWorld, start: np.ndarray, goal: np.ndarray) -> None:
    """PlanningError naming the deepest pair when the query's start or goal collides."""
    for what, controls in (("start", start), ("goal", goal)):
        pairs = world.collisions(controls)
        if pairs:
            first, second, depth = pairs[0]
            more = f" (and {len(pairs) - 1} more pairs)" if len(pairs) > 1 else ""
            raise PlanningError(f"the query's {what} collides: {first} is {depth * 1000:.1f} mm "
                                f"into {second}{more}")


def solve(plan: BuildPlan, settings: Optional[GeometricSettings] = None,
          seed: Optional[int] = None, stop: Optional[Callable[[], bool]] = None
          ) -> GeometricResult:
    """Searches ``plan``'s query with ``settings`` (None: the problem's own,
    ``GeometricSettings.of_problem``), OMPL seeded with ``seed`` (gui.planning.bridge
    .seed_ompl: a process's first search only). ``stop()`` true ends the search at the
    planner's next iteration and raises KeyboardInterrupt. PlanningError before the search
    when the problem has no query, or its start or goal collides."""
    from gui.planning.bridge import seed_ompl
    settings = GeometricSettings.of_problem(plan) if settings is None else settings
    settings.check()
    start, goal = query(plan)
    if seed is not None:
        seed_ompl(seed)
    world = GeometricWorld(plan, settings.resolution)
    try:
        check_query(world, start, goal)
        scales = control_scales(world.robots, world.size) if plan.problem.format != "2012" \
            else np.ones(world.size)
        return _search(world, settings, start, goal, seed, stop, scales)
    finally:
        world.close()


def _search(world: GeometricWorld, settings: GeometricSettings, start, goal, seed,
            stop, scales: np.ndarray) -> GeometricResult:
    checks_before, clearances_before = world.checks, world.clearance_checks
    started = time.perf_counter()
    clock = _Clock(time.monotonic() + settings.time_limit, stop)
    checks = _Checks(world, clock.over, scales, lambda: clock.deadline)
    clock.checks = checks
    search = _Search(checks, settings, start, goal)
    found = _rounds(search, settings, clock)
    del search
    # the search's OMPL objects are gone here, before anything is raised: a traceback holding
    # them would keep them to the interpreter's end
    if stop is not None and stop():
        raise KeyboardInterrupt
    if checks.error is not None:
        raise PlanningError(f"collision checking failed: {checks.error}") from checks.error
    return GeometricResult(settings.planner, seed, bool(len(found.path)), found.path,
                           time.perf_counter() - started, world.checks - checks_before,
                           _length(found.path, scales), found.status,
                           _length(found.unsimplified, scales),
                           found.simplify_s, found.graph_states,
                           world.clearance_checks - clearances_before, len(found.unsimplified),
                           np.asarray(scales, dtype=float), found.rounds, found.samples,
                           found.out_of_samples)


class _Clock:
    """When a search is over: its ``deadline`` (time.monotonic() s) passed, one of its
    ``checks``' callbacks failed, or ``stop()``. The planner has the time limit; a solution's
    simplification comes after, as Kautham's does, with no deadline (_run lifts it)."""

    def __init__(self, deadline: float, stop: Optional[Callable[[], bool]]):
        self.deadline = deadline
        self.stop = stop
        self.checks: Optional[_Checks] = None

    def over(self) -> bool:
        """(asked at every callback and during a motion's checks: _Checks)"""
        return time.monotonic() >= self.deadline \
            or (self.checks is not None and self.checks.error is not None) \
            or (self.stop is not None and bool(self.stop()))

    def seconds_left(self) -> float:
        return max(0.0, self.deadline - time.monotonic())


def _length(path: np.ndarray, scales: np.ndarray) -> float:
    """A path's length in the search's metric (its controls scaled by ``scales``; 0 for
    none)."""
    if not len(path):
        return 0.0
    return float(np.sum(np.linalg.norm(np.diff(path, axis=0) * scales, axis=1)))


class _Found(NamedTuple):
    """What one search ended with: OMPL's ``status``; the exact solution's states (n, k) as
    found (``unsimplified``) and as returned (``path``), both empty when none; the wall
    seconds of the simplification; the states of the planner's graph."""
    status: str
    path: np.ndarray
    unsimplified: np.ndarray
    simplify_s: float
    graph_states: int
    rounds: int = 1
    samples: int = 0
    out_of_samples: bool = False


def luby(index: int) -> int:
    """Luby's sequence (1 1 2 1 1 2 4 1 1 2 1 1 2 4 8 ...) at ``index`` (from 0)."""
    i = index + 1
    while True:
        k = i.bit_length()
        if i == (1 << k) - 1:
            return 1 << (k - 1)
        i -= (1 << (k - 1)) - 1


def _rounds(search: _Search, settings: GeometricSettings, clock: _Clock) -> _Found:
    """The search's rounds (module docstring: restarts) until one finds a path, the clock is
    over, or a callback failed; one round for a planner not restarted."""
    restarted = settings.restarts and settings.planner in RESTARTED_PLANNERS
    checks = search.checks
    checks.longest, checks.max_samples = settings.roadmap()
    rounds = 0
    while True:
        checks.motions = 0
        checks.budget = RESTART_MOTIONS * luby(rounds) if restarted else math.inf
        found = _run(search, settings.simplify, clock)
        rounds += 1
        if len(found.path) or not restarted or clock.over() or checks.motions < checks.budget:
            return found._replace(rounds=rounds, samples=checks.samples,
                                  out_of_samples=checks.samples >= checks.max_samples)
        search.setup.clear()        # the planner's trees and the problem's approximate paths


def _run(search: _Search, simplify: int, clock: _Clock) -> _Found:
    """What ``search`` finds in the clock's time (its solution then simplified as
    ``simplify`` says, a Simplification, with no deadline)."""
    ob, og, _ = _ompl()
    condition = ob.timedPlannerTerminationCondition(clock.seconds_left())   # _Checks: why
    search.checks.end_search = condition.terminate
    try:
        status = str(search.setup.solve(condition))
    finally:
        search.checks.end_search = _nothing
    data = ob.PlannerData(search.si)
    search.setup.getPlannerData(data)
    graph_states = int(data.numVertices())
    if not search.setup.haveExactSolutionPath():
        none = np.empty((0, search.checks.world.size))
        return _Found(status, none, none, 0.0, graph_states)
    unsimplified = _states(search)
    clock.deadline = math.inf
    # the simplification's shortcuts are not a PRM's connections, nor its samples
    search.checks.longest = search.checks.max_samples = math.inf
    over = clock.over
    if simplify == Simplification.NONE:
        return _Found(status, unsimplified, unsimplified, 0.0, graph_states)
    started = time.perf_counter()
    if simplify == Simplification.SMOOTH:
        og.PathSimplifier(search.si).smoothBSpline(search.setup.getSolutionPath(), 5)
    else:
        _simplify(og, search, over)
    return _Found(status, _states(search), unsimplified, time.perf_counter() - started,
                  graph_states)


def _states(search: _Search) -> np.ndarray:
    """The search's solution path's states (n, k)."""
    geometric = search.setup.getSolutionPath()
    return np.array([search.checks.vector(geometric.getState(i))
                     for i in range(geometric.getStateCount())])


def _simplify(og, search: _Search, over: Callable[[], bool]) -> None:
    """Shortcuts the solution (Simplification.SHORTEN) until ``over()`` (a stop), for at most
    SHORTCUT_ROUNDS rounds while each shortens it by 1 % or more: OMPL's
    reduceVertices, which only tries motions between states of the path that are not
    neighbours and keeps the path's own motions (checked already), so a shortcut cut short by
    the clock is one not taken (OMPL's whole simplification re-checks the path's motions, and
    one cut short there looks invalid)."""
    path = search.setup.getSolutionPath()
    simplifier = og.PathSimplifier(search.si)
    for _ in range(SHORTCUT_ROUNDS):
        if over() or path.getStateCount() <= 2:
            break
        before = path.length()
        if not simplifier.reduceVertices(path) or path.length() > before * SHORTER_ENOUGH:
            break


def load_plan(problem_file) -> BuildPlan:
    """A Kautham problem file's plan, built as ``rosrun GUI load_problem`` builds it (its
    warnings silenced)."""
    from gui.core.kautham.problem import load_problem
    from gui.core.translate import plan_problem
    logging.disable(logging.WARNING)
    try:
        return plan_problem(load_problem(problem_file))
    finally:
        logging.disable(logging.NOTSET)


def settings_of(plan: BuildPlan, time_limit: Optional[float] = None,
                planner: Optional[str] = None) -> GeometricSettings:
    """The problem's own settings (GeometricSettings.of_problem), ``time_limit`` s and
    ``planner`` (OMPL's name) overriding them when given."""
    settings = GeometricSettings.of_problem(plan)
    if time_limit is not None:
        settings = replace(settings, time_limit=time_limit)
    if planner is not None:
        settings = replace(settings, planner=planner)
    return settings


def solve_file(problem_file, seed: Optional[int] = None, time_limit: Optional[float] = None,
               planner: Optional[str] = None) -> GeometricResult:
    """``solve`` for a Kautham problem file (``load_plan``); ``time_limit`` s and ``planner``
    (OMPL's name) override the problem's."""
    plan = load_plan(problem_file)
    return solve(plan, settings_of(plan, time_limit, planner), seed)


def deepest_along(plan: BuildPlan, path: np.ndarray, spacing: float = 0.001
                  ) -> Tuple[float, Optional[Tuple[str, str]]]:
    """How deep any link a control moves goes into anything along ``path`` ((n, k) control
    vectors, as ``GeometricResult.path``): its first state and every configuration of each
    segment's straight motion, ``spacing`` m apart at most for any link point
    (``GeometricWorld.motion_points``), checked by ``GeometricWorld.collisions``. The deepest
    depth in m (0.0 when nothing touches) and its pair (first, second; None when nothing
    touches). A path a search passed at resolution r goes no deeper than about r / 2 (1 mm
    by default), up to the spacing."""
    deepest, pair = 0.0, None
    states = np.asarray(path, dtype=float)
    if len(states) == 0:
        return deepest, pair
    world = GeometricWorld(plan, resolution=spacing)
    try:
        points = [states[0]] + [point for a, b in zip(states, states[1:])
                                for point in world.motion_points(a, b)]
        for point in points:
            found = world.collisions(point)
            if found and found[0][2] > deepest:
                deepest, pair = float(found[0][2]), (found[0][0], found[0][1])
    finally:
        world.close()
    return deepest, pair


PATH_MATCH = 1e-6
"""rad or m: how far a configuration of a path file may be from the one its controls give
(``path_of_solution``)."""


def path_of_solution(plan: BuildPlan, solution) -> np.ndarray:
    """The control vectors (n, k) of a path file read for ``plan``'s problem
    (gui.core.kautham.solutions.Solution: a Kautham task file, as Kautham's GUI or ``plan``
    writes it): per waypoint, the controls that put every robot in its configuration (least
    squares over ``PlannedRobot.control_equations``), so that ``deepest_along`` checks the
    path as the search would have moved. PlanningError when a robot of the problem has no
    path in the file, or a waypoint is no configuration of the control space (farther than
    PATH_MATCH from the one its controls give, e.g. a joint no control moves away from its
    fixed value)."""
    robots = planned_robots(plan)
    size = control_size(robots)
    missing = [r.handle.name for r in robots if r.handle.name not in solution.paths]
    if missing:
        raise PlanningError(f"{solution.source}: no path for robot {missing[0]}")
    counts = {len(solution.paths[r.handle.name].joints) for r in robots}
    if len(counts) != 1:
        raise PlanningError(f"{solution.source}: the robots' paths differ in length")
    path = []
    for k in range(counts.pop()):
        wanted = [(_waypoint_base(r, solution.paths[r.handle.name], k),
                   solution.paths[r.handle.name].joints[k]) for r in robots]
        equations = [r.control_equations(base, joints, size)
                     for r, (base, joints) in zip(robots, wanted)]
        a = np.vstack([e[0] for e in equations])
        b = np.concatenate([e[1] for e in equations])
        controls = np.linalg.lstsq(a, b, rcond=None)[0]
        _check_waypoint(solution, robots, controls, wanted, k)
        path.append(controls)
    return np.array(path).reshape(-1, size)


def _waypoint_base(robot, waypoints, k: int) -> np.ndarray:
    """The robot's base pose at waypoint k: the file's, or its home when the file has none."""
    if waypoints.base_poses is None:
        return robot.handle.instance.base_pose
    return waypoints.base_poses[k]


def _check_waypoint(solution, robots, controls: np.ndarray, wanted, k: int) -> None:
    for robot, (base, joints) in zip(robots, wanted):
        got_base, got_joints = robot.configuration(controls)
        off = max(float(np.max(np.abs(got_joints - joints), initial=0.0)),
                  float(np.max(np.abs(got_base[:3, 3] - base[:3, 3]))))
        if off > PATH_MATCH:
            line = solution.paths[robot.handle.name].lines[k]
            raise PlanningError(f"{solution.source}:{line}: robot {robot.handle.name}'s "
                                f"configuration is {off:.3g} from any of the problem's "
                                "control space")


def task_rows(plan: BuildPlan, path: np.ndarray) -> List[List[float]]:
    """Each state of ``path`` as a Kautham task file's ``<Conf>`` row: per robot in the
    problem's order, for one whose controls move its base its position x y z (m, world) and
    orientation qx qy qz qw, then a value per link but the base (rad or m; 0 for a fixed
    joint), as Kautham's GUI writes them (gui.core.kautham.solutions reads them back)."""
    robots = planned_robots(plan)
    rows = []
    for controls in np.asarray(path, dtype=float):
        row: List[float] = []
        for robot in robots:
            base, joints = robot.configuration(controls)
            if robot.moves_base:
                position, (w, x, y, z) = pose_to_position_quaternion(base)
                row += [float(v) for v in position] + [float(x), float(y), float(z), float(w)]
            values = dict(zip(robot.movable, joints))
            row += [float(values.get(i, 0.0)) for i in range(1, len(robot.links))]
        rows.append(row)
    return rows


def write_task(path, name: str, rows: Sequence[Sequence[float]]) -> None:
    """Writes ``rows`` (``task_rows``) as a Kautham task file of one ``<Transit>``, through
    a file beside it renamed into place (a reader never sees half a file)."""
    import os
    import pathlib
    from xml.sax.saxutils import quoteattr
    target = pathlib.Path(path)
    text = f"<Task name={quoteattr(name)}>\n<Transit>\n" + "".join(
        "<Conf> " + " ".join(repr(float(v)) for v in row) + " </Conf>\n" for row in rows) + \
        "</Transit>\n</Task>\n"
    part = target.with_name(f".{target.name}.part")
    try:
        part.write_text(text)
        os.replace(part, target)
    finally:
        part.unlink(missing_ok=True)


__all__ = ["GEOMETRIC_PLANNERS", "NEAREST_PLANNERS", "OMPL_PLANNERS", "RESOLUTION",
           "GeometricResult", "GeometricSettings", "GeometricWorld", "Simplification",
           "check_query", "deepest_along", "load_plan", "query", "settings_of", "solve",
           "solve_file", "task_rows", "write_task"]
