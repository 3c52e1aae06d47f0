"""The robots declared with Set Robot: which world objects and joints make each one, under its
own ROS namespace and names (no rospy here, only the generated message classes).

A robot is metadata over the Core's objects and joints, for the ROS side only: its namespace
(``odin_common.interface.robot_namespace`` of its name), its URDF (the parameter
``<namespace>/robot_description``), its link names with the link frames' poses in their objects'
frames (its links' tf frames are "<namespace>/<link>") and its joints' own names, each one value
of a world joint with an offset (its ``<namespace>/joint_states`` give ``offset + that value``:
a hinge's angle, a slider's position, or a hinge-2 wheel's spin, its second value). The world
forgets a robot when one of its objects or joints goes (removal, New Scene): the rest of it
would no longer be the robot its description says.
"""
from __future__ import annotations

import collections
from dataclasses import dataclass
from typing import Dict, Iterable, List, Mapping, Sequence, Tuple

import numpy as np

from Messages.msg import Robot as RobotMessage
from odin_common.interface import JOINT_STATE_AXES, JointType, robot_link_frame, robot_namespace
from odin_common.rotations import IDENTITY_WXYZ, unit_quaternion
from virtual_world.core.validation import shared
from virtual_world.errors import InvalidArgument, UnknownName

@dataclass(frozen=True)
class RobotLink:
    object_id: str
    link: str
    position: Tuple[float, float, float]            # m: the link frame in the object's frame
    quaternion: Tuple[float, float, float, float]   # (w, x, y, z)


@dataclass(frozen=True)
class RobotJoint:
    joint_id: str
    name: str
    offset: float                                   # rad or m
    axis: int = 0                                   # which of the world joint's values


@dataclass(frozen=True)
class Robot:
    name: str
    namespace: str
    description: str
    links: Tuple[RobotLink, ...]
    joints: Tuple[RobotJoint, ...]

    def link_frames(self) -> Dict[str, str]:
        """{object ID: its link's tf frame}."""
        return {link.object_id: robot_link_frame(self.namespace, link.link)
                for link in self.links}


def _per_item(values: Sequence[float], count: int, size: int, what: str) -> np.ndarray:
    array = np.asarray(values, dtype=float).reshape(-1)
    if array.size == 0:
        return np.zeros((count, size))
    if array.size != count * size:
        raise InvalidArgument(f"{what}: {array.size} values for {count} link(s); expected "
                              f"{size} per link ({count * size}) or none")
    if not np.all(np.isfinite(array)):
        raise InvalidArgument(f"{what}: not finite")
    return array.reshape(count, size)


def _unique(names: Sequence[str], what: str) -> None:
    seen = set()
    for name in names:
        if not name:
            raise InvalidArgument(f"{what}: an empty name")
        if name in seen:
            raise InvalidArgument(f"{what}: {name!r} given twice")
        seen.add(name)


_LINK_NAMES = ("links", "objects", "link name", "object")
_JOINT_NAMES = ("joint_names", "joints", "joint name", "joint")
"""A robot's own names and the world IDs they name: (their fields of Messages/Robot, what one of
each is called in an error)."""


def _paired_names(message: RobotMessage, robot: str,
                  fields: Tuple[str, str, str, str]) -> Tuple[List[str], List[str]]:
    """The lists ``fields`` (_LINK_NAMES or _JOINT_NAMES) name: as many own names as world IDs,
    neither with an empty or repeated entry."""
    names_field, ids_field, name_noun, id_noun = fields
    names, ids = list(getattr(message, names_field)), list(getattr(message, ids_field))
    if len(names) != len(ids):
        raise InvalidArgument(f"Set Robot {robot!r}: {len(names)} {name_noun}(s) for "
                              f"{len(ids)} {id_noun}(s)")
    _unique(names, f"Set Robot {robot!r} {names_field}")
    _unique(ids, f"Set Robot {robot!r} {ids_field}")
    return names, ids


def robot_of(message: RobotMessage) -> Robot:
    """Messages/Robot -> Robot, every list checked (lengths, names, poses)."""
    name = message.name
    if not name:
        raise InvalidArgument("Set Robot: the robot needs a name")
    links, objects = _paired_names(message, name, _LINK_NAMES)
    positions = _per_item(message.link_positions, len(links), 3, "link_positions (m)")
    if len(message.link_orientations) == 0:
        orientations = [IDENTITY_WXYZ] * len(links)
    else:
        raw = _per_item(message.link_orientations, len(links), 4,
                        "link_orientations (w, x, y, z)")
        orientations = [tuple(shared(unit_quaternion, q, f"link_orientations of {link!r}"))
                        for q, link in zip(raw, links)]
    joint_names, joints = _paired_names(message, name, _JOINT_NAMES)
    offsets = np.asarray(message.joint_offsets, dtype=float).reshape(-1)
    if offsets.size == 0:
        offsets = np.zeros(len(joints))
    if offsets.size != len(joints) or not np.all(np.isfinite(offsets)):
        raise InvalidArgument(f"Set Robot {name!r}: joint_offsets must be {len(joints)} finite "
                              f"numbers (rad or m) or none, got {list(offsets)}")
    axes = _joint_axes(message.joint_axes, len(joints), name)
    namespace = shared(robot_namespace, name)
    return Robot(name, namespace, message.description,
                 tuple(RobotLink(o, link, tuple(p), tuple(q))
                       for o, link, p, q in zip(objects, links, positions.tolist(),
                                                orientations)),
                 tuple(RobotJoint(j, n, float(v), a)
                       for j, n, v, a in zip(joints, joint_names, offsets, axes)))


def _joint_axes(values, count: int, name: str) -> List[int]:
    # uint8[] arrives as bytes from a ROS message and as a list from Python callers
    axes = list(bytearray(values)) if isinstance(values, (bytes, bytearray)) else list(values)
    if not axes:
        return [0] * count
    if len(axes) != count or any(not 0 <= int(a) < 256 for a in axes):
        raise InvalidArgument(f"Set Robot {name!r}: joint_axes must be {count} axis indices "
                              f"(0 to 255) or none, got {axes}")
    return [int(a) for a in axes]


def robot_message(robot: Robot) -> RobotMessage:
    return RobotMessage(
        name=robot.name, ros_namespace=robot.namespace, description=robot.description,
        links=[link.link for link in robot.links],
        objects=[link.object_id for link in robot.links],
        link_positions=[v for link in robot.links for v in link.position],
        link_orientations=[v for link in robot.links for v in link.quaternion],
        joint_names=[j.name for j in robot.joints], joints=[j.joint_id for j in robot.joints],
        joint_offsets=[j.offset for j in robot.joints],
        joint_axes=[j.axis for j in robot.joints])


class RobotRegistry:
    """The robots in force, by name."""

    def __init__(self) -> None:
        self._robots: "collections.OrderedDict[str, Robot]" = collections.OrderedDict()

    def __iter__(self):
        return iter(self._robots.values())

    def __len__(self) -> int:
        return len(self._robots)

    def get(self, name: str) -> Robot:
        robot = self._robots.get(name)
        if robot is None:
            raise UnknownName(f"no robot {name!r} (robots: {sorted(self._robots)})")
        return robot

    def check(self, robot: Robot, objects: Iterable[str], joint_types: Mapping[str, int]
              ) -> None:
        """Refuses ``robot`` unless its objects and joints are in the world (``objects``;
        ``joint_types``: {joint ID: JointType}), its joints' world joints report the values
        named (JOINT_STATE_AXES), and neither its namespace nor any of its objects belongs to
        another robot."""
        present = set(objects)
        for link in robot.links:
            if link.object_id not in present:
                raise UnknownName(f"Set Robot {robot.name!r}: no object {link.object_id!r}")
        for joint in robot.joints:
            kind = joint_types.get(joint.joint_id)
            if kind is None:
                raise UnknownName(f"Set Robot {robot.name!r}: no joint {joint.joint_id!r}")
            values = JOINT_STATE_AXES.get(JointType(kind), ())
            if joint.axis >= len(values):
                reported = f"reports {', '.join(values)}" if values else "reports no value"
                raise InvalidArgument(
                    f"Set Robot {robot.name!r}: joint {joint.name!r} is value {joint.axis} of "
                    f"world joint {joint.joint_id!r}, a {JointType(kind).label}, which "
                    f"{reported} (joint_axes counts from 0)")
        for other in self._robots.values():
            if other.name == robot.name:
                continue
            if other.namespace == robot.namespace:
                raise InvalidArgument(f"Set Robot {robot.name!r}: namespace "
                                      f"{robot.namespace!r} is already robot {other.name!r}'s")
            shared = {link.object_id for link in robot.links} & \
                {link.object_id for link in other.links}
            if shared:
                raise InvalidArgument(f"Set Robot {robot.name!r}: object(s) {sorted(shared)} "
                                      f"already belong to robot {other.name!r}")

    def set(self, robot: Robot) -> None:
        self._robots[robot.name] = robot

    def remove(self, name: str) -> Robot:
        robot = self.get(name)
        del self._robots[name]
        return robot

    def clear(self) -> List[Robot]:
        gone = list(self._robots.values())
        self._robots.clear()
        return gone

    def using(self, object_ids: Iterable[str] = (), joint_ids: Iterable[str] = ()
              ) -> List[Robot]:
        """The robots one of whose objects or joints is among those given."""
        objects, joints = set(object_ids), set(joint_ids)
        return [r for r in self._robots.values()
                if any(link.object_id in objects for link in r.links)
                or any(j.joint_id in joints for j in r.joints)]

    def robot_of_object(self, object_id: str):
        for robot in self._robots.values():
            if any(link.object_id == object_id for link in robot.links):
                return robot
        return None

    def joint_states(self, states) -> List[Tuple[Robot, List[str], List[float], List[float]]]:
        """Each robot's joint states from the Core's (core.JointState list): (robot, names,
        positions rad or m, rates rad/s or m/s), the robot's own names and values."""
        by_id = {s.id: s for s in states}
        out = []
        for robot in self._robots.values():
            names, positions, rates = [], [], []
            for joint in robot.joints:
                state = by_id.get(joint.joint_id)
                if state is None or len(state.positions) <= joint.axis:
                    continue
                names.append(joint.name)
                positions.append(joint.offset + state.positions[joint.axis])
                rates.append(state.rates[joint.axis])
            if names:
                out.append((robot, names, positions, rates))
        return out
