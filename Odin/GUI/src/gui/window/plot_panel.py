"""Past the thesis: chosen joints' positions and speeds over time, from the world's
``~joint_states``.

Samples go into one bounded deque per joint axis (``history`` seconds of simulated time); the
plot is repainted by a timer at ``fps`` (never per message), with QPainter: positions on top,
speeds below, one colour per chosen joint, a shared time axis (simulated seconds). The list
names each channel as the window names its joint ("KukaLWR: Link1", ``channel_label``), the
world's ID in its tooltip; ``relabel()`` when the scene's robots change.
"""
from __future__ import annotations

import collections
import math
from typing import Callable, Optional

from PyQt5.QtCore import QPointF, QRectF, Qt, QTimer
from PyQt5.QtGui import QColor, QPainter, QPen, QPolygonF
from PyQt5.QtWidgets import (QListWidget, QListWidgetItem, QSplitter,
                             QVBoxLayout, QWidget)

COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
          "#17becf"]


class PlotCanvas(QWidget):
    def __init__(self, panel, parent=None):
        super().__init__(parent)
        self.panel = panel
        self.setMinimumSize(240, 160)

    def paintEvent(self, _event) -> None:
        painter = QPainter(self)
        painter.fillRect(self.rect(), Qt.white)
        chosen = self.panel.chosen()
        w, h = self.width(), self.height()
        half = h / 2
        t_now = self.panel.latest_time
        t0 = max(t_now - self.panel.history, self.panel.first_time)
        span = max(t_now - t0, 1e-6)
        for index, (title, field) in enumerate((("position (rad | m)", 1),
                                                ("speed (rad/s | m/s)", 2))):
            area = QRectF(44, index * half + 16, w - 52, half - 30)
            painter.setPen(QPen(QColor("#999999")))
            painter.drawRect(area)
            painter.setPen(Qt.black)
            painter.drawText(QPointF(46, index * half + 12), title)
            series = [(name, self.panel.samples.get(name, ())) for name in chosen]
            values = [s[field] for _, data in series for s in data if s[0] >= t0]
            if not values:
                continue
            low, high = min(values), max(values)
            if high - low < 1e-9:
                low, high = low - 1.0, high + 1.0
            pad = 0.05 * (high - low)
            low, high = low - pad, high + pad
            painter.drawText(QPointF(2, area.top() + 10), f"{high:.3g}")
            painter.drawText(QPointF(2, area.bottom()), f"{low:.3g}")
            for k, (name, data) in enumerate(series):
                poly = QPolygonF()
                for sample in data:
                    if sample[0] < t0:
                        continue
                    x = area.left() + (sample[0] - t0) / span * area.width()
                    y = area.bottom() - (sample[field] - low) / (high - low) * area.height()
                    poly.append(QPointF(x, y))
                painter.setPen(QPen(QColor(COLORS[k % len(COLORS)]), 1.5))
                painter.drawPolyline(poly)
        painter.setPen(Qt.black)
        painter.drawText(QPointF(46, h - 4), f"simulated time {t0:.1f} .. {t_now:.1f} s")
        painter.end()


def channel_label(channel: str, scene) -> str:
    """How the list names a ``~joint_states`` channel ("<joint id>", or "<joint id>/<axis>" for
    a joint of several axes): ``scene.joint_label`` of its joint ("<robot>: <joint name>" for
    a robot's joint, else the world ID; ``gui.window.scene.SceneModel``), " axis k" added for a
    joint of several axes."""
    joint, axis = channel, ""
    if channel not in scene.joints:
        head, _, tail = channel.rpartition("/")
        if tail.isdigit() and head in scene.joints:
            joint, axis = head, tail
    text = scene.joint_label(joint)
    return f"{text} axis {axis}" if axis else text


class JointPlotPanel(QWidget):
    """Check joints in the list to plot them. ``label(channel)``: the text a channel is listed
    under (None: its name, the world's ID)."""

    def __init__(self, history: float = 10.0, fps: float = 10.0,
                 label: Optional[Callable[[str], str]] = None, parent=None):
        super().__init__(parent)
        self.label = label or (lambda channel: channel)
        self.history = history
        self.samples: dict = {}
        self.latest_time = 0.0
        self.first_time = 0.0
        self.list = QListWidget()
        self.list.setToolTip("check the joints to plot")
        self.canvas = PlotCanvas(self)
        splitter = QSplitter(Qt.Horizontal)
        splitter.addWidget(self.list)
        splitter.addWidget(self.canvas)
        splitter.setStretchFactor(0, 2)
        splitter.setStretchFactor(1, 3)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(splitter)
        self._dirty = False
        self._rechoose: set = set()
        self._timer = QTimer(self)
        self._timer.timeout.connect(self._repaint)
        self._timer.start(int(1000 / fps))

    def chosen(self) -> list:
        """The checked channels' names (world IDs, as ``~joint_states`` names them)."""
        return [self.list.item(i).data(Qt.UserRole) for i in range(self.list.count())
                if self.list.item(i).checkState() == Qt.Checked]

    def choose(self, name: str, on: bool = True) -> None:
        """Checks (or unchecks) the channel ``name``: its world ID or the text it is listed
        under."""
        for i in range(self.list.count()):
            item = self.list.item(i)
            if name in (item.data(Qt.UserRole), item.text()):
                item.setCheckState(Qt.Checked if on else Qt.Unchecked)

    def relabel(self) -> None:
        """Lists every channel under ``label`` again (the scene's robots changed)."""
        for i in range(self.list.count()):
            item = self.list.item(i)
            item.setText(self.label(item.data(Qt.UserRole)))

    def on_joint_states(self, msg) -> None:
        t = msg.header.stamp.to_sec()
        if t < self.latest_time - 1e-9 or not self.samples:   # a first message, a restarted world
            self._rechoose |= set(self.chosen())
            self.samples.clear()
            self.list.clear()
            self.first_time = t
        # every message names every joint of the world, whose clock runs on across New
        # Scenes: a channel missing from this one left the world (New Scene, a removal)
        gone = self.samples.keys() - set(msg.name)
        if gone:
            self._forget(gone)
        self.latest_time = t
        keep = int(self.history * 100) + 1
        for k, name in enumerate(msg.name):
            data = self.samples.get(name)
            if data is None:
                data = self.samples[name] = collections.deque(maxlen=keep)
                item = QListWidgetItem(self.label(name))
                item.setData(Qt.UserRole, name)
                item.setToolTip(name)
                item.setCheckState(Qt.Checked if name in self._rechoose else Qt.Unchecked)
                self.list.addItem(item)
            position = msg.position[k] if k < len(msg.position) else math.nan
            velocity = msg.velocity[k] if k < len(msg.velocity) else math.nan
            data.append((t, position, velocity))
        self._dirty = True

    def _forget(self, channels: set) -> None:
        """Drops the channels of joints that left the world: their samples and list items (a
        checked one is checked again if its joint comes back, as after a reload)."""
        for i in reversed(range(self.list.count())):
            item = self.list.item(i)
            name = item.data(Qt.UserRole)
            if name in channels:
                if item.checkState() == Qt.Checked:
                    self._rechoose.add(name)
                self.list.takeItem(i)
        for name in channels:
            del self.samples[name]
        self._dirty = True

    def _repaint(self) -> None:
        if self._dirty and self.isVisible():
            self._dirty = False
            self.canvas.update()
