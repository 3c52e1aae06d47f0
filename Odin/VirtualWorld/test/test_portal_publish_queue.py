"""rospy's publication queue without its per-message yield (portal.publish_queue), on a fake
transport: what is sent, in which order and what a full queue drops stay rospy's."""
import threading

import pytest
import rospy.impl.tcpros_pubsub as tcpros_pubsub

from virtual_world.portal import publish_queue


class _Transport:
    """Just what QueuedConnection uses of a rospy transport; ``write_data`` waits for
    ``release`` so that messages pile up in the queue meanwhile."""

    def __init__(self):
        self.done = False
        self.sent = []
        self.release = threading.Event()
        self.arrived = threading.Condition()

    def set_cleanup_callback(self, callback):
        self._cleanup = callback

    def write_data(self, data):
        self.release.wait(10)
        with self.arrived:
            self.sent.append(data)
            self.arrived.notify_all()

    def wait_for(self, count: int) -> list:
        with self.arrived:
            assert self.arrived.wait_for(lambda: len(self.sent) >= count, 10)
        return list(self.sent)

    def close(self):
        self.done = True
        self.release.set()
        self._cleanup(self)


@pytest.fixture
def no_yield(monkeypatch):
    """rospy's queue as the world node uses it; yields the sleeps it asked for."""
    sleeps = []
    monkeypatch.setattr(tcpros_pubsub.time, "sleep", sleeps.append)
    publish_queue.queue_without_yield()
    yield sleeps
    publish_queue.queue_with_yield()


@pytest.fixture
def queued(no_yield):
    """``queued(size) -> (transport, connection)``; every transport closed afterwards."""
    transports = []

    def make(queue_size: int):
        transports.append(_Transport())
        return transports[-1], tcpros_pubsub.QueuedConnection(transports[-1], queue_size)
    yield make
    for transport in transports:
        transport.close()


def test_queued_messages_go_out_in_order_without_giving_the_gil_away(queued, no_yield):
    transport, connection = queued(0)
    for k in range(5):
        assert connection.write_data(b"m%d" % k) is True
    transport.release.set()
    assert transport.wait_for(5) == [b"m0", b"m1", b"m2", b"m3", b"m4"]
    assert no_yield == []          # rospy's own write_data sleeps 0 s after each message


def test_a_full_queue_drops_its_oldest_message_as_rospys_does(queued):
    transport, connection = queued(2)
    connection.write_data(b"first")
    # the sending thread may hold "first" already (waiting in write_data) or not: either way
    # the queue behind it keeps the two newest
    for k in range(4):
        connection.write_data(b"m%d" % k)
    transport.release.set()
    sent = transport.wait_for(2)
    assert sent[-2:] == [b"m2", b"m3"] and b"m0" not in sent and b"m1" not in sent


def test_an_error_of_the_sending_thread_reaches_the_next_publisher(queued):
    _, connection = queued(0)
    connection._error = OSError("peer gone")      # as rospy's sending thread sets it
    with pytest.raises(OSError, match="peer gone"):
        connection.write_data(b"m")
    assert connection.write_data(b"m") is True     # raised once
