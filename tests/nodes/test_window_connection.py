"""The window without a world, with a world that comes, goes and comes back, and with a slow
call: it says so, refuses cleanly, reconnects, and its event loop never stalls."""
from __future__ import annotations

import os
import pathlib
import signal
import time

import pytest

pytestmark = pytest.mark.forked

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_window_waits_for_the_world_then_reconnects(ros_master):
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from gui.window.testing import open_window, click, pump, screenshot, type_into, wait_for
    window = open_window()
    try:
        pump(0.5)
        assert not window.connected
        assert window.connection_text == "World: absent (waiting)"
        # every button still answers, with a message saying the world is absent
        click(window.simulation.new_scene_button)
        click(window.simulation.simulate_button)
        type_into(window.objects.name, "ball")
        click(window.objects.create_button)
        wait_for(lambda: len(window.errors) >= 3, 5, "three refusals")
        assert all("not running" in e for e in window.errors[-3:])
        screenshot(window, ROOT / "out" / "gui" / "absent.png")

        node = ros_master.rosrun("VirtualWorld", "virtualWorld")
        wait_for(lambda: window.connected, 30, "the window to find the world")
        assert window.connection_text == "World: connected"
        wait_for(lambda: window.settings.in_force_labels["rate"].text() == "25", 5,
                 "values in force read on connection")
        type_into(window.objects.name, "ball")
        click(window.objects.create_button)
        wait_for(lambda: "ball" in window.scene.objects, 5, "the ball built")

        # the world goes away: the window says so; it comes back: the window reconnects
        os.killpg(node.pid, signal.SIGINT)
        node.wait(10)
        wait_for(lambda: not window.connected, 10, "the window to see the world gone")
        assert "absent" in window.last_error
        ros_master.rosrun("VirtualWorld", "virtualWorld")
        wait_for(lambda: window.connected, 30, "the window to reconnect")
        type_into(window.objects.name, "ball")
        click(window.objects.create_button)
        wait_for(lambda: "Built object ball" in window.last_info and
                 "ball" in window.scene.objects, 10,
                 "the ball built in the new world", lambda: window.errors)
    finally:
        window.shutdown()


def test_a_slow_call_is_reported_and_never_blocks_the_event_loop(ros_master):
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from PyQt5.QtCore import QTimer
    from gui.window.testing import open_window, wait_for
    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    window = open_window()
    try:
        wait_for(lambda: window.connected, 15, "connection")
        done = []
        window.call("Slow call", lambda client, job: (time.sleep(2.0), client.call(
            "step_once", cycles=1))[1], lambda r: done.append(r))
        # the event loop keeps running: a 10 ms timer never waits long
        gaps, last = [], [time.monotonic()]

        def tick():
            now = time.monotonic()
            gaps.append(now - last[0])
            last[0] = now

        timer = QTimer()
        timer.timeout.connect(tick)
        timer.start(10)
        wait_for(lambda: window.busy_text.startswith("World slow"), 3, "the slow notice")
        assert "Slow call" in window.busy_text
        wait_for(lambda: done, 5, "the slow call's answer")
        timer.stop()
        assert done[0].sim_time > 0
        assert max(gaps) < 0.1, f"event loop stalled {max(gaps) * 1000:.0f} ms"
        wait_for(lambda: not window.busy_text.startswith("World slow"), 2, "notice cleared")
    finally:
        window.shutdown()


def test_the_viewer_image_shows_in_the_window(ros_master):
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from gui.window.testing import open_window, click, screenshot, type_into, wait_for
    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.rosrun("Viewer", "viewer")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    window = open_window()
    try:
        wait_for(lambda: window.connected, 15, "connection")
        window.tabs.setCurrentWidget(window.objects)
        window.objects.shape.setCurrentIndex(2)
        window.objects.box_sides.set_values((1.0, 1.0, 1.0))
        window.objects.position.set_values((0, 0, 0))
        type_into(window.objects.name, "cube")
        click(window.objects.create_button)
        wait_for(lambda: "cube" in window.scene.objects, 10, "the cube")
        # The window knows the cube when the world answers; the Viewer hears of it from the
        # world's Viewer link a moment later, and frames rendered before that are still on
        # their way: wait for a frame that shows it, not for a number of frames.
        wait_for(lambda: _colours(window.viewer_panel.image) > 2, 30, "the cube in the image")
        image = window.viewer_panel.image
        assert (image.width(), image.height()) == (640, 480)
        assert window.viewer_panel.label.pixmap() is not None
        screenshot(window, ROOT / "out" / "gui" / "viewer.png")
    finally:
        window.shutdown()


def test_a_restarted_world_is_offered_the_last_problem_again(ros_master, kautham_dir):
    """The world dies under a built problem and a new one starts empty: the window says so,
    offers the last problem (it never rebuilds unasked), and one click builds it again."""
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from gui.window.testing import open_window, click, screenshot, wait_for
    node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    window = open_window()
    problem = kautham_dir / "legacy_2012" / "examples" / "TRO" / "2DRR_obstacle.xml"
    try:
        wait_for(lambda: window.connected, 30, "the window to find the world")
        built = []
        window.simulation.problem_built.connect(built.append)
        window.simulation.open_problem(str(problem))
        wait_for(lambda: len(built) == 1, 60, "the problem built", lambda: window.errors)
        assert window.simulation.rebuild_button.isHidden()

        os.killpg(node.pid, signal.SIGKILL)       # a crash, not a shutdown
        node.wait(10)
        wait_for(lambda: not window.connected, 15, "the window to see the world gone")
        assert window.simulation.rebuild_button.isHidden()
        ros_master.rosrun("VirtualWorld", "virtualWorld")
        wait_for(lambda: window.connected, 30, "the window to reconnect")
        wait_for(lambda: window.simulation.rebuild_button.isVisible(), 5, "the offer")
        assert "2DRR_obstacle.xml" in window.simulation.rebuild_button.text()
        assert "restarted" in window.last_info
        assert len(built) == 1                    # offered, not rebuilt unasked
        screenshot(window, ROOT / "out" / "gui" / "rebuild_offer.png")

        click(window.simulation.rebuild_button)
        wait_for(lambda: len(built) == 2, 60, "the problem built again", lambda: window.errors)
        assert window.simulation.rebuild_button.isHidden()
        from gui.ros.client import WorldClient
        assert len(WorldClient().world().objects) > 0
    finally:
        window.shutdown()


def _colours(image) -> int:
    """How many colours a 16 x 12 grid of the image's pixels has (0 without an image): the
    Viewer's empty scene is its background and the grid's lines, two."""
    if image is None:
        return 0
    return len({image.pixel(x, y) for x in range(0, image.width(), 40)
                for y in range(0, image.height(), 40)})
