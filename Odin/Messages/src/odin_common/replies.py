"""How every Portal answers a service: the Core's refusal or a bug becomes ``success: false``.

A Portal's service handler returns the response's fields; ``guarded`` turns its outcome into
the service's response, so that a refusal (an ``OdinError``: the Core's rules) reaches the
caller with the Core's message and a bug is logged with its traceback and answered too: nothing
a caller sends ends a node. ROS-free: it takes the generated service class and imports no rospy
(its log goes to the "rosout" logger, where rospy's own logging goes).
"""
from __future__ import annotations

import logging
import traceback
from typing import Any, Callable, Dict

from odin_common.errors import OdinError

_log = logging.getLogger("rosout")

Fields = Dict[str, Any]


def guarded(service_class: Any, handler: Callable[[Any], Fields],
            in_force: Callable[[], Fields] = dict) -> Callable[[Any], Any]:
    """A server's callback: ``handler(request) -> fields`` answered as
    ``service_class``'s response with ``success: true`` and those fields; an OdinError as
    ``success: false`` with its message; anything else as ``success: false`` with
    "internal error: <type>: <message>" (logged with its traceback). A refusal also answers
    ``in_force()``: the values still in force (Set World's parameters, Set Step's values, the
    Viewer's camera), read after the refusal."""
    response_class = service_class._response_class

    def answer(request):
        try:
            return response_class(success=True, **handler(request))
        except OdinError as error:
            message = str(error)
        except Exception as error:  # a bug must not take the node down; say what happened
            _log.error("%s failed:\n%s", service_class._type, traceback.format_exc())
            message = f"internal error: {type(error).__name__}: {error}"
        return response_class(success=False, message=message, **in_force())
    return answer
