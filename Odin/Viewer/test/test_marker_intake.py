"""viewer.portal.markers: the world's markers become the View Object fields of their
geometries; geometries the world sent through View Object are left alone; deletions remove only
what markers added. The markers are read from the message's bytes as genpy would read them."""
import io

import numpy as np
import pytest
from geometry_msgs.msg import Point, Pose
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from odin_common.defaults import PLANE_DRAWN_SIZE, PLANE_DRAWN_THICKNESS
from odin_common.interface import Shape
from viewer.errors import ViewerError
from viewer.portal.markers import (MarkerIntake, RawMarkerArray, marker_view, read_markers,
                                   view_fields)
from viewer.core.scene import prepare_view


def _message(kind, name, scale=(1, 1, 1), points=(), action=Marker.ADD) -> Marker:
    m = Marker(type=kind, text=name, action=action)
    m.scale.x, m.scale.y, m.scale.z = scale
    m.color.r, m.color.a = 0.9, 1.0
    m.points = [Point(*p) for p in points]
    return m


def _marker(*args, **kwargs):
    return marker_view(_message(*args, **kwargs))


def _bytes(markers) -> bytes:
    buffer = io.BytesIO()
    MarkerArray(markers=markers).serialize(buffer)
    return buffer.getvalue()


def test_markers_read_from_bytes_are_what_genpy_reads():
    full = _message(Marker.TRIANGLE_LIST, "mesh é", (1, 1, 1),
                    points=[(0.5, -1, 2), (3, 4e-9, 5), (6, 7, 8.25)])
    full.header.frame_id, full.ns, full.id, full.mesh_resource = "odin/w", "geometries", 7, "x"
    full.pose = Pose()
    full.pose.position.x, full.pose.orientation.w = 1.5, 1.0
    full.colors = [ColorRGBA(0.1, 0.2, 0.3, 0.4)] * 3
    full.frame_locked = full.mesh_use_embedded_materials = True
    messages = [full, _message(Marker.CUBE, "box", (1, 2, 3)),
                _message(Marker.SPHERE, "", action=Marker.DELETEALL)]
    data = _bytes(messages)
    read = read_markers(data)
    expected = [marker_view(m) for m in MarkerArray().deserialize(data).markers]
    assert len(read) == len(expected) == 3
    for got, want in zip(read, expected):
        assert got[:5] == want[:5]
        np.testing.assert_array_equal(got.points, want.points)
    assert read[0].text == "mesh é" and read[0].points.shape == (3, 3)
    assert read_markers(_bytes([])) == []


def test_a_raw_marker_array_keeps_its_bytes_and_checks_as_a_marker_array():
    data = _bytes([_message(Marker.SPHERE, "s", (0.4, 0.4, 0.4))])
    raw = RawMarkerArray().deserialize(data)
    assert raw.raw == data and read_markers(raw.raw)[0].text == "s"
    assert (RawMarkerArray._type, RawMarkerArray._md5sum) == (MarkerArray._type,
                                                              MarkerArray._md5sum)


def test_bytes_that_are_no_whole_marker_array_are_refused():
    data = _bytes([_message(Marker.TRIANGLE_LIST, "m", points=[(0, 0, 0)] * 3)])
    for cut in (3, 20, len(data) // 2, len(data) - 1):
        with pytest.raises(ViewerError, match="cut short"):
            read_markers(data[:cut])
    with pytest.raises(ViewerError, match="bytes after"):
        read_markers(data + b"\0")
    with pytest.raises(ViewerError, match="cut short"):
        read_markers(b"\xff\xff\xff\x7f")                # two billion markers announced


def test_each_marker_type_gives_its_shape_and_the_viewer_accepts_it():
    triangle = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 0), (0, 1, 0), (0, 0, 1)]
    cases = [(_marker(Marker.SPHERE, "s", (0.4, 0.4, 0.4)), (0.2,), Shape.SPHERE),
             (_marker(Marker.CYLINDER, "c", (0.2, 0.2, 1.5)), (0.1, 1.5), Shape.CYLINDER),
             (_marker(Marker.CUBE, "b", (1, 2, 3)), (1, 2, 3), Shape.BOX),
             (_marker(Marker.CUBE, "p", (PLANE_DRAWN_SIZE, PLANE_DRAWN_SIZE,
                                         PLANE_DRAWN_THICKNESS)), (), Shape.PLANE)]
    for marker, parameters, shape in cases:
        name, got, indices, got_shape, color = view_fields(marker)
        assert (name, got, got_shape) == (marker.text, parameters, shape)
        prepare_view(name, got, indices, (0, 0, 0), (1, 0, 0, 0), color, got_shape)
    name, vertices, indices, shape, _ = view_fields(
        _marker(Marker.TRIANGLE_LIST, "m", points=triangle))
    assert shape == Shape.MESH and len(vertices) == 18 and list(indices) == list(range(6))
    prepare_view(name, vertices, indices, (0, 0, 0), (1, 0, 0, 0), (1, 0, 0, 1), shape)
    assert view_fields(_marker(Marker.SPHERE, "")) is None          # no geometry ID
    assert view_fields(_marker(Marker.ARROW, "a")) is None


def test_only_unknown_geometries_are_added_and_only_those_removed():
    intake = MarkerIntake()
    held = {"from_view_object"}
    views, removals = intake.changes([_marker(Marker.SPHERE, "from_view_object"),
                                      _marker(Marker.SPHERE, "from_marker")], held.__contains__)
    assert [v[0] for v in views] == ["from_marker"] and removals == []
    held.add("from_marker")
    views, _ = intake.changes([_marker(Marker.SPHERE, "from_marker")], held.__contains__)
    assert views == []                                   # drawn already
    views, removals = intake.changes([_marker(Marker.CUBE, "", action=Marker.DELETEALL),
                                      _marker(Marker.SPHERE, "from_marker")],
                                     held.__contains__)
    assert removals == ["from_marker"] and [v[0] for v in views] == ["from_marker"]
    _, removals = intake.changes([_marker(Marker.CUBE, "from_view_object",
                                          action=Marker.DELETE)], held.__contains__)
    assert removals == []
