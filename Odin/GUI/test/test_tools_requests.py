"""The tools' command lines become frozen requests (gui.tools): run_path's five modes each
with its run, the options each request carries, the plan tool's seeds within the one range
of gui.planning.bridge.MAX_SEED. No ROS, no world: nothing here runs a tool's work."""
from __future__ import annotations

import dataclasses

import pytest

from gui.core.paths import DEGREES, RADIANS
from gui.errors import GuiError, PlanningError
from gui.planning.bridge import MAX_SEED, check_seed
from gui.tools import benchmark, plan, run_path


def _path_request(*argv: str) -> run_path.PathRequest:
    return run_path._request(run_path._parser().parse_args(["p.xml", *argv]))


@pytest.mark.parametrize("mode", list(run_path.PathMode))
def test_each_mode_option_makes_a_request_of_its_mode_and_has_a_run(mode):
    request = _path_request(f"--{mode.value}", "rows.txt")
    assert request.mode is mode and request.path == "rows.txt"
    assert request.problem.path == "p.xml"
    assert mode in run_path._RUNS


def test_run_path_options_reach_the_request():
    request = _path_request("--tracked", "s.kps", "--degrees", "--fast", "--summary", "s.json",
                            "--solver", "worldstep", "--kinematic", "--from-here",
                            "--robot", "arm", "--timeout", "3", "--no-cache", "--at-home")
    assert request.units == DEGREES and not request.real_time and request.timeout == 3.0
    assert request.robot == "arm"
    assert request.tracked == run_path.TrackedOptions(
        from_here=True, summary="s.json", plot=None, solver="worldstep", kinematic=True)
    assert not request.problem.build.use_cache
    assert request.problem.build.start_at_query is False
    plain = _path_request("--position", "p.txt", "--double", "2", "--rate", "25")
    assert plain.units is None and plain.real_time and plain.double == 2 and plain.rate == 25
    assert _path_request("--initial", "i.txt", "--radians").units == RADIANS


def test_a_request_cannot_be_changed_once_made():
    request = _path_request("--velocity", "v.txt")
    with pytest.raises(dataclasses.FrozenInstanceError):
        request.rate = 10.0


def test_a_doubled_path_past_its_row_limit_is_refused_before_it_is_made():
    assert run_path._doublings(3, 10) == 3
    with pytest.raises(GuiError, match="MAX_PATH_ROWS"):
        run_path._doublings(20, 2)


def test_plan_options_reach_the_request_and_name_the_searches():
    args = plan._parser().parse_args(["p.xml", "--out", "o.path", "--backend", "pool",
                                      "--worlds", "/a,/b", "--parallel", "2", "--seed", "9"])
    request = plan._request(args)
    assert request.backend is plan.Backend.POOL and request.worlds == "/a,/b"
    assert request.seed == 9 and request.out == "o.path"
    assert request.searches() == " and the next 1"
    assert plan._pool_namespaces(request) == ["/a", "/b"]
    single = plan._request(plan._parser().parse_args(["p.xml", "--out", "o.path"]))
    assert single.backend is plan.Backend.CORE and single.searches() == ""


def test_seeds_are_checked_against_max_seed_with_room_for_the_searches_after_them():
    check_seed(MAX_SEED)
    check_seed(MAX_SEED - 3, room=3)
    with pytest.raises(PlanningError, match=r"must be an integer in \[1, 2\^32 - 3\)$"):
        check_seed(MAX_SEED - 2, room=3)
    for bad in (0, MAX_SEED + 1, True, 1.0):
        with pytest.raises(PlanningError, match=r"must be an integer in \[1, 2\^32\)$"):
            check_seed(bad)


@pytest.mark.parametrize("entropy", [b"\x00\x00\x00\x00", b"\xff\xff\xff\xff",
                                     b"\xfd\xff\xff\x7f", b"\xff\xff\xff\xbf"])
def test_a_drawn_seed_is_below_2_31_with_room_for_the_searches(monkeypatch, entropy):
    monkeypatch.setattr(plan.os, "urandom", lambda n: entropy)
    for searches in (1, 64):
        seed = plan._fresh_seed(searches)
        assert 1 <= seed and seed + searches < 2 ** 31
        check_seed(seed, room=searches)


def test_benchmark_overrides_are_checked_and_only_the_given_ones_kept():
    assert benchmark.SearchOverrides(goal_tolerance=0.5).given() == {"goal_tolerance": 0.5}
    with pytest.raises(GuiError, match="--goal-bias 2: between 0 and 1"):
        benchmark.SearchOverrides(goal_bias=2.0).given()
    with pytest.raises(GuiError, match="above --max-control-steps"):
        benchmark.SearchOverrides(min_control_steps=5, max_control_steps=2).given()
