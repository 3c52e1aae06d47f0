"""run_path --tracked against a live VirtualWorld (each test with its own roscore): Kautham's
public 2DRR_obstacle solution (.kps) followed by the joint servos to its goal."""
from __future__ import annotations

import json

import pytest

pytestmark = pytest.mark.forked


def test_the_2drr_kps_solution_runs_to_its_goal_with_a_summary_and_a_plot(world, kautham_dir,
                                                                         tmp_path):
    tro = kautham_dir / "legacy_2012" / "examples" / "TRO"
    problem, solution = tro / "2DRR_obstacle.xml", tro / "2DRR_obstacle_sol.kps"
    world.run(["rosrun", "GUI", "load_problem", str(problem), "--at-start"], timeout=120)
    from gui.ros.client import WorldClient
    from odin_common.interface import Solver
    client = WorldClient()
    assert client.world_parameters().solver == Solver.AUTO          # the world's default
    # the exact solver, set by run_path --solver (AUTO would pick it for this small chain;
    # QuickStep alone, 20 iterations, lets it shake under gravity near the goal: 0.073 rad)
    summary, plot = tmp_path / "summary.json", tmp_path / "plot.png"
    result = world.run(["rosrun", "GUI", "run_path", str(problem), "--at-start", "--tracked",
                        str(solution), "--fast", "--solver", "worldstep", "--summary",
                        str(summary), "--plot", str(plot)], timeout=180)
    last = result.stdout.splitlines()[-1]
    assert "kps path of 4 waypoints" in last and last.endswith("solver worldstep")
    assert client.world_parameters().solver == Solver.WORLDSTEP
    report = json.loads(summary.read_text())
    assert report["solver"] == "worldstep"
    assert report["goal_error"] <= 0.01
    assert 0.0 < report["tracking_error_max"] < 0.05
    assert report["duration_s"] > report["trajectory_s"] > 1.0
    joints = report["series"]["joints"]
    assert [j["name"] for j in joints] == ["2D-Robot/link1", "2D-Robot/link2", "2D-Robot/tcp"]
    assert len(joints[0]["actual"]) == len(report["series"]["time"])
    # the first sample of the path is the query's Init, the last its Goal
    assert joints[0]["target"][-1] == pytest.approx(-0.4335, abs=1e-3)
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not client.world().simulating
    client.close()


def test_the_2drr_kps_solution_runs_under_the_kinematic_drive(world, kautham_dir, tmp_path):
    """--kinematic: the chain's links follow the servos' law exactly, whatever the solver and
    the motors' force limits: at the goal, on the path as closely as the law lags behind its
    targets."""
    tro = kautham_dir / "legacy_2012" / "examples" / "TRO"
    problem, solution = tro / "2DRR_obstacle.xml", tro / "2DRR_obstacle_sol.kps"
    world.run(["rosrun", "GUI", "load_problem", str(problem), "--at-start"], timeout=120)
    summary = tmp_path / "summary.json"
    world.run(["rosrun", "GUI", "run_path", str(problem), "--at-start", "--tracked",
               str(solution), "--fast", "--kinematic", "--solver", "quickstep", "--summary",
               str(summary)], timeout=180)
    report = json.loads(summary.read_text())
    # QuickStep (20 iterations) lets the dynamic chain shake 0.073 rad off its goal: the
    # kinematic one is not in the LCP at all
    assert report["goal_error"] < 1e-6
    assert 0.0 < report["tracking_error_max"] < 0.05


def test_a_mismatched_plan_is_one_error_line_and_runs_nothing(world, kautham_dir, tmp_path):
    tro = kautham_dir / "legacy_2012" / "examples" / "TRO"
    problem = tro / "2DRR_obstacle.xml"
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=120)
    bad = tmp_path / "bad.kps"
    bad.write_text('<?xml version="1.0"?>\n<Planner>\n <Queries>\n  <Query Solved="True">\n'
                   '   <Result name="Path">0 1</Result>\n  </Query>\n </Queries>\n'
                   ' <SampleSet dim="2" size="2">\n  <Sample>0.5 0.5</Sample>\n'
                   '  <Sample>0.5 0.5 0.5</Sample>\n </SampleSet>\n</Planner>\n')
    result = world.run(["rosrun", "GUI", "run_path", str(problem), "--tracked", str(bad)],
                       check=False, timeout=60)
    errors = [line for line in result.stderr.splitlines()
              if not line.startswith("run_path: warning:")]
    assert result.returncode != 0 and len(errors) == 1 and f"{bad}:10:" in errors[0]
    assert "3 values" in errors[0]
