"""Fourth tab (thesis 7.4): a tool box to move objects, joints, motors and robots.

Move object: a force (at the centre of mass or at a point), a torque, or a linear / angular
velocity; vectors and points in the world or the body frame. Forces and torques persist until
deleted: their IDs (the world's answers) are listed for deletion. Velocities act once.
Move joint: a force / torque per joint axis (as many magnitudes as the joint type takes), with
the list of joint forces. Move motor: goal speeds. Move robot: initial position, velocity
path and position path files (``gui.core.paths``), optionally refined by double path precision
(a position path is refused, as run_path refuses it, where a row jumps or its first row is far
from where the robot is, unless "Allow jumps" is ticked: ``JUMP_OPTIONS``), and control paths
(rows of the robot's Kautham controls in [0, 1] with a duration, applied as Kautham's ODE
environment does: ``gui.core.control_path``, docs/INTERFACE.md), and tracked
paths (a Kautham plan: .kps solution, task file, OMPL or raw rows, timed within the joints'
limits and followed by the joint servos under full physics, ``gui.core.execution``; its
target against actual per joint is plotted below); a path runs on a worker of its own (Stop
ends it) so the other tabs stay usable meanwhile. Solve query (shown while a problem without
physics is open): its query solved with OMPL's geometric planners, the path shown and run
(``gui.window.solve_panel``).
"""
from __future__ import annotations

import pathlib
from typing import Optional

from PyQt5.QtWidgets import (QCheckBox, QComboBox, QFileDialog, QLabel, QListWidget,
                             QPushButton, QToolBox, QVBoxLayout, QWidget)

from gui.core.paths import MAX_ROW_JUMP, MAX_ROW_SLIDE, JumpOptions
from gui.errors import GuiError
from gui.window.fields import ChoiceButtons, VectorRow, int_spin
from gui.window.forms import form_grid, growing, span
from gui.window.scene import JOINT_TYPE_NAMES
from gui.window.solve_panel import SolvePanel
from gui.window.tracking_plot import TrackingPlot
from odin_common.interface import JOINT_FORCE_MAGNITUDES, ForceKind
from odin_common.step_values import StepValues

ACTIONS = ["force", "torque", "angular velocity", "linear velocity"]
#: the actions that add a persistent force (by their index in ACTIONS)
FORCE_ACTIONS = {0: ForceKind.FORCE, 1: ForceKind.TORQUE}
ANGULAR_VELOCITY = 2
SOLVE_TITLE = "Solve query"
UNITS = ["degrees (mm)", "radians (m)"]
"""The Move robot page's units in files (the index: 0 degrees, 1 radians)."""
ALLOW_JUMPS = "Allow jumps"
JUMP_OPTIONS = JumpOptions(degrees=f'Units in files "{UNITS[0]}"',
                           radians=f'Units in files "{UNITS[1]}"', allow=f'"{ALLOW_JUMPS}"')
"""The page's controls a refused jump names (run_path's --degrees, --radians, --allow-jumps)."""


class MotionTab(QWidget):
    def __init__(self, window, parent=None):
        super().__init__(parent)
        self.window = window
        self.toolbox = QToolBox()
        for page, title in [(self._object_page(), "Move object"),
                            (self._joint_page(), "Move joint"),
                            (self._motor_page(), "Move motor"),
                            (self._robot_page(), "Move robot")]:
            self.toolbox.addItem(page, title)
        self.solve = SolvePanel(window, self)       # a page while a geometric problem is open
        self.solve.hide()
        layout = QVBoxLayout(self)
        layout.addWidget(self.toolbox)
        self._connect(window)
        self._action_changed()
        self._joint_changed()

    def _object_page(self) -> QWidget:
        """Move object: a force, torque or velocity (at a point), and the forces in force."""
        page = QWidget()
        self.object = QComboBox()
        actions = ChoiceButtons(ACTIONS)          # index = action
        self.action_group, self.action_buttons = actions.group, actions.buttons
        self.vector = VectorRow("xyz", (0.0, 0.0, 10.0), -1e6, 1e6, 3, 1.0)
        self.vector_relative = QCheckBox("relative (body frame)")
        self.at_point = QCheckBox("at point")
        self.point = VectorRow("xyz", (0.0, 0.0, 0.0), -1e4, 1e4, 3, 0.1, "m")
        self.point_relative = QCheckBox("relative (body frame)")
        self.move_button = QPushButton("Move")
        self.forces = QListWidget()
        self.delete_force_button = QPushButton("Delete")
        form_grid([["Object", span(self.object, 2)],
                   [span(actions, 3)],
                   ["Intensity", self.vector, self.vector_relative],
                   [self.at_point, self.point, self.point_relative],
                   [None, None, self.move_button],
                   [span(self.forces, 2), self.delete_force_button]], page)
        return page

    def _joint_page(self) -> QWidget:
        """Move joint: a force or torque per axis, and the joint forces in force."""
        page = QWidget()
        self.joint = QComboBox()
        self.magnitudes = VectorRow(["1", "2", "3"], (1.0, 0.0, 0.0), -1e6, 1e6, 3, 0.5)
        self.joint_force_button = QPushButton("Add force")
        self.joint_forces = QListWidget()
        self.delete_joint_force_button = QPushButton("Delete")
        form_grid([["Joint", span(self.joint, 2)],
                   ["Magnitudes per axis\n(N m rotations, N translations)", self.magnitudes,
                    self.joint_force_button],
                   ["Forces and torques"],
                   [span(self.joint_forces, 2), self.delete_joint_force_button]], page)
        return page

    def _motor_page(self) -> QWidget:
        """Move motor: goal speeds per axis."""
        page = QWidget()
        self.motor = QComboBox()
        self.motor_speeds = VectorRow(["1", "2", "3"], (0.5, 0.0, 0.0), -1e3, 1e3, 3, 0.1)
        self.motor_button = QPushButton("Set velocity")
        form_grid([["Motor", span(self.motor, 2)],
                   ["Goal speed per axis\n(rad/s or m/s)", self.motor_speeds, self.motor_button],
                   growing()], page)
        return page

    def _robot_page(self) -> QWidget:
        """Move robot: the path files, Stop, and the tracked path's plot."""
        page = QWidget()
        self.robot = QComboBox()
        self.units = QComboBox()
        self.units.addItems(UNITS)
        self.initial_button = QPushButton("Set initial position...")
        self.velocity_button = QPushButton("Velocity path...")
        self.position_button = QPushButton("Position path...")
        self.controls_button = QPushButton("Control path...")
        self.controls_button.setToolTip("rows of the robot's controls in [0, 1] and a duration "
                                        "(s), applied as Kautham's ODE environment does")
        self.tracked_button = QPushButton("Tracked path...")
        self.tracked_button.setToolTip("a Kautham plan (.kps, task file, OMPL or raw rows) "
                                       "followed by the joint servos with contacts on")
        self.tracking_plot = TrackingPlot()
        self.double = int_spin(0, 0, 6, "times the path precision is doubled (2^n finer)")
        self.allow_jumps = QCheckBox(ALLOW_JUMPS)
        self.allow_jumps.setToolTip(
            f"position paths: run rows that move a revolute joint more than {MAX_ROW_JUMP:g} "
            f"rad or a prismatic one more than {MAX_ROW_SLIDE:g} m from the row before, or the "
            "first row from where the robot is (refused otherwise: a path read in the wrong "
            "unit, said)")
        self.stop_button = QPushButton("Stop path")
        self.stop_button.setEnabled(False)
        self.path_status = QLabel("No path running.")
        form_grid([["Robot", span(self.robot, 2)],
                   ["Units in files", self.units],
                   [None, self.initial_button],
                   [self.velocity_button, self.position_button, self.controls_button],
                   ["Double path precision (times)", self.double, self.allow_jumps],
                   [self.tracked_button, self.stop_button],
                   [span(self.path_status, 3)],
                   growing(span(self.tracking_plot, 3))], page)
        return page

    def _connect(self, window) -> None:
        """The widgets to this tab's actions, the scene's changes (of ``window``) to its lists."""
        self.action_group.buttonClicked.connect(lambda _b: self._action_changed())
        self.at_point.toggled.connect(lambda _b: self._action_changed())
        self.move_button.clicked.connect(self.move_object)
        self.delete_force_button.clicked.connect(self.delete_force)
        self.joint.currentIndexChanged.connect(lambda _i: self._joint_changed())
        self.joint_force_button.clicked.connect(self.add_joint_force)
        self.delete_joint_force_button.clicked.connect(self.delete_joint_force)
        self.motor.currentIndexChanged.connect(lambda _i: self._motor_changed())
        self.motor_button.clicked.connect(self.set_motor_velocity)
        self.initial_button.clicked.connect(lambda: self.choose_path("initial"))
        self.velocity_button.clicked.connect(lambda: self.choose_path("velocity"))
        self.position_button.clicked.connect(lambda: self.choose_path("position"))
        self.controls_button.clicked.connect(lambda: self.choose_path("control"))
        self.tracked_button.clicked.connect(lambda: self.choose_path("tracked"))
        self.stop_button.clicked.connect(self.stop_path)
        window.scene.changed.connect(self._scene_changed)

    # -- lists ----------------------------------------------------------------------------
    @staticmethod
    def _refill(combo: QComboBox, items) -> None:
        """``items``: IDs, or (label, ID) pairs; ``currentData()`` is the chosen ID."""
        pairs = [i if isinstance(i, tuple) else (i, i) for i in items]
        current = combo.currentData()
        combo.blockSignals(True)
        combo.clear()
        for label, item_id in pairs:
            combo.addItem(label, item_id)
            if item_id == current:
                combo.setCurrentIndex(combo.count() - 1)
        combo.blockSignals(False)

    def _scene_changed(self, what: str) -> None:
        scene = self.window.scene
        if what == "objects":
            self._refill(self.object, scene.objects)
        if what in ("joints", "robots"):    # a robot's joints and motors by its names
            self._refill(self.joint, scene.grouped(scene.joints, scene.joint_label))
            self._joint_changed()
        if what in ("motors", "robots"):
            self._refill(self.motor, scene.grouped(scene.motors, scene.motor_label))
            self._motor_changed()
        if what == "forces":
            self.forces.clear()
            self.forces.addItems(scene.forces)
            self.joint_forces.clear()
            self.joint_forces.addItems(scene.joint_forces)
        elif what == "robots":
            self._refill(self.robot, list(scene.robots))
            if scene.problem_format is not None:
                self.units.setCurrentIndex(0 if scene.problem_format == "2012" else 1)
            self._show_solve(scene.plan)

    def _show_solve(self, plan) -> None:
        """The Solve query page for ``plan`` when it has no physics, else no such page (a
        physics problem is planned by ``rosrun GUI plan``)."""
        geometric = plan if plan is not None and not plan.physics else None
        self.solve.set_plan(geometric)
        index = self.toolbox.indexOf(self.solve)
        if geometric is not None and index < 0:
            self.toolbox.addItem(self.solve, SOLVE_TITLE)
        elif geometric is None and index >= 0:
            self.toolbox.removeItem(index)
            self.solve.hide()

    def _action_changed(self) -> None:
        action = self.action_group.checkedId()
        force = action == 0
        self.vector_relative.setEnabled(action in (0, 1))
        self.at_point.setEnabled(force)
        self.point.setEnabled(force and self.at_point.isChecked())
        self.point_relative.setEnabled(force and self.at_point.isChecked())
        self.move_button.setText("Add force" if action == 0 else "Add torque" if action == 1
                                 else "Set velocity")

    def _joint_changed(self) -> None:
        joint_type = self.window.scene.joints.get(self.joint.currentData())
        magnitudes = JOINT_FORCE_MAGNITUDES.get(joint_type, ())
        count = len(magnitudes) if joint_type is not None else 3
        for k, box in enumerate(self.magnitudes.boxes):
            box.setEnabled(k < count)
        self.joint_force_button.setEnabled(count > 0)
        if joint_type is not None:
            self.joint_force_button.setToolTip(
                f"{JOINT_TYPE_NAMES.get(joint_type, joint_type)}: {count} magnitude(s)"
                + (f" ({', '.join(magnitudes)})" if magnitudes else ""))

    def _motor_changed(self) -> None:
        axes = self.window.scene.motors.get(self.motor.currentData(), 1)
        for k, box in enumerate(self.motor_speeds.boxes):
            box.setEnabled(k < axes)

    # -- objects --------------------------------------------------------------------------
    def move_object(self) -> None:
        object_id = self.object.currentData()
        if not object_id:
            self.window.show_error("Move object: choose an object (build one first)")
            return
        action = self.action_group.checkedId()
        vector = self.vector.values()
        if action in FORCE_ACTIONS:
            kind = FORCE_ACTIONS[action]
            options = dict(vector_in_body_frame=self.vector_relative.isChecked(),
                           at_point=kind == ForceKind.FORCE and self.at_point.isChecked(),
                           point=self.point.values(),
                           point_in_body_frame=self.point_relative.isChecked())

            def done(force_id):
                self.window.scene.add_force(force_id)
                self.window.show_info(f"Added {force_id}")

            self.window.call("Set External Force", lambda client, job: client.add_body_force(
                object_id, kind, vector, **options), done)
        else:
            velocity = dict(angular=vector) if action == ANGULAR_VELOCITY else \
                dict(linear=vector)
            self.window.call("Set Velocity", lambda client, job: client.set_body_velocity(
                object_id, **velocity),
                lambda _: self.window.show_info(f"Velocity of {object_id} set"))

    def delete_force(self) -> None:
        self._delete_selected(self.forces, lambda client, force_id:
                              client.remove_body_force(force_id), "Remove External Force",
                              "a force or torque")

    def _delete_selected(self, listing, remove, label: str, what: str) -> None:
        """Removes the force (on an object or a joint) chosen in ``listing`` with
        ``remove(client, force_id)``."""
        item = listing.currentItem()
        if item is None:
            self.window.show_error(f"Delete: select {what} in the list")
            return
        force_id = item.text()
        self.window.call(label, lambda client, job: remove(client, force_id),
                         lambda _: self.window.scene.remove_force(force_id))

    # -- joints ---------------------------------------------------------------------------
    def add_joint_force(self) -> None:
        joint_id = self.joint.currentData()
        if not joint_id:
            self.window.show_error("Move joint: choose a joint (build one first)")
            return
        joint_type = self.window.scene.joints.get(joint_id)
        # a type that takes none (fixed) or not reported yet: one, for the world to judge
        count = len(JOINT_FORCE_MAGNITUDES.get(joint_type, ())) or 1
        magnitudes = self.magnitudes.values()[:count]

        def done(force_id):
            self.window.scene.add_joint_force(force_id)
            self.window.show_info(f"Added {force_id}")

        self.window.call("Set Joint Force", lambda client, job: client.add_joint_force(
            joint_id, magnitudes), done)

    def delete_joint_force(self) -> None:
        self._delete_selected(self.joint_forces, lambda client, force_id:
                              client.remove_joint_force(force_id), "Remove Joint Force",
                              "a joint force")

    # -- motors ---------------------------------------------------------------------------
    def set_motor_velocity(self) -> None:
        motor_id = self.motor.currentData()
        if not motor_id:
            self.window.show_error("Move motor: choose a motor (load a robot or add one in "
                                   "the Joints tab)")
            return
        axes = self.window.scene.motors.get(motor_id, 1)
        speeds = list(self.motor_speeds.values()[:axes])
        self.window.call("Set Velocity", lambda client, job: client.set_velocities(
            [motor_id], speeds), lambda _: self.window.show_info(f"{motor_id}: goal {speeds}"))

    # -- robots ---------------------------------------------------------------------------
    def choose_path(self, kind: str) -> None:
        path, _ = QFileDialog.getOpenFileName(self, f"{kind.capitalize()} file", "",
                                              "Path files (*.txt *.path *.xml);;All files (*)")
        if path:
            self.run_path(kind, path)

    def run_path(self, kind: str, path: str) -> None:
        """``kind``: "initial", "velocity", "position", "control" or "tracked"; runs on the
        path worker."""
        from gui.core.paths import DEGREES, RADIANS, check_row_jumps, read_robot_paths, refine
        handle = self.window.scene.robots.get(self.robot.currentData())
        if handle is None:
            self.window.show_error("Move robot: open a problem with a robot first")
            return
        if kind == "control":
            self.run_control_path(handle, path)
            return
        units = DEGREES if self.units.currentIndex() == 0 else RADIANS
        if kind == "tracked":
            self.run_tracked_path(handle, path, units)
            return
        # read as run_path reads it: a file of every robot's values drives them all, one of
        # a robot's the chosen one; a base the rows do not carry stays where it is. Jumps as
        # run_path checks them: between rows here, the first row on the worker
        robots = {h.name: h for h in self.window.scene.robots.values()
                  if h.instance.role == "robot"}
        check_jumps = kind == "position" and not self.allow_jumps.isChecked()
        try:
            paths = read_robot_paths(path, list(robots.values()), units, handle.name)
            if check_jumps:
                for read in paths:
                    check_row_jumps(read, JUMP_OPTIONS)
        except Exception as error:  # a bad file is the user's: say what and where
            self.window.show_error(f"Move robot: {error}")
            return
        names = ", ".join(read.robot for read in paths)
        double = int(self.double.value()) if kind == "position" else 0

        def sent(client):
            from gui.ros.client import rows_to_send
            return rows_to_send(client, paths, robots, double,
                                JUMP_OPTIONS if check_jumps else None)

        if kind == "initial":
            self.window.call("Initial position", lambda client, job: client.set_position(
                [s for robot in sent(client) for s in robot.situations(0)],
                reset_velocity=True),
                lambda _: self.window.show_info(f"{names}: initial position set"))
            return
        rate = self.window.publication_rate or StepValues().rate
        total = len(refine(paths[0].rows, double))

        def work(client, job):
            from gui.ros.client import run_position_rows, run_velocity_rows, stop_velocity_rows
            from gui.window.worker import Cancelled
            rows = sent(client)
            runner = run_position_rows if kind == "position" else run_velocity_rows
            try:
                runner(client, rows, rate, progress=job.progress, sleep=job.sleep)
            except Cancelled:
                if kind == "velocity":   # leave the robots still, as a finished path does
                    stop_velocity_rows(client, rows)
                raise
            return total

        self.submit_path(f"{kind} path", pathlib.Path(path).name, names, total, work,
                         f" at {rate:g} Hz")

    def run_control_path(self, handle, path: str) -> None:
        """The control path file ``path`` for ``handle``'s robot, in real time on the path
        worker (the world paused meanwhile, running again afterwards if it was)."""
        from gui.core.control_path import control_size, read_control_path
        try:
            rows = read_control_path(path, control_size(handle))
        except GuiError as error:  # a bad file is the user's: say what and where
            self.window.show_error(f"Move robot: {error}")
            return

        def work(client, job):
            from gui.ros.world_port import run_on_client
            run_on_client(client, handle, rows, progress=lambda r: job.progress(r.index),
                          sleep=job.sleep)
            return len(rows)

        self.submit_path("control path", pathlib.Path(path).name, handle.name, len(rows),
                         work)

    def run_tracked_path(self, handle, path: str, units: str) -> None:
        """The plan in ``path`` (raw rows drive ``handle``'s robot, in ``units``), read and
        checked whole here, then run tracked (``run_tracked``)."""
        from gui.core.kautham.solutions import read_solution
        plan = self.window.scene.plan
        if plan is None:
            self.window.show_error("Move robot: a tracked path needs the problem opened here")
            return
        try:
            solution = read_solution(path, plan.problem, handle.name, units)
        except GuiError as error:  # a bad file is the user's: say what and where
            self.window.show_error(f"Move robot: {error}")
            return
        self.run_tracked(plan, solution, pathlib.Path(path).name, handle.name)

    def run_tracked(self, plan, solution, name: str, robots: str,
                    place: Optional[list] = None) -> None:
        """``solution`` (gui.core.kautham.solutions) of ``plan``'s robots (``robots``: how the
        log names them), called ``name``, executed in real time on the path worker (the world
        paused meanwhile, running again afterwards if it was); ``place``: situations (body ID,
        position, quaternion wxyz) the links are set to first (Set Position); a robot away
        from the path's start is moved there first, which the status line says; the report
        is plotted."""
        def work(client, job):
            from gui.ros.world_port import run_tracked_on_client
            from gui.window.worker import Cancelled
            if place is not None:
                client.set_position(place, reset_velocity=True)

            def progress(t: float, total: float) -> None:
                if job.cancelled:
                    raise Cancelled()
                job.progress((t, total))
            return run_tracked_on_client(client, plan, solution, progress=progress,
                                         real_time=True, from_here=True)

        def progress(value):
            t, total = value
            self._path_state(f"tracked path {name}: {t:.2f}/{total:.2f} s")

        def finished(report):
            self.tracking_plot.show_report(report)
            text = (f"tracked path {name}{report.start_move()}: goal error "
                    f"{report.goal_error:.3g}, tracking error "
                    f"max {report.tracking_error_max:.3g}, {report.duration_s:.2f} s, "
                    f"{report.contacts}")
            self._path_state(text, False)
            self.window.show_info(f"{robots}: {text}")

        def failed(message):
            self._path_state(f"tracked path {name}: {message}", False)
            self.window.show_error(message)

        placed = "placed at its start, " if place is not None else ""
        self._path_state(f"tracked path {name}: starting ({placed}{solution.format}, "
                         f"{solution.waypoint_count} waypoints)", True)
        self.window.path_worker.submit("tracked path", work, finished, failed, progress)

    def submit_path(self, label: str, name: str, robot: str, total: int, work,
                    pace: str = "") -> None:
        """Runs ``work`` on the path worker, its progress (rows done) in the status line."""
        def progress(k):
            self._path_state(f"{label} {name}: row {k}/{total}{pace}")

        def finished(_):
            self._path_state(f"{label} {name}: {total} rows done", False)
            self.window.show_info(f"{robot}: {label} done ({total} rows)")

        def failed(message):
            self._path_state(f"{label} {name}: {message}", False)
            self.window.show_error(message)

        self._path_state(f"{label} {name}: starting ({total} rows)", True)
        self.window.path_worker.submit(label, work, finished, failed, progress)

    def _path_state(self, text: str, running: Optional[bool] = None) -> None:
        """The path worker's state in the Move robot page's status line and Stop button, and
        in the Solve query page's (its paths run there too); ``running`` None: unchanged."""
        for label, button in ((self.path_status, self.stop_button),
                              (self.solve.path_status, self.solve.stop_button)):
            label.setText(text)
            if running is not None:
                button.setEnabled(running)

    def stop_path(self) -> None:
        self.window.path_worker.cancel()
