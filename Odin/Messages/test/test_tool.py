"""odin_common.tool: how executables end, and Ctrl-C turned into a stop request for work that
must not be cut in the middle."""
import os
import signal
import threading

import pytest

from odin_common.tool import stop_on_ctrl_c


def test_the_first_ctrl_c_sets_the_request_the_second_raises():
    before = signal.getsignal(signal.SIGINT)
    with stop_on_ctrl_c() as stop:
        assert not stop and not stop()
        os.kill(os.getpid(), signal.SIGINT)       # delivered before kill returns (to itself)
        assert stop and stop()
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGINT)
    assert signal.getsignal(signal.SIGINT) is before


def test_outside_the_main_thread_the_request_is_never_set_and_nothing_changes():
    seen = []

    def work():
        with stop_on_ctrl_c() as stop:
            seen.append(bool(stop))
    before = signal.getsignal(signal.SIGINT)
    thread = threading.Thread(target=work)
    thread.start()
    thread.join()
    assert seen == [False] and signal.getsignal(signal.SIGINT) is before
