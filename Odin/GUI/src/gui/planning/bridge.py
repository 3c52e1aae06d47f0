"""OMPL's control planners over an Odin back end (ROS-free; OMPL 2 from PyPI).

The OMPL problem (``gui.planning.problem`` says what each part means):
- state space: a compound of the tracked link's position and velocity (6 values: x, y, z m,
  vx, vy, vz m/s, world frame; the robot's base, or a held chain's tool; bounds from the
  problem's limits and ``max_speed``; weight 1:
  planners measure distances and cells here) and the whole world's body state vector
  (``Core.body_state_vector``, weight 0: carried, never measured) with one value appended,
  the state's verdict: 1 when the step into it made a forbidden contact
  (``forbidden_contacts``) or left the tracked link out of bounds, 0 otherwise;
- control space: [0, 1]^k, the robot's `.cntr` controls (those searched); a control lasts
  ``min_control_steps`` to ``max_control_steps`` propagation steps of ``step`` s;
- propagator: the back end's (restore, apply the row, step, read); over the Core's, a step
  is one C call that also judges the state and writes it, its verdict and the tracked link
  into OMPL's memory (``CoreBackend.propagate_into``), where the wheel allows it
  (``gui.planning.ompl_memory``);
- validity: the verdict: the tracked link in bounds and no forbidden contact on the way in;
- goal region: the tracked link within ``goal_tolerance`` of where the query's goal puts it,
  in the plane;
- projection (KPIECE1's grid): the tracked link's x and y, cells of a quarter of the goal
  region.

``plan(backend, planner, time_limit, seed)`` solves and answers a ``PlanResult`` whose
``rows`` are the control path (one row per propagation step), solved only when its replay
from the start (``verify``) ends in the goal region with no invalid step. The planner
classes the wheel's bindings construct are in ``PLANNERS``; OMPL 2.0.1's wheel defines no
constructor for SST and PDST (``UNCONSTRUCTIBLE``).
"""
from __future__ import annotations

import math
import os
import time
from collections import deque
from dataclasses import dataclass
from typing import Callable, List, NamedTuple, Optional, Tuple

import numpy as np

from gui.core.control_path import ControlRow
from gui.errors import PlanningError
from gui.planning import ompl_memory

PLANNERS = ("KPIECE1", "RRT", "EST")
"""Control planners of OMPL's Python wheel that construct from a SpaceInformation."""
UNCONSTRUCTIBLE = ("SST", "PDST")
"""Control planners the wheel names but cannot construct ("no constructor defined")."""

ROBOT_VALUES = 6
"""The robot component: the tracked link's position (3, m) then velocity (3, m/s), world
frame."""
WORLD_BOUND = 1e10
"""The world component's bounds: its values are never sampled for use, only carried (ODE's
random generator state, below 2^32, is its largest value)."""


@dataclass(frozen=True)
class PlanResult:
    """What a search found, as its replay confirms it. ``solved``: OMPL found an exact
    solution AND the rows, run again from the start in the back end's world, end in the goal
    region with no invalid step on the way (the search's own rule: no forbidden contact, the
    tracked link in bounds); ``rows``: the control path (the best approximate one when not
    solved; empty when the planner found nothing); ``final_position`` (3,) m, world: where the
    tracked link ends in that replay; ``goal_distance``: m, in the plane; ``propagations``:
    propagation steps the search ran; ``time_s``: wall-clock seconds of the search;
    ``status``: OMPL's planner status, what the search claimed (not the verdict: ``verdict``);
    ``invalid``: the replay's first invalid step ("" when none); ``disagreement``: what the
    replay shows against OMPL's exact solution ("" when they agree)."""
    planner: str
    seed: Optional[int]
    solved: bool
    status: str
    rows: Tuple[ControlRow, ...]
    final_position: np.ndarray
    goal_distance: float
    propagations: int
    time_s: float
    invalid: str = ""
    disagreement: str = ""

    @property
    def verdict(self) -> str:
        """One line: what the plan's replay does, never OMPL's status alone."""
        if self.solved:
            return (f"solved: the replay of its {len(self.rows)} rows ends "
                    f"{self.goal_distance:.4f} m from the goal, in the goal region, with no "
                    "forbidden contact and the tracked link in bounds all the way")
        if self.disagreement:
            return f"not solved: the replay disagrees with the search: {self.disagreement}"
        if not self.rows:
            return f"not solved: no path found ({self.status})"
        return (f"not solved: the closest plan ends {self.goal_distance:.4f} m from the goal"
                + (f"; its replay {self.invalid}" if self.invalid else ""))

    @property
    def duration(self) -> float:
        """s, simulated: the plan's length."""
        return sum(row.duration for row in self.rows)

    def statistics(self) -> dict:
        return {"planner": self.planner, "seed": self.seed, "solved": self.solved,
                "status": self.status, "time_s": round(self.time_s, 3),
                "propagations": self.propagations,
                "propagations_per_s": round(self.propagations / self.time_s, 1)
                if self.time_s > 0 else None,
                "rows": len(self.rows), "plan_duration_s": round(self.duration, 4),
                "final_position_m": [round(float(v), 4) for v in self.final_position],
                "goal_distance_m": round(self.goal_distance, 4), "verdict": self.verdict}


def _ompl():
    try:
        from ompl import base as ob, control as oc, util as ou
    except ImportError as error:
        raise PlanningError(f"OMPL's Python bindings are missing ({error}): tools/install.sh "
                            "installs the pinned wheel (tools/requirements.txt)") from None
    return ob, oc, ou


class _Callbacks:
    """The propagator and validity checker OMPL calls. They hold the back end and the
    problem, never the OMPL objects: a reference from a callback back to the SpaceInformation
    holding it would be a cycle through C++ that Python's collector cannot see."""

    def __init__(self, backend, world_size: int, direct: bool):
        self.backend = backend
        self.problem = backend.problem
        self.world_size = world_size
        self.direct = direct
        # the step whole in C, into OMPL's memory: a back end that can (the Core's)
        self.into = getattr(backend, "propagate_into", None) if direct else None
        self.error: Optional[BaseException] = None
        # without ``direct`` the world vector's slots are read and written through map: a
        # propagation moves a few hundred values each way, one OMPL call per value
        self._slots = range(world_size - 1)

    # -- state <-> vectors ---------------------------------------------------------------------
    def _vector(self, state) -> np.ndarray:
        """The world vector of ``state``; with ``direct``, an array over OMPL's own values
        (gui.planning.ompl_memory), which the back end reads before anything is written."""
        if self.direct:
            return ompl_memory.values(state[1], self.world_size - 1)
        return np.fromiter(map(state[1].__getitem__, self._slots), float, len(self._slots))

    def write(self, state, vector: np.ndarray, backend_outcome, touched: bool = False) -> None:
        """``state`` set to the world ``vector``, its tracked link's from ``backend_outcome``
        (the last step into it; None: read from the vector), flagged invalid when ``touched``
        (a forbidden contact on the way in)."""
        robot, world = state[0], state[1]
        if backend_outcome is None:
            position, velocity = self.backend.tracked_state(vector)
        else:
            position, velocity = backend_outcome.position, backend_outcome.velocity
        flag = 1.0 if touched or not self.problem.in_bounds(position, velocity) else 0.0
        if self.direct:
            values = ompl_memory.values(world, self.world_size)
            values[:-1] = vector
            values[-1] = flag
            values = ompl_memory.values(robot, ROBOT_VALUES)
            values[:3] = position
            values[3:] = velocity
            return
        for i in range(3):
            robot[i] = float(position[i])
            robot[3 + i] = float(velocity[i])
        deque(map(world.__setitem__, self._slots, vector.tolist()), maxlen=0)
        world[self.world_size - 1] = flag

    # -- OMPL's callbacks (an exception must not cross into C++: kept and re-raised) -----------
    def propagate(self, start, control, duration, result) -> None:
        try:
            steps = max(1, round(duration / self.problem.step))
            values = self.problem.controls(
                [control[i] for i in range(len(self.problem.searched))])
            vector = self._vector(start)
            if steps == 1 and self.into is not None:     # OMPL's every call: one step
                self.into(vector, values,
                          ompl_memory.values(result[1], self.world_size).reshape(1, -1),
                          ompl_memory.values(result[0], ROBOT_VALUES).reshape(1, -1))
                return
            outcome, touched = None, False
            for _ in range(steps):
                outcome = self.backend.propagate([(vector, values)])[0]
                vector = outcome.state
                # every step's contacts count, not the last one's only (OMPL asks one step
                # at a time, but a longer duration must not hide a contact on the way)
                touched = touched or bool(self.problem.forbidden_contacts(outcome.collisions))
            self.write(result, vector, outcome, touched)
        except BaseException as error:      # noqa: B902 - handed back to plan()
            self.error = self.error or _without_frames(error)
            self.write(result, self._vector(start), None)
            result[1][self.world_size - 1] = 1.0   # invalid: the search stops using it

    def valid(self, state) -> bool:
        # the verdict written with the state (a sampled state's is 0, its tracked values
        # drawn within the bounds)
        return state[1][self.world_size - 1] == 0.0


def _without_frames(error: BaseException) -> BaseException:
    """``error`` and the exceptions it was raised from or during, without their tracebacks.
    A traceback's frames lead (through each frame's caller) to this callback's frame, whose
    ``start`` and ``result`` are OMPL's, and to plan()'s, which holds the whole setup: kept by
    the callbacks, which the SpaceInformation holds, that is a cycle through C++ that Python's
    collector cannot see, and the search's OMPL objects would outlive it (nanobind reporting
    dozens of them leaked when the interpreter ends: a tool whose world died said so after
    its one line)."""
    seen = set()
    links: List[Optional[BaseException]] = [error]
    while links:
        link = links.pop()
        if link is not None and id(link) not in seen:
            seen.add(id(link))
            link.__traceback__ = None
            links += [link.__cause__, link.__context__]
    return error


class _Setup:
    """The OMPL objects of one search, kept together (OMPL holds raw pointers between them)."""

    def __init__(self, backend, planner: str):
        ob, oc, ou = _ompl()
        ou.setLogLevel(ou.LOG_WARN)
        problem = backend.problem
        settings = problem.settings
        self.backend = backend
        self.problem = problem
        self.start = backend.start_state()
        self.world_size = self.start.size + 1            # + the forbidden-contact flag
        self.robot_space = ob.RealVectorStateSpace(ROBOT_VALUES)
        bounds = ob.RealVectorBounds(ROBOT_VALUES)
        for axis in range(3):
            bounds.setLow(axis, float(problem.base_bounds[axis, 0]))
            bounds.setHigh(axis, float(problem.base_bounds[axis, 1]))
            bounds.setLow(3 + axis, -settings.max_speed)
            bounds.setHigh(3 + axis, settings.max_speed)
        self.robot_space.setBounds(bounds)
        cell = settings.goal_tolerance / 2
        self.robot_space.registerDefaultProjection(
            ob.RealVectorOrthogonalProjectionEvaluator(self.robot_space, [cell, cell], [0, 1]))
        self.world_space = ob.RealVectorStateSpace(self.world_size)
        wide = ob.RealVectorBounds(self.world_size)
        wide.setLow(-WORLD_BOUND)
        wide.setHigh(WORLD_BOUND)
        # the forbidden-contact flag of a valid state is 0: a state sampled anywhere else is
        # never valid, and EST, which grows only from valid samples, never propagated. The
        # world subspace weighs 0 in distances and a sample draws one number per value
        # whatever its bounds, so the other planners' searches are unchanged.
        wide.setLow(self.world_size - 1, 0.0)
        wide.setHigh(self.world_size - 1, 0.0)
        self.world_space.setBounds(wide)
        self.space = ob.CompoundStateSpace([self.robot_space, self.world_space], [1.0, 0.0])
        self.space.registerDefaultProjection(ob.SubspaceProjectionEvaluator(self.space, 0))
        searched = len(problem.searched)
        self.control_space = oc.RealVectorControlSpace(self.space, searched)
        unit = ob.RealVectorBounds(searched)
        unit.setLow(0.0)
        unit.setHigh(1.0)
        self.control_space.setBounds(unit)
        self.si = oc.SpaceInformation(self.space, self.control_space)
        self.si.setPropagationStepSize(problem.step)
        self.si.setMinMaxControlDuration(settings.min_control_steps,
                                         settings.max_control_steps)
        direct = ompl_memory.LayoutProbe.holds(self.space, (ROBOT_VALUES, self.world_size))
        self.callbacks = _Callbacks(backend, self.world_size, direct)
        self.si.setStatePropagator(self.callbacks.propagate)
        self.si.setStateValidityChecker(self.callbacks.valid)
        self.si.setup()
        self.goal = _goal_region(ob, self.si, problem)
        self.setup = oc.SimpleSetup(self.si)
        start = self.si.allocState()
        self.callbacks.write(start, self.start, backend_outcome=None)
        self.setup.setStartState(start)
        self.setup.setGoal(self.goal)
        self.planner = _planner(oc, self.si, planner, settings.goal_bias)
        self.setup.setPlanner(self.planner)

def _goal_region(ob, si, problem):
    class GoalXY(ob.GoalRegion):
        """The query's goal: the tracked link within the tolerance, in the plane."""

        def __init__(self, si, problem):
            super().__init__(si)
            self.problem = problem
            self.setThreshold(problem.settings.goal_tolerance)

        def distanceGoal(self, state) -> float:
            robot = state[0]
            return self.problem.goal_distance((robot[0], robot[1]))

    return GoalXY(si, problem)


def _planner(oc, si, name: str, goal_bias: float):
    if name in UNCONSTRUCTIBLE:
        raise PlanningError(f"planner {name}: OMPL's Python wheel defines no constructor for "
                            f"it; use one of {', '.join(PLANNERS)}")
    if name not in PLANNERS:
        raise PlanningError(f"unknown planner {name!r}: one of {', '.join(PLANNERS)}")
    planner = getattr(oc, name)(si)
    if hasattr(planner, "setGoalBias"):
        planner.setGoalBias(goal_bias)
    return planner


MAX_SEED = 2 ** 32 - 1
"""The largest seed OMPL takes (its generators' seed is a 32-bit unsigned integer): the one
home of the seeds' range, which every check and option of a seed reads."""


def check_seed(seed: int, room: int = 0) -> None:
    """PlanningError unless ``seed`` is an integer in [1, MAX_SEED - ``room``] (``room``:
    the seeds kept free above it, for the searches that follow it)."""
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 < seed <= MAX_SEED - room:
        below = f"2^{MAX_SEED.bit_length()}" + (f" - {room}" if room else "")
        raise PlanningError(f"seed {seed!r} must be an integer in [1, {below})")


def seed_ompl(seed: int) -> None:
    """Seeds OMPL's random generators; effective for a process's first search only (OMPL
    seeds each generator from one master it makes once)."""
    _, _, ou = _ompl()
    check_seed(seed)
    ou.RNG.setSeed(seed)


def plan(backend, planner: str = "KPIECE1", time_limit: float = 10.0,
         seed: Optional[int] = None, stop: Optional[Callable[[], bool]] = None,
         memory_limit_mb: Optional[float] = None) -> PlanResult:
    """Searches ``backend.problem`` with ``planner`` for at most ``time_limit`` s of wall
    clock (``seed``: OMPL's seed, see ``seed_ompl``) and, with ``memory_limit_mb``, until this
    process has grown by more than that many MB of resident memory since the search began
    (OMPL Benchmark's maxMem rule; the search ends as the clock would end it, its status
    what the planner answers). ``stop()`` true ends the search at the
    planner's next iteration (one propagation at most) and raises KeyboardInterrupt: what
    Ctrl-C does under ``odin_common.tool.stop_on_ctrl_c`` (OMPL's solve runs in C++, where
    no Python signal handler can raise; a propagation cut by an exception would be lost).
    A back end with ``check_query`` (the Core's) is asked first: PlanningError, before any
    search, for a query no search can solve (gui.planning.problem.query_refusal). The plan
    found is replayed in the back end and checked by the search's rule (``verify``): the
    result is solved only when that replay holds (``PlanResult``)."""
    if not (math.isfinite(time_limit) and time_limit > 0):
        raise PlanningError(f"time {time_limit!r} s must be positive")
    check = getattr(backend, "check_query", None)
    if check is not None:
        check()                 # a query no search can solve, refused before any search
    if seed is not None:
        seed_ompl(seed)
    setup = _Setup(backend, planner)
    before = _propagations(backend)
    started = time.perf_counter()
    deadline = time.monotonic() + time_limit
    callbacks = setup.callbacks
    memory_over = _memory_watch(memory_limit_mb)

    def over() -> bool:
        """OMPL's termination condition, asked once per planner iteration."""
        return time.monotonic() >= deadline or callbacks.error is not None or \
            (stop is not None and bool(stop())) or memory_over()

    ob, _, _ = _ompl()
    status = setup.setup.solve(ob.PlannerTerminationCondition(over))
    elapsed = time.perf_counter() - started
    propagations = _propagations(backend) - before
    if stop is not None and stop():
        raise KeyboardInterrupt
    if setup.callbacks.error is not None:
        error = setup.callbacks.error
        raise PlanningError(f"propagation failed: {error}") from error
    rows: List[ControlRow] = []
    if setup.setup.haveSolutionPath():
        rows = _rows(setup.setup.getSolutionPath(), setup.problem)
    exact = bool(setup.setup.haveExactSolutionPath())
    # OMPL's status is what the search claims; the verdict is the replay's, under the rule
    # the search used, from the start in this back end: a path counts only when it holds there
    problem = backend.problem
    checked = verify(backend, rows)
    final = checked.final_position
    distance = problem.goal_distance(final)
    solved = exact and problem.in_goal(final) and not checked.invalid
    differs = []
    if exact and not problem.in_goal(final):
        differs.append(f"its replay ends {distance:.4f} m from the goal, outside the "
                       f"{problem.settings.goal_tolerance:g} m goal region")
    if exact and checked.invalid:
        differs.append(f"its replay {checked.invalid}")
    disagreement = f"OMPL reports an exact solution, but {' and '.join(differs)}" \
        if differs else ""
    return PlanResult(planner, seed, solved, str(status), tuple(rows), final, distance,
                      propagations, elapsed, checked.invalid, disagreement)


MEMORY_CHECK_S = 0.1
"""s between two readings of the process's resident memory during a search with a limit (a
reading costs about as much as 2 % of a propagation)."""


def _memory_watch(limit_mb: Optional[float]) -> Callable[[], bool]:
    """A function true once this process's resident memory is more than ``limit_mb`` MB above
    what it was now (always false without a limit); it reads /proc at most every
    MEMORY_CHECK_S."""
    if limit_mb is None:
        return lambda: False
    if not (math.isfinite(limit_mb) and limit_mb > 0):
        raise PlanningError(f"memory limit {limit_mb!r} MB must be positive")
    ceiling = resident_bytes() + limit_mb * 2 ** 20
    state = dict(next_check=0.0, over=False)

    def over() -> bool:
        now = time.monotonic()
        if not state["over"] and now >= state["next_check"]:
            state["next_check"] = now + MEMORY_CHECK_S
            state["over"] = resident_bytes() > ceiling
        return state["over"]
    return over


def resident_bytes() -> int:
    """This process's resident memory, bytes (/proc/self/statm, as OMPL's
    getProcessMemoryUsage reads it)."""
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE")


def _rows(path, problem) -> List[ControlRow]:
    rows = []
    for k in range(path.getControlCount()):
        control = path.getControl(k)
        values = problem.controls([control[i] for i in range(len(problem.searched))])
        steps = max(1, round(path.getControlDuration(k) / problem.step))
        rows += [ControlRow(values, problem.step)] * steps
    return rows


class Replay(NamedTuple):
    """A plan run again from the start state in a back end, checked step by step as the
    search checks a state (no forbidden contact on the way in, the tracked link in bounds and
    no faster than max_speed): ``final_position`` (3,) m, world, where the tracked link ends;
    ``invalid``: the first step that breaks the rule ("makes an invalid step at row 42 (1.260
    s): ..."), "" when none does."""
    final_position: np.ndarray
    invalid: str


def verify(backend, rows) -> Replay:
    """``rows`` run from the start state in the back end and checked (``Replay``)."""
    problem = backend.problem
    vector = backend.start_state()
    position = None
    invalid = ""
    elapsed = 0.0
    for number, row in enumerate(rows, start=1):
        outcome = backend.propagate([(vector, row.controls)])[0]
        vector, position = outcome.state, outcome.position
        elapsed += row.duration
        if not invalid:
            why = _invalid_step(problem, outcome)
            if why:
                invalid = f"makes an invalid step at row {number} ({elapsed:.3f} s): {why}"
    if position is None:
        position = backend.tracked_state(vector)[0]
    return Replay(np.asarray(position), invalid)


def _invalid_step(problem, outcome) -> str:
    """Why the search would refuse the state ``outcome`` reached ("" when it would not)."""
    forbidden = problem.forbidden_contacts(outcome.collisions)
    if forbidden:
        first, second = forbidden[0]
        return f"{first} touches {second}, which is forbidden"
    if not problem.in_bounds(outcome.position, outcome.velocity):
        at = ", ".join(f"{float(v):.3f}" for v in outcome.position)
        fast = max(abs(float(v)) for v in outcome.velocity)
        return (f"{problem.tracked_body} at ({at}) m, {fast:.3f} m/s on its fastest axis: "
                f"outside the <Limits> or faster than {problem.settings.max_speed:g} m/s")
    return ""


def replay(backend, rows) -> np.ndarray:
    """(3,) m: where the tracked link ends when ``rows`` run from the start state in the back
    end (``verify`` also says whether the run keeps the search's rule)."""
    return verify(backend, rows).final_position


def _propagations(backend) -> int:
    return int(getattr(backend, "propagations", 0))


__all__ = ["MAX_SEED", "PLANNERS", "UNCONSTRUCTIBLE", "PlanResult", "Replay", "check_seed", "plan",
           "replay", "seed_ompl", "verify"]
