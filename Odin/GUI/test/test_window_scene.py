"""The window's scene model learns a new joint's type from Get State when the ``joint_data``
topic has not named it yet (a CI run timed out adding a motor to a hinge built a second earlier:
the topic's subscription had not connected, the type was unknown, and Add motor refused), and
never forgets a type a later topic message leaves out. Off-screen Qt, no ROS."""
from __future__ import annotations

import os
from types import SimpleNamespace

import pytest

pytestmark = pytest.mark.forked

HINGE, BALL = "1:door&", "2:bob&door"


def _inventory(joints):
    return SimpleNamespace(objects=["door", "bob"], joints=list(joints), motors=[],
                           body_forces=[], joint_forces=[], robots=())


def _joint_data(types: dict):
    return SimpleNamespace(joints=[SimpleNamespace(id=j, type=t) for j, t in types.items()])


@pytest.fixture
def scene():
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from gui.window.testing import app
    from gui.window.scene import SceneModel
    app()
    return SceneModel()


def test_get_state_types_a_joint_the_topic_has_not_named(scene):
    from odin_common.interface import JointType
    scene.on_inventory(_inventory([HINGE]), {}, {HINGE: int(JointType.HINGE)})
    assert scene.joints == {HINGE: JointType.HINGE}


def test_a_type_once_known_stays_when_the_topic_lags(scene):
    from odin_common.interface import JointType
    scene.on_inventory(_inventory([HINGE]), {}, {HINGE: int(JointType.HINGE)})
    scene.on_joint_data(_joint_data({}))                     # published before the hinge
    assert scene.joints == {HINGE: JointType.HINGE}
    scene.on_inventory(_inventory([HINGE, BALL]), {}, {BALL: int(JointType.BALL)})
    assert scene.joints == {HINGE: JointType.HINGE, BALL: JointType.BALL}   # Ball is 0


def test_the_topic_names_the_type_of_a_joint_get_state_did_not(scene):
    from odin_common.interface import JointType
    scene.on_inventory(_inventory([HINGE]), {}, {})
    assert scene.joints == {HINGE: None}
    scene.on_joint_data(_joint_data({HINGE: int(JointType.SLIDER)}))
    assert scene.joints == {HINGE: JointType.SLIDER}
