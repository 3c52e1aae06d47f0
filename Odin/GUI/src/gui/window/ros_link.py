"""rospy topics -> Qt signals. Subscriber callbacks run on rospy's threads; they only convert the
message (an image into a ``QImage`` copy) and emit a signal, which Qt queues to the GUI thread.

Topics subscribed (names are relative to the world's and Viewer's namespaces):
  ``<world>/world_update`` Messages/SpaceDistribution -> ``world_update(msg)``;
  ``<world>/joint_data``   Messages/JointsData -> ``joint_data(msg)``;
  ``<world>/joint_states`` sensor_msgs/JointState (world joint IDs) -> ``joint_states(msg)``;
  ``<viewer>/image``       sensor_msgs/Image (rgb8 / bgr8 / mono8) -> ``image(QImage)``.

Only the latest image is ever queued: a frame arriving while the previous one has not been
drawn yet replaces it (so a busy GUI thread never piles up frames).
"""
from __future__ import annotations

import threading

from PyQt5.QtCore import QObject, pyqtSignal
from PyQt5.QtGui import QImage

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
    """Subscribes once (rospy must be initialised); signals carry messages to the GUI thread."""

    world_update = pyqtSignal(object)
    joint_data = pyqtSignal(object)
    joint_states = pyqtSignal(object)
    image = pyqtSignal(object)
    _image_ready = pyqtSignal()

    def __init__(self, world: str = WORLD_NAMESPACE, viewer: str = VIEWER_NAMESPACE,
                 parent=None):
        super().__init__(parent)
        import rospy
        from sensor_msgs.msg import Image, JointState

        from Messages.msg import JointsData, SpaceDistribution
        self._lock = threading.Lock()
        self._latest_image = None
        self._image_ready.connect(self._emit_image)
        world = world.rstrip("/")
        self._subscribers = [
            rospy.Subscriber(f"{world}/world_update", SpaceDistribution,
                             self.world_update.emit, queue_size=2),
            rospy.Subscriber(f"{world}/joint_data", JointsData, self.joint_data.emit,
                             queue_size=2),
            rospy.Subscriber(f"{world}/joint_states", JointState, self.joint_states.emit,
                             queue_size=2),
            rospy.Subscriber(f"{viewer.rstrip('/')}/image", Image, self._on_image,
                             queue_size=1, buff_size=4 << 20),
        ]

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
        for subscriber in self._subscribers:
            subscriber.unregister()
        self._subscribers.clear()
