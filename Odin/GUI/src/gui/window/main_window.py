"""The main window: the five tabs of thesis chapter 7, the Viewer's image and the joint plot,
a message log, and the world's connection state in the status bar.

Everything the tabs ask of the world goes through ``call`` (the ``WorldWorker`` queue); paths
run on ``path_worker`` so that Pause, forces or New Scene are not stuck behind them. A refusal
from the world (or a bad input caught here) is written to the log and the status bar with the
world's message, and kept in ``last_error``.
"""
from __future__ import annotations

import time
from typing import Callable, Optional

from PyQt5.QtCore import Qt, QTimer
from PyQt5.QtGui import QTextCursor
from PyQt5.QtWidgets import (QLabel, QMainWindow, QPlainTextEdit, QSplitter, QTabWidget,
                             QVBoxLayout, QWidget)

from gui.window.joints_tab import JointsTab
from gui.window.motion_tab import MotionTab
from gui.window.objects_tab import ObjectsTab
from gui.window.plot_panel import JointPlotPanel, channel_label
from gui.window.scene import SceneModel
from gui.window.settings_tab import SettingsTab
from gui.window.simulation_tab import SimulationTab
from gui.window.viewer_panel import ViewerPanel
from gui.window.worker import WorldWorker
from odin_common.interface import VIEWER_NAMESPACE, WORLD_NAMESPACE

SLOW_AFTER = 1.0        # s: a call taking longer makes the status bar say the world is slow
SILENT_AFTER = 2.0      # s: no world_update for this long while connected: "not publishing"
REFRESH_PERIOD = 1.0    # s: Get World again while idle (motors, forces and robots have no topic)
READ_WORLD = "Get World"    # the label of the window's own reads (not "busy" unless slow)


class MainWindow(QMainWindow):
    def __init__(self, world: str = WORLD_NAMESPACE, viewer: str = VIEWER_NAMESPACE,
                 ros: bool = True, poll_period: float = 0.5):
        super().__init__()
        self.setWindowTitle("Odin GUI")
        self.world_namespace = world
        self.scene = SceneModel(self)
        self.worker = WorldWorker(world, poll_period, "world", self)
        self.path_worker = WorldWorker(world, poll_period, "paths", self)
        self.publication_rate: Optional[float] = None
        self.last_error = ""
        self.last_info = ""
        self.errors: list = []
        self.connected = False
        self._lost_world = False          # a world was connected once and went away
        self.last_update_time = 0.0
        self.updates = 0
        self.world_reads = 0              # Get World answers taken in
        self._reading_world = False       # a Get World is queued or running
        self._read_again = False          # ... and something changed since it was asked

        self._build_panels(viewer if ros else None)
        self._lay_out()
        self._build_status_bar(world)
        self.resize(1100, 760)
        self._connect_and_start_timers()
        self.link = None
        if ros:
            self._link_ros(world, viewer)
        self.worker.start()
        self.path_worker.start()

    def _build_panels(self, viewer: Optional[str]) -> None:
        """The five tabs, the Viewer's image (``viewer``: its namespace, None without ROS), the
        joint plot and the message log."""
        self.tabs = QTabWidget()
        self.simulation = SimulationTab(self)
        self.settings = SettingsTab(self)
        self.objects = ObjectsTab(self)
        self.motion = MotionTab(self)
        self.joints = JointsTab(self)
        for tab, title in [(self.simulation, "Simulation"), (self.settings, "Settings"),
                           (self.objects, "Objects"), (self.motion, "Motion"),
                           (self.joints, "Joints")]:
            self.tabs.addTab(tab, title)
        self.viewer_panel = ViewerPanel(viewer=viewer, frame_points=self.scene.robot_points)
        self.viewer_panel.message.connect(self.show_error)
        self.plot = JointPlotPanel(label=lambda channel: channel_label(channel, self.scene))
        self.scene.changed.connect(
            lambda what: self.plot.relabel() if what in ("robots", "joints") else None)
        self.log = QPlainTextEdit()
        self.log.setReadOnly(True)
        self.log.setMaximumBlockCount(500)
        self.log.setPlaceholderText("Messages from the world appear here.")

    def _lay_out(self) -> None:
        """The tabs left of the image over the plot, the log below them all."""
        right = QSplitter(Qt.Vertical)
        right.addWidget(self.viewer_panel)
        right.addWidget(self.plot)
        right.setSizes([300, 260])
        top = QSplitter(Qt.Horizontal)
        top.addWidget(self.tabs)
        top.addWidget(right)
        top.setSizes([560, 460])
        outer = QSplitter(Qt.Vertical)
        outer.addWidget(top)
        outer.addWidget(self.log)
        outer.setSizes([640, 90])
        central = QWidget()
        layout = QVBoxLayout(central)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addWidget(outer)
        self.setCentralWidget(central)

    def _build_status_bar(self, world: str) -> None:
        """The busy and connection labels, waiting for the world at namespace ``world``."""
        self.busy_text = ""
        self.connection_text = ""
        self.connection_label = QLabel()
        self.busy_label = QLabel()
        self.statusBar().addPermanentWidget(self.busy_label)
        self.statusBar().addPermanentWidget(self.connection_label)
        self._show_connection(False, f"VirtualWorld absent: waiting for {world}")

    def _connect_and_start_timers(self) -> None:
        """The worker's connection state, the health check (every 0.25 s) and the idle Get
        World (every REFRESH_PERIOD s)."""
        self.worker.connection.connect(self._on_connection)
        self._health = QTimer(self)
        self._health.timeout.connect(self._check_health)
        self._health.start(250)
        self.scene.stale.connect(self.refresh_world)
        self._refresh = QTimer(self)
        self._refresh.timeout.connect(self._poll_world)
        self._refresh.start(int(REFRESH_PERIOD * 1000))

    def _link_ros(self, world: str, viewer: str) -> None:
        """The topics of the world at ``world`` and the Viewer at ``viewer``, into the scene,
        the plot and the image."""
        from gui.window.ros_link import RosLink
        self.link = RosLink(world, viewer, self)
        self.link.world_update.connect(self.on_world_update)
        self.link.joint_data.connect(self.scene.on_joint_data)
        self.link.joint_states.connect(self.plot.on_joint_states)
        self.link.image.connect(self.viewer_panel.on_image)

    # -- calls --------------------------------------------------------------------------------
    def call(self, label: str, fn: Callable, on_done: Optional[Callable] = None,
             on_error: Optional[Callable] = None, quiet: bool = False):
        """Runs ``fn(client, job)`` on the worker; ``on_done(result)`` in the GUI thread;
        a failure goes to ``on_error`` or to the log (``quiet``: not logged)."""
        def finished(result) -> None:
            self.refresh_world()
            if on_done is not None:
                on_done(result)

        def failed(message: str) -> None:
            self.refresh_world()        # a refusal half-way may have changed the world
            if on_error is not None:
                on_error(message)
            elif not quiet:
                self.show_error(message)

        return self.worker.submit(label, fn, finished, failed)

    # -- what the world holds -----------------------------------------------------------------
    def refresh_world(self) -> None:
        """Asks Get World (on the worker) and shows its answer: the object tree, lists and
        menus; one request at a time, and another after it when asked again meanwhile."""
        if not self.connected:
            return
        if self._reading_world:
            self._read_again = True
            return
        self._reading_world, self._read_again = True, False
        known_motors = set(self.scene.motors)
        typed_joints = {j for j, kind in self.scene.joints.items() if kind is not None}

        def read(client, job):
            inventory = client.world()
            motors = [m for m in inventory.motors if m not in known_motors]
            joints = [j for j in inventory.joints if j not in typed_joints]
            axes, types = {}, {}
            if motors or joints:    # a motor's axes and a joint's type are in Get State only
                state = client.call("get_state", motors=motors, joints=joints)
                axes = dict(zip(state.motors, (int(a) for a in state.motor_axes)))
                types = {j.id: int(j.type) for j in state.joints}
            return inventory, axes, types

        self.worker.submit(READ_WORLD, read, self._world_read, self._world_unread)

    def _world_read(self, answer) -> None:
        inventory, axes, types = answer
        self._reading_world = False
        self.world_reads += 1
        self.scene.on_inventory(inventory, axes, types)
        self.simulation.show_world(inventory)
        if self._read_again:
            self.refresh_world()

    def _world_unread(self, message: str) -> None:
        self._reading_world = False
        if self._read_again:
            self.refresh_world()

    def _poll_world(self) -> None:
        if self.worker.current is None and self.worker.pending() == 0:
            self.refresh_world()

    def show_error(self, message: str) -> None:
        text = " ".join(str(message).split())
        self.last_error = text
        self.errors.append(text)
        self.log.appendHtml(f'<span style="color:#b71c1c">{time.strftime("%H:%M:%S")} '
                            f'{_escape(text)}</span>')
        self.log.moveCursor(QTextCursor.End)
        self.statusBar().showMessage(text, 10000)

    def show_info(self, message: str) -> None:
        self.last_info = message
        self.log.appendHtml(f'{time.strftime("%H:%M:%S")} {_escape(message)}')
        self.statusBar().showMessage(message, 5000)

    # -- connection and health ----------------------------------------------------------------
    def _on_connection(self, connected: bool, text: str) -> None:
        was = self.connected
        self._show_connection(connected, text)
        if connected and not was:
            self.show_info(text)
            self.settings.refresh()
            self.refresh_world()
            if self._lost_world:
                self.simulation.offer_rebuild()
        elif was and not connected:
            self._lost_world = True
            self.show_error(text)
            self.simulation.set_simulating(False)
            self.scene.forget_world()

    def _show_connection(self, connected: bool, text: str) -> None:
        self.connected = connected
        self.connection_text = "World: connected" if connected else "World: absent (waiting)"
        color = "#2e7d32" if connected else "#b71c1c"
        self.connection_label.setText(self.connection_text)
        self.connection_label.setToolTip(text)
        self.connection_label.setStyleSheet(f"color: {color}; font-weight: bold;")

    def _check_health(self) -> None:
        job = self.worker.current
        now = time.monotonic()
        text = ""
        if job is not None and job.started and now - job.started > SLOW_AFTER:
            text = f"World slow: waiting for {job.label} ({now - job.started:.1f} s)"
        elif self.worker.pending() > 0 or (job is not None and job.label != READ_WORLD):
            text = f"busy: {job.label if job else ''} (+{self.worker.pending()} queued)"
        elif self.connected and self.updates and now - self.last_update_time > SILENT_AFTER:
            text = "World not publishing"
        self.busy_text = text
        self.busy_label.setText(text)
        self.busy_label.setStyleSheet("color: #e65100;" if text.startswith("World") else "")

    def on_world_update(self, msg) -> None:
        self.updates += 1
        self.last_update_time = time.monotonic()
        self.scene.on_world_update(msg)
        self.simulation.on_world_update(msg)

    # -- closing ------------------------------------------------------------------------------
    def shutdown(self) -> None:
        self._health.stop()
        if self.link is not None:
            self.link.close()
            self.link = None
        self.viewer_panel.close_link()
        self.path_worker.stop()
        self.worker.stop()

    def closeEvent(self, event) -> None:
        self.shutdown()
        super().closeEvent(event)


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
