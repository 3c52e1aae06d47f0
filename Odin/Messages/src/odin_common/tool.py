"""How every Odin executable ends: quietly on a closed pipe and on Ctrl-C, with the usual codes.

``rosrun GUI problem_info FILE | head`` closes the pipe after ten lines; Python would then
print a BrokenPipeError traceback (twice: once more when it flushes stdout at exit). A shell
user expects what a C tool does: stop, print nothing, exit 128 + SIGPIPE (141). Ctrl-C likewise
ends with 128 + SIGINT (130) and no traceback. Every script in Odin/*/scripts and nodes/ runs
its main through ``run``.

Why it lives in the shared floor, beside the interface's facts: it is the one behaviour every
executable of every package shares (the world's and the Viewer's nodes, the replay tool, the
GUI's window and tools), and Messages is the one package all of them depend on. Like the
rest of ``odin_common`` it imports no ROS and no node package.
"""
from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
from typing import Callable, Iterator, Optional

EXIT_BROKEN_PIPE = 128 + signal.SIGPIPE
EXIT_INTERRUPTED = 128 + signal.SIGINT


def run(main: Callable[[], Optional[int]]) -> None:
    """Calls ``main()`` and exits with its status (None: 0), 141 when stdout was closed under
    it, 130 on Ctrl-C."""
    try:
        status = main()
        sys.stdout.flush()
    except BrokenPipeError:
        _silence_stdout()
        sys.exit(EXIT_BROKEN_PIPE)
    except KeyboardInterrupt:
        sys.exit(EXIT_INTERRUPTED)
    sys.exit(status or 0)


def _silence_stdout() -> None:
    """Points stdout at /dev/null, so the interpreter's flush at exit has nowhere to fail."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass



class StopRequest:
    """Set by Ctrl-C (SIGINT) while ``stop_on_ctrl_c`` is in force: ``bool(request)`` is
    whether the user asked to stop. Work that must not be cut in the middle (a service call
    whose answer is still in its socket, a C++ search) checks it between its steps, stops
    cleanly and raises KeyboardInterrupt itself."""

    def __init__(self) -> None:
        self.requested = False

    def __bool__(self) -> bool:
        return self.requested

    def __call__(self) -> bool:
        return self.requested


@contextlib.contextmanager
def stop_on_ctrl_c() -> Iterator[StopRequest]:
    """Within the block, the first Ctrl-C only sets the yielded ``StopRequest``; a second one
    raises KeyboardInterrupt at once (the user insists). Outside the main thread, where no
    signal handler can be set, the request is never set."""
    request = StopRequest()
    if threading.current_thread() is not threading.main_thread():
        yield request
        return

    def handler(signum, frame) -> None:
        if request.requested:
            raise KeyboardInterrupt
        request.requested = True

    previous = signal.signal(signal.SIGINT, handler)
    try:
        yield request
    finally:
        signal.signal(signal.SIGINT, previous)
