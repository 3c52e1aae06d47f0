"""Geometric benchmarks (issue 43): Kautham <Benchmark> files of problems without physics run in
`rosrun GUI benchmark` with OMPL's geometric planners over Odin's collision checks; OMPL's
statistics script reads the logs with the geometric benchmark's properties, a run repeats
`rosrun GUI plan` with its seed, the same runs on a 2-worker Dask cluster as serially, a query
that collides is one line in the log and summary, and bad input is one line before any run.
Our own puck problem (a 5 cm box in a 1 m square, a wall between start and goal) solves in
well under a second of search per run."""
from __future__ import annotations

import json
import pathlib
import shutil
import sqlite3
import subprocess
import sys

import pytest

from gui.errors import PlanningError
from gui.planning.benchmark import DaskRunner, prepare, run_serially, summary
from gui.planning.benchmark_log import GEOMETRIC_RUN_PROPERTIES, STATUS
from gui.planning.benchmark_run import RunResult, run_task
from gui.planning.benchmark_spec import command_line_experiments, read_benchmark_file
from kautham_files import write_problem

PUCK = """<?xml version="1.0"?><robot name="puck"><link name="base"><collision><geometry>
 <box size="0.05 0.05 0.05"/></geometry></collision></link></robot>"""
WALL = """<?xml version="1.0"?><robot name="wall"><link name="base"><collision><geometry>
 <box size="0.02 0.5 0.1"/></geometry></collision></link></robot>"""
CNTR = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="puck/X" value="0.5"/><DOF name="puck/Y" value="0.5"/></Offset>
 <Control name="puck/x" eigValue="1.0"><DOF name="puck/X" value="1.0"/></Control>
 <Control name="puck/y" eigValue="1.0"><DOF name="puck/Y" value="1.0"/></Control>
</ControlSet>"""
PROBLEM = """<?xml version="1.0"?><Problem>
 <Robot robot="puck.urdf"><Limits name="X" min="0" max="1"/><Limits name="Y" min="0" max="1"/>
  <Limits name="Z" min="0.05" max="0.05"/>
  <Home X="0.1" Y="0.1" Z="0.05" WX="0" WY="0" WZ="1" TH="0"/></Robot>
 <Obstacle obstacle="wall.urdf"><Home X="0.5" Y="0.25" Z="0.05" WX="0" WY="0" WZ="1" TH="0"/>
 </Obstacle>
 <Controls robot="puck.cntr"/>
 <Planner><Parameters><Name>PLANNER</Name>
  <Parameter name="Range">0.1</Parameter>
  <Parameter name="_Max Planning Time">5</Parameter></Parameters>
  <Queries><Query><Init>INIT</Init><Goal>0.6 0.2</Goal></Query></Queries></Planner>
</Problem>"""
# the wall spans x 0.49..0.51 m, y 0..0.5 m: from (0.4, 0.2) to (0.6, 0.2) the puck goes round
# its end; at (0.5, 0.3) it starts 35 mm into it
BENCHMARK = """<Benchmark Name="puck">
\t<Problem File="puck.xml" PlannerAlias="connect"/>
\t<Problem File="puck_rrt.xml" PlannerAlias="rrt"/>
\t<Parameter Name="maxTime" Value="4.0" />
\t<Parameter Name="runCount" Value="2" />
\t<Parameter Name="displayProgress" Value="false" />
\t<Parameter Name="filename" Value="puck.log" />
</Benchmark>
<Benchmark Name="wall">
\t<Problem File="puck_in_wall.xml" PlannerAlias="inwall"/>
\t<Parameter Name="runCount" Value="2" />
</Benchmark>
"""


def _puck(folder: pathlib.Path, name="puck.xml", planner="omplRRTConnect",
          init="0.4 0.2") -> pathlib.Path:
    return write_problem(folder, {"puck.urdf": PUCK, "wall.urdf": WALL, "puck.cntr": CNTR},
                         name, PROBLEM.replace("PLANNER", planner).replace("INIT", init))


@pytest.fixture
def benchmark_file(tmp_path) -> pathlib.Path:
    """Kautham's benchmark format over three puck problems: RRTConnect and RRT on the way
    round the wall, and one whose start is inside the wall."""
    _puck(tmp_path)
    _puck(tmp_path, "puck_rrt.xml", "omplRRT")
    _puck(tmp_path, "puck_in_wall.xml", init="0.5 0.3")
    path = tmp_path / "benchmarking.xml"
    path.write_text(BENCHMARK)
    return path


def _tool(*args):
    return subprocess.run([sys.executable, "-c", "from gui.tools.benchmark import main; "
                           "import sys; sys.exit(main())", *map(str, args)],
                          capture_output=True, text=True, timeout=300)


def _runs(out: pathlib.Path) -> list:
    return [RunResult.from_json(json.loads(line))
            for line in (out / "runs.jsonl").read_text().splitlines()[1:]]


@pytest.mark.slow
def test_a_geometric_benchmark_file_runs_and_ompl_s_script_reads_its_logs(benchmark_file,
                                                                         tmp_path):
    script = shutil.which("ompl_benchmark_statistics")
    assert script, "the OMPL wheel (tools/requirements.txt) installs ompl_benchmark_statistics"
    out = tmp_path / "out"
    run = _tool(benchmark_file, "--workers", "0", "--out", out)
    assert run.returncode == 0, run.stderr
    assert "Traceback" not in run.stderr
    results = _runs(out)
    database = tmp_path / "db.sqlite"
    subprocess.run([script, out / "puck.log", out / "wall.log", "-d", database], check=True,
                   capture_output=True, timeout=60)
    with sqlite3.connect(database) as db:
        planners = db.execute("SELECT name FROM plannerConfigs ORDER BY id").fetchall()
        columns = {c[1] for c in db.execute("PRAGMA table_info(runs)")}
        rows = db.execute("SELECT p.name, r.seed, r.solved, r.status, r.time, "
                          "r.collision_checks, r.graph_states, r.solution_length, "
                          "r.simplified_solution_length, r.simplified_solution_segments "
                          "FROM runs r JOIN plannerConfigs p ON r.plannerid = p.id").fetchall()
    assert planners == [("geometric_connect",), ("geometric_rrt",), ("geometric_inwall",)]
    assert {name.replace(" ", "_") for name, _, _ in GEOMETRIC_RUN_PROPERTIES} <= columns
    solved = {(f"geometric_{r.entry}", r.seed): r for r in results if r.solved}
    assert len(solved) == 4                          # both planners, both runs
    for name, seed, *values in rows:
        if name == "geometric_inwall":               # not searched: its status, no measures
            assert values[:2] == [0, STATUS.index("Invalid start")] and values[3] is None
            continue
        r = solved[(name, seed)]
        assert values[:3] == [1, STATUS.index("Exact solution"), pytest.approx(r.time_s)]
        assert values[3:5] == [r.geometric.collision_checks, r.geometric.graph_states]
        assert values[5] == pytest.approx(r.geometric.solution_length)
        assert values[6] == pytest.approx(r.geometric.simplified_length) and values[6] > 0.6
        assert values[6] <= values[5] + 1e-9 and values[7] == r.geometric.simplified_segments
    # the query that collides: one line in the summary and the log, no search
    data = json.loads((out / "summary.json").read_text())
    wall = data["experiments"][1]["planners"][0]
    assert (wall["runs"], wall["solved"], wall["failed"]) == (2, 0, 2)
    assert wall["errors"] == ["the query's start collides: puck is 35.0 mm into wall"]
    assert "not searched (Invalid start): the query's start collides: puck is 35.0 mm into " \
        "wall" in (out / "wall.log").read_text()
    assert data["plots"] == ["success_rate.png", "time_to_solution.png",
                             "collision_checks_per_s.png"]


def test_a_run_is_the_search_plan_makes_with_its_seed(tmp_path):
    """The benchmark's run 1 (seed 2) measures what `rosrun GUI plan --seed 2` finds: the same
    collision checks, graph, and path lengths."""
    problem = _puck(tmp_path)
    prepared = prepare(command_line_experiments([str(problem)], None, 2, 4.0))
    task = prepared.tasks[1]
    assert (task.geometric, task.planner, task.seed, task.refusal) == (True, "RRTConnect", 2, ())
    result = run_task(task)
    plan = subprocess.run([sys.executable, "-c", "from gui.tools.plan import main; import sys; "
                           "sys.exit(main())", str(problem), "--seed", "2", "--time", "4",
                           "--out", str(tmp_path / "p.task")], capture_output=True, text=True,
                          timeout=120)
    assert plan.returncode == 0, plan.stderr
    statistics = json.loads(plan.stdout[plan.stdout.index("{"):plan.stdout.rindex("}") + 1])
    assert result.solved and statistics["solved"]
    assert result.geometric.collision_checks == statistics["collision_checks"]
    assert result.geometric.graph_states == statistics["graph_states"]
    assert result.geometric.simplified_length == pytest.approx(statistics["path_length"])
    assert result.geometric.solution_length == pytest.approx(
        statistics["unsimplified_path_length"])


@pytest.mark.slow
def test_a_two_worker_dask_cluster_gives_exactly_the_serial_geometric_runs(tmp_path):
    experiments = command_line_experiments([str(_puck(tmp_path))], ["RRTConnect"], 3, 10.0)
    prepared = prepare(experiments, seed=5)
    serial, on_dask = [], []
    run_serially(prepared.tasks, serial.append, lambda: False)
    runner = DaskRunner(workers=2)
    try:
        assert len(runner.client.scheduler_info()["workers"]) == 2
        runner.run(prepared.tasks, on_dask.append, lambda: False)
    finally:
        runner.close()
    assert len(serial) == 3 and all(r.solved for r in serial)   # solved: no clock in them
    assert sorted(r.outcome() for r in on_dask) == sorted(r.outcome() for r in serial)
    assert len({r.digest for r in serial}) == 3                  # three different searches
    assert all(r.geometric.collision_checks > 0 for r in on_dask)


def test_a_stopped_geometric_run_ends_its_search_at_once(tmp_path):
    """SIGINT ends the run's search (solve's stop) well before STOP_GRACE_S would kill it: a
    wall across the whole square, so the search would go on for its 60 s."""
    import time

    from gui.planning.benchmark_run import STOP_GRACE_S, RunStopped
    (tmp_path / "across.urdf").write_text(WALL.replace("0.02 0.5 0.1", "0.02 2.2 0.1"))
    problem = _puck(tmp_path, "closed.xml")       # the wall from y = -0.85 to 1.35 m
    problem.write_text(problem.read_text().replace("wall.urdf", "across.urdf"))
    task = prepare(command_line_experiments([str(problem)], None, 1, 60.0)).tasks[0]
    started = time.monotonic()
    with pytest.raises(RunStopped):
        run_task(task, lambda: time.monotonic() - started > 3.0)
    assert time.monotonic() - started < 3.0 + STOP_GRACE_S / 2


def test_a_query_that_collides_is_recorded_without_a_search(tmp_path):
    problem = _puck(tmp_path, init="0.5 0.3")
    prepared = prepare(command_line_experiments([str(problem)], None, 2, 4.0))
    (_, (entry,)), = prepared.experiments
    assert entry.refusal == ("Invalid start",
                             "the query's start collides: puck is 35.0 mm into wall")
    results = {}
    run_serially(prepared.tasks, lambda r: results.setdefault(r.key, r), lambda: False)
    assert [(r.status, r.error, r.geometric) for r in results.values()] == \
        [("Invalid start", entry.refusal[1], None)] * 2
    planner = summary(prepared, results)["experiments"][0]["planners"][0]
    assert planner["errors"] == [entry.refusal[1]] and planner["success_rate"] == 0.0


def test_a_results_file_of_control_runs_still_reads():
    """runs.jsonl written before geometric runs (no "geometric" field): --resume reads it."""
    old = dict(experiment="e", entry="KPIECE1", run=0, planner="KPIECE1", seed=1, solved=True,
               approximate=False, status="Exact solution", time_s=2.0,
               solution_length_s=3.0, solution_difference_m=0.1, propagations=400,
               memory_mb=80.0, digest="ab", host="h", error="")
    result = RunResult.from_json(old)
    assert result.geometric is None and result.propagations_per_s == 200.0
    assert result.collision_checks_per_s is None
    assert RunResult.from_json(result.to_json()) == result


@pytest.mark.parametrize("args, what", [
    (["--planners", "RRTConnect,EST"], "unknown geometric planner 'EST'"),
    (["--min-control-steps", "3"], "--min-control-steps: only a search of a problem for one "
     "of Kautham's ODE planners takes it"),
    (["--goal-tolerance", "0.1"], "--goal-tolerance: only a search"),
])
def test_bad_input_for_a_geometric_problem_is_one_line_before_any_run(tmp_path, args, what):
    out = tmp_path / "out"
    run = _tool("--problem", _puck(tmp_path), *args, "--out", out)
    assert run.returncode == 2, run.stderr
    assert run.stderr.count("\n") == 1 and run.stderr.startswith("benchmark: error: ")
    assert what in run.stderr and "--problem" in run.stderr
    assert not (out / "runs.jsonl").exists()


def test_an_experiment_of_physics_and_geometric_problems_is_refused(kautham_dir, tmp_path):
    sphere = kautham_dir / "current_2025" / "demos" / "OMPL_ode_demos" / "Sphere" / "Sphere.xml"
    path = tmp_path / "mixed.xml"
    path.write_text(f'<Benchmark Name="mixed">\n<Problem File="{_puck(tmp_path)}"/>\n'
                    f'<Problem File="{sphere}"/>\n</Benchmark>\n')
    experiments = read_benchmark_file(str(path))
    with pytest.raises(PlanningError, match=f"{path}:3: experiment 'mixed' has physics and "
                       "geometric problems"):
        prepare(experiments)


def test_the_goal_bias_option_is_a_geometric_planner_s_goal_bias(tmp_path):
    prepared = prepare(command_line_experiments([str(_puck(tmp_path))], ["RRT"], 1, 2.0),
                       overrides={"goal_bias": 0.3})
    (_, (entry,)), = prepared.experiments
    assert dict(entry.common) == {"range": "0.1", "goal bias": "0.3", "resolution": "0.002"}


@pytest.mark.slow
def test_kautham_s_own_geometric_benchmark_file_runs_briefly(tmp_path):
    """Kautham's Cube-sPassage_R2 RRTConnect benchmark (three Ranges) from the whole corpus,
    one run each of 0.5 s: every run searched, no error, the log read by OMPL's script."""
    from gui.core.kautham.corpus import whole_corpus_dir, whole_missing_message
    corpus = whole_corpus_dir()
    if corpus is None:
        pytest.skip(whole_missing_message())
    file = corpus.joinpath("current_2025", "demos", "OMPL_geo_demos", "Cube-sPassage_R2",
                           "benchmarking_RRTconnect.xml")
    out = tmp_path / "out"
    run = _tool(file, "--runs", "1", "--time", "0.5", "--workers", "0", "--no-plots",
                "--out", out)
    assert run.returncode == 0, run.stderr
    results = _runs(out)
    assert sorted(r.entry for r in results) == ["RRTconnect_002", "RRTconnect_005",
                                                "RRTconnect_010"]
    assert all(r.error == "" and r.geometric.collision_checks > 0 for r in results)
    assert all(r.planner == "RRTConnect" for r in results)
    log = (out / "resultRRTconnect.log").read_text()
    assert "geometric_RRTconnect_002" in log and "range = 0.02" in log
    subprocess.run([shutil.which("ompl_benchmark_statistics"), out / "resultRRTconnect.log",
                    "-d", tmp_path / "db.sqlite"], check=True, capture_output=True, timeout=60)


def test_a_failed_run_s_reason_is_its_own_line_not_what_follows_it():
    from gui.planning.benchmark_run import _failure
    stderr = "not used: x\nrun: collision checking failed: why\nnanobind: leaked 3 types!\n" \
        "See https://nanobind.readthedocs.io/en/latest/refleaks.html\n"
    assert _failure(stderr, 2) == "run: collision checking failed: why"
    assert _failure("Segmentation fault\n", -11) == "Segmentation fault"
    assert _failure("", -9) == "exit status -9"


def test_max_mem_ends_a_geometric_search_with_its_reason(tmp_path):
    """maxMem as OMPL's Benchmark applies it ends the search; solve keeps nothing of a search
    it was asked to stop, so the run says why and has no measures (not a crash)."""
    task = prepare(command_line_experiments([str(_puck(tmp_path))], None, 1, 30.0,
                                            max_mem=0.25)).tasks[0]
    result = run_task(task)
    assert (result.status, result.solved, result.geometric) == ("Timeout", False, None)
    assert result.error == "ended by maxMem: the search grew by more than 0.25 MB"
