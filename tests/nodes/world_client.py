"""A small rospy client of the VirtualWorld node for tests, benches and experiments."""
from __future__ import annotations

import time

import rospy

from Messages import msg
from Services import srv
from odin_common.interface import WORLD_SERVICES



class WorldClient:
    """Calls ``/virtual_world/<name>`` with keyword fields; returns the response as it is."""

    def __init__(self, namespace: str = "/virtual_world", timeout: float = 30.0):
        self.namespace = namespace
        self._proxies = {}
        rospy.wait_for_service(f"{namespace}/start", timeout=timeout)

    def __call__(self, service: str, /, **fields):
        proxy = self._proxies.get(service)
        if proxy is None:
            service_class = getattr(srv, WORLD_SERVICES[service])
            proxy = rospy.ServiceProxy(f"{self.namespace}/{service}", service_class,
                                       persistent=True)
            self._proxies[service] = proxy
        request = proxy.request_class(**fields)
        return proxy(request)

    def ok(self, service: str, /, **fields):
        """Calls and insists on success."""
        response = self(service, **fields)
        assert response.success, f"{service} refused: {response.message}"
        return response

    def close(self) -> None:
        for proxy in self._proxies.values():
            proxy.close()

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
