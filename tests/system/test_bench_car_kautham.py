"""The car's side-by-side benchmark against Kautham 5.1.1 (tools/bench/bench_car_kautham.py):
Kautham's output read (solved exactly, at the time limit, not solved, crashed, killed), the
figures from each side's runs, the time limit, Kautham's environment and the run without the
peer built. No planning and no Kautham: the outputs and runs are written here."""
import json
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools" / "bench"))

import bench_car_kautham  # noqa: E402
from bench_car_kautham import Run, figures_of, read_kautham  # noqa: E402
from report import Refused  # noqa: E402

SETUP = """PEER seed 1
PEER family 5 planner KPIECECarPlanner
Info:    Using default state validity checker for OpenDE
Goal region, threshold = 0.05, memory address = 0x55641b8dcf30
Info:    KPIECE1: Starting planning with 1 states already in datastructure
"""
HEADLESS = "\nError: can not open X11 display\nODECOUNT quickstep {quick} worldstep {world}\n"
"""What the driver's stderr ends with after a solved search without a display: drawstuff's
dsError exits before the driver's ``PEER solved`` line, the shim's destructor still counts."""

SOLVED = SETUP + """\
Info:    KPIECE1: Created 12406 states in 3134 cells (1059 internal + 2075 external)
Info:    Solution found in 33.406689 seconds
Query Solved
1st Query is solved
States in Solution: 370
"""
AT_THE_LIMIT = SETUP + """\
Info:    ProblemDefinition: Adding approximate solution from planner KPIECE1
Info:    KPIECE1: Created 7844 states in 2150 cells (567 internal + 1583 external)
Info:    Solution found in 60.075404 seconds
Query Solved
1st Query is solved
States in Solution: 184
"""
NOTHING = SETUP + """\
Info:    KPIECE1: Created 1 states in 1 cells (0 internal + 1 external)
Info:    No solution found after 60.012 seconds
Query Solved
PEER solved 0 wall 60.2
"""


def test_a_run_solved_exactly_gives_its_search_time_and_ode_steps():
    run = read_kautham(SOLVED, HEADLESS.format(quick=91544, world=0), 1, 60.0)
    assert run["solved"] and run["claimed"] and not run["approximate"]
    assert run["time_s"] == 33.406689 and run["steps"] == 91544 and run["error"] == ""


def test_a_run_at_the_limit_with_an_approximate_solution_is_not_solved():
    run = read_kautham(AT_THE_LIMIT, HEADLESS.format(quick=67000, world=2), 1, 60.0)
    assert run["claimed"] and run["approximate"] and not run["solved"]
    assert run["time_s"] == 60.075404 and run["steps"] == 67002 and run["error"] == ""


def test_a_run_that_found_nothing_answers_not_solved_with_its_steps():
    run = read_kautham(NOTHING, "ODECOUNT quickstep 40 worldstep 0\n", 1, 60.0)
    assert not run["solved"] and not run["claimed"]
    assert run["time_s"] == 60.012 and run["steps"] == 40 and run["error"] == ""


def test_a_crashed_run_is_no_answer_and_says_how_it_ended():
    run = read_kautham(SETUP + "Info:    Solution found in 12.5 seconds\n", "free(): invalid "
                       "pointer\n", -6, 60.0)
    assert not run["solved"]
    assert run["error"].startswith("Kautham ended by signal 6")
    assert "no ODECOUNT line" in run["error"] and "free(): invalid pointer" in run["error"]


def test_a_run_killed_after_its_limit_is_no_answer():
    run = read_kautham(SETUP, "", None, 60.0)
    assert not run["solved"] and run["error"].startswith("no answer within the time limit")


def test_a_run_without_a_search_time_is_no_answer():
    run = read_kautham(SETUP + "Error: could not load\n", "ODECOUNT quickstep 0 worldstep 0\n",
                       4, 60.0)
    assert "no OMPL search time" in run["error"] and "Error: could not load" in run["error"]


def test_an_approximate_solution_well_before_the_limit_contradicts_kpiece_and_is_refused():
    early = AT_THE_LIMIT.replace("60.075404", "30.0")
    run = read_kautham(early, HEADLESS.format(quick=10, world=0), 1, 60.0)
    assert not run["solved"] and "approximate solution after 30 s" in run["error"]


def test_an_exact_solution_in_the_searchs_last_moment_is_solved():
    late = SOLVED.replace("33.406689", "59.9")
    run = read_kautham(late, HEADLESS.format(quick=10, world=0), 1, 60.0)
    assert run["solved"] and run["error"] == ""


def _pair(seed, solved, time_s, steps, error=""):
    return Run(seed, solved, time_s, steps, error)


def test_the_figures_of_both_sides_and_their_comparisons():
    kautham = [_pair(1, True, 20.0, 40000), _pair(2, False, 60.0, 90000),
               _pair(3, True, 30.0, 60000)]
    odin = [_pair(1, True, 10.0, 30000), _pair(2, True, 50.0, 100000),
            _pair(3, False, 60.0, 240000)]
    figures = figures_of(60.0, kautham, odin)
    # per seed, Odin's steps/s over Kautham's: 3000/2000, 2000/1500, 4000/2000
    assert figures["plan_car_steps_over_kautham"] == 1.5
    assert figures["plan_car_steps_per_s"] == 3000.0
    assert figures["plan_car_kautham_steps_per_s"] == 2000.0
    assert figures["plan_car_success"] == 0.667 and figures["plan_car_kautham_success"] == 0.667
    assert figures["plan_car_median_s"] == 30.0 and figures["plan_car_kautham_median_s"] == 25.0
    assert figures["plan_car_success_minus_kautham"] == 0.0
    assert figures["plan_car_time_over_kautham"] == 1.2


def test_the_steps_ratio_pairs_the_runs_by_seed_not_by_their_order():
    kautham = [_pair(2, False, 10.0, 10000), _pair(1, False, 10.0, 40000)]
    odin = [_pair(1, False, 10.0, 40000), _pair(2, False, 10.0, 20000)]
    figures = figures_of(10.0, kautham, odin)
    assert figures["plan_car_steps_over_kautham"] == 1.5    # ratios 1 and 2


def test_a_side_that_solved_nothing_has_the_limit_as_its_median():
    figures = figures_of(60.0, [_pair(1, False, 60.0, 1)], [_pair(1, True, 15.0, 1)])
    assert figures["plan_car_kautham_median_s"] == 60.0
    assert figures["plan_car_time_over_kautham"] == 0.25
    assert figures["plan_car_success_minus_kautham"] == 1.0


def test_a_run_without_an_answer_refuses_its_side_and_the_comparisons():
    kautham = [_pair(1, True, 20.0, 40000), _pair(2, False, None, None, "Kautham ended by "
                                                                       "signal 11")]
    odin = [_pair(1, True, 10.0, 30000), _pair(2, True, 10.0, 30000)]
    figures = figures_of(60.0, kautham, odin)
    assert figures["plan_car_success"] == 1.0 and figures["plan_car_steps_per_s"] == 3000.0
    for name in ("plan_car_kautham_success", "plan_car_kautham_median_s",
                 "plan_car_kautham_steps_per_s", "plan_car_steps_over_kautham",
                 "plan_car_success_minus_kautham", "plan_car_time_over_kautham"):
        assert isinstance(figures[name], Refused), name
        assert figures[name].reason == "1 of 2 runs gave no answer: Kautham ended by signal 11"


def test_without_kautham_only_odins_figures_come():
    figures = figures_of(60.0, None, [_pair(1, False, 60.0, 120000)])
    assert figures == {"plan_car_success": 0.0, "plan_car_median_s": 60.0,
                       "plan_car_steps_per_s": 2000.0}


def test_runs_read_back_from_their_records():
    records = [{"seed": 1, "solved": True, "time_s": 2.0, "steps": 10},
               {"seed": 2, "error": "gui.planning: boom"}]
    assert bench_car_kautham.runs_of(records) == [Run(1, True, 2.0, 10, ""),
                                                  Run(2, False, None, None, "gui.planning: boom")]


def _problem(tmp_path, parameters: str) -> pathlib.Path:
    path = tmp_path / "car.xml"
    path.write_text(f"<Problem><Planner><Parameters><Name>KPIECECarPlanner</Name>{parameters}"
                    "</Parameters></Planner></Problem>")
    return path


def test_the_time_limit_is_the_problems_own_else_kauthams_ode_default(tmp_path):
    own = _problem(tmp_path, '<Parameter name="_Max Planning Time"> 45 </Parameter>')
    assert bench_car_kautham.time_limit(own) == 45.0
    assert bench_car_kautham.time_limit(_problem(tmp_path, "")) == 60.0


def test_kautham_runs_without_a_display_and_with_the_step_counter():
    environment = bench_car_kautham.kautham_environment(
        {"DISPLAY": ":0", "LD_PRELOAD": "/x/other.so", "PATH": "/bin"})
    assert "DISPLAY" not in environment and environment["PATH"] == "/bin"
    odecount = bench_car_kautham.BUILD_DIR / "libodecount.so"
    assert environment["LD_PRELOAD"] == f"{odecount} /x/other.so"


def test_without_the_peer_built_the_run_says_so_in_one_line_and_measures_odin(
        monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(bench_car_kautham, "BUILD_DIR", tmp_path / "no_build")
    monkeypatch.setattr(bench_car_kautham, "SEEDS", 2)
    monkeypatch.setattr(bench_car_kautham, "_kautham", lambda *a: pytest.fail("Kautham ran"))
    monkeypatch.setattr(bench_car_kautham, "_odin", lambda problem, seed, limit: {
        "seed": seed, "solved": seed == 1, "time_s": 10.0 * seed, "steps": 20000 * seed})
    figures = bench_car_kautham.run(tmp_path)
    assert figures == {"plan_car_success": 0.5, "plan_car_median_s": 10.0,
                       "plan_car_steps_per_s": 2000.0}
    skipped = [line for line in capsys.readouterr().out.splitlines() if "skipped" in line]
    assert len(skipped) == 1 and "make bench-kautham" in skipped[0]
    written = json.loads((tmp_path / "car_kautham" / "runs.json").read_text())
    assert [r["seed"] for r in written["odin"]] == [1, 2] and written["kautham"] == []
