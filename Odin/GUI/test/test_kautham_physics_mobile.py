"""Mobile robots written here from Kautham's formats (the corpus has no car and no mobile
base with an arm) behave in Odin as in Kautham: a car as Kautham's CarEnvironment builds and
drives it, or by its own frame outside Kautham's car planner; a mobile base its controls push
(Kautham's physics) or hold (a geometric planner's problem); and the control path files that
drive them.

Expected values come from Kautham's own rules written out here (its control mapping, its ODE
environment's constants), not from the code under test."""
from __future__ import annotations

import math
import pathlib

import numpy as np
import pytest

from gui.core.plan import EntityStep, JointStep, ObjectStep
from gui.core.translate import BuildDefaults, plan_problem
from gui.core.control_path import ControlRow, read_control_path, run_control_path
from gui.core.kautham.problem import load_problem
from gui.core.model import CAR, MOBILE
from gui.errors import PathFileError
from kautham_files import KINEMATIC, SHELF, plan_steps, write_problem
from several_robots import ROVER_CNTR
from odin_common.interface import JointParameter, JointType


# -- a car ----------------------------------------------------------------------------------------
WHEEL = ('<link name="{n}_wheel_link"><inertial><mass value="0.2"/><inertia ixx="0.0003" '
         'iyy="0.0006" izz="0.0003" ixy="0" ixz="0" iyz="0"/></inertial><collision><origin '
         'rpy="1.5707963 0 0"/><geometry><cylinder radius="0.08" length="0.04"/></geometry>'
         '</collision></link><joint name="{n}_wheel" type="continuous"><parent '
         'link="base_link"/><child link="{n}_wheel_link"/><origin xyz="{x} {y} -0.03"/><axis '
         'xyz="0 1 0"/></joint>')


def _car(folder: pathlib.Path, planner: str = "KPIECECarPlanner") -> pathlib.Path:
    """A car whose base's x is ahead and z up, its wheels turning about its y, on the ground."""
    wheels = "".join(WHEEL.format(n=n, x=x, y=y) for n, x, y in (
        ("front_left", 0.25, 0.2), ("front_right", 0.25, -0.2), ("back_right", -0.25, -0.2),
        ("back_left", -0.25, 0.2)))
    car = ('<?xml version="1.0"?><robot name="SimpleCar"><link name="base_link"><inertial><mass '
           'value="2"/><inertia ixx="0.02" iyy="0.06" izz="0.08" ixy="0" ixz="0" iyz="0"/>'
           '</inertial><collision><geometry><box size="0.6 0.3 0.1"/></geometry></collision>'
           f'</link>{wheels}</robot>')
    obstacles = {      # one Kautham lets a robot push, one it doesn't
        f"{name}.urdf": f'<?xml version="1.0"?><robot name="{name}"><link name="base"><inertial>'
        '<mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" '
        'iyz="0"/></inertial><collision><geometry><box size="0.2 0.2 0.2"/></geometry>'
        '</collision></link></robot>' for name in ("cubeDE1", "wall1")}
    return write_problem(
        folder, {"car.urdf": car, **obstacles}, "car.xml",
        '<?xml version="1.0"?><Problem><Robot robot="car.urdf"><Home X="0" Y="0" Z="0.11" '
        'WX="0" WY="0" WZ="1" TH="0"/></Robot><Obstacle obstacle="cubeDE1.urdf"><Home X="0" '
        'Y="3" Z="0.1" WX="0" WY="0" WZ="1" TH="0"/></Obstacle><Obstacle obstacle="wall1.urdf">'
        '<Home X="0" Y="-3" Z="0.1" WX="0" WY="0" WZ="1" TH="0"/></Obstacle><Planner>'
        f'<Parameters><Name>{planner}</Name><Parameter name="PropagationStepSize">0.01'
        '</Parameter></Parameters></Planner></Problem>')


def _yaw(world) -> float:
    """rad: the car's heading about +z."""
    w, _, _, z = world.core.body_state("SimpleCar/base_link")[1]
    return 2 * math.atan2(z, w)


def test_a_kautham_car_gets_carenvironment_wheels_and_friction(tmp_path):
    plan = plan_problem(load_problem(_car(tmp_path)))
    handle = plan.robot()
    assert handle.kind == CAR
    entity = plan_steps(plan, EntityStep)[0].spec
    assert not any(o.fixed for o in entity.objects)            # a free, dynamic base
    wheels = [s.spec for s in plan_steps(plan, JointStep) if s.owner == "SimpleCar"]
    assert [w.type for w in wheels] == [JointType.HINGE2] * 4
    # CarEnvironment's world axes, whatever the car's frame: steering about +z for the first
    # two wheels in link order and -z for the others, spin about +y
    assert [w.axis1 for w in wheels] == [(0, 0, 1.0)] * 2 + [(0, 0, -1.0)] * 2
    assert [w.axis2 for w in wheels] == [(0, 1.0, 0)] * 4
    for joint in wheels:
        assert dict(((p, a), v) for p, a, v in joint.parameters) == {
            (JointParameter.SUSPENSION_ERP, 1): 0.4, (JointParameter.SUSPENSION_CFM, 1): 0.8}
    assert len(handle.motor_ids) == 4
    # CarEnvironment's setupContact: robot on ground 5, a manipulable cube 0.1, the other
    # obstacles ("fixed") 0.1; Odin mixes two by the smaller
    friction = {o.name: o.surface.friction for s in plan_steps(plan, (EntityStep, ObjectStep))
                for o in (s.spec.objects if isinstance(s, EntityStep) else [s.spec])}
    assert friction == {"ground": 5.0, "cubeDE1": 0.1, "wall1": 0.1, **{
        f"SimpleCar/{n}": 5.0 for n in ("base_link", "front_left_wheel_link",
                                        "front_right_wheel_link", "back_right_wheel_link",
                                        "back_left_wheel_link")}}


def test_a_kautham_car_rolls_toward_world_minus_x_with_positive_wheel_speed(tmp_path, world):
    plan = plan_problem(load_problem(_car(tmp_path)))
    world.execute(plan)
    world.run(0.5)
    handle = plan.robot()
    port = world
    # steering 0 (c = 0.5), wheel speed -5 + 15 x 0.6 = 4 rad/s: the chassis turns at 4 rad/s
    # about +y relative to its wheels, so they roll toward -x: 0.32 m/s on 0.08 m wheels
    straight = run_control_path(port, handle, [ControlRow((0.5, 0.6), 1.0)])
    assert straight[0].base_position[0] == pytest.approx(-0.32, abs=0.03)
    assert abs(straight[0].base_position[1]) < 0.005
    # steering +0.5 rad: the first wheels (ahead, at +x) turn by -0.5 about +z, the others
    # by +0.5 (reached at 1/s), so the car yaws about +z and, going toward -x, heads for -y
    turn = run_control_path(port, handle, [ControlRow((1.0, 0.6), 0.5)] * 6)
    assert _yaw(world) > 0.3
    assert turn[-1].base_position[1] < -0.02
    back = run_control_path(port, handle, [ControlRow((0.5, 0.0), 1.0)])   # -5 rad/s
    assert back[0].base_position[0] > turn[-1].base_position[0] + 0.2


def test_a_car_outside_kauthams_car_planner_drives_forward_and_turns_left(tmp_path, world):
    """Where CarEnvironment does not drive it, a car's axes come from its own frame: its
    wheels' joint axis, steering along its z; a positive wheel speed rolls it ahead."""
    plan = plan_problem(load_problem(_car(tmp_path, KINEMATIC)), BuildDefaults(ground=True))
    wheels = [s.spec for s in plan_steps(plan, JointStep) if s.owner == "SimpleCar"]
    for joint in wheels:     # reversed, as a robot's hinges: body1's turn relative to body2
        front = joint.anchor[0] > 0
        assert joint.axis1 == pytest.approx((0, 0, -1.0 if front else 1.0))
        assert joint.axis2 == pytest.approx((0, -1.0, 0))
    assert plan_steps(plan, ObjectStep)[0].spec.surface.friction is None    # the world's
    world.execute(plan)
    world.run(0.5)
    handle = plan.robot()
    port = world
    straight = run_control_path(port, handle, [ControlRow((0.5, 0.6), 1.0)])
    assert straight[0].base_position[0] == pytest.approx(0.32, abs=0.03)
    turn = run_control_path(port, handle, [ControlRow((1.0, 0.6), 0.5)] * 3)
    assert _yaw(world) > 0.1                                        # yawed left (+z)
    assert turn[-1].base_position[1] > 0.03                         # and went left


# -- a mobile base with an arm --------------------------------------------------------------------
ROVER = """<?xml version="1.0"?><robot name="rover">
 <link name="base"><inertial><mass value="4"/><inertia ixx="0.033" iyy="0.057" izz="0.083"
  ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.4 0.3 0.1"/>
  </geometry><contact_coefficients mu="0.1"/></collision></link>
 <link name="mast"><inertial><origin xyz="0 0 0.15"/><mass value="0.5"/><inertia ixx="0.0039"
  iyy="0.0039" izz="0.0002" ixy="0" ixz="0" iyz="0"/></inertial><collision><origin
  xyz="0 0 0.15"/><geometry><box size="0.05 0.05 0.3"/></geometry></collision></link>
 <joint name="pan" type="revolute"><parent link="base"/><child link="mast"/><origin
  xyz="0 0 0.05"/><axis xyz="0 0 1"/><limit lower="-1.5" upper="1.5" effort="5"
  velocity="1"/></joint>
</robot>"""

def _rover(folder: pathlib.Path) -> pathlib.Path:
    return write_problem(
        folder, {"rover.urdf": ROVER, "rover.cntr": ROVER_CNTR}, "rover.xml",
        '<?xml version="1.0"?><Problem><Robot robot="rover.urdf"><Limits name="X" min="-2" '
        'max="2"/><Limits name="Y" min="-2" max="2"/><Limits name="Z" min="0.05" max="0.05"/>'
        '<Home X="0" Y="0" Z="0.05" WX="0" WY="0" WZ="1" TH="0"/></Robot>'
        '<Controls robot="rover.cntr"/><Planner><Parameters><Name>omplRRTConnect</Name>'
        '</Parameters><Queries><Query><Init>0.5 0.5 0.5</Init><Goal>0.75 0.25 0.9</Goal>'
        '</Query></Queries></Planner></Problem>')


def test_a_mobile_robot_has_a_free_base_its_controls_drive_with_its_arm(tmp_path, world):
    """A robot whose controls move its base (the .cntr names X, Y) and a joint: Kautham's
    mobile base, free and dynamic; a control row pushes the base to its (x, y) and servos the
    joint, on the ground Kautham's physics adds when asked (BuildDefaults.ground)."""
    problem = load_problem(_rover(tmp_path))
    robot = problem.robots[0]
    assert robot.kind == MOBILE
    # p = c for X, Y and the joint; X1 = X2 = X3 = 0: Kuffner's quaternion is the identity
    np.testing.assert_allclose(robot.start.base_pose, np.array(
        [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.05], [0, 0, 0, 1]]), atol=1e-12)
    np.testing.assert_allclose(robot.goal.base_pose[:3, 3], (-2 + 4 * 0.75, -2 + 4 * 0.25,
                                                             0.05), atol=1e-12)
    np.testing.assert_allclose(robot.goal.joints, [-1.5 + 0.9 * 3])
    plan = plan_problem(problem, BuildDefaults(ground=True))
    entity = plan_steps(plan, EntityStep)[0].spec
    assert not any(o.fixed for o in entity.objects)
    assert [s.spec.type for s in plan_steps(plan, JointStep)] == [JointType.HINGE]  # no base joint
    assert next(b for b in plan.bodies() if b.id == "rover/base").surface.friction == 0.1
    world.execute(plan)
    world.run(0.5)
    handle = plan.robot()
    results = run_control_path(world, handle,
                               [ControlRow(handle.goal.controls, 0.5)] * 8)
    assert np.linalg.norm(results[-1].base_position[:2] - (1.0, -1.0)) < 0.03
    pan = {j.id: j.positions[0] for j in world.core.joint_states()}[handle.joint_ids[0]]
    assert pan + handle.built_at[0] == pytest.approx(1.2, abs=0.02)


CRATE = """<?xml version="1.0"?><robot name="crate"><link name="base"><inertial><mass
 value="0.05"/><inertia ixx="0.000683" iyy="0.000683" izz="0.000683" ixy="0" ixz="0" iyz="0"/>
 </inertial><collision><geometry><box size="0.3 0.3 0.3"/></geometry></collision></link>
</robot>"""


def test_without_kautham_physics_only_the_controls_and_attachments_move_anything(tmp_path,
                                                                                world):
    """A geometric planner's problem (Kautham simulates nothing): the mobile robot's base is
    held where its controls put it (kinematic: Set Velocity and Set Position move it, gravity
    and contacts do not), its joint by its servo; an obstacle whose URDF gives a mass (an object
    a task may carry) is a body held to the world where the problem puts it, in mid-air too; one
    without a mass is static geometry. No ground: in Kautham nothing falls."""
    (tmp_path / "crate.urdf").write_text(CRATE)
    (tmp_path / "shelf.urdf").write_text(SHELF)
    problem_file = _rover(tmp_path)
    problem_file.write_text(problem_file.read_text().replace("<Controls", (
        '<Obstacle obstacle="crate.urdf"><Home X="1" Y="0" Z="1.2" WX="0" WY="0" WZ="1" '
        'TH="0"/></Obstacle><Obstacle obstacle="shelf.urdf"><Home X="-1" Y="0" Z="0.8" WX="0" '
        'WY="0" WZ="1" TH="0"/></Obstacle><Controls')))
    plan = plan_problem(load_problem(problem_file))
    assert not plan.physics
    entity = plan_steps(plan, EntityStep)[0].spec
    assert [o.fixed for o in entity.objects] == [True, False]       # the base, the mast
    bodies = {b.id: b for b in plan.bodies()}
    assert bodies["shelf"].geometry_only and not bodies["crate"].geometry_only
    assert list(plan.holds()) == ["crate"]
    world.execute(plan)
    before = {i: world.position(i) for i in ("rover/base", "rover/mast", "crate")}
    world.run(2.0)
    for body, position in before.items():
        assert np.linalg.norm(world.position(body) - position) < 1e-4, body
    # a control row moves the held base (its velocity) and servos the joint; it then stops
    handle = plan.robot()
    assert handle.base_held
    results = run_control_path(world, handle,
                               [ControlRow(handle.goal.controls, 0.5)] * 2)
    np.testing.assert_allclose(results[0].base_position[:2], (1.0, -1.0), atol=1e-6)
    world.run(1.0)
    np.testing.assert_allclose(world.position("rover/base")[:2], (1.0, -1.0), atol=1e-6)


# -- control path files ---------------------------------------------------------------------------
def test_control_path_rows_and_their_errors(tmp_path):
    path = tmp_path / "path.txt"
    path.write_text("# c1 c2 duration\n0.5 0.5 0.2\n\n0.1, 0.9, 1\n")
    rows = read_control_path(path, 2)
    assert rows == [ControlRow((0.5, 0.5), 0.2), ControlRow((0.1, 0.9), 1.0)]
    for text, line, fragment in [("0.5 0.5 0.2\n1.5 0.5 0.2\n", 2, r"not all in \[0, 1\]"),
                                 ("0.5 0.5 0\n", 1, "not positive"),
                                 ("0.5 0.5\n", 1, "2 controls and a duration")]:
        path.write_text(text)
        with pytest.raises(PathFileError, match=fragment) as info:
            read_control_path(path, 2)
        assert info.value.line == line and str(path) in str(info.value)
