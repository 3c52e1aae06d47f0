"""Benchmark of tracked execution (issue 12): Kautham plans followed by the joint servos.

``tracked_goal_error_2drr`` / ``tracked_tracking_error_max_2drr``: the public 2DRR_obstacle
problem (legacy_2012/examples/TRO, built at its query's start) and its ``.kps`` solution run
on the world's Core (``gui.core.execution.execute_tracked`` through the ROS-free port of the
GUI's Core tests), under ODE's exact solver (WORLDSTEP, named in the figure's description:
QuickStep's 20 iterations let the chain shake near the goal, ``..._quickstep`` reports it).
Deterministic: one run each.

``rtf_grasp_tracked``: the grasp experiment in tracked mode (tools/experiments/grasp.py, no
Viewer frames): simulated time over wall-clock time of the tracked execution (approach, thumb,
closing, lift, carry), one Set Servo, one Step Once and the joints read per 40 ms cycle
through the world node; ``rtf_grasp_tracked_stepping`` the whole run's stepping rtf.
"""
import json
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(ROOT / "tools" / "experiments"))
sys.path.insert(0, str(ROOT / "Odin" / "GUI" / "test"))
sys.path.insert(0, str(HERE))

from forked import in_child  # noqa: E402


def _2drr(solver: int) -> dict:
    """(goal error, tracking error max) of the 2DRR .kps solution on the Core, ``solver``."""
    from gui.core.translate import BuildDefaults, plan_problem
    from gui.core.execution import execute_tracked
    from gui.core.kautham.corpus import corpus_dir
    from gui.core.kautham.problem import load_problem
    from gui.core.kautham.solutions import read_solution
    from gui_core_world import CoreWorld
    tro = corpus_dir() / "legacy_2012" / "examples" / "TRO"
    problem = load_problem(tro / "2DRR_obstacle.xml")
    plan = plan_problem(problem, BuildDefaults(start_at_query=True))
    world = CoreWorld()
    try:
        world.execute(plan)
        world.core.set_world_parameters(solver=solver)
        report = execute_tracked(world, plan,
                                 read_solution(tro / "2DRR_obstacle_sol.kps", problem))
    finally:
        world.close()
    return {"goal": report.goal_error, "tracking": report.tracking_error_max}


def _grasp_tracked(out_dir: pathlib.Path) -> dict:
    import grasp
    grasp.run(frames=False, out_root=out_dir, mode="tracked")
    summary = json.loads((out_dir / "grasp" / "summary.json").read_text())
    return {"tracking": summary["tracking"]["real_time_factor"],
            "stepping": summary["timing"]["rtf_stepping"]}


def run(out_dir: pathlib.Path) -> dict:
    from odin_common.interface import Solver
    exact = in_child(_2drr, Solver.WORLDSTEP)
    quick = in_child(_2drr, Solver.QUICKSTEP)
    grasp = in_child(_grasp_tracked, pathlib.Path(out_dir) / "tracked")
    return {"tracked_goal_error_2drr": exact["goal"],
            "tracked_tracking_error_max_2drr": exact["tracking"],
            "tracked_goal_error_2drr_quickstep": quick["goal"],
            "rtf_grasp_tracked": grasp["tracking"],
            "rtf_grasp_tracked_stepping": grasp["stepping"]}
