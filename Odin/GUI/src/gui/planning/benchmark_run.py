"""One run of a benchmark: a seeded search of one problem with one planner, in a process of its
own, from files it carries with it (ROS-free).

A ``RunTask`` holds everything a run needs: the bytes of every file its problem reads (the
problem, robots, obstacles, controls, meshes: ``problem_bundle`` records what a load opens), the
planner, the seed and the time limit. ``run_task`` writes the files to a temporary folder and
starts ``python -m gui.planning.benchmark_run``, which loads the problem from there, seeds OMPL
and plans exactly as ``rosrun GUI plan PROBLEM --planner P --seed S --time T`` does (a physics
problem: the Core back end; a geometric one: ``gui.planning.geometric_benchmark``), and answers
a ``RunResult`` as one JSON line. A geometric problem whose query collides is not searched: its
runs are answered at once with the reason the benchmark found before any run. A fresh process
per run because OMPL seeds its generators once per process; with the same files, planner and
seed a search grows the same tree on any machine, so a run that solves gives bit-identical rows
anywhere (``RunResult.digest``); a run the time limit cuts stops where the clock says.

Stopping: ``should_stop()`` is asked every ``POLL_S``; when true the run's process gets SIGINT
(its search stops within a propagation) and the run raises ``RunStopped``. The process is in a
session of its own (a terminal's Ctrl-C reaches the benchmark, which decides) and dies with
its parent (PR_SET_PDEATHSIG): a Dask worker that goes takes its run with it.
"""
from __future__ import annotations

import hashlib
import json
import os
import resource
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import asdict, dataclass
from typing import Callable, Dict, Optional, Tuple


POLL_S = 0.2
"""s: how often a running run asks whether to stop."""
STOP_GRACE_S = 10.0
"""s: how long a run's process may take to stop after SIGINT before it is killed."""
START_GRACE_S = 120.0
"""s: what a run's process may take beyond its time limit (imports, the world's build, the
replay of its plan) before it counts as hung and is killed."""


class RunStopped(Exception):
    """The run was asked to stop; nothing of it is kept."""


@dataclass(frozen=True)
class RunTask:
    """One run: ``experiment`` and ``entry`` (the planner's name in the log) name it with
    ``run`` (0-based); ``planner``: OMPL's; ``seed``: OMPL's; ``time_limit``: s of wall clock;
    ``problem``: the problem file's path within ``files`` ((relative path, bytes) pairs);
    ``overrides``: SearchSettings fields to change ((name, value) pairs); ``memory_limit_mb``:
    MB the run's process may grow by during its search (the benchmark's maxMem);
    ``geometric``: searched by a geometric planner (``gui.planning.geometric_benchmark``);
    ``refusal``: (OMPL's status, the reason) when the problem's query collides: not searched."""
    experiment: str
    entry: str
    run: int
    planner: str
    seed: int
    time_limit: float
    problem: str
    files: Tuple[Tuple[str, bytes], ...]
    overrides: Tuple[Tuple[str, object], ...] = ()
    memory_limit_mb: float = 4096.0
    geometric: bool = False
    refusal: Tuple[str, ...] = ()

    @property
    def key(self) -> Tuple[str, str, int]:
        return (self.experiment, self.entry, self.run)


@dataclass(frozen=True)
class GeometricMeasures:
    """What a geometric run measures beyond the common fields (OMPL's geometric benchmark's
    properties): ``collision_checks`` (configurations checked by the search); in the control
    space's units, ``solution_length`` (the path as the planner found it) and
    ``simplified_length``; ``simplified_segments`` (the simplified path's states - 1);
    ``simplification_s`` (s of wall clock); ``graph_states`` (the planner's graph or trees
    when it stopped)."""
    collision_checks: int
    solution_length: float
    simplified_length: float
    simplified_segments: int
    simplification_s: float
    graph_states: int

    def outcome(self) -> tuple:
        """Everything but the simplification's time (RunResult.outcome)."""
        return (self.collision_checks, self.solution_length, self.simplified_length,
                self.simplified_segments, self.graph_states)


@dataclass(frozen=True)
class RunResult:
    """What one run measured. ``solved``: an exact solution (OMPL's "solved"; a control run's
    only when its replay confirms it: ``gui.planning.bridge.PlanResult.solved``);
    ``approximate``: a path that is not a solution; ``status``: OMPL's planner status; ``time_s``: s
    of wall clock in the search (a geometric run's: the planner's, without the simplification);
    ``solution_length_s``: s, the plan's simulated duration (OMPL's PathControl length: the sum
    of its control durations; 0 without a path or for a geometric run);
    ``solution_difference_m``: m, where the plan ends from the goal, in the plane;
    ``propagations``: propagation steps run; ``memory_mb``: MB, the run process's peak resident
    memory; ``digest``: sha256 of the plan's rows (controls and durations, or a geometric
    path's states, exactly), equal for equal plans; ``host``: where it ran; ``error``: why the
    run failed, was not searched, or its plan's replay refuted the search ("" when none of
    these); ``geometric``: a geometric run's own measures (None for a control run)."""
    experiment: str
    entry: str
    run: int
    planner: str
    seed: int
    solved: bool
    approximate: bool
    status: str
    time_s: float
    solution_length_s: float
    solution_difference_m: Optional[float]
    propagations: int
    memory_mb: float
    digest: str
    host: str
    error: str = ""
    geometric: Optional[GeometricMeasures] = None

    @property
    def key(self) -> Tuple[str, str, int]:
        return (self.experiment, self.entry, self.run)

    @property
    def propagations_per_s(self) -> Optional[float]:
        if self.geometric is not None:
            return None
        return self.propagations / self.time_s if self.time_s > 0 else None

    @property
    def collision_checks_per_s(self) -> Optional[float]:
        """A geometric run's collision checks per second of its search and simplification."""
        if self.geometric is None:
            return None
        spent = self.time_s + self.geometric.simplification_s
        return self.geometric.collision_checks / spent if spent > 0 else None

    def outcome(self) -> tuple:
        """What is the same wherever and whenever the run is repeated, for a run that solved
        (a run cut by its time limit stops where the clock says): everything but time,
        memory and host."""
        return (self.key, self.planner, self.seed, self.solved, self.approximate, self.status,
                self.solution_length_s, self.solution_difference_m, self.propagations,
                self.digest, self.error,
                self.geometric.outcome() if self.geometric is not None else None)

    def to_json(self) -> dict:
        return asdict(self)

    @classmethod
    def from_json(cls, data: dict) -> "RunResult":
        """The result ``to_json`` wrote (a results file of before geometric runs too)."""
        fields = dict(data)
        measures = fields.pop("geometric", None)
        return cls(**fields, geometric=GeometricMeasures(**measures)
                   if measures is not None else None)


# ---------------------------------------------------------------------- the files a load reads

_recording: Optional[set] = None
_hook_installed = False
_NOT_PROBLEM_FILES = (".py", ".pyc", ".so", ".pth")


def _record_open(event: str, args) -> None:
    if _recording is None or event != "open":
        return
    path, mode = args[0], args[1]
    if not isinstance(path, (str, bytes)) or (mode and any(c in str(mode) for c in "wax+")):
        return
    path = os.path.abspath(os.fsdecode(path))
    if path.endswith(_NOT_PROBLEM_FILES) or "-packages" in path or \
            path.startswith(("/proc/", "/sys/", "/dev/", sys.prefix, sys.base_prefix)) or \
            path.startswith(_cache_folders()):
        return
    _recording.add(path)


def _cache_folders() -> tuple:
    """Folders of what readers derived and kept (a shape cache), never a problem's files:
    shipping them would make a benchmark's bundle depend on what this machine cached."""
    folders = [os.environ.get("ODIN_CACHE_DIR"), os.environ.get("XDG_CACHE_HOME"),
               os.path.join(os.path.expanduser("~"), ".cache")]
    return tuple(os.path.join(os.path.abspath(f), "") for f in folders if f)


def problem_bundle(load: Callable[[], object], problem: str
                   ) -> Tuple[str, Tuple[Tuple[str, bytes], ...]]:
    """Calls ``load()`` (which reads ``problem`` and everything it references) and answers
    (the problem's path within the bundle, the bundle: every regular file the load opened for
    reading, as (path relative to their common folder, bytes)). The interpreter's audit hook
    sees every ``open`` of the load, whichever library makes it."""
    global _recording, _hook_installed
    if not _hook_installed:
        sys.addaudithook(_record_open)
        _hook_installed = True
    from gui.core import shapes
    from gui.core.sizes import read_input_file
    cached = shapes._CACHE
    shapes._CACHE = {}      # this process's shapes read again: their files opened, and seen
    _recording = set()
    try:
        load()
        opened = {p for p in _recording if os.path.isfile(p)}
    finally:
        _recording = None
        shapes._CACHE = {**cached, **shapes._CACHE}
    problem = os.path.abspath(problem)
    opened.add(problem)
    root = os.path.commonpath([os.path.dirname(p) for p in opened])
    files = []
    for path in sorted(opened):
        files.append((os.path.relpath(path, root), read_input_file(path, "problem's file")))
    return os.path.relpath(problem, root), tuple(files)


# -------------------------------------------------------------------------- running one run

def run_task(task: RunTask, should_stop: Callable[[], bool] = lambda: False) -> RunResult:
    """Runs ``task`` in a process of its own (module docstring) and answers its result; a run
    whose process fails answers a result with ``error`` set and status "Crash", a refused
    one (``RunTask.refusal``) its status and reason at once. Raises ``RunStopped`` when
    ``should_stop()`` turns true first."""
    if task.refusal:
        status, why = task.refusal
        return RunResult(task.experiment, task.entry, task.run, task.planner, task.seed,
                         False, False, status, 0.0, 0.0, None, 0, 0.0, "",
                         socket.gethostname(), error=why)
    with tempfile.TemporaryDirectory(prefix="odin-bench-") as folder:
        for relative, data in task.files:
            path = os.path.join(folder, relative)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "wb") as f:
                f.write(data)
        order = dict(problem=os.path.join(folder, task.problem), planner=task.planner,
                     seed=task.seed, time_limit=task.time_limit,
                     memory_limit_mb=task.memory_limit_mb,
                     overrides=dict(task.overrides), geometric=task.geometric,
                     parent=os.getpid())
        child = subprocess.Popen(
            [sys.executable, "-m", "gui.planning.benchmark_run"], stdin=subprocess.PIPE,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True, cwd=folder)
        out, err = _wait(child, json.dumps(order).encode(), task.time_limit, should_stop)
    lines = out.decode(errors="replace").strip().splitlines()
    if child.returncode == 0 and lines:
        try:
            answer = json.loads(lines[-1])
            return RunResult.from_json(dict(experiment=task.experiment, entry=task.entry,
                                            run=task.run, planner=task.planner,
                                            seed=task.seed, **answer))
        except (ValueError, TypeError) as error:
            why = f"unreadable answer ({error})"
    else:
        why = _failure(err.decode(errors="replace"), child.returncode)
    return RunResult(task.experiment, task.entry, task.run, task.planner, task.seed,
                     False, False, "Crash", 0.0, 0.0, None, 0, 0.0, "", socket.gethostname(),
                     error=why)


def _failure(stderr: str, status: int) -> str:
    """Why a run's process failed: its own one line ("run: ..."), else its stderr's last line
    (what a library printed at exit may follow the run's line), else its exit status."""
    lines = stderr.strip().splitlines()
    ours = [line for line in lines if line.startswith("run: ")]
    return ours[-1] if ours else lines[-1] if lines else f"exit status {status}"


def _wait(child: subprocess.Popen, order: bytes, time_limit: float,
          should_stop: Callable[[], bool]) -> Tuple[bytes, bytes]:
    """Feeds ``order``, waits for the child while asking ``should_stop``; its (stdout,
    stderr)."""
    output: Dict[str, bytes] = {}

    def talk() -> None:
        output["out"], output["err"] = child.communicate(order)

    talker = threading.Thread(target=talk, daemon=True)
    talker.start()
    deadline = time.monotonic() + time_limit + START_GRACE_S
    try:
        while talker.is_alive():
            talker.join(POLL_S)
            if not talker.is_alive():
                break
            if should_stop():
                _end(child, talker)
                raise RunStopped
            if time.monotonic() > deadline:
                _end(child, talker)
                return b"", f"hung: no answer {START_GRACE_S:g} s past the time limit".encode()
    except BaseException:
        _end(child, talker)
        raise
    return output.get("out", b""), output.get("err", b"")


def _end(child: subprocess.Popen, talker: threading.Thread) -> None:
    """SIGINT (the search stops within a propagation), then SIGKILL after STOP_GRACE_S."""
    if child.poll() is None:
        try:
            child.send_signal(signal.SIGINT)
            child.wait(STOP_GRACE_S)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()
        except ProcessLookupError:
            pass
    talker.join(STOP_GRACE_S)


# -------------------------------------------------------------------------- the run's process

def search(problem: str, planner: str, seed: int, time_limit: float, overrides: dict,
           stop: Callable[[], bool], memory_limit_mb: Optional[float] = None) -> dict:
    """The search ``rosrun GUI plan problem --planner P --seed S --time T`` makes (the Core
    back end, the problem's own settings changed by ``overrides``), ended also by
    ``memory_limit_mb`` (``bridge.plan``); the RunResult fields it measures. Solved only as
    plan counts it (``PlanResult.solved``): a plan OMPL called exact that its replay refutes
    is recorded with the status "Approximate solution" and ``error`` saying what differs."""
    from gui.core.kautham.problem import load_problem
    from gui.core.translate import BuildDefaults, plan_problem
    from gui.planning.backend import CoreBackend
    from gui.planning.bridge import plan
    from gui.planning.problem import SearchSettings, planning_problem
    build = plan_problem(load_problem(problem), BuildDefaults())
    settings = SearchSettings.of_problem(build, **overrides)
    backend = CoreBackend(build, planning_problem(build, None, settings))
    try:
        result = plan(backend, planner, time_limit, seed, stop, memory_limit_mb)
    finally:
        backend.close()
    digest = hashlib.sha256()
    for row in result.rows:
        digest.update(repr((tuple(row.controls), row.duration)).encode())
    # solved as plan counts it (its replay in the goal region, no invalid step): a plan OMPL
    # called exact that its replay refutes is recorded as a path, not a solution, and why
    status = "Approximate solution" if result.disagreement else result.status
    return dict(solved=result.solved, approximate=bool(result.rows) and not result.solved,
                status=status, time_s=result.time_s,
                solution_length_s=result.duration,
                solution_difference_m=result.goal_distance if result.rows else None,
                propagations=result.propagations,
                memory_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                digest=digest.hexdigest() if result.rows else "",
                host=socket.gethostname(),
                error=f"the replay disagrees with the search: {result.disagreement}"
                if result.disagreement else "")


def _die_with_parent(parent: int) -> None:
    """SIGKILL when the process that started this one ends (Linux's PR_SET_PDEATHSIG)."""
    try:
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGKILL)          # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:                 # it ended before the request was made
        os._exit(1)


def main() -> int:
    """The run's process: the order as JSON on stdin, the result as one JSON line on
    stdout; exit 130 when stopped (SIGINT), 2 with one line on stderr when the run failed."""
    from odin_common.errors import OdinError
    from odin_common.tool import stop_on_ctrl_c
    order = json.loads(sys.stdin.read())
    _die_with_parent(order["parent"])
    try:
        if order.get("geometric"):
            from gui.planning.geometric_benchmark import search as run_search
        else:
            run_search = search
        with stop_on_ctrl_c() as stop:
            answer = run_search(order["problem"], order["planner"], order["seed"],
                                order["time_limit"], order["overrides"], stop,
                                order["memory_limit_mb"])
    except KeyboardInterrupt:
        return 130
    except (OdinError, OSError) as error:
        print(f"run: {' '.join(str(error).split())}", file=sys.stderr)
        return 2
    print(json.dumps(answer), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())


__all__ = ["GeometricMeasures", "RunResult", "RunStopped", "RunTask", "problem_bundle",
           "run_task", "search"]
