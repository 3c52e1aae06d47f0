"""Debian's RViz with Odin's configuration (VirtualWorld/rviz/odin.rviz) draws the world: run
under Xvfb while the grasp scene (the TX90 with the SAH hand, the cans, the table) simulates,
its screenshot shows the robot in its orange and the hand in white. The screenshot goes to
out/rviz/grasp.png (the README shows a copy: docs/images/rviz_grasp.png)."""
from __future__ import annotations

import os
import pathlib
import subprocess
import time

import numpy as np
import pytest

pytestmark = pytest.mark.forked

ROOT = pathlib.Path(__file__).resolve().parents[2]
OUT = ROOT / "out" / "rviz"
GRASP = "legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml"
SCREEN = (1200, 846)


class Xvfb:
    """An X server without a screen on a display number it picks itself (-displayfd)."""

    def __init__(self, size=SCREEN):
        read, write = os.pipe()
        self.process = subprocess.Popen(
            ["Xvfb", "-displayfd", str(write), "-screen", "0", f"{size[0]}x{size[1]}x24",
             "-nolisten", "tcp"], pass_fds=(write,), stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL, start_new_session=True)
        os.close(write)
        with os.fdopen(read) as answer:
            number = answer.readline().strip()
        if not number:
            self.close()
            raise RuntimeError("Xvfb did not start")
        self.display = f":{number}"

    def screenshot(self, path: pathlib.Path) -> np.ndarray:
        from PIL import Image
        path.parent.mkdir(parents=True, exist_ok=True)
        subprocess.run(["import", "-display", self.display, "-window", "root", str(path)],
                       check=True, capture_output=True, timeout=60)
        return np.asarray(Image.open(path).convert("RGB"))

    def close(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def _orange(image: np.ndarray) -> np.ndarray:
    """Pixels of the TX90's orange (its links are (0.76, 0.47, 0.10) and (0.98, 0.61, 0.12),
    lit): red well above blue, green between them."""
    r, g, b = (image[..., k].astype(int) for k in range(3))
    return (r > 90) & (r - b > 70) & (g > b + 20) & (r > g + 25)


def test_rviz_draws_the_running_grasp_scene(ros_master, kautham_dir):
    from gui.core.translate import plan_problem
    from gui.core.kautham.problem import load_problem
    from gui.ros.client import WorldClient

    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_robot")
    client = WorldClient()
    client.execute(plan_problem(load_problem(kautham_dir / GRASP)))
    client.set_step(steps_per_cycle=1, rate=25.0)   # running, without holding a core: RViz
    client.start()                                   # needs the CPU to start and draw
    screen = Xvfb()
    try:
        env = dict(ros_master.env, DISPLAY=screen.display, QT_QPA_PLATFORM="xcb")
        rviz = ros_master.popen(["roslaunch", "VirtualWorld", "rviz.launch"], log_name="rviz",
                                env=env)
        path = OUT / "grasp.png"
        deadline = time.monotonic() + 90
        while True:   # RViz takes a few seconds to start and to receive the meshes
            time.sleep(3)
            assert rviz.poll() is None, ros_master.log_text(rviz)[-3000:]
            image = screen.screenshot(path)
            orange = int(_orange(image).sum())
            if orange > 5000 or time.monotonic() > deadline:
                break
        assert client.world().simulating
        # the arm fills tens of thousands of pixels of the 3-D view; nothing else is orange
        assert orange > 5000, f"the robot is not drawn ({orange} orange pixels): {path}"
        bright = (image.min(axis=2) > 200)[:, SCREEN[0] // 3: 2 * SCREEN[0] // 3]
        assert bright.sum() > 500, "the white hand is not drawn"
    finally:
        screen.close()
        client.close()
