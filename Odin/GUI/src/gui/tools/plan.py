"""``rosrun GUI plan PROBLEM --planner NAME --time S --out PATH``: a motion plan for the
problem's query. A problem for one of Kautham's ODE planners is searched by one of OMPL's
control planners through Odin's physics (``gui.planning.bridge``) and written as a Kautham
control path (``run_path --controls`` runs it); any other by one of OMPL's geometric planners
over Odin's geometry (``gui.planning.geometric``: the problem's own planner and parameters),
interpolated as Kautham does (``gui.planning.geometric_output``) and written as a Kautham task
file or, ``--format ompl``, as OMPL rows (``run_path --tracked`` runs either). The search's
statistics are printed as JSON. ``--execute`` then runs the plan in the running world as
run_path would (``gui.tools.run_path.run_path``), its lines and summary printed. A control
search's plan counts as solved only when its replay from the start ends in the goal region
with no invalid step (``gui.planning.bridge.PlanResult.verdict``, printed on its own line);
a query no search can solve (its goal inside a fixed obstacle or outside the limits) is
refused before any search. Exits 1 with one line when no solution was found in time or the
replay disagrees with the search (what differs; nothing written), 2 on bad input, a refused
query, or when the plan written cannot run (no world, a world without the problem), 130 on
Ctrl-C (nothing written during the search; the robot held where it got to during the
run)."""
from __future__ import annotations

import enum
import json
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Optional, Sequence, Tuple

from gui.errors import GuiError
from gui.tools.common import (ProblemFile, ToolParser, add_build_options, check_master,
                              check_output, count, fail, one_line_errors, seconds,
                              warnings_to_stderr)
from odin_common.errors import OdinError
from odin_common.tool import stop_on_ctrl_c

if TYPE_CHECKING:
    import numpy as np

    from gui.planning.bridge import PlanResult
    from gui.planning.geometric import GeometricResult

TOOL = "plan"

DEFAULT_TIME_LIMIT_S = 10.0
"""s: a search's time limit when neither --time nor the problem ("_Max Planning Time") gives
one."""


class OutputFormat(enum.Enum):
    """How a geometric plan is written (a control search's plan is a control path): as
    Kautham's GUI writes a task file, or as OMPL's printAsMatrix rows."""
    KAUTHAM = "kautham"
    OMPL = "ompl"


class Backend(enum.Enum):
    """Where the searches' worlds are: in this process, or the world nodes of --worlds."""
    CORE = "core"
    POOL = "pool"


@dataclass(frozen=True)
class PlanRequest:
    """What plan is asked: the problem's query searched by ``planner`` for ``time`` s
    (None: the problem's "_Max Planning Time", else DEFAULT_TIME_LIMIT_S) with OMPL's
    ``seed`` (None: drawn); ``parallel`` searches at once (seeds ``seed`` + k). ``worlds``:
    the pool's namespaces, comma-separated, each waited for ``world_timeout`` s.
    ``goal_tolerance`` (m), ``min_control_steps``, ``max_control_steps``: a control search's
    settings (None: the problem's, ``gui.planning.problem.SearchSettings``); ``resolution``
    (m): a geometric search's (None: ``gui.planning.geometric.RESOLUTION``), ``restarts``
    too (gui.planning.geometric: a tree planner that finds no path started again). ``planner``:
    None, the problem's (a control search's: KPIECE1). ``out``: the file to write, as
    ``format`` says (a geometric plan), its states interpolated as Kautham does unless not
    ``interpolate``. ``execute``: run the plan in the running world once written, as
    run_path does (``from_here``: a robot away from the path's start moved there first;
    ``real_time``: not as fast as the world steps), waiting ``world_timeout`` s for the
    master, then for each of the world's answers."""
    problem: ProblemFile
    out: str
    planner: Optional[str] = None
    time: Optional[float] = None
    seed: Optional[int] = None
    backend: Backend = Backend.CORE
    worlds: str = "/virtual_world"
    world_timeout: float = 30.0
    robot: Optional[str] = None
    goal_tolerance: Optional[float] = None
    min_control_steps: Optional[int] = None
    max_control_steps: Optional[int] = None
    parallel: int = 1
    resolution: Optional[float] = None
    restarts: bool = True
    format: OutputFormat = OutputFormat.KAUTHAM
    interpolate: bool = True
    execute: bool = False
    from_here: bool = False
    real_time: bool = True

    def searches(self) -> str:
        """How the tool's lines name the searches after the first."""
        return f" and the next {self.parallel - 1}" if self.parallel > 1 else ""


@dataclass(frozen=True)
class PlanOutcome:
    """A control search's result (the first exact solution of the parallel searches, else
    the closest), its time limit (s) and its (first) seed."""
    result: PlanResult
    time_limit: float
    seed: int

    def failure(self, request: PlanRequest) -> str:
        result = self.result
        if result.disagreement:
            return (f"{request.problem.path}: the replay disagrees with the search "
                    f"({result.planner}, seed {result.seed}): {result.disagreement}; "
                    "nothing written")
        return (f"{request.problem.path}: no solution within {self.time_limit:g} s "
                f"({result.planner}, seed {self.seed}{request.searches()}): the closest "
                f"plan ends {result.goal_distance:.3f} m from the goal")

    def write(self, request: PlanRequest) -> None:
        """The motion plan written to ``request.out`` as a control path, its comments
        saying how it was made."""
        from gui.core.control_path import write_control_path
        result = self.result
        write_control_path(request.out, result.rows, comments=(
            f"control path planned by rosrun GUI plan {request.problem.path}",
            f"planner {result.planner}, seed {result.seed}, {result.time_s:.2f} s, "
            f"ends {result.goal_distance:.4f} m from the goal",
            "each row: the robot's controls in [0, 1], then the duration (s)"))
        print(f"plan: {len(result.rows)} rows ({result.duration:.3f} s) written to "
              f"{request.out}")

    def execute(self, request: PlanRequest) -> int:
        """--execute: the control path run as ``run_path --controls`` runs it."""
        from gui.tools.run_path import PathMode
        return _execute(request, PathMode.CONTROLS)


@dataclass(frozen=True)
class GeometricOutcome:
    """A geometric search's result, its time limit (s), its seed, the build plan it
    searched (the path's configurations are the plan's robots') and the states to write
    (n, k) in the control space: the result's path, interpolated as the request asks."""
    result: GeometricResult
    time_limit: float
    seed: int
    build_plan: object
    written: np.ndarray

    def failure(self, request: PlanRequest) -> str:
        within = f"{self.result.samples} samples (the problem's Max. Samples)" \
            if self.result.out_of_samples else f"{self.time_limit:g} s"
        return (f"{request.problem.path}: no solution within {within} "
                f"({self.result.planner}, seed {self.seed})")

    def write(self, request: PlanRequest) -> None:
        """The path written to ``request.out`` as ``request.format`` says."""
        from gui.planning.geometric import task_rows, write_task
        from gui.planning.geometric_output import write_ompl_rows
        rows = task_rows(self.build_plan, self.written)
        if request.format is OutputFormat.OMPL:
            write_ompl_rows(request.out, rows)
            what = "OMPL rows"
        else:
            write_task(request.out, f"{self.result.planner} seed {self.seed}", rows)
            what = "a Kautham task file"
        print(f"plan: {len(rows)} configurations written to {request.out} ({what}: "
              "run_path --tracked runs it)", flush=True)

    def execute(self, request: PlanRequest) -> int:
        """--execute: the path run as ``run_path --tracked`` runs it."""
        from gui.tools.run_path import PathMode
        return _execute(request, PathMode.TRACKED)


def _execute(request: PlanRequest, mode) -> int:
    """The plan written to ``request.out`` run in the running world by run_path in ``mode``
    (a ``gui.tools.run_path.PathMode``): its exit status, its failure as one line saying
    where the plan stays."""
    from gui.tools.run_path import PathRequest, TrackedOptions, run_path
    run = PathRequest(request.problem, mode, request.out, robot=request.robot,
                      real_time=request.real_time, timeout=request.world_timeout,
                      tracked=TrackedOptions(from_here=request.from_here))
    try:
        return run_path(run)
    except OdinError as error:
        robot = f" --robot {request.robot}" if request.robot else ""
        raise GuiError(f"--execute: {error} (the plan stays in {request.out}: rosrun GUI "
                       f"run_path {request.problem.path}{robot} --{mode.value} {request.out} "
                       "runs it)") from None


CONTROL_SEARCH_OPTIONS = (("backend", Backend.CORE, "--backend"),
                          ("goal_tolerance", None, "--goal-tolerance"),
                          ("min_control_steps", None, "--min-control-steps"),
                          ("max_control_steps", None, "--max-control-steps"),
                          ("parallel", 1, "--parallel"), ("robot", None, "--robot"))
"""(request field, its value when not given, option): what only a control search takes (a
geometric search plans every robot of the query together, in this process)."""


def _geometric_search(request: PlanRequest, build_plan, stop) -> GeometricOutcome:
    """The problem's query searched over Odin's geometry (gui.planning.geometric); the
    statistics say how many states are written when the interpolation changed their count."""
    from dataclasses import replace

    from gui.planning.geometric import RESOLUTION, GeometricSettings, solve
    from gui.planning.geometric_output import kautham_path
    for name, unset, option in CONTROL_SEARCH_OPTIONS:
        if getattr(request, name) != unset:
            raise GuiError(f"{option}: only a search of a problem for one of Kautham's ODE "
                           "planners takes it; this problem is planned geometrically")
    if request.format is OutputFormat.OMPL and build_plan.problem.format == "2012":
        raise GuiError("--format ompl: run_path reads a 2012 problem's plain rows as one "
                       "robot's joints in degrees, not as OMPL rows; --format kautham writes "
                       "this problem's plan")
    settings = GeometricSettings.of_problem(build_plan)
    settings = replace(settings, planner=request.planner or settings.planner,
                       time_limit=request.time if request.time is not None
                       else settings.time_limit,
                       resolution=request.resolution or RESOLUTION,
                       restarts=request.restarts)
    seed = request.seed if request.seed is not None else _fresh_seed(1)
    print(f"plan: {settings.planner} searching for up to {settings.time_limit:g} s, seed "
          f"{seed} (--seed {seed} repeats it)", flush=True)
    result = solve(build_plan, settings, seed, stop)
    written = kautham_path(result.path, settings.planner, settings.range, result.scales) \
        if request.interpolate else result.path
    statistics = result.statistics()
    if len(written) != result.states:
        statistics["states_written"] = len(written)
    print(json.dumps(statistics, indent=1), flush=True)
    return GeometricOutcome(result, settings.time_limit, seed, build_plan, written)


def search(request: PlanRequest, stop: Callable[[], bool]):
    """Says what it searches, with the seed, searches, then prints the statistics; a
    PlanOutcome, or a GeometricOutcome for a problem without physics. ``stop()`` true
    (Ctrl-C) ends the search and raises KeyboardInterrupt."""
    from gui.planning import bridge
    if request.backend is Backend.POOL:
        _pool_namespaces(request)           # a bad --worlds is said before anything waits
        check_master(TOOL, request.world_timeout)
    build_plan = request.problem.read()
    if not build_plan.physics:
        return _geometric_search(request, build_plan, stop)
    for option, given in (("--resolution", request.resolution is not None),
                          ("--no-restarts", not request.restarts),
                          ("--format ompl", request.format is OutputFormat.OMPL),
                          ("--no-interpolate", not request.interpolate)):
        if given:
            raise GuiError(f"{option}: only a geometric search takes it; this problem is "
                           "for one of Kautham's ODE planners (its plan is a control path: "
                           "rows of controls and a duration)")
    planner = request.planner or "KPIECE1"
    make_backend, time_limit = _backends(request, build_plan)
    seed = request.seed if request.seed is not None else _fresh_seed(request.parallel)
    searching = (f"plan: {planner} searching for up to {time_limit:g} s, seed {seed}"
                 f"{request.searches()} (--seed {seed} repeats it)")
    if request.parallel == 1:
        backend = make_backend(0)
        print(searching, flush=True)        # once the world is built: the search starts now
        try:
            result = bridge.plan(backend, planner, time_limit, seed, stop)
        finally:
            backend.close()
        print(json.dumps(result.statistics(), indent=1), flush=True)
        return _verdict(PlanOutcome(result, time_limit, seed))
    from gui.planning.parallel import plan_in_parallel
    print(searching, flush=True)
    result, outcomes = plan_in_parallel(make_backend, request.parallel, planner,
                                        time_limit, seed, stop)
    print(json.dumps({**result.statistics(), "searches": [o.summary() for o in outcomes]},
                     indent=1), flush=True)
    return _verdict(PlanOutcome(result, time_limit, seed))


def _verdict(outcome: PlanOutcome) -> PlanOutcome:
    """The plan's verdict said on its own line when it is a solution (its replay ends in the
    goal region without an invalid step; OMPL's "Exact solution" is only what the search
    claimed); otherwise main's one error line says why not."""
    if outcome.result.solved:
        print(f"plan: {outcome.result.verdict}", flush=True)
    return outcome


def _fresh_seed(searches: int) -> int:
    """A seed for OMPL from the system's entropy, in the lower half of [1, MAX_SEED], room
    left for ``searches`` consecutive ones."""
    from gui.planning.bridge import MAX_SEED
    return 1 + int.from_bytes(os.urandom(4), "little") % ((MAX_SEED + 1) // 2 - 1 - searches)


def _backends(request: PlanRequest, build_plan) -> Tuple[Callable[[int], object], float]:
    """(make_backend(k): the back end of search k of ``request.parallel``, the searches'
    time limit s). Every search's back end holds the problem's world: the Core builds one in
    the process calling it; with the pool, search k gets every ``request.parallel``-th world
    of ``request.worlds`` from the k-th."""
    from gui.planning.backend import check_query_in_core
    from gui.planning.problem import SearchSettings, planning_problem
    if request.parallel < 1:
        raise GuiError(f"--parallel {request.parallel}: need 1 or more searches")
    if request.backend is Backend.POOL:
        namespaces = _pool_namespaces(request)
    settings = SearchSettings.of_problem(build_plan, goal_tolerance=request.goal_tolerance,
                                         min_control_steps=request.min_control_steps,
                                         max_control_steps=request.max_control_steps)
    problem = planning_problem(build_plan, request.robot, settings)
    # a query no search can solve is refused here, before any back end or search starts
    check_query_in_core(build_plan, problem)
    planner = build_plan.problem.planner
    time_limit = request.time if request.time is not None else \
        (planner.search.time_limit if planner and planner.search.time_limit
         else DEFAULT_TIME_LIMIT_S)
    if request.backend is Backend.POOL:

        def pool_backend(k: int):
            from gui.planning.pool import PoolBackend
            return PoolBackend(build_plan, problem, namespaces[k::request.parallel],
                               timeout=request.world_timeout)
        return pool_backend, time_limit

    def core_backend(k: int):
        from gui.planning.backend import CoreBackend
        return CoreBackend(build_plan, problem)
    return core_backend, time_limit


def _pool_namespaces(request: PlanRequest) -> list:
    """The world nodes' namespaces of --worlds, at least one per search."""
    namespaces = [n.strip() for n in request.worlds.split(",") if n.strip()]
    if not namespaces:
        raise GuiError(f"--worlds {request.worlds!r}: no namespace given")
    if len(namespaces) < request.parallel:
        raise GuiError(f"--parallel {request.parallel} searches need as many worlds; "
                       f"--worlds names {len(namespaces)}")
    return namespaces


def _parser() -> ToolParser:
    from gui.planning.bridge import MAX_SEED, PLANNERS
    from gui.planning.geometric import OMPL_PLANNERS, RESOLUTION
    from gui.planning.parallel import MAX_SEARCHES
    from gui.planning.problem import MAX_CONTROL_STEPS
    parser = ToolParser(
        prog=TOOL, description="Plan a Kautham problem's query: a physics problem with an "
        "OMPL control planner through Odin's world (written as a control path), any other "
        "with an OMPL geometric planner over Odin's geometry (interpolated as Kautham does, "
        "written as a Kautham task file or OMPL rows); --execute then runs the plan in the "
        "running world, as run_path would.")
    parser.add_argument("problem", help="the problem XML file")
    parser.add_argument("--planner", default=None,
                        help=f"OMPL planner: for a physics problem a control planner, "
                        f"{', '.join(PLANNERS)} [KPIECE1]; for any other a geometric one, "
                        f"{', '.join(OMPL_PLANNERS)} [the problem's]")
    parser.add_argument("--time", type=seconds, default=None, metavar="S",
                        help="wall-clock seconds the planner may search [the problem's "
                        "\"_Max Planning Time\", else 10]")
    parser.add_argument("--out", required=True, metavar="PATH",
                        help="the plan file to write: a physics problem's control path (rows: "
                        "controls, duration s), any other's path as --format says")
    parser.add_argument("--seed", type=count(1, MAX_SEED), default=None,
                        help="OMPL's random seed [drawn at random, printed and written with "
                        "the path: --seed repeats a run]")
    parser.add_argument("--backend", choices=[b.value for b in Backend], default="core",
                        help="core: the world in this process [default]; pool: the world "
                        "nodes of --worlds over ROS (cleared and built from the problem)")
    parser.add_argument("--worlds", default="/virtual_world", metavar="NS[,NS...]",
                        help="--backend pool: the world nodes' namespaces [/virtual_world]")
    parser.add_argument("--world-timeout", type=seconds, default=30.0, metavar="S",
                        help="--backend pool: how long to wait for each world; --execute: "
                        "for the master, then for each of the world's answers [30]")
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
    parser.add_argument("--resolution", type=float, default=None, metavar="M",
                        help="a geometric search: no link moves more than M between two "
                        "checked configurations of a motion, so none goes deeper than M/2 "
                        f"into anything [{RESOLUTION}]")
    parser.add_argument("--no-restarts", dest="restarts", action="store_false",
                        help="a geometric search: run the planner once, as OMPL and Kautham "
                        "do [an RRT, RRTConnect or KPIECE search that finds no path is "
                        "cleared and started again, in rounds of growing length]")
    _output_options(parser)
    add_build_options(parser)
    return parser


def _output_options(parser: ToolParser) -> None:
    """How the plan is written and run (``PlanRequest.format`` ... ``real_time``)."""
    parser.add_argument("--format", choices=[f.value for f in OutputFormat],
                        default=OutputFormat.KAUTHAM.value,
                        help="a geometric plan: kautham, a task file as Kautham's GUI writes "
                        "it (<Task><Transit><Conf> rows); ompl, OMPL's printAsMatrix rows "
                        "of the same configurations [kautham]")
    parser.add_argument("--no-interpolate", dest="interpolate", action="store_false",
                        help="a geometric plan: write the planner's states only [interpolated "
                        "as Kautham does: no two states farther apart than 1%% of the "
                        "control space's diagonal (RRT, RRTConnect: a fifth of a Range below "
                        "4%%)]")
    parser.add_argument("--execute", action="store_true",
                        help="then run the plan in the running world, built by load_problem, "
                        "as run_path does (--tracked, or --controls for a physics problem), "
                        "within --world-timeout")
    parser.add_argument("--from-here", action="store_true",
                        help="--execute: a robot away from the path's start is moved there "
                        "first [it is refused]")
    parser.add_argument("--fast", action="store_true",
                        help="--execute: as fast as the world steps, not in real time")


def _request(args) -> PlanRequest:
    return PlanRequest(
        ProblemFile.of_args(args), args.out, planner=args.planner, time=args.time,
        seed=args.seed, backend=Backend(args.backend), worlds=args.worlds,
        world_timeout=args.world_timeout, robot=args.robot,
        goal_tolerance=args.goal_tolerance, min_control_steps=args.min_control_steps,
        max_control_steps=args.max_control_steps, parallel=args.parallel,
        resolution=args.resolution, restarts=args.restarts, format=OutputFormat(args.format),
        interpolate=args.interpolate, execute=args.execute, from_here=args.from_here,
        real_time=not args.fast)


@one_line_errors(TOOL)
def main(argv: Optional[Sequence[str]] = None) -> int:
    request = _request(_parser().parse_args(argv))
    warnings_to_stderr(TOOL)
    try:
        _check_execute_options(request)
        check_output("--out", request.out)
        with stop_on_ctrl_c() as stop:
            outcome = search(request, stop)
        if not outcome.result.solved:
            return fail(TOOL, GuiError(outcome.failure(request))) - 1
        outcome.write(request)
        if request.execute:
            return outcome.execute(request)
    except (OdinError, OSError) as error:   # an OSError as it is, not by its class
        return fail(TOOL, error)
    return 0


def _check_execute_options(request: PlanRequest) -> None:
    """The options of --execute alone are refused without it."""
    for option, given in (("--from-here", request.from_here),
                          ("--fast", not request.real_time)):
        if given and not request.execute:
            raise GuiError(f"{option}: only with --execute (it says how the plan is run)")


__all__ = ["DEFAULT_TIME_LIMIT_S", "Backend", "GeometricOutcome", "OutputFormat", "PlanOutcome",
           "PlanRequest", "main", "search"]
