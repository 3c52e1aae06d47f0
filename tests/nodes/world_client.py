"""A small client of the VirtualWorld node for tests, benches and experiments: raw service
calls by name (gui.ros.services.ServiceCaller) and the world's poses."""
from __future__ import annotations

import time

import rospy

from Messages import msg
from gui.ros.services import ServiceCaller
from odin_common.interface import WORLD_SERVICES


class WorldClient:
    """Calls ``/virtual_world/<name>`` with keyword fields; returns the response as it is (a
    broken call raises gui.errors.ServiceError). Requires ``rospy.init_node``."""

    def __init__(self, namespace: str = "/virtual_world", timeout: float = 30.0):
        self._caller = ServiceCaller(namespace, WORLD_SERVICES)
        self.namespace = self._caller.namespace
        self._caller.wait("start", timeout, f"no world answering after {timeout:g} s")

    def __call__(self, service: str, /, **fields):
        return self._caller.ask(service, **fields)

    def ok(self, service: str, /, **fields):
        """Calls and insists on success."""
        response = self(service, **fields)
        assert response.success, f"{service} refused: {response.message}"
        return response

    def close(self) -> None:
        self._caller.close()

    def poses(self, timeout: float = 10.0) -> dict:
        """{geometry id: (position, orientation)} from the next world_update."""
        update = rospy.wait_for_message(f"{self.namespace}/world_update", msg.SpaceDistribution,
                                        timeout=timeout)
        return {s.name: (tuple(s.position), tuple(s.orientation)) for s in update.situations}


def sphere(name: str, radius: float = 0.1, position=(0, 0, 1), mass: float = 1.0, **extra):
    return msg.Object(name=name, parameters=[radius], mass=mass, position=list(position),
                      orientation=[1, 0, 0, 0], **extra)


def box(name: str, sides=(1, 1, 1), position=(0, 0, 0), mass: float = 1.0, **extra):
    return msg.Object(name=name, parameters=list(sides), mass=mass, position=list(position),
                      orientation=[1, 0, 0, 0], **extra)


def wait_until(predicate, timeout: float = 10.0, period: float = 0.05):
    """Polls ``predicate`` until it returns a true value (returned) or raises TimeoutError."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(period)
    raise TimeoutError("condition not met in time")


def running_world(ros_master, *parameters: str):
    """The body of a world fixture: a VirtualWorld node started with ``parameters``
    ("_max_objects:=6"), up to its servo service; yields the master, then checks that the node
    lived."""
    node = ros_master.rosrun("VirtualWorld", "virtualWorld", *parameters)
    ros_master.wait_for_service("/virtual_world/set_servo")
    yield ros_master
    assert node.poll() is None, "virtualWorld died:\n" + ros_master.log_text(node)[-3000:]
