"""Whether the client of the service call being served is still there.

rospy gives a service handler the request alone, not the connection it came on: a long call
(a Propagate of half a minute) went on for ten minutes after its caller had timed out and
closed the connection. ``WatchedService`` is a ``rospy.Service`` that notes, on the thread
that handles a request (rospy's ``ServiceImpl._handle_request(transport, request)``, one
thread per connection), the connection's socket; ``watch()``, called on that thread, returns a
function any thread may call to ask whether the call should stop: the peer has closed the
connection (a non-blocking ``recv(1, MSG_PEEK)`` returning b"", an orderly close, or failing,
a reset), or the call has run past limits.MAX_CALL_SECONDS.
"""
from __future__ import annotations

import socket
import threading
import time
from typing import Callable, Optional

import rospy

from odin_common import limits

_served = threading.local()


class WatchedService(rospy.Service):
    """A rospy.Service whose handler may ``watch()`` its caller's connection."""

    def _handle_request(self, transport, request):
        _served.socket = getattr(transport, "socket", None)
        try:
            return super()._handle_request(transport, request)
        finally:
            _served.socket = None


def never() -> Optional[str]:
    """The watch of a call nobody can cancel."""
    return None


def watch(seconds: float = limits.MAX_CALL_SECONDS) -> Callable[[], Optional[str]]:
    """On a WatchedService handler's thread: a function that says why the call should stop,
    or None: the caller has closed its connection, or the call has run ``seconds`` of wall
    time (a safety net: a step's cost is not bounded by its bodies alone). Elsewhere (a call
    made in the process, a replay) only the time counts."""
    sock = getattr(_served, "socket", None)
    deadline = time.monotonic() + seconds

    def why() -> Optional[str]:
        if sock is not None and _closed(sock):
            return "the caller has gone"
        if time.monotonic() > deadline:
            return f"it ran past {seconds:g} s of wall time (MAX_CALL_SECONDS)"
        return None
    return why


def _closed(sock: socket.socket) -> bool:
    """Whether the peer closed ``sock``: a non-blocking peek reads its end (b"") or fails."""
    try:
        return sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
    except (BlockingIOError, InterruptedError):
        return False        # open, nothing sent: the caller waits for its answer
    except OSError:
        return True         # reset, or closed under us
