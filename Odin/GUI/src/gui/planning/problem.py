"""What a loaded Kautham problem asks of a planner (ROS-free, OMPL-free).

A planning problem drives one robot of a world built from the problem (``gui.core.translate``),
as Kautham's ODE environments drive the robots of its physics demos: a free body pushed by a
force (its 2D environments: the Sphere demos), a car on hinge-2 wheels (CarEnvironment), a
chain whose base is held to the world, driven at its joints (PlanarChainEnvironment):

- its **state** is the world's: every body's dynamic state (``Core.body_state_vector``); the
  planner measures distances and makes progress on the **tracked link**'s origin and velocity
  (m, m/s, world frame), bounded by the problem's ``<Limits>`` and ``SearchSettings.max_speed``.
  The tracked link is the robot's base, except for a robot whose base is held: there it is its
  tool, the last link of the chain from the base before it branches (a gripper's first link,
  where its fingers fork) or the chain's last link (Kautham's chain planner measures its body
  3, "the gripper's first link", which is this link of its demo chain);
- a **control** is a row of the robot's control path, k values in [0, 1] mapped as
  ``gui.core.control_path`` maps them (a free body: the force that reaches the row's position;
  a car: steering and wheel speed; joints: servo targets); in the plane
  (``SearchSettings.planar``, Kautham's 2D planners: "Control Dimensions" 2) the planner
  searches a free body's controls that move it in x or y only, and holds the others at the
  query's ``<Init>`` values (the Sphere's z control, which presses it onto the ground); a car's
  two controls and a chain's controls are all searched; a control is held for a whole number
  of propagation steps between ``min_control_steps`` and ``max_control_steps`` (Kautham's ODE
  planners' "Min/Max Control Steps"), each step one row of ``step`` s;
- the **goal region** is the query's ``<Goal>``: the tracked link within ``goal_tolerance`` m
  of where it is at the goal configuration, in x and y (Kautham's KauthamDEGoalRegion measures
  in the plane too, with a 0.05 m threshold, under planning times of minutes);
- a **motion is invalid** when something touches an obstacle it must not: Kautham's
  KauthamOpenDEEnvironment lets its robots touch the floor and the obstacles it lists as
  manipulable (``MANIPULABLE``: the cubes, boxes and cylinders of its demos), every other
  obstacle is "fixed" (the arena's walls), and nothing but the ground may touch a fixed
  obstacle: not the robot, not a block it pushes, not another fixed obstacle (the rule of
  Kautham's PlanarChainEnvironment for every robot: its 2D and car environments rule only the
  robot's contacts, and a block pushed into a wall, a free 2 kg body in both worlds, shoved the
  wall aside and knocked walls over in plans that counted as solved: issue 41); a held chain
  may push manipulable obstacles with its tool only (PlanarChainEnvironment's "tcp" bodies);
  or when the tracked link leaves the bounds.

``query_refusal`` says before any search why a query cannot be solved whatever the search does:
its start already touching what it must not, its goal outside the bounds or joint limits, or
the robot at its goal inside a fixed obstacle.
"""
from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from typing import Iterable, Optional, Tuple

import numpy as np

from gui.core.control_path import control_size
from gui.core.kautham.environment import MANIPULABLE
from gui.core.model import CAR, FREE_BODY, MOBILE
from gui.core.overlaps import BUILT_OVERLAP
from gui.core.plan import BuildPlan, RobotHandle
from gui.core.translate import GROUND
from gui.errors import PlanningError
from odin_common.limits import shown
from odin_common.rotations import quaternion_to_matrix

MAX_CONTROL_STEPS = 10_000
"""Propagation steps a planner may hold one control (Kautham's planners: 2 to 30): each step
is a world step the search waits for (10,000 of Kautham's 0.03 s steps is 300 s of simulated
time for one motion); OMPL takes it as an unsigned int."""


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

    @classmethod
    def of_problem(cls, plan: BuildPlan, **overrides) -> "SearchSettings":
        """The settings ``plan``'s problem asks for: its planner's Min/Max Control Steps, Goal
        Bias and Max Speed where it gives them (``PlannerSearch``), the defaults otherwise;
        then ``overrides`` (fields given as not None)."""
        planner = plan.problem.planner
        given = {}
        if planner is not None:
            search = planner.search
            given = {name: getattr(search, name) for name in
                     ("min_control_steps", "max_control_steps", "goal_bias", "max_speed")
                     if getattr(search, name) is not None}
        given.update({k: v for k, v in overrides.items() if v is not None})
        return cls(**given)

    def check(self) -> None:
        if self.step is not None and not (math.isfinite(self.step) and self.step > 0):
            raise PlanningError(f"step {self.step!r} s must be positive")
        steps = (self.min_control_steps, self.max_control_steps)
        if any(isinstance(n, bool) or not isinstance(n, int) for n in steps) or \
                not 1 <= steps[0] <= steps[1] <= MAX_CONTROL_STEPS:
            raise PlanningError(f"control steps {shown(steps[0])}...{shown(steps[1])}: need "
                                f"whole numbers 1 <= min <= max <= {MAX_CONTROL_STEPS:,} "
                                "(MAX_CONTROL_STEPS)")
        for name in ("goal_tolerance", "max_speed"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise PlanningError(f"{name} {value!r} must be positive")
        if not 0.0 <= self.goal_bias <= 1.0:
            raise PlanningError(f"goal_bias {self.goal_bias!r} must be in [0, 1]")


class ContactRole(enum.IntEnum):
    """What an object is to the rule of forbidden contacts (module docstring): a robot body
    is TOOL when it may push manipulable obstacles, ROBOT otherwise; anything that is not
    the ground, a fixed obstacle or the robot's is OTHER (manipulable obstacles, other
    robots' bodies)."""
    OTHER = 0
    GROUND = 1
    FIXED = 2
    TOOL = 3
    ROBOT = 4


FORBIDDEN_ROLE_PAIRS = (
    # a fixed obstacle is a free body in the world: whatever but the ground touches it may
    # move it (another fixed obstacle, the robot, a block it pushes)
    (ContactRole.FIXED, ContactRole.FIXED), (ContactRole.FIXED, ContactRole.TOOL),
    (ContactRole.FIXED, ContactRole.ROBOT), (ContactRole.FIXED, ContactRole.OTHER),
    # the robot touches only the ground and itself, but with its tool
    (ContactRole.ROBOT, ContactRole.OTHER))
"""The pairs of ContactRole whose contact makes a motion invalid (either order): the one
statement of the rule, which PlanningProblem.forbidden_contacts applies to named pairs and
odin_plan.c to a propagation's pairs (Core.plan_rule)."""
_FORBIDDEN_ROLES = frozenset(frozenset(pair) for pair in FORBIDDEN_ROLE_PAIRS)


@dataclass(frozen=True)
class PlanningProblem:
    """One robot's planning problem (module docstring). ``base_body``: the world ID of the
    robot's base body (a free base's force acts on it); ``tracked_body``: the tracked link's
    body and ``tracked_link_origin`` (3,) m, the link's origin in that body's frame (the
    inverse of the body's offset in the link, taken once); ``base_bounds``
    (3, 2): m, world frame, low and high per axis, for the tracked link's origin; ``goal_xy``
    (2,): m, world frame, the tracked link's origin at the goal; ``forbidden``: object IDs
    (the fixed obstacles) nothing but the ground may touch; ``robot_bodies``: the robot's
    body IDs; ``tool_bodies``: those that may push manipulable obstacles; ``step``: s, one
    propagation step; ``searched``: indices of the controls the planner chooses, the others
    held at ``held`` (the query start's controls)."""
    handle: RobotHandle
    base_body: str
    tracked_body: str
    tracked_link_origin: np.ndarray
    robot_bodies: Tuple[str, ...]
    tool_bodies: frozenset
    base_bounds: np.ndarray
    goal_xy: np.ndarray
    forbidden: frozenset
    control_size: int
    step: float
    settings: SearchSettings
    searched: Tuple[int, ...]
    held: Tuple[float, ...]
    # (first, second) geometry names -> whether that contact is forbidden, as asked (a few
    # dozen pairs, asked at every propagation)
    _verdicts: dict = field(default_factory=dict, init=False, compare=False, repr=False)

    def controls(self, searched_values) -> Tuple[float, ...]:
        """The full control row (k values) for the values of the searched controls."""
        full = list(self.held)
        for index, value in zip(self.searched, searched_values):
            full[index] = float(value)
        return tuple(full)

    def tracked_origin(self, body_position, body_quaternion) -> np.ndarray:
        """(3,) m, world: the tracked link's origin when its body's frame is at
        ``body_position`` with ``body_quaternion`` (w, x, y, z)."""
        return np.asarray(body_position) + \
            quaternion_to_matrix(body_quaternion) @ self.tracked_link_origin

    def goal_distance(self, tracked_position) -> float:
        """m: how far the tracked link is from the goal in the plane: the planner's metric,
        the figure ``plan`` prints and ``run_path --controls`` reports."""
        return float(math.hypot(tracked_position[0] - self.goal_xy[0],
                                tracked_position[1] - self.goal_xy[1]))

    def body_goal_distance(self, body_position, body_quaternion) -> float:
        """m: ``goal_distance`` of the tracked link when its body's frame is at
        ``body_position`` with ``body_quaternion`` (w, x, y, z), world frame."""
        return self.goal_distance(self.tracked_origin(body_position, body_quaternion))

    def in_goal(self, tracked_position) -> bool:
        return self.goal_distance(tracked_position) < self.settings.goal_tolerance

    def robot_contacts(self, pairs: Iterable[Tuple[str, str]]) -> list:
        """The distinct pairs of objects (sorted) among ``pairs`` (object IDs or geometry
        names) where the robot touches something else."""
        robot = set(self.robot_bodies)
        objects = {tuple(sorted((_object(a), _object(b)))) for a, b in pairs}
        return sorted(pair for pair in objects if (pair[0] in robot) != (pair[1] in robot))

    def forbidden_contacts(self, pairs: Iterable[Tuple[str, str]]) -> list:
        """The pairs (object IDs or geometry names) that make a motion invalid: anything but
        the ground touching a forbidden obstacle, or a robot body outside its tool touching
        anything but the ground (module docstring)."""
        verdicts = self._verdicts
        forbidden = []
        for first, second in pairs:
            key = (first, second)
            verdict = verdicts.get(key)
            if verdict is None:
                verdict = verdicts[key] = self._invalid(_object(first), _object(second))
            if verdict:
                forbidden.append(key)
        return forbidden

    def _invalid(self, first: str, second: str) -> bool:
        return frozenset((self.contact_role(first), self.contact_role(second))) \
            in _FORBIDDEN_ROLES

    def contact_role(self, object_id: str) -> "ContactRole":
        """What ``object_id`` is to the rule of forbidden contacts (``ContactRole``)."""
        if object_id == GROUND:
            return ContactRole.GROUND
        if object_id in self.forbidden:
            return ContactRole.FIXED
        if object_id in self.tool_bodies:
            return ContactRole.TOOL
        if object_id in self.robot_bodies:
            return ContactRole.ROBOT
        return ContactRole.OTHER

    def contact_roles(self, object_ids: Iterable[str]) -> dict:
        """{object id: its ContactRole} for those of ``object_ids`` whose role is not OTHER
        (Core.plan_rule's roles: an object not named has role 0, OTHER)."""
        roles = {name: self.contact_role(name) for name in object_ids}
        return {name: int(role) for name, role in roles.items() if role != ContactRole.OTHER}

    def in_bounds(self, tracked_position, tracked_velocity) -> bool:
        """Whether the tracked link is in the base's bounds, no faster than max_speed on any
        axis (NaN is not; plain floats: OMPL asks at every propagation)."""
        top = self.settings.max_speed
        return all(low <= float(p) <= high for p, (low, high) in
                   zip(tracked_position, self.base_bounds.tolist())) \
            and all(abs(float(v)) <= top for v in tracked_velocity)


def _object(name: str) -> str:
    """The object a geometry name belongs to (a composite part "name#k" -> "name")."""
    return name.split("#", 1)[0]


def planning_problem(plan: BuildPlan, robot: Optional[str] = None,
                     settings: Optional[SearchSettings] = None) -> PlanningProblem:
    """The planning problem of ``plan``'s robot (the first robot when None) searched with
    ``settings`` (None: ``SearchSettings.of_problem``); PlanningError when the robot is not
    one the planner drives or the problem has no query."""
    if settings is None:
        settings = SearchSettings.of_problem(plan)
    settings.check()
    try:
        handle = plan.robot(robot)
    except KeyError as error:
        raise PlanningError(str(error.args[0] if error.args else error)) from None
    if not plan.physics:
        raise PlanningError("the problem has no physics (not one of Kautham's ODE planners): "
                            "nothing to propagate")
    if handle.goal is None or handle.start is None:
        raise PlanningError(f"robot {handle.name}: the problem has no query (<Init> and "
                            "<Goal>) to plan")
    searched = _searched_controls(handle, settings)
    step = settings.step if settings.step is not None else plan.world.step
    size = control_size(handle)
    held = handle.start.controls if handle.kind != CAR and handle.start.controls else \
        (0.5,) * size
    tracked = _tracked_link(handle)
    tool = _tool_links(handle, tracked)
    goal = handle.instance.model.link_poses(handle.goal.base_pose, handle.goal.joints)[tracked]
    return PlanningProblem(
        handle=handle, base_body=handle.bodies[0].body_id,
        tracked_body=handle.bodies[tracked].body_id,
        tracked_link_origin=np.linalg.inv(handle.bodies[tracked].offset)[:3, 3],
        robot_bodies=tuple(b.body_id for b in handle.bodies),
        tool_bodies=frozenset(handle.bodies[i].body_id for i in tool),
        base_bounds=_base_bounds(handle), goal_xy=np.array(goal[:2, 3]),
        forbidden=frozenset(_forbidden(plan, handle)), control_size=size,
        step=float(step), settings=settings, searched=searched,
        held=tuple(float(v) for v in held))


def _searched_controls(handle: RobotHandle, settings: SearchSettings) -> Tuple[int, ...]:
    """The controls the planner chooses (module docstring); PlanningError when the robot's
    controls drive nothing."""
    if handle.kind == CAR:
        return tuple(range(control_size(handle)))
    controls = handle.instance.controls
    if controls is None:
        raise PlanningError(f"robot {handle.name}: it has no controls (no control file)")
    base_axes = controls.moved_base_axes() if controls.se3 else []
    driven_base = handle.kind in (FREE_BODY, MOBILE) and base_axes
    if not driven_base and not handle.motor_ids:
        raise PlanningError(f"robot {handle.name}: its controls move no axis of its base and "
                            "it has no joints to drive")
    searched = tuple(range(controls.size))
    if settings.planar and driven_base and not handle.motor_ids:
        searched = tuple(k for k in searched if np.any(controls.matrix[:2, k] != 0.0))
    return searched


def _tracked_link(handle: RobotHandle) -> int:
    """The index of the link the planner follows (module docstring): the base, or a held
    robot's tool."""
    model = handle.instance.model
    if handle.kind in (FREE_BODY, MOBILE, CAR) or not handle.motor_ids:
        return 0
    link, children = 0, model.children(0)
    while len(children) == 1:
        link = children[0]
        children = model.children(link)
    if link == 0:
        raise PlanningError(f"robot {handle.name}: its held base branches at once, so it has "
                            "no one tool for the planner to follow")
    return link


def _tool_links(handle: RobotHandle, tracked: int) -> list:
    """The links that may push manipulable obstacles: all but a held chain's links before its
    tool (the tool and what hangs from it)."""
    model = handle.instance.model
    if tracked == 0:
        return list(range(len(model.links)))
    tool, frontier = [], [tracked]
    while frontier:
        link = frontier.pop()
        tool.append(link)
        frontier += model.children(link)
    return sorted(tool)


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


def query_refusal(problem: PlanningProblem, world) -> Optional[str]:
    """Why ``problem``'s query cannot be solved whatever a search does, in one line, or None:
    ``start_refusal``, else ``goal_refusal``. ``world``: the problem's world in its start state
    (as built), anything answering ``check_collision(poses)`` with (first, second, depth m)
    pairs, the robot's links placed at ``poses`` (gui.planning.core_world.CoreWorld), which
    steps nothing and changes nothing."""
    return start_refusal(problem, world) or goal_refusal(problem, world)


def start_refusal(problem: PlanningProblem, world) -> Optional[str]:
    """One line when something already touches what it must not at the query's start
    (``forbidden_contacts``): the first step of every motion would be invalid; else None.
    ``world`` as ``query_refusal`` takes it."""
    start = problem.forbidden_contacts([(a, b) for a, b, _ in world.check_collision([])])
    if not start:
        return None
    first, second = sorted(start)[0]
    return (f"the query's start has {first} touching {second}, which is forbidden (nothing "
            "but the ground may touch a fixed obstacle): every motion from it is invalid")


def goal_refusal(problem: PlanningProblem, world) -> Optional[str]:
    """One line when no motion can reach the query's goal region, else None (``world`` as
    ``query_refusal`` takes it):

    - the goal puts the tracked link's origin outside ``base_bounds`` (the problem's
      ``<Limits>``: every state outside them is invalid), or a joint outside its limits;
    - the goal puts a link of the robot more than BUILT_OVERLAP (1 mm) into a fixed obstacle
      (``forbidden``): the robot could get there only through the obstacle or by pushing it
      away, and nothing may touch it (the deepest pair named, with its depth)."""
    handle = problem.handle
    goal = handle.goal
    poses = handle.instance.model.link_poses(goal.base_pose, goal.joints)
    tracked = [b.body_id for b in handle.bodies].index(problem.tracked_body)
    position = poses[tracked][:3, 3]
    at = "(" + ", ".join(f"{v:.3f}" for v in position) + ") m"
    for axis, value, (low, high) in zip("xyz", position, problem.base_bounds):
        if not low <= value <= high:
            return (f"the query's goal puts {problem.tracked_body} at {at}, outside the "
                    f"problem's <Limits>: {axis} {value:.3f} not in [{low:g}, {high:g}] m")
    model = handle.instance.model
    for index, value in zip(model.movable_links(), goal.joints):
        link = model.links[index]
        if link.limits is not None and not \
                link.limits[0] - JOINT_SLACK <= value <= link.limits[1] + JOINT_SLACK:
            return (f"the query's goal puts joint {link.joint_name or link.name} at "
                    f"{value:.6g}, outside its limits [{link.limits[0]:.6g}, "
                    f"{link.limits[1]:.6g}]")
    robot = set(problem.robot_bodies)
    inside = []
    for first, second, depth in world.check_collision(
            handle.situations(goal.joints, goal.base_pose)):
        if _object(second) in robot:
            first, second = second, first
        if depth > BUILT_OVERLAP and _object(first) in robot and \
                _object(second) in problem.forbidden:
            inside.append((float(depth), first, second))
    if not inside:
        return None
    depth, first, second = max(inside)
    more = f" (and {len(inside) - 1} more pairs)" if len(inside) > 1 else ""
    return (f"the query's goal (where it puts {problem.tracked_body}: {at}) is inside a fixed "
            f"obstacle: there {first} is {depth * 1000:.1f} mm into {second}{more}, which "
            "nothing may touch, so no motion reaches the goal")


def check_query(problem: PlanningProblem, world) -> None:
    """PlanningError with ``query_refusal``'s line when the query cannot be solved."""
    why = query_refusal(problem, world)
    if why is not None:
        raise PlanningError(why)


JOINT_SLACK = 1e-9
"""rad or m: how far past a joint's limit a goal's value may lie and count as at the limit
(Kautham maps a control of 0 or 1 onto the limit itself, in floating point)."""


__all__ = ["SearchSettings", "PlanningProblem", "check_query", "goal_refusal",
           "planning_problem", "query_refusal", "start_refusal"]
