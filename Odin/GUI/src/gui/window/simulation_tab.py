"""First tab (thesis 7.1): open a Kautham problem, New Scene, the tree of what was built and
the Simulate / Pause button.

Opening runs on the worker: the problem is read and planned (``gui.core.build.plan_problem``) and
sent step by step (``WorldClient.execute``); each answer adds the step's entries to the tree as
it comes, under its robot (Links, Joints, Motors) or under "Scene objects".

The button follows the world's real state: the Start answer, then the stamps of
``world_update`` (simulated time advancing = running), so a world started or paused by another
client shows up here too.
"""
from __future__ import annotations

import os
import pathlib
import time

from PyQt5.QtCore import Qt, pyqtSignal
from PyQt5.QtWidgets import (QCheckBox, QFileDialog, QHBoxLayout, QLabel, QPushButton,
                             QTreeWidget, QTreeWidgetItem, QVBoxLayout, QWidget)

from odin_common.specs import CompositeSpec

RUNNING_STYLE = "QPushButton { background: #2e7d32; color: white; font-weight: bold; }"
PAUSED_STYLE = "QPushButton { font-weight: bold; }"


class SimulationTab(QWidget):
    problem_built = pyqtSignal(str)     # problem path, once every request was answered

    def __init__(self, window, parent=None):
        super().__init__(parent)
        self.window = window
        self.simulating = False
        self._ignore_stamps_until = 0.0
        self._last_stamp = None
        self._same_stamps = 0
        self._advancing = 0
        self.building = False
        self.last_build_seconds = None

        self.tree = QTreeWidget()
        self.tree.setHeaderLabels(["Element", "World ID"])
        self.tree.setColumnWidth(0, 260)
        self.open_button = QPushButton("Open file")
        self.open_button.setToolTip("Read a Kautham problem (.xml) and build it in the world")
        self.replace_check = QCheckBox("New scene first")
        self.replace_check.setChecked(True)
        self.new_scene_button = QPushButton("New Scene!")
        self.simulate_button = QPushButton("Simulate!")
        self.simulate_button.setMinimumHeight(36)
        self.simulate_button.setStyleSheet(PAUSED_STYLE)
        self.status = QLabel("No problem loaded.")
        self.status.setWordWrap(True)

        row = QHBoxLayout()
        row.addWidget(self.open_button)
        row.addWidget(self.replace_check)
        row.addStretch(1)
        row.addWidget(self.new_scene_button)
        layout = QVBoxLayout(self)
        layout.addWidget(self.tree, 1)
        layout.addWidget(self.status)
        layout.addLayout(row)
        layout.addWidget(self.simulate_button)

        self.open_button.clicked.connect(self.choose_problem)
        self.new_scene_button.clicked.connect(self.new_scene)
        self.simulate_button.clicked.connect(self.toggle_simulation)
        self._groups: dict = {}

    # -- open ---------------------------------------------------------------------------------
    def choose_problem(self) -> None:
        start = os.environ.get("ODIN_KAUTHAM_DIR", str(pathlib.Path.home()))
        path, _ = QFileDialog.getOpenFileName(self, "Open a Kautham problem", start,
                                              "Kautham problems (*.xml);;All files (*)")
        if path:
            self.open_problem(path)

    def open_problem(self, path: str) -> None:
        """Reads, plans and builds ``path`` on the worker; the tree fills as answers come."""
        if self.building:
            self.window.show_error("Open file: a problem is still being built")
            return
        replace = self.replace_check.isChecked()
        self.building = True
        self.open_button.setEnabled(False)
        started = time.monotonic()
        self.status.setText(f"Reading {pathlib.Path(path).name} ...")

        def work(client, job):
            from gui.core.build import plan_problem
            from gui.core.kautham.problem import load_problem
            plan = plan_problem(load_problem(path))
            job.progress(("plan", plan))
            if replace:
                client.new_scene()
            total = len(plan.steps)
            return client.execute(plan, progress=lambda k, step, answer: job.progress(
                ("step", k, total, step, answer)))

        def progress(value):
            if value[0] == "plan":
                self._start_plan(value[1], replace)
            else:
                _, k, total, step, answer = value
                self._add_step(step, answer)
                self.status.setText(f"Building {pathlib.Path(path).name}: {k}/{total}")

        def done(ids):
            self.building = False
            self.open_button.setEnabled(True)
            self.last_build_seconds = time.monotonic() - started
            self.window.scene.plan = self._plan
            for handle in self._plan.robots:
                self.window.scene.add_robot(handle, self._plan.problem.format)
            for motor in ids["motors"].values():
                self.window.scene.add_motor(motor, 1)
            self.status.setText(f"Built {path} in {self.last_build_seconds:.2f} s: "
                                f"{len(ids['bodies'])} bodies, {len(ids['joints'])} joints, "
                                f"{len(ids['motors'])} motors.")
            self.tree.expandAll()
            self.window.show_info(f"Built {pathlib.Path(path).name} in "
                                  f"{self.last_build_seconds:.2f} s")
            self.problem_built.emit(path)

        def failed(message):
            self.building = False
            self.open_button.setEnabled(True)
            self.status.setText("Open file failed (see the message below).")
            self.window.show_error(message)

        self.window.worker.submit(f"Open {pathlib.Path(path).name}", work, done, failed,
                                  progress)

    def _start_plan(self, plan, replace: bool) -> None:
        self._plan = plan
        if replace:
            self._clear()
        self._roles = {inst.name: inst.role for inst in plan.problem.instances}
        for body in plan.bodies():
            if isinstance(body, CompositeSpec):
                self.window.scene.add_composite(body.id, [p.name for p in body.parts])

    def _group(self, *path: str) -> QTreeWidgetItem:
        key = tuple(path)
        item = self._groups.get(key)
        if item is None:
            parent = self._group(*path[:-1]) if len(path) > 1 else None
            item = QTreeWidgetItem([path[-1], ""])
            if parent is None:
                self.tree.addTopLevelItem(item)
            else:
                parent.addChild(item)
            item.setExpanded(len(path) == 1)
            self._groups[key] = item
        return item

    def _add_step(self, step, answer) -> None:
        """The tree items of one step the world answered (under its robot or obstacle, or
        under "Scene objects")."""
        owner = () if step.owner is None else \
            (f"{step.owner} ({self._roles.get(step.owner, 'robot')})",)
        for entry in step.entries(answer):
            self._group(*owner, entry.section).addChild(
                QTreeWidgetItem([entry.name, entry.world_id]))

    def add_built(self, group: str, name: str, world_id: str) -> None:
        """An element built from another tab ("Objects", "Joints", "Motors")."""
        self._group("Built here", group).addChild(QTreeWidgetItem([name, world_id]))
        self._group("Built here").setExpanded(True)

    def remove_built(self, world_id: str) -> None:
        for item in self.tree.findItems(world_id, Qt.MatchExactly | Qt.MatchRecursive, 1):
            parent = item.parent()
            if parent is not None:
                parent.removeChild(item)

    def element_count(self) -> int:
        """Leaves of the tree (built elements)."""
        count = 0
        stack = [self.tree.topLevelItem(i) for i in range(self.tree.topLevelItemCount())]
        while stack:
            item = stack.pop()
            if item.childCount() == 0 and item.text(1):
                count += 1
            stack.extend(item.child(i) for i in range(item.childCount()))
        return count

    def _clear(self) -> None:
        self.tree.clear()
        self._groups.clear()
        self.window.scene.clear()

    # -- new scene ----------------------------------------------------------------------------
    def new_scene(self) -> None:
        def done(_):
            self._ignore_stamps_until = time.monotonic() + 0.5
            self._clear()
            self.status.setText("New scene.")
            self.window.show_info("New Scene: the world is empty")

        self.window.call("New Scene", lambda client, job: client.new_scene(), done)

    # -- simulate / pause ---------------------------------------------------------------------
    def toggle_simulation(self) -> None:
        want = not self.simulating

        def done(simulating: bool):
            self._ignore_stamps_until = time.monotonic() + 0.5
            self.set_simulating(simulating)

        self.window.call("Simulate" if want else "Pause",
                         lambda client, job: client.start() if want else client.pause(), done)

    def set_simulating(self, simulating: bool) -> None:
        self.simulating = simulating
        if simulating:
            self.simulate_button.setText("Simulation running...  (click to pause)")
            self.simulate_button.setStyleSheet(RUNNING_STYLE)
        else:
            self.simulate_button.setText("Simulate!")
            self.simulate_button.setStyleSheet(PAUSED_STYLE)

    def on_world_update(self, msg) -> None:
        stamp = msg.header.stamp.to_sec()
        last, self._last_stamp = self._last_stamp, stamp
        if last is None or time.monotonic() < self._ignore_stamps_until:
            return
        if stamp != last:
            self._same_stamps = 0
            self._advancing += 1
            if not self.simulating and self._advancing >= 2:
                self.set_simulating(True)
        else:
            self._advancing = 0
            self._same_stamps += 1
            if self.simulating and self._same_stamps >= 2:
                self.set_simulating(False)
