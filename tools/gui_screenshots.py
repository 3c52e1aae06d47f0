"""The README's window screenshots, taken in real use: a private roscore, the world and the
Viewer by rosrun, the window (off-screen Qt) loading a Kautham problem, simulating it, the Viewer's
image framed on the robot, and one screenshot per tab into docs/images/gui_*.png.

    python tools/gui_screenshots.py [--problem FILE] [--out DIR]

Needs the Kautham corpus (ODIN_KAUTHAM_DIR, tools/get_kautham.sh).
"""
from __future__ import annotations

import argparse
import os
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
PROBLEM = "legacy_2012/examples/Kuka_two_columns.xml"


def take(problem: pathlib.Path, out: pathlib.Path) -> list:
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from odin_common.ros_master import RosMaster
    with RosMaster() as master:
        master.apply_to_this_process()
        master.rosrun("VirtualWorld", "virtualWorld")
        master.rosrun("Viewer", "viewer", f"_snapshot_dir:={master.ros_home}")
        master.wait_for_service("/virtual_world/get_world")
        master.wait_for_service("/viewer/set_camera")
        from gui.window.testing import open_window, click, pump, screenshot, wait_for
        window = open_window()
        try:
            return _tour(window, problem, out, click, pump, screenshot, wait_for)
        finally:
            window.shutdown()


def _tour(window, problem, out, click, pump, screenshot, wait_for) -> list:
    wait_for(lambda: window.connected, 30, "the window to find the world")
    built = []
    window.simulation.problem_built.connect(built.append)
    window.simulation.open_problem(str(problem))
    wait_for(lambda: built, 120, "the problem built", lambda: window.errors)
    wait_for(lambda: window.viewer_panel.camera is not None, 30, "the Viewer's first image")
    wait_for(lambda: window.viewer_panel.frame_points(), 30, "the robot's poses")
    click(window.viewer_panel.frame_button)
    _turn_two_joints()
    click(window.simulation.simulate_button)
    _show_joints_in_plot(window)
    pump(4.0)                                  # the arm turns, the plot fills
    wait_for(lambda: window.viewer_panel.frames > 20, 30, "the Viewer's images")
    shots = []
    for index, name in enumerate(["gui_window", "gui_settings_gravity", "gui_objects",
                                  "gui_motion", "gui_joints"]):
        window.tabs.setCurrentIndex(index)
        pump(1.0)
        shots.append(screenshot(window, out / f"{name}.png"))
    shots.append(screenshot(window.viewer_panel, out / "gui_viewer.png"))
    return shots


def _turn_two_joints() -> None:
    """The first two motors of the robot turn slowly (the Motion tab's Set Velocity), every
    axis of a motor alike (a car's wheel has two: steering and spin)."""
    from gui.ros.client import WorldClient
    client = WorldClient()
    motors = sorted(m for m in client.world().motors if m.startswith("motor:"))[:2]
    axes = client.call("get_state", motors=motors).motor_axes
    client.set_velocities(motors, [speed for speed, count in zip((0.4, -0.25), axes)
                                   for _ in range(count)])
    client.close()


def _show_joints_in_plot(window) -> None:
    """Ticks the first three joints in the window's joint plot (the list beside the plot)."""
    from PyQt5.QtCore import Qt
    from PyQt5.QtWidgets import QListWidget
    for widget in window.plot.findChildren(QListWidget):
        for row in range(min(3, widget.count())):
            item = widget.item(row)
            if item.flags() & Qt.ItemIsUserCheckable:
                item.setCheckState(Qt.Checked)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    corpus = pathlib.Path(os.environ.get("ODIN_KAUTHAM_DIR", ROOT.parent / "shared" / "kautham"))
    parser.add_argument("--problem", type=pathlib.Path, default=corpus / PROBLEM)
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "docs" / "images")
    args = parser.parse_args()
    if not args.problem.is_file():
        print(f"gui_screenshots: error: {args.problem}: no such problem (the Kautham corpus: "
              "tools/get_kautham.sh)", file=sys.stderr)
        return 2
    for path in take(args.problem, args.out):
        print(path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
