"""Asking a ROS master, or any ROS node's XML-RPC API, one question with a deadline: the one
XML-RPC transport that gives up (``TimeoutTransport``) and the one Master API call
(``call_master``) that Odin makes without rospy.

Who asks: a node waiting for its master before ``rospy.init_node`` (``odin_common.node``), a
tool that gives up on an absent master after its timeout, the GUI pinging a node it suspects
dead (``gui.ros.services.node_answers``) and the test harness's private roscore
(``odin_common.ros_master``). Plain ``xmlrpc.client``, no rospy and no rosgraph: the harness
needs only the ROS command-line tools, and a Portal must not load the harness to get this.
``xmlrpc.client``'s own transport waits for ever on a host that accepts a connection and
never answers (a port squatted by a hung process, a host that drops packets).
"""
from __future__ import annotations

import xmlrpc.client
from typing import Any, Optional


class TimeoutTransport(xmlrpc.client.Transport):
    """XML-RPC over HTTP that gives up after ``timeout`` s (None: the socket's default, as
    the standard transport)."""

    def __init__(self, timeout: Optional[float]):
        super().__init__()
        self.timeout = timeout

    def make_connection(self, host):
        connection = super().make_connection(host)
        if self.timeout is not None:
            connection.timeout = self.timeout
        return connection


class MasterRefusal(Exception):
    """The master answered a Master API call with an error status (a code other than 1:
    an unknown service, a parameter it will not set); ``str()`` is the master's message."""


def call_master(uri: str, caller_id: str, method: str, *args: Any,
                timeout: Optional[float] = None) -> Any:
    """The value of one ROS Master API call (``getPid``, ``lookupService``, ``setParam``...)
    made as ``caller_id`` to the master at ``uri``, given up after ``timeout`` s (None: the
    socket's default). Raises OSError or ``xmlrpc.client.Error`` when the master does not
    answer in time, ``MasterRefusal`` when it answers with an error status."""
    proxy = xmlrpc.client.ServerProxy(uri, transport=TimeoutTransport(timeout))
    code, message, value = getattr(proxy, method)(caller_id, *args)
    if code != 1:
        raise MasterRefusal(message)
    return value


__all__ = ["TimeoutTransport", "MasterRefusal", "call_master"]
