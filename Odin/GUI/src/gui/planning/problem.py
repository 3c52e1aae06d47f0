"""What a loaded Kautham problem asks of a planner (ROS-free, OMPL-free).

A planning problem drives one robot whose base is a free body (Kautham's 2D environments: the
Sphere demos), in a world built from the problem (``gui.core.build``):

- its **state** is the world's: every body's dynamic state (``Core.body_state_vector``); the
  planner measures distances and makes progress on the robot base's position and velocity
  (m, m/s, world frame), bounded by the problem's ``<Limits>`` and ``SearchSettings.max_speed``;
- a **control** is a row of the robot's control path, k values in [0, 1] (the `.cntr`'s,
  mapped as ``gui.core.control_path`` maps them); in the plane (``SearchSettings.planar``,
  Kautham's 2D planners: "Control Dimensions" 2) the planner searches the controls that move
  the base in x or y only, and holds the others at the query's ``<Init>`` values (the
  Sphere's z control, which presses it onto the ground); a control is held for a whole number of propagation
  steps between ``min_control_steps`` and ``max_control_steps`` (Kautham's ODE planners'
  "Min/Max Control Steps"), each step one row of ``step`` s;
- the **goal region** is the query's ``<Goal>``: the base within ``goal_tolerance`` m of the
  goal's position in x and y (Kautham's KauthamDEGoalRegion measures in the plane too, with a
  0.05 m threshold, under planning times of minutes);
- a **motion is invalid** when the robot touches an obstacle it must not: Kautham's
  KauthamOpenDEEnvironment lets its robots touch the floor and the obstacles it lists as
  manipulable (``MANIPULABLE``: the cubes, boxes and cylinders of its demos), every other
  obstacle is "fixed" (the arena's walls); or when its base leaves the bounds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable, Optional, Tuple

import numpy as np

from gui.core.build import GROUND, BuildPlan, RobotHandle
from gui.core.model import FREE_BODY, MOBILE
from gui.errors import PlanningError

MANIPULABLE = frozenset(
    [f"cubeDE{k}" for k in ("", 1, 2, 3, 4, 5, 6, 7, 8)] + ["cylinder1", "cylinder2",
                                                            "cylinder3", "SimpleCar"]
    + [f"box{k}" for k in (2, 3, 4, 5)])
"""Obstacles a robot may push: those Kautham's KauthamOpenDEEnvironment types
"freeManipulatable" (by body name); the others are "fixed", which its robots must not touch."""


@dataclass(frozen=True)
class SearchSettings:
    """How a planner searches. ``step``: s, one propagation step, one control path row (None:
    the world's step, Kautham's PropagationStepSize). ``min_control_steps`` /
    ``max_control_steps``: how long a control is held, in steps (Kautham's Sphere planners:
    2 and 30). ``goal_tolerance``: m, the goal region's radius in the plane. ``max_speed``:
    m/s, the base's speed bound per axis (Kautham's "Max Speed": 10). ``goal_bias``: the
    fraction of samples drawn in the goal region where the planner samples goals.
    ``planar``: search only the controls that move the base in x or y (module docstring)."""
    step: Optional[float] = None
    min_control_steps: int = 2
    max_control_steps: int = 30
    goal_tolerance: float = 0.25
    max_speed: float = 10.0
    goal_bias: float = 0.05
    planar: bool = True

    def check(self) -> None:
        if self.step is not None and not (math.isfinite(self.step) and self.step > 0):
            raise PlanningError(f"step {self.step!r} s must be positive")
        if not 1 <= self.min_control_steps <= self.max_control_steps:
            raise PlanningError(f"control steps {self.min_control_steps}..."
                                f"{self.max_control_steps}: need 1 <= min <= max")
        for name in ("goal_tolerance", "max_speed"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise PlanningError(f"{name} {value!r} must be positive")
        if not 0.0 <= self.goal_bias <= 1.0:
            raise PlanningError(f"goal_bias {self.goal_bias!r} must be in [0, 1]")


@dataclass(frozen=True)
class PlanningProblem:
    """One robot's planning problem (module docstring). ``base_body``: the world ID of the
    robot's base body; ``base_bounds`` (3, 2): m, world frame, low and high per axis;
    ``goal_xy`` (2,): m, world frame; ``forbidden``: object IDs the robot must not touch;
    ``robot_bodies``: the robot's body IDs; ``step``: s, one propagation step;
    ``searched``: indices of the controls the planner chooses, the others held at
    ``held`` (the query start's controls)."""
    handle: RobotHandle
    base_body: str
    robot_bodies: Tuple[str, ...]
    base_bounds: np.ndarray
    goal_xy: np.ndarray
    forbidden: frozenset
    control_size: int
    step: float
    settings: SearchSettings
    searched: Tuple[int, ...]
    held: Tuple[float, ...]

    def controls(self, searched_values) -> Tuple[float, ...]:
        """The full control row (k values) for the values of the searched controls."""
        full = list(self.held)
        for index, value in zip(self.searched, searched_values):
            full[index] = float(value)
        return tuple(full)

    def goal_distance(self, base_position) -> float:
        """m: how far the base is from the goal in the plane."""
        return float(math.hypot(base_position[0] - self.goal_xy[0],
                                base_position[1] - self.goal_xy[1]))

    def in_goal(self, base_position) -> bool:
        return self.goal_distance(base_position) < self.settings.goal_tolerance

    def forbidden_contacts(self, pairs: Iterable[Tuple[str, str]]) -> list:
        """The pairs (object IDs or geometry names) that touch the robot and a forbidden
        obstacle."""
        robot = set(self.robot_bodies)
        return [(a, b) for a, b in pairs
                if (_object(a) in robot and _object(b) in self.forbidden)
                or (_object(b) in robot and _object(a) in self.forbidden)]

    def in_bounds(self, base_position, base_velocity) -> bool:
        low, high = self.base_bounds[:, 0], self.base_bounds[:, 1]
        position = np.asarray(base_position)
        return bool(np.all(position >= low) and np.all(position <= high)
                    and np.all(np.abs(base_velocity) <= self.settings.max_speed))


def _object(name: str) -> str:
    """The object a geometry name belongs to (a composite part "name#k" -> "name")."""
    return name.split("#", 1)[0]


def planning_problem(plan: BuildPlan, robot: Optional[str] = None,
                     settings: SearchSettings = SearchSettings()) -> PlanningProblem:
    """The planning problem of ``plan``'s robot (the first robot when None); PlanningError
    when the robot is not one the planner drives or the problem has no query."""
    settings.check()
    try:
        handle = plan.robot(robot)
    except KeyError as error:
        raise PlanningError(str(error.args[0] if error.args else error)) from None
    if handle.kind not in (FREE_BODY, MOBILE) or handle.motor_ids:
        raise PlanningError(f"robot {handle.name} is a {handle.kind or 'fixed'} robot"
                            f"{' with joints' if handle.motor_ids else ''}: the planner "
                            "drives a free body (Kautham's 2D environments) only")
    if handle.goal is None or handle.start is None:
        raise PlanningError(f"robot {handle.name}: the problem has no query (<Init> and "
                            "<Goal>) to plan")
    controls = handle.instance.controls
    if controls is None or not controls.se3 or not controls.moved_base_axes():
        raise PlanningError(f"robot {handle.name}: its controls move no axis of its base")
    if plan.world is None:
        raise PlanningError("the problem has no physics (not one of Kautham's ODE planners): "
                            "nothing to propagate")
    step = settings.step if settings.step is not None else plan.world.step
    searched = tuple(range(controls.size))
    if settings.planar:
        searched = tuple(k for k in searched if np.any(controls.matrix[:2, k] != 0.0))
    held = handle.start.controls or (0.5,) * controls.size
    return PlanningProblem(
        handle=handle, base_body=handle.bodies[0].body_id,
        robot_bodies=tuple(b.body_id for b in handle.bodies),
        base_bounds=_base_bounds(handle), goal_xy=np.array(handle.goal.base_pose[:2, 3]),
        forbidden=frozenset(_forbidden(plan, handle)), control_size=controls.size,
        step=float(step), settings=settings, searched=searched,
        held=tuple(float(v) for v in held))


def _base_bounds(handle: RobotHandle) -> np.ndarray:
    """(3, 2): the problem's <Limits> per axis, wide open where it gives none."""
    bounds = np.array([[-1e3, 1e3]] * 3)
    for axis, name in enumerate("XYZ"):
        if name in handle.instance.limits:
            bounds[axis] = handle.instance.limits[name]
    return bounds


def _forbidden(plan: BuildPlan, handle: RobotHandle) -> list:
    robot = {b.body_id for b in handle.bodies}
    return [body.id for body in plan.bodies()
            if body.id not in robot and body.id != GROUND
            and _object(body.id) not in MANIPULABLE]


__all__ = ["MANIPULABLE", "SearchSettings", "PlanningProblem", "planning_problem"]
