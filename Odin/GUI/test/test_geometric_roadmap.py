"""A PRM's neighbour settings (gui.planning.geometric.GeometricSettings): Kautham's
MaxNearestNeighbors and DistanceThreshold, Kautham 2012's Max. Neighs, Neigh Thresshold and
Max. Samples, read from the problem and used by the search, on the two-link arm of
test_geometric_planning made a PRM problem."""
from __future__ import annotations

import subprocess

import pytest

from gui.errors import PlanningError, ProblemError
from gui.planning.geometric import GeometricSettings, _Checks, _Search, query, solve
from gui.planning.geometric_world import GeometricWorld
from kautham_files import write_problem
from test_geometric_planning import ARM, CNTR, POST, PROBLEM, _plan


def _prm_problem(folder, parameters: str):
    text = PROBLEM.replace("INIT", "0.125 0.5").replace("GOAL", "0.875 0.5").replace(
        "<Name>omplRRTConnect</Name>", "<Name>omplPRM</Name>" + parameters).replace(
        '<Parameter name="_Max Planning Time">60</Parameter>',
        '<Parameter name="_Max Planning Time">20</Parameter>')
    return write_problem(folder, {"arm.urdf": ARM, "arm.cntr": CNTR, "post.urdf": POST},
                         "arm.xml", text)


def _parameters(**values) -> str:
    return "".join(f'<Parameter name="{name}">{value}</Parameter>'
                   for name, value in values.items())


def test_the_neighbour_settings_of_either_era_are_the_searchs(tmp_path):
    plan = _plan(_prm_problem(tmp_path, _parameters(
        MaxNearestNeighbors=7, DistanceThreshold=0.5) + '<Parameter name="Max. Samples">300'
        '</Parameter>'))
    settings = GeometricSettings.of_problem(plan)
    assert (settings.planner, settings.max_neighbours, settings.neighbour_distance,
            settings.max_samples) == ("PRM", 7, 0.5, 300)
    assert settings.roadmap() == (0.5, 300)
    (tmp_path / "b").mkdir()
    old = _plan(_prm_problem(tmp_path / "b", '<Parameter name="Max. Neighs">4</Parameter>'
                             '<Parameter name="Neigh Thresshold">1.5</Parameter>'))
    settings = GeometricSettings.of_problem(old)
    assert (settings.max_neighbours, settings.neighbour_distance) == (4, 1.5)


def test_the_prms_k_nearest_is_set_on_the_planner(tmp_path):
    plan = _plan(_prm_problem(tmp_path, _parameters(MaxNearestNeighbors=7)))
    world = GeometricWorld(plan)
    try:
        start, goal = query(plan)
        checks = _Checks(world, lambda: False, [1.0, 1.0])
        search = _Search(checks, GeometricSettings.of_problem(plan), start, goal)
        assert search.planner.getMaxNearestNeighbors() == 7
    finally:
        world.close()


def test_the_search_ends_unsolved_at_its_max_samples_and_says_so(tmp_path):
    problem = _prm_problem(tmp_path, '<Parameter name="Max. Samples">5</Parameter>')
    result = solve(_plan(problem), seed=1)
    assert not result.solved and result.out_of_samples and result.samples == 5
    assert result.time_s < 5.0         # long before the 20 s limit
    run = subprocess.run(["rosrun", "GUI", "plan", str(problem), "--seed", "1", "--out",
                          str(tmp_path / "p.xml")], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 1
    assert run.stderr.strip().splitlines()[-1].endswith(
        "arm.xml: no solution within 5 samples (the problem's Max. Samples) (PRM, seed 1)")


def test_no_connection_is_tried_beyond_the_neighbour_distance(tmp_path):
    """A distance of a hundredth of the space's: no two samples are that near, the roadmap
    never connects, and the search ends at its time unsolved; without it, it solves."""
    near = _plan(_prm_problem(tmp_path, _parameters(DistanceThreshold=0.01)))
    settings = GeometricSettings.of_problem(near)
    from dataclasses import replace
    result = solve(near, replace(settings, time_limit=1.0), seed=1)
    assert not result.solved and not result.out_of_samples
    assert solve(near, replace(settings, time_limit=5.0, neighbour_distance=None),
                 seed=1).solved


@pytest.mark.parametrize("parameter, value, message", [
    ("Max. Samples", "0", "Max. Samples '0' is not a whole number >= 1"),
    ("MaxNearestNeighbors", "2.5", "MaxNearestNeighbors '2.5' is not a whole number >= 1"),
    ("DistanceThreshold", "-1", "DistanceThreshold '-1' is not positive"),
])
def test_a_bad_neighbour_setting_is_refused_at_load_naming_it(tmp_path, parameter, value,
                                                              message):
    with pytest.raises(ProblemError, match=message):
        _plan(_prm_problem(tmp_path, f'<Parameter name="{parameter}">{value}</Parameter>'))


def test_settings_given_in_code_are_checked(tmp_path):
    for bad in (dict(max_samples=0), dict(max_neighbours=1.5), dict(neighbour_distance=0.0)):
        with pytest.raises(PlanningError):
            GeometricSettings(planner="PRM", **bad).check()
