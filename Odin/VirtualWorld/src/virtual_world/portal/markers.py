"""The world's geometries as RViz markers (visualization_msgs/MarkerArray), no rospy here.

One marker per geometry (a composite part by part), in namespace ``MARKER_NAMESPACE``, drawn
as the Viewer draws it: a sphere, cylinder or box as RViz's own SPHERE, CYLINDER and CUBE; a
mesh or a capsule as a TRIANGLE_LIST (meshes simplified for display as the Viewer does,
odin_common.meshes.display_mesh, and wound to face outwards: RViz lights one side only);
a plane as a thin square floor of PLANE_DRAWN_SIZE. Colours
are the Viewer's: the object's colour, DEFAULT_COLOR for an all-zero one, COLLIDING_COLOR while
the world reports the geometry colliding (the contact-less policy's Collided, as the Viewer).

Each marker sits in its object's tf frame (``frame_locked``: RViz moves it with the frame every
frame), so markers are sent only when something changes: a geometry built, removed, re-framed
(its object became a robot's link) or recoloured. ``text`` carries the geometry's name (RViz
draws no text for these types; the Viewer reads it to add geometries it learns from markers,
e.g. from a bag). Messages are serialised once per marker with numpy (a hand's meshes hold
hundreds of thousands of points): ``full()`` is a DELETEALL then every marker, what a new
subscriber gets; ``take_changes()`` only what changed since the last call.
"""
from __future__ import annotations

import collections
import struct
from dataclasses import dataclass
from typing import Dict, Iterable, Optional, Sequence, Tuple

import numpy as np
from visualization_msgs.msg import Marker, MarkerArray

from odin_common.defaults import (COLLIDING_COLOR, DEFAULT_COLOR, PLANE_DRAWN_SIZE,
                                  PLANE_DRAWN_THICKNESS)
from odin_common.interface import Shape, shape_of
from odin_common.meshes import capsule_mesh, display_mesh, facing_outwards
from odin_common.rotations import compose_poses, wxyz_to_xyzw
from virtual_world.core.arrays import flat_float64, uint32_array

MARKER_NAMESPACE = "odin"
"""The namespace of the world's geometry markers."""

Pose = Tuple[Sequence[float], Sequence[float]]    # (position m, quaternion (w, x, y, z))


def _string(text: str) -> bytes:
    encoded = text.encode("utf-8")
    return struct.pack("<I", len(encoded)) + encoded


def display_color(color: Sequence[float]) -> Tuple[float, float, float, float]:
    """(r, g, b, a) as drawn: DEFAULT_COLOR for an all-zero colour, alpha 1 when 3 are given."""
    values = tuple(float(v) for v in color)
    if len(values) == 3:
        values += (1.0,)
    return DEFAULT_COLOR if not any(values) else values


_IDENTITY = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))   # (position, quaternion (w, x, y, z))


@dataclass(frozen=True)
class _Shape:
    """What a geometry looks like as a marker, in the geometry's own frame."""
    type: int
    scale: Tuple[float, float, float]
    offset: Pose                  # the marker's pose in the geometry's frame
    points: bytes                 # TRIANGLE_LIST corners, (3 t, 3) float64 little-endian
    point_count: int


def marker_shape(parameters: Sequence[float], indices: Sequence[int], shape: int) -> _Shape:
    """The marker of a geometry built with these Object/Part fields (already checked by the
    Core)."""
    params = flat_float64(parameters)
    kind = shape_of(params.size, shape)
    if kind == Shape.SPHERE:
        d = 2 * params[0]
        return _Shape(Marker.SPHERE, (d, d, d), _IDENTITY, b"", 0)
    if kind == Shape.CYLINDER:
        d = 2 * params[0]
        return _Shape(Marker.CYLINDER, (d, d, params[1]), _IDENTITY, b"", 0)
    if kind == Shape.BOX:
        return _Shape(Marker.CUBE, tuple(params[:3]), _IDENTITY, b"", 0)
    if kind == Shape.PLANE:
        return _Shape(Marker.CUBE, (PLANE_DRAWN_SIZE, PLANE_DRAWN_SIZE, PLANE_DRAWN_THICKNESS),
                      ((0.0, 0.0, -PLANE_DRAWN_THICKNESS / 2), (1.0, 0.0, 0.0, 0.0)), b"", 0)
    if kind == Shape.CAPSULE:
        return _triangle_list(*capsule_mesh(params[0], params[1]))
    index_values = uint32_array(indices)
    if index_values is None:
        index_values = np.asarray(indices)
    key = (params.tobytes(), index_values.astype(np.int64).tobytes())
    marker = _MESH_MARKERS.pop(key, None)
    if marker is None:
        vertices, triangles = display_mesh(params.reshape(-1, 3), indices)
        # RViz lights the front side only
        marker = _triangle_list(vertices, facing_outwards(vertices, triangles))
    _MESH_MARKERS[key] = marker   # most recently used last
    _trim_mesh_markers()
    return marker


def _triangle_list(vertices: np.ndarray, triangles: np.ndarray) -> _Shape:
    corners = np.ascontiguousarray(vertices[triangles], dtype="<f8")
    return _Shape(Marker.TRIANGLE_LIST, (1.0, 1.0, 1.0), _IDENTITY, corners.tobytes(),
                  len(corners))


_MESH_MARKERS: "collections.OrderedDict[Tuple[bytes, bytes], _Shape]" = \
    collections.OrderedDict()
"""Markers of the meshes built lately, by their exact parameters and indices: simplifying a
mesh for display is most of a build's marker cost (~0.3 s for the TX90 + hand), and the same
robot comes back after every New Scene. Markers are never changed once made."""
#: bytes of points the cache of mesh markers keeps at most (the TX90 + hand: ~15 MB)
MESH_MARKER_BYTES = 64 * 2 ** 20


def _trim_mesh_markers() -> None:
    held = sum(len(m.points) for m in _MESH_MARKERS.values())
    while len(_MESH_MARKERS) > 1 and held > MESH_MARKER_BYTES:
        held -= len(_MESH_MARKERS.popitem(last=False)[1].points)


class _GeometryMarker:
    """One geometry's marker, serialised in three pieces: up to the colour (frame, pose), the
    colour, and the rest (points, name)."""

    def __init__(self, marker_id: int, name: str, shape: _Shape, color: tuple):
        self.id = marker_id
        self.name = name
        self.shape = shape
        self.color = color
        self.colliding = False
        self.tail = (struct.pack("<iiB", 0, 0, 1) + struct.pack("<I", shape.point_count)
                     + shape.points + struct.pack("<I", 0) + _string(name) + _string("")
                     + struct.pack("<B", 0))
        self.head = b""

    def place(self, frame: str, pose: Pose) -> None:
        """The marker in ``frame`` at the geometry's ``pose`` in that frame."""
        position, quaternion = compose_poses(np.asarray(pose[0], float),
                                             np.asarray(pose[1], float),
                                             np.asarray(self.shape.offset[0], float),
                                             np.asarray(self.shape.offset[1], float))
        self.head = (struct.pack("<3I", 0, 0, 0) + _string(frame) + _string(MARKER_NAMESPACE)
                     + struct.pack("<iii", self.id, self.shape.type, Marker.ADD)
                     + struct.pack("<7d", *position, *wxyz_to_xyzw(quaternion))
                     + struct.pack("<3d", *self.shape.scale))

    def serialised(self) -> bytes:
        color = COLLIDING_COLOR if self.colliding else self.color
        return self.head + struct.pack("<4f", *color) + self.tail


def _action(marker_id: int, action: int, name: str = "") -> bytes:
    """A DELETE (of one marker) or DELETEALL marker."""
    return (struct.pack("<3I", 0, 0, 0) + _string("") + _string(MARKER_NAMESPACE)
            + struct.pack("<iii", marker_id, Marker.CUBE, action) + bytes(7 * 8 + 3 * 8)
            + bytes(4 * 4) + struct.pack("<iiB", 0, 0, 0) + struct.pack("<I", 0)
            + struct.pack("<I", 0) + _string(name) + _string("") + struct.pack("<B", 0))


class GeometryMarkers:
    """The markers of every geometry the world holds (see the module)."""

    def __init__(self) -> None:
        self._markers: "collections.OrderedDict[str, _GeometryMarker]" = \
            collections.OrderedDict()
        self._next_id = 0
        self._changed: Dict[str, Optional[bytes]] = {}   # name -> marker, or a DELETE
        self._cleared = False
        self._colliding: set = set()     # names of the markers drawn grey now

    def __len__(self) -> int:
        return len(self._markers)

    def add(self, name: str, parameters: Sequence[float], indices: Sequence[int], shape: int,
            color: Sequence[float], frame: str, pose: Pose) -> None:
        """A geometry built (or rebuilt under the same name) with its Object/Part fields, in
        ``frame`` at ``pose`` (its pose in that frame)."""
        old = self._markers.get(name)
        marker = _GeometryMarker(old.id if old else self._take_id(), name,
                                 marker_shape(parameters, indices, shape), display_color(color))
        marker.place(frame, pose)
        self._markers[name] = marker
        self._changed[name] = None
        self._colliding.discard(name)       # a new marker starts in its own colour

    def place(self, name: str, frame: str, pose: Pose) -> None:
        """The geometry's object has a new tf frame (it became, or stopped being, a robot's
        link)."""
        marker = self._markers.get(name)
        if marker is not None:
            marker.place(frame, pose)
            self._changed[name] = None

    def remove(self, names: Iterable[str]) -> None:
        for name in names:
            marker = self._markers.pop(name, None)
            if marker is not None:
                self._changed[name] = _action(marker.id, Marker.DELETE, name)
                self._colliding.discard(name)

    def clear(self) -> None:
        self._markers.clear()
        self._changed.clear()
        self._colliding.clear()
        self._cleared = True

    def set_colliding(self, names: Iterable[str]) -> None:
        """The geometries reported colliding now (every other one is not). Called every
        publication: it touches only the markers whose state changed (10,000 objects)."""
        colliding = set(names)
        for name in colliding.symmetric_difference(self._colliding):
            marker = self._markers.get(name)
            if marker is not None:
                marker.colliding = name in colliding
                self._changed[name] = None
        self._colliding = {name for name in colliding if name in self._markers}

    def full(self) -> MarkerArray:
        """A DELETEALL, then every marker: what a subscriber that just came needs."""
        return _PreSerialisedMarkers(
            [_action(0, Marker.DELETEALL)] + [m.serialised() for m in self._markers.values()])

    def take_changes(self) -> Optional[MarkerArray]:
        """The markers added, moved to a new frame, recoloured or deleted since the last call
        (a New Scene sends a DELETEALL first); None when nothing changed."""
        if not self._changed and not self._cleared:
            return None
        parts = [_action(0, Marker.DELETEALL)] if self._cleared else []
        for name, deleted in self._changed.items():
            marker = self._markers.get(name)
            parts.append(marker.serialised() if marker is not None else deleted)
        self._changed.clear()
        self._cleared = False
        return _PreSerialisedMarkers([p for p in parts if p is not None])

    def _take_id(self) -> int:
        self._next_id += 1
        return self._next_id


class _PreSerialisedMarkers(MarkerArray):
    """A MarkerArray whose markers are already serialised."""

    __slots__ = ("_parts",)

    def __init__(self, parts: Sequence[bytes]):
        super().__init__()
        self._parts = list(parts)

    def serialize(self, buff) -> None:
        buff.write(struct.pack("<I", len(self._parts)))
        for part in self._parts:
            buff.write(part)


__all__ = ["MARKER_NAMESPACE", "GeometryMarkers", "display_color", "marker_shape"]
