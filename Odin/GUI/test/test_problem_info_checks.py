"""problem_info checks the query's start and goal (issue 41, finding 7): two cranes of our own
built with their booms through each other, and a crane whose goal swings its boom through a
post, are said in problem_info's JSON (per robot: the pair, its depth in m, start or goal) and
in one warning line on stderr each, the lines load_problem writes; a goal past a joint's
limits, which Kautham's controls clamp into them, is said too; ``--no-checks`` says nothing of
them and builds nothing; a clear problem has nothing to say."""
from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import pytest

from kautham_files import crane_and_post, crane_urdf, write_problem

SCRIPT = pathlib.Path(__file__).resolve().parents[1] / "scripts" / "problem_info"

# one control slews both cranes: slew = -3 + 6 c rad (offset 0.5, the default)
TWO_CNTR = """<?xml version="1.0"?><ControlSet>
 <Control name="slew" eigValue="1.0"><DOF name="west/boom" value="1.0"/>
  <DOF name="east/boom" value="1.0"/></Control>
</ControlSet>"""

# west's mast at x 0, east's at 1.2 turned half a turn, 2 cm higher: at the start (slew 0)
# both booms lie along x between 0.2 and 1 m, 3 cm of their 5 cm overlapping in z; the goal
# (slew 1.5 rad) swings them apart
TWO_CRANES = """<?xml version="1.0"?><Problem>
 <Robot robot="west.urdf"><Home X="0" Y="0" Z="0.5" WX="0" WY="0" WZ="1" TH="0"/></Robot>
 <Robot robot="east.urdf"><Home X="1.2" Y="0" Z="0.52" WX="0" WY="0" WZ="1"
  TH="3.141592653589793"/></Robot>
 <Controls robot="cranes.cntr"/>
 <Planner><Parameters><Name>omplRRTConnect</Name></Parameters>
  <Queries><Query><Init>0.5</Init><Goal>0.75</Goal></Query></Queries></Planner>
</Problem>"""


def _two_cranes(folder: pathlib.Path) -> pathlib.Path:
    return write_problem(folder, {"west.urdf": crane_urdf("west"),
                                  "east.urdf": crane_urdf("east"),
                                  "cranes.cntr": TWO_CNTR}, "cranes.xml", TWO_CRANES)


def _info(problem: pathlib.Path, *options: str):
    """(problem_info's JSON, its stderr's warning lines about collisions and limits)."""
    done = subprocess.run([sys.executable, str(SCRIPT), str(problem), *options],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    lines = [line for line in done.stderr.splitlines() if "not used:" not in line]
    return json.loads(done.stdout), lines


def _robot(info: dict, name: str) -> dict:
    return next(r for r in info["robots"] if r["name"] == name)


def test_two_robots_built_through_each_other_are_said_at_the_start(tmp_path):
    info, lines = _info(_two_cranes(tmp_path))
    for name in ("west", "east"):
        collisions = _robot(info, name)["collisions"]
        assert len(collisions) == 1, collisions
        pair = collisions[0]
        assert pair["at"] == "start"
        assert {pair["first"], pair["second"]} == {"west/boom", "east/boom"}
        assert pair["depth"] == pytest.approx(0.03, abs=1e-4)
        assert _robot(info, name)["outside_limits"] == []
    assert len(info["overlaps"]) == 1 and info["goal_overlaps"] == []
    assert len(lines) == 1, lines
    assert lines[0].startswith("problem_info: warning: ") and str(tmp_path) in lines[0]
    assert "built with parts inside each other" in lines[0]
    assert ("west/boom in east/boom by 30.0 mm" in lines[0]
            or "east/boom in west/boom by 30.0 mm" in lines[0]), lines[0]


def test_a_goal_through_an_obstacle_is_said_at_the_goal_as_load_problem_says_it(tmp_path):
    info, lines = _info(crane_and_post(tmp_path, "0.5"))
    crane = _robot(info, "crane")
    # the boom (5 cm thick) across the post (10 cm): 2.5 + 5 cm deep along the boom's width
    assert crane["collisions"] == [dict(at="goal", first="crane/boom", second="post",
                                        depth=pytest.approx(0.075, abs=1e-4))]
    assert info["overlaps"] == [] and len(info["goal_overlaps"]) == 1
    assert lines == [f"problem_info: warning: {tmp_path / 'crane.xml'}: the query's goal puts "
                     "parts inside each other: crane/boom in post by 75.0 mm; a path to it "
                     "ends in collision"]


def test_a_goal_past_a_joint_limit_is_said_with_the_value_asked(tmp_path):
    info, lines = _info(crane_and_post(tmp_path, "1.2"))
    crane = _robot(info, "crane")
    assert crane["outside_limits"] == [dict(
        at="goal", dof="boom", joint="slew", parameter=pytest.approx(1.2),
        value=pytest.approx(4.2), limits=[-3.0, 3.0])]
    assert crane["goal"]["joints"] == [pytest.approx(3.0)]       # clamped, as Kautham does
    assert len(lines) == 1, lines
    assert "the query's goal asks joint slew of crane for 4.2 rad, outside its limits " \
           "[-3, 3]" in lines[0], lines[0]


def test_a_clear_problem_says_nothing_and_no_checks_builds_nothing(tmp_path):
    info, lines = _info(crane_and_post(tmp_path, "0.75"))
    assert _robot(info, "crane")["collisions"] == [] and lines == []
    assert info["overlaps"] == [] and info["goal_overlaps"] == []
    unchecked, lines = _info(crane_and_post(tmp_path, "0.5"), "--no-checks")
    assert _robot(unchecked, "crane")["collisions"] is None and lines == []
    assert unchecked["overlaps"] is None and unchecked["goal_overlaps"] is None
