"""run_path against a live VirtualWorld refuses a position path whose first row jumps from
where the robot is (issue 41, finding 6): a crane of our own placed by --initial at slew
1.5 rad, then driven with the same radian file read in degrees, is refused in one line with
the unit hint and not moved; read in radians, or with --allow-jumps, it runs."""
from __future__ import annotations

import numpy as np
import pytest
from crane import CRANE_URDF

pytestmark = pytest.mark.forked

PROBLEM = """<?xml version="1.0"?><Problem>
 <Robot robot="crane.urdf"><Home X="0" Y="0" Z="0.5" WX="0" WY="0" WZ="1" TH="0"/></Robot>
</Problem>"""


def _slew(world_client) -> float:
    """The slew joint's reading in the world (rad from where the crane was built, at 0)."""
    joints = [j for j in world_client.world().joints if j.endswith("crane/boom")]
    return float(world_client.joint_positions(joints)[0])


def test_a_radian_path_read_in_degrees_is_refused_where_the_robot_is(world, tmp_path):
    from gui.ros.client import WorldClient
    (tmp_path / "crane.urdf").write_text(CRANE_URDF)
    problem = tmp_path / "crane.xml"
    problem.write_text(PROBLEM)
    path = tmp_path / "slew.path"
    path.write_text("1.5\n1.52\n1.54\n")
    world.run(["rosrun", "GUI", "load_problem", str(problem)], timeout=60)
    world.run(["rosrun", "GUI", "run_path", str(problem), "--initial", str(path)], timeout=60)
    client = WorldClient()
    assert _slew(client) == pytest.approx(1.5, abs=1e-3)

    run = ["rosrun", "GUI", "run_path", str(problem), "--position", str(path), "--rate", "50"]
    refused = world.run(run + ["--degrees"], check=False, timeout=60)
    assert refused.returncode != 0 and refused.stdout == ""
    lines = [line for line in refused.stderr.splitlines() if ": warning: " not in line]
    jump = 1.5 - np.radians(1.5)
    assert lines == [f"run_path: error: {path}:1: joint slew moves {jump:.3g} rad "
                     f"({np.degrees(jump):.3g} deg) in one row from where the robot is, more "
                     f"than 0.5 rad (MAX_ROW_JUMP); the path is read in degrees (--degrees, a "
                     f"2012 problem's default): --radians if it is in radians; --allow-jumps "
                     f"to run it anyway"]
    assert _slew(client) == pytest.approx(1.5, abs=1e-3)       # nothing was sent

    ran = world.run(run + ["--double", "1"], timeout=60)
    assert ran.stdout.splitlines()[-1].startswith("crane: 5 rows at 50 Hz")
    assert _slew(client) == pytest.approx(1.54, abs=1e-3)
    world.run(run + ["--degrees", "--allow-jumps"], timeout=60)
    assert _slew(client) == pytest.approx(np.radians(1.54), abs=1e-3)
    client.close()
