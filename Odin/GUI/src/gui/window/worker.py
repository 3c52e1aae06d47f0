"""The Qt side of the world client: service calls on a thread of their own, never the GUI's.

``WorldWorker`` is a ``QThread`` that owns one ``gui.ros.client.WorldClient`` (persistent service
proxies are not shared between threads) and runs *jobs* from a queue one at a time; given
``node=VIEWER`` it owns a ``gui.ros.viewer.ViewerClient`` instead (the Viewer panel's camera).
A job is a callable ``fn(client, job) -> result``; its result or the error's message comes
back to the GUI thread through Qt signals (queued connections), where the ``on_done`` /
``on_error`` callbacks given to ``submit`` run.

Connection: while no world answers, the worker polls the master for the world's services every
``poll_period`` seconds; jobs submitted meanwhile fail at once with a message saying the world is
absent. Once connected, the worker checks the world is still registered, and its node answers
(gui.ros.services.node_answers), every ``poll_period`` seconds while idle, and drops the
connection when a call breaks.

Long jobs (paths) look at ``job.cancelled`` / call ``job.sleep(seconds)``, which raises
``Cancelled`` as soon as ``cancel()`` is called.

Given ``node=None`` the worker serves no node: its jobs are work of this process (a geometric
search, gui.window.solve_panel) run with ``client`` None, off the GUI thread and off the
world's queue; it never polls a master.
"""
from __future__ import annotations

import itertools
import queue
import threading
import time
import traceback
from dataclasses import dataclass, field
from typing import Any, Callable, NamedTuple, Optional

from PyQt5.QtCore import QThread, pyqtSignal

from gui.errors import GuiError, ServiceError
from gui.ros.services import node_answers
from odin_common.interface import WORLD_NAMESPACE


def _world_client(namespace: str, timeout: float):
    from gui.ros.client import WorldClient
    return WorldClient(namespace, timeout=timeout)


def _viewer_client(namespace: str, timeout: float):
    from gui.ros.viewer import ViewerClient
    return ViewerClient(namespace, timeout=timeout)


class NodeKind(NamedTuple):
    """What a worker serves: the node's name in the window's messages, the service whose
    registration says the node is up, and its client's constructor ``(namespace, timeout s)``."""
    title: str
    probe: str
    connect: Callable[[str, float], Any]


WORLD = NodeKind("VirtualWorld", "set_joint_force", _world_client)
VIEWER = NodeKind("Viewer", "set_camera", _viewer_client)


class Cancelled(GuiError):
    """A job stopped on the user's request."""


@dataclass(eq=False)
class Job:
    """One unit of work for the worker. ``fn(client, job)`` runs on the worker's thread."""
    id: int
    label: str
    fn: Callable[[Any, "Job"], Any]
    needs_world: bool = True
    worker: Optional["WorldWorker"] = None
    started: float = 0.0
    _cancel: threading.Event = field(default_factory=threading.Event)

    @property
    def cancelled(self) -> bool:
        return self._cancel.is_set()

    def sleep(self, seconds: float) -> None:
        """Waits ``seconds``; raises ``Cancelled`` at once if the job is cancelled."""
        if self._cancel.wait(max(0.0, seconds)):
            raise Cancelled(f"{self.label}: stopped")

    def check(self) -> None:
        if self._cancel.is_set():
            raise Cancelled(f"{self.label}: stopped")

    def progress(self, value: Any) -> None:
        """Sends ``value`` to the GUI thread (the ``on_progress`` callback of the job)."""
        self.check()
        if self.worker is not None:
            self.worker.progressed.emit(self.id, value)


class WorldWorker(QThread):
    """Runs jobs against ``<namespace>/*`` off the GUI thread; see the module docstring.

    Signals (received in the GUI thread): ``connection(bool connected, str text)``,
    ``busy(str label)`` (empty when idle), and the per-job results routed to callbacks."""

    connection = pyqtSignal(bool, str)
    busy = pyqtSignal(str)
    finished_job = pyqtSignal(int, object)
    failed_job = pyqtSignal(int, str)
    progressed = pyqtSignal(int, object)

    def __init__(self, namespace: str = WORLD_NAMESPACE, poll_period: float = 0.5,
                 name: str = "world", parent=None, node: Optional[NodeKind] = WORLD):
        super().__init__(parent)
        self.namespace = namespace.rstrip("/")
        self.node = node
        self.poll_period = poll_period
        self.name = name
        self._queue: "queue.Queue[Optional[Job]]" = queue.Queue()
        self._ids = itertools.count(1)
        self._callbacks: dict = {}
        self._client = None
        self._connected = False
        self._stopping = False
        self._current: Optional[Job] = None
        self.finished_job.connect(self._dispatch_done)
        self.failed_job.connect(self._dispatch_error)
        self.progressed.connect(self._dispatch_progress)

    # -- GUI-thread API ----------------------------------------------------------------------
    @property
    def connected(self) -> bool:
        return self._connected

    @property
    def current(self) -> Optional[Job]:
        """The job running now (None when idle); its ``started`` is a ``time.monotonic``."""
        return self._current

    def pending(self) -> int:
        return self._queue.qsize()

    def submit(self, label: str, fn: Callable, on_done: Optional[Callable] = None,
               on_error: Optional[Callable] = None, on_progress: Optional[Callable] = None,
               needs_world: bool = True) -> Job:
        job = Job(next(self._ids), label, fn, needs_world=needs_world, worker=self)
        self._callbacks[job.id] = (on_done, on_error, on_progress)
        self._queue.put(job)
        return job

    def cancel(self) -> None:
        """Cancels the running job and every queued one (their ``on_error`` gets a message)."""
        job = self._current
        if job is not None:
            job._cancel.set()
        while True:
            try:
                queued = self._queue.get_nowait()
            except queue.Empty:
                break
            if queued is not None:
                queued._cancel.set()
                self.failed_job.emit(queued.id, f"{queued.label}: cancelled")

    def stop(self, timeout_ms: int = 3000) -> None:
        self._stopping = True
        self.cancel()
        self._queue.put(None)
        self.wait(timeout_ms)

    # -- callbacks (GUI thread) --------------------------------------------------------------
    def _dispatch_done(self, job_id: int, result) -> None:
        on_done, _, _ = self._callbacks.pop(job_id, (None, None, None))
        if on_done is not None:
            on_done(result)

    def _dispatch_error(self, job_id: int, message: str) -> None:
        _, on_error, _ = self._callbacks.pop(job_id, (None, None, None))
        if on_error is not None:
            on_error(message)

    def _dispatch_progress(self, job_id: int, value) -> None:
        _, _, on_progress = self._callbacks.get(job_id, (None, None, None))
        if on_progress is not None:
            on_progress(value)

    # -- worker thread -----------------------------------------------------------------------
    def run(self) -> None:
        last_check = 0.0
        while not self._stopping:
            now = time.monotonic()
            if self.node is not None and now - last_check >= self.poll_period:
                last_check = now
                self._check_connection()
            try:
                job = self._queue.get(timeout=self.poll_period)
            except queue.Empty:
                continue
            if job is None:
                break
            self._run_job(job)
        self._drop_client()

    def _run_job(self, job: Job) -> None:
        if job.cancelled:
            return
        if job.needs_world and self.node is not None and not self._connected:
            self._check_connection()
            if not self._connected:
                self.failed_job.emit(job.id, f"{job.label}: the {self.node.title} is not "
                                     f"running ({self.namespace}/* absent); waiting for it")
                return
        self._current = job
        job.started = time.monotonic()
        self.busy.emit(job.label)
        try:
            result = job.fn(self._client, job)
        except Cancelled as error:
            self.failed_job.emit(job.id, str(error))
        except ServiceError as error:
            self.failed_job.emit(job.id, str(error))
            if "call failed" in error.reason:
                self._check_connection()
        except GuiError as error:
            self.failed_job.emit(job.id, str(error))
        except Exception as error:  # a bug must not kill the worker: report it in the window
            traceback.print_exc()
            self.failed_job.emit(job.id, f"{job.label}: {type(error).__name__}: {error}")
        else:
            self.finished_job.emit(job.id, result)
        finally:
            self._current = None
            self.busy.emit("")

    def _check_connection(self) -> None:
        title = self.node.title
        if not node_answers(f"{self.namespace}/{self.node.probe}"):
            if self._connected or self._client is not None:
                self._drop_client()
            self._set_connected(False, f"{title} absent: waiting for {self.namespace}")
            return
        if self._client is None:
            try:
                self._client = self.node.connect(self.namespace, 2.0)
            except Exception as error:  # a node coming up or going down
                self._client = None
                self._set_connected(False, f"{title} not answering: {error}")
                return
        self._set_connected(True, f"{title} connected ({self.namespace})")

    def _set_connected(self, connected: bool, text: str) -> None:
        changed = connected != self._connected
        self._connected = connected
        if changed or not hasattr(self, "_announced"):
            self._announced = True
            self.connection.emit(connected, text)

    def _drop_client(self) -> None:
        if self._client is not None:
            try:
                self._client.close()
            except Exception:
                pass
        self._client = None
