"""portal.caller: how a long call learns that it should stop (its caller gone, or
MAX_CALL_SECONDS of wall time past)."""
import socket
import time

from virtual_world.portal import caller


def test_a_closed_peer_is_seen_and_an_open_quiet_one_is_not():
    ours, theirs = socket.socketpair()
    try:
        assert not caller._closed(ours)          # open, nothing sent
        theirs.sendall(b"next request")
        assert not caller._closed(ours)          # data waiting is no close (and stays unread)
        assert ours.recv(64) == b"next request"
        theirs.close()
        assert caller._closed(ours)
    finally:
        ours.close()


def test_a_call_that_runs_past_its_seconds_is_told_to_stop_naming_the_limit():
    why = caller.watch(seconds=0.05)             # no connection on this thread: time only
    assert why() is None
    time.sleep(0.1)
    assert "MAX_CALL_SECONDS" in why()
