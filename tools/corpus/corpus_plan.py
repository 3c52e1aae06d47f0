"""The planning pass of `make corpus` (tools/corpus/run.py): every problem problem_info accepts
that names a planner other than Kautham's ODE planners (``rosrun GUI plan`` routes such a
problem to ``gui.planning.geometric``) is built as ``plan`` builds it and its query searched by
``gui.planning.geometric.solve`` with the problem's own planner and parameters, OMPL seeded
with ``PLAN_SEED``, for the problem's own time limit (``GeometricSettings.of_problem``: its
``_Max Planning Time``; ``cap`` s at most when given).

Each problem is planned in a process of its own, forked from this one once it has imported
what planning uses (``preload``): a crash (a signal) or a hang (no answer
``LOAD_TIMEOUT`` s after its start while it loads, or ``PLAN_MARGIN`` s past its time limit
once it searches) is that problem's failure, and the next starts afresh.

Outcome of a problem (``plan``): solved | not solved (in its time limit) | refused (the one
line of ``PlanningError`` or of the loader: ``REFUSALS`` names its kind) | failed (a traceback,
a crash, a hang, or the collision checks failing) | skipped (a physics problem: its ODE
planner searches through Odin's world, not here; or a problem that names no planner).
"""
from __future__ import annotations

import json
import logging
import os
import re
import signal
import tempfile
import time
from typing import Callable, Optional

import corpus_checks as checks

PLAN_SEED = 1
"""OMPL's seed for every problem: a run is repeatable."""
LOAD_TIMEOUT = checks.PROBLEM_INFO_TIMEOUT
"""s: a problem not searching yet this long after its process started has hung loading."""
PLAN_MARGIN = 30.0
"""s: past a search's time limit, its process has hung. Building the problem's world, checking
its query and the search's overrun took under 1 s past the limit on every problem of the
corpus here (two TIAGos 0.47 s; the planner looks at its clock once per iteration and every
16 checks of a motion); the rest is room for a cold cache of shapes and a loaded machine."""
PLANNED = ("solved", "not solved", "refused", "failed")
"""The outcomes of a problem the pass planned (``skipped`` is the other)."""
REFUSALS = (("no query", re.compile(r"has no query")),
            ("start collides", re.compile(r"query's start collides")),
            ("goal collides", re.compile(r"query's goal collides")),
            ("planner unknown", re.compile(r"is not one of Kautham's geometric planners")),
            ("no controls", re.compile(r"no robot of the problem has controls")),
            ("bad parameter", re.compile(r"must be (positive|in \[)")))
"""(kind, what its line says) of the refusals the report counts apart; any other is
``other``."""
CHECKS_FAILED = re.compile(r"^collision checking failed: ")
"""A PlanningError that is Odin's failure, not the problem's: a collision check raised."""


def preload() -> None:
    """Imports what planning uses before the problems' processes are forked (each then starts
    searching in the time its problem takes to load, not the seconds of imports)."""
    import gui.planning.geometric  # noqa: F401
    import gui.planning.core_world  # noqa: F401
    import gui.planning.bridge  # noqa: F401
    import gui.tools.common  # noqa: F401
    # the Core each search builds its world in (core_world imports it when a world is made)
    import virtual_world.core  # noqa: F401
    from ompl import base, geometric, util  # noqa: F401


def skipped(info: dict) -> Optional[dict]:
    """Why a problem problem_info accepted (its result ``info``) is not planned here (its
    planning result: skip physics | no planner, and the reason), or None when it is."""
    if info["physics"]:
        return dict(plan="skipped", skip="physics", plan_reason=(
            f"a physics problem ({info['planner']}): an OMPL control planner searches it "
            "through Odin's world (rosrun GUI plan), not this pass"))
    if not info.get("planner"):
        return dict(plan="skipped", skip="no planner", plan_reason="names no planner")
    return None


def plan_all(corpus, infos: dict, cap: Optional[float] = None, progress=print) -> dict:
    """{file: its planning result} for every file of ``infos`` ({file: problem_info's result
    of a file it accepted}), in order."""
    out = {}
    for k, (relative, info) in enumerate(infos.items(), start=1):
        out[relative] = skipped(info)
        if out[relative] is not None:
            continue
        progress(f"[plan {k}/{len(infos)}] {relative}", flush=True)
        out[relative] = plan_one(corpus / relative, cap)
    return out


def plan_one(path, cap: Optional[float] = None, child: Optional[Callable[[], int]] = None
             ) -> dict:
    """The planning result of the problem file ``path`` in a process of its own (``child``:
    what that process runs instead, for the tests): {"plan": an outcome, ...}."""
    child = child or (lambda: plan_child(str(path), cap))
    started = time.monotonic()
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        watch = _Watch(out.fileno(), started)
        code = checks.wait(checks.fork(child, out, err), watch.deadline)
        wall = round(time.monotonic() - started, 2)
        lines = [json.loads(line) for line in _read(out.fileno()).splitlines()
                 if line.startswith("{")]
        stderr = _read(err.fileno())
    result = dict(plan_wall_s=wall)
    for line in lines:
        result.update(line)
    if code == 0 and "plan" in result:
        return result
    result.update(plan="failed", plan_traceback="Traceback" in stderr,
                  plan_reason=_failure(code, watch, stderr), plan_trace=stderr[-1500:])
    return result


class _Watch:
    """When a problem's process has hung, from what it has written: ``LOAD_TIMEOUT`` s after
    its start until it says its time limit, then that limit and ``PLAN_MARGIN`` after it
    said so."""

    def __init__(self, fd: int, started: float):
        self.fd = fd
        self.started = started
        self.limit: Optional[float] = None
        self.searching_at = 0.0

    def deadline(self) -> float:
        if self.limit is None:
            said = [json.loads(line) for line in _read(self.fd).splitlines(keepends=True)
                    if line.startswith("{") and line.endswith("\n")]
            limits = [entry["time_limit"] for entry in said if "time_limit" in entry]
            if not limits:
                return self.started + LOAD_TIMEOUT
            self.limit = float(limits[0])
            self.searching_at = time.monotonic()
        return self.searching_at + self.limit + PLAN_MARGIN


def _read(fd: int) -> str:
    """What a child has written to the file ``fd`` so far (without moving its offset)."""
    size = os.fstat(fd).st_size
    return os.pread(fd, size, 0).decode(errors="replace") if size else ""


def _failure(code: Optional[int], watch: _Watch, stderr: str) -> str:
    """The one-line reason of a problem's process that gave no outcome."""
    if code is None:
        if watch.limit is None:
            return f"hung loading the problem (no search after {LOAD_TIMEOUT:g} s)"
        return (f"hung: still searching {PLAN_MARGIN:g} s past its {watch.limit:g} s time "
                "limit")
    if code < 0:
        return f"crashed: {signal.Signals(-code).name}"
    # a traceback's own lines are indented: its last unindented line says what was raised
    said = [line for line in stderr.splitlines() if line.strip() and not line[0].isspace()]
    return f"exit {code}: " + (said[-1][-600:] if said else "no output")


def refusal_kind(reason: str) -> str:
    """The kind of a refusal's line (``REFUSALS``), else ``other``."""
    return next((kind for kind, pattern in REFUSALS if pattern.search(reason)), "other")


# -- the problem's process ------------------------------------------------------------------------

def plan_child(path: str, cap: Optional[float]) -> int:
    """Plans ``path`` (in the problem's process): prints one JSON line with the planner and
    time limit once it has them, then one with the outcome."""
    from dataclasses import replace

    from gui.errors import GuiError, PlanningError
    from gui.planning.geometric import GeometricSettings, solve
    from gui.tools.common import ProblemFile
    logging.disable(logging.WARNING)    # the loader's warnings: problem_info reports them
    try:
        plan = ProblemFile(path).read()
        settings = GeometricSettings.of_problem(plan)
    except GuiError as error:
        return _say(_refused(error))
    limit = settings.time_limit if cap is None else min(settings.time_limit, cap)
    settings = replace(settings, time_limit=limit)
    _say(dict(ompl_planner=settings.planner, time_limit=limit))
    try:
        result = solve(plan, settings, PLAN_SEED)
    except PlanningError as error:
        return _say(_refused(error))
    return _say(dict(plan="solved" if result.solved else "not solved",
                     plan_s=round(result.time_s, 3), states=result.states,
                     checks=result.checks, length=round(result.length, 6),
                     graph_states=result.graph_states))


def _refused(error) -> dict:
    line = " ".join(str(error).split())[:600]
    if CHECKS_FAILED.search(line):
        return dict(plan="failed", plan_reason=line, plan_traceback=False)
    return dict(plan="refused", plan_reason=line, refusal=refusal_kind(line))


def _say(entry: dict) -> int:
    print(json.dumps(entry), flush=True)
    return 0
