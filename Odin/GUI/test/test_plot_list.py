"""The joint plot's list names each channel as the window names its joint (issue 28: it showed
truncated world IDs such as "1:>Staub"): "<robot>: <its joint name>", " axis k" for a joint
of several axes, the world's ID for a joint of no robot and in every tooltip; checking and
plotting still go by the world's ID. Off-screen Qt, no ROS (each test in a process of its
own)."""
from __future__ import annotations

import os
from types import SimpleNamespace

import pytest

pytestmark = pytest.mark.forked

HAND = "1:>Staubli TX90/Base&TX90 SAHand Right/Shoulder"
WHEEL = "hinge2:SimpleCar/base_link&SimpleCar/wheel1"


def _message(t: float, names):
    stamp = SimpleNamespace(to_sec=lambda: t)
    return SimpleNamespace(header=SimpleNamespace(stamp=stamp), name=list(names),
                           position=[0.1 * k for k in range(len(names))],
                           velocity=[0.0] * len(names))


@pytest.fixture
def scene():
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from gui.window.testing import app
    from gui.window.scene import SceneModel
    app()
    model = SceneModel()
    model.joints = {HAND: None, WHEEL: None, "loose": None}
    return model


def _robots(scene):
    from gui.ros.client import WorldRobot
    scene.world_robots = (
        WorldRobot("TX90 SAHand Right", "/tx90", (), (), ("Shoulder",), (HAND,)),
        WorldRobot("SimpleCar", "/car", (), (), ("wheel1",), (WHEEL,)))


def test_the_list_names_robots_joints_and_plots_by_world_id(scene):
    from PyQt5.QtCore import Qt
    from gui.window.plot_panel import JointPlotPanel, channel_label
    _robots(scene)
    panel = JointPlotPanel(label=lambda channel: channel_label(channel, scene))
    panel.on_joint_states(_message(1.0, [HAND, f"{WHEEL}/1", f"{WHEEL}/2", "loose"]))
    items = [panel.list.item(i) for i in range(panel.list.count())]
    assert [i.text() for i in items] == ["TX90 SAHand Right: Shoulder",
                                         "SimpleCar: wheel1 axis 1",
                                         "SimpleCar: wheel1 axis 2", "loose"]
    assert [i.toolTip() for i in items] == [HAND, f"{WHEEL}/1", f"{WHEEL}/2", "loose"]
    panel.choose("SimpleCar: wheel1 axis 2")
    panel.choose(HAND)
    assert panel.chosen() == [HAND, f"{WHEEL}/2"]
    assert items[0].checkState() == Qt.Checked
    panel.on_joint_states(_message(1.01, [HAND, f"{WHEEL}/1", f"{WHEEL}/2", "loose"]))
    assert len(panel.samples[f"{WHEEL}/2"]) == 2


def test_names_come_when_the_robots_are_known(scene):
    from gui.window.plot_panel import JointPlotPanel, channel_label
    panel = JointPlotPanel(label=lambda channel: channel_label(channel, scene))
    panel.on_joint_states(_message(1.0, [HAND]))
    assert panel.list.item(0).text() == HAND          # no robot declared yet: the world's ID
    _robots(scene)
    panel.relabel()
    assert panel.list.item(0).text() == "TX90 SAHand Right: Shoulder"


def test_the_list_follows_the_joints_the_world_has_across_scenes(scene):
    """The world's clock runs on across New Scenes, so the list cannot wait for time to go
    back: a joint no message names any more left the world and leaves the list (a 2025
    problem loaded after a 2012 one listed both robots' joints); one checked comes back
    checked when its joint does (the same problem loaded again)."""
    from gui.window.plot_panel import JointPlotPanel
    panel = JointPlotPanel()
    panel.on_joint_states(_message(1.0, [HAND, "loose"]))
    panel.choose(HAND)
    panel.on_joint_states(_message(2.0, [WHEEL]))           # another problem, later in time
    assert [panel.list.item(i).text() for i in range(panel.list.count())] == [WHEEL]
    assert set(panel.samples) == {WHEEL} and panel.chosen() == []
    panel.on_joint_states(_message(3.0, []))                # New Scene: no joint at all
    assert panel.list.count() == 0
    panel.on_joint_states(_message(4.0, [HAND, "loose"]))   # the first one again
    assert panel.chosen() == [HAND] and set(panel.samples) == {HAND, "loose"}
