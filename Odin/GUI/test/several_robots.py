"""Problems of our own with several robots and with a mobile base, in both Kautham formats,
for the tests of paths that drive them (issue 41, findings 2 and 4): the writers and what
their controls map to, written out here from Kautham's rules (not from the code under test).

- ``two_arms_2012``: a Kautham 2012 problem of two DH arms (``arm``, ``arm_2``, 1 m apart),
  each of two revolute joints and its own .rob control set of two controls, so the problem's
  control vector is 4 values, ``arm``'s then ``arm_2``'s (Kautham 2012's
  ``WorkSpace::moveRobotsTo``);
- ``two_arms_current``: the current format's two URDF arms (``left``, ``right``: two models,
  as a .cntr's "robot/" prefix names a model or an instance) sharing one .cntr of 2 controls,
  one per arm's joint: every robot maps the whole vector;
- ``rover``: a current mobile manipulator, a base its controls move in x and y (Kautham's SE3
  base, kind MOBILE) carrying a mast on a revolute pan joint, under a geometric planner (its
  base held kinematic where it is put).
"""
from __future__ import annotations

import math
import pathlib

CUBE_IV = "#Inventor V2.1 ascii\n\nSeparator { Cube { width 100 height 100 depth 100 } }\n"
"""A 0.1 m cube (2012 geometry is in mm)."""

JOINT_LIMIT_DEG = 90.0
"""Both 2012 arms' joints: -90..90 degrees, so a control c maps to -90 + 180 c degrees."""


def _dh_joint(name: str, movable: bool, parent: str = "", d: float = 0.0) -> str:
    limits = JOINT_LIMIT_DEG if movable else 0.0
    return (f'<Joint name="{name}" ivFile="cube.iv"><DHPars alpha="0" a="0" theta="0" '
            f'd="{d}"/><Description rotational="true" movable="{str(movable).lower()}"/>'
            f'<Limits Hi="{limits}" Low="{-limits}"/><Parent name="{parent}"/></Joint>\n')


def _rob(name: str) -> str:
    """A 2012 DH arm: a fixed base, joints J1 and J2 about z (0.15 m apart), controls c1 -> J1
    and c2 -> J2 (offset 0.5, eigValue 1: p = c)."""
    joints = (_dh_joint("Base", False) + _dh_joint("J1", True, "Base", d=150)
              + _dh_joint("J2", True, "J1", d=150))
    controls = ('<ControlSet size="2"><Offset><DOF name="J1" value="0.5"/><DOF name="J2" '
                'value="0.5"/></Offset><Control name="c1" eigValue="1.0"><DOF name="J1" '
                'value="1.0"/></Control><Control name="c2" eigValue="1.0"><DOF name="J2" '
                'value="1.0"/></Control></ControlSet>')
    return (f'<?xml version="1.0"?>\n<Robot name="{name}" DHType="Modified" robType="Chain">\n'
            f'<Joints size="3">{joints}</Joints>\n{controls}\n</Robot>\n')


def joint_2012(c: float) -> float:
    """rad: a 2012 arm's joint for control value c."""
    return math.radians(-JOINT_LIMIT_DEG + 2.0 * JOINT_LIMIT_DEG * c)


def two_arms_2012(folder: pathlib.Path) -> pathlib.Path:
    """The 2012 problem (module docstring); its query starts every control at 0.5 (the arms
    straight, joints 0) and ends at 0.75 (45 degrees)."""
    (folder / "cube.iv").write_text(CUBE_IV)
    (folder / "arm.rob").write_text(_rob("arm"))
    robots = ('<Robot robot="arm.rob"><Home X="0" Y="0" Z="0" WX="0" WY="0" WZ="1" TH="0"/>'
              '</Robot><Robot robot="arm.rob"><Home X="1000" Y="0" Z="0" WX="0" WY="0" '
              'WZ="1" TH="0"/></Robot>')
    path = folder / "two_arms_2012.xml"
    path.write_text(f'<?xml version="1.0"?>\n<Problem>\n{robots}\n<Planner><Parameters><Name>'
                    'PRM</Name></Parameters><Queries><Query><Init>0.5 0.5 0.5 0.5</Init><Goal>'
                    '0.75 0.75 0.75 0.75</Goal></Query></Queries></Planner>\n</Problem>\n')
    return path


def kps(folder: pathlib.Path, samples, name: str = "plan.kps") -> pathlib.Path:
    """A Kautham 2012 solution (``Planner::saveData``) whose solved query runs through
    ``samples`` (rows of control values) in order, from the first to the last."""
    rows = "".join(f"  <Sample>{' '.join(str(v) for v in row)}</Sample>\n" for row in samples)
    path = folder / name
    path.write_text(f'<?xml version="1.0"?>\n<Planner>\n <Queries>\n  <Query Init="0" '
                    f'Goal="{len(samples) - 1}" Solved="True">\n   <Result name="Path">'
                    f'{" ".join(str(k) for k in range(len(samples)))}</Result>\n  </Query>\n'
                    f' </Queries>\n <SampleSet dim="{len(samples[0])}" size="{len(samples)}">\n'
                    f'{rows} </SampleSet>\n</Planner>\n')
    return path


ARM_URDF = """<?xml version="1.0"?><robot name="{name}">
 <link name="base"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
 <link name="boom"><collision><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.04 0.04"/>
  </geometry></collision></link>
 <joint name="swing" type="revolute"><parent link="base"/><child link="boom"/><origin
  xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/>
 </joint>
</robot>"""
"""A current arm: a 0.4 m boom swinging -1..1 rad about z, 0.1 m up its base."""


def swing(c: float) -> float:
    """rad: a current arm's swing for its control value c (limits -1..1, p = c)."""
    return -1.0 + 2.0 * c


def two_arms_current(folder: pathlib.Path) -> pathlib.Path:
    """The current problem (module docstring): ``left`` at the origin, ``right`` 1 m along y,
    controls ``a`` -> left's swing, ``b`` -> right's, both starting at 0.5 (swing 0)."""
    for name in ("left", "right"):
        (folder / f"{name}.urdf").write_text(ARM_URDF.format(name=name))
    (folder / "arms.cntr").write_text(
        '<?xml version="1.0"?><ControlSet><Control name="a" eigValue="1"><DOF name="left/boom" '
        'value="1"/></Control><Control name="b" eigValue="1"><DOF name="right/boom" '
        'value="1"/></Control></ControlSet>')
    path = folder / "two_arms.xml"
    path.write_text(
        '<?xml version="1.0"?><Problem><Robot robot="left.urdf"><Home X="0" Y="0" Z="0.05" '
        'WX="0" WY="0" WZ="1" TH="0"/></Robot><Robot robot="right.urdf"><Home X="0" Y="1" '
        'Z="0.05" WX="0" WY="0" WZ="1" TH="0"/></Robot><Controls robot="arms.cntr"/><Planner>'
        '<Parameters><Name>omplRRTConnect</Name></Parameters><Queries><Query><Init>0.5 0.5'
        '</Init><Goal>0.75 0.25</Goal></Query></Queries></Planner></Problem>')
    return path


ROVER = """<?xml version="1.0"?><robot name="rover">
 <link name="base"><inertial><mass value="4"/><inertia ixx="0.033" iyy="0.057" izz="0.083"
  ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.4 0.3 0.1"/>
  </geometry></collision></link>
 <link name="mast"><inertial><origin xyz="0 0 0.15"/><mass value="0.5"/><inertia ixx="0.0039"
  iyy="0.0039" izz="0.0002" ixy="0" ixz="0" iyz="0"/></inertial><collision><origin
  xyz="0 0 0.15"/><geometry><box size="0.05 0.05 0.3"/></geometry></collision></link>
 <joint name="pan" type="revolute"><parent link="base"/><child link="mast"/><origin
  xyz="0 0 0.05"/><axis xyz="0 0 1"/><limit lower="-1.5" upper="1.5" effort="5"
  velocity="1"/></joint>
</robot>"""

ROVER_CNTR = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="rover/X1" value="0"/><DOF name="rover/X2" value="0"/>
  <DOF name="rover/X3" value="0"/></Offset>
 <Control name="rover/x" eigValue="1"><DOF name="rover/X" value="1"/></Control>
 <Control name="rover/y" eigValue="1"><DOF name="rover/Y" value="1"/></Control>
 <Control name="rover/pan" eigValue="1"><DOF name="rover/mast" value="1"/></Control>
</ControlSet>"""
"""Kautham's controls order the rover's DOFs X, Y (its base, world x and y: limits -2..2 m,
Home unrotated), then its pan joint; X1 = X2 = X3 = 0 is no rotation."""


def rover(folder: pathlib.Path) -> pathlib.Path:
    """The mobile manipulator (module docstring), built at its query's Init: base at
    (0, 0, 0.05) m, pan 0."""
    (folder / "rover.urdf").write_text(ROVER)
    (folder / "rover.cntr").write_text(ROVER_CNTR)
    path = folder / "rover.xml"
    path.write_text(
        '<?xml version="1.0"?><Problem><Robot robot="rover.urdf"><Limits name="X" min="-2" '
        'max="2"/><Limits name="Y" min="-2" max="2"/><Limits name="Z" min="0.05" max="0.05"/>'
        '<Home X="0" Y="0" Z="0.05" WX="0" WY="0" WZ="1" TH="0"/></Robot>'
        '<Controls robot="rover.cntr"/><Planner><Parameters><Name>omplRRTConnect</Name>'
        '</Parameters><Queries><Query><Init>0.5 0.5 0.5</Init><Goal>0.75 0.25 0.9</Goal>'
        '</Query></Queries></Planner></Problem>')
    return path
