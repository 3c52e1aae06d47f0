"""Geometries the Viewer learns from the world's RViz markers (``<~world>/markers``), so that a
rosbag of the world's topics played back drives the Viewer without a world to call View Object.

The world draws each geometry as one marker whose ``text`` is the geometry's ID
(virtual_world.portal.markers): SPHERE, CYLINDER and CUBE with the primitive's size as scale, a
plane as a CUBE of PLANE_DRAWN_SIZE x PLANE_DRAWN_SIZE x PLANE_DRAWN_THICKNESS, a mesh or a
capsule as a TRIANGLE_LIST of its triangles in the geometry's frame. A geometry the Viewer does
not hold is added from its marker (at the origin: the next world_update places it); one it
already holds (from View Object) is left alone; a DELETE or DELETEALL removes only what markers
added. Colours are the marker's, which are the Viewer's own colours.
"""
from __future__ import annotations

from typing import List, Optional, Tuple

import numpy as np
from visualization_msgs.msg import Marker

from odin_common.interface import PLANE_DRAWN_SIZE, PLANE_DRAWN_THICKNESS, Shape

IDENTITY = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))


def _is_plane(scale) -> bool:
    return (np.isclose(scale.x, PLANE_DRAWN_SIZE) and np.isclose(scale.y, PLANE_DRAWN_SIZE)
            and np.isclose(scale.z, PLANE_DRAWN_THICKNESS))


def view_fields(marker: Marker) -> Optional[Tuple[str, tuple, tuple, int, tuple]]:
    """(ID, parameters, indices, shape, colour) of the View Object a marker stands for; None
    for a marker that is no geometry of the world's (no ID, another type)."""
    name = marker.text
    if not name:
        return None
    s = marker.scale
    color = (marker.color.r, marker.color.g, marker.color.b, marker.color.a)
    if marker.type == Marker.SPHERE:
        return name, (s.x / 2,), (), int(Shape.SPHERE), color
    if marker.type == Marker.CYLINDER:
        return name, (s.x / 2, s.z), (), int(Shape.CYLINDER), color
    if marker.type == Marker.CUBE:
        if _is_plane(s):
            return name, (), (), int(Shape.PLANE), color
        return name, (s.x, s.y, s.z), (), int(Shape.BOX), color
    if marker.type == Marker.TRIANGLE_LIST and len(marker.points) >= 3:
        points = np.array([(p.x, p.y, p.z) for p in marker.points], dtype=float)
        return (name, tuple(points.reshape(-1)), tuple(range(len(points))), int(Shape.MESH),
                color)
    return None


class MarkerIntake:
    """Which geometries came from markers; turns a MarkerArray into scene changes."""

    def __init__(self) -> None:
        self.added: set = set()

    def changes(self, markers: List[Marker], held) -> Tuple[list, list]:
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
