"""Benchmark of the grasp experiment (thesis 10.3): ``rtf_grasp``.

The whole grasp run (tools/experiments/grasp.py) with the thesis's default step values (1 ms
steps, 40 per cycle, 25 Hz) and the world node under ``~free_run``; cycles back to back (Step
Once, one cycle per call, as the GUI's per-cycle commands need), no Viewer frames. The figure
is simulated time over the wall-clock time spent advancing the world (``rtf_stepping`` of the
summary); goal >= 1.0. ``rtf_grasp`` is the median of RUNS runs (this machine is shared: one
run alone can read 20 % low); ``rtf_grasp_overall`` also counts the GUI's own service calls.

``rtf_grasp_exact_meshes`` is one run with the hand's meshes colliding as given
(collision_mesh_tolerance 0 instead of the experiment's 4 mm), timed in the same bench run,
and ``rtf_grasp_mesh_tolerance_speedup`` the ratio of the two.
"""
import json
import os
import pathlib
import statistics
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent.parent
sys.path.insert(0, str(ROOT / "tools" / "experiments"))

RUNS = 3


def _run_grasp(out_dir: pathlib.Path, world_changes: dict) -> dict:
    """One headless grasp run in a child process (rospy.init_node works once per process);
    returns its summary's timing."""
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            import grasp
            grasp.WORLD.update(world_changes)
            grasp.run(frames=False, out_root=out_dir)
            code = 0
        finally:
            os._exit(code)
    _, status = os.waitpid(pid, 0)
    if status != 0:
        raise RuntimeError(f"the grasp run ended with status {status:#x}")
    summary = json.loads((out_dir / "grasp" / "summary.json").read_text())
    return summary["timing"]


def run(out_dir: pathlib.Path) -> dict:
    out = pathlib.Path(out_dir) / "experiments"
    timings = [_run_grasp(out, {}) for _ in range(RUNS)]
    exact = _run_grasp(pathlib.Path(out_dir) / "experiments_exact_meshes",
                       {"collision_mesh_tolerance": 0.0})
    rtf = statistics.median(float(t["rtf_stepping"]) for t in timings)
    return {"rtf_grasp": rtf,
            "rtf_grasp_overall": statistics.median(float(t["rtf_overall"]) for t in timings),
            "rtf_grasp_exact_meshes": float(exact["rtf_stepping"]),
            "rtf_grasp_mesh_tolerance_speedup": round(rtf / float(exact["rtf_stepping"]), 3)}
