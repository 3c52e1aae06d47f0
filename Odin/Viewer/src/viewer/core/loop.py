"""The render thread: the one thread that owns the scene and the OpenGL context.

Other threads (rospy's service and subscriber threads) never touch the scene or GL: they hand
work to the loop. :meth:`RenderLoop.call` runs a function on the render thread between frames
and returns its result (or raises its exception) in the caller's thread; :meth:`RenderLoop.post`
queues one without waiting, :meth:`RenderLoop.post_later` one to run once a delay has passed. Work
is done in the order it arrived, as soon as the thread is free, and a frame is rendered every 1/rate
seconds whatever arrives, then handed to ``on_frame`` -- while someone wants frames (``wanted``): a
Viewer nobody watches renders nothing and costs no CPU beyond keeping its scene up to date (a frame
of the TX90 scene is tens of ms of a core). ROS-free: the Portal wires it to topics and services.
"""
from __future__ import annotations

import collections
import heapq
import itertools
import logging
import threading
import time
from typing import Callable, Optional

import numpy as np

from viewer.errors import ViewerError
from viewer.core.scene import Scene

log = logging.getLogger(__name__)


class _Job:
    __slots__ = ("fn", "done", "result", "error")

    def __init__(self, fn: Callable) -> None:
        self.fn = fn
        self.done = threading.Event()
        self.result = None
        self.error: Optional[BaseException] = None


class RenderLoop:
    """Renders ``scene`` at ``rate_hz`` on a thread of its own.

    on_frame(frame (h, w, 3) uint8 RGB, number) is called on the render thread after each frame
    (number counts from 1); it must be quick (publish, queue for writing).
    wanted() is asked once a period on the render thread: False skips that period's frame (it
    must be quick too: a subscriber count). None: always wanted.
    renderer_factory() is called on the render thread and returns an object with
    ``render(scene) -> frame`` and ``close()`` (normally :class:`viewer.core.renderer.Renderer`).
    """

    def __init__(self, scene: Scene, renderer_factory: Callable, rate_hz: float = 25.0,
                 on_frame: Optional[Callable] = None,
                 wanted: Optional[Callable[[], bool]] = None) -> None:
        if not (rate_hz > 0 and rate_hz < 1000):
            raise ViewerError(f"render rate must be in (0, 1000) Hz, got {rate_hz}")
        self.scene = scene
        self.period = 1.0 / rate_hz
        self._renderer_factory = renderer_factory
        self._on_frame = on_frame
        self._wanted = wanted
        self._jobs: collections.deque = collections.deque()
        self._later: list = []                 # heap of (due, order, job): post_later
        self._order = itertools.count()
        self._wake = threading.Condition()
        self._running = False
        self._thread: Optional[threading.Thread] = None
        self._started = threading.Event()
        self._start_error: Optional[BaseException] = None
        self.renderer = None
        self.frames = 0
        self.last_frame: Optional[np.ndarray] = None
        self.render_errors = 0

    # -- lifecycle -------------------------------------------------------------------------
    def start(self, timeout: float = 30.0) -> None:
        """Starts the thread; raises if the renderer cannot be created there."""
        self._running = True
        self._thread = threading.Thread(target=self._run, name="viewer-render", daemon=True)
        self._thread.start()
        if not self._started.wait(timeout):
            raise ViewerError(f"the render thread did not start within {timeout} s")
        if self._start_error is not None:
            raise ViewerError(f"cannot start rendering: {self._start_error}")

    def stop(self, timeout: float = 10.0) -> None:
        """Stops the thread after the frame under way; frees the renderer (idempotent)."""
        with self._wake:
            self._running = False
            self._wake.notify_all()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout)

    def __enter__(self) -> "RenderLoop":
        self.start()
        return self

    def __exit__(self, *exc_info) -> None:
        self.stop()

    # -- work from other threads -----------------------------------------------------------
    def post(self, fn: Callable) -> None:
        """Queues fn(scene, renderer) for the render thread; errors are logged, not raised."""
        with self._wake:
            self._jobs.append(_Job(fn))
            self._wake.notify_all()

    def post_later(self, delay: float, fn: Callable) -> None:
        """Queues fn(scene, renderer) for the render thread once ``delay`` s have passed
        (jobs of equal delay run in the order posted); errors are logged, not raised."""
        with self._wake:
            heapq.heappush(self._later, (time.monotonic() + delay, next(self._order), _Job(fn)))
            self._wake.notify_all()

    def call(self, fn: Callable, timeout: float = 10.0):
        """Runs fn(scene, renderer) on the render thread; returns its result or raises its
        exception here. Raises ViewerError if the loop is not running or takes over timeout s."""
        if threading.current_thread() is self._thread:
            return fn(self.scene, self.renderer)
        if not self._running:
            raise ViewerError("the Viewer's render thread is not running")
        job = _Job(fn)
        with self._wake:
            self._jobs.append(job)
            self._wake.notify_all()
        if not job.done.wait(timeout):
            raise ViewerError(f"the render thread did not answer within {timeout} s")
        if job.error is not None:
            raise job.error
        return job.result

    # -- the thread ------------------------------------------------------------------------
    def _run(self) -> None:
        try:
            self.renderer = self._renderer_factory()
        except Exception as error:  # reported to start(), which raises it in the caller
            self._start_error = error
            self._running = False
            self._started.set()
            return
        self._started.set()
        deadline = time.monotonic()
        try:
            while True:
                with self._wake:
                    while self._running and not self._jobs:
                        wake_at = min(deadline, self._later[0][0]) if self._later else deadline
                        if time.monotonic() >= wake_at:
                            break
                        self._wake.wait(max(0.0, wake_at - time.monotonic()))
                    if not self._running:
                        break
                    jobs, self._jobs = self._jobs, collections.deque()
                    while self._later and self._later[0][0] <= time.monotonic():
                        jobs.append(heapq.heappop(self._later)[2])
                for job in jobs:
                    self._do(job)
                now = time.monotonic()
                if now >= deadline:
                    if self._frame_wanted():
                        self._render_one()
                    deadline += self.period
                    if deadline < time.monotonic():   # late: next frame at once, no burst
                        deadline = time.monotonic()
        finally:
            with self._wake:
                self._running = False
                leftover, self._jobs = self._jobs, collections.deque()
                leftover.extend(job for _, _, job in self._later)
                self._later = []
            for job in leftover:
                job.error = ViewerError("the Viewer is shutting down")
                job.done.set()
            try:
                self.renderer.close()
            except Exception:  # closing must not hide why the loop ended
                log.exception("closing the renderer failed")

    def _do(self, job: _Job) -> None:
        try:
            job.result = job.fn(self.scene, self.renderer)
        except Exception as error:  # anything a caller sent must not end the loop
            job.error = error
            if not isinstance(error, ViewerError):
                log.exception("viewer job failed")
        finally:
            job.done.set()

    def _frame_wanted(self) -> bool:
        if self._wanted is None:
            return True
        try:
            return bool(self._wanted())
        except Exception:  # a failing question must not stop the frames: render
            self.render_errors += 1
            if self.render_errors <= 5:
                log.exception("asking whether a frame is wanted failed")
            return True

    def _render_one(self) -> None:
        try:
            frame = self.renderer.render(self.scene)
        except Exception:  # keep rendering whatever one frame did
            self.render_errors += 1
            if self.render_errors <= 5:
                log.exception("rendering a frame failed")
            return
        self.frames += 1
        self.last_frame = frame
        if self._on_frame is not None:
            try:
                self._on_frame(frame, self.frames)
            except Exception:
                log.exception("handling frame %d failed", self.frames)
