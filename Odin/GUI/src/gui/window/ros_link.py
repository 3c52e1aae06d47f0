"""The window's topics (gui.ros.topics) -> Qt signals. The callbacks run on the ROS client's
threads; they only convert the message (an image into a ``QImage`` copy) and emit a signal,
which Qt queues to the GUI thread.

  ``<world>/world_update`` -> ``world_update(msg)``;
  ``<world>/joint_data``   -> ``joint_data(msg)``;
  ``<world>/joint_states`` -> ``joint_states(msg)``;
  ``<viewer>/image``       (rgb8 / bgr8 / mono8 / rgba8) -> ``image(QImage)``.

Only the latest image is ever queued: a frame arriving while the previous one has not been
drawn yet replaces it (so a busy GUI thread never piles up frames).
"""
from __future__ import annotations

import threading

from PyQt5.QtCore import QObject, pyqtSignal
from PyQt5.QtGui import QImage

from gui.ros.topics import WindowTopics
from odin_common.interface import VIEWER_NAMESPACE, WORLD_NAMESPACE

_FORMATS = {"rgb8": (QImage.Format_RGB888, 3), "bgr8": (QImage.Format_RGB888, 3),
            "mono8": (QImage.Format_Grayscale8, 1), "rgba8": (QImage.Format_RGBA8888, 4)}


def image_to_qimage(msg) -> QImage:
    """sensor_msgs/Image -> a QImage that owns its pixels (null image for unknown encodings)."""
    fmt = _FORMATS.get(msg.encoding)
    if fmt is None or msg.width == 0 or msg.height == 0:
        return QImage()
    data = bytes(msg.data)
    image = QImage(data, msg.width, msg.height, msg.step, fmt[0]).copy()
    if msg.encoding == "bgr8":
        image = image.rgbSwapped()
    return image


class RosLink(QObject):
    """Subscribes once (the process must be a ROS node); signals carry messages to the GUI
    thread."""

    world_update = pyqtSignal(object)
    joint_data = pyqtSignal(object)
    joint_states = pyqtSignal(object)
    image = pyqtSignal(object)
    _image_ready = pyqtSignal()

    def __init__(self, world: str = WORLD_NAMESPACE, viewer: str = VIEWER_NAMESPACE,
                 parent=None):
        super().__init__(parent)
        self._lock = threading.Lock()
        self._latest_image = None
        self._image_ready.connect(self._emit_image)
        self._topics = WindowTopics(self.world_update.emit, self.joint_data.emit,
                                    self.joint_states.emit, self._on_image, world, viewer)

    def _on_image(self, msg) -> None:
        image = image_to_qimage(msg)
        with self._lock:
            pending = self._latest_image is not None
            self._latest_image = image
        if not pending:
            self._image_ready.emit()

    def _emit_image(self) -> None:
        with self._lock:
            image, self._latest_image = self._latest_image, None
        if image is not None:
            self.image.emit(image)

    def close(self) -> None:
        self._topics.close()
