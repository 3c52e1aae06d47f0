"""rosbag: the world's topics recorded with `rosbag record` and played back with no world
running drive the Viewer (it learns the geometries from the markers, the poses from
world_update) and RViz with Odin's configuration: both draw the red sphere of the recorded
scene, which neither shows before the bag plays."""
from __future__ import annotations

import os
import signal
import time

import numpy as np
import pytest

pytestmark = [pytest.mark.forked, pytest.mark.slow]

TOPICS = ["/virtual_world/world_update", "/virtual_world/markers", "/tf", "/tf_static",
          "/clock"]


def _red(image: np.ndarray) -> int:
    """Red pixels (the sphere) of an image."""
    r, g, b = (image[..., k].astype(int) for k in range(3))
    return int(((r > 120) & (r - g > 70) & (r - b > 70)).sum())


def _view(screenshot: np.ndarray) -> np.ndarray:
    """RViz's 3-D view in a screenshot of odin.rviz's layout (its panels have red icons)."""
    return screenshot[70:740, 370:900]


def _stop(process) -> None:
    """SIGINT to the process group (rosbag record closes its bag on it), then wait."""
    os.killpg(process.pid, signal.SIGINT)
    process.wait(timeout=30)


def _record(ros_master, bag) -> None:
    from gui.ros.client import WorldClient
    from odin_common.specs import ObjectSpec
    from world_client import wait_until
    world = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/build_object")
    recorder = ros_master.popen(["rosbag", "record", "-O", str(bag), *TOPICS],
                                log_name="rosbag_record")
    wait_until(lambda: all(any(node.startswith("/record") for node in ros_master.subscribers(t))
                           for t in TOPICS), timeout=60)    # rosbag subscribed to each topic
    client = WorldClient()
    client.build_object(ObjectSpec("ground", (4.0, 4.0, 0.1), position=(0, 0, -0.05),
                                   color=(0.55, 0.6, 0.55, 1), geometry_only=True))
    client.build_object(ObjectSpec("sphere", (0.4,), position=(0, 0, 2.0),
                                   color=(0.9, 0.1, 0.1, 1)))
    tetra = (0, 0, 0, 0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5)
    client.build_object(ObjectSpec("wedge", tetra, indices=(0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3),
                                   position=(1.0, 1.0, 0.0), color=(0.2, 0.3, 0.9, 1),
                                   geometry_only=True))
    client.start()
    time.sleep(2.0)
    client.close()
    _stop(recorder)
    _stop(world)
    assert bag.stat().st_size > 10_000


def test_a_bag_of_the_worlds_topics_drives_the_viewer_and_rviz(ros_master, tmp_path):
    import rospy
    from sensor_msgs.msg import Image
    from test_rviz import Xvfb

    bag = tmp_path / "world.bag"
    _record(ros_master, bag)

    ros_master.rosrun("Viewer", "viewer", "_eye:=[3.5, -3.5, 2.5]", "_target:=[0, 0, 0.5]")
    screen = Xvfb()
    try:
        env = dict(ros_master.env, DISPLAY=screen.display, QT_QPA_PLATFORM="xcb")
        rviz = ros_master.popen(["roslaunch", "VirtualWorld", "rviz.launch"], log_name="rviz",
                                env=env)
        if not rospy.core.is_initialized():
            rospy.init_node("bag_check", anonymous=True, disable_signals=True)

        def viewer_image() -> np.ndarray:
            message = rospy.wait_for_message("/viewer/image", Image, timeout=60)
            return np.frombuffer(message.data, np.uint8).reshape(message.height,
                                                                 message.width, 3)

        time.sleep(8.0)                 # RViz starts
        assert _red(viewer_image()) == 0
        assert _red(_view(screen.screenshot(tmp_path / "rviz_before.png"))) == 0
        player = ros_master.popen(["rosbag", "play", "--loop", str(bag)], log_name="rosbag_play")
        deadline = time.monotonic() + 60
        viewer_red = rviz_red = 0
        while time.monotonic() < deadline and (viewer_red < 500 or rviz_red < 500):
            time.sleep(1.0)
            assert rviz.poll() is None, ros_master.log_text(rviz)[-3000:]
            viewer_red = _red(viewer_image())
            rviz_red = _red(_view(screen.screenshot(tmp_path / "rviz_playing.png")))
        assert viewer_red >= 500, f"the Viewer does not draw the sphere ({viewer_red} px)"
        assert rviz_red >= 500, f"RViz does not draw the sphere ({rviz_red} px)"
        _stop(player)
    finally:
        screen.close()
