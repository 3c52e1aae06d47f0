"""The window's Viewer panel navigates through the Viewer's Set Camera: "Frame the robot" aims
at the robot, a left drag orbits about the target at the same distance, the wheel zooms, and
the Viewer's own answer (Set Camera read back by another client) says so."""
from __future__ import annotations

import math
import os
import pathlib

import numpy as np
import pytest

pytestmark = pytest.mark.forked

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _viewer_camera():
    import rospy
    from Services.srv import SetCamera
    answer = rospy.ServiceProxy("/viewer/set_camera", SetCamera)()
    return np.array(answer.eye), np.array(answer.target)


def test_the_viewer_panel_frames_orbits_and_zooms(ros_master):
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from PyQt5.QtCore import QEvent, QPoint, QPointF, Qt
    from PyQt5.QtGui import QMouseEvent
    from PyQt5.QtWidgets import QApplication
    from PyQt5.QtTest import QTest
    from Messages.msg import Joint, Robot
    from gui.window.testing import open_window, click, pump, screenshot, wait_for
    from world_client import WorldClient, box, sphere
    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    ros_master.rosrun("Viewer", "viewer")
    ros_master.wait_for_service("/viewer/set_camera")
    other = WorldClient()
    other.ok("build_object", object=box("floor", sides=(20, 20, 0.1), position=(0, 0, -0.05),
                                        geometry_only=True))
    other.ok("build_object", object=sphere("ball", position=(0.5, 0.2, 1.0)))
    hinge = other.ok("set_joint", action=0, type=Joint.HINGE, body1="ball", body2="",
                     anchor=[0.5, 0.2, 1.5], axis1=[0, 1, 0]).id
    other.ok("set_robot", robot=Robot(name="pendulum", links=["bob"], objects=["ball"],
                                      joint_names=["swing"], joints=[hinge]))
    window = open_window()
    panel = window.viewer_panel
    try:
        wait_for(lambda: panel.camera is not None and window.scene.world_robots and
                 "ball" in window.scene.poses, 30, "the Viewer's camera and the robot")
        click(panel.frame_button)
        wait_for(lambda: np.allclose(_viewer_camera()[1], (0.5, 0.2, 1.0), atol=1e-6), 10,
                 "the Viewer aimed at the robot", _viewer_camera)
        eye, target = _viewer_camera()
        distance = np.linalg.norm(eye - target)
        assert distance < 3.0       # a ball of 0.1 m framed, not a 20 m floor

        label = panel.label
        centre = label.rect().center()
        QTest.mousePress(label, Qt.LeftButton, Qt.NoModifier, centre)
        for k in range(1, 11):      # QTest.mouseMove carries no buttons: a real drag's events
            QApplication.sendEvent(label, QMouseEvent(
                QEvent.MouseMove, QPointF(centre + QPoint(10 * k, 0)), Qt.NoButton,
                Qt.LeftButton, Qt.NoModifier))
            pump(0.01)
        QTest.mouseRelease(label, Qt.LeftButton, Qt.NoModifier, centre + QPoint(100, 0))

        def azimuth(point):
            return math.atan2(point[1] - target[1], point[0] - target[0])
        wait_for(lambda: abs(azimuth(_viewer_camera()[0]) - (azimuth(eye) - 1.0)) < 1e-6, 10,
                 "a 100-pixel drag to orbit 1 rad", _viewer_camera)
        assert np.linalg.norm(_viewer_camera()[0] - target) == pytest.approx(distance)

        panel._wheel(2.0)       # two notches towards the target (QTest has no wheel event)
        wait_for(lambda: abs(np.linalg.norm(_viewer_camera()[0] - target) -
                             distance * 0.85 ** 2) < 1e-6, 10, "zoomed in", _viewer_camera)
        frames = panel.frames
        wait_for(lambda: panel.frames > frames + 2, 10, "images of the new view")
        window.tabs.setCurrentWidget(window.simulation)
        screenshot(window, ROOT / "out" / "gui" / "viewer_navigated.png")
        assert window.errors == []
    finally:
        window.shutdown()
        other.close()
