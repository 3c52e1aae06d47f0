"""The world's side of the Viewer's services: optional, and never in the world's way.

The thesis's world calls the Viewer's View Object, Viewer Remove Object and New Scene whenever
its scene changes. Here those calls leave the loop thread at once: they go into a queue that a
worker thread of this module sends. The Viewer may be absent, slow, or restarted at any time:

* while no Viewer serves ``<viewer>/view_object``, changes are only recorded;
* when a Viewer appears (or a new one replaces the old: its service address changes), the worker
  sends it the whole current scene: New Scene, then View Object for every geometry at its
  latest pose;
* a call that fails marks the Viewer out of date, and the next check re-sends the scene;
* a call that outlasts CALL_TIMEOUT is given up on but not taken back: its request is on its
  way and the Viewer may still apply it. Nothing more is sent to that Viewer until it has
  answered (or its connection broke); only then is the scene re-sent, so a late removal or
  New Scene can never land after the re-sent scene and take objects out of it. (It did: the
  Viewer's mirror lost objects under churn and got them back only when it restarted.)

Calls go over one persistent connection per service (a fresh one cost a lookup at the master,
a TCP connection and a thread in each node, for every geometry of every load); the
connections are dropped when a call fails or another Viewer takes the services' names.

The world therefore never blocks or fails because of the Viewer.
"""
from __future__ import annotations

import collections
import logging
import threading
import time
from typing import Callable, Optional, Sequence, Tuple

import rosgraph
import rospy

from Services.srv import (ViewObject, ViewObjectRequest, ViewerNewScene, ViewerRemoveObject)

_log = logging.getLogger("rosout")

#: s, how often the worker looks for a Viewer (or a new one) when it has nothing to send.
CHECK_PERIOD = 1.0
#: s, longest a single call to the Viewer may take before the Viewer counts as gone.
CALL_TIMEOUT = 5.0


class ViewerLink:
    """Mirrors the world's geometries into whatever Viewer is up.

    ``current_poses()`` (called on the worker thread) returns ``{geometry id: (position,
    orientation)}`` with the latest poses, so that a late Viewer starts from the present.
    It must be thread-safe (the Portal returns a copy made on the loop thread).
    """

    def __init__(self, namespace: str, current_poses: Callable[[], dict]):
        self._namespace = namespace.rstrip("/")
        self._current_poses = current_poses
        self._scene: "collections.OrderedDict[str, ViewObjectRequest]" = collections.OrderedDict()
        self._outbox: collections.deque = collections.deque()
        self._lock = threading.Condition()
        self._synced_uri: str | None = None
        self._proxies: dict = {}     # service name -> persistent rospy.ServiceProxy
        # a call given up on (CALL_TIMEOUT) that may still land: (Viewer URI, the thread
        # waiting for its answer, its proxy)
        self._late: Optional[Tuple[str, threading.Thread, object]] = None
        self._uri: Optional[str] = None   # the Viewer the calls under way go to
        self._stop = False
        self._thread = threading.Thread(target=self._work, name="viewer-link", daemon=True)
        self._thread.start()

    # -- called on the world's loop thread ------------------------------------------------
    def view(self, requests: Sequence[ViewObjectRequest]) -> None:
        with self._lock:
            for request in requests:
                self._scene[request.id] = request
                self._outbox.append(("view", request))
            self._lock.notify()

    def remove(self, ids: Sequence[str]) -> None:
        with self._lock:
            for geometry_id in ids:
                self._scene.pop(geometry_id, None)
                self._outbox.append(("remove", geometry_id))
            self._lock.notify()

    def new_scene(self) -> None:
        with self._lock:
            self._scene.clear()
            self._outbox.clear()
            self._outbox.append(("new_scene", None))
            self._lock.notify()

    def close(self) -> None:
        with self._lock:
            self._stop = True
            self._lock.notify()
        self._thread.join(timeout=CALL_TIMEOUT + 1.0)

    @property
    def connected(self) -> bool:
        return self._synced_uri is not None

    # -- the worker thread ----------------------------------------------------------------
    def _work(self) -> None:
        while True:
            with self._lock:
                if not self._outbox and not self._stop:
                    self._lock.wait(CHECK_PERIOD)
                if self._stop:
                    break
                batch = list(self._outbox)
                self._outbox.clear()
            try:
                self._deliver(batch)
            except Exception as error:  # a Viewer that fails is a Viewer that is gone
                if self._synced_uri is not None:
                    _log.warning("Viewer at %s unreachable (%s); will re-send the scene when "
                                 "it is back", self._namespace, error)
                self._synced_uri = None
                self._close_proxies()
        self._close_proxies()

    def _deliver(self, batch: list) -> None:
        uri = self._service_uri()
        if uri is None:
            self._synced_uri = None
            self._close_proxies()
            return
        if self._awaiting_late_call(uri):
            self._synced_uri = None
            return  # the batch is in the scene the resync sends once the late call is in
        self._uri = uri
        if uri != self._synced_uri:
            self._close_proxies()     # connected to the Viewer that was there before
            self._resync()
            self._synced_uri = uri
            return  # the resync already sent the present state, batch included
        for kind, payload in batch:
            if kind == "view":
                self._call("view_object", ViewObject, payload)
            elif kind == "remove":
                self._call("remove_object", ViewerRemoveObject, payload)
            else:
                self._call("new_scene", ViewerNewScene)

    def _resync(self) -> None:
        with self._lock:
            scene = list(self._scene.values())
        poses = self._current_poses()
        self._call("new_scene", ViewerNewScene)
        for request in scene:
            if request.id in poses:
                position, orientation = poses[request.id]
                request = ViewObjectRequest(request.id, request.parameters, request.indices,
                                            list(position), list(orientation), request.color,
                                            request.shape)
            self._call("view_object", ViewObject, request)
        _log.info("Viewer at %s received the current scene (%d geometries)",
                  self._namespace, len(scene))

    def _awaiting_late_call(self, uri: str) -> bool:
        """Whether a call given up on may still land at the Viewer at ``uri`` (one at
        another URI is another process's: it cannot touch this Viewer's scene)."""
        if self._late is None:
            return False
        late_uri, thread, proxy = self._late
        if late_uri == uri:
            thread.join(CHECK_PERIOD)       # rather than ask the master again at once
            if thread.is_alive():
                return True
        self._late = None
        proxy.close()       # answered, or a Viewer that is gone: its connection is done with
        return False

    def _call(self, name: str, service_class, *arguments) -> None:
        proxy = self._proxies.get(name)
        if proxy is None:
            proxy = self._proxies[name] = rospy.ServiceProxy(
                f"{self._namespace}/{name}", service_class, persistent=True)
        try:
            response = _with_timeout(lambda: proxy(*arguments), CALL_TIMEOUT)
        except _LateCall as late:
            # its connection stays open and is closed when it is in: closing it now would
            # end the wait here, not the request on its way to the Viewer
            del self._proxies[name]
            self._late = (self._uri, late.thread, proxy)
            raise
        if not response.success:
            # The Viewer refused: its scene is still consistent, only this geometry is missing.
            _log.warning("Viewer %s refused %s: %s", self._namespace, name, response.message)

    def _close_proxies(self) -> None:
        for proxy in self._proxies.values():
            proxy.close()
        self._proxies.clear()

    def _service_uri(self) -> str | None:
        try:
            master = rosgraph.Master(rospy.get_name())
            return master.lookupService(f"{self._namespace}/view_object")
        except Exception:  # no such service (rosgraph raises its own error types) or no master
            return None


class _LateCall(TimeoutError):
    """A call not answered in time; ``thread`` still waits for its answer."""

    def __init__(self, message: str, thread: threading.Thread) -> None:
        super().__init__(message)
        self.thread = thread


def _with_timeout(function: Callable, timeout: float):
    """Runs ``function`` on a helper thread and gives up waiting after ``timeout`` seconds
    (rospy's service calls have no timeout of their own): raises _LateCall, whose thread
    ends when the call does."""
    outcome: dict = {}

    def target():
        try:
            outcome["value"] = function()
        except Exception as error:
            outcome["error"] = error

    started = time.monotonic()
    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    thread.join(timeout)
    if thread.is_alive():
        raise _LateCall(f"no answer after {time.monotonic() - started:.1f} s", thread)
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]
