"""Helpers for driving the window off-screen in tests and benchmarks (no pytest import)."""
from __future__ import annotations

import pathlib
import time
from typing import Callable

from PyQt5.QtCore import Qt
from PyQt5.QtTest import QTest
from PyQt5.QtWidgets import QApplication


_APP = []


def app() -> QApplication:
    """The process's QApplication (created once and kept alive here)."""
    if QApplication.instance() is None:
        _APP.append(QApplication(["odin-gui-test"]))
    return QApplication.instance()


def open_window(poll_period: float = 0.2):
    """The process's QApplication, this process as the ROS node "gui", and a shown MainWindow
    polling the world every ``poll_period`` s (the caller shuts it down)."""
    from gui.ros.node import join_as_gui
    from gui.window.main_window import MainWindow
    app()
    join_as_gui("gui")
    window = MainWindow(poll_period=poll_period)
    window.show()
    return window


def pump(seconds: float = 0.05) -> None:
    """Runs the Qt event loop for ``seconds``."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        QApplication.processEvents()
        time.sleep(0.005)


def wait_for(predicate: Callable[[], object], timeout: float = 10.0, what: str = "condition",
             details: Callable[[], object] = lambda: ""):
    """Runs the event loop until ``predicate()`` is true (returned); AssertionError after
    ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while True:
        QApplication.processEvents()
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what} {details()}")
        time.sleep(0.005)


def click(button) -> None:
    """A real left click in the middle of ``button`` (it must be enabled)."""
    QTest.mouseClick(button, Qt.LeftButton)


def type_into(widget, text: str) -> None:
    """Selects all and types ``text`` as keystrokes, then Enter (spin boxes commit on it)."""
    widget.setFocus()
    QTest.keyClick(widget, Qt.Key_A, Qt.ControlModifier)
    QTest.keyClicks(widget, text)
    QTest.keyClick(widget, Qt.Key_Return)


def screenshot(widget, path: pathlib.Path) -> pathlib.Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    pump(0.05)
    if not widget.grab().save(str(path)):
        raise OSError(f"could not write {path}")
    return path
