"""A tracked execution's target against actual per joint (gui.core.execution.TrackingReport),
drawn with QPainter: one strip per joint (target dashed grey, actual in colour), a shared time
axis (simulated s). ``TrackingPlot`` shows it in the window; ``save_png`` writes it to a file
(off-screen, for ``run_path --plot``)."""
from __future__ import annotations

from PyQt5.QtCore import QPointF, QRectF, Qt
from PyQt5.QtGui import QColor, QImage, QPainter, QPen, QPolygonF
from PyQt5.QtWidgets import QWidget

from gui.window.plot_panel import COLORS

STRIP_HEIGHT = 90
"""px per joint in a saved PNG."""
MIN_SPAN = 1e-3
"""rad or m: the least range a strip shows."""


def draw(painter: QPainter, width: int, height: int, report) -> None:
    """Draws ``report`` (or a hint when None) into a width x height area."""
    painter.fillRect(QRectF(0, 0, width, height), Qt.white)
    painter.setPen(Qt.black)
    if report is None or len(report.times) == 0:
        painter.drawText(QPointF(10, 20), "no tracked execution yet")
        return
    painter.drawText(QPointF(8, 14), f"goal error {report.goal_error:.2g}   tracking error max "
                     f"{report.tracking_error_max:.2g}   {report.duration_s:.2f} s, "
                     f"{report.contacts}")
    names = report.names
    top, bottom = 22.0, 18.0
    strip = (height - top - bottom) / max(len(names), 1)
    times = report.times
    t0, t1 = 0.0, float(times[-1]) or 1.0
    for k, name in enumerate(names):
        area = QRectF(60, top + k * strip + 12, width - 68, strip - 16)
        painter.setPen(QPen(QColor("#999999")))
        painter.drawRect(area)
        painter.setPen(Qt.black)
        painter.drawText(QPointF(62, area.top() - 2),
                         f"{name} ({report.units[k]}): target dashed, actual solid")
        target, actual = report.targets[:, k], report.actuals[:, k]
        low = float(min(target.min(), actual.min()))
        high = float(max(target.max(), actual.max()))
        if high - low < MIN_SPAN:          # a joint that stays put: no magnified noise
            middle = 0.5 * (low + high)
            low, high = middle - 0.5 * MIN_SPAN, middle + 0.5 * MIN_SPAN
        painter.drawText(QPointF(2, area.top() + 10), f"{high:.3g}")
        painter.drawText(QPointF(2, area.bottom()), f"{low:.3g}")
        for values, pen in ((target, QPen(QColor("#555555"), 1.5, Qt.DashLine)),
                            (actual, QPen(QColor(COLORS[k % len(COLORS)]), 1.5))):
            poly = QPolygonF([QPointF(area.left() + (t - t0) / (t1 - t0) * area.width(),
                                      area.bottom() - (v - low) / (high - low) * area.height())
                              for t, v in zip(times, values)])
            painter.setPen(pen)
            painter.drawPolyline(poly)
    painter.setPen(Qt.black)
    painter.drawText(QPointF(60, height - 4), f"{t0:g} s")
    painter.drawText(QPointF(width - 150, height - 4), f"{t1:.2f} s (simulated)")


class TrackingPlot(QWidget):
    """The window's view of the last tracked execution."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.report = None
        self.setMinimumSize(320, 200)

    def show_report(self, report) -> None:
        self.report = report
        self.update()

    def paintEvent(self, _event) -> None:
        painter = QPainter(self)
        draw(painter, self.width(), self.height(), self.report)
        painter.end()


def save_png(report, path: str, width: int = 900) -> None:
    """Writes the plot of ``report`` to ``path`` (needs a QGuiApplication; ``run_path`` makes
    an off-screen one)."""
    height = int(40 + STRIP_HEIGHT * max(len(report.names), 1))
    image = QImage(width, height, QImage.Format_RGB32)
    painter = QPainter(image)
    painter.setRenderHint(QPainter.Antialiasing)
    draw(painter, width, height, report)
    painter.end()
    if not image.save(str(path), "PNG"):
        raise OSError(f"cannot write {path}")
