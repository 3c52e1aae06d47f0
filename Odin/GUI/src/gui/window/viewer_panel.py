"""Past the thesis: the Viewer's live image (``/viewer/image``) inside the window, navigated
with the mouse through the Viewer's Set Camera service.

Left drag orbits about the camera's target (horizontal: about world z; vertical: up and down,
never over the poles), right or middle drag (or shift + left drag) pans, the wheel zooms towards
the target. "Frame the robot" aims the camera at the robots the world holds (every object when
it holds none), "Fit scene" gives the camera back to the Viewer's own fitting. Every move is a
Set Camera (``gui.ros.viewer.ViewerClient.set_camera``) sent on a worker of the panel's own
(gui.window.worker); while one is on its way only the latest move waits, so a fast drag never
queues calls. The camera the panel moves from is the Viewer's answer (``camera``), in the world
frame (REP 103), metres.
"""
from __future__ import annotations

import math
import time
from typing import Callable, Optional, Sequence

import numpy as np
from PyQt5.QtCore import QObject, Qt, pyqtSignal
from PyQt5.QtGui import QPixmap
from PyQt5.QtWidgets import (QHBoxLayout, QLabel, QPushButton, QSizePolicy, QVBoxLayout,
                             QWidget)

from gui.ros.viewer import CameraAnswer, CameraPose
from gui.window.worker import VIEWER, WorldWorker
from odin_common.interface import VIEWER_NAMESPACE

ORBIT_PER_PIXEL = 0.01      # rad of orbit per pixel dragged
ZOOM_PER_STEP = 0.85        # distance factor per wheel notch (120 eighths of a degree)
MAX_ELEVATION = 1.5         # rad: the orbit stops short of the poles (up stays world z)
MIN_DISTANCE = 0.02         # m: the eye never reaches the target
FRAME_MARGIN = 0.3          # m added to a framed set of origins' radius (links have extent)


# -- navigation (pure) --------------------------------------------------------------------------
def orbit(camera: CameraPose, d_azimuth: float, d_elevation: float) -> CameraPose:
    """The eye turned about the target: ``d_azimuth`` rad about world z, ``d_elevation`` rad
    up (clamped below the poles); the distance is kept and up is world z."""
    target = np.asarray(camera.target)
    offset = np.asarray(camera.eye) - target
    distance = np.linalg.norm(offset)
    azimuth = math.atan2(offset[1], offset[0]) + d_azimuth
    elevation = math.asin(max(-1.0, min(1.0, offset[2] / distance))) + d_elevation
    elevation = max(-MAX_ELEVATION, min(MAX_ELEVATION, elevation))
    eye = target + distance * np.array([math.cos(elevation) * math.cos(azimuth),
                                        math.cos(elevation) * math.sin(azimuth),
                                        math.sin(elevation)])
    return camera._replace(eye=tuple(eye), up=(0.0, 0.0, 1.0))


def pan(camera: CameraPose, dx: float, dy: float) -> CameraPose:
    """Eye and target moved together in the image plane: ``dx``, ``dy`` fractions of the
    image's height (right, down), so what was under the cursor stays under it at the target's
    depth."""
    eye, target = np.asarray(camera.eye), np.asarray(camera.target)
    forward = target - eye
    distance = np.linalg.norm(forward)
    right = np.cross(forward, camera.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward / distance)
    span = 2 * distance * math.tan(camera.fov_y / 2)      # m the image's height covers
    shift = span * (-dx * right + dy * up)
    return camera._replace(eye=tuple(eye + shift), target=tuple(target + shift))


def zoom(camera: CameraPose, factor: float) -> CameraPose:
    """The eye moved along the line of sight to ``factor`` times its distance to the target."""
    eye, target = np.asarray(camera.eye), np.asarray(camera.target)
    offset = eye - target
    distance = max(np.linalg.norm(offset) * factor, MIN_DISTANCE)
    return camera._replace(eye=tuple(target + offset / np.linalg.norm(offset) * distance))


def frame(camera: CameraPose, points: Sequence, margin: float = FRAME_MARGIN) -> CameraPose:
    """The camera looking at the sphere around ``points`` (m, world frame; radius their
    spread + ``margin``) from its present direction, the whole sphere in view."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2
    radius = float(np.max(np.linalg.norm(pts - centre, axis=1))) + margin
    aspect = camera.width / camera.height
    half_fov = min(camera.fov_y, 2 * math.atan(math.tan(camera.fov_y / 2) * aspect)) / 2
    direction = np.asarray(camera.eye) - np.asarray(camera.target)
    direction /= np.linalg.norm(direction)
    eye = centre + direction * radius / math.sin(half_fov) * 1.05
    return camera._replace(eye=tuple(eye), target=tuple(centre), up=(0.0, 0.0, 1.0))


# -- Set Camera off the GUI thread --------------------------------------------------------------
class CameraLink(QObject):
    """Sends Set Camera requests (keyword arguments of ``ViewerClient.set_camera``) through a
    worker of its own (gui.window.worker with the Viewer's client), the latest one only: while
    one is on its way, a newer request replaces the one waiting. ``answered`` carries the
    request's number and the Viewer's camera (CameraPose), ``failed`` a message. GUI thread
    only."""

    answered = pyqtSignal(int, object)
    failed = pyqtSignal(str)

    def __init__(self, viewer: str = VIEWER_NAMESPACE, parent=None):
        super().__init__(parent)
        self.worker = WorldWorker(viewer, name="viewer", parent=self, node=VIEWER)
        self._waiting: Optional[tuple] = None     # (number, request) not sent yet
        self._on_its_way = False
        self._numbers = 0
        self._closed = False
        self.worker.start()

    def send(self, **request) -> int:
        """Queues a Set Camera, replacing one not sent yet; returns its number."""
        self._numbers += 1
        self._waiting = (self._numbers, request)
        if not self._on_its_way:
            self._send_waiting()
        return self._numbers

    def close(self) -> None:
        self._closed = True     # the requests the worker drops now are nobody's concern
        self.worker.stop(2000)

    def _send_waiting(self) -> None:
        (number, request), self._waiting = self._waiting, None
        self._on_its_way = True
        self.worker.submit("Set Camera", lambda viewer, job: viewer.set_camera(**request),
                           lambda answer: self._answered(number, answer), self._failed)

    def _answered(self, number: int, answer: CameraAnswer) -> None:
        if answer.refusal:
            self.failed.emit(f"Set Camera refused: {answer.refusal}")
        self.answered.emit(number, answer.camera)
        self._send_next()

    def _failed(self, message: str) -> None:      # Viewer absent or gone: said, tried again
        if self._closed:
            return
        self.failed.emit(message)
        self._send_next()

    def _send_next(self) -> None:
        self._on_its_way = False
        if self._waiting is not None:
            self._send_waiting()


class _ImageLabel(QLabel):
    """The image; mouse drags and the wheel go to ``on_drag(dx, dy, button, modifiers)`` and
    ``on_wheel(notches)`` (pixels, notches of 120)."""

    def __init__(self, text: str, on_drag: Callable, on_wheel: Callable):
        super().__init__(text)
        self._on_drag, self._on_wheel = on_drag, on_wheel
        self._last = None

    def mousePressEvent(self, event) -> None:
        self._last = event.pos()

    def mouseMoveEvent(self, event) -> None:
        if self._last is None:
            return
        d = event.pos() - self._last
        self._last = event.pos()
        self._on_drag(d.x(), d.y(), event.buttons(), event.modifiers())

    def mouseReleaseEvent(self, event) -> None:
        self._last = None

    def wheelEvent(self, event) -> None:
        self._on_wheel(event.angleDelta().y() / 120.0)


class ViewerPanel(QWidget):
    """The image with mouse navigation; ``frame_points`` (set by the window) answers the world
    points (m) "Frame the robot" aims at; ``message`` reports a refusal or an absent Viewer."""

    message = pyqtSignal(str)

    def __init__(self, parent=None, viewer: Optional[str] = VIEWER_NAMESPACE,
                 frame_points: Callable[[], list] = list):
        super().__init__(parent)
        self.label = _ImageLabel("No image from the Viewer yet\n(rosrun Viewer viewer)",
                                 self._drag, self._wheel)
        self.label.setAlignment(Qt.AlignCenter)
        self.label.setMinimumSize(320, 240)
        self.label.setSizePolicy(QSizePolicy.Ignored, QSizePolicy.Ignored)
        self.label.setStyleSheet("background: #202020; color: #bbbbbb;")
        self.label.setToolTip("Drag: orbit. Right drag or shift + drag: pan. Wheel: zoom.")
        self.frame_button = QPushButton("Frame the robot")
        self.frame_button.setToolTip("Aim the camera at the robots (every object without one)")
        self.fit_button = QPushButton("Fit scene")
        self.fit_button.setToolTip("The Viewer's own camera, fitted to the whole scene")
        self.frame_points = frame_points
        self.frames = 0
        self.last_frame_time = 0.0
        self.image = None
        self.camera: Optional[CameraPose] = None
        self._last_request = 0
        self.camera_answers = 0
        self.link = CameraLink(viewer, self) if viewer is not None else None
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.label, 1)
        row = QHBoxLayout()
        row.addWidget(self.frame_button)
        row.addWidget(self.fit_button)
        row.addStretch(1)
        layout.addLayout(row)
        self.frame_button.clicked.connect(self.frame_robot)
        self.fit_button.clicked.connect(lambda: self._send(fit_scene=True))
        if self.link is not None:
            self.link.answered.connect(self._answered)
            self.link.failed.connect(self.message.emit)

    # -- image --------------------------------------------------------------------------------
    def on_image(self, image) -> None:
        if image.isNull():
            return
        if self.image is None and self.camera is None:
            self._send()        # the first image: learn the Viewer's camera
        self.image = image
        self.frames += 1
        self.last_frame_time = time.monotonic()
        if self.isVisible():
            self.label.setPixmap(QPixmap.fromImage(image).scaled(
                self.label.size(), Qt.KeepAspectRatio, Qt.SmoothTransformation))

    # -- camera -------------------------------------------------------------------------------
    def _send(self, **fields) -> None:
        if self.link is not None:
            self._last_request = self.link.send(**fields)

    def _answered(self, number: int, camera: CameraPose) -> None:
        self.camera_answers += 1
        if number == self._last_request:    # an older answer would undo the moves since
            self.camera = camera

    def move_to(self, camera: CameraPose) -> None:
        """Fixes the Viewer's camera at ``camera`` (shown at once; the answer confirms it)."""
        self.camera = camera
        self._send(eye=camera.eye, target=camera.target, up=camera.up)

    def _drag(self, dx: int, dy: int, buttons, modifiers) -> None:
        if self.camera is None:
            return
        panning = buttons & (Qt.RightButton | Qt.MiddleButton) or \
            (buttons & Qt.LeftButton and modifiers & Qt.ShiftModifier)
        if panning:
            height = max(self.label.height(), 1)
            self.move_to(pan(self.camera, dx / height, dy / height))
        elif buttons & Qt.LeftButton:
            self.move_to(orbit(self.camera, -dx * ORBIT_PER_PIXEL, dy * ORBIT_PER_PIXEL))

    def _wheel(self, notches: float) -> None:
        if self.camera is not None and notches:
            self.move_to(zoom(self.camera, ZOOM_PER_STEP ** notches))

    def frame_robot(self) -> None:
        points = self.frame_points()
        if self.camera is None:
            self.message.emit("Frame the robot: no camera from the Viewer yet "
                              "(rosrun Viewer viewer)")
        elif not points:
            self.message.emit("Frame the robot: the world holds nothing to frame")
        else:
            self.move_to(frame(self.camera, points))

    def close_link(self) -> None:
        if self.link is not None:
            self.link.close()
            self.link = None
