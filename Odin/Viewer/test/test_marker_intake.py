"""viewer.portal.markers: the world's markers become the View Object fields of their
geometries; geometries the world sent through View Object are left alone; deletions remove only
what markers added."""
from geometry_msgs.msg import Point
from visualization_msgs.msg import Marker

from odin_common.interface import PLANE_DRAWN_SIZE, PLANE_DRAWN_THICKNESS, Shape
from viewer.portal.markers import MarkerIntake, view_fields
from viewer.core.scene import prepare_view


def _marker(kind, name, scale=(1, 1, 1), points=(), action=Marker.ADD) -> Marker:
    m = Marker(type=kind, text=name, action=action)
    m.scale.x, m.scale.y, m.scale.z = scale
    m.color.r, m.color.a = 0.9, 1.0
    m.points = [Point(*p) for p in points]
    return m


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
    assert shape == Shape.MESH and len(vertices) == 18 and indices == tuple(range(6))
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
