"""What a benchmark asks for: Kautham's ``<Benchmark>`` files, or the same from the command line
(ROS-free, OMPL-free; ``gui.planning.benchmark`` runs it).

Kautham's console reads a benchmark file (``apps/console/benchmark.cpp``) as:

- one or more ``<Benchmark Name="...">`` elements side by side (pugixml reads several top-level
  elements; each is an experiment of its own with a log of its own; ``Name`` defaults to
  "NO_NAME");
- in each, ``<Problem File="..." PlannerAlias="..."/>`` rows: ``File`` relative to the
  benchmark file's folder; each row adds that problem's ``<Planner>`` to the experiment, named
  by its alias in the log (Kautham builds the world from the first row's problem and takes only
  the planner from the others; Odin runs each row on its own file, which is the same world when
  the rows share it, as Kautham's demos do);
- ``<Parameter Name="..." Value="..."/>`` rows, OMPL's Benchmark::Request: ``maxTime`` (s per
  run, 5), ``maxMem`` (MB per run, 4096), ``runCount`` (100), ``timeBetweenUpdates`` (s, 0.05),
  ``displayProgress`` and ``saveConsoleOutput`` (true), ``filename`` (the log's name; Kautham
  writes it beside the benchmark file, Odin in the output folder). Any other name, or a row
  without ``Value``, is an error (Kautham: "Incorrect name", "No value").

Odin's control planners are OMPL's KPIECE1, RRT and EST; a problem's own ``<Planner>`` (one of
Kautham's ODE planners) stands for the OMPL planner it is built on (``OMPL_PLANNER_OF``).
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, replace
from typing import Optional, Sequence, Tuple

from gui.core.kautham.xmlfile import Node, parse_xml_bytes
from gui.core.sizes import read_input_file
from gui.errors import PlanningError, ProblemError

OMPL_PLANNER_OF = {
    "KPIECE2DPlanner": "KPIECE1", "KnowledgeOrientedKPIECE2DPlanner": "KPIECE1",
    "KPIECECarPlanner": "KPIECE1", "KPIECEChainPlanner": "KPIECE1",
    "RRT2DPlanner": "RRT", "KnowledgeOrientedRRT2DPlanner": "RRT",
}
"""Kautham's ODE planners and the OMPL control planner each is built on (the knowledge-oriented
ones add Kautham's own sampling, which Odin does not have: plain KPIECE1 or RRT here)."""


@dataclass(frozen=True)
class Request:
    """OMPL's Benchmark::Request as Kautham's ``<Parameter>`` rows set it. ``max_time``: s of
    wall clock per run (None: each problem's own ``_Max Planning Time``, else 10 s: the
    command-line form's default); ``max_mem``: MB a run's process may grow by during its
    search (OMPL's rule: the search ends there, as the clock would end it); ``run_count``:
    runs per planner; ``time_between_updates``: s (Odin's runs report no progress series:
    kept for the log); ``display_progress``: the progress line;
    ``filename``: the log's file name ("" : ``<experiment>.log``)."""
    max_time: Optional[float] = 5.0
    max_mem: float = 4096.0
    run_count: int = 100
    time_between_updates: float = 0.05
    display_progress: bool = True
    save_console_output: bool = True
    filename: str = ""


@dataclass(frozen=True)
class Row:
    """One planner configuration of an experiment: ``problem`` (a path), ``planner`` (an OMPL
    planner's name, or None: the problem's own ``<Planner>``), ``alias`` (its name in the log,
    "" for the planner's), ``where`` ("file:line" of its ``<Problem>``, or "--problem")."""
    problem: str
    planner: Optional[str] = None
    alias: str = ""
    where: str = ""

    def name(self, planner: str) -> str:
        """The planner's name in the log: the alias, with the planner's name when the command
        line chose it for every row (a row's alias then stands for its problem)."""
        if not self.alias:
            return planner
        return self.alias if self.planner is None else f"{self.alias}-{planner}"


@dataclass(frozen=True)
class Experiment:
    """One ``<Benchmark>``: its ``name``, ``rows`` and ``request``."""
    name: str
    rows: Tuple[Row, ...]
    request: Request

    @property
    def log_name(self) -> str:
        return os.path.basename(self.request.filename) or f"{_safe(self.name)}.log"


_PARAMETERS = {"maxtime": "max_time", "maxmem": "max_mem", "runcount": "run_count",
               "timebetweenupdates": "time_between_updates",
               "displayprogress": "display_progress",
               "saveconsoleoutput": "save_console_output", "filename": "filename"}
_XML_DECLARATION = re.compile(rb"^\s*<\?xml[^>]*\?>")


def read_benchmark_file(path: str) -> Tuple[Experiment, ...]:
    """The experiments of Kautham's benchmark file ``path``. A ``ProblemError`` names the file
    and line of anything wrong (no ``<Benchmark>``, no ``<Problem>``, a row without ``File``,
    an unknown or valueless ``<Parameter>``, a bad number)."""
    data = read_input_file(path, "benchmark file", ProblemError)
    # Several <Benchmark> elements side by side, as pugixml reads them: one synthetic root
    # around them, on the first line, so that every line keeps its number.
    data = _XML_DECLARATION.sub(b"", data, count=1)
    root = parse_xml_bytes(b"<OdinBenchmarks>" + data + b"</OdinBenchmarks>", path)
    folder = os.path.dirname(os.path.abspath(path))
    experiments = tuple(_experiment(node, folder) for node in root.findall("Benchmark"))
    if not experiments:
        raise ProblemError("no <Benchmark> element", path, 1)
    return experiments


def _experiment(node: Node, folder: str) -> Experiment:
    rows = []
    for problem in node.findall("Problem"):
        file = problem.require("File")
        rows.append(Row(os.path.normpath(os.path.join(folder, file)), None,
                        problem.get("PlannerAlias", "") or "", f"{problem.path}:{problem.line}"))
    if not rows:
        raise node.error("<Benchmark> has no <Problem File=... PlannerAlias=...> row")
    request = Request()
    for parameter in node.findall("Parameter"):
        request = _parameter(parameter, request)
    return Experiment(node.get("Name") or "NO_NAME", tuple(rows), request)


def _parameter(node: Node, request: Request) -> Request:
    name = node.require("Name")
    field = _PARAMETERS.get(name.strip().lower())
    if field is None:
        raise node.error(f"<Parameter Name=\"{name}\">: not one of Kautham's benchmark "
                         f"parameters ({', '.join(sorted(_PARAMETERS.values()))})")
    if node.get("Value") is None:
        raise node.error(f"<Parameter Name=\"{name}\"> has no Value=")
    if field in ("display_progress", "save_console_output"):
        return replace(request, **{field: node.flag("Value", True)})
    if field == "filename":
        return replace(request, filename=node.get("Value").strip())
    value = node.number("Value")
    if field == "run_count":
        if value != int(value) or value < 1:
            raise node.error(f"<Parameter Name=\"runCount\" Value=\"{node.get('Value')}\">: "
                             "a whole number of runs, at least 1")
        return replace(request, run_count=int(value))
    if value <= 0:
        raise node.error(f"<Parameter Name=\"{name}\" Value=\"{node.get('Value')}\">: must "
                         "be positive")
    return replace(request, **{field: value})


def command_line_experiments(problems: Sequence[str], planners: Optional[Sequence[str]],
                             runs: int, time_limit: Optional[float],
                             max_mem: Optional[float] = None) -> Tuple[Experiment, ...]:
    """``--problem P ... --planners A,B --runs N --time S --max-mem MB``: one experiment per
    problem, named after its file, with every planner (None: the problem's own)."""
    experiments = []
    for problem in problems:
        rows = tuple(Row(os.path.abspath(problem), p, "", "--problem")
                     for p in (planners or [None]))
        name = os.path.splitext(os.path.basename(problem))[0]
        request = Request(max_time=time_limit, run_count=runs,
                          max_mem=max_mem or Request.max_mem)
        experiments.append(Experiment(name, rows, request))
    names = [e.name for e in experiments]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise PlanningError(f"--problem: two problems are both called {twice[0]!r}: their "
                            "logs would be one file")
    return tuple(experiments)


def with_planners(experiments: Sequence[Experiment], planners: Sequence[str]
                  ) -> Tuple[Experiment, ...]:
    """Every row of ``experiments`` with each of ``planners`` instead of its own."""
    return tuple(replace(e, rows=tuple(replace(r, planner=p) for r in e.rows
                                       for p in planners)) for e in experiments)


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "experiment"


__all__ = ["OMPL_PLANNER_OF", "Experiment", "Request", "Row", "command_line_experiments",
           "read_benchmark_file", "with_planners"]
