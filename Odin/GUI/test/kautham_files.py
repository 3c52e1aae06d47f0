"""What the tests of Kautham problems share: problem files written here from Kautham's formats
(for what the corpus lacks) and the readers of a build plan they check."""
from __future__ import annotations

import pathlib

from odin_common.world_parameters import WorldParameters

KINEMATIC = "omplRRTConnect"
"""A planner of Kautham's without physics: the problem's URDF is simulated as it says."""

SHELF = """<?xml version="1.0"?><robot name="shelf"><link name="base"><collision><geometry>
 <box size="1 0.4 0.02"/></geometry></collision></link></robot>"""
"""An obstacle without a mass: a 1 m x 0.4 m x 2 cm board."""


TWO_LINK_URDF = """<?xml version="1.0"?>
<robot name="{name}">
  <link name="base"><inertial><mass value="2.0"/>
    <inertia ixx="{ixx}" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry>{geometry}</geometry></collision></link>
  <link name="arm"><inertial><mass value="1.0"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.5"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
"""


def two_link_urdf(ixx="0.1", geometry='<box size="0.2 0.2 0.2"/>', name="r") -> str:
    """A URDF robot ``name`` of two links (a base of ``geometry`` and inertia ``ixx`` kg m^2,
    an arm turning +-1 rad about z)."""
    return TWO_LINK_URDF.format(ixx=ixx, geometry=geometry, name=name)


def default_parameters() -> dict:
    """Odin's documented world parameters, gravity as a tuple (as a plan carries it)."""
    return {**WorldParameters().as_dict(), "gravity": WorldParameters().gravity}


def plan_steps(plan, kind) -> list:
    """The steps of ``plan`` that are ``kind`` (a step class or a tuple of them), in order."""
    return [s for s in plan.steps if isinstance(s, kind)]


def write_problem(folder: pathlib.Path, files: dict[str, str], name: str,
                  problem: str) -> pathlib.Path:
    """Writes ``files`` (file name -> text: the robot's URDF, its .cntr, the obstacles') into
    ``folder``, then the problem's XML ``problem`` as ``name``; returns the problem's path."""
    for file_name, text in files.items():
        (folder / file_name).write_text(text)
    path = folder / name
    path.write_text(problem)
    return path


def crane_urdf(name: str = "crane") -> str:
    """A crane of our own: a 1 m mast and a 1 m boom (5 cm thick) slewing +-3 rad about z 0.6 m
    up the mast (the boom along the base's x at 0 rad), named ``name``."""
    return f"""<?xml version="1.0"?><robot name="{name}">
 <link name="mast"><collision><geometry><box size="0.2 0.2 1"/></geometry></collision></link>
 <link name="boom"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.05 0.05"/>
  </geometry></collision></link>
 <joint name="slew" type="revolute"><parent link="mast"/><child link="boom"/><origin
  xyz="0 0 0.6"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="30" velocity="1"/>
 </joint>
</robot>"""


POST_URDF = """<?xml version="1.0"?><robot name="post"><link name="base"><collision><geometry>
 <box size="0.1 0.1 0.4"/></geometry></collision></link></robot>"""
"""A 0.1 x 0.1 x 0.4 m post, static."""

CRANE_CNTR = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="crane/boom" value="0.5"/></Offset>
 <Control name="crane/slew" eigValue="1.0"><DOF name="crane/boom" value="1.0"/></Control>
</ControlSet>"""
"""The crane's one control: slew = -3 + 6 c rad."""


def crane_and_post(folder: pathlib.Path, goal: str) -> pathlib.Path:
    """A current problem: the crane at the origin and a post 0.7 m along x at the boom's
    height; its query starts at c 0.25 (the boom along -1.5 rad, clear) and ends at ``goal``
    (c 0.5 lays the boom along +x, through the post; c 1.2 asks 4.2 rad, past the 3 rad limit,
    which Kautham's controls clamp)."""
    return write_problem(
        folder, {"crane.urdf": crane_urdf(), "crane.cntr": CRANE_CNTR, "post.urdf": POST_URDF},
        "crane.xml", f"""<?xml version="1.0"?><Problem>
 <Robot robot="crane.urdf"><Home X="0" Y="0" Z="0.5" WX="0" WY="0" WZ="1" TH="0"/></Robot>
 <Obstacle obstacle="post.urdf"><Home X="0.7" Y="0" Z="1.1" WX="0" WY="0" WZ="1" TH="0"/>
 </Obstacle>
 <Controls robot="crane.cntr"/>
 <Planner><Parameters><Name>omplRRTConnect</Name></Parameters>
  <Queries><Query><Init>0.25</Init><Goal>{goal}</Goal></Query></Queries></Planner>
</Problem>""")
