"""SpaceDistribution written from pose arrays decodes as the ordinary message."""
import io

import numpy as np
import pytest
import rospy

from Messages.msg import SpaceDistribution
from virtual_world.portal.conversions import SpaceDistributionWriter


def _decode(message) -> SpaceDistribution:
    buffer = io.BytesIO()
    message.serialize(buffer)
    decoded = SpaceDistribution()
    decoded.deserialize(buffer.getvalue())
    return decoded


@pytest.mark.parametrize("names", [[], ["a"], ["ball", "ünïcode", ">not>a>composite", "x" * 300]])
def test_round_trip(names):
    writer = SpaceDistributionWriter()
    rng = np.random.default_rng(1)
    for _ in range(2):  # the second message reuses the layout of the first
        positions = rng.normal(size=(len(names), 3))
        quaternions = rng.normal(size=(len(names), 4))
        decoded = _decode(writer.message(names, positions, quaternions, rospy.Time(3, 5)))
        assert decoded.header.stamp == rospy.Time(3, 5) and decoded.header.frame_id == "world"
        assert [s.name for s in decoded.situations] == names
        for i, situation in enumerate(decoded.situations):
            assert list(situation.position) == positions[i].tolist()
            assert list(situation.orientation) == quaternions[i].tolist()


def test_layout_follows_scene_changes():
    writer = SpaceDistributionWriter()
    one = _decode(writer.message(["a"], np.zeros((1, 3)), np.ones((1, 4)), rospy.Time(0)))
    none = _decode(writer.message([], np.zeros((0, 3)), np.zeros((0, 4)), rospy.Time(0)))
    two = _decode(writer.message(["a", "b"], np.zeros((2, 3)), np.ones((2, 4)), rospy.Time(0)))
    assert (len(one.situations), len(none.situations), len(two.situations)) == (1, 0, 2)


def _genpy_bytes(message) -> bytes:
    buffer = io.BytesIO()
    message.serialize(buffer)
    return buffer.getvalue()


@pytest.mark.parametrize("name", ["ball", "ünïcode part", ""])
def test_view_requests_serialise_byte_for_byte_as_genpy(name):
    """PackedViewObjectRequest writes what genpy writes for the same fields: a mesh (a
    message's tuples), a primitive, and lists or numpy arrays given instead."""
    from types import SimpleNamespace
    from Services.srv import ViewObjectRequest
    from virtual_world.portal.conversions import view_requests
    rng = np.random.default_rng(2)
    mesh = SimpleNamespace(name=name, parameters=tuple(rng.normal(size=30).tolist()),
                           indices=tuple(int(i) for i in rng.integers(0, 10, 27)),
                           position=(1.0, -2.0, 0.5), orientation=(0.5, 0.5, -0.5, 0.5),
                           color=(0.1, 0.2, 0.3, 1.0), shape=9)
    box = SimpleNamespace(name=name + "box", parameters=[0.1, 0.2, 0.3], indices=[],
                          position=(0.0, 0.0, -0.0), orientation=(1.0, 0.0, 0.0, 0.0),
                          color=(0.0, 0.0, 0.0, 0.0), shape=0)
    arrays = SimpleNamespace(**{**vars(mesh), "parameters": np.array(mesh.parameters),
                                "indices": np.array(mesh.indices, dtype=np.uint32)})
    for geometry, request in zip((mesh, box, arrays), view_requests([mesh, box, arrays])):
        plain = ViewObjectRequest(geometry.name, list(geometry.parameters),
                                  list(geometry.indices), list(geometry.position),
                                  list(geometry.orientation), list(geometry.color),
                                  geometry.shape)
        assert _genpy_bytes(request) == _genpy_bytes(plain)
        # the fields alone (a Viewer's resync sends them again through genpy) say the same
        again = ViewObjectRequest(*(getattr(request, f) for f in ViewObjectRequest.__slots__))
        assert _genpy_bytes(again) == _genpy_bytes(plain)
