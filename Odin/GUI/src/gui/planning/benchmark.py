"""Planning benchmarks: many seeded searches of Kautham problems, here or on a Dask cluster,
written as OMPL's benchmark log (ROS-free; ``rosrun GUI benchmark``, docs/PLANNING.md): a
physics problem by OMPL's control planners through Odin's world, a problem without physics by
OMPL's geometric planners over Odin's collision checks (``gui.planning.geometric_benchmark``).

``prepare`` turns experiments (``gui.planning.benchmark_spec``) into ``RunTask``s after checking
everything a run needs (every problem loads and plans, every planner exists): bad input is one
``OdinError`` before any run starts; a query no search can solve (a geometric problem's start
or goal that collides, a physics problem's start touching what it must not or goal inside a
fixed obstacle or outside the limits) is not bad input but a finding, recorded in each of its
runs (status and reason) without a search. A physics run counts as solved only when its plan's
replay ends in the goal region with no invalid step (``gui.planning.bridge.plan``). Run k of every
planner of an experiment has seed ``seed + k``, so the planners meet the same draws and ``rosrun
GUI plan PROBLEM --planner P --seed S`` repeats any run. ``execute`` runs the tasks serially
(``workers=0``) or on Dask (``DaskRunner``: a local cluster of worker processes, or an existing
scheduler), hands each result to ``on_result`` as it arrives, and stops every run when
``should_stop()`` turns true. ``ResultStore`` keeps the results as they come (``runs.jsonl``),
so that ``--resume`` runs only the runs still missing.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import signal
import sys
import threading
import time
import uuid
from dataclasses import dataclass
from typing import Callable, Dict, Iterable, List, Optional, Sequence, Tuple

from gui.errors import GuiError, PlanningError
from odin_common.errors import OdinError
from gui.planning.benchmark_run import RunResult, RunStopped, RunTask, problem_bundle, run_task
from gui.planning.benchmark_spec import OMPL_PLANNER_OF, Experiment

DEFAULT_TIME_S = 10.0
"""s per run when neither the benchmark nor the problem (``_Max Planning Time``) gives one."""
RESULTS_FILE = "runs.jsonl"
SCHEDULER_TIMEOUT_S = 10.0
"""s: how long to wait for ``--scheduler`` to answer, and then for its first worker, before
giving up (``--scheduler-timeout``)."""


@dataclass(frozen=True)
class PlannedEntry:
    """One planner configuration as it runs: its name in the log, the OMPL planner, the time
    limit (s) and the problem (path); ``geometric``: a geometric planner's search
    (``gui.planning.geometric_benchmark``); ``refusal``: (OMPL's status, the reason) when no
    search can solve its problem's query (its runs are recorded unsearched); ``common``: the
    settings its planner runs with, (name, value) pairs for the log."""
    name: str
    planner: str
    time_limit: float
    problem: str
    problem_planner: str
    geometric: bool = False
    refusal: Tuple[str, ...] = ()
    common: Tuple[Tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Prepared:
    """What will run: the experiments with their entries (in order) and every task."""
    experiments: Tuple[Tuple[Experiment, Tuple[PlannedEntry, ...]], ...]
    tasks: Tuple[RunTask, ...]
    seed: int

    def fingerprint(self) -> str:
        """Changes when any run would differ (its problem's bytes, planner, seed, limits)."""
        digest = hashlib.sha256()
        for task in self.tasks:
            digest.update(repr((task.key, task.planner, task.seed, task.time_limit,
                                task.problem, task.overrides, task.memory_limit_mb)).encode())
            for relative, data in task.files:
                digest.update(relative.encode() + hashlib.sha256(data).digest())
        return digest.hexdigest()


# --------------------------------------------------------------------------------- preparing

def _load_for_planning(problem: str, overrides: dict):
    """Loads and builds ``problem`` as a run does, and its world once: (its BuildPlan, the
    refusal of a query no search can solve: (OMPL's status, reason), else ())."""
    from gui.core.kautham.problem import load_problem
    from gui.core.translate import BuildDefaults, plan_problem
    from gui.planning import geometric_benchmark as geometric
    from gui.planning.backend import CoreBackend
    from gui.planning.problem import SearchSettings, planning_problem
    build = plan_problem(load_problem(problem), BuildDefaults())
    if geometric.is_geometric(build):
        geometric.run_settings(build, None, DEFAULT_TIME_S, overrides)
        return build, geometric.check_problem(build) or ()
    settings = SearchSettings.of_problem(build, **overrides)
    backend = CoreBackend(build, planning_problem(build, None, settings))
    try:
        return build, backend.refusal() or ()
    finally:
        backend.close()


def _load(row, overrides: dict, loaded: Dict[str, tuple]) -> tuple:
    """(BuildPlan, refusal, bundle path, bundle files) of ``row``'s problem, loaded once."""
    if row.problem not in loaded:
        if not os.path.isfile(row.problem):
            raise PlanningError(f"{row.where}: problem {row.problem}: no such file")
        built = []
        try:
            relative, files = problem_bundle(
                lambda: built.append(_load_for_planning(row.problem, overrides)), row.problem)
        except OdinError as error:
            raise PlanningError(f"{row.where}: {error}") from None
        loaded[row.problem] = (*built[0], relative, files)
    return loaded[row.problem]


def _control_entry(row, build, max_time: Optional[float], refusal: tuple) -> PlannedEntry:
    """``row``'s entry for a physics problem: an OMPL control planner (``refusal``: its
    query's, its runs recorded unsearched)."""
    from gui.planning.bridge import PLANNERS, UNCONSTRUCTIBLE
    own = build.problem.planner
    planner = row.planner or OMPL_PLANNER_OF.get(own.name if own else "")
    if planner is None:
        raise PlanningError(
            f"{row.where}: problem {row.problem}: its planner "
            f"{own.name if own else '(none)'!s} is not one Odin runs: choose with "
            f"--planners (one or more of {', '.join(PLANNERS)})")
    if planner not in PLANNERS:
        why = "OMPL's Python wheel cannot construct it" if planner in UNCONSTRUCTIBLE \
            else "unknown planner"
        raise PlanningError(f"{row.where}: planner {planner!r}: {why}; one of "
                            f"{', '.join(PLANNERS)}")
    own_time = own.search.time_limit if own is not None else None
    limit = max_time or own_time or DEFAULT_TIME_S
    return PlannedEntry(row.name(planner), planner, float(limit), row.problem,
                        own.name if own else "", refusal=tuple(refusal))


def _geometric_entry(row, build, max_time: Optional[float], refusal: tuple,
                     overrides: dict) -> PlannedEntry:
    """``row``'s entry for a problem without physics: an OMPL geometric planner with the
    problem's own parameters (``gui.planning.geometric_benchmark``)."""
    from gui.planning import geometric_benchmark as geometric
    own = build.problem.planner
    limit = float(max_time or geometric.own_time_limit(build) or DEFAULT_TIME_S)
    try:
        settings = geometric.run_settings(build, row.planner, limit, overrides)
    except PlanningError as error:
        raise PlanningError(f"{row.where}: {error}") from None
    return PlannedEntry(row.name(settings.planner), settings.planner, limit, row.problem,
                        own.name if own else "", True, tuple(refusal),
                        tuple(geometric.common_properties(settings).items()))


def prepare(experiments: Sequence[Experiment], seed: int = 1,
            overrides: Optional[dict] = None) -> Prepared:
    """Checks and expands ``experiments`` into tasks (module docstring). PlanningError or
    ProblemError, naming the row, for a problem that does not load or plan, an unknown
    planner, two entries of an experiment with one name, or an experiment of both physics
    and geometric problems (Kautham benchmarks one family of planners at a time)."""
    overrides = dict(overrides or {})
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 1:
        raise PlanningError(f"seed {seed!r}: a whole number, at least 1")
    loaded: Dict[str, tuple] = {}
    planned, tasks = [], []
    for experiment in experiments:
        entries: List[PlannedEntry] = []
        for row in experiment.rows:
            build, refusal, relative, files = _load(row, overrides, loaded)
            max_time = experiment.request.max_time
            entry = _geometric_entry(row, build, max_time, refusal, overrides) \
                if not build.physics else _control_entry(row, build, max_time, refusal)
            if any(e.name == entry.name for e in entries):
                raise PlanningError(f"{row.where}: experiment {experiment.name!r} already has "
                                    f"a planner named {entry.name!r} (PlannerAlias)")
            if entries and entries[0].geometric != entry.geometric:
                raise PlanningError(f"{row.where}: experiment {experiment.name!r} has physics "
                                    "and geometric problems: one family of planners per "
                                    "<Benchmark>, as in Kautham")
            entries.append(entry)
            tasks += [RunTask(experiment.name, entry.name, k, entry.planner, seed + k,
                              entry.time_limit, relative, files,
                              tuple(sorted(overrides.items())), experiment.request.max_mem,
                              entry.geometric, entry.refusal)
                      for k in range(experiment.request.run_count)]
        planned.append((experiment, tuple(entries)))
    names = [e.name for e in experiments]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise PlanningError(f"two experiments are both named {twice[0]!r}")
    return Prepared(tuple(planned), tuple(tasks), seed)


# ---------------------------------------------------------------------------------- results

class ResultStore:
    """The results of one benchmark in ``folder/runs.jsonl``: a first line naming what is run
    (``Prepared.fingerprint``), then one result per line, appended and flushed as it arrives."""

    def __init__(self, folder: str, prepared: Prepared, resume: bool):
        self.path = os.path.join(folder, RESULTS_FILE)
        self.results: Dict[tuple, RunResult] = {}
        fingerprint = prepared.fingerprint()
        if os.path.exists(self.path) and os.path.getsize(self.path) > 0:
            if not resume:
                raise GuiError(f"{self.path} exists: --resume to finish that benchmark, or "
                               "another --out")
            self._read(fingerprint)
        else:
            with open(self.path, "w") as f:
                f.write(json.dumps({"odin_benchmark": fingerprint}) + "\n")
        wanted = {t.key for t in prepared.tasks}
        self.results = {k: r for k, r in self.results.items() if k in wanted}

    def _read(self, fingerprint: str) -> None:
        with open(self.path) as f:
            lines = f.read().splitlines()
        try:
            header = json.loads(lines[0])
        except (ValueError, IndexError):
            header = {}
        if header.get("odin_benchmark") != fingerprint:
            raise GuiError(f"--resume: {self.path}:1: written for another benchmark (other "
                           "problems, planners, seeds or limits)")
        for number, line in enumerate(lines[1:], start=2):
            try:
                result = RunResult.from_json(json.loads(line))
            except (ValueError, TypeError):
                if number == len(lines):       # cut by the stop that interrupted it
                    continue
                raise GuiError(f"--resume: {self.path}:{number}: not a run's result") from None
            self.results[result.key] = result
        with open(self.path, "w") as f:        # without a cut last line
            f.write("\n".join([lines[0]] + [json.dumps(r.to_json())
                                            for r in self.results.values()]) + "\n")

    def add(self, result: RunResult) -> None:
        self.results[result.key] = result
        with open(self.path, "a") as f:
            f.write(json.dumps(result.to_json()) + "\n")
            f.flush()
            os.fsync(f.fileno())

    def missing(self, tasks: Iterable[RunTask]) -> List[RunTask]:
        return [t for t in tasks if t.key not in self.results]


# ---------------------------------------------------------------------------------- running

def run_serially(tasks: Sequence[RunTask], on_result: Callable[[RunResult], None],
                 should_stop: Callable[[], bool]) -> None:
    """Each task in turn in this process's children; returns early when stopped."""
    for task in tasks:
        if should_stop():
            return
        try:
            on_result(run_task(task, should_stop))
        except RunStopped:
            return


def _run_on_worker(task: RunTask, stop_event: str) -> RunResult:
    """A Dask task: the run, stopped when the benchmark sets the Dask Event ``stop_event``."""
    from distributed import Event
    event = Event(stop_event)
    checked = [0.0, False]

    def should_stop() -> bool:
        now = time.monotonic()
        if now - checked[0] >= 1.0:            # one scheduler round trip a second
            checked[0] = now
            checked[1] = bool(event.is_set())
        return checked[1]

    return run_task(task, should_stop)


@contextlib.contextmanager
def _sigint_ignored():
    """SIGINT ignored while local workers start: they inherit it, so that a terminal's Ctrl-C,
    which reaches the whole process group, is the benchmark's to handle (it stops the runs and
    closes the cluster) and no worker dies printing a traceback."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


class DaskRunner:
    """Runs tasks on Dask: ``scheduler`` (an address, ``tcp://host:8786``) or a local cluster
    of ``workers`` worker processes, one thread each (a run keeps one core busy)."""

    def __init__(self, scheduler: Optional[str] = None, workers: int = 0,
                 timeout_s: float = SCHEDULER_TIMEOUT_S):
        try:
            from distributed import Client, LocalCluster
        except ImportError as error:
            raise PlanningError(f"Dask is missing ({error}): tools/install.sh installs the "
                                "pinned dask[distributed] (tools/requirements.txt)") from None
        self.cluster = None
        if scheduler:
            try:
                self.client = Client(scheduler, timeout=timeout_s)
            except (OSError, TimeoutError, ValueError) as error:
                raise PlanningError(f"--scheduler {scheduler}: no Dask scheduler answers "
                                    f"({' '.join(str(error).split()) or type(error).__name__})"
                                    ) from None
            try:
                self.client.wait_for_workers(1, timeout=timeout_s)
            except (OSError, TimeoutError):
                self.close()
                raise PlanningError(f"--scheduler {scheduler}: the scheduler has no worker "
                                    f"after {timeout_s:g} s (start dask worker "
                                    f"{scheduler} on the machines that run)") from None
        else:
            with _sigint_ignored():
                self.cluster = LocalCluster(n_workers=workers, threads_per_worker=1,
                                            processes=True, dashboard_address=None,
                                            silence_logs=logging.ERROR)
            self.client = Client(self.cluster)

    def run(self, tasks: Sequence[RunTask], on_result: Callable[[RunResult], None],
            should_stop: Callable[[], bool]) -> None:
        """Every task; results handed over as they arrive; stops every run when asked."""
        from distributed import Event, wait
        from distributed.client import FIRST_COMPLETED
        stop_event = f"odin-benchmark-stop-{uuid.uuid4().hex}"
        event = Event(stop_event, client=self.client)
        pending = [self.client.submit(_run_on_worker, task, stop_event, pure=False,
                                      key=f"odin-run-{k}-{uuid.uuid4().hex[:8]}")
                   for k, task in enumerate(tasks)]
        try:
            while pending:
                if should_stop():
                    break
                try:
                    done, remaining = wait(pending, timeout=0.25, return_when=FIRST_COMPLETED)
                except TimeoutError:
                    continue
                pending = list(remaining)
                for future in done:
                    on_result(self._result(future))
        finally:
            if pending:
                self._stop(event, pending)

    def _result(self, future) -> RunResult:
        try:
            return future.result()
        except RunStopped:
            raise
        except Exception as error:              # a worker without Odin, a lost worker
            raise PlanningError(f"a Dask worker failed a run: {type(error).__name__}: "
                                f"{' '.join(str(error).split())}") from None

    def _stop(self, event, pending) -> None:
        """Every running run told to stop (they end within a second and STOP_GRACE_S), the
        queued ones cancelled."""
        try:
            event.set()
            self.client.cancel(pending)
            from distributed import wait
            wait(pending, timeout=15.0)
        except Exception:                      # noqa: BLE001 - a cluster already gone
            pass

    def close(self) -> None:
        try:
            self.client.close(timeout=10)
        except Exception:                      # noqa: BLE001 - closing what is gone
            pass
        if self.cluster is not None:
            try:
                self.cluster.close(timeout=10)
            except Exception:                  # noqa: BLE001
                pass

    def hosts(self) -> List[str]:
        """Where the workers run (for the log's setup text)."""
        try:
            info = self.client.scheduler_info()
            return sorted({w.get("host", "?") for w in info.get("workers", {}).values()})
        except Exception:                      # noqa: BLE001
            return []


# -------------------------------------------------------------------------------- progress

class Progress:
    """One line: runs done of all, solved, and the time left at the rate so far; rewritten
    in place on a terminal, one line per run elsewhere."""

    def __init__(self, total: int, done: int, solved: int, stream=sys.stderr,
                 enabled: bool = True):
        self.total, self.done, self.solved = total, done, solved
        self.started_with = done
        self.started = time.monotonic()
        self.stream = stream
        self.enabled = enabled
        self.tty = hasattr(stream, "isatty") and stream.isatty()
        self.width = 0

    def add(self, result: RunResult) -> None:
        self.done += 1
        self.solved += result.solved
        if self.enabled:
            line = f"benchmark: {self.done}/{self.total} runs done, {self.solved} solved, " \
                f"{self.eta()}"
            if self.tty:      # over the line before, to its end (a shorter one leaves none)
                end = "" if self.done < self.total else "\n"
                line = "\r" + line.ljust(self.width) + end
                self.width = len(line) - 1 - len(end)
            else:
                line += "\n"
            self.stream.write(line)
            self.stream.flush()

    def eta(self) -> str:
        new = self.done - self.started_with
        if new <= 0:
            return "ETA unknown"
        left = (time.monotonic() - self.started) / new * (self.total - self.done)
        minutes, seconds = divmod(int(round(left)), 60)
        return f"ETA {minutes}m{seconds:02d}s" if minutes else f"ETA {seconds}s"

    def finish(self) -> None:
        if self.enabled and self.tty and self.done < self.total:
            self.stream.write("\n")


# -------------------------------------------------------------------------------- summary

def summary(prepared: Prepared, results: Dict[tuple, RunResult]) -> dict:
    """Per experiment (``geometric``: of geometric planners) and planner: runs done, solved,
    failed, success rate, the solved runs' times (s: median, mean, min, max), the distinct
    reasons of the runs that failed or were not searched (``errors``), and the median
    propagations per second (control) or collision checks per second and simplified path
    length (geometric)."""
    out = []
    for experiment, entries in prepared.experiments:
        planners = []
        for entry in entries:
            runs = [r for r in results.values()
                    if r.experiment == experiment.name and r.entry == entry.name]
            times = sorted(r.time_s for r in runs if r.solved)
            planner = dict(
                name=entry.name, planner=entry.planner, problem=entry.problem,
                time_limit_s=entry.time_limit, runs=len(runs),
                runs_asked=experiment.request.run_count,
                solved=sum(r.solved for r in runs), failed=sum(bool(r.error) for r in runs),
                success_rate=round(sum(r.solved for r in runs) / len(runs), 4) if runs else None,
                time_s=_stats(times), errors=sorted({r.error for r in runs if r.error}))
            if entry.geometric:
                planner.update(
                    collision_checks_per_s_median=_median(sorted(
                        r.collision_checks_per_s for r in runs if r.collision_checks_per_s)),
                    simplified_length_median=_median(sorted(
                        r.geometric.simplified_length for r in runs
                        if r.solved and r.geometric is not None)))
            else:
                planner.update(propagations_per_s_median=_median(sorted(
                    r.propagations_per_s for r in runs if r.propagations_per_s)))
            planners.append(planner)
        out.append(dict(name=experiment.name, log=experiment.log_name,
                        geometric=any(e.geometric for e in entries), planners=planners))
    return dict(seed=prepared.seed, experiments=out)


def _median(values: List[float]) -> Optional[float]:
    if not values:
        return None
    n = len(values)
    middle = values[n // 2] if n % 2 else (values[n // 2 - 1] + values[n // 2]) / 2
    return round(middle, 4)


def _stats(values: List[float]) -> Optional[dict]:
    if not values:
        return None
    return dict(median=_median(values), mean=round(sum(values) / len(values), 4),
                min=round(values[0], 4), max=round(values[-1], 4))


__all__ = ["DaskRunner", "Prepared", "Progress", "ResultStore", "prepare", "run_serially",
           "summary"]
