"""What ``run_path`` reports means what it says (issue 28) against a live VirtualWorld: a
control path's distance to the goal is the planner's (the link it tracks, in the plane), the
very figure ``plan`` prints for the same path, for each kind of robot Kautham's ODE demos
drive: a free body (the Sphere), a car and a held chain."""
from __future__ import annotations

import json
import logging
import time

import numpy as np
import pytest

from gui.core.control_path import ControlRow, write_control_path

pytestmark = pytest.mark.forked

SPHERE = ("current_2025", "demos", "OMPL_ode_demos", "Sphere", "Sphere.xml")
CAR = ("demos", "OMPL_ode_demos", "Car", "k-PMPCar.xml")
CHAIN = ("demos", "OMPL_ode_demos", "Chain", "k-PMPChain.xml")


def _planned_figure(problem_file, controls) -> tuple:
    """(rows, the distance ``plan`` prints for them): the rows replayed from the problem's
    start in a world of this process, measured as the planner measures (gui.planning)."""
    from gui.core.kautham.problem import load_problem
    from gui.core.translate import plan_problem
    from gui.planning.backend import CoreBackend
    from gui.planning.bridge import replay
    from gui.planning.problem import planning_problem
    logging.disable(logging.WARNING)
    try:
        built = plan_problem(load_problem(problem_file))
    finally:
        logging.disable(logging.NOTSET)
    problem = planning_problem(built)
    backend = CoreBackend(built, problem)
    try:
        rows = [ControlRow(c, problem.step) for c in controls]
        return rows, problem.goal_distance(replay(backend, rows))
    finally:
        backend.close()


@pytest.mark.parametrize("kind,controls", [
    ("free body", [(0.426, 0.578, 0.4)] * 20),
    ("car", [(0.7, 1.0)] * 30 + [(0.2, 0.9)] * 20),
    ("chain", [(0.9, 0.2, 0.5)] * 20 + [(0.1, 0.8, 0.5)] * 20),
])
def test_a_control_path_ends_as_far_from_the_goal_as_plan_said(world, kautham_dir,
                                                               ode_demos_dir, tmp_path,
                                                               kind, controls):
    problem = {"free body": kautham_dir.joinpath(*SPHERE), "car": ode_demos_dir.joinpath(*CAR),
               "chain": ode_demos_dir.joinpath(*CHAIN)}[kind]
    rows, figure = _planned_figure(problem, controls)
    path = tmp_path / "planned.path"
    write_control_path(path, rows)
    # the world already running, as after the README's ball: the load leaves the problem
    # paused at its start, where the plan started (else the sphere landed meanwhile and the
    # replay ended 0.69 m from a goal its plan reached within 0.25 m)
    world.run(["rosservice", "call", "/virtual_world/start", "simulate: true"])
    loaded = world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=120)
    assert "the world is paused at its start" in loaded.stdout.splitlines()[-1]
    time.sleep(1.0)
    result = world.run(["rosrun", "GUI", "run_path", str(problem), "--controls", str(path),
                        "--fast"], timeout=180)
    lines = result.stdout.splitlines()
    assert lines[-1].endswith(f", ends {figure:.4f} m from the goal"), (lines[-1], figure)
    assert lines[-2].endswith(f", {figure:.4f} m from the goal")
    # the link the planner tracks: a held chain's gripper, not its fixed base
    tracked = {"free body": "SphereDE", "car": "SimpleCar/base_link",
               "chain": "Chain/gripper"}[kind]
    assert f" s {tracked} at [" in lines[-2]


def test_a_kps_run_backwards_is_refused_away_from_its_start_and_moved_there_when_asked(
        world, tro_singularity, tmp_path):
    """Kautham's 2DRR_singularity solution runs its query backwards (Query Init="1"
    Goal="0"); the robot built at the problem's start is 1.8 rad from the path's: refused in
    one line, nothing changed (not even --solver); --from-here moves it there first, a
    segment of the summary and of the last line."""
    problem = tro_singularity / "2DRR_singularity.xml"
    solution = tro_singularity / "2DRR_singularity_sol.kps"
    world.run(["rosrun", "GUI", "load_problem", str(problem), "--at-start"], timeout=120)
    from gui.ros.client import WorldClient
    from odin_common.interface import Solver
    client = WorldClient()
    joints = [j for j in client.world().joints]
    before = [j.positions[0] for j in client.call("get_state", joints=joints).joints]
    result = world.run(["rosrun", "GUI", "run_path", str(problem), "--at-start", "--tracked",
                        str(solution), "--fast", "--solver", "worldstep"], check=False,
                       timeout=120)
    errors = [line for line in result.stderr.splitlines()
              if not line.startswith("run_path: warning:")]
    assert result.returncode == 2 and errors == [
        "run_path: error: the robot is 1.8 rad from the path's start (2D-Robot/link2); "
        "--from-here to move it there first"], result.stderr
    assert client.world_parameters().solver == Solver.AUTO
    after = [j.positions[0] for j in client.call("get_state", joints=joints).joints]
    assert after == before
    summary = tmp_path / "summary.json"
    result = world.run(["rosrun", "GUI", "run_path", str(problem), "--at-start", "--tracked",
                        str(solution), "--fast", "--solver", "worldstep", "--from-here",
                        "--summary", str(summary)], timeout=180)
    last = result.stdout.splitlines()[-1]
    assert last.startswith("kps path of 3 waypoints from sample 1 to sample 0, after a 1.8 "
                           "rad move to its start ("), last
    report = json.loads(summary.read_text())
    assert report["query"] == {"init": 1, "goal": 0}
    move = report["segments"][0]
    assert move["what"] == "to the path's start" and move["distance"] == pytest.approx(
        1.803, abs=1e-3)
    assert report["goal_error"] <= 0.01
    client.close()


def test_the_readme_s_position_path_runs_word_for_word(world, kautham_dir):
    """The README's hand session names a position path for the Kuka problem: the file is in
    the repository and the README's two lines run as written (in bash, after setup.bash).
    They name $ODIN_KAUTHAM_DIR: without the corpus the test skips as the others do
    (``kautham_dir``; CI requires the corpus)."""
    import os
    import pathlib
    readme = pathlib.Path(os.environ["ODIN_ROOT"], "README.md").read_text().splitlines()
    lines = [line for line in readme if line.startswith("rosrun GUI ")
             and "Kuka_two_columns.xml" in line
             and ("load_problem" in line or "--position" in line)]
    assert len(lines) == 2 and "load_problem" in lines[0], lines
    for line in lines:
        result = world.run(["bash", "-c", line], timeout=180)
    assert result.stdout.splitlines()[-1].startswith("KukaLWR: 100 rows at ")
    from gui.ros.client import WorldClient
    client = WorldClient()
    state = client.call("get_state", joints=[j for j in client.world().joints
                                             if j.endswith("&KukaLWR/Link1")])
    assert state.joints[0].positions[0] == pytest.approx(np.radians(90.0), abs=0.02)
    client.close()
