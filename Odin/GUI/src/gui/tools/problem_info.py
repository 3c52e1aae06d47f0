"""``rosrun GUI problem_info PROBLEM``: a Kautham problem described as Odin would build it,
JSON on stdout; never imports rospy."""
from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING, Optional, Sequence

from gui.errors import GuiError
from gui.tools.common import (ProblemFile, ToolParser, add_build_options, count, fail,
                              one_line_errors, warnings_to_stderr)

if TYPE_CHECKING:
    from gui.core.plan import BuildPlan, RobotHandle

TOOL = "problem_info"

MAX_INDENT = 16
"""problem_info --indent: the most spaces per level of the JSON (each level's lines carry them)."""


@dataclass(frozen=True)
class InfoRequest:
    """What problem_info is asked: the problem, and the JSON's indentation (0: compact)."""
    problem: ProblemFile
    indent: int = 1


def _configuration(configuration) -> Optional[dict]:
    if configuration is None:
        return None
    from gui.core.kinematics import pose_to_position_quaternion
    position, quaternion = pose_to_position_quaternion(configuration.base_pose)
    return dict(controls=list(configuration.controls or ()), base_position=list(position),
                base_quaternion=list(quaternion),
                joints=[float(v) for v in configuration.joints])


def _robot(handle: RobotHandle) -> dict:
    controls = handle.instance.controls
    return dict(name=handle.name, kind=handle.kind, joints=handle.joint_keys,
                joint_names=handle.instance.model.joint_names(),
                home=[float(v) for v in handle.home],
                built_at=[float(v) for v in handle.built_at], motors=handle.motor_ids,
                controls=list(controls.names) if controls is not None else [],
                start=_configuration(handle.start), goal=_configuration(handle.goal))


def describe(build_plan: BuildPlan) -> dict:
    """The JSON-ready description of a build plan: the world settings it sets, bodies where
    they are built and joints (world frame), robots with their start and goal, and what Odin
    does not use (``ignored``)."""
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
                robots=[_robot(h) for h in build_plan.robots if h.instance.role == "robot"],
                attachments=[dict(robot=a.robot, link=a.link, obstacle=a.obstacle)
                             for a in problem.attachments],
                ignored=[i.describe() for i in build_plan.ignored])


def describe_problem(problem: ProblemFile) -> dict:
    """``describe`` of the problem's build plan."""
    return describe(problem.read())


def _parser() -> ToolParser:
    parser = ToolParser(
        prog=TOOL, description="Describe a Kautham problem as Odin would build it "
        "(JSON on stdout; no ROS needed).")
    parser.add_argument("problem", help="problem XML file")
    parser.add_argument("--indent", type=count(0, MAX_INDENT), default=1,
                        help="JSON indentation (0: compact)")
    add_build_options(parser)
    return parser


@one_line_errors(TOOL)
def main(argv: Optional[Sequence[str]] = None) -> int:
    args = _parser().parse_args(argv)
    request = InfoRequest(ProblemFile.of_args(args), args.indent)
    warnings_to_stderr(TOOL)
    try:
        description = describe_problem(request.problem)
    except GuiError as error:
        return fail(TOOL, error)
    json.dump(description, sys.stdout, indent=request.indent or None)
    sys.stdout.write("\n")
    return 0


__all__ = ["MAX_INDENT", "InfoRequest", "describe", "describe_problem", "main"]
