"""Where a tracked path starts (issue 28): a ``.kps`` solution's query names its Init and Goal
samples, which may run the problem's query backwards (Kautham's 2DRR_singularity solution:
``Query Init="1" Goal="0"``); the path runs from the sample it names, and a robot away from it
is refused before anything moves, or moved there first as a segment of the report."""
from __future__ import annotations

import logging

import numpy as np
import pytest

from gui.core.execution import AwayFromStart, TrackingDefaults, execute_tracked
from gui.core.kautham.problem import load_problem
from gui.core.kautham.solutions import read_solution
from gui.core.translate import BuildDefaults, plan_problem
from gui.errors import PathFileError
from gui_core_world import CoreWorld
from odin_common.interface import Solver


@pytest.fixture
def world():
    w = CoreWorld()
    yield w
    w.close()


def _load(path):
    logging.disable(logging.WARNING)
    try:
        return load_problem(path)
    finally:
        logging.disable(logging.NOTSET)


def test_a_kps_query_names_the_samples_its_path_runs_between(tro_singularity):
    problem = _load(tro_singularity / "2DRR_singularity.xml")
    solution = read_solution(tro_singularity / "2DRR_singularity_sol.kps", problem)
    assert (solution.query.init, solution.query.goal) == (1, 0)
    assert solution.query.describe() == "sample 1 to sample 0"
    path = solution.paths["2D-Robot"]
    # <Result name="Path">1 2 0</Result>: from the problem's Goal back to its Init
    robot = problem.robots[0]
    assert path.joints[0] == pytest.approx(robot.goal.joints)
    assert path.joints[-1] == pytest.approx(robot.start.joints)


def test_a_kps_whose_path_does_not_run_from_its_query_s_init_is_refused(kautham_dir,
                                                                        tmp_path):
    tro = kautham_dir / "legacy_2012" / "examples" / "TRO"
    problem = _load(tro / "2DRR_obstacle.xml")
    text = (tro / "2DRR_obstacle_sol.kps").read_text()
    assert '<Query Init="0" Goal="1"' in text
    for query, said in [('<Query Init="5" Goal="1"', "the query runs from sample 5 to "
                         "sample 1, its path from sample 0 to sample 1"),
                        ('<Query Init="0" Goal="400"', '<Query Goal="400">: no such sample'),
                        ('<Query Init="first" Goal="1"',
                         '<Query Init="first">: not a sample index')]:
        bad = tmp_path / "bad.kps"
        bad.write_text(text.replace('<Query Init="0" Goal="1"', query))
        with pytest.raises(PathFileError) as error:
            read_solution(bad, problem)
        assert str(error.value).startswith(f"{bad}:15: ") and said in str(error.value)


def _singularity_world(world, tro_singularity):
    """The singularity problem built at its query's start (sample 0) in ``world``."""
    problem = _load(tro_singularity / "2DRR_singularity.xml")
    plan = plan_problem(problem, BuildDefaults(start_at_query=True))
    world.execute(plan)
    world.core.set_world_parameters(solver=Solver.WORLDSTEP)
    return problem, plan, read_solution(tro_singularity / "2DRR_singularity_sol.kps", problem)


def test_a_robot_away_from_the_path_s_start_is_refused_and_nothing_moves(tro_singularity,
                                                                         world):
    problem, plan, solution = _singularity_world(world, tro_singularity)
    port = world
    before = world.core.body_state_vector()
    with pytest.raises(AwayFromStart) as error:
        execute_tracked(port, plan, solution)
    # joint 2: 0.687 of the problem's Init against 0.4 of the path's first sample (its Goal)
    assert error.value.distance == pytest.approx(np.radians(360 * (0.687 - 0.4)), abs=1e-6)
    assert error.value.unit == "rad" and error.value.channel == "2D-Robot/link2"
    assert str(error.value) == "the robot is 1.8 rad from the path's start (2D-Robot/link2)"
    assert world.core.body_state_vector().tobytes() == before.tobytes()


def test_from_here_moves_it_to_the_start_first_as_a_reported_segment(tro_singularity, world):
    problem, plan, solution = _singularity_world(world, tro_singularity)
    report = execute_tracked(world, plan, solution, from_here=True)
    move, path = report.segments[0], report.segments[1]
    assert move["what"] == "to the path's start" and move["channel"] == "2D-Robot/link2"
    assert move["distance"] == pytest.approx(1.803, abs=1e-3) and move["unit"] == "rad"
    assert 0.5 < move["end_s"] == path["start_s"] < path["end_s"] <= report.duration_s
    assert report.segments[-1]["what"] == "settle"
    assert report.query == {"init": 1, "goal": 0}
    summary = report.to_json()
    assert summary["segments"] == report.segments and summary["query"] == report.query
    # it ends at the path's last sample: the problem's Init, where it was built
    assert report.goal_error <= 0.01
    assert report.actuals[-1][:2] == pytest.approx(problem.robots[0].start.joints[:2],
                                                   abs=0.01)


def test_a_robot_at_the_path_s_start_runs_with_a_move_of_nothing_reported(kautham_dir, world):
    tro = kautham_dir / "legacy_2012" / "examples" / "TRO"
    problem = _load(tro / "2DRR_obstacle.xml")
    plan = plan_problem(problem, BuildDefaults(start_at_query=True))
    world.execute(plan)
    report = execute_tracked(world, plan,
                             read_solution(tro / "2DRR_obstacle_sol.kps", problem),
                             TrackingDefaults(settle=0.1))
    assert report.segments[0]["distance"] < TrackingDefaults().start_tolerance
    assert report.segments[0]["end_s"] == 0.0 and report.query == {"init": 0, "goal": 1}
