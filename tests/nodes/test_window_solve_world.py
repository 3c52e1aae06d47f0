"""The Motion tab's Solve query page as a user drives it, against the real VirtualWorld and
Viewer nodes: the two-link arm of Odin/GUI/test/test_geometric_planning.py opened in the
window with a short query beside the post (a tracked run of its fold past the post takes
25 s of real time; Odin/GUI/test/test_window_solve.py solves that one), its query solved, the
path shown in the world (the links end where the goal puts them) and run tracked (placed at
its start, the servos bring it to the goal). Screenshots of the window after Solve, after Show
and after Run go to out/gui/."""
from __future__ import annotations

import os
import pathlib
import sys

import numpy as np
import pytest

pytestmark = [pytest.mark.forked, pytest.mark.slow]

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHOTS = ROOT / "out" / "gui"
sys.path.insert(0, str(ROOT / "Odin" / "GUI" / "test"))     # the arm problem's files

GOAL = "0.3 0.5"
GOAL_JOINTS = (-0.8, 0.0)
"""rad: the shoulder and the elbow at the query's goal (shoulder -2 + 4 c1 rad, elbow
-2.5 + 5 c2 rad: test_geometric_planning); from the start (-1.5, 0) the stretched arm turns
0.7 rad clear of the post."""


def _fresh_image(panel, wait_for, after: float) -> None:
    """Waits for a Viewer image that arrived after ``after`` (time.monotonic)."""
    wait_for(lambda: panel.last_frame_time > after + 0.3, 10, "a Viewer image of the scene")


def _link_positions(handle) -> dict:
    from world_client import WorldClient
    client = WorldClient()
    ids = [body.body_id for body in handle.bodies]
    state = client.ok("get_state", objects=ids)
    return {b.id: np.array(b.position) for b in state.bodies}


def test_open_solve_show_and_run_the_arm(ros_master, tmp_path):
    import time
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from gui.window.testing import click, open_window, screenshot, wait_for
    from test_geometric_planning import _problem
    world = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    ros_master.rosrun("Viewer", "viewer")
    ros_master.wait_for_service("/viewer/set_camera")
    window = open_window()
    try:
        wait_for(lambda: window.connected and window.updates > 0, 15, "the window to connect")
        window.simulation.open_problem(str(_problem(tmp_path, goal=GOAL)))
        wait_for(lambda: "arm" in window.scene.robots and not window.simulation.building, 30,
                 "the arm problem built")
        tab, page = window.motion, window.motion.solve
        window.tabs.setCurrentWidget(tab)
        tab.toolbox.setCurrentWidget(page)
        assert page.planner.currentText() == "RRTConnect" and page.plan is window.scene.plan
        page.seed.setValue(1)
        wait_for(lambda: window.scene.world_robots and window.scene.robot_points(), 10,
                 "the arm's links in world_update")
        # the camera comes from the Viewer on its own time: Frame before it says so (CI)
        wait_for(lambda: window.viewer_panel.camera is not None, 15, "the Viewer's camera")
        click(window.viewer_panel.frame_button)
        click(page.solve_button)
        wait_for(lambda: not page.solving, 60, "the search", page.result_label.text)
        assert page.solved.result.solved, page.result_label.text()
        assert page.result_label.text().startswith("Solved in ")
        _fresh_image(window.viewer_panel, wait_for, time.monotonic())
        screenshot(window, SHOTS / "solve_solved.png")

        click(page.show_button)
        wait_for(lambda: "show" in page.path_status.text(), 5, "Show under way")
        wait_for(lambda: "rows done" in page.path_status.text(), 30, "Show's last frame",
                 page.path_status.text)
        handle = window.scene.robots["arm"]
        expected = {b: p for b, p, _q in handle.situations(np.array(GOAL_JOINTS))}
        positions = _link_positions(handle)
        for body, position in expected.items():
            assert positions[body] == pytest.approx(position, abs=1e-6), body
        _fresh_image(window.viewer_panel, wait_for, time.monotonic())
        screenshot(window, SHOTS / "solve_shown.png")

        # Run: the arm is at the goal after Show; placed at the path's start, it follows the
        # path with the servos
        click(page.run_button)
        wait_for(lambda: tab.tracking_plot.report is not None, 90, "the tracked run's end",
                 page.path_status.text)
        report = tab.tracking_plot.report
        status = page.path_status.text()
        assert report.goal_error <= 0.01 and report.tracking_error_max < 0.05, status
        assert "goal error" in status and "move to its start" not in status
        assert not report.collisions, status
        _fresh_image(window.viewer_panel, wait_for, time.monotonic())
        screenshot(window, SHOTS / "solve_run.png")
        assert window.errors == [], window.errors
    finally:
        window.shutdown()
    assert not page.solver.isRunning()
    assert world.poll() is None, "virtualWorld died:\n" + ros_master.log_text(world)[-3000:]
