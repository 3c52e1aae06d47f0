"""Geometries the Viewer learns from the world's RViz markers (``<~world>/markers``), so that a
rosbag of the world's topics played back drives the Viewer without a world to call View Object.

The world draws each geometry as one marker whose ``text`` is the geometry's ID
(virtual_world.portal.markers): SPHERE, CYLINDER and CUBE with the primitive's size as scale, a
plane as a CUBE of PLANE_DRAWN_SIZE x PLANE_DRAWN_SIZE x PLANE_DRAWN_THICKNESS, a mesh or a
capsule as a TRIANGLE_LIST of its triangles in the geometry's frame. A geometry the Viewer does
not hold is added from its marker (at the origin: the next world_update places it); one it
already holds (from View Object) is left alone; a DELETE or DELETEALL removes only what markers
added. Markers are taken MARKER_GRACE s after they arrive, in the order they arrived. Colours are
the marker's, which are the Viewer's own colours.

The markers are read from the message's bytes (:class:`RawMarkerArray`, :func:`read_markers`):
genpy makes a Python object per point, ~1 s of CPU for the TX90 grasp scene's triangles, on
every problem load, for geometries that View Object brings anyway. Here a marker's points stay
one numpy array over the received bytes, and only the markers of geometries the Viewer does
not hold are turned into shapes.
"""
from __future__ import annotations

import struct
from typing import List, NamedTuple, Optional, Tuple

import numpy as np
from visualization_msgs.msg import Marker, MarkerArray

from odin_common.defaults import PLANE_DRAWN_SIZE, PLANE_DRAWN_THICKNESS
from odin_common.interface import Shape
from viewer.errors import ViewerError

IDENTITY = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))

#: s the Viewer waits before it takes a MarkerArray: a live world publishes its markers when
#: it builds and sends View Object right after, so by then the geometries are held and no
#: mesh is built twice (once from its marker, again from View Object: a second of CPU for the
#: TX90 grasp scene the first time); a bag played back shows its geometries this much later.
MARKER_GRACE = 1.0


class MarkerView(NamedTuple):
    """What the Viewer reads of a visualization_msgs/Marker: ``text`` (the geometry's ID),
    ``type`` and ``action`` (Marker's constants), ``scale`` (x, y, z) m, ``color`` (r, g, b,
    a) and ``points`` (n, 3) float64 m, in the marker's frame."""
    text: str
    type: int
    action: int
    scale: tuple
    color: tuple
    points: np.ndarray


def marker_view(marker: Marker) -> MarkerView:
    """A Marker message's fields as :class:`MarkerView`."""
    points = np.array([(p.x, p.y, p.z) for p in marker.points], dtype=float).reshape(-1, 3)
    s, c = marker.scale, marker.color
    return MarkerView(marker.text, marker.type, marker.action, (s.x, s.y, s.z),
                      (c.r, c.g, c.b, c.a), points)


class RawMarkerArray(MarkerArray):
    """visualization_msgs/MarkerArray that keeps the bytes it came as (``raw``) instead of
    making its markers: the same type and MD5 sum, so a Subscriber of this class connects
    only to MarkerArray publishers. :func:`read_markers` reads ``raw``."""
    __slots__ = ("raw",)

    def deserialize(self, data):
        self.raw = bytes(data)
        return self


# A Marker's wire layout (visualization_msgs/Marker, little-endian), as genpy reads it:
# header (seq, stamp secs and nsecs: 3 uint32; frame_id: string), ns (string),
# id, type, action (3 int32), pose (7 float64), scale (3 float64), color (4 float32),
# lifetime (2 int32), frame_locked (uint8), points (uint32 n, n x 3 float64),
# colors (uint32 n, n x 4 float32), text (string), mesh_resource (string),
# mesh_use_embedded_materials (uint8). A string is a uint32 length and its UTF-8 bytes.
_TYPE_ACTION = struct.Struct("<3i")          # id, type, action
_POSE_BYTES = 7 * 8
_SCALE = struct.Struct("<3d")
_COLOR = struct.Struct("<4f")
_LIFETIME_AND_LOCK_BYTES = 2 * 4 + 1
_COUNT = struct.Struct("<I")


class _Reader:
    """Reads a serialized message from the front, checking every length against the end."""

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.at = 0

    def take(self, size: int) -> int:
        """Moves past ``size`` bytes; returns where they start."""
        start = self.at
        if size < 0 or start + size > len(self.data):
            raise ViewerError(f"MarkerArray message cut short: {size} bytes wanted at byte "
                              f"{start} of {len(self.data)}")
        self.at = start + size
        return start

    def unpack(self, layout: struct.Struct) -> tuple:
        return layout.unpack_from(self.data, self.take(layout.size))

    def count(self) -> int:
        return self.unpack(_COUNT)[0]

    def string(self) -> str:
        size = self.count()
        start = self.take(size)
        return self.data[start:start + size].decode("utf-8", "replace")


def read_markers(data: bytes) -> List[MarkerView]:
    """The markers of a serialized visualization_msgs/MarkerArray (RawMarkerArray.raw), each
    marker's points a view of ``data``. Raises :class:`ViewerError` for bytes that are not
    a whole MarkerArray."""
    reader = _Reader(data)
    markers = []
    for _ in range(reader.count()):
        reader.take(3 * 4)                              # header: seq, stamp
        reader.string()                                 # header.frame_id
        reader.string()                                 # ns
        _, kind, action = reader.unpack(_TYPE_ACTION)
        reader.take(_POSE_BYTES)
        scale = reader.unpack(_SCALE)
        color = reader.unpack(_COLOR)
        reader.take(_LIFETIME_AND_LOCK_BYTES)
        n = reader.count()
        points = np.frombuffer(data, dtype="<f8", count=3 * n,
                               offset=reader.take(24 * n)).reshape(n, 3)
        reader.take(16 * reader.count())                # per-point colours
        text = reader.string()
        reader.string()                                 # mesh_resource
        reader.take(1)                                  # mesh_use_embedded_materials
        markers.append(MarkerView(text, kind, action, scale, color, points))
    if reader.at != len(data):
        raise ViewerError(f"MarkerArray message has {len(data) - reader.at} bytes after its "
                          f"{len(markers)} markers")
    return markers


def _is_plane(scale) -> bool:
    return (np.isclose(scale[0], PLANE_DRAWN_SIZE) and np.isclose(scale[1], PLANE_DRAWN_SIZE)
            and np.isclose(scale[2], PLANE_DRAWN_THICKNESS))


def view_fields(marker: MarkerView) -> Optional[Tuple[str, tuple, tuple, int, tuple]]:
    """(ID, parameters, indices, shape, colour) of the View Object a marker stands for (a
    mesh's parameters and indices as arrays); None for a marker that is no geometry of the
    world's (no ID, another type)."""
    name = marker.text
    if not name:
        return None
    x, y, z = marker.scale
    color = tuple(marker.color)
    if marker.type == Marker.SPHERE:
        return name, (x / 2,), (), int(Shape.SPHERE), color
    if marker.type == Marker.CYLINDER:
        return name, (x / 2, z), (), int(Shape.CYLINDER), color
    if marker.type == Marker.CUBE:
        if _is_plane(marker.scale):
            return name, (), (), int(Shape.PLANE), color
        return name, (x, y, z), (), int(Shape.BOX), color
    if marker.type == Marker.TRIANGLE_LIST and len(marker.points) >= 3:
        points = marker.points
        return (name, points.reshape(-1), np.arange(len(points), dtype=np.uint32),
                int(Shape.MESH), color)
    return None


class MarkerIntake:
    """Which geometries came from markers (and still do: a View Object, Remove Object or New
    Scene of the same ID makes it the services' again, ``forget``); turns a MarkerArray into
    scene changes."""

    def __init__(self) -> None:
        self.added: set = set()

    def forget(self, object_ids) -> None:
        """The services now own these IDs: a later DELETE or DELETEALL leaves them alone (a
        marker's DELETE, taken MARKER_GRACE s late, removed the world's object built again
        meanwhile under the same ID)."""
        self.added.difference_update(object_ids)

    def changes(self, markers: List[MarkerView], held) -> Tuple[list, list]:
        """(views to add: (ID, parameters, indices, shape, colour), IDs to remove) for a
        MarkerArray's markers; ``held(id)`` says whether the Viewer holds a geometry."""
        views, removals = [], []
        for marker in markers:
            if marker.action == Marker.DELETEALL:
                removals.extend(sorted(self.added))
                self.added.clear()
                views = []
            elif marker.action == Marker.DELETE:
                if marker.text in self.added:
                    self.added.discard(marker.text)
                    removals.append(marker.text)
                    views = [v for v in views if v[0] != marker.text]
            elif marker.action == Marker.ADD:
                name = marker.text
                if name in self.added:
                    continue    # a geometry drawn already (a re-framed or recoloured marker)
                if held(name) and name not in removals:
                    continue    # the world sent it through View Object: no points to convert
                fields = view_fields(marker)
                if fields is None:
                    continue
                views.append(fields)
                self.added.add(fields[0])
        return views, removals
