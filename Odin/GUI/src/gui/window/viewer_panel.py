"""Past the thesis: the Viewer's live image (``/viewer/image``) inside the window."""
from __future__ import annotations

import time

from PyQt5.QtCore import Qt
from PyQt5.QtGui import QPixmap
from PyQt5.QtWidgets import QLabel, QSizePolicy, QVBoxLayout, QWidget


class ViewerPanel(QWidget):
    def __init__(self, parent=None):
        super().__init__(parent)
        self.label = QLabel("No image from the Viewer yet\n(rosrun Viewer viewer)")
        self.label.setAlignment(Qt.AlignCenter)
        self.label.setMinimumSize(320, 240)
        self.label.setSizePolicy(QSizePolicy.Ignored, QSizePolicy.Ignored)
        self.label.setStyleSheet("background: #202020; color: #bbbbbb;")
        self.frames = 0
        self.last_frame_time = 0.0
        self.image = None
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.label)

    def on_image(self, image) -> None:
        if image.isNull():
            return
        self.image = image
        self.frames += 1
        self.last_frame_time = time.monotonic()
        if self.isVisible():
            self.label.setPixmap(QPixmap.fromImage(image).scaled(
                self.label.size(), Qt.KeepAspectRatio, Qt.SmoothTransformation))
