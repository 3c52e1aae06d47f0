"""The GUI's client of the Viewer: its services (``odin_common.interface.VIEWER_SERVICES``)
through one ``gui.ros.services.ServiceCaller``, no Qt.

The window asks the Viewer for its camera (Set Camera: read it, fix it, give it back to the
Viewer's own fitting) and for snapshots (Save Snapshot); cameras come back as ``CameraPose``
(world frame, REP 103, metres). A broken call, and a refused Save Snapshot, raise
``gui.errors.ViewerError``; a refused Set Camera still answers the camera in force, so its
refusal comes back with it (``CameraAnswer``).

The proxies are not persistent: a Viewer restarted under the same name is reached at the next
call, without a failed one first (camera moves are few; the ~1 ms of a fresh connection does not
matter). Each call blocks until the Viewer answers: the window calls from a worker thread
(gui.window.worker). Requires ``rospy.init_node`` (done here unless already done).
"""
from __future__ import annotations

from typing import NamedTuple, Optional, Sequence, Tuple

from gui.errors import ViewerError
from gui.ros.services import ServiceCaller, join_ros_graph
from odin_common.interface import VIEWER_NAMESPACE, VIEWER_SERVICES


class CameraPose(NamedTuple):
    """eye, target, up: world frame, metres; fov_y: rad; width, height: pixels."""
    eye: tuple
    target: tuple
    up: tuple
    fov_y: float
    width: int
    height: int


class CameraAnswer(NamedTuple):
    """Set Camera's answer: the camera in force, and the Viewer's message if it refused the
    request ("" when it took it)."""
    camera: CameraPose
    refusal: str


class ViewerClient:
    """Calls ``<namespace>/<service>`` of the Viewer's services."""

    def __init__(self, namespace: str = VIEWER_NAMESPACE, timeout: float = 10.0,
                 node_name: str = "gui"):
        join_ros_graph(node_name)
        self._caller = ServiceCaller(namespace, VIEWER_SERVICES, ViewerError,
                                     persistent=False)
        self.namespace = self._caller.namespace
        self._caller.wait("set_camera", timeout,
                          f"no Viewer answering after {timeout:g} s "
                          "(is `rosrun Viewer viewer` running?)")

    def set_camera(self, eye: Optional[Sequence[float]] = None,
                   target: Optional[Sequence[float]] = None,
                   up: Sequence[float] = (0.0, 0.0, 1.0), fit_scene: bool = False,
                   size: Optional[Tuple[int, int]] = None,
                   fov_y: Optional[float] = None) -> CameraAnswer:
        """Set Camera: fixes the camera at ``eye`` looking at ``target`` (m, world frame; both
        or neither) with ``up``, or gives it back to the Viewer's fitting (``fit_scene``); sets
        the image ``size`` (width, height pixels) and ``fov_y`` (rad) if given. Nothing given
        only reads the camera in force."""
        fields = dict(fit_scene=bool(fit_scene))
        if eye is not None:
            fields.update(set_pose=True, eye=[float(v) for v in eye],
                          target=[float(v) for v in target], up=[float(v) for v in up])
        if size is not None:
            fields.update(set_size=True, width=int(size[0]), height=int(size[1]))
        if fov_y is not None:
            fields.update(set_fov=True, fov_y=float(fov_y))
        answer = self._caller.ask("set_camera", **fields)
        camera = CameraPose(tuple(answer.eye), tuple(answer.target), tuple(answer.up),
                            float(answer.fov_y), int(answer.width), int(answer.height))
        return CameraAnswer(camera, "" if answer.success else answer.message)

    def camera(self) -> CameraPose:
        """The camera in force."""
        return self.set_camera().camera

    def save_snapshot(self, name: str) -> str:
        """Save Snapshot: the current frame as the PNG ``name`` in the Viewer's
        ``~snapshot_dir``; returns the file's absolute path."""
        return self._caller.call("save_snapshot", name=name).path

    def close(self) -> None:
        self._caller.close()
