"""``rosrun GUI load_problem PROBLEM``: a Kautham problem built in a running VirtualWorld, all
or nothing (``gui.planning.rehearsal.load_scene``), the world left paused at its start."""
from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Optional, Sequence

from gui.tools.common import (ProblemFile, ToolParser, add_build_options, add_timeout_option,
                              check_master, one_line_errors, warnings_to_stderr)

if TYPE_CHECKING:
    from gui.ros.client import WorldClient

TOOL = "load_problem"


@dataclass(frozen=True)
class LoadRequest:
    """What load_problem is asked: the problem; ``keep``: add it to the world's scene instead
    of a new one; ``timeout``: s to wait for the ROS master, then for each of the world's
    services."""
    problem: ProblemFile
    keep: bool = False
    timeout: float = 10.0


class _WorldConnection:
    """A WorldClient made on a thread of its own, started before the problem is read: joining
    the ROS graph and finding the world (~0.25 s, mostly waiting on the master) then overlaps
    reading the problem and making its build plan (~0.5 s) instead of following it."""

    def __init__(self, timeout: float):
        # imported here, not on the thread (the service classes too, which WorldClient
        # imports when made): two threads importing modules at once can deadlock on their locks
        import Services.srv  # noqa: F401
        from gui.ros.client import WorldClient
        self._client = None
        self._error: Optional[BaseException] = None
        self._thread = threading.Thread(target=self._connect, args=(WorldClient, timeout),
                                        name="connect to the world", daemon=True)
        self._thread.start()

    def _connect(self, world_client, timeout: float) -> None:
        try:
            self._client = world_client(timeout=timeout)
        except BaseException as error:  # handed to the main thread by client()
            self._error = error

    def client(self) -> WorldClient:
        """The connected WorldClient; raises what connecting raised (WorldError when no
        world answers within the timeout)."""
        self._thread.join()
        if self._error is not None:
            raise self._error
        return self._client


def load(request: LoadRequest, say: Callable[[str], None]) -> str:
    """Builds the problem in the world (its build plan first rehearsed in this process unless
    a rehearsal of the same plan passed before: ``gui.planning.rehearsal_cache``); ``say``
    is told how long reading took and each request's answer. Returns the world's namespace;
    OdinError when the master, the world or the problem refuses."""
    started = time.monotonic()
    check_master(TOOL, request.timeout)
    connection = _WorldConnection(request.timeout)
    build_plan = request.problem.read()
    total = len(build_plan.steps)
    say(f"loaded {request.problem.path} in {time.monotonic() - started:.2f} s: {total} "
        "requests")
    from gui.planning.rehearsal import load_scene, warm_up
    from gui.planning.rehearsal_cache import plan_digest, seen
    digest = plan_digest(build_plan)
    if not seen(digest):    # a rehearsal to come: its imports while the world is found
        warm_up()           # (the connecting thread imports nothing)
    client = connection.client()

    def progress(k: int, step, answer_id: str) -> None:
        say(f"[{k}/{total}] {step.label()} -> {answer_id}")

    load_scene(client, build_plan, keep=request.keep, progress=progress,
               plan_key=digest)
    return client.namespace


def _say(line: str) -> None:
    print(line, flush=True)


def _parser() -> ToolParser:
    parser = ToolParser(
        prog=TOOL, description="Build a Kautham problem in a running VirtualWorld.")
    parser.add_argument("problem", help="problem XML file")
    parser.add_argument("--keep", action="store_true",
                        help="add to the current scene instead of calling New Scene first "
                        "(the problem is first built alone, in the room the world has left, "
                        "in this process; a clash with what the world holds is refused by "
                        "the world, and what was built of the problem removed)")
    add_timeout_option(parser)
    add_build_options(parser)
    return parser


@one_line_errors(TOOL)
def main(argv: Optional[Sequence[str]] = None) -> int:
    args = _parser().parse_args(argv)
    request = LoadRequest(ProblemFile.of_args(args), keep=args.keep, timeout=args.timeout)
    warnings_to_stderr(TOOL)
    started = time.monotonic()
    namespace = load(request, _say)
    print(f"built {request.problem.path} in {time.monotonic() - started:.2f} s; the world is "
          f"paused at its start (rosservice call {namespace}/start \"simulate: true\" runs "
          f"it)", flush=True)
    return 0


__all__ = ["LoadRequest", "load", "main"]
