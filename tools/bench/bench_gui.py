"""GUI benchmarks: problem_info (no ROS) and load_problem into a running VirtualWorld + Viewer.

gui_info_tx90_hand_s: wall time of the whole ``problem_info`` process (the package's
    executable run by the venv's python, without rosrun's ~1 s of rospack lookup) on
    TX90_RHand_ICRA10_5PMD_TwoCan.xml; median of RUNS. Goal <= 1.5 s.
gui_load_tx90_hand_s: wall time of the whole ``load_problem`` process for the same problem
    into a fresh VirtualWorld with a Viewer attached, until every object is built (the world
    answers Build Entity after the Viewer has been told); median of RUNS (each loads into the
    world the previous one left, as the GUI does: the world's trimesh data and markers of the
    first load serve the others), gui.core.shape_cache filled by problem_info before.
    Goal <= 1.0 s.
"""
from __future__ import annotations

import os
import pathlib
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPTS = ROOT / "Odin" / "GUI" / "scripts"
RUNS = 3     # odd: the median is one of the runs


def _problem() -> pathlib.Path:
    kautham = pathlib.Path(os.environ.get("ODIN_KAUTHAM_DIR", ROOT.parent / "shared" / "kautham"))
    return kautham / "legacy_2012" / "examples" / "TX90_RHand_ICRA10_5PMD_TwoCan.xml"


def _timed(args, env=None) -> float:
    started = time.monotonic()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                   env=env, timeout=300)
    return time.monotonic() - started


def run(out_dir: pathlib.Path) -> dict:
    problem = _problem()
    figures = {}
    infos = [_timed([sys.executable, str(SCRIPTS / "problem_info"), str(problem)])
             for _ in range(RUNS)]
    print(f"  problem_info {[round(t, 3) for t in infos]} s")
    figures["gui_info_tx90_hand_s"] = round(statistics.median(infos), 3)
    from odin_common.ros_master import RosMaster
    times = []
    with RosMaster() as master:
        master.rosrun("Viewer", "viewer")
        master.rosrun("VirtualWorld", "virtualWorld")
        master.wait_for_service("/virtual_world/set_joint_force")
        master.wait_for_service("/viewer/view_object")
        for _ in range(RUNS):
            times.append(_timed([sys.executable, str(SCRIPTS / "load_problem"), str(problem)],
                                env=master.env))
    print(f"  load_problem {[round(t, 3) for t in times]} s")
    figures["gui_load_tx90_hand_s"] = round(statistics.median(times), 3)
    return figures
