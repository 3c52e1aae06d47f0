"""The GUI's headless tools: ``problem_info``, ``load_problem`` and ``run_path``.

Each ``*_main(argv)`` returns the exit status; errors end with status 2 and ONE line on stderr
saying what and where (file and line for parsed files). ``problem_info`` never imports rospy.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from typing import Optional, Sequence

import numpy as np

from gui.errors import GuiError
from gui.core.kinematics import pose_to_position_quaternion

_JOINT_NAMES = {1: "hinge", 2: "slider", 8: "fixed"}


def _fail(tool: str, error: Exception) -> int:
    text = " ".join(str(error).split())
    print(f"{tool}: error: {text}", file=sys.stderr)
    return 2


def describe(plan) -> dict:
    """The JSON-ready description of a plan: bodies at Home and joints (world frame)."""
    from gui.core.build import (CompositeRequest, EntityRequest, JointRequest, ObjectRequest)
    bodies, joints = [], []

    def body(req, entity: Optional[str]):
        if isinstance(req, ObjectRequest):
            kind = {1: "sphere", 2: "cylinder", 3: "box"}.get(len(req.parameters), "mesh")
            parameters = list(req.parameters) if kind != "mesh" else []
            bodies.append(dict(name=req.name, entity=entity, shape=kind,
                               position=list(req.position), quaternion=list(req.orientation),
                               triangles=req.triangle_count,
                               mass=None if req.geometry_only else req.mass,
                               static=req.geometry_only, parameters=parameters))
        else:
            bodies.append(dict(name=req.id, entity=entity, shape="composite",
                               position=list(req.position), quaternion=list(req.orientation),
                               triangles=req.triangle_count,
                               mass=None if req.geometry_only else req.mass,
                               static=req.geometry_only,
                               parts=[p.name for p in req.parts]))

    limits = {}
    for handle in plan.robots:
        model = handle.instance.model
        for key, i in zip(handle.joint_keys, model.movable_links()):
            limits[key] = model.links[i].limits
    for step in plan.steps:
        if isinstance(step, EntityRequest):
            for req in step.objects + step.composites:
                body(req, step.name)
        elif isinstance(step, (ObjectRequest, CompositeRequest)):
            body(step, None)
        elif isinstance(step, JointRequest):
            lim = limits.get(step.key)
            joints.append(dict(name=step.key, type=_JOINT_NAMES.get(step.type, str(step.type)),
                               parent=step.body1 or None, child=step.body2,
                               anchor=list(step.anchor), axis=_kinematic_axis(step),
                               limits=None if lim is None else [lim[0], lim[1]]))
    robots = [dict(name=h.name, joints=h.joint_keys, home=[float(v) for v in h.home],
                   motors=h.motor_ids) for h in plan.robots]
    return dict(problem=plan.problem.source, format=plan.problem.format,
                units=dict(length="m", angle="rad", mass="kg", quaternion="w,x,y,z"),
                bodies=bodies, joints=joints, robots=robots)


def _kinematic_axis(step) -> list:
    """The joint's axis as the robot model states it (Kautham's sign): a robot's hinges and
    sliders are sent to the world with the axis reversed (see gui.core.build)."""
    from gui.core.build import JOINT_HINGE, JOINT_SLIDER
    if step.type in (JOINT_HINGE, JOINT_SLIDER) and step.body1:
        return [-v for v in step.axis1]
    return list(step.axis1)


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


def _step_label(step) -> str:
    from gui.core.build import (CompositeRequest, EntityRequest, JointRequest, MotorRequest,
                           ObjectRequest)
    if isinstance(step, EntityRequest):
        members = step.objects + step.composites
        tris = sum(m.triangle_count for m in members)
        return f"entity {step.name}: {len(members)} bodies, {tris} triangles"
    if isinstance(step, ObjectRequest):
        return f"object {step.name} ({step.triangle_count} triangles)"
    if isinstance(step, CompositeRequest):
        return f"composite {step.id} ({len(step.parts)} parts)"
    if isinstance(step, JointRequest):
        return f"joint {step.key} ({_JOINT_NAMES.get(step.type, step.type)})"
    if isinstance(step, MotorRequest):
        return f"motor on {step.joint_key}"
    return type(step).__name__


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
            print(f"[{k}/{total}] {_step_label(step)} -> {answer_id}", flush=True)

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
