"""``rosrun GUI benchmark``: Kautham benchmark files (or the same from the command line) run as
seeded searches, through Odin's physics (a problem for one of Kautham's ODE planners) or over
Odin's geometry (any other: OMPL's geometric planners), here or on a Dask cluster; OMPL's logs,
a JSON summary and plots (docs/PLANNING.md). Exit status: 0 done, 2 with one line on bad input
or a failure, 130 on Ctrl-C (the finished runs kept: ``--resume`` goes on from them)."""
from __future__ import annotations

import argparse
import datetime
import json
import logging
import os
import sys
import time
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

from gui.errors import GuiError
from gui.planning.benchmark import SCHEDULER_TIMEOUT_S
from gui.tools.common import ToolParser, count, one_line_errors, reading, seconds
from odin_common.tool import stop_on_ctrl_c

TOOL = "benchmark"

MAX_RUNS = 1_000_000
"""Runs per planner one benchmark may ask (each is a search of up to its time limit)."""


def _parser() -> argparse.ArgumentParser:
    from gui.planning.bridge import MAX_SEED, PLANNERS
    from gui.planning.geometric import OMPL_PLANNERS
    from gui.planning.parallel import MAX_SEARCHES
    from gui.planning.problem import MAX_CONTROL_STEPS
    parser = ToolParser(
        prog=TOOL, description="Benchmark OMPL planners on Kautham problems: control "
        "planners through Odin's physics (problems for Kautham's ODE planners), geometric "
        "planners over Odin's collision checks (any other); a Kautham <Benchmark> file, or "
        "--problem ... --planners ...; OMPL benchmark logs, summary.json and plots in --out.")
    parser.add_argument("file", nargs="?", help="Kautham benchmark file (<Benchmark> rows)")
    parser.add_argument("--problem", action="append", default=[], metavar="P",
                        help="a problem file instead of a benchmark file (repeatable)")
    parser.add_argument("--planners", metavar="A,B", help="OMPL planners for every problem: "
                        f"control ({', '.join(PLANNERS)}) for a physics problem, geometric "
                        f"({', '.join(OMPL_PLANNERS)}) for any other [each problem's own "
                        "<Planner>]")
    parser.add_argument("--runs", type=count(1, MAX_RUNS), metavar="N",
                        help="runs per planner [the file's runCount; 10 with --problem]")
    parser.add_argument("--time", type=seconds, metavar="S", help="wall-clock seconds per run "
                        "[the file's maxTime; with --problem each problem's "
                        "\"_Max Planning Time\", else 10]")
    parser.add_argument("--max-mem", type=float, metavar="MB", help="MB a run's process may "
                        "grow by during its search; the search ends there, as at its time "
                        "limit (OMPL's maxMem) [the file's maxMem, else 4096]")
    parser.add_argument("--seed", type=count(1, MAX_SEED), default=1,
                        help="run k of every planner has seed SEED+k [1]")
    parser.add_argument("--out", default="benchmark", metavar="DIR",
                        help="folder for the logs, runs.jsonl, summary.json and plots "
                        "[./benchmark]")
    parser.add_argument("--resume", action="store_true",
                        help="go on with the runs DIR/runs.jsonl does not hold yet")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="tcp://HOST:8786",
                       help="run on this Dask cluster [a local one]")
    where.add_argument("--workers", type=count(0, MAX_SEARCHES), metavar="N",
                       help="local Dask worker processes [one per core]; 0: no Dask, one run "
                       "after another in this process")
    parser.add_argument("--scheduler-timeout", type=seconds, metavar="S",
                        help="s to wait for --scheduler to answer, then for its first worker "
                        f"[{SCHEDULER_TIMEOUT_S:g}]")
    parser.add_argument("--no-plots", action="store_true", help="no PNG figures")
    search = parser.add_argument_group(
        "search settings", "change every problem's own (as rosrun GUI plan's options do); "
        "a geometric search takes --goal-bias only")
    search.add_argument("--min-control-steps", type=count(1, MAX_CONTROL_STEPS), metavar="N",
                        help="a control is held at least N propagation steps")
    search.add_argument("--max-control-steps", type=count(1, MAX_CONTROL_STEPS), metavar="N",
                        help="and at most N")
    search.add_argument("--goal-bias", type=float, metavar="F",
                        help="the fraction of expansions aimed at the goal (KPIECE1's, RRT's "
                        "and the geometric planners that take one)")
    search.add_argument("--goal-tolerance", type=float, metavar="M",
                        help="goal region radius in the plane, m [0.25]")
    return parser


@dataclass(frozen=True)
class SearchOverrides:
    """The search settings the command line changes in every problem's own (None: the
    problem's; ``gui.planning.problem.SearchSettings``): control steps, KPIECE1's and RRT's
    goal bias (a fraction), the goal region's radius (m, in the plane)."""
    min_control_steps: Optional[int] = None
    max_control_steps: Optional[int] = None
    goal_bias: Optional[float] = None
    goal_tolerance: Optional[float] = None

    def given(self) -> dict:
        """The settings given (SearchSettings field: value), checked; GuiError otherwise."""
        given = {name: getattr(self, name) for name in
                 ("min_control_steps", "max_control_steps", "goal_bias", "goal_tolerance")
                 if getattr(self, name) is not None}
        for name in ("min_control_steps", "max_control_steps"):
            if name in given and given[name] < 1:
                raise GuiError(f"--{name.replace('_', '-')} {given[name]}: at least 1")
        if given.get("min_control_steps", 1) > given.get("max_control_steps", 10 ** 9):
            raise GuiError("--min-control-steps is above --max-control-steps")
        if "goal_bias" in given and not 0.0 <= given["goal_bias"] <= 1.0:
            raise GuiError(f"--goal-bias {given['goal_bias']:g}: between 0 and 1")
        if "goal_tolerance" in given and not given["goal_tolerance"] > 0:
            raise GuiError(f"--goal-tolerance {given['goal_tolerance']:g}: must be positive")
        return given


@dataclass(frozen=True)
class BenchmarkRequest:
    """What benchmark is asked: a Kautham benchmark ``file`` or ``problems`` (one of the
    two); ``planners`` ("A,B"), ``runs``, ``time`` (s), ``max_mem`` (MB) replacing the
    file's (None: its own); run k of every planner seeded ``seed`` + k; the results in the
    folder ``out`` (``resume``: the runs it holds kept); Dask's ``scheduler`` (its answer
    awaited ``scheduler_timeout`` s) or ``workers`` local processes (0: none, None: one per
    core); ``plots``: PNG figures written."""
    file: Optional[str] = None
    problems: Tuple[str, ...] = ()
    planners: Optional[str] = None
    runs: Optional[int] = None
    time: Optional[float] = None
    max_mem: Optional[float] = None
    seed: int = 1
    out: str = "benchmark"
    resume: bool = False
    scheduler: Optional[str] = None
    workers: Optional[int] = None
    scheduler_timeout: Optional[float] = None
    plots: bool = True
    overrides: SearchOverrides = SearchOverrides()


def _request(args) -> BenchmarkRequest:
    return BenchmarkRequest(
        args.file, tuple(args.problem), planners=args.planners, runs=args.runs, time=args.time,
        max_mem=args.max_mem, seed=args.seed, out=args.out, resume=args.resume,
        scheduler=args.scheduler, workers=args.workers,
        scheduler_timeout=args.scheduler_timeout, plots=not args.no_plots,
        overrides=SearchOverrides(args.min_control_steps, args.max_control_steps,
                                  args.goal_bias, args.goal_tolerance))


@one_line_errors(TOOL)
def main(argv: Optional[Sequence[str]] = None) -> int:
    request = _request(_parser().parse_args(argv))
    logging.getLogger("gui.core").setLevel(logging.ERROR)   # problem_info lists what is unused
    return run_benchmark(request)


def run_benchmark(request: BenchmarkRequest) -> int:
    """Runs the runs the request asks (those ``out`` does not hold yet, with ``resume``),
    writes the logs, runs.jsonl, summary.json and plots; 0, or 130 when Ctrl-C stopped it
    (the finished runs kept)."""
    prepared, out = _prepare(request)
    return _run(request, prepared, out)


def _experiments(request: BenchmarkRequest):
    from dataclasses import replace
    from gui.planning import benchmark_spec as spec
    if bool(request.file) == bool(request.problems):
        raise GuiError("give a benchmark file or --problem (one or more), not both or neither")
    if request.runs is not None and request.runs < 1:
        raise GuiError(f"--runs {request.runs}: at least 1")
    if request.time is not None and not request.time > 0:
        raise GuiError(f"--time {request.time:g}: must be positive")
    if request.max_mem is not None and not request.max_mem > 0:
        raise GuiError(f"--max-mem {request.max_mem:g}: must be positive")
    planners = [p.strip() for p in request.planners.split(",") if p.strip()] \
        if request.planners else None
    if request.planners is not None and not planners:
        raise GuiError(f"--planners {request.planners!r}: no planner named")
    if request.problems:
        with reading("problem", ", ".join(request.problems)):
            return spec.command_line_experiments(request.problems, planners,
                                                 request.runs or 10, request.time,
                                                 request.max_mem)
    with reading("benchmark file", request.file):
        experiments = spec.read_benchmark_file(request.file)
    if planners:
        experiments = spec.with_planners(experiments, planners)
    return tuple(replace(e, request=replace(
        e.request, run_count=request.runs or e.request.run_count,
        max_time=request.time or e.request.max_time,
        max_mem=request.max_mem or e.request.max_mem)) for e in experiments)


def _prepare(request: BenchmarkRequest):
    from gui.planning.benchmark import prepare
    from gui.planning.benchmark_plots import check_plotting
    experiments = _experiments(request)
    out = os.path.abspath(request.out)
    if os.path.exists(out) and not os.path.isdir(out):
        raise GuiError(f"--out {request.out}: a file, not a folder")
    parent = os.path.dirname(out)
    if not os.path.isdir(parent) or not os.access(parent, os.W_OK | os.X_OK):
        raise GuiError(f"--out {request.out}: cannot make it in {parent}")
    timeout = request.scheduler_timeout
    if timeout is not None and not timeout > 0:
        raise GuiError(f"--scheduler-timeout {timeout:g}: must be positive")
    if timeout is not None and not request.scheduler:
        raise GuiError("--scheduler-timeout: only with --scheduler")
    if request.workers is not None and request.workers < 0:
        raise GuiError(f"--workers {request.workers}: 0 or more")
    if request.plots:
        check_plotting()
    return prepare(experiments, request.seed, request.overrides.given()), out


def _run(request: BenchmarkRequest, prepared, out: str) -> int:
    from gui.planning.benchmark import DaskRunner, Progress, ResultStore, run_serially
    # a scheduler that does not answer is bad input: refused before anything is written
    runner = DaskRunner(request.scheduler,
                        timeout_s=request.scheduler_timeout or SCHEDULER_TIMEOUT_S) \
        if request.scheduler else None
    try:
        os.makedirs(out, exist_ok=True)
        store = ResultStore(out, prepared, request.resume)
        todo = store.missing(prepared.tasks)
        if runner is None and todo and request.workers != 0:
            runner = DaskRunner(None, request.workers or os.cpu_count() or 1)
    except BaseException:
        if runner is not None:
            runner.close()
        raise
    if runner is None:
        where = "in this process"
    else:
        workers = len(runner.client.scheduler_info().get("workers", {}))
        where = f"on Dask: {request.scheduler or 'a local cluster'}, {workers} workers"
    print(f"{TOOL}: {len(todo)} runs to do of {len(prepared.tasks)} ({where}); results in "
          f"{out}", flush=True)
    show = any(e.request.display_progress for e, _ in prepared.experiments)
    progress = Progress(len(prepared.tasks), len(store.results),
                        sum(r.solved for r in store.results.values()), enabled=show)
    started = datetime.datetime.now()
    clock = time.monotonic()
    interrupted = False

    def on_result(result) -> None:
        store.add(result)
        progress.add(result)

    hosts = []
    try:
        with stop_on_ctrl_c() as stop:
            try:
                if runner is None:
                    run_serially(todo, on_result, stop)
                else:
                    hosts = runner.hosts()
                    runner.run(todo, on_result, stop)
            except KeyboardInterrupt:
                stop.requested = True
            interrupted = bool(stop)
    finally:
        progress.finish()
        if runner is not None:
            runner.close()
    _write_outputs(request, prepared, store, out, started, time.monotonic() - clock, hosts)
    if interrupted:
        print(f"{TOOL}: stopped: {len(store.results)} of {len(prepared.tasks)} runs kept in "
              f"{store.path} (--resume goes on)", file=sys.stderr)
        return 130
    return 0


SETUP = {
    False: "Odin: OMPL control planners searching through Odin's ODE world (rosrun GUI "
           "benchmark)",
    True: "Odin: OMPL geometric planners searching Kautham's control space over Odin's "
          "collision checks (rosrun GUI benchmark; gui.planning.geometric), every solution "
          "simplified as OMPL's Benchmark does",
}
"""The first line of a log's setup text, for control (False) and geometric (True) planners."""


def _setup_text(prepared, entries, hosts, by_entry=None) -> str:
    """A log's free setup text: how its planners searched, each entry's planner and problem
    (and why a refused one was not searched), why each of its runs in ``by_entry`` ({entry
    name: results}) that failed or whose replay refuted its search is not solved, where the
    workers ran."""
    geometric = any(e.geometric for e in entries)
    lines = [f"{SETUP[geometric]}; run k has seed {prepared.seed}+k; rosrun GUI plan PROBLEM "
             "--planner P --seed S --time T repeats a run"]
    if not geometric:
        lines[0] += ("; a run counts as solved only when its plan's replay ends in the goal "
                     "region with no forbidden contact on the way")
    for e in entries:
        line = f"{e.name}: {e.planner} on {e.problem} (its planner: {e.problem_planner})"
        refused = ""
        if e.refusal:
            refused = e.refusal[1]
            line += f"; not searched ({e.refusal[0]}): {refused}"
        lines.append(line)
        # a refused entry's runs all carry its reason, said once above
        lines += [f"{e.name} run {r.run} (seed {r.seed}): not solved: {r.error}"
                  for r in (by_entry or {}).get(e.name, ()) if r.error and r.error != refused]
    return "\n".join(lines + ([f"workers on: {', '.join(hosts)}"] if hosts else []))


def _write_outputs(request, prepared, store, out, started, total_s, hosts) -> None:
    from gui.planning.benchmark import summary
    from gui.planning.benchmark_log import write_log
    data = summary(prepared, store.results)
    changed = {name.replace("_", " "): repr(value)
               for name, value in (prepared.tasks[0].overrides if prepared.tasks else ())}
    for experiment, entries in prepared.experiments:
        by_entry = {e.name: sorted((r for r in store.results.values()
                                    if r.experiment == experiment.name and r.entry == e.name),
                                   key=lambda r: r.run) for e in entries}
        write_log(os.path.join(out, experiment.log_name), experiment.name,
                  [(e.name, {"planner": e.planner, "problem": e.problem,
                             "time limit": repr(e.time_limit), **dict(e.common), **changed})
                   for e in entries],
                  by_entry, seed=prepared.seed,
                  max_time=max(e.time_limit for e in entries),
                  max_mem=experiment.request.max_mem,
                  run_count=experiment.request.run_count, total_s=total_s,
                  setup=_setup_text(prepared, entries, hosts, by_entry), started=started,
                  geometric=any(e.geometric for e in entries))
    if request.plots and store.results:
        from gui.planning.benchmark_plots import write_plots
        data["plots"] = [os.path.basename(p) for p in write_plots(out, data, store.results)]
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(data, f, indent=1)
    print(json.dumps(data, indent=1), flush=True)


__all__ = ["BenchmarkRequest", "SearchOverrides", "main", "run_benchmark"]
