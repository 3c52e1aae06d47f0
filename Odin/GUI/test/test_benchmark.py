"""Planning benchmarks (issue 29): Kautham's <Benchmark> files, OMPL's log read by OMPL's own
statistics script, the same runs on a 2-worker Dask cluster as serially, bad input refused
before any run, and Ctrl-C keeping the finished runs for --resume."""

import json
import os
import pathlib
import shutil
import signal
import socket
import sqlite3
import subprocess
import sys
import time

import pytest

from gui.errors import PlanningError, ProblemError
from gui.planning.benchmark import DaskRunner, ResultStore, prepare, run_serially
from gui.planning.benchmark_log import RUN_PROPERTIES, STATUS
from gui.planning.benchmark_run import RunResult
from gui.planning.benchmark_spec import (Experiment, Request, Row, command_line_experiments,
                                         read_benchmark_file, with_planners)

SPHERE = ("current_2025", "demos", "OMPL_ode_demos", "Sphere", "Sphere.xml")
BENCHMARK_FILE = """<?xml version="1.0"?>
<Benchmark Name="spheres">
\t<Problem File="Sphere/Sphere.xml" PlannerAlias="kp"/>
\t<Problem File="Sphere/k-PMPSphere.xml" PlannerAlias="walls"/>
\t<Parameter Name="maxTime" Value="12.5" />
\t<Parameter Name="maxMem" Value="8000.0" />
\t<Parameter Name="runCount" Value="3" />
\t<Parameter Name="displayProgress" Value="false" />
\t<Parameter Name="filename" Value="result.log" />
</Benchmark>
<Benchmark>
\t<Problem File="Sphere/Sphere.xml" PlannerAlias=""/>
</Benchmark>
"""


def _tool(*args, **kwargs):
    return subprocess.run([sys.executable, "-c", "from gui.tools.benchmark import main; "
                           "import sys; sys.exit(main())", *args],
                          capture_output=True, text=True, timeout=300, **kwargs)


@pytest.fixture
def demos(kautham_dir, tmp_path):
    """A benchmark file written from Kautham's format beside the corpus's Sphere demos (the
    corpus is read-only: the file lives in a copy of the folder's layout)."""
    folder = tmp_path / "OMPL_ode_demos"
    shutil.copytree(kautham_dir.joinpath(*SPHERE[:-2]), folder)
    shutil.copytree(kautham_dir.joinpath(*SPHERE[:2], "models"), tmp_path / "models")
    path = folder / "benchmarking.xml"
    path.write_text(BENCHMARK_FILE)
    return path


def test_a_benchmark_file_written_from_kautham_s_format_parses(demos):
    first, second = read_benchmark_file(str(demos))
    folder = demos.parent
    assert first.name == "spheres" and first.log_name == "result.log"
    assert first.rows == (Row(str(folder / "Sphere" / "Sphere.xml"), None, "kp",
                              f"{demos}:3"),
                          Row(str(folder / "Sphere" / "k-PMPSphere.xml"), None, "walls",
                              f"{demos}:4"))
    assert first.request == Request(max_time=12.5, max_mem=8000.0, run_count=3,
                                    display_progress=False, filename="result.log")
    # Kautham's defaults: "NO_NAME", OMPL's Request (5 s, 4096 MB, 100 runs)
    assert second.name == "NO_NAME" and second.log_name == "NO_NAME.log"
    assert second.request == Request()
    assert second.rows[0].name("KPIECE1") == "KPIECE1"
    # --planners puts each planner on every row; the alias then names the row's problem
    renamed = with_planners((first,), ["RRT", "EST"])[0]
    assert [r.name(r.planner) for r in renamed.rows] == ["kp-RRT", "kp-EST", "walls-RRT",
                                                         "walls-EST"]


@pytest.mark.parametrize("text, where, what", [
    ("<Benchmark><Parameter Name='maxTime' Value='1'/></Benchmark>", 1, "no <Problem"),
    ("<Benchmark>\n<Problem PlannerAlias='a'/></Benchmark>", 2, "no attribute File="),
    ("<Benchmark><Problem File='p.xml'/>\n\n<Parameter Name='maxtim' Value='1'/></Benchmark>",
     3, "not one of Kautham's benchmark parameters"),
    ("<Benchmark><Problem File='p.xml'/>\n<Parameter Name='runCount'/></Benchmark>", 2,
     "no Value="),
    ("<Benchmark><Problem File='p.xml'/>\n<Parameter Name='runCount' Value='2.5'/>"
     "</Benchmark>", 2, "whole number"),
    ("<Benchmark><Problem File='p.xml'/>\n<Parameter Name='maxTime' Value='-1'/>"
     "</Benchmark>", 2, "positive"),
    ("<Experiment/>", 1, "no <Benchmark>"),
])
def test_a_malformed_benchmark_file_is_refused_with_its_line(tmp_path, text, where, what):
    path = tmp_path / "b.xml"
    path.write_text(text)
    with pytest.raises(ProblemError) as error:
        read_benchmark_file(str(path))
    assert error.value.line == where and what in str(error.value)


@pytest.mark.slow
def test_the_log_reads_into_ompl_s_database_with_ompl_s_own_script(kautham_dir, tmp_path):
    script = shutil.which("ompl_benchmark_statistics")
    assert script, "the OMPL wheel (tools/requirements.txt) installs ompl_benchmark_statistics"
    out = tmp_path / "out"
    run = _tool("--problem", str(kautham_dir.joinpath(*SPHERE)), "--planners", "KPIECE1",
                "--runs", "2", "--time", "60", "--workers", "0", "--out", str(out),
                "--no-plots")
    assert run.returncode == 0, run.stderr
    database = tmp_path / "db.sqlite"
    subprocess.run([script, str(out / "Sphere.log"), "-d", str(database)], check=True,
                   capture_output=True, timeout=60)
    results = [RunResult.from_json(json.loads(line))
               for line in (out / "runs.jsonl").read_text().splitlines()[1:]]
    with sqlite3.connect(database) as db:
        experiment = db.execute("SELECT name, timelimit, runcount, seed, version "
                                "FROM experiments").fetchall()
        planners = db.execute("SELECT name FROM plannerConfigs").fetchall()
        columns = [c[1] for c in db.execute("PRAGMA table_info(runs)")]
        runs = db.execute("SELECT seed, solved, status, time, propagations, "
                          "solution_length, approximate_solution FROM runs ORDER BY seed"
                          ).fetchall()
    assert experiment == [("Sphere", 60.0, 2, "1", "OMPL 2.0.1")]
    assert planners == [("control_KPIECE1",)]
    assert {name.replace(" ", "_") for name, _, _ in RUN_PROPERTIES} <= set(columns)
    for row, result in zip(runs, sorted(results, key=lambda r: r.seed)):
        assert row[:3] == (result.seed, int(result.solved), STATUS.index(result.status))
        assert row[3] == pytest.approx(result.time_s)
        assert row[4] == result.propagations
        assert row[5] == pytest.approx(result.solution_length_s)
        assert row[6] == int(result.approximate)


@pytest.mark.slow
def test_a_two_worker_dask_cluster_gives_exactly_the_serial_runs(kautham_dir, tmp_path):
    experiments = command_line_experiments([str(kautham_dir.joinpath(*SPHERE))], ["KPIECE1"],
                                           8, 120.0)
    prepared = prepare(experiments, seed=3)
    serial, on_dask = [], []
    run_serially(prepared.tasks, serial.append, lambda: False)
    runner = DaskRunner(workers=2)
    try:
        assert len(runner.client.scheduler_info()["workers"]) == 2
        runner.run(prepared.tasks, on_dask.append, lambda: False)
    finally:
        runner.close()
    assert len(serial) == 8 and all(r.solved for r in serial)   # solved: no clock in them
    assert sorted(r.outcome() for r in on_dask) == sorted(r.outcome() for r in serial)
    assert len({r.digest for r in serial}) == 8                  # eight different searches


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("args, what", [
    (["--problem", "/nonexistent/p.xml"], "/nonexistent/p.xml: no such file"),
    (["--planners", "KPIECE1,PRM"], "planner 'PRM': unknown planner"),
    (["--planners", "SST"], "cannot construct"),
    (["--scheduler", "tcp://127.0.0.1:{port}", "--scheduler-timeout", "1"],
     "no Dask scheduler answers"),
    (["--scheduler-timeout", "1"], "only with --scheduler"),
    (["--runs", "0"], "--runs 0"),
    (["--max-mem", "-1"], "--max-mem -1: must be positive"),
    (["--max-control-steps", "0"], "--max-control-steps 0: at least 1"),
    (["--min-control-steps", "9", "--max-control-steps", "3"], "is above"),
])
def test_bad_input_is_one_line_before_any_run(kautham_dir, tmp_path, args, what):
    args = [a.format(port=_free_port()) for a in args]
    if "--problem" not in args:
        args = ["--problem", str(kautham_dir.joinpath(*SPHERE))] + args
    out = tmp_path / "out"
    started = time.monotonic()
    run = _tool(*args, "--time", "30", "--out", str(out))
    assert run.returncode == 2
    assert run.stderr.count("\n") == 1 and run.stderr.startswith("benchmark: error: ")
    assert what in run.stderr
    assert not (out / "runs.jsonl").exists()
    assert time.monotonic() - started < 60


def test_a_missing_problem_of_a_benchmark_file_names_its_row(demos, tmp_path):
    text = BENCHMARK_FILE.replace("k-PMPSphere.xml", "gone.xml")
    demos.write_text(text)
    run = _tool(str(demos), "--out", str(tmp_path / "out"))
    assert run.returncode == 2
    assert f"{demos}:4: problem" in run.stderr and "gone.xml: no such file" in run.stderr


def test_resuming_another_benchmark_s_results_is_refused(kautham_dir, tmp_path):
    sphere = str(kautham_dir.joinpath(*SPHERE))
    one = prepare(command_line_experiments([sphere], ["KPIECE1"], 2, 5.0))
    other = prepare(command_line_experiments([sphere], ["KPIECE1"], 2, 6.0))
    ResultStore(str(tmp_path), one, resume=False)
    with pytest.raises(Exception) as error:
        ResultStore(str(tmp_path), one, resume=False)
    assert "--resume" in str(error.value)
    with pytest.raises(Exception) as error:
        ResultStore(str(tmp_path), other, resume=True)
    assert "written for another benchmark" in str(error.value)


def test_an_experiment_with_two_planners_of_one_name_is_refused(kautham_dir):
    sphere = str(kautham_dir.joinpath(*SPHERE))
    experiment = Experiment("e", (Row(sphere, None, "a"), Row(sphere, None, "a")), Request())
    with pytest.raises(PlanningError, match="already has a planner named 'a'"):
        prepare([experiment])


def _runs_of_our_module(mark: str) -> list:
    """Run processes (gui.planning.benchmark_run) whose environment holds ``mark``: those of
    one benchmark, not those other tests run at the same time on other workers."""
    found = subprocess.run(["pgrep", "-f", "gui.planning.benchmark_run"], capture_output=True,
                           text=True).stdout.split()
    ours = []
    for pid in found:
        try:
            environment = pathlib.Path(f"/proc/{pid}/environ").read_bytes()
        except OSError:
            continue                            # ended meanwhile
        if mark.encode() in environment.split(b"\0"):
            ours.append(pid)
    return ours


@pytest.mark.slow
def test_ctrl_c_stops_the_workers_runs_and_keeps_the_finished_ones(kautham_dir, tmp_path):
    out = tmp_path / "out"
    options = ["--problem", str(kautham_dir.joinpath(*SPHERE)), "--planners", "KPIECE1",
               "--runs", "6", "--time", "120", "--out", str(out), "--no-plots"]
    mark = f"ODIN_TEST_BENCHMARK={os.getpid()}-{time.monotonic_ns()}"
    tool = subprocess.Popen([sys.executable, "-c", "from gui.tools.benchmark import main; "
                             "import sys; sys.exit(main())",
                             *options, "--workers", "2"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            env=dict(os.environ, ODIN_TEST_BENCHMARK=mark.split("=", 1)[1]),
                            start_new_session=True)     # its own group, as a terminal's job
    try:
        for line in tool.stderr:                        # the first finished run
            if "runs done" in line:
                break
        assert _runs_of_our_module(mark), "no run of this benchmark found running"
        os.killpg(tool.pid, signal.SIGINT)              # what a terminal's Ctrl-C does
        started = time.monotonic()
        _, err = tool.communicate(timeout=60)
    finally:
        if tool.poll() is None:
            os.killpg(tool.pid, signal.SIGKILL)
    assert tool.returncode == 130, err
    assert time.monotonic() - started < 30
    assert "--resume goes on" in err and "Traceback" not in err, err
    kept = (out / "runs.jsonl").read_text().splitlines()[1:]
    assert 1 <= len(kept) < 6
    for _ in range(50):                                 # no run left behind
        if not _runs_of_our_module(mark):
            break
        time.sleep(0.1)
    assert not _runs_of_our_module(mark)
    resumed = _tool(*options, "--workers", "0", "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert f"{6 - len(kept)} runs to do of 6" in resumed.stdout
    results = (out / "runs.jsonl").read_text().splitlines()[1:]
    assert sorted(json.loads(r)["run"] for r in results) == list(range(6))


@pytest.mark.slow
def test_a_scheduler_without_workers_is_refused_before_any_run(kautham_dir, tmp_path):
    from distributed import LocalCluster
    with LocalCluster(n_workers=0, processes=False, protocol="tcp", host="127.0.0.1",
                      dashboard_address=None) as cluster:
        run = _tool("--problem", str(kautham_dir.joinpath(*SPHERE)), "--scheduler",
                    cluster.scheduler_address, "--scheduler-timeout", "1.5",
                    "--out", str(tmp_path / "out"))
    assert run.returncode == 2 and "has no worker after 1.5 s" in run.stderr, run.stderr
    assert run.stderr.count("\n") == 1
    assert not (tmp_path / "out" / "runs.jsonl").exists()


def test_a_problem_s_bundle_holds_the_files_it_reads_and_no_cache(kautham_dir, tmp_path,
                                                                  monkeypatch):
    from gui.planning.benchmark_run import problem_bundle
    cache = tmp_path / "cache"
    cache.mkdir()
    (cache / "entry.npz").write_bytes(b"derived")
    monkeypatch.setenv("ODIN_CACHE_DIR", str(cache))
    sphere = kautham_dir.joinpath(*SPHERE)

    def load():
        (cache / "entry.npz").read_bytes()              # what a shape cache would read
        from gui.core.kautham.problem import load_problem
        load_problem(str(sphere))

    relative, files = problem_bundle(load, str(sphere))
    names = dict(files)
    assert relative == "OMPL_ode_demos/Sphere/Sphere.xml"
    assert names[relative] == sphere.read_bytes()
    assert "models/robots/OpenDERobots/SphereDE.urdf" in names
    assert "OMPL_ode_demos/Sphere/controls/sp3.cntr" in names
    assert not any("npz" in name for name in names)


def test_max_mem_ends_a_search_as_its_time_limit_would(kautham_dir):
    """maxMem as OMPL's Benchmark applies it: the search ends once the run's process has grown
    by more than maxMem MB of resident memory, and the run is recorded like one the clock
    ended (the walls demo with EST keeps searching for its whole minute without it)."""
    from gui.planning.benchmark_run import run_task
    walls = str(kautham_dir.joinpath(*SPHERE[:-1], "k-PMPSphere.xml"))
    experiments = command_line_experiments([walls], ["EST"], 1, 60.0, max_mem=0.25)
    task = prepare(experiments, seed=1).tasks[0]
    assert task.memory_limit_mb == 0.25
    result = run_task(task)
    assert result.error == "" and result.status != "Crash", result
    assert result.time_s < 20 and result.propagations > 0 and not result.solved


def test_the_memory_watch_fires_once_the_process_grew_by_the_limit():
    from gui.planning.bridge import MEMORY_CHECK_S, _memory_watch
    over = _memory_watch(8.0)
    assert not over()
    grown = bytearray(32 * 2 ** 20)         # resident once written
    grown[::4096] = b"x" * len(grown[::4096])
    time.sleep(MEMORY_CHECK_S * 1.5)
    assert over()
    assert not _memory_watch(None)()
    with pytest.raises(PlanningError, match="must be positive"):
        _memory_watch(0.0)
