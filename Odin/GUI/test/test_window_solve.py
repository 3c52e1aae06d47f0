"""The Motion tab's Solve query page (gui.window.solve_panel) off-screen, no ROS: the two-link
arm of test_geometric_planning (it must fold past a post) solved on the page's worker with the
problem's settings, a colliding goal refused in the window's error line, a search cancelled,
Show's frames placing the links along the path, Run handing the tracked runner the very
solution a saved task file reads as (the path interpolated as `rosrun GUI plan` writes it),
and no page for a physics problem. Each test in a
process of its own (QApplication once per process, OMPL seeded once per process)."""
from __future__ import annotations

import os
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from gui.core.kautham.problem import load_problem
from gui.core.kautham.solutions import read_solution
from gui.core.translate import plan_problem
from gui.planning.geometric import query, task_rows
from test_geometric_planning import _problem

pytestmark = pytest.mark.forked


class _Window:
    """What the Motion tab asks of the main window: its scene, messages and path worker."""

    def __init__(self):
        from gui.window.scene import SceneModel
        from gui.window.worker import WorldWorker
        self.scene = SceneModel()
        self.path_worker = WorldWorker(name="paths", node=None)
        self.path_worker.start()
        self.worker = WorldWorker(name="world", node=None)       # its busy signal only
        self.simulation = SimpleNamespace(building=False)
        self.publication_rate = 25.0
        self.errors, self.infos = [], []

    def show_error(self, text):
        self.errors.append(text)

    def show_info(self, text):
        self.infos.append(text)


@pytest.fixture
def tab():
    """A shown Motion tab of a window without ROS; its workers stopped afterwards."""
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from gui.window.motion_tab import MotionTab
    from gui.window.testing import app
    app()
    window = _Window()
    motion = MotionTab(window)
    motion.show()
    yield motion
    window.path_worker.stop()
    assert not motion.solve.solver.isRunning()      # stopped with the window's path worker


def _open(tab, plan):
    """``plan`` as the Simulation tab leaves a built problem in the scene."""
    tab.window.scene.plan = plan
    for handle in plan.robots:
        tab.window.scene.add_robot(handle, plan.problem.format)


def _solve(tab, timeout=60.0):
    from gui.window.testing import click, wait_for
    page = tab.solve
    click(page.solve_button)
    assert page.solving and page.cancel_button.isEnabled()
    # on the page's own worker: neither the GUI thread nor the world's queue
    assert page.solver.pending() == 1 or page.solver.current is not None
    wait_for(lambda: not page.solving, timeout, "the search to end", page.result_label.text)
    return page


def test_the_page_solves_the_query_off_the_gui_thread_and_says_what_it_found(tab, tmp_path):
    from gui.window.motion_tab import SOLVE_TITLE
    plan = plan_problem(load_problem(_problem(tmp_path)))
    _open(tab, plan)
    page = tab.solve
    index = tab.toolbox.indexOf(page)
    assert index == 4 and tab.toolbox.itemText(index) == SOLVE_TITLE
    assert (page.planner.currentText(), page.time_limit.value()) == ("RRTConnect", 60.0)
    assert not page.show_button.isEnabled() and not page.run_button.isEnabled()
    page.time_limit.setValue(20.0)
    page.seed.setValue(7)
    _solve(tab)
    result = page.solved.result
    assert result.solved and result.seed == 7 and result.checks > 0
    assert page.solved.settings.time_limit == 20.0 and page.solved.settings.range == 0.1
    text = page.result_label.text()
    assert text.startswith("Solved in ") and f"{result.states} states" in text
    assert "seed 7" in text and "collision checks" in text
    assert page.show_button.isEnabled() and page.run_button.isEnabled()
    assert tab.window.errors == []
    assert not page.seed.isEnabled()        # OMPL took its seed: another would be ignored


class _Job:
    """What a path worker's job gives its work: progress and a pacing sleep (not slept)."""

    def __init__(self):
        self.done = []

    def progress(self, k):
        self.done.append(k)

    def sleep(self, seconds):
        pass


class _Client:
    """A world that records each Set Position."""

    def __init__(self):
        self.frames = []

    def set_position(self, situations, reset_velocity=True):
        self.frames.append({body: np.asarray(p) for body, p, _q in situations})


def test_show_places_the_links_from_the_start_along_the_path_to_the_goal(tab, tmp_path,
                                                                        monkeypatch):
    from gui.window.solve_panel import SHOW_SECONDS
    from gui.window.testing import click
    plan = plan_problem(load_problem(_problem(tmp_path)))
    _open(tab, plan)
    _solve(tab)
    submitted = []
    monkeypatch.setattr(tab, "submit_path", lambda *a, **k: submitted.append(a))
    click(tab.solve.show_button)
    label, name, robots, total, work, pace = submitted[0]
    assert (label, robots, pace) == ("show", "arm", " at 25 Hz")
    client, job = _Client(), _Job()
    assert work(client, job) == total == len(client.frames)
    assert job.done == list(range(1, total + 1))
    assert abs(total - SHOW_SECONDS * 25) <= len(tab.solve.solved.result.path)
    arm = plan.robot("arm")
    # the query: shoulder -2 + 4 c1 rad, elbow -2.5 + 5 c2 rad (test_geometric_planning)
    for frame, joints in ((client.frames[0], [-1.5, 0.0]), (client.frames[-1], [1.5, 0.0])):
        for body, position, _q in arm.situations(np.array(joints)):
            assert frame[body] == pytest.approx(position, abs=1e-9)
    # no frame jumps: the fore link's tip moves by less than the path's share of a frame
    tips = np.array([f[arm.bodies[-1].body_id] for f in client.frames])
    assert np.max(np.linalg.norm(np.diff(tips, axis=0), axis=1)) < 0.15


def test_run_hands_the_tracked_runner_what_the_saved_task_file_reads_as(tab, tmp_path,
                                                                      monkeypatch):
    from gui.window.testing import click
    plan = plan_problem(load_problem(_problem(tmp_path)))
    _open(tab, plan)
    page = _solve(tab)
    runs = []
    monkeypatch.setattr(tab, "run_tracked", lambda *a, **k: runs.append((*a, k)))
    click(page.run_button)
    run_plan, solution, name, robots, options = runs[0]
    # placed at the path's start first (a straight move there from the goal hits the post)
    arm = plan.robot("arm")
    placed = {body: p for body, p, _q in options["place"]}
    for body, position, _q in arm.situations(np.array([-1.5, 0.0])):
        assert placed[body] == pytest.approx(position, abs=1e-9)
    assert run_plan is plan and robots == "arm" and name == "RRTConnect seed " + \
        str(page.solved.result.seed)
    page.save_task(str(tmp_path / "arm_task.xml"))
    saved = read_solution(tmp_path / "arm_task.xml", plan.problem)
    assert solution.format == saved.format == "task"
    assert solution.paths["arm"].joints == pytest.approx(saved.paths["arm"].joints)
    # the path as rosrun GUI plan writes it: interpolated as Kautham does (Range 0.1: steps
    # of 0.02 at most in the control space)
    assert len(saved.paths["arm"].joints) > page.solved.result.states
    assert len(saved.paths["arm"].joints) >= page.solved.result.length / 0.02
    start, goal = query(plan)
    assert np.array(task_rows(plan, [start, goal])) == pytest.approx(
        saved.paths["arm"].joints[[0, -1]])
    assert any("arm_task.xml" in info for info in tab.window.infos)


def test_a_goal_in_the_post_is_refused_in_the_error_line_and_nothing_is_shown(tab, tmp_path):
    plan = plan_problem(load_problem(_problem(tmp_path, goal="0.5 0.5")))
    _open(tab, plan)
    page = _solve(tab)
    assert len(tab.window.errors) == 1
    assert tab.window.errors[0].startswith("Solve: the query's goal collides: arm/")
    assert "mm into post" in tab.window.errors[0]
    assert page.solved is None and not page.show_button.isEnabled()
    assert page.solve_button.isEnabled()            # the user may change it and try again


def test_cancel_ends_a_search_at_once_and_says_so(tab, tmp_path):
    """RRTstar keeps improving its path until its time is up: only Cancel ends it early."""
    import time
    from gui.window.testing import click, wait_for
    _open(tab, plan_problem(load_problem(_problem(tmp_path))))
    page = tab.solve
    page.planner.setCurrentText("RRTstar")
    click(page.solve_button)
    wait_for(lambda: page.solver.current is not None, 10, "the search to start")
    time.sleep(0.5)
    cancelled = time.monotonic()
    click(page.cancel_button)
    wait_for(lambda: not page.solving, 10, "the search to stop")
    assert time.monotonic() - cancelled < 3.0
    assert page.result_label.text() == "Solve: cancelled"
    assert tab.window.infos[-1] == "Solve: cancelled" and tab.window.errors == []
    assert page.solved is None and page.solve_button.isEnabled()


def test_a_problem_opened_mid_search_ends_the_search_and_none_starts_while_one_builds(
        tab, tmp_path):
    """The Simulation tab rehearses a problem it opens in a Core of the window's process: no
    search may run beside it (this ODE collides in one thread at a time)."""
    from gui.window.testing import click, wait_for
    _open(tab, plan_problem(load_problem(_problem(tmp_path))))
    page, window = tab.solve, tab.window
    page.planner.setCurrentText("RRTstar")
    click(page.solve_button)
    wait_for(lambda: page.solver.current is not None, 10, "the search to start")
    window.simulation.building = True
    window.worker.busy.emit("Open other.xml")
    wait_for(lambda: not page.solving, 5, "the search to stop")
    assert window.infos[-2] == "Solve: cancelled (Open other.xml: another problem)"
    page.solve()
    assert window.errors == ["Solve: a problem is being opened; solve once it is built"]
    assert not page.solving


def test_the_window_shut_down_mid_search_stops_the_search(tab, tmp_path):
    """The window stops its path worker as it closes: the search's worker stops with it (a
    QThread running past the window would end the process with an abort)."""
    import time
    from gui.window.testing import click, wait_for
    _open(tab, plan_problem(load_problem(_problem(tmp_path))))
    page = tab.solve
    page.planner.setCurrentText("RRTstar")
    click(page.solve_button)
    wait_for(lambda: page.solver.current is not None, 10, "the search to start")
    stopped = time.monotonic()
    tab.window.path_worker.stop()
    assert not page.solver.isRunning() and time.monotonic() - stopped < 3.0


def test_a_physics_problem_keeps_the_tab_as_it_was(tab, tmp_path):
    plan = plan_problem(load_problem(_problem(tmp_path)))
    _open(tab, replace(plan, physics=True))
    assert tab.toolbox.count() == 4 and tab.toolbox.indexOf(tab.solve) == -1
    _open(tab, plan)
    assert tab.toolbox.count() == 5
    _open(tab, replace(plan, physics=True))
    assert tab.toolbox.count() == 4 and tab.solve.plan is None


def test_a_problem_without_a_query_says_so_and_cannot_be_solved(tab, tmp_path):
    from kautham_files import write_problem
    from test_geometric_planning import ARM, CNTR, POST, PROBLEM
    text = PROBLEM.replace("<Queries><Query><Init>INIT</Init><Goal>GOAL</Goal></Query></Queries>",
                           "")
    problem = write_problem(tmp_path, {"arm.urdf": ARM, "arm.cntr": CNTR, "post.urdf": POST},
                            "arm.xml", text)
    _open(tab, plan_problem(load_problem(problem)))
    assert tab.toolbox.indexOf(tab.solve) == 4
    assert "the problem has no query (<Init> and <Goal>) to plan" in \
        tab.solve.problem_label.text()
    assert not tab.solve.solve_button.isEnabled()


def test_show_frames_cut_each_segment_by_its_length_and_keep_every_state():
    from gui.window.solve_panel import show_frames
    path = np.array([[0.0, 0.0], [0.3, 0.0], [0.3, 0.1]])
    frames = show_frames(path, 40)
    assert len(frames) == 1 + 30 + 10
    assert frames[0] == pytest.approx(path[0]) and frames[30] == pytest.approx(path[1])
    assert frames[-1] == pytest.approx(path[2])
    steps = np.linalg.norm(np.diff(frames, axis=0), axis=1)
    assert steps == pytest.approx(np.full(40, 0.01))
    assert len(show_frames(np.array([[0.5, 0.5], [0.5, 0.5]]), 40)) == 2
