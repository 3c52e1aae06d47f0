"""ODE for the whole process: the library checked and initialised once, and its messages routed
into Python's logging.

ODE's error and debug handlers end the process after they return, so the Core validates every
argument before calling ODE; odin_step.c's handlers print those messages to stderr first, and
buffer the non-fatal ones (dMessage), which ``drain_messages`` moves into logging.

Every function of the ode layer that makes ODE act (creates, configures, moves, frees, steps,
collides, computes a mass) is decorated with ``drains_ode_messages``: what ODE said reaches
logging before that function returns, so no caller above the ode layer drains by hand. Reading
a value back makes ODE say nothing, so readers are left undecorated (hot read-outs stay lean).
"""
from __future__ import annotations

import functools
import logging
import threading
from typing import Callable, List, TypeVar

from virtual_world.errors import OdeConfigurationError
from virtual_world.ode.bindings import ffi, lib

log = logging.getLogger("virtual_world.core")

_READY = False
_LOCK = threading.Lock()
_DRAIN_LOCK = threading.Lock()
_MESSAGE_BUFFER = ffi.new("char[]", 512)
_MESSAGE_NUMBER = ffi.new("int *")
_LEVELS = ("message", "debug", "error")

F = TypeVar("F", bound=Callable)


def init_ode() -> None:
    """Checks the library's precision, initialises ODE once and routes its messages."""
    global _READY
    with _LOCK:
        if _READY:
            return
        if not lib.dCheckConfiguration(b"ODE_double_precision"):
            raise OdeConfigurationError(
                "libode is not built with double precision (dCheckConfiguration"
                "('ODE_double_precision') is false); Odin needs Debian's double-precision libode")
        lib.odin_install_handlers()
        if not lib.dInitODE2(0):
            raise OdeConfigurationError("dInitODE2 failed")
        _READY = True


def drain_messages() -> List[str]:
    """Moves ODE's buffered messages into logging (warning level) and returns them."""
    messages = []
    with _DRAIN_LOCK:   # one buffer for the process; cffi lets go of the GIL in C calls
        while True:
            level = lib.odin_drain_message(_MESSAGE_BUFFER, 512, _MESSAGE_NUMBER)
            if level < 0:
                return messages
            text = ffi.string(_MESSAGE_BUFFER).decode("utf-8", "replace")
            messages.append(text)
            log.warning("ODE %s %d: %s", _LEVELS[level], _MESSAGE_NUMBER[0], text)


def drains_ode_messages(function: F) -> F:
    """Decorates an ode-layer function that makes ODE act: ODE's buffered messages go to
    logging (drain_messages) as it returns or raises."""
    @functools.wraps(function)
    def drained(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        finally:
            drain_messages()
    return drained
