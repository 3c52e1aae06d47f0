"""Benchmark of the grasp experiment (thesis 10.3): ``rtf_grasp``.

The whole grasp run (tools/experiments/grasp.py) with the thesis's default step values (1 ms
steps, 40 per cycle, 25 Hz) and the world node under ``~free_run``; cycles back to back (Step
Once, one cycle per call, as the GUI's per-cycle commands need), no Viewer node. The figure
is simulated time over the wall-clock time spent advancing the world (``rtf_stepping`` of the
summary). ``rtf_grasp`` is the median of RUNS runs (this machine is shared: one run alone can
read 20 % low); ``rtf_grasp_overall`` also counts the GUI's own service calls.

``rtf_grasp_with_viewer``: the same with the Viewer node rendering the scene at 25 Hz beside
the world (its camera of the experiment: no snapshots saved), runs alternating with those
without; ``rtf_grasp_viewer_ratio`` = rtf_grasp_with_viewer / rtf_grasp (the issue's "a
Viewer that never starves the world": on 2 cores the Viewer has one of its own).

``propagate_rtf_grasp``: the carry (the hand holding the can) propagated again from the
snapshot taken when it began, as a planner would (Propagate, no publication, no Viewer):
simulated over wall-clock time, median of the runs.

``rtf_grasp_exact_meshes`` is one run with the hand's meshes colliding as given
(collision_mesh_tolerance 0 instead of the experiment's 4 mm), timed in the same bench run,
and ``rtf_grasp_mesh_tolerance_speedup`` the ratio of the two.

``rtf_grasp_kinematic``: the grasp in tracked mode with the arm, the palm and the hand's placing
joints under the kinematic drive and the flexing finger joints dynamic (``grasp.run(
kinematic=True)``), stepping rtf as rtf_grasp's, median of RUNS runs; ``grasp_kinematic_held``
the fraction of those runs whose outcome checks all held (``grasp.verdict``).
"""
import json
import pathlib
import statistics
import sys

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(ROOT / "tools" / "experiments"))
sys.path.insert(0, str(HERE))

from forked import in_child  # noqa: E402

RUNS = 3


def _grasp_timing(out_dir: pathlib.Path, world_changes: dict, viewer: bool = False) -> dict:
    """One grasp run without frames (in a child: see forked), with or without a Viewer node;
    its summary's timing, with the rtf of the carry propagated again from its snapshot."""
    import grasp
    grasp.WORLD.update(world_changes)
    grasp.run(frames=False, out_root=out_dir, mode="velocity", viewer=viewer)   # the thesis's
    summary = json.loads((out_dir / "grasp" / "summary.json").read_text())
    return dict(summary["timing"], propagate_rtf=summary["carry_propagated"]["rtf"])


def _kinematic_grasp(out_dir: pathlib.Path) -> dict:
    """One kinematic grasp run without frames or Viewer (in a child): its stepping rtf and
    whether its outcome checks held."""
    import grasp
    facts = grasp.run(frames=False, out_root=out_dir, mode="tracked", viewer=False,
                      kinematic=True)
    summary = json.loads((out_dir / "grasp_kinematic" / "summary.json").read_text())
    return {"rtf": float(summary["timing"]["rtf_stepping"]), "held": grasp.verdict(facts)[0]}


def run_kinematic(out_dir: pathlib.Path) -> dict:
    """``rtf_grasp_kinematic`` and ``grasp_kinematic_held`` (the module's docstring)."""
    runs = [in_child(_kinematic_grasp, pathlib.Path(out_dir) / "experiments_kinematic")
            for _ in range(RUNS)]
    return {"rtf_grasp_kinematic": statistics.median(r["rtf"] for r in runs),
            "grasp_kinematic_held": sum(bool(r["held"]) for r in runs) / len(runs)}


def run(out_dir: pathlib.Path) -> dict:
    out = pathlib.Path(out_dir) / "experiments"
    timings, with_viewer = [], []
    for _ in range(RUNS):   # alternately, so that both see the same host
        timings.append(in_child(_grasp_timing, out, {}, False))
        with_viewer.append(in_child(_grasp_timing, pathlib.Path(out_dir) / "experiments_viewer",
                                    {}, True))
    exact = in_child(_grasp_timing, pathlib.Path(out_dir) / "experiments_exact_meshes",
                     {"collision_mesh_tolerance": 0.0})
    rtf = statistics.median(float(t["rtf_stepping"]) for t in timings)
    rtf_viewer = statistics.median(float(t["rtf_stepping"]) for t in with_viewer)
    return {"rtf_grasp": rtf,
            "rtf_grasp_with_viewer": rtf_viewer,
            "rtf_grasp_viewer_ratio": round(rtf_viewer / rtf, 3),
            "rtf_grasp_overall": statistics.median(float(t["rtf_overall"]) for t in timings),
            "propagate_rtf_grasp": statistics.median(float(t["propagate_rtf"]) for t in timings),
            "rtf_grasp_exact_meshes": float(exact["rtf_stepping"]),
            "rtf_grasp_mesh_tolerance_speedup": round(rtf / float(exact["rtf_stepping"]), 3),
            **run_kinematic(out_dir)}
