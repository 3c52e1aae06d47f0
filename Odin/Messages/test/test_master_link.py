"""odin_common.master_link: one Master API call, its value, the master's refusal, and a
deadline that holds against a host that accepts a connection and never answers."""
import socket
import threading
import time
from xmlrpc.server import SimpleXMLRPCServer

import pytest

from odin_common.master_link import MasterRefusal, call_master


@pytest.fixture
def master():
    """A stand-in master on a loopback port: getPid answers, lookupService refuses."""
    server = SimpleXMLRPCServer(("127.0.0.1", 0), logRequests=False)
    server.register_function(lambda caller: [1, "", 4242], "getPid")
    server.register_function(lambda caller, name: [-1, f"unknown service [{name}]", ""],
                             "lookupService")
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def test_the_value_of_an_answered_call(master):
    assert call_master(master, "/odin_test", "getPid", timeout=5.0) == 4242
    assert call_master(master, "/odin_test", "getPid") == 4242     # the socket's default


def test_an_error_status_is_the_masters_refusal_with_its_message(master):
    with pytest.raises(MasterRefusal, match=r"unknown service \[/a/b\]"):
        call_master(master, "/odin_test", "lookupService", "/a/b", timeout=5.0)


def test_a_host_that_never_answers_is_given_up_after_the_timeout():
    """The kernel accepts the connection into the backlog; nobody ever reads the request."""
    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen(1)
        uri = f"http://127.0.0.1:{silent.getsockname()[1]}"
        outcome = []

        def ask() -> None:
            started = time.monotonic()
            try:
                call_master(uri, "/odin_test", "getPid", timeout=0.3)
            except OSError as error:
                outcome.append((type(error), time.monotonic() - started))
        asker = threading.Thread(target=ask, daemon=True)
        asker.start()
        asker.join(10.0)
    assert outcome and issubclass(outcome[0][0], TimeoutError), outcome
    assert 0.25 <= outcome[0][1] < 5.0
