"""``rosrun GUI problem_info PROBLEM``: a Kautham problem described as Odin would build it,
JSON on stdout; never imports rospy.

Unless ``--no-checks``, the problem is also built in a VirtualWorld Core of this process
(``gui.planning.core_world``; about 0.5 s more for the TX90 flagship, 0.7 s instead of 0.2 s,
most of it trimesh's import and the meshes' masses) and its query checked with load_problem's rules
(``gui.core.overlaps``): the parts it builds inside each other, and per robot the pairs its
start and its goal put inside each other (robot with robot included), and the DOFs its start
or goal asks past their limits, which Kautham's controls clamp into them
(``ControlMap.past_limits``). Each is said in the JSON and in one warning line on stderr, the
collisions' lines those load_problem writes."""
from __future__ import annotations

import json
import logging
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING, Dict, List, Optional, Sequence

from gui.errors import GuiError
from gui.tools.common import (ProblemFile, ToolParser, add_build_options, count, fail,
                              one_line_errors, warnings_to_stderr)
from odin_common.errors import OdinError

if TYPE_CHECKING:
    from gui.core.overlaps import Overlap
    from gui.core.plan import BuildPlan, RobotHandle

TOOL = "problem_info"

MAX_INDENT = 16
"""problem_info --indent: the most spaces per level of the JSON (each level's lines carry them)."""

_LOG = logging.getLogger("gui.core.overlaps")
"""The checks' warnings: a logger under gui.core, which the tool prints as warning lines."""


@dataclass(frozen=True)
class InfoRequest:
    """What problem_info is asked: the problem, the JSON's indentation (0: compact), and
    whether the problem is built in a Core to check its query (``checks``)."""
    problem: ProblemFile
    indent: int = 1
    checks: bool = True


@dataclass(frozen=True)
class QueryChecks:
    """What building a plan in a Core of this process finds (module docstring): the pairs it
    builds inside each other (``overlaps``, gui.core.overlaps.Overlap, depth m) and whether
    the world exempts them (``exempt``), the pairs the goal adds (``goal``), and per robot
    name the pairs of its links where it starts and at the goal (``robots``: [(at, Overlap)],
    at "start" or "goal")."""
    overlaps: List["Overlap"]
    exempt: bool
    goal: List["Overlap"]
    robots: Dict[str, list]


def check_query(build_plan: BuildPlan) -> QueryChecks:
    """Builds ``build_plan`` in a Core of this process and checks its query (QueryChecks);
    the Core's refusal (OdinError) as it is. The plan's robots get the Core's joint and motor
    IDs (``BuildPlan.record_world_ids``), the IDs a world node answers too."""
    from gui.core.overlaps import goal_overlaps, start_overlaps
    from gui.planning.core_world import CoreWorld
    world = CoreWorld()
    try:
        answer = world.execute(build_plan)
        at_start = start_overlaps(world, build_plan)
        at_goal = goal_overlaps(world, build_plan, answer["overlaps"])
        owner = {name: handle.name for handle in build_plan.robots
                 for body in handle.bodies for name in world.core.geometry_names(body.body_id)}
    finally:
        world.close()
    robots: Dict[str, list] = {h.name: [] for h in build_plan.robots}
    for at, pairs in (("start", at_start), ("goal", at_goal)):
        for pair in pairs:
            for name in dict.fromkeys(owner.get(n) for n in pair[:2]):
                if name is not None:
                    robots[name].append((at, pair))
    return QueryChecks(answer["overlaps"], answer["overlaps_exempt"], at_goal, robots)


def _configuration(configuration) -> Optional[dict]:
    if configuration is None:
        return None
    from gui.core.kinematics import pose_to_position_quaternion
    position, quaternion = pose_to_position_quaternion(configuration.base_pose)
    return dict(controls=list(configuration.controls or ()), base_position=list(position),
                base_quaternion=list(quaternion),
                joints=[float(v) for v in configuration.joints])


def past_limits(handle: RobotHandle) -> list:
    """(at, gui.core.kautham.controls.PastLimit) for each DOF the robot's query asks past its
    limits, at "start" or "goal" (its controls clamp it into them, as Kautham's do)."""
    controls = handle.instance.controls
    out = []
    for at in ("start", "goal"):
        configuration = getattr(handle, at)
        if controls is None or configuration is None or configuration.controls is None:
            continue
        out.extend((at, past) for past in
                   controls.past_limits(handle.instance, configuration.controls))
    return out


def _overlap(overlap: Overlap) -> dict:
    return dict(first=overlap.first, second=overlap.second, depth=overlap.depth)


def _robot(handle: RobotHandle, checks: Optional[QueryChecks] = None) -> dict:
    controls = handle.instance.controls
    collisions = None if checks is None else [dict(at=at, **_overlap(o))
                                              for at, o in checks.robots[handle.name]]
    return dict(name=handle.name, kind=handle.kind, joints=handle.joint_keys,
                joint_names=handle.instance.model.joint_names(),
                home=[float(v) for v in handle.home],
                built_at=[float(v) for v in handle.built_at], motors=handle.motor_ids,
                controls=list(controls.names) if controls is not None else [],
                start=_configuration(handle.start), goal=_configuration(handle.goal),
                collisions=collisions,
                outside_limits=[dict(at=at, dof=p.dof, joint=p.joint, parameter=p.parameter,
                                     value=p.value,
                                     limits=list(p.limits) if p.limits is not None else None)
                                for at, p in past_limits(handle)])


def describe(build_plan: BuildPlan, checks: Optional[QueryChecks] = None) -> dict:
    """The JSON-ready description of a build plan: the world settings it sets, bodies where
    they are built and joints (world frame), robots with their start and goal, and what Odin
    does not use (``ignored``). Each robot's ``outside_limits``: the DOFs its query asks past
    their limits (``past_limits``: at, dof, joint, parameter, value rad / m, limits). From
    ``checks`` (None: not checked, each null): "overlaps" (pairs built inside each other:
    first, second, depth m), "overlaps_exempt", "goal_overlaps" (the pairs the goal adds), as
    load_problem's build answers them, and each robot's ``collisions`` (at, first, second,
    depth m; robot with robot listed under both)."""
    bodies, joints = [], []
    for step in build_plan.steps:
        description = step.describe()
        bodies.extend(description["bodies"])
        joints.extend(description["joints"])
    settings = build_plan.world
    world = dict(parameters={k: list(v) if isinstance(v, tuple) else v
                             for k, v in settings.parameters.items()},
                 step=settings.step, steps_per_cycle=settings.steps_per_cycle,
                 rate=settings.rate, own=list(settings.own))
    problem = build_plan.problem
    return dict(problem=problem.source, format=problem.format,
                planner=problem.planner.name if problem.planner else None,
                physics=build_plan.physics,
                units=dict(length="m", angle="rad", mass="kg", quaternion="w,x,y,z"),
                world=world, bodies=bodies, joints=joints,
                robots=[_robot(h, checks) for h in build_plan.robots
                        if h.instance.role == "robot"],
                attachments=[dict(robot=a.robot, link=a.link, obstacle=a.obstacle)
                             for a in problem.attachments],
                ignored=[i.describe() for i in build_plan.ignored],
                overlaps=None if checks is None else [_overlap(o) for o in checks.overlaps],
                overlaps_exempt=None if checks is None else checks.exempt,
                goal_overlaps=None if checks is None else [_overlap(o) for o in checks.goal])


def describe_problem(problem: ProblemFile, checks: bool = False) -> dict:
    """``describe`` of the problem's build plan, its query checked when ``checks``
    (``check_query``; what it finds is warned about, ``warn_checks``). A problem a world
    refuses to build is described unchecked, with a warning (load_problem refuses it)."""
    build_plan = problem.read()
    if not checks:
        return describe(build_plan)
    try:
        found = check_query(build_plan)
    except OdinError as error:
        _LOG.warning(f"{build_plan.problem.source}: start and goal not checked: a world "
                     f"refuses to build it: {' '.join(str(error).split())}")
        return describe(build_plan)
    warn_checks(build_plan, found)
    return describe(build_plan, found)


def warn_checks(build_plan: BuildPlan, checks: QueryChecks) -> None:
    """One warning line each for the parts built inside each other and those the goal puts
    inside each other (load_problem's lines), for pairs where a robot starts that the build
    did not find (a robot built elsewhere: ``--at-home``), and for the DOFs the start or the
    goal asks past their limits."""
    from gui.core.overlaps import goal_warning, overlap_warning, query_warning
    source = build_plan.problem.source
    if checks.overlaps:
        _LOG.warning(overlap_warning(source, checks.overlaps, checks.exempt))
    built = {frozenset((o.first, o.second)) for o in checks.overlaps}
    at_start = {(o.first, o.second): o for pairs in checks.robots.values()
                for at, o in pairs if at == "start" and frozenset(o[:2]) not in built}
    if at_start:
        _LOG.warning(query_warning(source, sorted(at_start.values(), key=lambda o: -o.depth),
                                   "start"))
    if checks.goal:
        _LOG.warning(goal_warning(source, checks.goal))
    for at in ("start", "goal"):
        said = [_past_limit(handle, past) for handle in build_plan.robots
                for when, past in past_limits(handle) if when == at]
        if said:
            _LOG.warning(f"{source}: the query's {at} asks {', '.join(said)}; Kautham's "
                         "controls clamp it to the limit, and so does Odin")


def _past_limit(handle: RobotHandle, past) -> str:
    """A DOF asked past its limits, for a warning line."""
    from gui.core.model import PRISMATIC
    if past.joint is None:
        return (f"the base's {past.dof} of {handle.name} at {past.parameter:.3g} of its range, "
                "outside [0, 1]")
    model = handle.instance.model
    kind = next(link.joint for link in model.links if link.name == past.dof)
    unit = "m" if kind == PRISMATIC else "rad"
    low, high = past.limits
    return (f"joint {past.joint} of {handle.name} for {past.value:.3g} {unit}, outside its "
            f"limits [{low:g}, {high:g}]")


def _parser() -> ToolParser:
    parser = ToolParser(
        prog=TOOL, description="Describe a Kautham problem as Odin would build it "
        "(JSON on stdout; no ROS needed).")
    parser.add_argument("problem", help="problem XML file")
    parser.add_argument("--indent", type=count(0, MAX_INDENT), default=1,
                        help="JSON indentation (0: compact)")
    parser.add_argument("--no-checks", dest="checks", action="store_false",
                        help="do not build the problem in a world of this process to check its "
                        "start and goal for collisions (about 0.5 s for the TX90 flagship); "
                        "their JSON keys are null")
    add_build_options(parser)
    return parser


@one_line_errors(TOOL)
def main(argv: Optional[Sequence[str]] = None) -> int:
    args = _parser().parse_args(argv)
    request = InfoRequest(ProblemFile.of_args(args), args.indent, args.checks)
    warnings_to_stderr(TOOL)
    try:
        description = describe_problem(request.problem, request.checks)
    except GuiError as error:
        return fail(TOOL, error)
    json.dump(description, sys.stdout, indent=request.indent or None)
    sys.stdout.write("\n")
    return 0


__all__ = ["MAX_INDENT", "InfoRequest", "QueryChecks", "check_query", "describe",
           "describe_problem", "main", "past_limits", "warn_checks"]
