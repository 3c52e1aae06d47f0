"""Geometric planning (gui.planning.geometric, `rosrun GUI plan` on a problem without physics):
a two-link arm of our own must fold to swing past a post; the query's start and goal are
checked first, every motion of a returned path is clear to the resolution's promise, and the
path is written as a Kautham task file that run_path's reader reads back."""
from __future__ import annotations

import pathlib
import subprocess
from dataclasses import replace

import numpy as np
import pytest

from gui.core.kautham.problem import load_problem
from gui.core.kautham.solutions import read_solution
from gui.core.translate import plan_problem
from gui.errors import PlanningError
from gui.planning.geometric import (GeometricSettings, GeometricWorld, query, solve, task_rows,
                                    write_task)
from kautham_files import write_problem

ARM = """<?xml version="1.0"?><robot name="arm">
 <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
 <link name="upper"><collision><origin xyz="0.25 0 0"/><geometry><box size="0.5 0.05 0.05"/>
  </geometry></collision></link>
 <link name="fore"><collision><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.04 0.04"/>
  </geometry></collision></link>
 <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><origin
  xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="30" velocity="1.5"/>
 </joint>
 <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin
  xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-2.5" upper="2.5" effort="10"
  velocity="2"/></joint>
</robot>"""

CNTR = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="arm/upper" value="0.5"/><DOF name="arm/fore" value="0.5"/></Offset>
 <Control name="arm/shoulder" eigValue="1.0"><DOF name="arm/upper" value="1.0"/></Control>
 <Control name="arm/elbow" eigValue="1.0"><DOF name="arm/fore" value="1.0"/></Control>
</ControlSet>"""

POST = """<?xml version="1.0"?><robot name="post"><link name="base"><collision><geometry>
 <box size="0.1 0.1 0.6"/></geometry></collision></link></robot>"""

PROBLEM = """<?xml version="1.0"?><Problem>
 <Robot robot="arm.urdf"><Home X="0" Y="0" Z="0" WX="0" WY="0" WZ="1" TH="0"/></Robot>
 <Obstacle obstacle="post.urdf"><Home X="0.7" Y="0" Z="0.1" WX="0" WY="0" WZ="1" TH="0"/>
 </Obstacle>
 <Controls robot="arm.cntr"/>
 <Planner><Parameters><Name>omplRRTConnect</Name>
  <Parameter name="Range">0.1</Parameter>
  <Parameter name="_Max Planning Time">60</Parameter></Parameters>
  <Queries><Query><Init>INIT</Init><Goal>GOAL</Goal></Query></Queries></Planner>
</Problem>"""
# shoulder -2 + 4 c1 rad, elbow -2.5 + 5 c2 rad: (0.125, 0.5) points the stretched arm along
# -1.5 rad, (0.875, 0.5) along +1.5 rad; on the way straight it sweeps x > 0, through the post


def _problem(folder: pathlib.Path, init="0.125 0.5", goal="0.875 0.5") -> pathlib.Path:
    return write_problem(folder, {"arm.urdf": ARM, "arm.cntr": CNTR, "post.urdf": POST},
                         "arm.xml", PROBLEM.replace("INIT", init).replace("GOAL", goal))


def _plan(problem_file):
    return plan_problem(load_problem(problem_file))


def test_the_problems_planner_and_parameters_are_the_search_settings(tmp_path):
    settings = GeometricSettings.of_problem(_plan(_problem(tmp_path)))
    assert (settings.planner, settings.range, settings.time_limit) == ("RRTConnect", 0.1, 60.0)


def test_the_straight_way_hits_the_post_and_each_end_is_clear(tmp_path):
    plan = _plan(_problem(tmp_path))
    world = GeometricWorld(plan)
    try:
        start, goal = query(plan)
        assert world.valid(start) and world.valid(goal)
        middle = world.collisions((start + goal) / 2)
        assert {frozenset(p[:2]) for p in middle} & {frozenset(("arm/fore", "post")),
                                                     frozenset(("arm/upper", "post"))}
    finally:
        world.close()


def test_a_goal_inside_the_post_is_refused_before_the_search_naming_the_pair(tmp_path):
    with pytest.raises(PlanningError,
                       match=r"the query's goal collides: arm/\w+ is [0-9.]+ mm into post"):
        solve(_plan(_problem(tmp_path, goal="0.5 0.5")), seed=3)


def test_consecutive_checks_of_a_motion_move_no_link_more_than_the_resolution(tmp_path):
    """The link frames' origins move no more than the bound between two checked points
    (the bound also covers every point of their geometry)."""
    plan = _plan(_problem(tmp_path))
    world = GeometricWorld(plan, resolution=0.004)
    try:
        start, goal = query(plan)
        points = [start] + world.motion_points(start, goal)
        robot = world.robots[0]
        origins = [np.array([p[:3, 3] for p in robot.handle.instance.model.link_poses(
            *robot.configuration(c))]) for c in points]
        moves = [np.max(np.linalg.norm(b - a, axis=1)) for a, b in zip(origins, origins[1:])]
        assert max(moves) <= 0.004
        assert len(points) > 100            # 3 rad of the shoulder, the arm 0.9 m long
    finally:
        world.close()


def test_rrtconnect_folds_the_arm_past_the_post_and_no_link_goes_into_it(tmp_path):
    """At a 1 cm resolution (fewer checks: a quick test) no link goes deeper than 5 mm into
    the post anywhere along the path, checked four times finer."""
    plan = _plan(_problem(tmp_path))
    settings = replace(GeometricSettings.of_problem(plan), resolution=0.01)
    result = solve(plan, settings, seed=1)
    assert result.solved and result.path.shape[1] == 2 and result.checks > 0
    start, goal = query(plan)
    assert result.path[0] == pytest.approx(start) and result.path[-1] == pytest.approx(goal)
    # the elbow folds somewhere on the way (the straight way is blocked)
    assert np.max(np.abs(result.path[:, 1] - 0.5)) > 0.05
    world = GeometricWorld(plan, resolution=0.0025)     # four times finer than the search's
    try:
        deepest = 0.0
        for a, b in zip(result.path, result.path[1:]):
            for point in world.motion_points(a, b):
                pairs = world.collisions(point)
                deepest = max([deepest] + [depth for _, _, depth in pairs])
        assert deepest <= 0.005
    finally:
        world.close()


def test_the_path_is_a_task_file_the_tracked_reader_reads(tmp_path):
    problem_file = _problem(tmp_path)
    plan = _plan(problem_file)
    path = np.array([[0.125, 0.5], [0.2, 0.9], [0.875, 0.5]])
    out = tmp_path / "path.xml"
    write_task(out, "RRTConnect seed 1", task_rows(plan, path))
    solution = read_solution(out, load_problem(problem_file))
    joints = solution.paths["arm"].joints
    np.testing.assert_allclose(joints, [[-1.5, 0.0], [-1.2, 2.0], [1.5, 0.0]], atol=1e-12)


@pytest.mark.slow
def test_plan_writes_the_same_task_file_for_the_same_seed(tmp_path):
    problem_file = _problem(tmp_path)
    outputs = []
    for k in range(2):
        out = tmp_path / f"p{k}.xml"
        run = subprocess.run(["rosrun", "GUI", "plan", str(problem_file), "--seed", "5",
                              "--resolution", "0.02", "--out", str(out)],
                             capture_output=True, text=True, timeout=300)
        assert run.returncode == 0, run.stderr
        assert "RRTConnect searching" in run.stdout and '"solved": true' in run.stdout
        assert "leaked" not in run.stderr     # no OMPL object outlives the search (nanobind)
        outputs.append(out.read_text())
    assert outputs[0] == outputs[1] and outputs[0].startswith("<Task name=")


def test_plan_refuses_a_control_search_option_for_a_geometric_problem(tmp_path):
    run = subprocess.run(["rosrun", "GUI", "plan", str(_problem(tmp_path)), "--parallel", "2",
                          "--out", str(tmp_path / "p.xml")], capture_output=True, text=True,
                         timeout=120)
    errors = [line for line in run.stderr.splitlines() if ": warning: " not in line]
    assert run.returncode == 2 and len(errors) == 1
    assert errors[0].startswith("plan: error: --parallel: only a search of a problem for one")
    assert not (tmp_path / "p.xml").exists()


@pytest.mark.parametrize("given, expected", [(0.0, 0), (1.0, 1), (2.0, 2), (None, 2), (5.0, 2)])
def test_kautham_simplify_solution_values(given, expected):
    """Kautham's omplplanner reads 0 as none, 1 as B-spline smoothing, anything else (its
    default 2) as shortening."""
    from gui.planning.geometric import Simplification
    assert Simplification.of_kautham(given) == expected


def test_a_path_not_simplified_is_the_path_found(tmp_path):
    problem = _problem(tmp_path)
    problem.write_text(problem.read_text().replace(
        '<Parameter name="Range">0.1</Parameter>',
        '<Parameter name="Range">0.1</Parameter><Parameter name="_Simplify Solution">0'
        '</Parameter>'))
    plan = _plan(problem)
    settings = replace(GeometricSettings.of_problem(plan), resolution=0.01)
    assert settings.simplify == 0
    result = solve(plan, settings, seed=1)
    assert result.solved and result.simplify_s == 0.0
    assert result.states == result.unsimplified_states


def test_deepest_along_names_the_pair_a_path_through_the_post_meets_and_zero_when_free(tmp_path):
    """The straight start-goal motion sweeps the arm through the post: deepest_along reports
    a depth and the post's pair; the arm swung the other way (x < 0) touches nothing."""
    from gui.planning.geometric import deepest_along
    plan = _plan(_problem(tmp_path))
    start, goal = query(plan)
    depth, pair = deepest_along(plan, np.array([start, goal]), spacing=0.005)
    assert depth > 0 and pair is not None and "post" in pair
    assert set(pair) & {"arm/fore", "arm/upper"}
    (tmp_path / "free").mkdir()
    free = _plan(_problem(tmp_path / "free", init="0.2 0.5", goal="0.2 0.9"))
    assert deepest_along(free, np.array(query(free)), spacing=0.005) == (0.0, None)
