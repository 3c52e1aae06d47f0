"""The window's position paths are checked for jumps as run_path's are (issue 41, finding 6):
on a crane of our own, the Move robot page refuses a degree path read in radians at the row
that jumps (file, line, joint, jump, the page's own units choice and its "Allow jumps" box) and
starts nothing; ticked, the box lets the same path start; the first row is checked on the path
worker against where the robot is in the world (a Core of this process standing in for the
world node), and a path from where the crane stands passes. Off-screen, no ROS; each test in
a process of its own (QApplication once per process)."""
from __future__ import annotations

import os
from types import SimpleNamespace

import pytest

from gui.core.kautham.problem import load_problem
from gui.core.translate import plan_problem
from gui.errors import PathFileError
from kautham_files import write_problem
from test_path_jumps import CRANE, PROBLEM

pytestmark = pytest.mark.forked


class _Window:
    """What the Motion tab asks of the main window; its path worker's ``submit`` records the
    paths submitted (label, work) instead of running them."""

    def __init__(self):
        from gui.window.scene import SceneModel
        from gui.window.worker import WorldWorker
        self.scene = SceneModel()
        self.path_worker = WorldWorker(name="paths", node=None)
        self.worker = WorldWorker(name="world", node=None)       # its busy signal only
        self.simulation = SimpleNamespace(building=False)
        self.publication_rate = 25.0
        self.errors, self.infos, self.submitted = [], [], []
        self.path_worker.submit = lambda label, work, *callbacks: \
            self.submitted.append((label, work))

    def show_error(self, text):
        self.errors.append(text)

    def show_info(self, text):
        self.infos.append(text)


@pytest.fixture
def crane(tmp_path):
    """A shown Motion tab with the crane's problem open (current format: paths in radians,
    the crane built at Home: slew 0 rad, hoist 0 m), its plan and a folder for paths."""
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from gui.window.motion_tab import MotionTab
    from gui.window.testing import app
    app()
    window = _Window()
    tab = MotionTab(window)
    tab.show()
    plan = plan_problem(load_problem(write_problem(tmp_path, {"crane.urdf": CRANE}, "crane.xml",
                                                   PROBLEM)))
    window.scene.plan = plan
    for handle in plan.robots:
        window.scene.add_robot(handle, plan.problem.format)
    tab.toolbox.setCurrentIndex(3)
    yield tab, plan, tmp_path
    tab.solve.shutdown()


def _path(folder, text: str, name: str = "crane.path") -> str:
    path = folder / name
    path.write_text(text)
    return str(path)


def test_a_degree_path_read_in_radians_is_refused_at_the_row_that_jumps(crane):
    tab, _, folder = crane
    assert tab.units.currentText() == "radians (m)" and not tab.allow_jumps.isChecked()
    path = _path(folder, "0 0\n30 0\n60 0\n")
    tab.run_path("position", path)
    assert tab.window.submitted == []
    assert tab.window.errors == [
        f"Move robot: {path}:2: joint slew moves 30 rad (1.72e+03 deg) in one row from the "
        "row before, more than 0.5 rad (MAX_ROW_JUMP); the path is read in radians (Units in "
        "files \"radians (m)\", a current problem's default): Units in files \"degrees (mm)\" "
        "if it is in degrees; \"Allow jumps\" to run it anyway"]
    tab.allow_jumps.setChecked(True)
    tab.run_path("position", path)
    assert [label for label, _ in tab.window.submitted] == ["position path"]
    assert len(tab.window.errors) == 1


def test_the_first_row_is_checked_against_where_the_robot_is_on_the_path_worker(
        crane, world, monkeypatch):
    tab, plan, folder = crane
    world.execute(plan)                       # the crane stands at slew 0 rad, hoist 0 m
    runs = []
    monkeypatch.setattr("gui.ros.client.run_position_rows",
                        lambda client, robots, *a, **k: runs.append(robots[0].rows.tolist()))
    job = SimpleNamespace(progress=lambda value: None, sleep=lambda seconds: None)
    degrees = _path(folder, "60 0\n60.2 0\n")    # close rows, far from where the crane is
    tab.run_path("position", degrees)
    with pytest.raises(PathFileError) as error:
        tab.window.submitted[-1][1](world, job)
    assert str(error.value) == (
        f"{degrees}:1: joint slew moves 60 rad (3.44e+03 deg) in one row from where the robot "
        "is, more than 0.5 rad (MAX_ROW_JUMP); the path is read in radians (Units in files "
        "\"radians (m)\", a current problem's default): Units in files \"degrees (mm)\" if it "
        "is in degrees; \"Allow jumps\" to run it anyway")
    assert runs == []
    tab.run_path("position", _path(folder, "0.2 0.01\n0.4 0.02\n", "near.path"))
    tab.window.submitted[-1][1](world, job)                  # from where it stands: runs
    assert runs == [[[0.2, 0.01], [0.4, 0.02]]]
    tab.allow_jumps.setChecked(True)
    tab.run_path("position", degrees)
    tab.window.submitted[-1][1](world, job)                  # allowed: runs as it is
    assert runs[-1] == [[60.0, 0.0], [60.2, 0.0]]
    assert tab.window.errors == []
