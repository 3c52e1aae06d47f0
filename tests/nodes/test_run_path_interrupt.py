"""Ctrl-C stops ``run_path`` against a live VirtualWorld (issue 28): the robot is held where it
got to (a free body at rest, joint servos on the present values, motors at speed zero), the
tool says how far it got and exits 130, writing no summary."""
from __future__ import annotations

import os
import signal
import subprocess
import time

import numpy as np
import pytest

pytestmark = pytest.mark.forked

SPHERE = ("current_2025", "demos", "OMPL_ode_demos", "Sphere", "Sphere.xml")
TRO = ("legacy_2012", "examples", "TRO")


def _interrupt_after(world, args, line: str) -> tuple[int, str, str, float]:
    """Starts ``rosrun GUI run_path *args``, sends Ctrl-C to its group once it printed a line
    starting with ``line``: (status, stdout, stderr, seconds from Ctrl-C to exit)."""
    tool = subprocess.Popen(["rosrun", "GUI", "run_path", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=world.env,
                            start_new_session=True)
    try:
        said = ""
        while not any(said_line.startswith(line) for said_line in said.splitlines()):
            out = tool.stdout.readline()
            assert out, f"run_path ended before {line!r}: {said}{tool.stderr.read()}"
            said += out
        os.killpg(tool.pid, signal.SIGINT)
        sent = time.monotonic()
        status = tool.wait(timeout=30)
        took = time.monotonic() - sent
        return status, said + tool.stdout.read(), tool.stderr.read(), took
    finally:
        if tool.poll() is None:
            os.killpg(tool.pid, signal.SIGKILL)
            tool.wait()


def _assert_interrupted(status: int, out: str, err: str, took: float) -> str:
    assert status == 128 + signal.SIGINT, err
    assert took < 2.0, took
    assert "Traceback" not in err
    last = out.splitlines()[-1]
    assert last.startswith("run_path: interrupted at ") and "held" in last, out
    return last


def test_ctrl_c_stops_a_control_path_with_the_sphere_at_rest(world, kautham_dir, tmp_path):
    problem = kautham_dir.joinpath(*SPHERE)
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=120)
    path = tmp_path / "east.path"                         # 30 s in real time, pushing east
    path.write_text("".join("0.9 0.5 0.5 0.1\n" for _ in range(300)))
    status, out, err, took = _interrupt_after(world, [str(problem), "--controls", str(path)],
                                              "[5/300]")
    last = _assert_interrupted(status, out, err, took)
    assert " of 300 (" in last and "s of 30.00 s)" in last
    from gui.ros.client import WorldClient
    client = WorldClient()
    _, _, linear, angular = client.body_kinematics(_sphere_body(client))
    assert np.abs(linear).max() < 1e-9 and np.abs(angular).max() < 1e-9
    client.close()


def _sphere_body(client) -> str:
    return next(o for o in client.world().objects if "Sphere" in o)


def test_ctrl_c_stops_a_tracked_path_with_the_joints_held(world, kautham_dir, tmp_path):
    tro = kautham_dir.joinpath(*TRO)
    problem, solution = tro / "2DRR_obstacle.xml", tro / "2DRR_obstacle_sol.kps"
    world.run(["rosrun", "GUI", "load_problem", str(problem), "--at-start"], timeout=120)
    summary = tmp_path / "summary.json"
    status, out, err, took = _interrupt_after(
        world, [str(problem), "--at-start", "--tracked", str(solution), "--summary",
                str(summary)], "t=1.00/")
    last = _assert_interrupted(status, out, err, took)
    assert "interrupted at t=1." in last
    assert not summary.exists()
    from gui.ros.client import WorldClient
    client = WorldClient()
    joints = [j for j in client.world().joints]
    before = [j.positions[0] for j in client.call("get_state", joints=joints).joints]
    client.call("step_once", cycles=25)                  # 1 s more under the held servos
    after = [j.positions[0] for j in client.call("get_state", joints=joints).joints]
    assert np.abs(np.subtract(after, before)).max() < 2e-3, (before, after)
    client.close()


def test_ctrl_c_stops_a_velocity_path_with_the_motors_at_rest(world, kautham_dir, tmp_path):
    problem = kautham_dir.joinpath(*TRO) / "2DRR_obstacle.xml"
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=120)
    path = tmp_path / "turn.txt"                          # 20 s at 25 rows a second
    path.write_text("".join("5 5 0\n" for _ in range(500)))
    status, out, err, took = _interrupt_after(
        world, [str(problem), "--velocity", str(path), "--rate", "25"], "[5/500]")
    last = _assert_interrupted(status, out, err, took)
    assert " of 500 (" in last and "s of 20.00 s)" in last
    from gui.ros.client import WorldClient
    client = WorldClient()
    assert list(client.call("get_state").motor_goals) == [0.0] * 3
    client.close()
