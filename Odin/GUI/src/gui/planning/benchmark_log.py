"""OMPL's benchmark log format, written from Odin's runs (ROS-free, OMPL-free).

The format as OMPL's ``Benchmark::saveResultsToStream`` writes it and its
``ompl_benchmark_statistics.py`` reads it into the SQLite database Planner Arena plots:

    OMPL version 2.0.1
    Experiment <name>
    Running on <host>
    Starting at <date>
    <<<|
    <setup: free text>
    |>>>
    <<<|
    <cpu information: free text>
    |>>>
    <seed> is the random seed
    <s> seconds per run
    <MB> MB per run
    <n> runs per planner
    <s> seconds spent to collect the data
    1 enum types
    status|Unknown status|Invalid start|...
    <k> planners
    control_<planner name>   (geometric_<planner name> for a geometric planner)
    <c> common properties
    <name> = <value>
    <p> properties for each run
    <property name> <TYPE>          (sorted by name; TYPE: REAL, INTEGER, BOOLEAN, ENUM, STRING)
    <r> runs
    <value>; <value>; ...;          (one run a line, in the order of the properties; empty:
    .                                 not measured)

A control planner (``control_<name>``) writes what OMPL's control benchmark reports (time,
solved, approximate solution, solution difference and length, memory, status) and Odin's own:
propagations, propagations per second, and the run's seed (``rosrun GUI plan ... --seed S``
repeats it). A geometric planner (``geometric_<name>``) writes what OMPL's geometric benchmark
reports of it (``Benchmark::benchmark``: time, memory, status, solved, approximate solution,
solution length, simplification time, simplified solution length and segments, graph states),
the ``collision checks`` Kautham's benchmark adds (``apps/console/benchmark.cpp``), and Odin's
collision checks per second and seed.
"""
from __future__ import annotations

import datetime
import platform
import socket
from typing import Callable, Dict, Sequence

from gui.planning.benchmark_run import RunResult

OMPL_VERSION = "2.0.1"
"""The OMPL whose planners run (tools/requirements.txt pins the wheel)."""
STATUS = ("Unknown status", "Invalid start", "Invalid goal", "Unrecognized goal type",
          "Timeout", "Approximate solution", "Exact solution", "Crash", "Abort", "Infeasible")
"""OMPL's PlannerStatus::StatusType names in the enum's order (the log's status ENUM)."""

RUN_PROPERTIES = (
    ("approximate solution", "BOOLEAN", lambda r: _flag(r.approximate) if r.digest else ""),
    ("memory", "REAL", lambda r: _real(r.memory_mb)),
    ("propagations", "INTEGER", lambda r: str(r.propagations)),
    ("propagations per second", "REAL", lambda r: _real(r.propagations_per_s)),
    ("seed", "INTEGER", lambda r: str(r.seed)),
    ("solution difference", "REAL", lambda r: _real(r.solution_difference_m)
     if r.digest else ""),
    ("solution length", "REAL", lambda r: _real(r.solution_length_s) if r.digest else ""),
    ("solved", "BOOLEAN", lambda r: _flag(r.solved)),
    ("status", "ENUM", lambda r: str(STATUS.index(r.status) if r.status in STATUS else 0)),
    ("time", "REAL", lambda r: _real(r.time_s)),
)
"""Each run's properties (name, type, its value from a RunResult), sorted by name as OMPL
sorts them. Units: time s, memory MB, solution length s (simulated), solution difference m."""


def _path(value) -> Callable[[RunResult], str]:
    """A property of a geometric run's path: empty without one (as OMPL writes it only for a
    run with a solution)."""
    return lambda r: value(r) if r.digest and r.geometric is not None else ""


def _measure(value) -> Callable[[RunResult], str]:
    """A geometric measure: empty for a run that was not searched."""
    return lambda r: value(r) if r.geometric is not None else ""


GEOMETRIC_RUN_PROPERTIES = (
    ("approximate solution", "BOOLEAN",
     lambda r: _flag(r.status == "Approximate solution") if r.geometric is not None else ""),
    ("collision checks", "INTEGER", _measure(lambda r: str(r.geometric.collision_checks))),
    ("collision checks per second", "REAL", lambda r: _real(r.collision_checks_per_s)),
    ("graph states", "INTEGER", _measure(lambda r: str(r.geometric.graph_states))),
    ("memory", "REAL", lambda r: _real(r.memory_mb) if r.memory_mb > 0 else ""),
    ("seed", "INTEGER", lambda r: str(r.seed)),
    ("simplification time", "REAL", _path(lambda r: _real(r.geometric.simplification_s))),
    ("simplified solution length", "REAL",
     _path(lambda r: _real(r.geometric.simplified_length))),
    ("simplified solution segments", "INTEGER",
     _path(lambda r: str(r.geometric.simplified_segments))),
    ("solution length", "REAL", _path(lambda r: _real(r.geometric.solution_length))),
    ("solved", "BOOLEAN", lambda r: _flag(r.solved)),
    ("status", "ENUM", lambda r: str(STATUS.index(r.status) if r.status in STATUS else 0)),
    ("time", "REAL", lambda r: _real(r.time_s)),
)
"""A geometric planner's run properties, sorted by name. Units: time (the planner's, without
the simplification) and simplification time s, memory MB, solution lengths in the control
space's units (Kautham's [0, 1] per control: OMPL's path length there)."""


def _flag(value: bool) -> str:
    return "1" if value else "0"


def _real(value) -> str:
    return "" if value is None else repr(float(value))


def write_log(path: str, experiment: str, planners: Sequence[tuple],
              results: Dict[str, Sequence[RunResult]], *, seed: int, max_time: float,
              max_mem: float, run_count: int, total_s: float, setup: str,
              started: datetime.datetime, geometric: bool = False) -> None:
    """Writes the log of one experiment to ``path``. ``planners``: (name in the log, common
    properties {name: value}) in order; ``results``: each planner's runs (by its name), in run
    order; ``max_time`` s and ``max_mem`` MB per run; ``total_s``: s spent collecting;
    ``geometric``: the planners are geometric ones (module docstring)."""
    prefix, properties = ("geometric_", GEOMETRIC_RUN_PROPERTIES) if geometric else \
        ("control_", RUN_PROPERTIES)
    lines = [f"OMPL version {OMPL_VERSION}",
             f"Experiment {experiment}",
             f"Running on {socket.gethostname()}",
             f"Starting at {started:%Y-%m-%d %H:%M:%S}",
             "<<<|", *_text(setup), "|>>>",
             "<<<|", *_text(_cpu_info()), "|>>>",
             f"{seed} is the random seed",
             f"{max_time!r} seconds per run",
             f"{max_mem!r} MB per run",
             f"{run_count} runs per planner",
             f"{total_s!r} seconds spent to collect the data",
             "1 enum types",
             "|".join(("status",) + STATUS),
             f"{len(planners)} planners"]
    for name, common in planners:
        runs = results.get(name, ())
        lines += [f"{prefix}{name}", f"{len(common)} common properties"]
        lines += [f"{key} = {common[key]}" for key in sorted(common)]
        lines += [f"{len(properties)} properties for each run"]
        lines += [f"{prop} {kind}" for prop, kind, _ in properties]
        lines += [f"{len(runs)} runs"]
        lines += ["".join(f"{value(run)}; " for _, _, value in properties) for run in runs]
        lines += ["."]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def _text(text: str) -> list:
    """Free text between <<<| and |>>>: no line of it may start the closing mark."""
    return [line if not line.startswith("|>>>") else " " + line
            for line in text.rstrip("\n").splitlines()]


def _cpu_info() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            model = next((line.split(":", 1)[1].strip() for line in f
                          if line.startswith("model name")), "")
    except OSError:
        model = ""
    return f"{platform.machine()} {model}".strip()


__all__ = ["GEOMETRIC_RUN_PROPERTIES", "OMPL_VERSION", "RUN_PROPERTIES", "STATUS",
           "write_log"]
