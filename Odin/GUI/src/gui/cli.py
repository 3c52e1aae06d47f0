"""The GUI's headless tools: ``problem_info``, ``load_problem``, ``run_path`` and ``plan``.

Each ``*_main(argv)`` returns the exit status; errors end with status 2 and ONE line on stderr
saying what and where (file and line for parsed files). ``problem_info`` never imports rospy.
What a problem holds that Odin does not use is warned about on stderr, once each
("<tool>: warning: ..."), and listed by ``problem_info`` under ``ignored``.
"""
from __future__ import annotations

import argparse
import atexit
import json
import logging
import os
import sys
import threading
import time
from typing import Callable, Optional, Sequence

import numpy as np

from gui.cli_boundary import (ToolParser, count, fail, hertz, one_line_errors, reading,
                              seconds)
from gui.errors import GuiError, PlanningError
from odin_common.errors import OdinError
from odin_common.tool import stop_on_ctrl_c


def without_teardown(main: Callable[[], Optional[int]]) -> Callable[[], int]:
    """``main`` for a tool's process that ends with it: once ``main`` has returned, stdout and
    stderr are flushed, the exit handlers run (rospy leaves the ROS graph, logging flushes
    its files) and the process ends with ``main``'s status, without the interpreter's
    teardown, which frees every object one at a time: 0.45 s after load_problem (a problem's
    meshes, rospy's and numpy's modules), where the system frees the memory at once. An
    exception (a closed pipe, Ctrl-C) leaves as usual, for odin_common.tool.run."""
    def ended() -> int:
        status = main() or 0
        sys.stdout.flush()
        sys.stderr.flush()
        atexit._run_exitfuncs()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    return ended


MAX_INDENT = 16
"""problem_info --indent: the most spaces per level of the JSON (each level's lines carry them)."""


def _check_output(option: str, path: Optional[str]) -> None:
    """Before any work: the folder ``path`` is to be written in exists and is writable."""
    if path is None:
        return
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise GuiError(f"{option} {path}: no folder {folder}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise GuiError(f"{option} {path}: folder {folder} is not writable")
    if os.path.isdir(path):
        raise GuiError(f"{option} {path}: is a folder, not a file")


def _check_master(tool: str, timeout: float) -> None:
    """Before any work: a ROS master answers at ROS_MASTER_URI within ``timeout`` s (rospy
    would wait for one for ever, saying "Will keep trying")."""
    from odin_common.node import wait_for_master
    wait_for_master(f"/{tool}", timeout=timeout, quiet=True)


def _warnings_to_stderr(tool: str) -> None:
    """The loader's warnings (what Odin does not use) as "<tool>: warning: ..." lines."""
    logger = logging.getLogger("gui.core")
    if not any(getattr(h, "odin_tool", None) == tool for h in logger.handlers):
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter(f"{tool}: warning: %(message)s"))
        handler.odin_tool = tool
        logger.addHandler(handler)
        logger.propagate = False


def _configuration(configuration) -> Optional[dict]:
    if configuration is None:
        return None
    from gui.core.kinematics import pose_to_position_quaternion
    position, quaternion = pose_to_position_quaternion(configuration.base_pose)
    return dict(controls=list(configuration.controls or ()), base_position=list(position),
                base_quaternion=list(quaternion),
                joints=[float(v) for v in configuration.joints])


def _robot(handle) -> dict:
    controls = handle.instance.controls
    return dict(name=handle.name, kind=handle.kind, joints=handle.joint_keys,
                joint_names=handle.instance.model.joint_names(),
                home=[float(v) for v in handle.home],
                built_at=[float(v) for v in handle.built_at], motors=handle.motor_ids,
                controls=list(controls.names) if controls is not None else [],
                start=_configuration(handle.start), goal=_configuration(handle.goal))


def describe(plan) -> dict:
    """The JSON-ready description of a plan: the world settings it sets, bodies where they
    are built and joints (world frame), robots with their start and goal, and what Odin does
    not use (``ignored``)."""
    bodies, joints = [], []
    for step in plan.steps:
        description = step.describe()
        bodies.extend(description["bodies"])
        joints.extend(description["joints"])
    world = dict(parameters={k: list(v) if isinstance(v, tuple) else v
                             for k, v in plan.world.parameters.items()},
                 step=plan.world.step, steps_per_cycle=plan.world.steps_per_cycle,
                 rate=plan.world.rate, own=list(plan.world.own))
    problem = plan.problem
    return dict(problem=problem.source, format=problem.format,
                planner=problem.planner.name if problem.planner else None,
                physics=plan.physics,
                units=dict(length="m", angle="rad", mass="kg", quaternion="w,x,y,z"),
                world=world, bodies=bodies, joints=joints,
                robots=[_robot(h) for h in plan.robots if h.instance.role == "robot"],
                attachments=[dict(robot=a.robot, link=a.link, obstacle=a.obstacle)
                             for a in problem.attachments],
                ignored=[i.describe() for i in plan.ignored])


def _build_options(parser: argparse.ArgumentParser) -> None:
    """The options that change how a problem is built (gui.core.translate.BuildDefaults)."""
    ground = parser.add_mutually_exclusive_group()
    ground.add_argument("--physics", dest="ground", action="store_const", const=True,
                        help="Kautham's ODE physics (world settings, a ground plane) for any "
                        "problem [default: for problems with an ODE planner]")
    ground.add_argument("--no-physics", dest="ground", action="store_const", const=False,
                        help="no ground plane, Odin's default world settings")
    start = parser.add_mutually_exclusive_group()
    start.add_argument("--at-home", dest="start_at_query", action="store_const", const=False,
                       help="build robots at Home (as the thesis's tool built 2012 problems)")
    start.add_argument("--at-start", dest="start_at_query", action="store_const", const=True,
                       help="build robots at the query's start, where Kautham leaves a problem it "
                       "loads [default; Home when the problem has no query]")
    parser.add_argument("--inertia", choices=("auto", "file", "shape"), default="auto",
                        help="links' inertia: the file's where plausible (auto), always the "
                        "file's, or the shape's")
    parser.add_argument("--no-cache", action="store_true",
                        help="read every geometry file, bypassing the cache of shapes read "
                        "before (~/.cache/odin/shapes, gui.core.shape_cache)")


def _plan(args):
    from gui.core import shape_cache
    from gui.core.translate import BuildDefaults, plan_problem
    from gui.core.kautham.problem import load_problem
    if args.no_cache:
        shape_cache.set_enabled(False)
    defaults = BuildDefaults(ground=args.ground, start_at_query=args.start_at_query,
                             inertia=args.inertia)
    with reading("problem", args.problem):
        return plan_problem(load_problem(args.problem), defaults)


@one_line_errors("problem_info")
def problem_info_main(argv: Optional[Sequence[str]] = None) -> int:
    parser = ToolParser(
        prog="problem_info", description="Describe a Kautham problem as Odin would build it "
        "(JSON on stdout; no ROS needed).")
    parser.add_argument("problem", help="problem XML file")
    parser.add_argument("--indent", type=count(0, MAX_INDENT), default=1,
                        help="JSON indentation (0: compact)")
    _build_options(parser)
    args = parser.parse_args(argv)
    _warnings_to_stderr("problem_info")
    try:
        plan = _plan(args)
    except GuiError as error:
        return fail("problem_info", error)
    json.dump(describe(plan), sys.stdout, indent=args.indent or None)
    sys.stdout.write("\n")
    return 0


class _WorldConnection:
    """A WorldClient made on a thread of its own, started before the problem is read: joining
    the ROS graph and finding the world (~0.25 s, mostly waiting on the master) then overlaps
    reading and planning the problem (~0.5 s) instead of following it."""

    def __init__(self, timeout: float):
        # imported here, not on the thread (the service classes too, which WorldClient
        # imports when made): two threads importing modules at once can deadlock on their locks
        import Services.srv  # noqa: F401
        from gui.ros.client import WorldClient
        self._client = None
        self._error: Optional[BaseException] = None
        self._thread = threading.Thread(target=self._connect, args=(WorldClient, timeout),
                                        name="connect to the world", daemon=True)
        self._thread.start()

    def _connect(self, world_client, timeout: float) -> None:
        try:
            self._client = world_client(timeout=timeout)
        except BaseException as error:  # handed to the main thread by client()
            self._error = error

    def client(self):
        """The connected WorldClient; raises what connecting raised (WorldError when no
        world answers within the timeout)."""
        self._thread.join()
        if self._error is not None:
            raise self._error
        return self._client


@one_line_errors("load_problem")
def load_problem_main(argv: Optional[Sequence[str]] = None) -> int:
    parser = ToolParser(
        prog="load_problem", description="Build a Kautham problem in a running VirtualWorld.")
    parser.add_argument("problem", help="problem XML file")
    parser.add_argument("--keep", action="store_true",
                        help="add to the current scene instead of calling New Scene first "
                        "(the problem is first built alone, in the room the world has left, "
                        "in this process; a clash with what the world holds is refused by "
                        "the world, and what was built of the problem removed)")
    parser.add_argument("--timeout", type=seconds, default=10.0,
                        help="seconds to wait for the ROS master, then for the world's "
                        "services [10]")
    _build_options(parser)
    args = parser.parse_args(argv)
    _warnings_to_stderr("load_problem")
    started = time.monotonic()
    try:
        _check_master("load_problem", args.timeout)
        connection = _WorldConnection(args.timeout)
        plan = _plan(args)
    except OdinError as error:
        return fail("load_problem", error)
    total = len(plan.steps)
    print(f"loaded {args.problem} in {time.monotonic() - started:.2f} s: {total} requests",
          flush=True)
    try:
        from gui.planning.rehearsal import load_scene, warm_up
        from gui.planning.rehearsal_cache import plan_digest, seen
        plan_key = plan_digest(plan)
        if not seen(plan_key):  # a rehearsal to come: its imports while the world is found
            warm_up()           # (the connecting thread imports nothing)
        client = connection.client()

        def progress(k: int, step, answer_id: str) -> None:
            print(f"[{k}/{total}] {step.label()} -> {answer_id}", flush=True)

        load_scene(client, plan, keep=args.keep, progress=progress, plan_key=plan_key)
    except OdinError as error:
        return fail("load_problem", error)
    print(f"built {args.problem} in {time.monotonic() - started:.2f} s; the world is paused "
          f"at its start (rosservice call {client.namespace}/start \"simulate: true\" runs "
          f"it)", flush=True)
    return 0


@one_line_errors("run_path")
def run_path_main(argv: Optional[Sequence[str]] = None) -> int:
    parser = ToolParser(
        prog="run_path", description="Drive a robot built by load_problem with a path file.")
    parser.add_argument("problem", help="the problem XML file the scene was built from")
    kind = parser.add_mutually_exclusive_group(required=True)
    kind.add_argument("--initial", metavar="FILE", help="initial position (first row used)")
    kind.add_argument("--position", metavar="FILE", help="position path: one row per cycle")
    kind.add_argument("--velocity", metavar="FILE", help="velocity path: one row per cycle")
    kind.add_argument("--controls", metavar="FILE", help="control path: rows of the robot's "
                      "Kautham controls in [0, 1] and a duration (s), applied as Kautham's "
                      "ODE environment does (docs/INTERFACE.md); prints the distance to the "
                      "goal as plan measures it")
    kind.add_argument("--tracked", metavar="FILE", help="a Kautham plan (.kps solution, task "
                      "file, OMPL rows or raw rows), timed within the joints' limits and "
                      "followed by the joint servos under full physics (docs/INTERFACE.md)")
    parser.add_argument("--from-here", action="store_true",
                        help="tracked: a robot away from the path's first sample (a .kps "
                        "query's Init) is first moved there, a segment of the summary [it is "
                        "refused]")
    parser.add_argument("--summary", metavar="OUT.json", help="tracked: write the execution's "
                        "summary (goal and tracking errors, collisions, per-joint series, "
                        "segments)")
    parser.add_argument("--plot", metavar="OUT.png", help="tracked: plot target against "
                        "actual per joint")
    parser.add_argument("--solver", choices=["auto", "quickstep", "worldstep"],
                        help="tracked: set the world's solver first (Set World; it stays set "
                        "until the next problem load, which sets every world parameter). The "
                        "summary and the last line name the solver in force: AUTO (the "
                        "world's default) steps small articulated scenes exactly (dWorldStep) "
                        "and large ones with QuickStep, which alone can let a chain shake near "
                        "its goal where WORLDSTEP, the exact solver, reaches it")
    parser.add_argument("--kinematic", action="store_true",
                        help="tracked: the path's robots under the kinematic drive first (Set "
                        "Servo drive KINEMATIC on every joint's motor; it stays set): the links "
                        "follow the servos' law exactly and push what they meet, no force "
                        "limit (docs/INTERFACE.md, \"Kinematic drive\")")
    units = parser.add_mutually_exclusive_group()
    units.add_argument("--degrees", action="store_true",
                       help="values in degrees (mm) [default for 2012 problems]")
    units.add_argument("--radians", action="store_true",
                       help="values in radians (m) [default for current problems]")
    parser.add_argument("--robot", help="robot name (default: the first robot)")
    parser.add_argument("--double", type=count(0, MAX_DOUBLINGS), default=0, metavar="N",
                        help="double the path precision N times (position paths)")
    parser.add_argument("--rate", type=hertz, default=0.0,
                        help="rows per second (default: the world's publication rate)")
    parser.add_argument("--fast", action="store_true",
                        help="control and tracked paths: as fast as the world steps, not in "
                        "real time")
    parser.add_argument("--timeout", type=seconds, default=10.0,
                        help="seconds to wait for the ROS master, then for the world's "
                        "services [10]")
    _build_options(parser)
    args = parser.parse_args(argv)
    _warnings_to_stderr("run_path")
    from gui.core.paths import DEGREES, RADIANS, load_robot_path, refine
    try:
        _check_output("--summary", args.summary)
        _check_output("--plot", args.plot)
        _check_master("run_path", args.timeout)
        plan = _plan(args)
        try:
            handle = plan.robot(args.robot)
        except KeyError as error:
            raise GuiError(f"{args.problem}: {error.args[0]}") from None
        if args.controls:
            return _run_controls(args, plan, handle)
        if args.tracked:
            return _run_tracked(args, plan)
        unit = DEGREES if args.degrees else RADIANS if args.radians else (
            DEGREES if plan.problem.format == "2012" else RADIANS)
        file = args.initial or args.position or args.velocity
        with reading("path file", file):
            rows = load_robot_path(file, handle, unit)
        if args.position and args.double:
            rows = refine(rows, _doublings(args.double, len(rows)))
        from gui.ros.client import WorldClient, run_position_path, run_velocity_path
        client = WorldClient(timeout=args.timeout)
        if args.initial:
            client.set_position(handle.situations(rows[0]), reset_velocity=True)
            print(f"{handle.name}: initial position set ({len(handle.bodies)} bodies)")
            return 0
        rate = args.rate if args.rate > 0 else client.publication_rate()
        done = [0]
        with stop_on_ctrl_c() as stop:

            def progress(k: int) -> None:
                done[0] = k
                print(f"[{k}/{len(rows)}]", flush=True)
                if stop:                    # between two calls: none is cut in the middle
                    raise _Stopped

            try:
                if args.position:
                    run_position_path(client, handle, rows, rate, progress=progress)
                else:
                    run_velocity_path(client, handle, rows, rate, progress=progress)
            except _Stopped:
                pass
            if stop:
                if args.velocity:           # the last row's speeds would drive on
                    client.set_velocities(handle.motor_ids, np.zeros(len(handle.motor_ids)))
                return _interrupted(f"row {done[0]} of {len(rows)} ({done[0] / rate:.2f} s "
                                    f"of {len(rows) / rate:.2f} s)")
        print(f"{handle.name}: {len(rows)} rows at {rate:g} Hz done")
    except OdinError as error:
        return fail("run_path", error)
    return 0


MAX_DOUBLINGS = 20
"""run_path --double N: the most doublings of a path's precision asked (each doubles its rows)."""

MAX_PATH_ROWS = 1_000_000
"""Rows of a path after --double: 11 hours at 25 rows per second (memory grows with them)."""


def _doublings(times: int, rows: int) -> int:
    """``times`` if a path of ``rows`` rows doubled that many times has at most
    MAX_PATH_ROWS rows, else GuiError."""
    if rows * 2 ** times > MAX_PATH_ROWS:
        raise GuiError(f"--double {times}: {rows:,} rows would become {rows * 2 ** times:,}, "
                       f"more than {MAX_PATH_ROWS:,} (MAX_PATH_ROWS)")
    return times


class _Stopped(Exception):
    """Raised between two rows of a path when Ctrl-C asked to stop."""


def _interrupted(where: str) -> int:
    """run_path stopped by Ctrl-C, the robot held: says how far it got; 130 (128 + SIGINT)."""
    from odin_common.tool import EXIT_INTERRUPTED
    print(f"run_path: interrupted at {where}; the robot is held there", flush=True)
    return EXIT_INTERRUPTED


def _run_tracked(args, plan) -> int:
    """run_path --tracked: the plan read and checked whole, then executed in the running world
    (paused meanwhile); one line per simulated second, then the figures."""
    from gui.ros.world_port import run_tracked_on_client
    from gui.core.kautham.solutions import read_solution
    from gui.core.paths import DEGREES, RADIANS
    units = DEGREES if args.degrees else RADIANS if args.radians else None
    with reading("plan", args.tracked):
        solution = read_solution(args.tracked, plan.problem, args.robot, units)
    from gui.ros.client import WorldClient
    from odin_common.interface import Solver
    client = WorldClient(timeout=args.timeout)
    _record_world_ids(client, plan)
    _check_start(client, plan, solution, args.from_here)       # before --solver changes a thing
    if args.solver:
        client.set_world(solver=Solver[args.solver.upper()])
    if args.kinematic:
        from odin_common.interface import ServoDrive
        for handle in plan.robots:
            if handle.name in solution.paths:
                client.set_drive(handle.motor_ids, ServoDrive.KINEMATIC)
    solver = Solver(client.world_parameters().solver).name.lower()
    shown = [0]

    def progress(t: float, total: float) -> None:
        if t >= shown[0] + 1.0 or t >= total - 1e-9:
            shown[0] = int(t)
            print(f"t={t:.2f}/{total:.2f} s", flush=True)

    reached = [0.0, 0.0]

    def progress_of(t: float, total: float) -> None:
        reached[:] = [t, total]
        progress(t, total)

    with stop_on_ctrl_c() as stop:
        report = run_tracked_on_client(client, plan, solution, progress=progress_of,
                                       real_time=not args.fast, stop=stop,
                                       from_here=args.from_here)
    if stop:
        return _interrupted(f"t={reached[0]:.2f} s of {reached[1]:.2f} s")
    query = f" from {solution.query.describe()}" if solution.query is not None else ""
    print(f"{solution.format} path of {solution.waypoint_count} waypoints{query}"
          f"{report.start_move()}: goal error {report.goal_error:.3g}, tracking error max "
          f"{report.tracking_error_max:.3g}, {report.duration_s:.2f} s simulated, "
          f"{len(report.collisions)} colliding pairs, solver {solver}")
    if args.summary:
        with open(args.summary, "w") as out:
            json.dump(dict(report.to_json(), solver=solver), out, indent=1)
    if args.plot:
        _save_plot(report, args.plot)
    return 0


def _check_start(client, plan, solution, from_here: bool) -> None:
    """Unless ``from_here``: the robots are where the path starts (``gui.core.execution``'s
    rule), else one line saying how far they are and what would move them there."""
    from gui.core.execution import AwayFromStart, plan_tracking
    from gui.ros.world_port import ClientWorldPort
    try:
        plan_tracking(ClientWorldPort(client), plan, solution, from_here=from_here)
    except AwayFromStart as error:
        raise GuiError(f"{error}; --from-here to move it there first") from None


def _record_world_ids(client, plan) -> None:
    """The world's body, joint and motor IDs for the plan's robots: the ones it holds that the
    plan predicts (the scene was built by load_problem, whose answers are not at hand here)."""
    inventory = client.world()
    held = set(inventory.objects) | set(inventory.joints) | set(inventory.motors)
    for handle in plan.robots:
        missing = [i for i in [b.body_id for b in handle.bodies] + list(handle.joint_ids)
                   + list(handle.motor_ids) if i not in held]
        if missing:
            raise GuiError(f"the world holds no {missing[0]!r} of robot {handle.name}: build "
                           f"the problem first (rosrun GUI load_problem {plan.problem.source})")


def _save_plot(report, path: str) -> None:
    import os
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from PyQt5.QtGui import QGuiApplication
    from gui.window.tracking_plot import save_png
    application = QGuiApplication.instance() or QGuiApplication(["run_path"])
    save_png(report, path)
    del application


def _run_controls(args, plan, handle) -> int:
    """run_path --controls: the control path through Propagate (the world paused meanwhile);
    one line per row: its time, where the link the planner tracks is and, for a problem with
    a query, its distance to the goal in the planner's metric (``_goal_meter``): the figure
    ``plan`` printed for the same path."""
    from gui.core.control_path import control_size, read_control_path
    from gui.ros.world_port import run_on_client
    with reading("control path", args.controls):
        rows = read_control_path(args.controls, control_size(handle))
    meter = _goal_meter(plan, handle)
    from gui.ros.client import WorldClient
    client = WorldClient(timeout=args.timeout)
    _record_world_ids(client, plan)
    watched = handle.bodies[0].body_id if meter is None else meter.tracked_body
    elapsed, distance = [0.0], [None]

    def progress(result):
        elapsed[0] += result.actuation.duration
        position, quaternion = result.watched[0], result.watched[1]
        where = np.round(position, 3).tolist()
        to_goal = ""
        if meter is not None:
            distance[0] = meter.body_goal_distance(position, quaternion)
            to_goal = f", {distance[0]:.4f} m from the goal"
        print(f"[{result.index}/{len(rows)}] t={elapsed[0]:.3f} s {watched} at {where}"
              f"{to_goal}", flush=True)

    with stop_on_ctrl_c() as stop:
        results = run_on_client(client, handle, rows, real_time=not args.fast,
                                progress=progress, stop=stop, watch=watched)
    if stop:
        total = sum(row.duration for row in rows)
        return _interrupted(f"row {len(results)} of {len(rows)} ({elapsed[0]:.2f} s of "
                            f"{total:.2f} s)")
    ends = "" if distance[0] is None else f", ends {distance[0]:.4f} m from the goal"
    print(f"{handle.name}: {len(rows)} control rows done ({elapsed[0]:.3f} s simulated)"
          f"{ends}")
    return 0


def _goal_meter(plan, handle):
    """The planning problem whose metric ``plan`` reports (``PlanningProblem.goal_distance``:
    the tracked link, in the plane), or None, said on stderr, when the problem has no query
    or the planner cannot take it (then only where the base is is printed)."""
    if handle.goal is None:
        return None
    from gui.planning.problem import planning_problem
    try:
        return planning_problem(plan, handle.name)
    except PlanningError as error:
        print(f"run_path: note: no distance to the goal: {error}", file=sys.stderr)
        return None


# ------------------------------------------------------------------------------ plan (issue 17)

@one_line_errors("plan")
def plan_main(argv: Optional[Sequence[str]] = None) -> int:
    """``rosrun GUI plan PROBLEM --planner NAME --time S --out PATH``: plans the problem's
    query with one of OMPL's control planners through Odin's physics (gui.planning), writes
    the solution as a Kautham control path (``run_path --controls`` runs it), prints the
    search's statistics as JSON; exits 1 with one line when no solution was found in time,
    2 on bad input."""
    from gui.planning.bridge import MAX_SEED, PLANNERS
    from gui.planning.parallel import MAX_SEARCHES
    from gui.planning.problem import MAX_CONTROL_STEPS
    parser = ToolParser(
        prog="plan", description="Plan a Kautham physics problem's query with an OMPL control "
        "planner through Odin's world; write the solution as a control path.")
    parser.add_argument("problem", help="the problem XML file")
    parser.add_argument("--planner", default="KPIECE1",
                        help=f"OMPL control planner: {', '.join(PLANNERS)} [KPIECE1]")
    parser.add_argument("--time", type=seconds, default=None, metavar="S",
                        help="wall-clock seconds the planner may search [the problem's "
                        "\"_Max Planning Time\", else 10]")
    parser.add_argument("--out", required=True, metavar="PATH",
                        help="control path file to write (rows: controls, duration s)")
    parser.add_argument("--seed", type=count(1, MAX_SEED), default=None,
                        help="OMPL's random seed [drawn at random, printed and written with "
                        "the path: --seed repeats a run]")
    parser.add_argument("--backend", choices=("core", "pool"), default="core",
                        help="core: the world in this process [default]; pool: the world "
                        "nodes of --worlds over ROS (cleared and built from the problem)")
    parser.add_argument("--worlds", default="/virtual_world", metavar="NS[,NS...]",
                        help="--backend pool: the world nodes' namespaces [/virtual_world]")
    parser.add_argument("--world-timeout", type=seconds, default=30.0, metavar="S",
                        help="--backend pool: how long to wait for each world [30]")
    parser.add_argument("--robot", help="robot name (default: the first robot)")
    parser.add_argument("--goal-tolerance", type=float, default=None, metavar="M",
                        help="goal region radius in the plane, m [0.25]")
    parser.add_argument("--min-control-steps", type=count(1, MAX_CONTROL_STEPS),
                        default=None, metavar="N",
                        help="a control is held at least N propagation steps [the problem's "
                        "\"Min Control Steps\", else 2]")
    parser.add_argument("--max-control-steps", type=count(1, MAX_CONTROL_STEPS),
                        default=None, metavar="N",
                        help="and at most N [the problem's \"Max Control Steps\", else 30]")
    parser.add_argument("--parallel", type=count(1, MAX_SEARCHES), default=1, metavar="N",
                        help="N independent searches at once, seeds SEED..SEED+N-1, each in a "
                        "process with a back end of its own (pool: its share of --worlds); "
                        "the first solution wins [1]")
    _build_options(parser)
    args = parser.parse_args(argv)
    _warnings_to_stderr("plan")
    try:
        _check_output("--out", args.out)
        with stop_on_ctrl_c() as stop:
            result, time_limit, seed = _search(args, stop)
        if not result.solved:
            return fail("plan", GuiError(
                f"{args.problem}: no solution within {time_limit:g} s ({args.planner}, seed "
                f"{seed}{_searches(args)}): the closest plan ends {result.goal_distance:.3f} m "
                "from the goal")) - 1
        from gui.core.control_path import write_control_path
        write_control_path(args.out, result.rows, comments=(
            f"control path planned by rosrun GUI plan {args.problem}",
            f"planner {args.planner}, seed {result.seed}, {result.time_s:.2f} s, "
            f"ends {result.goal_distance:.4f} m from the goal",
            "each row: the robot's controls in [0, 1], then the duration (s)"))
        print(f"plan: {len(result.rows)} rows ({result.duration:.3f} s) written to {args.out}")
    except (OdinError, OSError) as error:
        return fail("plan", error)
    return 0


def _searches(args) -> str:
    return f" and the next {args.parallel - 1}" if args.parallel > 1 else ""


def _search(args, stop):
    """(the plan's result, the time limit s, the (first) seed); says what it searches, with
    the seed, then prints the statistics. ``stop()`` true (Ctrl-C) ends the search and
    raises KeyboardInterrupt, nothing written."""
    from gui.planning.bridge import plan
    make_backend, time_limit = _planning_backends(args)
    seed = args.seed if args.seed is not None else _fresh_seed(args.parallel)
    searching = (f"plan: {args.planner} searching for up to {time_limit:g} s, seed {seed}"
                 f"{_searches(args)} (--seed {seed} repeats it)")
    if args.parallel == 1:
        backend = make_backend(0)
        print(searching, flush=True)        # once the world is built: the search starts now
        try:
            result = plan(backend, args.planner, time_limit, seed, stop)
        finally:
            backend.close()
        print(json.dumps(result.statistics(), indent=1), flush=True)
        return result, time_limit, seed
    from gui.planning.parallel import plan_in_parallel
    print(searching, flush=True)
    result, outcomes = plan_in_parallel(make_backend, args.parallel, args.planner,
                                        time_limit, seed, stop)
    print(json.dumps({**result.statistics(), "searches": [o.summary() for o in outcomes]},
                     indent=1), flush=True)
    return result, time_limit, seed


def _fresh_seed(searches: int) -> int:
    """A seed for OMPL from the system's entropy, in [1, 2^31) (room for ``searches``)."""
    return 1 + int.from_bytes(os.urandom(4), "little") % (2 ** 31 - 1 - searches)


def _planning_backends(args):
    """(make_backend(k): the back end of search k of ``args.parallel``, the search's time
    limit s). Every search's back end holds the problem's world: the Core builds one in the
    process calling it; with the pool, search k gets every ``args.parallel``-th world of
    ``--worlds`` from the k-th."""
    from gui.planning.problem import SearchSettings, planning_problem
    if args.parallel < 1:
        raise GuiError(f"--parallel {args.parallel}: need 1 or more searches")
    if args.backend == "pool":
        namespaces = [n.strip() for n in args.worlds.split(",") if n.strip()]
        if not namespaces:
            raise GuiError(f"--worlds {args.worlds!r}: no namespace given")
        if len(namespaces) < args.parallel:
            raise GuiError(f"--parallel {args.parallel} searches need as many worlds; "
                           f"--worlds names {len(namespaces)}")
        _check_master("plan", args.world_timeout)
    plan = _plan(args)
    settings = SearchSettings.of_problem(plan, goal_tolerance=args.goal_tolerance,
                                         min_control_steps=args.min_control_steps,
                                         max_control_steps=args.max_control_steps)
    problem = planning_problem(plan, args.robot, settings)
    planner = plan.problem.planner
    time_limit = args.time if args.time is not None else \
        (planner.search.time_limit if planner and planner.search.time_limit else 10.0)
    if args.backend == "pool":

        def pool_backend(k: int):
            from gui.planning.pool import PoolBackend
            return PoolBackend(plan, problem, namespaces[k::args.parallel],
                               timeout=args.world_timeout)
        return pool_backend, time_limit

    def core_backend(k: int):
        from gui.planning.backend import CoreBackend
        return CoreBackend(plan, problem)
    return core_backend, time_limit
