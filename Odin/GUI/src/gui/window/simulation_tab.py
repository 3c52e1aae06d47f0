"""First tab (thesis 7.1): open a Kautham problem, New Scene, the tree of what was built and
the Simulate / Pause button.

The tree shows what the world holds, whoever built it (Get World, ``show_world``): each robot
declared with Set Robot with its Links (the robot's link names), Joints and Motors (the robot's
own joint names), then the Scene objects (under the Kautham instance that made them when this
window built them), the Joints and Motors of no robot, and the Forces.

Opening runs on the worker: the problem is read and planned
(``gui.core.translate.plan_problem``), rehearsed whole in a Core of this process and only then
sent step by step (``gui.planning.rehearsal.load_scene``: all or nothing, a problem the world
would refuse midway leaves the scene as it was); while it is built each answer adds the step's
entries to the tree as it comes; once built, the world's answer replaces them.

The button follows the world's real state: the Start answer, then the stamps of
``world_update`` (simulated time advancing = running), so a world started or paused by another
client shows up here too.
"""
from __future__ import annotations

import os
import pathlib
import time
from typing import Optional

from PyQt5.QtCore import pyqtSignal
from PyQt5.QtWidgets import (QCheckBox, QFileDialog, QHBoxLayout, QLabel, QPushButton,
                             QTreeWidget, QTreeWidgetItem, QVBoxLayout, QWidget)

from gui.core.plan import SCENE_OBJECTS
from odin_common.interface import motor_joint
from odin_common.limits import MIN_STEP

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
        self.last_problem: Optional[str] = None      # the last problem built, to offer again

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
        self.rebuild_button = QPushButton()
        self.rebuild_button.setToolTip("The world restarted empty: build the last problem again")
        self.rebuild_button.setStyleSheet("QPushButton { color: #b71c1c; font-weight: bold; }")
        self.rebuild_button.hide()

        row = QHBoxLayout()
        row.addWidget(self.open_button)
        row.addWidget(self.replace_check)
        row.addStretch(1)
        row.addWidget(self.new_scene_button)
        layout = QVBoxLayout(self)
        layout.addWidget(self.tree, 1)
        layout.addWidget(self.status)
        layout.addWidget(self.rebuild_button)
        layout.addLayout(row)
        layout.addWidget(self.simulate_button)

        self.open_button.clicked.connect(self.choose_problem)
        self.new_scene_button.clicked.connect(self.new_scene)
        self.simulate_button.clicked.connect(self.toggle_simulation)
        self.rebuild_button.clicked.connect(self.rebuild)
        self.problem_built.connect(self._remember)
        self._groups: dict = {}
        self._roles: dict = {}
        self._owners: dict = {}     # world ID -> the Kautham instance it was built for here
        self._shown = None          # the inventory the tree shows

    # -- a world that came back -------------------------------------------------------------
    def _remember(self, path: str) -> None:
        self.last_problem = path
        self.rebuild_button.hide()

    def offer_rebuild(self) -> None:
        """After the world was lost and came back (empty: a new node): offer the last problem
        built, never rebuild unasked (the user may want the empty world)."""
        if self.last_problem is None:
            return
        name = pathlib.Path(self.last_problem).name
        self.rebuild_button.setText(f"Rebuild {name} in the new world")
        self.rebuild_button.show()
        self.status.setText(f"The world restarted empty; {name} can be built again.")
        self.window.show_info(f"The world restarted: 'Rebuild {name}' builds it again")

    def rebuild(self) -> None:
        if self.last_problem is not None:
            self.rebuild_button.hide()
            self.open_problem(self.last_problem)

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
            from gui.core.translate import plan_problem
            from gui.core.kautham.problem import load_problem
            from gui.planning.rehearsal import load_scene
            plan = plan_problem(load_problem(path))
            total = len(plan.steps)

            def step_done(k: int, step, answer: str) -> None:
                if k == 1:      # the plan was rehearsed whole: the tree changes from here
                    job.progress(("plan", plan))
                job.progress(("step", k, total, step, answer))
            return load_scene(client, plan, keep=not replace, progress=step_done)

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
            self.window.refresh_world()
            self.status.setText(f"Built {path} in {self.last_build_seconds:.2f} s: "
                                f"{len(ids['bodies'])} bodies, {len(ids['joints'])} joints, "
                                f"{len(ids['motors'])} motors.")
            self.tree.expandAll()
            self.window.show_info(f"Built {pathlib.Path(path).name} in "
                                  f"{self.last_build_seconds:.2f} s")
            if ids["overlaps"]:
                from gui.core.overlaps import overlap_warning
                self.window.show_info(overlap_warning(pathlib.Path(path).name, ids["overlaps"],
                                                      ids["overlaps_exempt"]))
            self.problem_built.emit(path)

        def failed(message):
            self.building = False
            self.open_button.setEnabled(True)
            self.window.refresh_world()
            self.status.setText("Open file failed (see the message below).")
            self.window.show_error(message)

        self.window.worker.submit(f"Open {pathlib.Path(path).name}", work, done, failed,
                                  progress)

    def _start_plan(self, plan, replace: bool) -> None:
        self._plan = plan
        if replace:
            self._clear()
        self._roles.update({inst.name: inst.role for inst in plan.problem.instances})

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

    def _owner_label(self, owner: str) -> str:
        return f"{owner} ({self._roles.get(owner, 'robot')})"

    def _add_step(self, step, answer) -> None:
        """The tree items of one step the world answered (under its robot or obstacle, or
        under "Scene objects"), shown while a problem is being built."""
        owner = () if step.owner is None else (self._owner_label(step.owner),)
        for entry in step.entries(answer):
            self._group(*owner, entry.section).addChild(
                QTreeWidgetItem([entry.name, entry.world_id]))
            if step.owner is not None:
                self._owners[entry.world_id] = step.owner

    # -- what the world holds -----------------------------------------------------------------
    def show_world(self, inventory) -> None:
        """Shows Get World's answer in the tree (kept as it is while a problem is being built,
        and when nothing changed, so expansion and selection stay)."""
        if self.building:
            return
        if not self.window.scene.objects and not inventory.objects:
            self._owners.clear()
        shown = (inventory.objects, inventory.joints, inventory.motors, inventory.robots,
                 inventory.body_forces, inventory.joint_forces)
        if shown == self._shown:
            return
        self._shown = shown
        expanded = {key for key, item in self._groups.items() if item.isExpanded()}
        self.tree.clear()
        self._groups.clear()
        robot_joints = {}
        in_robots = set()
        for robot in inventory.robots:
            label = self._owner_label(robot.name)
            for link, object_id in zip(robot.links, robot.objects):
                self._leaf((label, "Links"), link, object_id)
                in_robots.add(object_id)
            for name, joint_id in zip(robot.joint_names, robot.joints):
                self._leaf((label, "Joints"), name, joint_id)
                robot_joints[joint_id] = (label, name)
        for object_id in inventory.objects:
            if object_id not in in_robots:
                owner = self._owners.get(object_id)
                group = (self._owner_label(owner), "Links") if owner else (SCENE_OBJECTS,)
                self._leaf(group, object_id, object_id)
        for joint_id in inventory.joints:
            if joint_id not in robot_joints:
                self._leaf(("Joints",), joint_id, joint_id)
        for motor_id in inventory.motors:
            owner = robot_joints.get(motor_joint(motor_id))
            if owner:
                self._leaf((owner[0], "Motors"), owner[1], motor_id)
            else:
                self._leaf(("Motors",), motor_id, motor_id)
        for force_id in inventory.body_forces + inventory.joint_forces:
            self._leaf(("Forces",), force_id, force_id)
        for key, item in self._groups.items():
            item.setExpanded(key in expanded or len(key) == 1)
        if not self.window.scene.robots:
            self.status.setText(_summary(inventory))

    def _leaf(self, group: tuple, name: str, world_id: str) -> None:
        self._group(*group).addChild(QTreeWidgetItem([name, world_id]))

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
        self._owners.clear()
        self._shown = None

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
        # a step moves the stamp by at least MIN_STEP; a change while paused (a build, Set
        # Position) moves it by a nanosecond only (the world clock, docs/ROS.md)
        if stamp - last >= MIN_STEP:
            self._same_stamps = 0
            self._advancing += 1
            if not self.simulating and self._advancing >= 2:
                self.set_simulating(True)
        else:
            self._advancing = 0
            self._same_stamps += 1
            if self.simulating and self._same_stamps >= 2:
                self.set_simulating(False)


def _summary(inventory) -> str:
    """One line on what the world holds (the status of a window that built none of it)."""
    if not inventory.objects:
        return "The world is empty: open a problem, or build from the other tabs."
    robots = ", ".join(r.name for r in inventory.robots)
    return (f"The world holds {len(inventory.objects)} objects, {len(inventory.joints)} "
            f"joints and {len(inventory.motors)} motors" +
            (f"; robots: {robots}." if robots else "."))
