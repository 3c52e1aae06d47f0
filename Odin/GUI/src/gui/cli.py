"""The GUI's headless tools: ``problem_info``, ``load_problem`` and ``run_path``.

Each ``*_main(argv)`` returns the exit status; errors end with status 2 and ONE line on stderr
saying what and where (file and line for parsed files). ``problem_info`` never imports rospy.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Optional, Sequence

from gui.errors import GuiError


def _fail(tool: str, error: Exception) -> int:
    text = " ".join(str(error).split())
    print(f"{tool}: error: {text}", file=sys.stderr)
    return 2


def describe(plan) -> dict:
    """The JSON-ready description of a plan: bodies at Home and joints (world frame)."""
    bodies, joints = [], []
    for step in plan.steps:
        description = step.describe()
        bodies.extend(description["bodies"])
        joints.extend(description["joints"])
    robots = [dict(name=h.name, joints=h.joint_keys, home=[float(v) for v in h.home],
                   motors=h.motor_ids) for h in plan.robots]
    return dict(problem=plan.problem.source, format=plan.problem.format,
                units=dict(length="m", angle="rad", mass="kg", quaternion="w,x,y,z"),
                bodies=bodies, joints=joints, robots=robots)


def problem_info_main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="problem_info", description="Describe a Kautham problem as Odin would build it "
        "(JSON on stdout; no ROS needed).")
    parser.add_argument("problem", help="problem XML file")
    parser.add_argument("--indent", type=int, default=1, help="JSON indentation (0: compact)")
    args = parser.parse_args(argv)
    from gui.core.build import plan_problem
    from gui.core.kautham.problem import load_problem
    try:
        plan = plan_problem(load_problem(args.problem))
    except GuiError as error:
        return _fail("problem_info", error)
    json.dump(describe(plan), sys.stdout, indent=args.indent or None)
    sys.stdout.write("\n")
    return 0


def load_problem_main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="load_problem", description="Build a Kautham problem in a running VirtualWorld.")
    parser.add_argument("problem", help="problem XML file")
    parser.add_argument("--keep", action="store_true",
                        help="add to the current scene instead of calling New Scene first")
    parser.add_argument("--timeout", type=float, default=10.0,
                        help="seconds to wait for the world's services")
    args = parser.parse_args(argv)
    from gui.core.build import plan_problem
    from gui.core.kautham.problem import load_problem
    started = time.monotonic()
    try:
        plan = plan_problem(load_problem(args.problem))
    except GuiError as error:
        return _fail("load_problem", error)
    total = len(plan.steps)
    print(f"loaded {args.problem} in {time.monotonic() - started:.2f} s: {total} requests",
          flush=True)
    try:
        from gui.ros.client import WorldClient
        client = WorldClient(timeout=args.timeout)
        if not args.keep:
            client.new_scene()

        def progress(k: int, step, answer_id: str) -> None:
            print(f"[{k}/{total}] {step.label()} -> {answer_id}", flush=True)

        client.execute(plan, progress=progress)
    except GuiError as error:
        return _fail("load_problem", error)
    print(f"built {args.problem} in {time.monotonic() - started:.2f} s", flush=True)
    return 0


def run_path_main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="run_path", description="Drive a robot built by load_problem with a path file.")
    parser.add_argument("problem", help="the problem XML file the scene was built from")
    kind = parser.add_mutually_exclusive_group(required=True)
    kind.add_argument("--initial", metavar="FILE", help="initial position (first row used)")
    kind.add_argument("--position", metavar="FILE", help="position path: one row per cycle")
    kind.add_argument("--velocity", metavar="FILE", help="velocity path: one row per cycle")
    units = parser.add_mutually_exclusive_group()
    units.add_argument("--degrees", action="store_true",
                       help="values in degrees (mm) [default for 2012 problems]")
    units.add_argument("--radians", action="store_true",
                       help="values in radians (m) [default for current problems]")
    parser.add_argument("--robot", help="robot name (default: the first robot)")
    parser.add_argument("--double", type=int, default=0, metavar="N",
                        help="double the path precision N times (position paths)")
    parser.add_argument("--rate", type=float, default=0.0,
                        help="rows per second (default: the world's publication rate)")
    parser.add_argument("--timeout", type=float, default=10.0)
    args = parser.parse_args(argv)
    from gui.core.build import plan_problem
    from gui.core.kautham.problem import load_problem
    from gui.core.paths import DEGREES, RADIANS, load_robot_path, refine
    try:
        plan = plan_problem(load_problem(args.problem))
        handles = [h for h in plan.robots if args.robot in (None, h.name)]
        if not handles:
            raise GuiError(f"no robot named {args.robot!r} in {args.problem} (robots: "
                           + ", ".join(h.name for h in plan.robots) + ")")
        handle = handles[0]
        unit = DEGREES if args.degrees else RADIANS if args.radians else (
            DEGREES if plan.problem.format == "2012" else RADIANS)
        file = args.initial or args.position or args.velocity
        rows = load_robot_path(file, handle, unit)
        if args.position and args.double:
            rows = refine(rows, args.double)
        from gui.ros.client import WorldClient, run_position_path, run_velocity_path
        client = WorldClient(timeout=args.timeout)
        if args.initial:
            client.set_position(handle.situations(rows[0]), reset_velocity=True)
            print(f"{handle.name}: initial position set ({len(handle.bodies)} bodies)")
            return 0
        rate = args.rate if args.rate > 0 else client.publication_rate()
        if args.position:
            run_position_path(client, handle, rows, rate,
                              progress=lambda k: print(f"[{k}/{len(rows)}]", flush=True))
        else:
            run_velocity_path(client, handle, rows, rate,
                              progress=lambda k: print(f"[{k}/{len(rows)}]", flush=True))
        print(f"{handle.name}: {len(rows)} rows at {rate:g} Hz done")
    except GuiError as error:
        return _fail("run_path", error)
    return 0
