"""What the world's standard ROS topics need beyond the Core (no rospy here).

tf, RViz markers, interactive markers and robots' joint states describe *objects*, *frames* and
*robots*, where the Core answers geometries and joints. ``WorldMirror`` keeps that view, fed by
the world's services as they succeed (``WorldServices`` calls it: built, removed, cleared, Set
Robot), so that it never disagrees with the Core:

- ``frames`` (ObjectFrames): each object's tf frame and how it follows its geometries;
- ``markers`` (GeometryMarkers): each geometry's marker in its object's frame;
- ``robots`` (RobotRegistry): the robots declared, whose links rename their objects' frames;
- ``clock`` (WorldClock): the stamps of every publication;
- ``objects``: what each object is (static, movable) for tf and interactive markers.

``take_robot_changes()`` hands the ROS layer the robots set and removed since it last asked
(it sets and deletes their robot_description parameters).
"""
from __future__ import annotations

import collections
from dataclasses import dataclass
from typing import Dict, Iterable, List, Optional, Sequence, Tuple

import numpy as np

from odin_common.interface import Shape, shape_of
from odin_common.specs import CompositeSpec
from virtual_world.core.arrays import flat_float64
from virtual_world.portal.clock import WorldClock
from virtual_world.portal.frames import IDENTITY_POSE, ObjectFrames
from virtual_world.portal.markers import GeometryMarkers
from virtual_world.portal.robots import Robot, RobotRegistry


@dataclass(frozen=True)
class ObjectInfo:
    """What an object is, for the ROS side."""
    static: bool            # geometry only: never moves (tf_static)
    movable: bool           # a body that contacts and forces move (not fixed, not static)
    geometries: Tuple[str, ...]
    size: float             # m, a rough diameter (interactive markers' handles)


class WorldMirror:
    """See the module docstring."""

    def __init__(self) -> None:
        self.frames = ObjectFrames()
        self.markers = GeometryMarkers()
        self.robots = RobotRegistry()
        self.clock = WorldClock()
        self.objects: "collections.OrderedDict[str, ObjectInfo]" = collections.OrderedDict()
        self.changed = False             # the world changed since the last publication
        self._robot_changes: List[Tuple[str, Robot]] = []
        self._movable: Optional[List[str]] = None   # movable_objects until the next change

    # -- the scene's changes (the world's services call these after the Core succeeded) -------
    def built(self, object_id: str, spec, geometries: Sequence) -> None:
        """An object built from ``spec`` (ObjectSpec or CompositeSpec) whose geometries are
        ``geometries`` (core.BuiltGeometry or View Object requests: name, parameters,
        indices, colour, world pose right after the build, shape)."""
        pose = (tuple(spec.position), tuple(spec.orientation))
        self.frames.add(object_id, pose,
                        [(g.name, (tuple(g.position), tuple(g.orientation))) for g in geometries],
                        static=bool(spec.geometry_only))
        frame = self.frames.frame(object_id)
        in_frame = self.frames.geometries_in_frame(object_id)
        for g in geometries:
            self.markers.add(g.name, g.parameters, g.indices, g.shape, g.color, frame,
                             in_frame[g.name])
        self.objects[object_id] = ObjectInfo(
            static=bool(spec.geometry_only),
            movable=not (spec.geometry_only or spec.fixed),
            geometries=tuple(g.name for g in geometries), size=_size(spec))
        self._movable = None
        self.changed = True

    def removed(self, object_id: str = "", joint_ids: Iterable[str] = ()) -> None:
        """An object (with its joints) or joints alone went; robots using them are forgotten."""
        joint_ids = list(joint_ids)
        for robot in self.robots.using([object_id] if object_id else [], joint_ids):
            self._forget(robot)
        info = self.objects.pop(object_id, None)
        if info is not None:
            self.frames.remove(object_id)
            self.markers.remove(info.geometries)
        self._movable = None
        self.changed = True

    def cleared(self) -> None:
        """New Scene: nothing is left."""
        for robot in self.robots.clear():
            self._robot_changes.append(("remove", robot))
        self.frames.clear()
        self.markers.clear()
        self.objects.clear()
        self._movable = None
        self.changed = True

    # -- robots --------------------------------------------------------------------------------
    def set_robot(self, robot: Robot, joint_types: Dict[str, int]) -> None:
        """Declares (or replaces) ``robot`` after checking it against the objects held and
        ``joint_types`` ({joint ID: JointType} of the Core's joints); all or nothing."""
        self.robots.check(robot, self.objects, joint_types)
        replaced = [link.object_id for link in self.robots.get(robot.name).links] \
            if robot.name in {r.name for r in self.robots} else []
        frames = robot.link_frames()
        self.frames.check_links(frames, replaced)
        for object_id in replaced:
            self.frames.unset_link(object_id)
        for link in robot.links:
            self.frames.set_link(link.object_id, frames[link.object_id],
                                 (link.position, link.quaternion))
        self.robots.set(robot)
        self._replace_markers(set(replaced) | set(frames))
        self._robot_changes.append(("set", robot))
        self._movable = None
        self.changed = True

    def remove_robot(self, name: str) -> Robot:
        robot = self.robots.get(name)
        self._forget(robot)
        return robot

    def take_robot_changes(self) -> List[Tuple[str, Robot]]:
        """[("set" | "remove", robot)] since the last call, in order."""
        changes, self._robot_changes = self._robot_changes, []
        return changes

    def _forget(self, robot: Robot) -> None:
        self.robots.remove(robot.name)
        objects = [link.object_id for link in robot.links]
        for object_id in objects:
            self.frames.unset_link(object_id)
        self._replace_markers(objects)
        self._robot_changes.append(("remove", robot))
        self._movable = None

    def _replace_markers(self, object_ids: Iterable[str]) -> None:
        for object_id in object_ids:
            if object_id not in self.frames:
                continue
            frame = self.frames.frame(object_id)
            for name, pose in self.frames.geometries_in_frame(object_id).items():
                self.markers.place(name, frame, pose)

    # -- reading -------------------------------------------------------------------------------
    def movable_objects(self) -> List[str]:
        """Objects a user may drag or push: bodies neither fixed nor static, and no robot's
        link (a link is moved through its joints). Asked every publication: computed again
        only after the scene or its robots changed."""
        if self._movable is None:
            self._movable = [o for o, info in self.objects.items()
                             if info.movable and self.robots.robot_of_object(o) is None]
        return list(self._movable)


def _size(spec) -> float:
    """A rough diameter (m) of the object: its parts' sizes and how far they sit from its
    origin (at least 5 cm; a plane counts as 1 m)."""
    composite = isinstance(spec, CompositeSpec)
    extent = 0.05
    for part in (spec.parts if composite else [spec]):
        values = flat_float64(part.parameters)
        if shape_of(values.size, part.shape) == Shape.MESH:
            size = float(np.ptp(values.reshape(-1, 3), axis=0).max())
        else:
            size = 2 * float(np.abs(values).max()) if values.size else 1.0
        offset = float(np.linalg.norm(part.position)) if composite else 0.0
        extent = max(extent, size + 2 * offset)
    return extent


__all__ = ["ObjectInfo", "WorldMirror", "IDENTITY_POSE"]
