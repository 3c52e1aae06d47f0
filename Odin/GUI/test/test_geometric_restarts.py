"""A geometric search's restarts (gui.planning.geometric: a tree planner that finds no path is
cleared and started again, in rounds of RESTART_MOTIONS x Luby's sequence motion checks): on
the two-link arm of test_geometric_planning, with rounds made a few motions long."""
from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace

import pytest

from gui.planning import geometric
from gui.planning.geometric import GeometricSettings, luby, solve
from test_geometric_planning import _plan, _problem


def test_lubys_sequence():
    assert [luby(i) for i in range(16)] == [1, 1, 2, 1, 1, 2, 4, 1, 1, 2, 1, 1, 2, 4, 8, 1]


def _settings(plan, **changes) -> GeometricSettings:
    return replace(GeometricSettings.of_problem(plan), resolution=0.01, **changes)


def test_a_tree_search_whose_rounds_end_without_a_path_is_restarted_until_one_finds_it(
        tmp_path, monkeypatch):
    monkeypatch.setattr(geometric, "RESTART_MOTIONS", 3)
    plan = _plan(_problem(tmp_path))
    result = solve(plan, _settings(plan, planner="RRT"), seed=4)
    assert result.solved and result.rounds > 3
    assert result.statistics()["rounds"] == result.rounds


def test_without_restarts_the_planner_runs_once(tmp_path, monkeypatch):
    monkeypatch.setattr(geometric, "RESTART_MOTIONS", 3)
    plan = _plan(_problem(tmp_path))
    result = solve(plan, _settings(plan, planner="RRT", restarts=False), seed=4)
    assert result.solved and result.rounds == 1


@pytest.mark.parametrize("planner", ["PRM", "RRTstar"])
def test_a_roadmap_or_an_optimizing_planner_is_not_restarted(tmp_path, monkeypatch, planner):
    monkeypatch.setattr(geometric, "RESTART_MOTIONS", 3)
    plan = _plan(_problem(tmp_path))
    result = solve(plan, _settings(plan, planner=planner, time_limit=1.0), seed=4)
    assert result.solved and result.rounds == 1


SEARCH = """
import json, sys
from dataclasses import replace
from gui.core.kautham.problem import load_problem
from gui.core.translate import plan_problem
from gui.planning import geometric
geometric.RESTART_MOTIONS = 3
plan = plan_problem(load_problem(sys.argv[1]))
settings = replace(geometric.GeometricSettings.of_problem(plan), resolution=0.01, planner="RRT")
result = geometric.solve(plan, settings, seed=7)
print(json.dumps({"rounds": result.rounds, "path": result.path.tolist()}))
"""


def test_a_seeds_rounds_and_path_are_the_same_from_run_to_run(tmp_path):
    """Rounds end after a count of motion checks, not a time: a seed's search repeats."""
    problem_file = _problem(tmp_path)
    runs = [subprocess.run([sys.executable, "-c", SEARCH, str(problem_file)],
                           capture_output=True, text=True, timeout=120) for _ in range(2)]
    assert all(r.returncode == 0 for r in runs), runs[0].stderr
    first, second = (json.loads(r.stdout.splitlines()[-1]) for r in runs)
    assert first["rounds"] > 1 and first == second


def test_no_restarts_is_refused_for_a_physics_problem_in_one_line(kautham_dir, tmp_path):
    sphere = kautham_dir / "current_2025" / "demos" / "OMPL_ode_demos" / "Sphere" / "Sphere.xml"
    run = subprocess.run(["rosrun", "GUI", "plan", str(sphere), "--no-restarts",
                          "--out", str(tmp_path / "p.xml")], capture_output=True, text=True,
                         timeout=120)
    errors = [line for line in run.stderr.splitlines() if ": warning: " not in line]
    assert run.returncode == 2 and len(errors) == 1, run.stderr
    assert errors[0].startswith("plan: error: --no-restarts: only a geometric search takes it")
    assert not (tmp_path / "p.xml").exists()
