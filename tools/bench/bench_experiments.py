"""Benchmark of the grasp experiment (thesis 10.3): ``rtf_grasp``.

The whole grasp run (tools/experiments/grasp.py) with the thesis's default step values (1 ms
steps, 40 per cycle, 25 Hz) and the world node under ``~free_run``; cycles back to back (Step
Once, one cycle per call, as the GUI's per-cycle commands need), no Viewer frames. The figure
is simulated time over the wall-clock time spent advancing the world (``rtf_stepping`` of the
summary); goal >= 1.0. ``rtf_grasp_overall`` also counts the GUI's own service calls.
"""
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent.parent
sys.path.insert(0, str(ROOT / "tools" / "experiments"))


def run(out_dir: pathlib.Path) -> dict:
    import os
    pid = os.fork()  # rospy.init_node works once per process: run in a child
    if pid == 0:
        code = 1
        try:
            import json
            import grasp
            grasp.run(frames=False, out_root=pathlib.Path(out_dir) / "experiments")
            code = 0
        finally:
            os._exit(code)
    _, status = os.waitpid(pid, 0)
    if status != 0:
        raise RuntimeError(f"the grasp run ended with status {status:#x}")
    import json
    summary = json.loads((pathlib.Path(out_dir) / "experiments" / "grasp" / "summary.json")
                         .read_text())
    timing = summary["timing"]
    return {"rtf_grasp": float(timing["rtf_stepping"]),
            "rtf_grasp_overall": float(timing["rtf_overall"])}
