"""The window shows the world as it is, whoever built it: a world built, changed and emptied by
raw service calls from another client (as rosservice or a planner would) shows in the window's
tree, object list, joint list and Motion menus, grouped by robot with the robot's own joint
names."""
from __future__ import annotations

import os
import pathlib

import pytest

pytestmark = pytest.mark.forked

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _tree(tab) -> dict:
    """{top-level label: {group label: [(name, world ID)]}} of the Simulation tab's tree
    (a leaf right under a top-level item sits under the group "")."""
    tree = {}
    for i in range(tab.tree.topLevelItemCount()):
        top = tab.tree.topLevelItem(i)
        groups = tree.setdefault(top.text(0), {})
        for j in range(top.childCount()):
            child = top.child(j)
            if child.childCount() == 0:
                groups.setdefault("", []).append((child.text(0), child.text(1)))
            for k in range(child.childCount()):
                leaf = child.child(k)
                groups.setdefault(child.text(0), []).append((leaf.text(0), leaf.text(1)))
    return tree


def _combo(combo) -> list:
    return [(combo.itemText(i), combo.itemData(i)) for i in range(combo.count())]


def test_a_world_built_by_another_client_shows_in_the_window(ros_master):
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from Messages.msg import Joint, Robot
    from gui.window.testing import open_window, screenshot, wait_for
    from world_client import WorldClient, box, sphere
    node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    window = open_window()
    try:
        wait_for(lambda: window.connected and window.world_reads > 0, 15, "the first Get World")
        assert window.simulation.status.text().startswith("The world is empty")

        other = WorldClient()
        other.ok("build_object", object=sphere("ball", position=(0, 0, 1)))
        other.ok("build_object", object=box("crate", sides=(0.3, 0.3, 0.3),
                                            position=(1, 0, 0.15)))
        hinge = other.ok("set_joint", action=0, type=Joint.HINGE, body1="ball", body2="",
                         anchor=[0, 0, 1.5], axis1=[0, 1, 0]).id
        motor = other.ok("set_motor", joint=hinge).id
        force = other.ok("set_external_force", object="crate", kind=0, vector=[0, 0, 1]).id
        other.ok("set_robot", robot=Robot(name="pendulum", links=["bob"], objects=["ball"],
                                          joint_names=["swing"], joints=[hinge]))

        expected = {"pendulum (robot)": {"Links": [("bob", "ball")],
                                         "Joints": [("swing", hinge)],
                                         "Motors": [("swing", motor)]},
                    "Scene objects": {"": [("crate", "crate")]},
                    "Forces": {"": [(force, force)]}}
        wait_for(lambda: _tree(window.simulation) == expected, 10, "the tree of that world",
                 lambda: _tree(window.simulation))
        assert "2 objects, 1 joints and 1 motors; robots: pendulum" in \
            window.simulation.status.text()
        objects = window.objects.list
        assert [objects.item(i).text() for i in range(objects.count())] == ["ball", "crate"]
        joints = window.joints.list
        assert [joints.item(i).text() for i in range(joints.count())] == \
            [f"pendulum: swing   [{hinge}]"]
        joints.setCurrentRow(0)
        assert window.joints.selected() == hinge
        assert _combo(window.motion.joint) == [("pendulum: swing", hinge)]
        assert _combo(window.motion.motor) == [("pendulum: swing (motor)", motor)]
        assert window.scene.motors == {motor: 1}
        assert list(window.motion.forces.item(i).text()
                    for i in range(window.motion.forces.count())) == [force]
        window.tabs.setCurrentWidget(window.simulation)
        window.simulation.tree.expandAll()
        screenshot(window, ROOT / "out" / "gui" / "world_built_elsewhere.png")

        # another client removes the crate (its force goes with it), then empties the world
        other.ok("remove_object", id="crate")
        wait_for(lambda: "crate" not in window.scene.objects and
                 "Scene objects" not in _tree(window.simulation), 10, "the crate gone",
                 lambda: _tree(window.simulation))
        assert "Forces" not in _tree(window.simulation) and not window.scene.forces
        other.ok("new_scene")
        wait_for(lambda: window.simulation.tree.topLevelItemCount() == 0 and
                 not window.scene.objects and joints.count() == 0 and
                 window.motion.motor.count() == 0, 10, "the empty world")
        assert window.simulation.status.text().startswith("The world is empty")
        assert window.errors == []
        other.close()
    finally:
        window.shutdown()
    assert node.poll() is None, "virtualWorld died:\n" + ros_master.log_text(node)[-3000:]
