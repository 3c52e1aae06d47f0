"""A position path row that moves a joint further than it could in one row is refused before
anything is sent (issue 41, finding 6): a radian path read in degrees, on a crane of our own
(a revolute boom over a prismatic hoist), names its file, line, joint, jump and units, with a
hint about the other unit; rows within the bounds, and the grasp's own paths, pass."""
from __future__ import annotations

import math
import os
import pathlib

import numpy as np
import pytest

from gui.core.kautham.problem import load_problem
from gui.core.paths import (DEGREES, MAX_ROW_JUMP, MAX_ROW_SLIDE, RADIANS, check_first_row,
                            check_row_jumps, read_robot_path)
from gui.core.translate import plan_problem
from gui.errors import PathFileError
from kautham_files import write_problem

CRANE = """<?xml version="1.0"?><robot name="crane">
 <link name="mast"><collision><geometry><box size="0.2 0.2 1"/></geometry></collision></link>
 <link name="boom"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.05 0.05"/>
  </geometry></collision></link>
 <link name="hook"><collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision>
 </link>
 <joint name="slew" type="revolute"><parent link="mast"/><child link="boom"/><origin
  xyz="0 0 0.6"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="30" velocity="1"/>
 </joint>
 <joint name="hoist" type="prismatic"><parent link="boom"/><child link="hook"/><origin
  xyz="0.9 0 0"/><axis xyz="0 0 -1"/><limit lower="0" upper="0.5" effort="50" velocity="0.2"/>
 </joint>
</robot>"""

PROBLEM = """<?xml version="1.0"?><Problem>
 <Robot robot="crane.urdf"><Home X="0" Y="0" Z="0.5" WX="0" WY="0" WZ="1" TH="0"/></Robot>
</Problem>"""


@pytest.fixture
def crane(tmp_path):
    """The crane's handle (built at Home: slew 0 rad, hoist 0 m) and a folder for paths."""
    problem = write_problem(tmp_path, {"crane.urdf": CRANE}, "crane.xml", PROBLEM)
    return plan_problem(load_problem(problem)).robots[0], tmp_path


def _path(folder: pathlib.Path, text: str) -> pathlib.Path:
    path = folder / "crane.path"
    path.write_text(text)
    return path


def test_a_radian_path_read_in_degrees_is_refused_at_its_first_row_with_a_hint(crane):
    handle, folder = crane
    # radians written for a robot standing at slew 1.5 rad: read in degrees, row 1 asks 0.026
    path = _path(folder, "# slew rad, hoist m\n1.5 0.1\n1.55 0.1\n")
    read = read_robot_path(path, handle, DEGREES)
    check_row_jumps(read)                       # the rows among themselves are close
    with pytest.raises(PathFileError) as error:
        check_first_row(read, np.array([1.5, 0.1]))
    message = str(error.value)
    assert message.startswith(f"{path}:2: joint slew moves ")
    jump = 1.5 - math.radians(1.5)
    assert f"{jump:.3g} rad ({math.degrees(jump):.3g} deg)" in message
    assert f"more than {MAX_ROW_JUMP:g} rad (MAX_ROW_JUMP)" in message
    assert "--radians if it is in radians" in message and "--allow-jumps" in message
    assert "\n" not in message


def test_a_degree_path_read_in_radians_is_refused_between_two_rows_with_a_hint(crane):
    handle, folder = crane
    path = _path(folder, "0 0\n\n10 0\n20 0\n")
    read = read_robot_path(path, handle, RADIANS)
    with pytest.raises(PathFileError, match=r":3: joint slew moves 10 rad \(573 deg\) in one "
                       r"row from the row before.*--degrees if it is in degrees"):
        check_row_jumps(read)
    assert np.array_equal(read.rows, [[0, 0], [10, 0], [20, 0]])  # SI, nothing changed


def test_a_prismatic_joint_has_its_own_bound_in_metres(crane):
    handle, folder = crane
    read = read_robot_path(_path(folder, "0 0\n0 0.09\n0 0.2\n"), handle, RADIANS)
    with pytest.raises(PathFileError, match=r":3: joint hoist moves 0.11 m \(110 mm\) in one "
                       rf"row from the row before, more than {MAX_ROW_SLIDE:g} m "
                       r"\(MAX_ROW_SLIDE\); --allow-jumps"):
        check_row_jumps(read)


def test_rows_within_the_bounds_pass_and_an_unknown_start_is_not_compared(crane):
    handle, folder = crane
    read = read_robot_path(_path(folder, "0 0\n28 5\n56 10\n"), handle, DEGREES)
    check_row_jumps(read)
    check_first_row(read, np.array([0.4, 0.0]))
    check_first_row(read, np.array([np.nan, 0.0]))  # a joint the world does not read
    with pytest.raises(PathFileError, match=":1: joint slew moves 0.6 rad .* from where the "
                       "robot is"):
        check_first_row(read, np.array([0.6, 0.0]))


def test_the_grasp_and_hand_session_paths_pass(kautham_dir):
    paths = pathlib.Path(os.environ["ODIN_ROOT"], "Odin", "GUI", "paths")
    examples = kautham_dir / "legacy_2012" / "examples"
    grasp = plan_problem(load_problem(examples / "TX90_RHand_ICRA10_5PMD_TwoCan.xml"))
    check_row_jumps(read_robot_path(paths / "grasp_approach.txt", grasp.robots[0], RADIANS))
    kuka = plan_problem(load_problem(examples / "Kuka_two_columns.xml")).robots[0]
    read = read_robot_path(paths / "kuka_two_columns.txt", kuka, DEGREES)
    check_row_jumps(read)
    check_first_row(read, kuka.built_at)
