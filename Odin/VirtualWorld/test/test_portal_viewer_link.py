"""The world's link to the Viewer (portal.viewer_link) against a fake Viewer whose calls may
take longer than the link waits: the Viewer's scene converges to the world's after churn,
without a restart. A call the link gave up on still lands (its bytes were sent: closing the
connection does not take them back), as it does on a real, slow Viewer."""
from __future__ import annotations

import threading
import time
from types import SimpleNamespace

import pytest

from Services.srv import ViewObjectRequest
from virtual_world.portal import viewer_link
from virtual_world.portal.viewer_link import ViewerLink

URI = "rosrpc://fake-viewer:1"


class FakeViewer:
    """A Viewer's scene behind its three services; ``slow`` is the delay (s) of the calls
    to come, in order, before each takes effect."""

    def __init__(self) -> None:
        self.scene: set = set()
        self.slow: list = []
        self.lock = threading.Lock()
        self.calls = 0

    def call(self, name: str, arguments: tuple):
        with self.lock:
            delay = self.slow.pop(0) if self.slow else 0.0
            self.calls += 1
        time.sleep(delay)
        with self.lock:
            if name == "view_object":
                self.scene.add(arguments[0].id)
            elif name == "remove_object":
                self.scene.discard(arguments[0])
            else:
                self.scene.clear()
        return SimpleNamespace(success=True, message="")


@pytest.fixture
def fake_viewer(monkeypatch):
    viewer = FakeViewer()

    class Proxy:
        def __init__(self, service: str, service_class, persistent: bool = False) -> None:
            self.name = service.rsplit("/", 1)[1]

        def __call__(self, *arguments):
            return viewer.call(self.name, arguments)

        def close(self) -> None:
            pass            # what was sent is on its way: the Viewer still applies it

    monkeypatch.setattr(viewer_link.rospy, "ServiceProxy", Proxy)
    monkeypatch.setattr(ViewerLink, "_service_uri", lambda self: URI)
    monkeypatch.setattr(viewer_link, "CALL_TIMEOUT", 0.2)
    monkeypatch.setattr(viewer_link, "CHECK_PERIOD", 0.05)
    return viewer


def request(name: str) -> ViewObjectRequest:
    return ViewObjectRequest(name, [0.1], [], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0],
                             [0.0, 0.0, 0.0, 0.0], 0)


#: s a converged scene must stay so: longer than any slow call of these tests
STEADY = 1.0


def converged(link: ViewerLink, viewer: FakeViewer, timeout: float = 10.0) -> set:
    """The Viewer's scene once it has equalled the world's for STEADY s (or when ``timeout``
    s have passed)."""
    world = set(link._scene)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if viewer.scene == world and not link._outbox:
            time.sleep(STEADY)
            if viewer.scene == world:
                return set(viewer.scene)
        time.sleep(0.02)
    return set(viewer.scene)


def test_a_removal_that_lands_after_the_link_gave_up_on_it_does_not_lose_the_rebuilt_object(
        fake_viewer):
    link = ViewerLink("/viewer", dict)
    try:
        link.view([request("kept"), request("rebuilt")])
        assert converged(link, fake_viewer) == {"kept", "rebuilt"}
        fake_viewer.slow = [0.6]              # the removal takes 3 x the link's patience
        link.remove(["rebuilt"])
        time.sleep(0.05)
        link.view([request("rebuilt")])       # built again while the removal is on its way
        assert converged(link, fake_viewer) == {"kept", "rebuilt"}
    finally:
        link.close()


def test_a_new_scene_that_lands_late_does_not_empty_the_resent_scene(fake_viewer):
    link = ViewerLink("/viewer", dict)
    try:
        link.view([request("old")])
        assert converged(link, fake_viewer) == {"old"}
        fake_viewer.slow = [0.5]
        link.new_scene()
        time.sleep(0.05)
        link.view([request(f"new{i}") for i in range(5)])
        assert converged(link, fake_viewer) == {f"new{i}" for i in range(5)}
    finally:
        link.close()
