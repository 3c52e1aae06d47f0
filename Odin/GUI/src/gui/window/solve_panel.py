"""The Motion tab's "Solve query" page: the opened problem's query solved with OMPL's geometric
planners over Odin's geometry (``gui.planning.geometric``), the path shown in the world, and
run there tracked.

For a problem without physics only (a physics problem is planned by ``rosrun GUI plan``
through the world's physics). The planner (OMPL's class names), the time limit (s) and the seed
start as the problem's (``GeometricSettings.of_problem``). Solve runs the search on a worker
of the panel's own (``gui.window.worker`` with no node: the search is this process's work,
never the GUI thread's nor the world's queue); Cancel ends it at the planner's next iteration.
A start or goal in collision is refused before the search, in the window's error line.

After a solved search: Show places the world's robots along the path by forward kinematics,
one Set Position of every link per frame (the path's straight segments of the control space,
what the search checked, cut into frames in proportion to their lengths, SHOW_SECONDS in all);
Run places the robots at the path's start (Set Position) and executes the path tracked, as a
Kautham task file run by "Tracked path..." is (``MotionTab.run_tracked``): the path as
``rosrun GUI plan`` writes it, interpolated as Kautham does (``geometric_output.kautham_path``),
each state a row of ``geometric.task_rows``; Save writes that task file.
Both run on the window's path worker, so Stop path ends them.
"""
from __future__ import annotations

import os
import pathlib
import time
from dataclasses import replace
from typing import List, NamedTuple, Optional

import numpy as np
from PyQt5.QtCore import Qt, QTimer
from PyQt5.QtWidgets import QComboBox, QFileDialog, QLabel, QPushButton, QSpinBox, QWidget

from gui.core.kautham.solutions import TASK, RowLayout, Solution
from gui.core.plan import BuildPlan
from gui.errors import GuiError
from gui.planning.geometric import (OMPL_PLANNERS, GeometricResult, GeometricSettings,
                                    query, task_rows, write_task)
from gui.window.fields import spin
from gui.window.forms import form_grid, growing, span
from gui.window.worker import Cancelled, WorldWorker
from odin_common.step_values import StepValues

SHOW_SECONDS = 3.0
"""s a Show takes, whatever the path: a geometric path has no timing of its own (Run times it
within the joints' limits)."""
MAX_SEED = 2 ** 31 - 1
"""The largest seed the field takes (Qt's spin box is 32-bit signed; OMPL takes any
positive 32-bit value)."""
TIME_RANGE = (0.01, 86400.0)
"""s: the time limits the field takes."""
_OMPL_SEEDED: List[bool] = []
"""Not empty once this process ran a search: OMPL takes a seed before its first one only."""


class Solved(NamedTuple):
    """A search's ``result`` for ``plan`` (the problem it searched) with ``settings``."""
    plan: BuildPlan
    settings: GeometricSettings
    result: GeometricResult

    def written(self) -> np.ndarray:
        """The path (n, k) as Kautham hands it on and ``rosrun GUI plan`` writes it:
        interpolated (gui.planning.geometric_output)."""
        from gui.planning.geometric_output import kautham_path
        return kautham_path(self.result.path, self.settings.planner, self.settings.range,
                            self.result.scales)

    def name(self) -> str:
        """How the path is named in the status lines and the task file."""
        seed = self.result.seed
        return self.settings.planner + (f" seed {seed}" if seed is not None else "")


def show_frames(path: np.ndarray, count: int) -> np.ndarray:
    """``path`` (n, k) in the control space cut into about ``count`` frames along its straight
    segments, each segment's share in proportion to its length; every state of the path is a
    frame (at least one frame per segment)."""
    from gui.planning.geometric_output import interpolate
    path = np.asarray(path, dtype=float)
    total = float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)))
    return interpolate(path, total / count) if total > 0 else path.copy()


def solution_of(plan: BuildPlan, path: np.ndarray, name: str) -> Solution:
    """``path``'s states as the Solution a task file of ``task_rows`` reads as
    (gui.core.kautham.solutions), its rows numbered from 1."""
    rows = task_rows(plan, path)
    waypoints = RowLayout.of(plan.problem).split(pathlib.Path(name), rows,
                                                 list(range(1, len(rows) + 1)))
    return Solution(name, TASK, waypoints)


def frame_situations(plan: BuildPlan, solution: Solution) -> List[list]:
    """Per waypoint of ``solution``: (body ID, position m, quaternion wxyz), world frame, of
    every link of its robots (forward kinematics: ``RobotHandle.situations``)."""
    frames: List[list] = [[] for _ in range(solution.waypoint_count)]
    for name, waypoints in solution.paths.items():
        handle = plan.robot(name)
        for k, joints in enumerate(waypoints.joints):
            base = None if waypoints.base_poses is None else waypoints.base_poses[k]
            frames[k] += handle.situations(joints, base)
    return frames


def _fresh_seed() -> int:
    return 1 + int.from_bytes(os.urandom(4), "little") % MAX_SEED


class SolvePanel(QWidget):
    """The page; ``tab``: the Motion tab (its path worker's runs), ``window``: the main
    window (its scene, messages and path worker)."""

    def __init__(self, window, tab, parent=None):
        super().__init__(parent)
        self.window, self.tab = window, tab
        self.plan: Optional[BuildPlan] = None
        self.solved: Optional[Solved] = None
        self.solving = False
        self._started = 0.0
        self._time_limit = 0.0
        self._settings = GeometricSettings()
        self._unsolvable = ""       # why the opened problem has nothing to solve
        self.solver = WorldWorker(name="planning", parent=self, node=None)
        self._build()
        self._clock = QTimer(self)
        self._clock.timeout.connect(self._tick)
        # the window stops its workers when it closes: the search's stops with them (a
        # running QThread must not outlive the window)
        window.path_worker.finished.connect(self.shutdown, Qt.DirectConnection)
        window.worker.busy.connect(self._world_busy)
        self.solver.start()
        self.set_plan(None)

    def _build(self) -> None:
        self.problem_label = QLabel()
        self.problem_label.setWordWrap(True)
        self.planner = QComboBox()
        self.planner.addItems(OMPL_PLANNERS)
        self.time_limit = spin(10.0, *TIME_RANGE, decimals=None, suffix="s",
                               tip="wall-clock seconds the search may take")
        self.seed = QSpinBox()
        self.seed.setRange(0, MAX_SEED)
        self.seed.setSpecialValueText("random")
        self.seed.setToolTip("OMPL's seed (random: one drawn, shown with the result); OMPL "
                             "takes it before the process's first search only")
        self.solve_button = QPushButton("Solve")
        self.cancel_button = QPushButton("Cancel")
        self.result_label = QLabel("No search yet.")
        self.result_label.setWordWrap(True)
        self.show_button = QPushButton("Show")
        self.show_button.setToolTip("the robots placed along the path in the world "
                                    f"({SHOW_SECONDS:g} s, Set Position)")
        self.run_button = QPushButton("Run")
        self.run_button.setToolTip("the path executed tracked by the joint servos, with "
                                   "contacts on (as Tracked path... runs a task file)")
        self.save_button = QPushButton("Save task file...")
        self.path_status = QLabel("No path running.")    # the Motion tab's path worker's
        self.path_status.setWordWrap(True)
        self.stop_button = QPushButton("Stop path")
        self.stop_button.setEnabled(False)
        form_grid([[span(self.problem_label, 3)],
                   ["Planner (OMPL)", span(self.planner, 2)],
                   ["Time limit", span(self.time_limit, 2)],
                   ["Seed", span(self.seed, 2)],
                   [None, self.solve_button, self.cancel_button],
                   [span(self.result_label, 3)],
                   [self.show_button, self.run_button, self.save_button],
                   [span(self.path_status, 2), self.stop_button],
                   growing()], self)
        self.solve_button.clicked.connect(self.solve)
        self.cancel_button.clicked.connect(self.cancel)
        self.show_button.clicked.connect(self.show_path)
        self.run_button.clicked.connect(self.run_path)
        self.save_button.clicked.connect(self.choose_task_file)
        self.stop_button.clicked.connect(lambda: self.tab.stop_path())

    # -- the problem ------------------------------------------------------------------------
    def set_plan(self, plan: Optional[BuildPlan]) -> None:
        """The problem opened in the window (None: none, or one with physics); the fields
        take its planner and time limit, any earlier path is forgotten."""
        if plan is self.plan and plan is not None:
            return
        self.plan, self.solved = plan, None
        self._settings = GeometricSettings()
        self._unsolvable = ""
        if plan is None:
            self.problem_label.setText("Open a problem without physics (one of Kautham's "
                                       "geometric planners) to solve its query here.")
        else:
            name = plan.problem.planner.name if plan.problem.planner else None
            try:
                self._settings = GeometricSettings.of_problem(plan)
                said = f"its planner {name} runs as OMPL's {self._settings.planner}" if name \
                    else "it names no planner"
            except GuiError as error:   # a planner Odin does not run: the user picks one
                said = str(error)
            try:
                query(plan)
            except GuiError as error:   # nothing to solve: said here, Solve disabled
                self._unsolvable = said = str(error)
            self.problem_label.setText(f"{pathlib.Path(plan.problem.source).name}: {said}.")
        self.planner.setCurrentText(self._settings.planner)
        self.time_limit.setValue(self._settings.time_limit)
        self.result_label.setText("No search yet.")
        self._enable()

    def _enable(self) -> None:
        ready = self.plan is not None and not self._unsolvable
        self.solve_button.setEnabled(ready and not self.solving)
        self.cancel_button.setEnabled(self.solving)
        self.seed.setEnabled(not _OMPL_SEEDED and not self.solving)
        path = self.solved is not None and self.solved.result.solved
        for button in (self.show_button, self.run_button, self.save_button):
            button.setEnabled(path)

    # -- the search ---------------------------------------------------------------------------
    def settings(self) -> GeometricSettings:
        """The problem's settings with the planner and time limit of the fields."""
        return replace(self._settings, planner=self.planner.currentText(),
                       time_limit=float(self.time_limit.value()))

    def solve(self) -> None:
        """Searches the query on the panel's worker with the fields' settings."""
        if self.plan is None or self.solving:
            return
        if self.window.simulation.building:
            self.window.show_error("Solve: a problem is being opened; solve once it is built")
            return
        plan, settings = self.plan, self.settings()
        seed = None
        if not _OMPL_SEEDED:
            seed = int(self.seed.value()) or _fresh_seed()
            _OMPL_SEEDED.append(True)

        def work(_client, job):
            from gui.planning.geometric import solve
            try:
                return solve(plan, settings, seed, stop=lambda: job.cancelled)
            except KeyboardInterrupt:       # solve's answer to stop(): the user's Cancel
                raise Cancelled("Solve: cancelled") from None

        self.solving, self._started = True, time.monotonic()
        self._time_limit = settings.time_limit
        self._clock.start(200)
        self._tick()
        self._enable()
        self.solver.submit("Solve", work, lambda r: self._solved(plan, settings, r),
                           self._failed, needs_world=False)

    def _tick(self) -> None:
        elapsed = time.monotonic() - self._started
        self.result_label.setText(f"Solving with {self.planner.currentText()}: "
                                  f"{elapsed:.1f}/{self._time_limit:g} s ...")

    def _finish(self) -> None:
        self.solving = False
        self._clock.stop()

    def _solved(self, plan: BuildPlan, settings: GeometricSettings,
                result: GeometricResult) -> None:
        self._finish()
        if plan is not self.plan:       # another problem was opened meanwhile
            self._enable()
            return
        self.solved = Solved(plan, settings, result)
        rate = f"{result.checks / result.time_s:,.0f}/s" if result.time_s > 0 else "-"
        seed = f"seed {result.seed}" if result.seed is not None else "OMPL seeded earlier"
        if result.solved:
            text = (f"Solved in {result.time_s:.2f} s ({result.planner}, {seed}): "
                    f"{result.states} states, length {result.length:.3f}, "
                    f"{result.checks:,} collision checks ({rate}).")
        else:
            text = (f"No solution within {settings.time_limit:g} s ({result.planner}, "
                    f"{seed}): {result.checks:,} collision checks ({rate}).")
        self.result_label.setText(text)
        self.window.show_info(f"Solve: {text[0].lower()}{text[1:]}")
        self._enable()

    def _failed(self, message: str) -> None:
        self._finish()
        self.result_label.setText(message)
        if message == "Solve: cancelled":
            self.window.show_info(message)
        else:
            self.window.show_error(f"Solve: {message}")
        self._enable()

    def cancel(self) -> None:
        self.solver.cancel()

    def _world_busy(self, label: str) -> None:
        """A problem opened while a search runs ends the search: the Simulation tab rehearses
        it in a Core of this process, and this process's ODE (built without its per-thread
        collision data, ODE_EXT_mt_collisions) must not collide in two threads at once; the
        search's path would be of the problem replaced anyway."""
        if self.solving and self.window.simulation.building:
            self.window.show_info(f"Solve: cancelled ({label}: another problem)")
            self.cancel()

    def shutdown(self) -> None:
        self._clock.stop()
        self.solver.stop()

    # -- the path in the world ----------------------------------------------------------------
    def _robots_here(self) -> bool:
        """The solved problem's robots are the world's, as this window built them."""
        plan = self.solved.plan if self.solved else None
        if plan is None or plan is not self.window.scene.plan or not self.window.scene.robots:
            self.window.show_error("Solve: open the problem in the world first (its robots "
                                   "are not there)")
            return False
        return True

    def show_path(self) -> None:
        """The robots placed along the path, SHOW_SECONDS in all, on the path worker."""
        if self.solved is None or not self._robots_here():
            return
        solved = self.solved
        rate = self.window.publication_rate or StepValues().rate
        frames = show_frames(solved.result.path, max(2, round(SHOW_SECONDS * rate)))

        def work(client, job):
            situations = frame_situations(solved.plan, solution_of(
                solved.plan, frames, solved.name()))
            start = time.monotonic()
            for k, frame in enumerate(situations, start=1):
                client.set_position(frame, reset_velocity=True)
                job.progress(k)
                if k < len(situations):
                    job.sleep(start + k / rate - time.monotonic())
            return len(situations)

        robots = ", ".join(i.name for i in solved.plan.problem.robots)
        self.tab.submit_path("show", solved.name(), robots, len(frames), work,
                             f" at {rate:g} Hz")

    def run_path(self) -> None:
        """The robots placed at the path's start, then its states run tracked
        (``MotionTab.run_tracked``): from wherever they are (the goal, after Show) the
        tracked run's own move to the start is a straight one, which the path exists to
        avoid."""
        if self.solved is None or not self._robots_here():
            return
        solved = self.solved
        try:
            solution = solution_of(solved.plan, solved.written(), solved.name())
            start = frame_situations(solved.plan, solution_of(
                solved.plan, solved.result.path[:1], solved.name()))[0]
        except GuiError as error:
            self.window.show_error(f"Run: {error}")
            return
        self.tab.run_tracked(solved.plan, solution, solved.name(),
                             ", ".join(solution.paths), place=start)

    def choose_task_file(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save the path as a Kautham task file", "",
                                              "Kautham task files (*.xml);;All files (*)")
        if path:
            self.save_task(path)

    def save_task(self, path: str) -> None:
        """The path written as a Kautham task file (``run_path --tracked`` runs it)."""
        if self.solved is None or not self.solved.result.solved:
            return
        solved = self.solved
        rows = task_rows(solved.plan, solved.written())
        try:
            write_task(path, solved.name(), rows)
        except OSError as error:
            self.window.show_error(f"Save task file: {path}: {error.strerror or error}")
            return
        self.window.show_info(f"Saved {len(rows)} configurations to {path} (a Kautham task "
                              "file)")
