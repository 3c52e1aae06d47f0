"""Kautham 5.1.1 as the geometric planners' peer (tools/bench/kautham_peer.py): the driver's
output read, a run's failures said, where the driver is expected and how it is built; with a
stand-in driver (a shell script), the arguments passed and the time limit enforced; with the
real peer built (`make bench-kautham`), one solve of the TX90 demo whose path Odin reads."""
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools" / "bench"))

import kautham_peer  # noqa: E402

TX90 = ("current_2025", "demos", "OMPL_geo_demos", "TX90_IOC", "OMPL_RRTConnect_TX90_TwoCan.xml")
SOLVED = """PEER seed 7
Info:    RRTConnect: Starting planning with 1 states already in datastructure
PEER family 1 planner omplRRTConnect
Info:    RRTConnect: Created 13 states (6 start + 7 goal)
EXACT_SOLUTION found
PEER solved 1 wall 0.0213
PEER states 9
"""
NOT_SOLVED = """PEER seed 3
PEER family 1 planner omplRRT
APPROXIMATE_SOLUTION - No exact solution found
PEER solved 0 wall 1.002
"""
STAND_IN = """#!/usr/bin/env bash
# stands in for kautham-peer-solve: says what it was given the driver's way, sleeps $SLEEP
while [ $# -gt 0 ]; do
  case "$1" in --seed) seed=$2; shift 2;; --time) time=$2; shift 2;;
    --task) task=$2; shift 2;; *) problem=$1; shift;; esac
done
echo "PEER seed $seed"
echo "PEER family 1 planner omplRRTConnect"
sleep "${SLEEP:-0}"
echo "PEER solved 1 wall $time"
echo "PEER states 2"
echo "<Task name='$(basename "$problem")' cwd='$PWD'></Task>" > "$task"
"""


def test_a_solved_run_is_read_from_the_peer_lines_among_ompls(tmp_path):
    task = tmp_path / "path.xml"
    task.write_text("<Task/>")
    run = kautham_peer.PeerRun.from_output(SOLVED, "a warning\n", 0, task)
    assert (run.solved, run.failed, run.error) == (True, False, "")
    assert (run.seed, run.family, run.planner) == (7, "1", "omplRRTConnect")
    assert (run.wall_s, run.states, run.returncode, run.task_file) == (0.0213, 9, 0, task)


def test_a_run_not_solved_is_an_answer_with_its_time_and_no_path(tmp_path):
    task = tmp_path / "stale.xml"
    task.write_text("<Task/>")               # not this run's: it did not solve
    run = kautham_peer.PeerRun.from_output(NOT_SOLVED, "", 1, task)
    assert (run.solved, run.failed, run.wall_s, run.states, run.task_file) == \
        (False, False, 1.002, None, None)


APPROXIMATE_BUT_TRUE = """PEER seed 2
PEER family 2 planner omplRRT
Info:    ProblemDefinition: Adding approximate solution from planner RRT
APPROXIMATE_SOLUTION - No exact solution found
Difference = 0.0525639
No solution found
PEER solved 1 wall 15.1277
PEER states 200
"""


def test_an_approximate_solution_is_not_solved_though_the_driver_says_so(tmp_path):
    """Kautham 5.1.1's library answered true after an approximate solution (UR3e, seed 2:
    the path ends 5 cm from the goal); its console's words decide."""
    task = tmp_path / "path.xml"
    task.write_text("<Task/>")
    run = kautham_peer.PeerRun.from_output(APPROXIMATE_BUT_TRUE, "", 0, task)
    assert (run.solved, run.failed, run.task_file, run.wall_s) == (False, False, None, 15.1277)


def test_a_problem_kautham_cannot_load_is_a_failed_run_saying_why_with_stderr_s_tail():
    stderr = "\n".join(f"line {k}" for k in range(20)) + "\n"
    run = kautham_peer.PeerRun.from_output("PEER seed 1\nPEER load failed\n", stderr, 3)
    assert not run.solved and run.failed and run.returncode == 3
    assert run.error.startswith("Kautham could not load the problem | PEER load failed")
    assert "line 19" in run.error and "line 11" not in run.error


def test_an_exit_status_that_disagrees_with_the_peer_line_is_a_failure_not_a_solve():
    run = kautham_peer.PeerRun.from_output(SOLVED, "", 1)
    assert not run.solved and run.failed and "status 1" in run.error
    error = kautham_peer.PeerRun.from_output("Error: no robot\nsomething\n", "", 4)
    assert error.failed and error.error == "Kautham raised an error | Error: no robot"


def test_why_not_names_where_the_driver_is_expected_and_the_make_target(tmp_path):
    assert kautham_peer.peer_binary(tmp_path) is None
    why = kautham_peer.why_not(tmp_path)
    assert str(tmp_path / "kautham-peer-solve") in why and "make bench-kautham" in why
    with pytest.raises(FileNotFoundError, match="make bench-kautham"):
        kautham_peer.solve(tmp_path / "p.xml", 1, 1.0, tmp_path / "out", build_dir=tmp_path)


def _stand_in(tmp_path: pathlib.Path) -> pathlib.Path:
    build = tmp_path / "build"
    build.mkdir()
    driver = build / "kautham-peer-solve"
    driver.write_text(STAND_IN)
    driver.chmod(0o755)
    return build


def test_solve_passes_the_seed_time_and_task_file_and_runs_in_the_out_folder(tmp_path):
    build, out = _stand_in(tmp_path), tmp_path / "out"
    run = kautham_peer.solve(tmp_path / "problem.xml", 5, 2.5, out, build_dir=build)
    assert (run.solved, run.seed, run.wall_s, run.states) == (True, 5, 2.5, 2)
    assert run.task_file == out / "problem_kautham_seed5.xml"
    assert run.task_file.read_text() == f"<Task name='problem.xml' cwd='{out}'></Task>\n"


def test_a_run_past_its_time_limit_and_margin_is_killed_and_failed(tmp_path, monkeypatch):
    monkeypatch.setattr(kautham_peer, "MARGIN_S", 0.5)
    monkeypatch.setenv("SLEEP", "30")
    run = kautham_peer.solve(tmp_path / "problem.xml", 1, 0.1, tmp_path / "out",
                             build_dir=_stand_in(tmp_path))
    assert not run.solved and run.failed and run.returncode is None
    assert "killed" in run.error and run.task_file is None


def test_the_time_limit_is_the_problems_max_planning_time_else_kauthams_ten_s(tmp_path):
    problem = tmp_path / "p.xml"
    problem.write_text("<Problem><Planner><Parameters><Name>omplRRT</Name>"
                       "<Parameter name='Max Planning Time'>3</Parameter>"
                       "<Parameter name='_Max Planning Time'> 1.5 </Parameter>"
                       "</Parameters></Planner></Problem>")
    assert kautham_peer.own_time_limit(problem) == 1.5
    problem.write_text("<Problem><Planner><Parameters><Name>omplRRT</Name>"
                       "<Parameter name='Max Planning Time'>3</Parameter>"
                       "</Parameters></Planner></Problem>")
    assert kautham_peer.own_time_limit(problem) == kautham_peer.KAUTHAM_DEFAULT_TIME_S == 10.0


def test_build_refuses_a_missing_peer_folder_in_one_line(tmp_path, capsys):
    assert kautham_peer.build(tmp_path / "build", peer=tmp_path / "nowhere") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(tmp_path / "nowhere") in err
    assert kautham_peer.PEER_ENVIRONMENT in err and not (tmp_path / "build").exists()


def test_build_does_nothing_when_the_peer_is_built(tmp_path, capsys):
    for name in kautham_peer.BUILT:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("")
    assert kautham_peer.build(tmp_path, peer=tmp_path / "nowhere") == 0
    assert "nothing to do" in capsys.readouterr().out


def test_the_peer_folder_is_the_variables_else_beside_the_clone(monkeypatch, tmp_path):
    monkeypatch.setenv(kautham_peer.PEER_ENVIRONMENT, str(tmp_path))
    assert kautham_peer.peer_dir() == tmp_path
    monkeypatch.delenv(kautham_peer.PEER_ENVIRONMENT)
    assert kautham_peer.peer_dir() == ROOT.parent / "shared" / "peers" / "kautham"


def test_kautham_solves_the_tx90_demo_with_seed_1_and_odin_reads_its_path(kautham_dir,
                                                                         tmp_path):
    if kautham_peer.peer_binary() is None:
        pytest.skip(kautham_peer.why_not())
    from gui.core.kautham.problem import load_problem
    from gui.core.kautham.solutions import TASK, read_solution
    problem_file = kautham_dir.joinpath(*TX90)
    run = kautham_peer.solve(problem_file, 1, None, tmp_path)
    assert run.solved and not run.failed, run.error
    assert (run.seed, run.planner, run.returncode) == (1, "omplRRTConnect", 0)
    assert 0 < run.wall_s < kautham_peer.own_time_limit(problem_file)
    solution = read_solution(run.task_file, load_problem(problem_file))
    assert solution.format == TASK and solution.waypoint_count == run.states >= 2
