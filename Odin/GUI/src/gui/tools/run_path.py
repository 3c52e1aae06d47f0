"""``rosrun GUI run_path PROBLEM --MODE FILE``: a robot built by load_problem driven with a
path file, in one of five modes (``PathMode``): an initial position, a position or velocity
path (a row per cycle), a control path (Kautham's controls through Propagate) or a tracked
Kautham solution (timed, followed by the joint servos under full physics). Ctrl-C stops it
between two calls to the world, the robot held there: exit 130."""
from __future__ import annotations

import enum
import json
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Dict, List, Optional, Sequence

import numpy as np

from gui.core.contacts import ContactLedger
from gui.errors import GuiError, PlanningError
from gui.tools.common import (ProblemFile, ToolParser, add_build_options, add_timeout_option,
                              check_master, check_output, count, hertz, one_line_errors,
                              reading, warnings_to_stderr)
from odin_common.tool import stop_on_ctrl_c

if TYPE_CHECKING:
    from gui.core.paths import RobotPath, RobotRows
    from gui.core.plan import BuildPlan, RobotHandle
    from gui.ros.client import WorldClient

TOOL = "run_path"

MAX_DOUBLINGS = 20
"""run_path --double N: the most doublings of a path's precision asked (each doubles its rows)."""

MAX_PATH_ROWS = 1_000_000
"""Rows of a path after --double: 11 hours at 25 rows per second (memory grows with them)."""


class PathMode(enum.Enum):
    """What the path file holds, named by its option (``--initial FILE`` ...)."""
    INITIAL = "initial"         # a position path's first row, set at once
    POSITION = "position"       # positions, one row per cycle
    VELOCITY = "velocity"       # joint speeds, one row per cycle
    CONTROLS = "controls"       # Kautham controls in [0, 1] and a duration (s) per row
    TRACKED = "tracked"         # a Kautham solution, timed and tracked by the joint servos


@dataclass(frozen=True)
class TrackedOptions:
    """--tracked only: move the robot to the path's start first (``from_here``), where to
    write the summary (JSON) and the plot (PNG), the world's solver to set first ("auto",
    "quickstep", "worldstep"; None: as it is) and whether the joints' motors are put under
    the kinematic drive first."""
    from_here: bool = False
    summary: Optional[str] = None
    plot: Optional[str] = None
    solver: Optional[str] = None
    kinematic: bool = False


@dataclass(frozen=True)
class PathRequest:
    """What run_path is asked. ``units``: ``gui.core.paths.DEGREES`` or ``RADIANS``, None:
    the problem's (degrees and mm for 2012 problems); ``double``: precision doublings of a
    position path; ``rate``: rows per second, Hz (0: the world's publication rate);
    ``real_time``: control and tracked paths in real time, not as fast as the world steps;
    ``timeout``: s to wait for the ROS master, then for each of the world's services;
    ``allow_jumps``: a position path may move a joint further than it could in one row
    (``gui.core.paths.check_row_jumps``)."""
    problem: ProblemFile
    mode: PathMode
    path: str
    robot: Optional[str] = None
    units: Optional[str] = None
    double: int = 0
    rate: float = 0.0
    real_time: bool = True
    timeout: float = 10.0
    tracked: TrackedOptions = TrackedOptions()
    allow_jumps: bool = False


def run_path(request: PathRequest) -> int:
    """Runs the request's path in the running world, a line per row (per simulated second
    for a tracked path) on stdout; 0 when done, 130 when Ctrl-C stopped it. Before any
    work: the output folders, the master, the problem and its robot are checked."""
    check_output("--summary", request.tracked.summary)
    check_output("--plot", request.tracked.plot)
    check_master(TOOL, request.timeout)
    build_plan = request.problem.read()
    try:
        handle = build_plan.robot(request.robot)
    except KeyError as error:
        raise GuiError(f"{request.problem.path}: {error.args[0]}") from None
    return _RUNS[request.mode](request, build_plan, handle)


# ------------------------------------------------------- initial, position and velocity rows

def _read_rows(request: PathRequest, build_plan: BuildPlan, handle: RobotHandle
               ) -> List[RobotPath]:
    """The path file read for the robots it drives (``gui.core.paths.read_robot_paths``:
    every robot's columns, or the request's robot's; ``handle`` is that robot); a position
    path's rows checked for jumps between them (before any doubling: the midpoints halve
    them) unless ``allow_jumps``, its doubling checked."""
    from gui.core.paths import DEGREES, RADIANS, check_row_jumps, read_robot_paths
    units = request.units or (DEGREES if build_plan.problem.format == "2012" else RADIANS)
    with reading("path file", request.path):
        paths = read_robot_paths(request.path, _robots(build_plan), units, request.robot)
    _one_robot(request, [path.robot for path in paths], "columns")
    if request.mode is PathMode.POSITION:
        if not request.allow_jumps:
            for path in paths:
                check_row_jumps(path)
        if request.double:
            _doublings(request.double, len(paths[0].rows))
    return paths


def _robots(build_plan: BuildPlan) -> List[RobotHandle]:
    """The problem's robots (not its movable multi-link obstacles), in its order."""
    return [h for h in build_plan.robots if h.instance.role == "robot"]


def _one_robot(request: PathRequest, driven: List[str], what: str) -> None:
    """GuiError when --robot names a robot and the file drives others too (it holds every
    robot's ``what``): the option would do nothing."""
    if request.robot is not None and driven != [request.robot]:
        raise GuiError(f"--robot {request.robot}: {request.path} holds every robot's {what} "
                       f"({', '.join(driven)}): without --robot it drives them all")


def _robot_rows(request: PathRequest, paths: List[RobotPath], client: WorldClient,
                build_plan: BuildPlan) -> List[RobotRows]:
    """Each path's robot with its rows as sent and where its base is in the world now (a
    base the rows do not carry stays there, ``gui.core.paths.RobotRows``); a position path's
    first row checked against where the robots are unless ``allow_jumps`` (a base's columns
    against its position now), then its precision doubled as asked. Every robot is checked
    before any row is sent."""
    from gui.core.paths import COMMAND_LINE
    from gui.ros.client import rows_to_send
    position = request.mode is PathMode.POSITION
    return rows_to_send(client, paths, {h.name: h for h in _robots(build_plan)},
                        request.double if position else 0,
                        COMMAND_LINE if position and not request.allow_jumps else None)


def _names(robots: List[RobotRows]) -> str:
    return ", ".join(robot.handle.name for robot in robots)


def _doublings(times: int, rows: int) -> int:
    """``times`` if a path of ``rows`` rows doubled that many times has at most
    MAX_PATH_ROWS rows, else GuiError."""
    if rows * 2 ** times > MAX_PATH_ROWS:
        raise GuiError(f"--double {times}: {rows:,} rows would become {rows * 2 ** times:,}, "
                       f"more than {MAX_PATH_ROWS:,} (MAX_PATH_ROWS)")
    return times


def _set_initial(request: PathRequest, build_plan: BuildPlan, handle: RobotHandle) -> int:
    """--initial: the robots set at the file's first row, their speeds zeroed (a placement,
    so not checked for a jump from where they are); a base the row does not carry stays
    where it is. What the placement put inside something it did not touch before is said
    (``gui.core.contacts``)."""
    paths = _read_rows(request, build_plan, handle)
    from gui.ros.client import WorldClient
    client = WorldClient(timeout=request.timeout)
    robots = _robot_rows(request, paths, client, build_plan)
    contacts = ContactLedger(client.check_collision([]))
    client.set_position([s for robot in robots for s in robot.situations(0)],
                        reset_velocity=True)
    for first, second, depth in client.check_collision([]):
        contacts.see(first, second, depth, 0.0)
    print(f"{_names(robots)}: initial position set "
          f"({sum(len(robot.handle.bodies) for robot in robots)} bodies), "
          f"{contacts.describe()}")
    return 0


class _Stopped(Exception):
    """Raised between two rows of a path when Ctrl-C asked to stop."""


def _run_rows(request: PathRequest, build_plan: BuildPlan, handle: RobotHandle) -> int:
    """--position, --velocity: a row per cycle at ``request.rate`` (the world's publication
    rate when 0), a line per row. A position path is checked for jumps before any is sent.
    After each row the world's Check Collision says what touches (a position row places the
    robot, so only then can it be inside something): the pairs the path made are told from
    those the scene rested on before the first row (``gui.core.contacts``), a line each as
    they come and in the last line."""
    paths = _read_rows(request, build_plan, handle)
    from gui.ros.client import (WorldClient, run_position_rows, run_velocity_rows,
                                stop_velocity_rows)
    client = WorldClient(timeout=request.timeout)
    velocity = request.mode is PathMode.VELOCITY
    robots = _robot_rows(request, paths, client, build_plan)
    rows = robots[0].rows
    rate = request.rate if request.rate > 0 else client.publication_rate()
    done = [0]
    contacts = ContactLedger(client.check_collision([]))
    with stop_on_ctrl_c() as stop:

        def progress(k: int) -> None:
            done[0] = k
            known = len(contacts.made)
            for first, second, depth in client.check_collision([]):
                contacts.see(first, second, depth, k / rate)
            news = "".join(f"; {c['first']} | {c['second']} collide, {c['depth_m'] * 1000:.1f}"
                           " mm" for c in contacts.made[known:])
            print(f"[{k}/{len(rows)}]{news}", flush=True)
            if stop:                    # between two calls: none is cut in the middle
                raise _Stopped

        try:
            run = run_velocity_rows if velocity else run_position_rows
            run(client, robots, rate, progress=progress)
        except _Stopped:
            pass
        if stop:
            if velocity:                # the last row's speeds would drive on
                stop_velocity_rows(client, robots)
            return _interrupted(f"row {done[0]} of {len(rows)} ({done[0] / rate:.2f} s "
                                f"of {len(rows) / rate:.2f} s)")
    print(f"{_names(robots)}: {len(rows)} rows at {rate:g} Hz done, {contacts.describe()}")
    return 0


def _interrupted(where: str) -> int:
    """run_path stopped by Ctrl-C, the robot held: says how far it got; 130 (128 + SIGINT)."""
    from odin_common.tool import EXIT_INTERRUPTED
    print(f"run_path: interrupted at {where}; the robot is held there", flush=True)
    return EXIT_INTERRUPTED


def _check_world_holds(client: WorldClient, build_plan: BuildPlan) -> None:
    """The world holds the body, joint and motor IDs the build plan predicts for its robots
    (the scene was built by load_problem, whose answers are not at hand here)."""
    inventory = client.world()
    held = set(inventory.objects) | set(inventory.joints) | set(inventory.motors)
    for handle in build_plan.robots:
        missing = [i for i in [b.body_id for b in handle.bodies] + list(handle.joint_ids)
                   + list(handle.motor_ids) if i not in held]
        if missing:
            raise GuiError(f"the world holds no {missing[0]!r} of robot {handle.name}: build "
                           f"the problem first (rosrun GUI load_problem "
                           f"{build_plan.problem.source})")


# ------------------------------------------------------------------------------ control rows

def _run_controls(request: PathRequest, build_plan: BuildPlan, handle: RobotHandle) -> int:
    """--controls: the control path through Propagate (the world paused meanwhile); one line
    per row: its time, where the link the planner tracks is and, for a problem with a query,
    its distance to the goal in the planner's metric (``_goal_meter``): the figure ``plan``
    printed for the same path."""
    from gui.core.control_path import read_control_paths
    from gui.ros.world_port import run_on_client
    with reading("control path", request.path):
        drives = read_control_paths(request.path, _robots(build_plan),
                                    build_plan.problem.format == "2012", request.robot)
    _one_robot(request, [h.name for h, _ in drives], "controls")
    handle, rows = drives[0]
    meters = [_goal_meter(build_plan, h) for h, _ in drives]
    from gui.ros.client import WorldClient
    client = WorldClient(timeout=request.timeout)
    _check_world_holds(client, build_plan)
    watched = [h.bodies[0].body_id if meter is None else meter.tracked_body
               for (h, _), meter in zip(drives, meters)]
    elapsed, distance = [0.0], {}

    def progress(result) -> None:
        elapsed[0] += result.actuation.duration
        states = [result.watched] + [client.body_kinematics(w) for w in watched[1:]]
        said = []
        for (robot, _), body, meter, state in zip(drives, watched, meters, states):
            to_goal = ""
            if meter is not None:
                distance[robot.name] = meter.body_goal_distance(state[0], state[1])
                to_goal = f", {distance[robot.name]:.4f} m from the goal"
            said.append(f"{body} at {np.round(state[0], 3).tolist()}{to_goal}")
        print(f"[{result.index}/{len(rows)}] t={elapsed[0]:.3f} s {'; '.join(said)}",
              flush=True)

    contacts = ContactLedger(client.check_collision([]))
    with stop_on_ctrl_c() as stop:
        results = run_on_client(client, handle, rows, real_time=request.real_time,
                                progress=progress, stop=stop, watch=watched[0],
                                contacts=contacts, others=drives[1:])
    if stop:
        total = sum(row.duration for row in rows)
        return _interrupted(f"row {len(results)} of {len(rows)} ({elapsed[0]:.2f} s of "
                            f"{total:.2f} s)")
    ends = "" if not distance else ", ends " + ", ".join(
        f"{name + ' ' if len(drives) > 1 else ''}{d:.4f} m" for name, d in distance.items()
    ) + " from the goal"
    print(f"{', '.join(h.name for h, _ in drives)}: {len(rows)} control rows done "
          f"({elapsed[0]:.3f} s simulated), {contacts.describe()}{ends}")
    return 0


def _goal_meter(build_plan: BuildPlan, handle: RobotHandle):
    """The planning problem whose metric ``plan`` reports (``PlanningProblem.goal_distance``:
    the tracked link, in the plane), or None, said on stderr, when the problem has no query
    or the planner cannot take it (then only where the base is is printed)."""
    if handle.goal is None:
        return None
    from gui.planning.problem import planning_problem
    try:
        return planning_problem(build_plan, handle.name)
    except PlanningError as error:
        print(f"run_path: note: no distance to the goal: {error}", file=sys.stderr)
        return None


# --------------------------------------------------------------------------- a tracked path

def _run_tracked(request: PathRequest, build_plan: BuildPlan, handle: RobotHandle) -> int:
    """--tracked: the Kautham solution read and checked whole, then executed in the running
    world (paused meanwhile); one line per simulated second, then the figures. ``handle``
    is not used: the solution names its robots."""
    from gui.core.kautham.solutions import read_solution
    from gui.ros.world_port import run_tracked_on_client
    with reading("plan", request.path):         # the word its users know: a Kautham plan
        solution = read_solution(request.path, build_plan.problem, request.robot,
                                 request.units)
    _one_robot(request, list(solution.paths), "configuration")
    client, solver = _tracked_world(request, build_plan, solution)
    shown = [0]
    reached = [0.0, 0.0]

    def progress(t: float, total: float) -> None:
        reached[:] = [t, total]
        if t >= shown[0] + 1.0 or t >= total - 1e-9:
            shown[0] = int(t)
            print(f"t={t:.2f}/{total:.2f} s", flush=True)

    with stop_on_ctrl_c() as stop:
        report = run_tracked_on_client(client, build_plan, solution, progress=progress,
                                       real_time=request.real_time, stop=stop,
                                       from_here=request.tracked.from_here)
    if stop:
        return _interrupted(f"t={reached[0]:.2f} s of {reached[1]:.2f} s")
    query = f" from {solution.query.describe()}" if solution.query is not None else ""
    print(f"{solution.format} path of {solution.waypoint_count} waypoints{query}"
          f"{report.start_move()}: goal error {report.goal_error:.3g}, tracking error max "
          f"{report.tracking_error_max:.3g}, {report.duration_s:.2f} s simulated, "
          f"{report.contacts}, solver {solver}")
    if request.tracked.summary:
        with open(request.tracked.summary, "w") as out:
            json.dump(dict(report.to_json(), solver=solver), out, indent=1)
    if request.tracked.plot:
        _save_plot(report, request.tracked.plot)
    return 0


def _tracked_world(request: PathRequest, build_plan: BuildPlan, solution):
    """(the world's client, the name of the solver in force): the world checked to hold the
    robots and, unless ``from_here``, to have them at the solution's start; then set as the
    request's --solver and --kinematic ask."""
    from gui.ros.client import WorldClient
    from odin_common.interface import ServoDrive, Solver
    client = WorldClient(timeout=request.timeout)
    _check_world_holds(client, build_plan)
    _check_start(client, build_plan, solution, request.tracked.from_here)  # before any change
    if request.tracked.solver:
        client.set_world(solver=Solver[request.tracked.solver.upper()])
    if request.tracked.kinematic:
        for handle in build_plan.robots:
            if handle.name in solution.paths:
                client.set_drive(handle.motor_ids, ServoDrive.KINEMATIC)
    return client, Solver(client.world_parameters().solver).name.lower()


def _check_start(client: WorldClient, build_plan: BuildPlan, solution, from_here: bool) -> None:
    """Unless ``from_here``: the robots are where the path starts (``gui.core.execution``'s
    rule), else one line saying how far they are and what would move them there."""
    from gui.core.execution import AwayFromStart, plan_tracking
    from gui.ros.world_port import ClientWorldPort
    try:
        plan_tracking(ClientWorldPort(client), build_plan, solution, from_here=from_here)
    except AwayFromStart as error:
        raise GuiError(f"{error}; --from-here to move it there first") from None


def _save_plot(report, path: str) -> None:
    import os
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from PyQt5.QtGui import QGuiApplication
    from gui.window.tracking_plot import save_png
    application = QGuiApplication.instance() or QGuiApplication([TOOL])
    save_png(report, path)
    del application


_RUNS: Dict[PathMode, Callable[[PathRequest, "BuildPlan", "RobotHandle"], int]] = {
    PathMode.INITIAL: _set_initial, PathMode.POSITION: _run_rows,
    PathMode.VELOCITY: _run_rows, PathMode.CONTROLS: _run_controls,
    PathMode.TRACKED: _run_tracked}
"""Each mode's run: (request, build plan, the request's robot) -> exit status."""


def _parser() -> ToolParser:
    from gui.core.paths import MAX_ROW_JUMP, MAX_ROW_SLIDE
    parser = ToolParser(
        prog=TOOL, description="Drive a robot built by load_problem with a path file.")
    parser.add_argument("problem", help="the problem XML file the scene was built from")
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--initial", metavar="FILE", help="initial position (first row used)")
    mode.add_argument("--position", metavar="FILE", help="position path: one row per cycle")
    mode.add_argument("--velocity", metavar="FILE", help="velocity path: one row per cycle")
    mode.add_argument("--controls", metavar="FILE", help="control path: rows of the robot's "
                      "Kautham controls in [0, 1] and a duration (s), applied as Kautham's "
                      "ODE environment does (docs/INTERFACE.md); prints the distance to the "
                      "goal as plan measures it")
    mode.add_argument("--tracked", metavar="FILE", help="a Kautham plan (.kps solution, task "
                      "file, OMPL rows or raw rows), timed within the joints' limits and "
                      "followed by the joint servos under full physics (docs/INTERFACE.md)")
    _tracked_options(parser)
    units = parser.add_mutually_exclusive_group()
    units.add_argument("--degrees", action="store_true",
                       help="values in degrees (mm) [default for 2012 problems]")
    units.add_argument("--radians", action="store_true",
                       help="values in radians (m) [default for current problems]")
    parser.add_argument("--robot", help="the robot a file of one robot's values drives "
                        "[default: the first robot]; a file of every robot's (rows as long as "
                        "all their columns, a task file, a .kps of all the controls) drives "
                        "them all and is refused with --robot")
    parser.add_argument("--double", type=count(0, MAX_DOUBLINGS), default=0, metavar="N",
                        help="double the path precision N times (position paths)")
    parser.add_argument("--allow-jumps", action="store_true",
                        help=f"position paths: run rows that move a revolute joint more than "
                        f"{MAX_ROW_JUMP:g} rad (MAX_ROW_JUMP) or a prismatic one more than "
                        f"{MAX_ROW_SLIDE:g} m (MAX_ROW_SLIDE) from the row before, or the first "
                        f"row from where the robot is [refused: a path read in the wrong unit, "
                        f"said]")
    parser.add_argument("--rate", type=hertz, default=0.0,
                        help="rows per second (default: the world's publication rate)")
    parser.add_argument("--fast", action="store_true",
                        help="control and tracked paths: as fast as the world steps, not in "
                        "real time")
    add_timeout_option(parser)
    add_build_options(parser)
    return parser


def _tracked_options(parser: ToolParser) -> None:
    """The options of --tracked alone (``TrackedOptions``)."""
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


def _request(args) -> PathRequest:
    from gui.core.paths import DEGREES, RADIANS
    mode = next(m for m in PathMode if getattr(args, m.value) is not None)
    return PathRequest(
        ProblemFile.of_args(args), mode, getattr(args, mode.value), robot=args.robot,
        units=DEGREES if args.degrees else RADIANS if args.radians else None,
        double=args.double, rate=args.rate, real_time=not args.fast, timeout=args.timeout,
        tracked=TrackedOptions(from_here=args.from_here, summary=args.summary,
                               plot=args.plot, solver=args.solver,
                               kinematic=args.kinematic),
        allow_jumps=args.allow_jumps)


@one_line_errors(TOOL)
def main(argv: Optional[Sequence[str]] = None) -> int:
    args = _parser().parse_args(argv)
    request = _request(args)
    warnings_to_stderr(TOOL)
    return run_path(request)


__all__ = ["MAX_DOUBLINGS", "MAX_PATH_ROWS", "PathMode", "PathRequest", "TrackedOptions",
           "main", "run_path"]
