"""run_path against a live VirtualWorld with several robots and with a mobile base (issue 41,
findings 2 and 4), on problems of our own (Odin/GUI/test/several_robots.py): a mobile base
stays where it is under rows of its arm alone and moves by rows that carry its x and y; two
2012 arms each follow their share of a .kps of every robot's controls, --robot drives one
with a .kps of its own controls and is refused with one of every robot's; position and
control rows of both arms drive both."""
from __future__ import annotations

import pathlib
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "Odin" / "GUI" / "test"))     # the problems' writers
from several_robots import joint_2012, kps, rover, two_arms_2012  # noqa: E402

pytestmark = pytest.mark.forked


def _handles(problem: pathlib.Path) -> dict:
    """{robot name: its plan handle}, IDs as load_problem builds them."""
    from gui.core.kautham.problem import load_problem
    from gui.core.translate import plan_problem
    return {h.name: h for h in plan_problem(load_problem(problem)).robots}


def _joints(client, handle) -> np.ndarray:
    """rad: the robot's movable joints in the world."""
    return np.asarray(handle.built_at) + client.joint_positions(handle.joint_ids)


def _base(client, handle) -> np.ndarray:
    """m, world: where the base link's origin is (its body's offset taken off)."""
    from odin_common.rotations import quaternion_to_matrix
    position, quaternion, _, _ = client.body_kinematics(handle.bodies[0].body_id)
    body = np.eye(4)
    body[:3, :3] = quaternion_to_matrix(quaternion)
    body[:3, 3] = position
    return (body @ np.linalg.inv(handle.bodies[0].offset))[:3, 3]


def _errors(result) -> list:
    return [line for line in result.stderr.splitlines() if ": warning: " not in line]


def test_a_mobile_base_stays_where_it_is_under_its_arms_rows_and_moves_by_its_own(world,
                                                                                 tmp_path):
    """The issue's cart went back where it was built under a one-row path of its arm, and a
    row with its base's columns was refused; here the rover, put at (0.2, 0.2) by another
    client, stays there under a row of its pan joint, then follows rows of x y pan (m, m,
    rad: its controls' order) and a velocity path of its x (m/s)."""
    from gui.ros.client import WorldClient
    problem = rover(tmp_path)
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=60)
    client = WorldClient()
    handle = _handles(problem)["rover"]
    np.testing.assert_allclose(_base(client, handle), [0.0, 0.0, 0.05], atol=1e-6)
    away = np.eye(4)
    away[:3, 3] = (0.2, 0.2, 0.05)
    client.set_position(handle.situations([0.0], away), reset_velocity=True)
    run = ["rosrun", "GUI", "run_path", str(problem), "--rate", "50"]

    arm = tmp_path / "pan.path"
    arm.write_text("0.3\n")
    world.run(run + ["--position", str(arm)], timeout=60)
    np.testing.assert_allclose(_base(client, handle), [0.2, 0.2, 0.05], atol=1e-6)
    assert _joints(client, handle)[0] == pytest.approx(0.3, abs=1e-3)

    both = tmp_path / "rover.path"
    both.write_text("# x y pan\n0.25 0.2 0.3\n0.3 0.15 0.35\n")
    world.run(run + ["--position", str(both)], timeout=60)
    np.testing.assert_allclose(_base(client, handle), [0.3, 0.15, 0.05], atol=1e-6)
    assert _joints(client, handle)[0] == pytest.approx(0.35, abs=1e-3)

    far = tmp_path / "far.path"
    far.write_text("1.3 0.15 0.35\n")
    refused = world.run(run + ["--position", str(far)], check=False, timeout=60)
    assert refused.returncode != 0 and _errors(refused) == [
        f"run_path: error: {far}:1: the base of rover along X moves 1 m (1e+03 mm) in one row "
        f"from where the robot is, more than 0.1 m (MAX_ROW_SLIDE); --allow-jumps to run it "
        f"anyway"]

    speeds = tmp_path / "speeds.path"
    speeds.write_text("0.5 0 0\n" * 10)              # 0.5 m/s along x for 1 s, pan still
    client.start()
    world.run(["rosrun", "GUI", "run_path", str(problem), "--rate", "10", "--velocity",
               str(speeds)], timeout=60)
    client.pause()
    x, y, z = _base(client, handle)
    assert 0.55 < x < 1.05 and y == pytest.approx(0.15, abs=1e-3)
    assert np.linalg.norm(client.body_kinematics(handle.bodies[0].body_id)[2]) < 1e-9
    client.close()


def test_two_2012_arms_each_follow_their_share_of_one_kautham_plan(world, tmp_path):
    """The issue's two-arm .kps of the problem's 14 values was refused and one of 7 values
    drove both arms whatever --robot said: here each arm reaches its own share of a 4-value
    plan, a 2-value plan with --robot arm_2 moves arm_2 alone, --robot with the plan of every
    robot is refused in one line, and a position path of both arms' joints moves both."""
    from gui.ros.client import WorldClient
    problem = two_arms_2012(tmp_path)
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=60)
    client = WorldClient()
    arm, arm_2 = _handles(problem).values()
    run = ["rosrun", "GUI", "run_path", str(problem), "--fast"]

    every = kps(tmp_path, [[0.5, 0.5, 0.5, 0.5], [0.75, 0.25, 0.5, 1.0]], "every.kps")
    world.run(run + ["--tracked", str(every)], timeout=180)
    np.testing.assert_allclose(_joints(client, arm), [joint_2012(0.75), joint_2012(0.25)],
                               atol=0.01)
    np.testing.assert_allclose(_joints(client, arm_2), [0.0, joint_2012(1.0)], atol=0.01)

    one = kps(tmp_path, [[0.5, 1.0], [0.25, 0.5]], "one.kps")
    world.run(run + ["--tracked", str(one), "--robot", "arm_2"], timeout=180)
    np.testing.assert_allclose(_joints(client, arm), [joint_2012(0.75), joint_2012(0.25)],
                               atol=0.01)
    np.testing.assert_allclose(_joints(client, arm_2), [joint_2012(0.25), 0.0], atol=0.01)

    refused = world.run(run + ["--tracked", str(every), "--robot", "arm"], check=False,
                        timeout=60)
    assert refused.returncode != 0 and _errors(refused) == [
        f"run_path: error: --robot arm: {every} holds every robot's configuration (arm, "
        f"arm_2): without --robot it drives them all"]

    rows = tmp_path / "both.path"                    # degrees: arm J1 J2, arm_2 J1 J2
    rows.write_text("45 -45 -45 0\n40 -40 -40 5\n")
    world.run(run + ["--position", str(rows), "--rate", "50"], timeout=60)
    np.testing.assert_allclose(_joints(client, arm), np.radians([40, -40]), atol=1e-3)
    np.testing.assert_allclose(_joints(client, arm_2), np.radians([-40, 5]), atol=1e-3)
    client.close()


def test_one_control_path_drives_both_2012_arms(world, tmp_path):
    """A control row of both arms' controls end to end (and a duration) servos each arm to
    its share, in one Propagate per row."""
    from gui.ros.client import WorldClient
    problem = two_arms_2012(tmp_path)
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=60)
    client = WorldClient()
    arm, arm_2 = _handles(problem).values()
    controls = tmp_path / "both.controls"
    controls.write_text("0.75 0.25 0.25 0.75 2.0\n")
    result = world.run(["rosrun", "GUI", "run_path", str(problem), "--fast", "--controls",
                        str(controls)], timeout=120)
    assert result.stdout.splitlines()[-1].startswith("arm, arm_2: 1 control rows done")
    np.testing.assert_allclose(_joints(client, arm), [joint_2012(0.75), joint_2012(0.25)],
                               atol=0.01)
    np.testing.assert_allclose(_joints(client, arm_2), [joint_2012(0.25), joint_2012(0.75)],
                               atol=0.01)
    client.close()
