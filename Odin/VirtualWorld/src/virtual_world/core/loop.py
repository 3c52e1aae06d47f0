"""The Portal's running loop without ROS: one thread owns the Core and everything it touches.

rospy answers every service call on a thread of its own. Those threads never touch the Core:
they hand a function to :meth:`WorldLoop.call`, which queues it and waits for the loop thread
to run it *between* steps. A call can therefore never meet a half-done step, and the answer
the caller gets is the one computed on the world as it is.

One cycle (thesis 4.4):

1. serve the queued calls (while waiting for the next tick, calls run as soon as they arrive,
   so a paused world answers at once);
2. if simulating, advance the Core by ``steps_per_cycle`` steps of ``step`` seconds;
3. hand the cycle's output to ``publish`` (the Portal turns it into messages).

Ticks follow ``rate`` on the wall clock. A cycle that overruns its period starts the next one at
once without trying to catch up. With ``free_run`` cycles run back to back, as fast as the
machine allows, and ``publish`` is told to publish only ``rate`` times per wall-clock second.
"""
from __future__ import annotations

import collections
import dataclasses
import logging
import queue
import threading
import time
from typing import Any, Callable

from odin_common import limits
from odin_common.errors import InvalidArgument as CommonInvalidArgument
from odin_common.limits import shown
from virtual_world.core.step_values import StepValues
from virtual_world.errors import InvalidArgument

_log = logging.getLogger(__name__)

#: Most cycles one Step Once request may ask for (a request must not hold the world for long).
MAX_STEP_ONCE_CYCLES = 100_000

#: Share of a cycle's period that queued calls may take before the cycle steps and publishes;
#: the rest of the calls wait for the next cycle, so a burst of calls never stalls publication.
CALL_BUDGET_SHARE = 0.5


class LoopStopped(RuntimeError):
    """The loop ended before the call could run."""


@dataclasses.dataclass
class _PendingCall:
    function: Callable[[], Any]
    done: threading.Event = dataclasses.field(default_factory=threading.Event)
    result: Any = None
    error: BaseException | None = None


@dataclasses.dataclass(frozen=True)
class CycleReport:
    """What one cycle did, for publication and statistics."""

    sim_time: float            # s, simulated time after the cycle
    stepped: bool              # the Core advanced in this cycle
    wall_time: float           # s, time.monotonic() at the end of the cycle
    publish_due: bool          # free run: True only at the publication rate


class RealTimeFactor:
    """Simulated seconds per wall-clock second over a sliding window of cycles."""

    def __init__(self, window: float = 1.0):
        self._window = window
        self._samples: collections.deque = collections.deque()

    def add(self, wall_time: float, sim_time: float) -> float:
        self._samples.append((wall_time, sim_time))
        while len(self._samples) > 2 and wall_time - self._samples[1][0] >= self._window:
            self._samples.popleft()
        (wall0, sim0), (wall1, sim1) = self._samples[0], self._samples[-1]
        return (sim1 - sim0) / (wall1 - wall0) if wall1 > wall0 else 0.0


class WorldLoop:
    """Runs cycles on the thread that calls :meth:`run`; other threads use :meth:`call`.

    ``advance(step, count)`` advances the simulation and returns the simulated time;
    ``publish(report)`` publishes the state of the world. Both run on the loop thread.
    """

    def __init__(self, advance: Callable[[float, int], float],
                 publish: Callable[[CycleReport], None],
                 step_values: StepValues = StepValues(), simulate: bool = False,
                 free_run: bool = False, bodies: Callable[[], int] = lambda: 1):
        """``bodies()``: how many bodies a step advances (Core.body_count), which bounds a
        Step Once's work (odin_common.limits.MAX_BODY_STEPS_PER_CALL)."""
        self._bodies = bodies
        self._advance = advance
        self._publish = publish
        self.step_values = step_values
        self.simulate = simulate
        self.free_run = free_run
        self.sim_time = 0.0
        self._calls: queue.SimpleQueue = queue.SimpleQueue()
        self._stop = threading.Event()
        self._loop_thread: threading.Thread | None = None
        self._last_publication = float("-inf")

    # -- used from any thread ---------------------------------------------------------------
    def call(self, function: Callable[[], Any], timeout: float | None = None) -> Any:
        """Runs ``function`` on the loop thread between steps and returns its result (or raises
        its exception). From the loop thread itself it runs at once."""
        if threading.current_thread() is self._loop_thread:
            return function()
        if self._stop.is_set():
            raise LoopStopped("the world loop has stopped")
        pending = _PendingCall(function)
        self._calls.put(pending)
        if not pending.done.wait(timeout):
            raise TimeoutError("the world loop did not serve the call in time")
        if pending.error is not None:
            raise pending.error
        return pending.result

    def stop(self) -> None:
        self._stop.set()
        self._calls.put(None)  # wakes the loop if it waits for calls

    # -- used on the loop thread ------------------------------------------------------------
    def advance_cycle(self) -> CycleReport:
        """Steps one cycle now (Step Once and the running loop), then publishes."""
        values = self.step_values
        self.sim_time = self._advance(values.step, values.steps_per_cycle)
        return self._finish_cycle(stepped=True, force_publish=True)

    def step_cycles(self, cycles: int, cancelled: Callable[[], object] = lambda: None) -> float:
        """Step Once: ``cycles`` whole cycles (0 means 1) of a paused world, each published;
        returns the simulated time after them. ``cancelled()`` is asked before each cycle:
        when the caller has gone the cycles done so far stand (each was published), as if
        it had asked for fewer, and the rest are not run."""
        if self.simulate:
            raise InvalidArgument("the simulation is running: pause it (Start false) to step once")
        cycles = cycles or 1
        if cycles > MAX_STEP_ONCE_CYCLES:
            raise InvalidArgument(f"cycles must be at most {MAX_STEP_ONCE_CYCLES}, got "
                                  f"{shown(cycles)}")
        try:
            limits.check_work(f"Step Once of {cycles:,} cycles",
                              cycles * self.step_values.steps_per_cycle, self._bodies())
        except CommonInvalidArgument as error:
            raise InvalidArgument(str(error)) from None
        for done in range(cycles):
            why = cancelled()
            if why:
                _log.info("Step Once stopped, %d cycle(s) not run: %s", cycles - done,
                          why if isinstance(why, str) else "the caller has gone")
                break
            self.advance_cycle()
        return self.sim_time

    def run(self) -> None:
        """The running loop; returns after :meth:`stop`, failing every call still queued."""
        self._loop_thread = threading.current_thread()
        next_tick = time.monotonic()
        try:
            while not self._stop.is_set():
                period = self.step_values.period
                self._serve_calls(until=next_tick, budget=CALL_BUDGET_SHARE * period)
                if self._stop.is_set():
                    break
                if self.simulate:
                    self.sim_time = self._advance(self.step_values.step,
                                                  self.step_values.steps_per_cycle)
                self._finish_cycle(stepped=self.simulate, force_publish=not self.free_run)
                now = time.monotonic()
                next_tick = (now if (self.free_run and self.simulate)
                             else max(next_tick + period, now))
        finally:
            self._fail_queued_calls()

    def _finish_cycle(self, stepped: bool, force_publish: bool) -> CycleReport:
        now = time.monotonic()
        due = force_publish or now - self._last_publication >= self.step_values.period
        if due:
            self._last_publication = now
        report = CycleReport(self.sim_time, stepped, now, due)
        self._publish(report)
        return report

    def _serve_calls(self, until: float, budget: float) -> None:
        """Runs queued calls: all that arrive before ``until``; past it, at most ``budget``
        seconds more of those already queued."""
        hard_stop = max(until, time.monotonic()) + budget
        while not self._stop.is_set():
            now = time.monotonic()
            wait = until - now
            try:
                pending = self._calls.get(timeout=wait) if wait > 0 else self._calls.get_nowait()
            except queue.Empty:
                return
            if pending is None:
                continue
            self._run(pending)
            if time.monotonic() >= hard_stop:
                return

    @staticmethod
    def _run(pending: _PendingCall) -> None:
        try:
            pending.result = pending.function()
        except BaseException as error:  # handed to the calling thread, which re-raises it
            pending.error = error
        finally:
            pending.done.set()

    def _fail_queued_calls(self) -> None:
        while True:
            try:
                pending = self._calls.get_nowait()
            except queue.Empty:
                return
            if pending is not None:
                pending.error = LoopStopped("the world loop has stopped")
                pending.done.set()
