"""Several robots in one path file, and a mobile base in a position or velocity path (issue 41,
findings 2 and 4), read without ROS on problems of our own (several_robots.py): a file of
every robot's values is split per robot in every mode (a .kps of all the controls, raw rows,
OMPL rows, position and velocity rows, control rows); a file of one robot's drives that robot
alone; a position row carries a mobile base's x and y first, as Kautham's controls order its
DOFs, and a row without them leaves the base where it is, not where it was built."""
from __future__ import annotations

import math

import numpy as np
import pytest

from gui.core.control_path import ControlRow, read_control_paths, run_control_path
from gui.core.kautham.problem import load_problem
from gui.core.kautham.solutions import KPS, OMPL, ROWS, read_solution
from gui.core.kinematics import pose_to_position_quaternion
from gui.core.paths import (DEGREES, MAX_ROW_SLIDE, RADIANS, RobotRows, check_first_row,
                            check_row_jumps, read_robot_paths)
from gui.core.translate import plan_problem
from gui.errors import PathFileError
from several_robots import (joint_2012, kps, rover, swing, two_arms_2012,
                            two_arms_current)


def _write(folder, text: str, name: str = "path.txt"):
    path = folder / name
    path.write_text(text)
    return path


def _robots(plan) -> list:
    return [h for h in plan.robots if h.instance.role == "robot"]


# -- a Kautham plan (run_path --tracked) -----------------------------------------------------------
def test_a_2012_kps_of_every_robots_controls_is_split_between_them(tmp_path):
    """Kautham 2012's samples hold every robot's controls end to end, as its query does: 4
    values for two arms of 2 controls, arm's first."""
    problem = load_problem(two_arms_2012(tmp_path))
    plan = kps(tmp_path, [[0.5, 0.5, 0.5, 0.5], [0.75, 0.25, 0.5, 1.0]])
    solution = read_solution(plan, problem)
    assert solution.format == KPS and list(solution.paths) == ["arm", "arm_2"]
    np.testing.assert_allclose(solution.paths["arm"].joints[-1],
                               [joint_2012(0.75), joint_2012(0.25)])
    np.testing.assert_allclose(solution.paths["arm_2"].joints[-1], [0.0, joint_2012(1.0)])
    np.testing.assert_allclose(solution.paths["arm_2"].joints[0], [0.0, 0.0])


def test_a_2012_kps_of_one_robots_controls_moves_that_robot_alone(tmp_path):
    """A sample as long as one robot's controls is that robot's: the robot named (the first
    by default); the other robot is not in the plan, so nothing drives it."""
    problem = load_problem(two_arms_2012(tmp_path))
    plan = kps(tmp_path, [[0.5, 0.5], [0.75, 0.25]])
    second = read_solution(plan, problem, robot="arm_2")
    assert list(second.paths) == ["arm_2"]
    np.testing.assert_allclose(second.paths["arm_2"].joints[-1],
                               [joint_2012(0.75), joint_2012(0.25)])
    assert list(read_solution(plan, problem).paths) == ["arm"]


def test_a_kps_sample_of_another_length_names_both_lengths(tmp_path):
    problem = load_problem(two_arms_2012(tmp_path))
    plan = kps(tmp_path, [[0.5, 0.5, 0.5]])
    with pytest.raises(PathFileError) as error:
        read_solution(plan, problem)
    assert str(error.value) == (f"{plan}:9: <Sample> 0 has 3 values, the controls are 4 (arm: "
                                f"2 + arm_2: 2), or 2 (arm's: c1, c2)")


def test_a_current_kps_sample_is_the_controls_every_robot_maps(tmp_path):
    problem = load_problem(two_arms_current(tmp_path))
    solution = read_solution(kps(tmp_path, [[0.5, 0.5], [0.75, 0.25]]), problem)
    assert list(solution.paths) == ["left", "right"]
    assert solution.paths["left"].joints[-1] == pytest.approx([swing(0.75)])
    assert solution.paths["right"].joints[-1] == pytest.approx([swing(0.25)])


def test_raw_rows_of_every_robot_are_split_between_them(tmp_path):
    problem = load_problem(two_arms_2012(tmp_path))
    rows = _write(tmp_path, "# arm J1 J2, arm_2 J1 J2 (degrees)\n0 0 0 0\n45 -30 10 90\n")
    solution = read_solution(rows, problem)
    assert solution.format == ROWS and list(solution.paths) == ["arm", "arm_2"]
    np.testing.assert_allclose(solution.paths["arm_2"].joints[-1],
                               [math.radians(10), math.radians(90)])
    assert list(read_solution(_write(tmp_path, "45 -30\n"), problem, "arm_2").paths) == \
        ["arm_2"]


def test_ompl_rows_of_every_robot_are_read_so_whichever_robot_is_named(tmp_path):
    """A current problem's OMPL row (every robot's configuration) is read as such with a
    robot named too (the window always names one): the plan says it moves them all, for
    run_path to refuse --robot with it."""
    problem = load_problem(two_arms_current(tmp_path))
    solution = read_solution(_write(tmp_path, "0 0\n0.3 -0.2\n"), problem, robot="right")
    assert solution.format == OMPL and list(solution.paths) == ["left", "right"]
    assert solution.paths["right"].joints[-1] == pytest.approx([-0.2])


# -- position and velocity rows (run_path --initial, --position, --velocity) -----------------------
def test_position_rows_of_every_robot_drive_them_all_and_one_robots_drive_it(tmp_path):
    plan = plan_problem(load_problem(two_arms_2012(tmp_path)))
    every = read_robot_paths(_write(tmp_path, "0 0 0 0\n10 20 30 40\n"), _robots(plan),
                             DEGREES)
    assert [p.robot for p in every] == ["arm", "arm_2"]
    np.testing.assert_allclose(every[1].rows[-1], np.radians([30, 40]))
    assert every[1].names == ["arm_2/J1", "arm_2/J2"]      # the same joints' names told apart
    one = read_robot_paths(_write(tmp_path, "10 20\n"), _robots(plan), DEGREES, "arm_2")
    assert [p.robot for p in one] == ["arm_2"]
    path = _write(tmp_path, "1 2 3\n")
    with pytest.raises(PathFileError) as error:
        read_robot_paths(path, _robots(plan), DEGREES)
    assert str(error.value) == (f"{path}:1: 3 values, expected 4 (every robot: arm: 2 joints "
                                f"+ arm_2: 2 joints) or 2 (arm: 2 joints)")


def test_a_mobile_base_is_first_in_a_row_as_kauthams_controls_order_it(tmp_path):
    """The rover's controls move its base's X and Y, then its pan joint: a row is x y pan
    (m, m, rad; mm in degrees) or pan alone."""
    plan = plan_problem(load_problem(rover(tmp_path)))
    with_base = read_robot_paths(_write(tmp_path, "0.2 0.1 0.3\n"), _robots(plan), RADIANS)[0]
    assert with_base.base_axes == (0, 1) and with_base.names == ["X", "Y", "pan"]
    np.testing.assert_allclose(with_base.joints, [[0.3]])
    in_mm = read_robot_paths(_write(tmp_path, "200 100 90\n"), _robots(plan), DEGREES)[0]
    np.testing.assert_allclose(in_mm.rows, [[0.2, 0.1, math.pi / 2]])
    alone = read_robot_paths(_write(tmp_path, "0.3\n"), _robots(plan), RADIANS)[0]
    assert alone.base_axes == () and alone.names == ["pan"]
    path = _write(tmp_path, "0.2 0.3\n")
    with pytest.raises(PathFileError, match=r"2 values, expected 3 \(rover: base X Y, 1 "
                       r"joints\) or 1 \(rover: 1 joints\)"):
        read_robot_paths(path, _robots(plan), RADIANS)


def _base_situation(situations, body: str):
    return next((p, q) for b, p, q in situations if b == body)


def test_a_row_without_the_base_leaves_it_where_it_is_and_with_it_moves_it_along_x_and_y(
        tmp_path):
    """The issue's cart went back to where it was built under a row of its arm alone: the
    row's base is where the base is (here 0.2, 0.2 m, turned 0.3 rad about z), moved along
    the row's axes only, its height and turn kept."""
    handle = _robots(plan_problem(load_problem(rover(tmp_path))))[0]
    here = np.eye(4)
    here[:3, :3] = [[math.cos(0.3), -math.sin(0.3), 0], [math.sin(0.3), math.cos(0.3), 0],
                    [0, 0, 1]]
    here[:3, 3] = (0.2, 0.2, 0.05)
    body = handle.bodies[0]
    expected_position, expected_turn = pose_to_position_quaternion(here @ body.offset)
    alone = RobotRows(handle, np.array([[0.4]]), (), here)
    position, turn = _base_situation(alone.situations(0), body.body_id)
    np.testing.assert_allclose(position, expected_position, atol=1e-12)
    np.testing.assert_allclose(turn, expected_turn, atol=1e-12)
    moved = RobotRows(handle, np.array([[0.5, -0.1, 0.4]]), (0, 1), here)
    position, turn = _base_situation(moved.situations(0), body.body_id)
    np.testing.assert_allclose(position, [0.5, -0.1, expected_position[2]], atol=1e-12)
    np.testing.assert_allclose(turn, expected_turn, atol=1e-12)
    speeds = RobotRows(handle, np.array([[0.5, -0.1, 0.4]]), (0, 1), here)
    assert speeds.base_velocity(0) == (body.body_id, (0.5, -0.1, 0.0))
    np.testing.assert_allclose(speeds.speeds(0), [0.4])


def test_a_base_column_is_bound_as_a_prismatic_joint_is(tmp_path):
    """MAX_ROW_SLIDE (0.1 m a row: 2.5 m/s at 25 Hz) for a base's x or y, between rows and
    from where the base is."""
    plan = plan_problem(load_problem(rover(tmp_path)))
    path = _write(tmp_path, "0 0 0\n0.05 0 0\n0.55 0 0\n")
    read = read_robot_paths(path, _robots(plan), RADIANS)[0]
    with pytest.raises(PathFileError) as error:
        check_row_jumps(read)
    assert str(error.value).startswith(
        f"{path}:3: the base of rover along X moves 0.5 m (500 mm) in one row from the row "
        f"before, more than {MAX_ROW_SLIDE:g} m (MAX_ROW_SLIDE); --allow-jumps")
    with pytest.raises(PathFileError, match="the base of rover along Y moves 0.3 m .* from "
                       "where the robot is"):
        check_first_row(read, np.array([0.0, 0.3, 0.0]))


# -- control rows (run_path --controls) ----------------------------------------------------------
def test_control_rows_of_every_robot_are_shared_out_and_one_robots_drive_it(tmp_path):
    plan = plan_problem(load_problem(two_arms_2012(tmp_path)))
    every = read_control_paths(_write(tmp_path, "0.75 0.25 0.5 1 0.5\n"), _robots(plan),
                               legacy=True)
    assert [(h.name, rows) for h, rows in every] == [
        ("arm", [ControlRow((0.75, 0.25), 0.5)]), ("arm_2", [ControlRow((0.5, 1.0), 0.5)])]
    one = read_control_paths(_write(tmp_path, "0.75 0.25 0.5\n"), _robots(plan), legacy=True,
                             robot="arm_2")
    assert [(h.name, rows) for h, rows in one] == [("arm_2", [ControlRow((0.75, 0.25), 0.5)])]
    with pytest.raises(PathFileError, match="4 values a row, expected 5 .* or 3 .arm's 2 "
                       "controls and a duration"):
        read_control_paths(_write(tmp_path, "0.5 0.5 0.5 1\n"), _robots(plan), legacy=True)
    shared = plan_problem(load_problem(two_arms_current(tmp_path)))
    both = read_control_paths(_write(tmp_path, "0.75 0.25 1\n"), _robots(shared), False)
    assert [(h.name, rows) for h, rows in both] == [
        ("left", [ControlRow((0.75, 0.25), 1.0)]), ("right", [ControlRow((0.75, 0.25), 1.0)])]


def test_one_control_path_drives_both_arms_at_once(tmp_path, world):
    """Each arm's servo goes to its own share of the row, in the same Propagate."""
    plan = plan_problem(load_problem(two_arms_current(tmp_path)))
    world.execute(plan)
    left, right = _robots(plan)
    rows = [ControlRow((0.75, 0.25), 1.5)]
    run_control_path(world, left, rows, others=[(right, rows)])
    swings = world.joint_positions([left.joint_ids[0], right.joint_ids[0]])
    np.testing.assert_allclose(swings, [swing(0.75), swing(0.25)], atol=0.01)


class _StandingClient:
    """What rows_to_send asks of the world: a base body's kinematics (frame origin m,
    quaternion (w, x, y, z), world) and joint readings (rad, from where they were built)."""

    def __init__(self, position, quaternion, readings):
        self.position, self.quaternion, self.readings = position, quaternion, readings

    def body_kinematics(self, body_id):
        return self.position, self.quaternion, np.zeros(3), np.zeros(3)

    def joint_positions(self, joint_ids):
        return np.asarray(self.readings[:len(joint_ids)], dtype=float)


def test_rows_to_send_start_from_where_a_mobile_base_is_for_run_path_and_the_window(tmp_path):
    """run_path and the window's Move robot page send rows through rows_to_send: a row of the
    pan joint alone keeps the rover's base where the world has it (0.2, 0.2 m), not where it
    was built, and the first row is checked against the base's x and y there."""
    from gui.core.paths import COMMAND_LINE, read_robot_paths
    from gui.ros.client import rows_to_send
    handle = _robots(plan_problem(load_problem(rover(tmp_path))))[0]
    body = handle.bodies[0]
    here = np.eye(4)
    here[:3, 3] = (0.2, 0.2, 0.05)
    position, quaternion = pose_to_position_quaternion(here @ body.offset)
    client = _StandingClient(position, quaternion, [0.0])
    pan = read_robot_paths(_write(tmp_path, "0.1\n0.2\n"), [handle], RADIANS)
    sent = rows_to_send(client, pan, {handle.name: handle}, double=1, first_row=COMMAND_LINE)
    np.testing.assert_allclose(sent[0].rows, [[0.1], [0.15], [0.2]], atol=1e-15)
    base, _ = _base_situation(sent[0].situations(0), body.body_id)
    np.testing.assert_allclose(base, position, atol=1e-12)
    far = read_robot_paths(_write(tmp_path, "1.0 0.2 0.1\n"), [handle], RADIANS)
    with pytest.raises(PathFileError, match="from where the robot is"):
        rows_to_send(client, far, {handle.name: handle}, first_row=COMMAND_LINE)
