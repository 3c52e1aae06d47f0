"""A mobile manipulator of our own under Kautham's physics, following a tracked path: its
planar base (Kautham's controls move its x and y, never its height or tilt) stays on its
floor while its arm swings, and the run's report tells the contacts it rests on (the base on
the ground) from those the path made (issue 41, finding 4)."""
from __future__ import annotations

import math
import pathlib

import numpy as np

from gui.core.execution import execute_tracked
from gui.core.kautham.problem import load_problem
from gui.core.kautham.solutions import read_solution
from gui.core.translate import BuildDefaults, plan_problem
from gui_core_world import CoreWorld
from kautham_files import write_problem
from odin_common.rotations import quaternion_to_matrix

# a 0.6 x 0.4 x 0.1 m cart of 6 kg; on it a mast turning about z carries a 0.8 m boom of 3 kg
# held out sideways at 0.45 m: swinging it shakes the cart as an arm on a mobile base does
CART = """<?xml version="1.0"?><robot name="cart">
 <link name="base"><inertial><mass value="6"/><inertia ixx="0.085" iyy="0.185" izz="0.26"
  ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.6 0.4 0.1"/>
  </geometry></collision></link>
 <link name="mast"><inertial><origin xyz="0.4 0 0.4"/><mass value="3"/><inertia ixx="0.03"
  iyy="0.23" izz="0.26" ixy="0" ixz="0" iyz="0"/></inertial><collision><origin
  xyz="0 0 0.2"/><geometry><box size="0.05 0.05 0.4"/></geometry></collision><collision>
  <origin xyz="0.4 0 0.42"/><geometry><box size="0.8 0.04 0.04"/></geometry></collision></link>
 <joint name="pan" type="revolute"><parent link="base"/><child link="mast"/><origin
  xyz="0 0 0.05"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="40"
  velocity="2"/></joint>
</robot>"""
CART_CNTR = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="cart/X1" value="0"/><DOF name="cart/X2" value="0"/>
  <DOF name="cart/X3" value="0"/></Offset>
 <Control name="cart/x" eigValue="1"><DOF name="cart/X" value="1"/></Control>
 <Control name="cart/y" eigValue="1"><DOF name="cart/Y" value="1"/></Control>
 <Control name="cart/pan" eigValue="1"><DOF name="cart/mast" value="1"/></Control>
</ControlSet>"""
HEIGHT = 0.05
"""m: the cart's base link origin above the ground, resting on it (half its 0.1 m)."""


def _cart_problem(folder: pathlib.Path) -> pathlib.Path:
    return write_problem(
        folder, {"cart.urdf": CART, "cart.cntr": CART_CNTR}, "cart.xml",
        '<?xml version="1.0"?><Problem><Robot robot="cart.urdf"><Limits name="X" min="-2" '
        f'max="2"/><Limits name="Y" min="-2" max="2"/><Limits name="Z" min="{HEIGHT}" '
        f'max="{HEIGHT}"/><Home X="0" Y="0" Z="{HEIGHT}" WX="0" WY="0" WZ="1" TH="0"/></Robot>'
        '<Controls robot="cart.cntr"/><Planner><Parameters><Name>omplRRTConnect</Name>'
        '</Parameters><Queries><Query><Init>0.5 0.5 0.5</Init><Goal>0.6 0.55 0.9</Goal>'
        '</Query></Queries></Planner></Problem>')


def _task(folder: pathlib.Path) -> pathlib.Path:
    """The cart drives 0.4 m along x and 0.2 m along y while its boom swings from 0 to 1.2
    rad, back to -1.2 and to 1.2 again (rows: x y z qx qy qz qw pan)."""
    rows = [(0.0, 0.0, 0.0), (0.2, 0.1, -1.2), (0.3, 0.15, 1.2), (0.4, 0.2, 1.2)]
    confs = "".join(f"<Conf>{x} {y} {HEIGHT} 0 0 0 1 {pan}</Conf>" for x, y, pan in rows)
    path = folder / "cart_task.xml"
    path.write_text(f"<Task><Transit>{confs}</Transit></Task>")
    return path


def _corners(position: np.ndarray, quaternion: np.ndarray) -> np.ndarray:
    """(4,) m: the heights of the cart's four bottom corners (its box 0.6 x 0.4 x 0.1 m)."""
    rotation = quaternion_to_matrix(quaternion)
    return np.array([(rotation @ (sx * 0.3, sy * 0.2, -0.05) + position)[2]
                     for sx in (-1, 1) for sy in (-1, 1)])


def test_a_planar_mobile_base_stays_on_its_floor_while_its_arm_swings(tmp_path):
    problem = load_problem(_cart_problem(tmp_path))
    plan = plan_problem(problem, BuildDefaults(ground=True))
    assert plan.physics
    world = CoreWorld()
    try:
        world.execute(plan)
        world.run(0.5)                      # settles on the ground
        base = plan.robot().bodies[0].body_id
        resting = _corners(*world.core.body_state(base)[:2])
        moved, tilt = [0.0], [0.0]

        def progress(t: float, total: float) -> None:
            position, quaternion = world.core.body_state(base)[:2]
            moved.append(float(np.max(np.abs(_corners(position, quaternion) - resting))))
            up = quaternion_to_matrix(quaternion)[:, 2]
            tilt.append(math.acos(min(1.0, up[2])))

        solution = read_solution(_task(tmp_path), problem)
        report = execute_tracked(world, plan, solution, progress=progress)
    finally:
        world.close()
    # on its floor to within 1 mm the whole way: no corner lifted or sunk more
    assert max(moved) < 1e-3, (max(moved), max(tilt))
    assert report.goal_error < 0.01
    # resting on the ground is support, not a collision the path made
    pairs = {frozenset((c["first"], c["second"])) for c in report.collisions}
    assert not any(base in " ".join(p) for p in pairs), report.collisions
    assert any("cart/base" in " ".join((c["first"], c["second"])) for c in report.support)
