"""Every world object's tf frame and its pose from the geometry poses the Core reads (ROS-free).

The Core reports geometries (a composite part by part); tf wants one frame per object. An
object's frame is named by ``odin_common.interface.frame_id`` (with a "_2", "_3"... suffix when
the name is taken) and sits at the object's origin (its spec's pose), except for a link of a
declared robot (Set Robot): then the frame is the robot's link frame "<namespace>/<link>",
placed where the robot says the link frame sits in the object's frame. Either way the frame is
rigidly attached to one of the object's geometries, so its pose is that geometry's pose
composed with a fixed transform, computed for every object at once with numpy.

A static object (built ``geometry_only``) goes on /tf_static, the others on /tf.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, Iterable, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from odin_common.interface import WORLD_FRAME, frame_id, unique_frame
from odin_common.rotations import IDENTITY_WXYZ, compose_poses, invert_pose
from virtual_world.errors import InvalidArgument

Pose = Tuple[Sequence[float], Sequence[float]]    # (position m, quaternion (w, x, y, z))
IDENTITY_POSE: Pose = ((0.0, 0.0, 0.0), IDENTITY_WXYZ)


@dataclass
class _Frame:
    name: str                  # the tf frame
    own_name: str              # the frame by the object's ID (when no robot link renames it)
    static: bool
    geometries: Dict[str, Pose]   # each geometry's pose in the object's frame
    link: Pose                 # the tf frame's pose in the object's frame (a robot's link)
    position: np.ndarray = None    # (3,) m: the tf frame's origin in the first geometry's frame
    quaternion: np.ndarray = None  # (4,) (w, x, y, z): its orientation there

    def __post_init__(self) -> None:
        self.place(self.link)

    @property
    def geometry(self) -> str:
        """The geometry the frame follows (the object's first)."""
        return next(iter(self.geometries))

    def place(self, link: Pose) -> None:
        self.link = tuple(np.asarray(v, float) for v in link)
        object_in_geometry = invert_pose(*self.geometries[self.geometry])
        self.position, self.quaternion = compose_poses(*object_in_geometry, *self.link)


FramePoses = Tuple[List[str], np.ndarray, np.ndarray]
"""(frames, positions (n, 3) m, quaternions (n, 4) (w, x, y, z)), world frame."""


class ObjectFrames:
    """The frames of the objects the world holds; fed by the Portal's build, removal and New
    Scene answers and by Set Robot."""

    def __init__(self) -> None:
        self._objects: Dict[str, _Frame] = {}
        self._taken = {WORLD_FRAME}    # every frame in use (kept: a set per build is O(n^2))
        self._layout_key: Optional[tuple] = None
        self._layout: tuple = ()

    # -- the scene's changes -------------------------------------------------------------------
    def add(self, object_id: str, object_pose: Pose, geometries: Sequence[Tuple[str, Pose]],
            static: bool) -> str:
        """An object built at ``object_pose`` (world) whose geometries were then at the given
        world poses; returns its frame."""
        world_in_object = invert_pose(*object_pose)
        in_object = {name: compose_poses(*world_in_object, np.asarray(pose[0], float),
                                         np.asarray(pose[1], float))
                     for name, pose in geometries}
        frame = unique_frame(frame_id(object_id), self._taken)
        self._objects[object_id] = _Frame(frame, frame, static, in_object, IDENTITY_POSE)
        self._taken.add(frame)
        self._layout_key = None
        return frame

    def remove(self, object_id: str) -> None:
        entry = self._objects.pop(object_id, None)
        if entry is not None:
            self._taken.discard(entry.name)
            self._layout_key = None

    def clear(self) -> None:
        self._objects.clear()
        self._taken = {WORLD_FRAME}
        self._layout_key = None

    def __contains__(self, object_id: str) -> bool:
        return object_id in self._objects

    # -- robots ---------------------------------------------------------------------------------
    def check_links(self, links: Mapping[str, str], replaced: Iterable[str] = ()) -> None:
        """Refuses robot link frames ({object ID: frame}) for unknown objects or frames that
        another object's frame already uses (``replaced``: objects whose link frames go)."""
        released = {o for o in replaced if o in self._objects}
        for object_id in links:
            if object_id not in self._objects:
                raise InvalidArgument(f"no object {object_id!r} (Set Robot: every link's "
                                      "object must be built first)")
        users = {f.name: o for o, f in self._objects.items()
                 if o not in links and o not in released}
        users[WORLD_FRAME] = "the world"
        for object_id, frame in links.items():
            if frame in users:
                raise InvalidArgument(f"the link frame {frame!r} of {object_id!r} is already "
                                      f"the frame of {users[frame]!r}")

    def set_link(self, object_id: str, frame: str, link_in_object: Pose) -> None:
        """The object becomes a robot's link: its frame is ``frame``, at ``link_in_object``
        (the link frame's pose in the object's frame)."""
        entry = self._objects[object_id]
        self._taken.discard(entry.name)
        entry.name = frame
        self._taken.add(frame)
        entry.place(link_in_object)
        self._layout_key = None

    def unset_link(self, object_id: str) -> None:
        """The object is no robot's link any more: back to its own frame."""
        entry = self._objects.get(object_id)
        if entry is None:
            return
        self._taken.discard(entry.name)
        entry.name = unique_frame(entry.own_name, self._taken)
        self._taken.add(entry.name)
        entry.place(IDENTITY_POSE)
        self._layout_key = None

    # -- reading --------------------------------------------------------------------------------
    def frame(self, object_id: str) -> str:
        return self._objects[object_id].name

    def frames(self, object_ids: Sequence[str]) -> List[str]:
        """The frame of each object ("" for one this table does not hold)."""
        return [self._objects[o].name if o in self._objects else "" for o in object_ids]

    def is_static(self, object_id: str) -> bool:
        return self._objects[object_id].static

    def geometries_in_frame(self, object_id: str) -> Dict[str, Pose]:
        """{geometry name: its pose in the object's tf frame} (what markers are drawn at)."""
        entry = self._objects[object_id]
        frame_in_link = invert_pose(*entry.link)
        return {name: compose_poses(*frame_in_link, *pose)
                for name, pose in entry.geometries.items()}

    def poses(self, names: Sequence[str], positions: np.ndarray, quaternions: np.ndarray
              ) -> Tuple[FramePoses, FramePoses]:
        """(dynamic, static) frame poses in the world from the Core's geometry poses (names,
        (n, 3) m, (n, 4) (w, x, y, z)); objects whose geometry is not among ``names`` are left
        out."""
        key = (tuple(names), len(self._objects))
        if key != self._layout_key:
            self._layout = self._lay_out(names)
            self._layout_key = key
        moving, static, rows, offset, local_p, local_q = self._layout
        if not rows.size:
            return ([], np.zeros((0, 3)), np.zeros((0, 4))), ([], np.zeros((0, 3)),
                                                               np.zeros((0, 4)))
        p = np.asarray(positions, float)[rows]          # copies: the Core's arrays stay
        q = np.asarray(quaternions, float)[rows]
        if offset.size:
            # one composition for every frame away from its geometry: its cost is numpy's per
            # call, not per frame; a frame at its geometry's pose (a lone object's, as the
            # 100-sphere scene's) is that pose, and composing those had cost the node's
            # loop a twentieth of its time at 25 publications a second
            p[offset], q[offset] = compose_poses(p[offset], q[offset], local_p, local_q)
        split = len(moving)
        return (moving, p[:split], q[:split]), (static, p[split:], q[split:])

    def _lay_out(self, names: Sequence[str]) -> tuple:
        """(moving frames, static frames, the row of each one's geometry in ``names`` and
        its pose in that geometry's frame), the moving frames first."""
        row_of = {name: i for i, name in enumerate(names)}
        groups = {False: [], True: []}
        for entry in self._objects.values():
            row = row_of.get(entry.geometry)
            if row is not None:
                groups[entry.static].append((entry.name, row, entry.position, entry.quaternion))
        ordered = groups[False] + groups[True]
        local_p = np.asarray([e[2] for e in ordered], float).reshape(-1, 3)
        local_q = np.asarray([e[3] for e in ordered], float).reshape(-1, 4)
        offset = np.flatnonzero(np.any(local_p != 0.0, axis=1)
                                | np.any(local_q != IDENTITY_WXYZ, axis=1))
        return ([e[0] for e in groups[False]], [e[0] for e in groups[True]],
                np.asarray([e[1] for e in ordered], dtype=np.intp), offset,
                local_p[offset], local_q[offset])


