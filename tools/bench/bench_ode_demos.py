"""Kautham's four physics demos benchmarked as a planning researcher would (issue 29):
``rosrun GUI benchmark`` on Kautham <Benchmark> files with one experiment per demo (the
Sphere, k-PMPSphere, the chain, the car), each at its problem's own ``_Max Planning Time``
(150, 150, 90 and 120 s), 10 runs of each of KPIECE1, RRT and EST (seeds 1 to 10), on a local
Dask cluster of one worker per core.

  bench_<demo>_<planner>_success   fraction of the 10 runs that reached the goal region
                                   (demo: sphere, kpmpsphere, chain, car; planner lower case)

The car runs with ``--max-control-steps 400`` (a control held up to 20 s instead of the
problem's 2.5 s; docs/PLANNING.md, "The car's success rate"): under the problem's own 5 to 50
steps KPIECE1 solves it about 2 runs in 10. It is a second ``benchmark`` command (the search
settings of the command line apply to every problem of a file); the plots cover both.

The benchmark files are written at run time into out/bench/ode_demos/ (``benchmark_file``): the
Sphere demos live in the Kautham corpus ($ODIN_KAUTHAM_DIR), the car and the chain in
tools/kautham/ode_demos, so their ``File`` attributes are absolute paths. The logs and runs land in
physics/ and car/ there, the summary of both and the plots (success_rate.png,
time_to_solution.png, propagations_per_s.png) in ode_demos/; docs/PLANNING.md shows them.
``ODIN_BENCH_DEMO_RUNS`` and ``ODIN_BENCH_DEMO_TIME`` (s) shorten the benchmark for development (the
figures then measure that shorter benchmark), and ``ODIN_BENCH_DEMO_WORKERS`` sets the local Dask
workers (default: one per core). A ``make bench`` stopped in the middle of it goes on from the runs
it finished (``_benchmark``).
"""
import json
import os
import pathlib
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
PLANNERS = ("KPIECE1", "RRT", "EST")
RUNS = int(os.environ.get("ODIN_BENCH_DEMO_RUNS", 10))
WORKERS = os.environ.get("ODIN_BENCH_DEMO_WORKERS")


def demos(kautham: pathlib.Path) -> tuple:
    """(experiment name, problem path, its own _Max Planning Time s) of each demo."""
    sphere = kautham / "current_2025" / "demos" / "OMPL_ode_demos" / "Sphere"
    ode = ROOT / "tools" / "kautham" / "ode_demos" / "demos" / "OMPL_ode_demos"
    return (("sphere", sphere / "Sphere.xml", 150),
            ("kpmpsphere", sphere / "k-PMPSphere.xml", 150),
            ("chain", ode / "Chain" / "k-PMPChain.xml", 90),
            ("car", ode / "Car" / "k-PMPCar.xml", 120))


CAR_SETTINGS = ("--max-control-steps", "400")
"""The car's search settings: a control may last long enough to turn it a quarter at the
speeds OMPL's uniform control sampler draws (100 to 150 steps of 0.05 s at full steering and
full speed; the mean speed drawn is a quarter of full speed forward)."""


def benchmark_file(path: pathlib.Path, demos_run: tuple) -> None:
    """Kautham's <Benchmark> format, one experiment per demo at its own time limit."""
    short = os.environ.get("ODIN_BENCH_DEMO_TIME")
    parts = []
    for name, problem, own_s in demos_run:
        seconds = float(short) if short else own_s
        parts.append(f"""<Benchmark Name="{name}">
\t<Problem File="{problem}" PlannerAlias="{name}"/>
\t<Parameter Name="maxTime" Value="{seconds:g}" />
\t<Parameter Name="maxMem" Value="4096.0" />
\t<Parameter Name="runCount" Value="{RUNS}" />
\t<Parameter Name="displayProgress" Value="true" />
\t<Parameter Name="filename" Value="{name}.log" />
</Benchmark>
""")
    path.write_text("".join(parts))


def _benchmark(file: pathlib.Path, where: pathlib.Path, settings: tuple) -> None:
    """``rosrun GUI benchmark FILE`` into ``where``; it goes on with the runs a stopped
    ``make bench`` left there (``--resume``) when they are of the same benchmark (problems'
    bytes, planners, seeds, limits), and starts again when they are not."""
    command = [sys.executable, str(ROOT / "Odin" / "GUI" / "scripts" / "benchmark"), str(file),
               "--planners", ",".join(PLANNERS), *settings,
               *(("--workers", WORKERS) if WORKERS else ()), "--out", str(where), "--no-plots"]
    if (where / "runs.jsonl").exists():
        resumed = subprocess.run(command + ["--resume"], stdout=subprocess.DEVNULL,
                                 stderr=subprocess.PIPE, text=True)
        if resumed.returncode == 0:
            return
        if "written for another benchmark" not in resumed.stderr:
            raise RuntimeError(f"benchmark --resume failed: {resumed.stderr.strip()}")
        (where / "runs.jsonl").unlink()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)


def run(out_dir: pathlib.Path) -> dict:
    from gui.core.kautham.corpus import corpus_dir, missing_message
    from gui.planning.benchmark_plots import write_plots
    from gui.planning.benchmark_run import RunResult
    kautham = corpus_dir()
    if kautham is None:
        raise RuntimeError(missing_message())
    folder = out_dir / "ode_demos"
    every = demos(kautham)
    summaries, results = [], {}
    for part, chosen, settings in (("physics", every[:3], ()), ("car", every[3:], CAR_SETTINGS)):
        where = folder / part
        where.mkdir(parents=True, exist_ok=True)
        file = where / f"{part}.xml"
        benchmark_file(file, chosen)
        _benchmark(file, where, settings)
        summaries.append(json.loads((where / "summary.json").read_text()))
        for line in (where / "runs.jsonl").read_text().splitlines()[1:]:
            result = RunResult.from_json(json.loads(line))
            results[result.key] = result
    summary = dict(seed=1, experiments=[e for s in summaries for e in s["experiments"]])
    write_plots(str(folder), summary, results)
    (folder / "summary.json").write_text(json.dumps(summary, indent=1))
    figures = {}
    for experiment in summary["experiments"]:
        for planner in experiment["planners"]:
            figures[f"bench_{experiment['name']}_{planner['planner'].lower()}_success"] = \
                planner["success_rate"]
    return figures
