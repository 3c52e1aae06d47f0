"""rospy's publication queues without the thread switch they force on every message.

A rospy Publisher made with a ``queue_size`` hands each serialised message to one queue per
subscriber connection (``rospy.impl.tcpros_pubsub.QueuedConnection``); a thread per connection
sends it. After queueing, rospy's ``write_data`` calls ``time.sleep(0)`` "to yield the rest of
the thread quantum": it gives the GIL away so that the sending thread runs at once. The world
publishes five to ten topics a cycle from its loop thread, so every cycle gave the GIL away
that many times in the middle of its work and waited to get it back; on a loaded host each
wait costs up to the interpreter's switch interval (5 ms). The kinematic grasp, one Step Once
per cycle, spent about a tenth of its stepping time in those yields (issue 30's profile).

``queue_without_yield()`` makes ``write_data`` queue the message and wake the connection's
thread, as rospy does, without the ``sleep(0)``: the sending thread runs when the loop next
lets go of the GIL (the ODE step and the wait for calls both do, at most one cycle later), or
after the switch interval. What is sent, in which order and to whom is unchanged; only the
moment a message leaves the node moves, by less than a cycle.
"""
from __future__ import annotations

from rospy.impl.tcpros_pubsub import QueuedConnection

_ROSPY_WRITE_DATA = QueuedConnection.write_data


def _write_data(self, data) -> bool:
    """rospy's ``QueuedConnection.write_data`` (python3-rospy 1.15) without its
    ``time.sleep(0)``."""
    with self._lock:
        if self._error:         # an error of the sending thread is raised here, as rospy does
            error, self._error = self._error, None
            raise error
        if self._queue_size > 0 and len(self._queue) == self._queue_size:
            del self._queue[0]  # full: the oldest message goes
        self._queue.append(data)
        self._cond_data_available.notify()
    return True


def queue_without_yield() -> None:
    """From now on every queued publication of this process queues without yielding."""
    QueuedConnection.write_data = _write_data


def queue_with_yield() -> None:
    """rospy's own ``write_data`` again (tests)."""
    QueuedConnection.write_data = _ROSPY_WRITE_DATA
