"""load_problem names a query's goal that puts the robot inside something (issue 41, finding
7): a crane of our own whose goal swings its boom through a post is warned about in one line
naming the pair and its depth; the same crane with its goal clear of the post loads with no
such warning; the world is built either way."""
from __future__ import annotations

import pytest
from crane import CRANE_URDF

pytestmark = pytest.mark.forked

CNTR = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="crane/boom" value="0.5"/></Offset>
 <Control name="crane/slew" eigValue="1.0"><DOF name="crane/boom" value="1.0"/></Control>
</ControlSet>"""

POST = """<?xml version="1.0"?><robot name="post"><link name="base"><collision><geometry>
 <box size="0.1 0.1 0.4"/></geometry></collision></link></robot>"""

# slew -3 + 6 c rad: c 0.25 points the boom along -1.5 rad, c 0.5 along +x, through the post
PROBLEM = """<?xml version="1.0"?><Problem>
 <Robot robot="crane.urdf"><Home X="0" Y="0" Z="0.5" WX="0" WY="0" WZ="1" TH="0"/></Robot>
 <Obstacle obstacle="post.urdf"><Home X="0.7" Y="0" Z="1.1" WX="0" WY="0" WZ="1" TH="0"/>
 </Obstacle>
 <Controls robot="crane.cntr"/>
 <Planner><Parameters><Name>omplRRTConnect</Name></Parameters>
  <Queries><Query><Init>0.25</Init><Goal>GOAL</Goal></Query></Queries></Planner>
</Problem>"""


def _problem(folder, goal: str):
    for name, text in (("crane.urdf", CRANE_URDF), ("crane.cntr", CNTR), ("post.urdf", POST)):
        (folder / name).write_text(text)
    problem = folder / "crane.xml"
    problem.write_text(PROBLEM.replace("GOAL", goal))
    return problem


def test_a_goal_through_a_post_is_warned_about_and_a_clear_one_is_not(world, tmp_path):
    through = world.run(["rosrun", "GUI", "load_problem", str(_problem(tmp_path, "0.5"))],
                        timeout=60)
    warned = [line for line in through.stderr.splitlines() if "the query's goal" in line]
    assert len(warned) == 1, through.stderr
    assert warned[0].startswith("load_problem: warning: ")
    # the boom (5 cm thick) across the post (10 cm): 2.5 + 5 cm deep along the boom's width
    assert "crane/boom in post by 75.0 mm" in warned[0], warned[0]
    assert "built " in through.stdout
    clear = world.run(["rosrun", "GUI", "load_problem", str(_problem(tmp_path, "0.75"))],
                      timeout=60)
    assert "the query's goal" not in clear.stderr and "built " in clear.stdout
