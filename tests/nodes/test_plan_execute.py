"""`rosrun GUI plan ... --execute` against a live VirtualWorld (each test with its own roscore):
a geometric plan of our own two-link arm written, then run tracked in the world as
`run_path --tracked` runs it, its summary line printed; without a world, the plan is written
and the run refused in one line."""
from __future__ import annotations

import json
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "Odin" / "GUI" / "test"))     # the arm problem's files
from test_geometric_planning import _problem  # noqa: E402

SUMMARY = re.compile(r"^(\w+) path of (\d+) waypoints: goal error ([0-9.e+-]+), tracking error "
                     r"max [0-9.e+-]+, [0-9.]+ s simulated, (\d+) colliding pairs? made by "
                     r"the path(?: \(.*\))?, \d+ resting contacts?, solver \w+$")


def _statistics(stdout: str) -> dict:
    return json.loads(stdout[stdout.index("{"):stdout.index("}") + 1])


def _plan_and_run(world, problem, *options: str):
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=120)
    run = world.run(["rosrun", "GUI", "plan", str(problem), "--seed", "3", "--resolution",
                     "0.02", "--execute", "--fast", *options], check=False, timeout=180)
    assert run.returncode == 0, run.stderr
    summary = SUMMARY.match(run.stdout.splitlines()[-1])
    assert summary, run.stdout[-500:]
    return run, summary.group(1), int(summary.group(2)), float(summary.group(3)), \
        int(summary.group(4))


def test_a_short_plan_is_interpolated_written_as_a_task_file_and_run_tracked(world,
                                                                              tmp_path):
    # the stretched arm turns 0.5 rad, clear of the post: a few interpolated states
    problem = _problem(tmp_path, goal="0.25 0.5")
    out = tmp_path / "short.xml"
    run, kind, waypoints, goal_error, colliding = _plan_and_run(world, problem, "--out",
                                                                str(out))
    statistics = _statistics(run.stdout)
    assert statistics["solved"] and statistics["states_written"] > statistics["states"]
    assert (kind, waypoints, colliding) == ("task", statistics["states_written"], 0)
    assert goal_error < 1e-3
    assert out.read_text().startswith("<Task name=")


def test_the_arm_folds_past_the_post_from_ompl_rows_without_touching_it(world, tmp_path):
    problem = _problem(tmp_path)
    out = tmp_path / "fold.txt"
    run, kind, waypoints, goal_error, colliding = _plan_and_run(
        world, problem, "--format", "ompl", "--no-interpolate", "--out", str(out))
    assert (kind, waypoints, colliding) == ("ompl", _statistics(run.stdout)["states"], 0)
    assert goal_error < 1e-3
    assert len(out.read_text().split("\n")) == waypoints + 2    # rows, then a blank line


def test_without_a_world_the_plan_is_written_and_the_run_refused_in_one_line(ros_master,
                                                                             tmp_path):
    problem, out = _problem(tmp_path), tmp_path / "plan.xml"
    run = ros_master.run(["rosrun", "GUI", "plan", str(problem), "--seed", "3",
                          "--resolution", "0.02", "--execute", "--world-timeout", "2",
                          "--out", str(out)], check=False, timeout=120)
    errors = [line for line in run.stderr.splitlines() if ": warning: " not in line]
    assert run.returncode == 2 and len(errors) == 1, run.stderr
    assert errors[0].startswith("plan: error: --execute: /virtual_world: no VirtualWorld "
                                "answering after 2 s")
    assert errors[0].endswith(f"(the plan stays in {out}: rosrun GUI run_path {problem} "
                              f"--tracked {out} runs it)")
    assert out.read_text().startswith("<Task name=")


def test_a_physics_plan_is_run_as_a_control_path_ending_where_plan_said(world, kautham_dir,
                                                                         tmp_path):
    problem = kautham_dir / "current_2025" / "demos" / "OMPL_ode_demos" / "Sphere" / "Sphere.xml"
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=120)
    run = world.run(["rosrun", "GUI", "plan", str(problem), "--planner", "KPIECE1", "--time",
                     "30", "--seed", "2", "--execute", "--fast", "--out",
                     str(tmp_path / "sphere.path")], check=False, timeout=180)
    assert run.returncode == 0, run.stderr
    statistics = _statistics(run.stdout)
    last = re.match(r"^SphereDE: (\d+) control rows done \([0-9.]+ s simulated\), \d+ "
                    r"colliding pairs? made by the path(?: \(.*\))?, \d+ resting contacts?, "
                    r"ends ([0-9.]+) m from the goal$", run.stdout.splitlines()[-1])
    assert last, run.stdout[-500:]
    assert int(last.group(1)) == statistics["rows"]
    assert abs(float(last.group(2)) - statistics["goal_distance_m"]) < 1e-3
