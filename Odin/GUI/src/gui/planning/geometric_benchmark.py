"""A benchmark's geometric runs: Kautham problems without physics searched by OMPL's geometric
planners over Odin's collision checks (``gui.planning.geometric``), as ``rosrun GUI
benchmark`` runs them (ROS-free).

Before any run, ``check_problem`` builds the problem's scene once and checks its query: a
start or goal that collides is not searched; each of its runs is recorded at once with OMPL's
status (Invalid start, Invalid goal) and the one-line reason. A run (``search``, in a process
of its own: ``gui.planning.benchmark_run``) is ``gui.planning.geometric.solve`` with the
problem's own planner parameters (``GeometricSettings.of_problem``: Range, Goal Bias), the
benchmark's planner, time limit and seed, and the solution always simplified, as OMPL's
Benchmark simplifies every solution it measures. The measures are OMPL's geometric
benchmark's: the planner's time without the simplification (``time``), the path's length as
found and as simplified, the simplification's time, the simplified path's segments, the
planner's graph states, and the collision checks Kautham's benchmark adds.
"""
from __future__ import annotations

import hashlib
import resource
import socket
from dataclasses import asdict, replace
from typing import Callable, Optional, Tuple

from gui.errors import PlanningError

CONTROL_ONLY = ("min_control_steps", "max_control_steps", "goal_tolerance")
"""The benchmark's search options (gui.planning.problem.SearchSettings fields) that only a
control search takes; ``goal_bias`` is the geometric planners' Goal Bias too."""


def is_geometric(build) -> bool:
    """Whether ``build`` (a BuildPlan) is planned geometrically: its problem has no physics
    (not one of Kautham's ODE planners), as ``rosrun GUI plan`` routes it."""
    return not build.physics


def run_settings(build, planner: Optional[str], time_limit: float, overrides: dict):
    """The GeometricSettings of a run: the problem's own (``GeometricSettings.of_problem``),
    ``planner`` (OMPL's name; None: the problem's), ``time_limit`` s, the Goal Bias of
    ``overrides`` (SearchSettings fields by name) and the solution simplified (module
    docstring). PlanningError for a planner Odin does not run or an override a geometric
    search does not take."""
    from gui.planning.geometric import GeometricSettings, Simplification
    refused = sorted(set(overrides) & set(CONTROL_ONLY))
    if refused:
        raise PlanningError(f"--{refused[0].replace('_', '-')}: only a search of a problem for "
                            "one of Kautham's ODE planners takes it; this problem is planned "
                            "geometrically")
    settings = GeometricSettings.of_problem(build)
    settings = replace(settings, planner=planner or settings.planner,
                       time_limit=float(time_limit), simplify=Simplification.SHORTEN,
                       goal_bias=overrides.get("goal_bias", settings.goal_bias))
    settings.check()
    return settings


def own_time_limit(build) -> Optional[float]:
    """s: the problem's own "_Max Planning Time" (None when it gives none)."""
    planner = build.problem.planner
    return dict(planner.geometric).get("time_limit") if planner is not None else None


def common_properties(settings) -> dict:
    """The settings a geometric run's planner runs with, as a log's common properties."""
    return {"range": "default" if settings.range is None else repr(settings.range),
            "goal bias": "default" if settings.goal_bias is None else repr(settings.goal_bias),
            "resolution": repr(settings.resolution)}


def check_problem(build) -> Optional[Tuple[str, str]]:
    """Builds ``build``'s scene and checks its query: (OMPL's status, the one-line reason)
    when its start or goal collides, None when both are clear. PlanningError when it has no
    query or no robot with controls."""
    from gui.planning.geometric import GeometricWorld, check_query, query
    start, goal = query(build)
    world = GeometricWorld(build)
    try:
        try:
            check_query(world, start, goal)
        except PlanningError as error:
            status = "Invalid start" if world.collisions(start) else "Invalid goal"
            return status, " ".join(str(error).split())
        return None
    finally:
        world.close()


def search(problem: str, planner: str, seed: int, time_limit: float, overrides: dict,
           stop: Callable[[], bool], memory_limit_mb: Optional[float] = None) -> dict:
    """One geometric run (module docstring) of the problem file ``problem``: the RunResult
    fields it measures. ``stop()`` true raises KeyboardInterrupt; a search that grows past
    ``memory_limit_mb`` MB is ended and answered with ``error`` saying so."""
    from gui.core.kautham.problem import load_problem
    from gui.core.translate import BuildDefaults, plan_problem
    from gui.planning.bridge import _memory_watch
    from gui.planning.geometric import solve
    build = plan_problem(load_problem(problem), BuildDefaults())
    settings = run_settings(build, planner, time_limit, overrides)
    memory_over = _memory_watch(memory_limit_mb)
    try:
        result = solve(build, settings, seed, lambda: bool(stop()) or memory_over())
    except KeyboardInterrupt:
        if stop() or not memory_over():
            raise
        # solve() raises on any stop and keeps nothing of the search: the run is recorded
        # as ended by maxMem, without the measures
        return _measured(False, "Timeout", 0.0, None, error=(
            f"ended by maxMem: the search grew by more than {memory_limit_mb:g} MB"))
    return _measured(result.solved, result.status, result.time_s - result.simplify_s, result)


def _measured(solved: bool, status: str, time_s: float, result, error: str = "") -> dict:
    """The RunResult fields of a geometric run as JSON values (``result``: its
    GeometricResult, or None)."""
    from gui.planning.benchmark_run import GeometricMeasures
    digest = ""
    if result is not None and len(result.path):
        hashed = hashlib.sha256()
        for row in result.path:
            hashed.update(repr(tuple(float(v) for v in row)).encode())
        digest = hashed.hexdigest()
    measures = None if result is None else GeometricMeasures(
        collision_checks=result.checks, solution_length=result.unsimplified_length,
        simplified_length=result.length, simplified_segments=max(result.states - 1, 0),
        simplification_s=result.simplify_s, graph_states=result.graph_states)
    return dict(solved=solved, approximate=False, status=status, time_s=time_s,
                solution_length_s=0.0, solution_difference_m=None, propagations=0,
                memory_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                digest=digest, host=socket.gethostname(), error=error,
                geometric=None if measures is None else asdict(measures))


__all__ = ["CONTROL_ONLY", "check_problem", "common_properties", "is_geometric",
           "own_time_limit", "run_settings", "search"]
