"""Interactive markers for the world's movable objects (RViz's Interact tool).

Server ``~interactive`` (topics ``~interactive/update``, ``~interactive/update_full``,
``~interactive/feedback``; Debian's python3-interactive-markers). Every object a user may move
(a body neither fixed nor static, and no robot's link: ``WorldMirror.movable_objects``) gets a
marker at its origin, in the ``world`` frame, with arrows and rings along the world axes and a
handle that opens a menu:

- dragging an arrow or a ring sets the object's pose (Set Position, velocities reset), as long
  as the mouse is held;
- **Push** +x, -x, +y, -y, +z: adds ``~push_speed`` (m/s) along that world axis to the object's
  velocity (Get State, then Set Velocity);
- **Remove**: Remove Object.

Each goes through the world's own services (so a ``~record`` recording holds it and a refusal is
logged with the world's message). The markers follow the objects at ``SYNC_RATE``, except the
one being dragged, while the server has a subscriber.
"""
from __future__ import annotations

import logging
import time
from typing import Callable, Dict, Tuple

import numpy as np
from geometry_msgs.msg import Pose
from interactive_markers.interactive_marker_server import InteractiveMarkerServer
from interactive_markers.menu_handler import MenuHandler
from visualization_msgs.msg import (InteractiveMarker, InteractiveMarkerControl,
                                    InteractiveMarkerFeedback, Marker)

from Services.srv import GetStateRequest, RemoveObjectRequest, SetPositionRequest, \
    SetVelocityRequest
from Messages.msg import Situation
from odin_common.interface import WORLD_FRAME
from odin_common.rotations import wxyz_to_xyzw, xyzw_to_wxyz
from virtual_world.portal.mirror import WorldMirror

_log = logging.getLogger("rosout")

SYNC_RATE = 10.0          # Hz: how often the markers follow their objects
MOVED_BY = 1e-4           # m or rad: a marker is moved when its object moved more than this
PUSHES = {"+x": (1, 0, 0), "-x": (-1, 0, 0), "+y": (0, 1, 0), "-y": (0, -1, 0),
          "+z (up)": (0, 0, 1)}
"""The Push menu's entries: direction in the world frame."""

HANDLE_COLOR = (1.0, 0.55, 0.1, 0.8)


def _pose(position, quaternion_wxyz) -> Pose:
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = (float(v) for v in position)
    (pose.orientation.x, pose.orientation.y, pose.orientation.z,
     pose.orientation.w) = (float(v) for v in wxyz_to_xyzw(quaternion_wxyz))
    return pose


def _axis_controls(name: str, quaternion_xyzw) -> list:
    controls = []
    for mode, prefix in ((InteractiveMarkerControl.MOVE_AXIS, "move"),
                         (InteractiveMarkerControl.ROTATE_AXIS, "rotate")):
        control = InteractiveMarkerControl()
        control.name = f"{prefix}_{name}"
        (control.orientation.x, control.orientation.y, control.orientation.z,
         control.orientation.w) = quaternion_xyzw
        control.interaction_mode = mode
        control.orientation_mode = InteractiveMarkerControl.FIXED
        controls.append(control)
    return controls


def object_marker(object_id: str, position, quaternion_wxyz, size: float) -> InteractiveMarker:
    """The interactive marker of one object: axis controls fixed to the world's axes and a
    menu handle at its origin."""
    marker = InteractiveMarker()
    marker.header.frame_id = WORLD_FRAME
    marker.name = object_id
    marker.description = object_id
    marker.pose = _pose(position, quaternion_wxyz)
    marker.scale = max(1.2 * size, 0.1)
    h = 0.5 ** 0.5
    for axis, q in (("x", (0.0, 0.0, 0.0, 1.0)), ("y", (0.0, 0.0, h, h)),
                    ("z", (0.0, -h, 0.0, h))):
        marker.controls.extend(_axis_controls(axis, q))
    handle = Marker(type=Marker.SPHERE)
    handle.scale.x = handle.scale.y = handle.scale.z = 0.25 * marker.scale
    handle.color.r, handle.color.g, handle.color.b, handle.color.a = HANDLE_COLOR
    menu = InteractiveMarkerControl(name="menu", always_visible=True,
                                    interaction_mode=InteractiveMarkerControl.MENU)
    menu.markers.append(handle)
    marker.controls.append(menu)
    return marker


class InteractiveObjects:
    """The interactive marker server of the movable objects (see the module)."""

    def __init__(self, mirror: WorldMirror, serve: Callable[[str, object], object],
                 push_speed: float):
        """``serve(service name, request) -> response``: the world's own service handler
        (``success`` and ``message`` answered, as over ROS)."""
        self.mirror = mirror
        self._serve = serve
        self.push_speed = float(push_speed)
        self.server = InteractiveMarkerServer("~interactive")
        self.menu = MenuHandler()
        push = self.menu.insert("Push")
        self._push_entries: Dict[int, Tuple[float, float, float]] = {}
        for title, direction in PUSHES.items():
            self._push_entries[self.menu.insert(title, parent=push,
                                                callback=self._on_menu)] = direction
        self._remove_entry = self.menu.insert("Remove", callback=self._on_menu)
        self._shown: Dict[str, Tuple[np.ndarray, np.ndarray]] = {}   # id -> pose shown
        self._dragging: set = set()
        self._next_sync = 0.0

    # -- the loop thread: follow the world -------------------------------------------------------
    def sync(self, object_poses: Dict[str, Tuple[np.ndarray, np.ndarray]]) -> None:
        """Adds, moves and erases markers so they match the movable objects at
        ``object_poses`` ({object ID: (position m, quaternion (w, x, y, z))}, world frame), at
        most SYNC_RATE times a second (``due``)."""
        if not self.due():
            return
        self._next_sync = time.monotonic() + 1.0 / SYNC_RATE
        movable = [o for o in self.mirror.movable_objects() if o in object_poses]
        changed = False
        for object_id in set(self._shown) - set(movable):
            self.server.erase(object_id)
            del self._shown[object_id]
            self._dragging.discard(object_id)
            changed = True
        moved = self._moved([o for o in movable
                             if o in self._shown and o not in self._dragging], object_poses)
        for object_id in movable:
            position, quaternion = object_poses[object_id]
            if object_id not in self._shown:
                self.server.insert(object_marker(object_id, position, quaternion,
                                                 self.mirror.objects[object_id].size),
                                   self._on_feedback)
                self.menu.apply(self.server, object_id)
            elif object_id in moved:
                self.server.setPose(object_id, _pose(position, quaternion))
            else:
                continue
            self._shown[object_id] = (np.array(position), np.array(quaternion))
            changed = True
        if changed:
            self.server.applyChanges()

    def due(self) -> bool:
        """Whether ``sync`` would follow the objects now (the caller may skip gathering
        their poses otherwise): its period has passed and someone (RViz) listens. Without a
        listener the markers wait: following 100 free-running spheres cost the world a
        twentieth of its stepping time for no one, and the first sync after RViz connects
        brings them up to date (its update, and the latched update_full after it)."""
        return time.monotonic() >= self._next_sync and self._heard()

    def _heard(self) -> bool:
        return (self.server.update_pub.get_num_connections() > 0
                or self.server.init_pub.get_num_connections() > 0)

    def _moved(self, object_ids: list, object_poses: dict) -> set:
        """Those of ``object_ids`` (shown) that moved more than MOVED_BY from where their
        marker shows them: comparisons of stacked arrays, not numpy calls an object (which had
        cost the world a tenth of its time with 100 objects free running)."""
        if not object_ids:
            return set()
        moves = [np.abs(np.array([object_poses[o][k] for o in object_ids])
                        - np.array([self._shown[o][k] for o in object_ids])).max(axis=1)
                 for k in (0, 1)]     # positions, quaternions
        far = np.maximum(*moves) >= MOVED_BY
        return {o for o, f in zip(object_ids, far) if f}

    # -- rospy's threads: what the user did -------------------------------------------------------
    def _on_feedback(self, feedback: InteractiveMarkerFeedback) -> None:
        name = feedback.marker_name
        if feedback.event_type == InteractiveMarkerFeedback.MOUSE_DOWN:
            self._dragging.add(name)
        elif feedback.event_type == InteractiveMarkerFeedback.MOUSE_UP:
            self._dragging.discard(name)
        elif feedback.event_type == InteractiveMarkerFeedback.POSE_UPDATE:
            self._drag(name, feedback)

    def _drag(self, object_id: str, feedback: InteractiveMarkerFeedback) -> None:
        p, q = feedback.pose.position, feedback.pose.orientation
        quaternion = xyzw_to_wxyz([q.x, q.y, q.z, q.w])
        if not np.linalg.norm(quaternion) > 0:
            return
        request = SetPositionRequest(
            situations=[Situation(object_id, [p.x, p.y, p.z],
                                  (quaternion / np.linalg.norm(quaternion)).tolist())],
            reset_velocity=True)
        self._call("set_position", request)

    def _on_menu(self, feedback: InteractiveMarkerFeedback) -> None:
        object_id = feedback.marker_name
        if feedback.menu_entry_id == self._remove_entry:
            self._call("remove_object", RemoveObjectRequest(id=object_id))
            return
        direction = self._push_entries.get(feedback.menu_entry_id)
        if direction is None:
            return
        state = self._call("get_state", GetStateRequest(objects=[object_id]))
        if state is None:
            return
        linear = state.bodies[0].linear
        velocity = [v + self.push_speed * d for v, d in zip(linear, direction)]
        self._call("set_velocity", SetVelocityRequest(object=object_id, set_linear=True,
                                                      linear=velocity))

    def _call(self, service: str, request):
        response = self._serve(service, request)
        if not response.success:
            _log.warning("virtual_world: interactive marker: %s refused: %s", service,
                         response.message)
            return None
        return response

    def close(self) -> None:
        self.server.clear()
        self.server.applyChanges()
