"""A geometric plan as Kautham hands it on (gui.planning.geometric_output, `rosrun GUI plan
--format`, `--no-interpolate`): interpolated as Kautham's trySolve does, every state added on a
motion the search checked, written as OMPL's printAsMatrix rows that run_path's reader reads
back; the tool's refusals of what does not apply. The problem is test_geometric_planning's
two-link arm that must fold past a post."""
from __future__ import annotations

import json
import math
import os
import signal
import subprocess
from dataclasses import replace

import numpy as np
import pytest

from gui.core.kautham.problem import load_problem
from gui.core.kautham.solutions import OMPL, read_solution
from gui.core.translate import plan_problem
from gui.planning.geometric import GeometricSettings, GeometricWorld, solve, task_rows
from gui.planning.geometric_output import (interpolate, kautham_path, longest_segment,
                                           ompl_rows_text, write_ompl_rows)
from test_geometric_planning import _problem


def test_the_longest_segment_is_1_percent_of_the_control_spaces_diagonal():
    assert longest_segment(2, "PRM") == pytest.approx(0.01 * math.sqrt(2))
    assert longest_segment(6, "RRTConnect", 0.5) == pytest.approx(0.01 * math.sqrt(6))


def test_a_short_rrt_range_makes_five_states_per_range_step_as_in_kautham():
    # 4 L = 0.0566 for k = 2: Range 0.05 is shorter, so L = Range / 5
    assert longest_segment(2, "RRTConnect", 0.05) == pytest.approx(0.01)
    assert longest_segment(2, "RRT", 0.05) == pytest.approx(0.01)
    # Kautham's PRM, RRT* and KPIECE keep 1 %, whatever their Range
    assert longest_segment(2, "KPIECE1", 0.05) == pytest.approx(0.01 * math.sqrt(2))


def test_each_segment_is_cut_into_ceil_of_its_length_over_the_longest_pieces():
    path = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.0], [0.1, 0.06]])
    out = interpolate(path, 0.03)
    # 0.1 / 0.03 -> 4 pieces, a repeated state -> 1, 0.06 / 0.03 -> exactly 2
    np.testing.assert_allclose(out, [[0, 0], [0.025, 0], [0.05, 0], [0.075, 0], [0.1, 0],
                                     [0.1, 0], [0.1, 0.03], [0.1, 0.06]], atol=1e-15)
    assert out[4].tolist() == [0.1, 0.0] and out[-1].tolist() == [0.1, 0.06]


def test_a_path_of_one_state_is_left_as_it_is():
    single = np.array([[0.3, 0.7]])
    assert kautham_path(single, "RRT", 0.1).tolist() == [[0.3, 0.7]]
    assert kautham_path(np.empty((0, 2)), "RRT").shape == (0, 2)


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    """(the problem file, its build plan, a path the search found at a 1 cm resolution)."""
    problem_file = _problem(tmp_path_factory.mktemp("arm"))
    plan = plan_problem(load_problem(problem_file))
    settings = replace(GeometricSettings.of_problem(plan), resolution=0.01)
    result = solve(plan, settings, seed=2)
    assert result.solved
    return problem_file, plan, result.path


def test_the_interpolated_states_lie_on_the_paths_segments_and_are_clear(arm):
    _, plan, path = arm
    out = kautham_path(path, "RRTConnect", 0.1)
    longest = longest_segment(2, "RRTConnect", 0.1)
    steps = np.linalg.norm(np.diff(out, axis=0), axis=1)
    assert len(out) > len(path) and np.max(steps) <= longest + 1e-12
    assert np.sum(steps) == pytest.approx(np.sum(np.linalg.norm(np.diff(path, axis=0),
                                                                axis=1)))
    for state in path:                              # the planner's states are kept
        assert np.min(np.linalg.norm(out - state, axis=1)) == 0.0
    world = GeometricWorld(plan, resolution=0.01)
    try:
        assert all(world.valid(state) for state in out)
    finally:
        world.close()


def test_ompl_rows_are_laid_out_as_printasmatrix_writes_them():
    assert ompl_rows_text([[-1.5, 0.0], [0.25, 1e-17]]) == "-1.5 0.0 \n0.25 1e-17 \n\n"


def test_ompl_rows_are_read_back_as_ompl_rows_with_the_task_files_joints(arm, tmp_path):
    problem_file, plan, path = arm
    rows = task_rows(plan, kautham_path(path, "RRTConnect", 0.1))
    out = tmp_path / "path.txt"
    write_ompl_rows(out, rows)
    solution = read_solution(out, load_problem(problem_file))
    assert solution.format == OMPL
    np.testing.assert_array_equal(solution.paths["arm"].joints, rows)  # full precision
    assert [p.name for p in tmp_path.iterdir()] == ["path.txt"]        # no part file left


def _plan(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(["rosrun", "GUI", "plan", *args], capture_output=True, text=True,
                          timeout=timeout)


def _statistics(stdout: str) -> dict:
    return json.loads(stdout[stdout.index("{"):stdout.index("}") + 1])


def test_plan_writes_ompl_rows_of_the_same_states_as_its_task_file(tmp_path):
    problem_file = _problem(tmp_path)
    common = [str(problem_file), "--seed", "5", "--resolution", "0.02"]
    task = _plan(*common, "--out", str(tmp_path / "p.xml"))
    ompl = _plan(*common, "--format", "ompl", "--out", str(tmp_path / "p.txt"))
    assert task.returncode == ompl.returncode == 0, task.stderr + ompl.stderr
    statistics = _statistics(ompl.stdout)
    assert statistics == _statistics(task.stdout) | {"time_s": statistics["time_s"],
                                                      "collision_checks_per_s": statistics[
                                                          "collision_checks_per_s"],
                                                      "simplify_s": statistics["simplify_s"]}
    assert statistics["states_written"] > statistics["states"] >= 2
    problem = load_problem(problem_file)
    as_task = read_solution(tmp_path / "p.xml", problem).paths["arm"].joints
    as_rows = read_solution(tmp_path / "p.txt", problem).paths["arm"].joints
    assert len(as_rows) == statistics["states_written"]
    np.testing.assert_array_equal(as_rows, as_task)
    assert f"{len(as_rows)} configurations written to {tmp_path / 'p.txt'} (OMPL rows" \
        in ompl.stdout


def test_no_interpolate_writes_the_planners_states_only(tmp_path):
    problem_file = _problem(tmp_path)
    run = _plan(str(problem_file), "--seed", "5", "--resolution", "0.02", "--no-interpolate",
                "--format", "ompl", "--out", str(tmp_path / "p.txt"))
    assert run.returncode == 0, run.stderr
    statistics = _statistics(run.stdout)
    assert "states_written" not in statistics
    rows = (tmp_path / "p.txt").read_text().split("\n")
    assert len(rows) == statistics["states"] + 2 and rows[-2:] == ["", ""]


def _one_error(run: subprocess.CompletedProcess) -> str:
    errors = [line for line in run.stderr.splitlines() if ": warning: " not in line]
    assert run.returncode == 2 and len(errors) == 1, run.stderr
    return errors[0]


@pytest.mark.parametrize("options, says", [
    (["--physics", "--format", "ompl"], "plan: error: --format ompl: only a geometric search"),
    (["--physics", "--no-interpolate"], "plan: error: --no-interpolate: only a geometric"),
    (["--from-here"], "plan: error: --from-here: only with --execute"),
    (["--fast"], "plan: error: --fast: only with --execute"),
    (["--format", "rows"], "plan: error: --format invalid choice: 'rows'"),
])
def test_plan_refuses_an_output_option_that_does_not_apply_in_one_line(tmp_path, options,
                                                                       says):
    run = _plan(str(_problem(tmp_path)), *options, "--out", str(tmp_path / "p.txt"),
                timeout=60)
    assert _one_error(run).startswith(says)
    assert not (tmp_path / "p.txt").exists()


def test_plan_refuses_ompl_rows_for_a_2012_problem(arm_and_box, tmp_path):
    run = _plan(str(arm_and_box("a.xml", 500)), "--format", "ompl", "--out",
                str(tmp_path / "p.txt"), timeout=60)
    assert _one_error(run).startswith("plan: error: --format ompl: run_path reads a 2012 "
                                      "problem's plain rows as one robot's joints in degrees")
    assert not (tmp_path / "p.txt").exists()


def test_ctrl_c_during_a_geometric_search_exits_130_and_writes_nothing(tmp_path):
    out = tmp_path / "p.txt"
    # a 0.1 mm resolution: thousands of checks per motion, the search far from done at once
    plan = subprocess.Popen(["rosrun", "GUI", "plan", str(_problem(tmp_path)), "--resolution",
                             "0.0001", "--format", "ompl", "--execute", "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)     # its own group, as a terminal's job
    try:
        assert "RRTConnect searching" in plan.stdout.readline()
        os.killpg(plan.pid, signal.SIGINT)              # what a terminal's Ctrl-C does
        _, err = plan.communicate(timeout=60)
    finally:
        if plan.poll() is None:
            os.killpg(plan.pid, signal.SIGKILL)
            plan.wait()
    assert plan.returncode == 130, err
    assert "Traceback" not in err and not out.exists()
