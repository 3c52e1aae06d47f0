"""Parallel searches (ROS-free here): one problem searched by several independent OMPL
searches at once, each in a process of its own with a back end of its own and its own seed;
the first exact solution wins and the others stop.

OMPL's control planners call their propagator one motion at a time, so a single search cannot
use a second core (the pool back end spreads a batch, and a search makes batches of one). A
sampling planner's time to a solution varies widely from seed to seed, so N searches with N
seeds on N cores finish at the fastest one's time: on this machine's 2 cores the median time
to a solution falls toward the best of two draws. With the pool back end each search gets its
own share of the pool's world nodes (on one host or several).

Processes are forked: each child inherits the problem's build plan and makes its back end
(``make_backend(k)``), seeds OMPL with ``seed + k`` (OMPL seeds a process once) and searches;
the parent never loads OMPL before forking.
"""
from __future__ import annotations

import multiprocessing
import queue
import time
from dataclasses import dataclass
from typing import Callable, List, Optional, Tuple

from gui.errors import PlanningError
from gui.planning.bridge import PlanResult, check_seed, plan

START_GRACE_S = 60.0
"""s: how long a child may take to build its back end before its search starts."""

MAX_SEARCHES = 64
"""Searches (processes) one parallel run may start: each is a process of its own with a world
of its own (~150 MB), and a search cannot use more than one core; more than the host has
cores only share them."""


@dataclass(frozen=True)
class SearchOutcome:
    """One search of a parallel run: its seed and result, or the error that ended it, or
    neither when it was stopped because another search solved first."""
    seed: int
    result: Optional[PlanResult] = None
    error: str = ""

    def summary(self) -> dict:
        if self.result is None:
            return {"seed": self.seed, "error": self.error} if self.error else \
                {"seed": self.seed, "stopped": True}
        r = self.result
        return {"seed": self.seed, "solved": r.solved, "time_s": round(r.time_s, 3),
                "goal_distance_m": round(r.goal_distance, 4), "propagations": r.propagations}


def _search(make_backend, index: int, planner: str, time_limit: float, seed: int,
            answers, stop) -> None:
    """A child's work: its back end, its search, its answer on the queue."""
    try:
        backend = make_backend(index)
        try:
            answers.put((index, plan(backend, planner, time_limit, seed, stop), ""))
        finally:
            backend.close()
    except BaseException as error:     # noqa: B902 - told to the parent, never lost
        answers.put((index, None, f"{type(error).__name__}: {error}"))


def plan_in_parallel(make_backend: Callable[[int], object], count: int, planner: str,
                     time_limit: float, seed: int, stop: Optional[Callable[[], bool]] = None
                     ) -> Tuple[PlanResult, List[SearchOutcome]]:
    """``count`` searches of ``planner`` at once, search k with ``make_backend(k)`` and seed
    ``seed + k``, each for at most ``time_limit`` s: (the first exact solution, or the
    closest approximate one when none solved; every search's outcome). PlanningError when
    every search failed. ``stop()`` true (asked every 0.1 s; each child asks its own copy,
    which its own Ctrl-C sets: a terminal's Ctrl-C reaches the whole process group) ends
    every search, waits for the children to be gone and raises KeyboardInterrupt."""
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_SEARCHES:
        raise PlanningError(f"parallel searches {count!r}: need a whole number in [1, "
                            f"{MAX_SEARCHES}] (MAX_SEARCHES)")
    check_seed(seed, room=count)
    context = multiprocessing.get_context("fork")
    answers = context.Queue()
    children = [context.Process(target=_search, daemon=True, name=f"search{k}",
                                args=(make_backend, k, planner, time_limit, seed + k, answers,
                                      stop))
                for k in range(count)]
    for child in children:
        child.start()
    outcomes: List[Optional[SearchOutcome]] = [None] * count
    deadline = time.monotonic() + time_limit + START_GRACE_S
    try:
        while any(o is None for o in outcomes):
            if stop is not None and stop():
                break
            try:
                index, result, error = answers.get(timeout=0.1)
            except queue.Empty:
                if time.monotonic() >= deadline:
                    break
                continue
            outcomes[index] = SearchOutcome(seed + index, result, error)
            if result is not None and result.solved:
                break
    finally:
        for child in children:
            if child.is_alive():
                child.terminate()
        for child in children:
            child.join(timeout=5.0)
    if stop is not None and stop():
        raise KeyboardInterrupt
    outcomes = [o or SearchOutcome(seed + k, error="" if _solved(outcomes) else "no answer")
                for k, o in enumerate(outcomes)]
    return _best(outcomes), outcomes


def _solved(outcomes) -> bool:
    return any(o is not None and o.result is not None and o.result.solved for o in outcomes)


def _best(outcomes: List[SearchOutcome]) -> PlanResult:
    results = [o.result for o in outcomes if o.result is not None]
    if not results:
        raise PlanningError("every search failed: " + "; ".join(
            f"seed {o.seed}: {o.error}" for o in outcomes))
    solved = [r for r in results if r.solved]
    return solved[0] if solved else min(results, key=lambda r: r.goal_distance)


__all__ = ["SearchOutcome", "plan_in_parallel"]
