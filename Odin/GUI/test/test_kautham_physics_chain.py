"""Fixed-base arms written here from Kautham's formats (a URDF, its .cntr, a problem; the
corpus has no such chain with physics) behave in Odin as in Kautham: started through the .cntr
and the limits, driven and resisted as Kautham's chain planner and the URDF say, carrying what
is attached, standing where a geometric problem puts them, and bad input one error naming the
file and line.

Expected values come from Kautham's own rules written out here (its control mapping, its ODE
environment's constants), not from the code under test."""
from __future__ import annotations

import pathlib

import numpy as np
import pytest

from gui.core.plan import EntityStep, JointStep, MotorStep, ObjectStep, WorldStep
from gui.core.translate import BuildDefaults, plan_problem
from gui.core.control_path import ControlRow, run_control_path
from gui.core.kautham.problem import load_problem
from gui.core.model import FIXED_BASE
from gui.errors import ProblemError
from kautham_files import KINEMATIC, SHELF, default_parameters, plan_steps, write_problem
from odin_common.interface import JointParameter, JointType, Shape


ARM = """<?xml version="1.0"?><robot name="arm">
 <link name="base"><inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0"
  ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.2 0.2 0.1"/></geometry>
  </collision></link>
 <link name="upper"><inertial><origin xyz="0.25 0 0"/><mass value="1"/><inertia ixx="0.001"
  iyy="0.021" izz="0.021" ixy="0" ixz="0" iyz="0"/></inertial><collision><origin
  xyz="0.25 0 0"/><geometry><box size="0.5 0.05 0.05"/></geometry></collision>
  <gazebo_placeholder/></link>
 <link name="fore"><inertial><origin xyz="0.2 0 0"/><mass value="0.5"/><inertia ixx="0.0005"
  iyy="0.007" izz="0.007" ixy="0" ixz="0" iyz="0"/></inertial><collision><origin
  xyz="0.2 0 0"/><geometry><box size="0.4 0.04 0.04"/></geometry><contact_coefficients
  mu="0.3" kp="20000" kd="50"/></collision></link>
 <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><origin
  xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="30" velocity="1.5"/>
  <dynamics damping="DAMPING" friction="FRICTION"/></joint>
 <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin
  xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-2.5" upper="2.5" effort="10"
  velocity="2"/></joint>
 <transmission name="t1"/>
</robot>"""

ARM_CNTR = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="arm/upper" value="0.5"/><DOF name="arm/fore" value="0.5"/></Offset>
 <Control name="arm/shoulder" eigValue="1.0"><DOF name="arm/upper" value="1.0"/></Control>
 <Control name="arm/elbow" eigValue="0.5"><DOF name="arm/fore" value="2.0"/></Control>
</ControlSet>"""

ARM_PROBLEM = """<?xml version="1.0"?><Problem>
 <Robot robot="arm.urdf"><Home X="0" Y="0" Z="0.05" WX="0" WY="0" WZ="1" TH="0"/></Robot>
 OBSTACLE
 <Controls robot="arm.cntr"/>
 ATTACH
 <Planner><Parameters><Name>PLANNER</Name>
  <Parameter name="PropagationStepSize">0.01</Parameter></Parameters>
  <Queries><Query>QUERY</Query></Queries></Planner>
</Problem>"""


def _arm(folder: pathlib.Path, damping=2.0, friction=0.5, query="<Init>0.75 0.25</Init>"
         "<Goal>0.25 0.75</Goal>", obstacle="", attach="", cntr=ARM_CNTR,
         planner="KPIECEChainPlanner") -> pathlib.Path:
    """The two-link arm's problem in ``folder`` (Kautham's chain planner: its physics; a
    planner without physics, such as omplRRTConnect, builds the URDF's own joints)."""
    urdf = ARM.replace("DAMPING", str(damping)).replace("FRICTION", str(friction))
    return write_problem(folder, {"arm.urdf": urdf, "arm.cntr": cntr}, "arm.xml",
                         ARM_PROBLEM.replace("QUERY", query).replace("OBSTACLE", obstacle)
                         .replace("ATTACH", attach).replace("PLANNER", planner))


def test_a_chain_starts_at_its_init_through_the_cntr_and_its_limits(tmp_path):
    problem = load_problem(_arm(tmp_path))
    robot = problem.robots[0]
    assert robot.kind == FIXED_BASE
    # p = 0.5 + map (c - 0.5) (the elbow's map is eigValue 0.5 x 2.0 = 1), then low + p span
    np.testing.assert_allclose(robot.start.joints, [-2 + 0.75 * 4, -2.5 + 0.25 * 5])
    np.testing.assert_allclose(robot.goal.joints, [-2 + 0.25 * 4, -2.5 + 0.75 * 5])
    plan = plan_problem(problem)
    handle = plan.robot()
    np.testing.assert_allclose(handle.built_at, robot.start.joints)
    joints = {s.key: s.spec for s in plan_steps(plan, JointStep)}
    base = joints["arm/<base>"]            # Kautham's chain: its base held by a fixed joint
    assert base.type == JointType.FIXED and base.body2 == ""
    # the stops relative to where the joint is built: [-2, 2] at 1.0
    stops = {p: v for p, _, v in joints["arm/upper"].parameters}
    assert stops == pytest.approx({JointParameter.LO_STOP: -3.0, JointParameter.HI_STOP: 1.0})


def test_urdf_physics_become_mass_properties_motor_limits_and_surfaces(tmp_path):
    plan = plan_problem(load_problem(_arm(tmp_path, planner=KINEMATIC)))
    bodies = {b.id: b for b in plan.bodies()}
    upper = bodies["arm/upper"]
    # one box at (0.25, 0, 0) in the link: the body sits there; the file's centre of mass
    # is there too, its tensor (plausible for a 1 kg 0.5 m box) kept, in the body's axes
    assert upper.center_of_mass == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)
    assert upper.inertia == pytest.approx((0.001, 0.021, 0.021, 0, 0, 0))
    fore = bodies["arm/fore"]
    assert fore.surface.friction == 0.3 and fore.surface.stiffness == 20000.0 \
        and fore.surface.damping == 50.0
    motors = {(s.joint_key, s.purpose): s for s in plan_steps(plan, MotorStep)}
    assert motors[("arm/upper", "")].spec.max_forces == (30.0,)          # effort
    assert motors[("arm/fore", "")].spec.max_forces == (10.0,)
    assert motors[("arm/upper", "friction")].spec.max_forces == (0.5,)
    damping = motors[("arm/upper", "damping")]
    assert damping.parameters == ((JointParameter.CFM, 1, 0.5),)       # 1 / 2 N m s/rad
    assert ("arm/fore", "damping") not in motors
    assert plan.robot().max_speeds == [1.5, 2.0]
    assert any(i.what == "<transmission>" for i in plan.ignored)


def test_kautham_s_chain_planner_drives_the_chain_as_its_environment_does(tmp_path, world):
    """Kautham's chain planner (PlanarChainEnvironment) drives every joint at up to 1 rad/s
    under 7 N m and its ODE environment reads no joint damping or friction, whatever the
    URDF says (here 30 and 10 N m, 1.5 and 2 rad/s, damping 2 N m s, friction 0.5 N m):
    each unused value is warned about."""
    plan = plan_problem(load_problem(_arm(tmp_path)))
    motors = {(s.joint_key, s.purpose): s.spec for s in plan_steps(plan, MotorStep)}
    assert set(motors) == {("arm/upper", ""), ("arm/fore", "")}
    assert all(spec.max_forces == (7.0,) for spec in motors.values())
    handle = plan.robot()
    assert handle.max_speeds == [1.0, 1.0] and handle.max_forces == [7.0, 7.0]
    assert any(i.what == '<dynamics> of joint "upper"' for i in plan.ignored)
    # both joints 2 rad and more from their targets: each turns at the environment's speed
    world.execute(plan)
    run_control_path(world, handle, [ControlRow(handle.goal.controls, 0.01)] * 30)
    rates = {j.id: j.rates[0] for j in world.core.joint_states() if j.rates}
    assert [abs(rates[j]) for j in handle.joint_ids] == pytest.approx([1.0, 1.0], rel=0.02)


@pytest.mark.parametrize("damping,friction", [(2.0, 0.5), (2.0, 0.0), (0.0, 0.5)])
def test_joint_damping_and_friction_resist_as_urdf_says(tmp_path, world, damping, friction):
    """With the driving motor off, a constant joint torque tau gives the shoulder a terminal
    speed (tau - friction) / damping (time constant I / b < 0.2 s); a torque below the
    friction does not move it. ODE's exact solver: QuickStep's default 20 iterations leave
    a chain's constraints loose (README, known limits)."""
    plan = plan_problem(load_problem(_arm(tmp_path, damping=damping, friction=friction,
                                          query="<Init>0.5 0.5</Init>", planner=KINEMATIC)))
    world.execute(plan)
    handle = plan.robot()
    core = world.core
    core.set_world_parameters(solver=1)
    shoulder, elbow = handle.joint_ids
    for motor in handle.motor_ids:
        core.set_joint_parameters(motor, [(JointParameter.MAX_FORCE, 1, 0.0)])
    core.set_joint_parameters(elbow, [(JointParameter.LO_STOP, 1, 0.0),
                                      (JointParameter.HI_STOP, 1, 0.0)])   # one rigid arm
    force = core.add_joint_force(shoulder, [0.4])
    world.run(1.0)
    rate = {j.id: j.rates for j in core.joint_states()}[shoulder][0]
    if friction > 0.4:
        assert abs(rate) < 1e-4
    else:
        assert rate == pytest.approx(0.4 / damping, rel=0.01)
    if damping == 0:
        return
    core.remove_joint_force(force)
    core.add_joint_force(shoulder, [0.9])
    world.run(1.0)
    rate = {j.id: j.rates for j in core.joint_states()}[shoulder][0]
    assert rate == pytest.approx((0.9 - friction) / damping, rel=0.01)


def test_a_control_row_servos_the_chain_to_its_configuration(tmp_path, world):
    plan = plan_problem(load_problem(_arm(tmp_path)))
    world.execute(plan)
    handle = plan.robot()
    run_control_path(world, handle, [ControlRow(handle.goal.controls, 0.5)] * 6)
    readings = {j.id: j.positions[0] for j in world.core.joint_states() if j.positions}
    reached = np.array([readings[j] for j in handle.joint_ids]) + handle.built_at
    np.testing.assert_allclose(reached, handle.goal.joints, atol=0.01)


def test_an_initially_attached_obstacle_rides_its_link(tmp_path, world):
    (tmp_path / "box.urdf").write_text(
        '<?xml version="1.0"?><robot name="box"><link name="b"><collision><geometry><box '
        'size="0.05 0.05 0.05"/></geometry></collision></link></robot>')
    problem = load_problem(_arm(
        tmp_path, obstacle='<Obstacle obstacle="box.urdf"><Home X="0.9" Y="0.5" Z="0.15" '
        'WX="0" WY="0" WZ="1" TH="0"/></Obstacle>',
        attach='<InitialAttachedObstacle robot="arm" link="fore" obstacle="box"/>'))
    plan = plan_problem(problem)
    joint = next(s.spec for s in plan_steps(plan, JointStep) if s.key == "arm/fore+box")
    assert joint.type == JointType.FIXED and joint.body2 == "box"
    box = next(b for b in plan.bodies() if b.id == "box")
    assert not box.geometry_only                       # a body, to ride the link
    world.execute(plan)
    handle = plan.robot()
    fore_before, box_before = world.position("arm/fore"), world.position("box")
    run_control_path(world, handle, [ControlRow(handle.goal.controls, 0.5)] * 4)
    fore, box_now = world.position("arm/fore"), world.position("box")
    assert np.linalg.norm(box_now - box_before) > 0.2           # it moved with the arm
    assert np.linalg.norm(box_now - fore) == pytest.approx(
        np.linalg.norm(box_before - fore_before), abs=0.005)   # at the same distance


def test_new_query_format_and_kautham_name(tmp_path):
    query = ('<RobotControl name="arm/shoulder" init="0.75" goal="0.25"/>'
             '<RobotControl name="arm/elbow" init="0.25" goal="0.75"/>')
    problem = load_problem(_arm(tmp_path, query=query))
    np.testing.assert_allclose(problem.robots[0].start.joints, [1.0, -1.25])
    np.testing.assert_allclose(problem.robots[0].goal.joints, [-1.0, 1.25])


# -- bad input: one error naming the file and line, nothing built ----------------------------------
def _line(path: pathlib.Path, fragment: str) -> int:
    text = path.read_text()
    return text[:text.index(fragment)].count("\n") + 1


@pytest.mark.parametrize("kwargs,file,fragment,message", [
    (dict(query="<Init>0.5</Init>"), "arm.xml", "<Init>", "1 values, the controls are 2"),
    (dict(query='<RobotControl name="arm/wrist" init="0" goal="1"/>'), "arm.xml",
     "arm/wrist", "is not a control"),
    (dict(cntr=ARM_CNTR.replace('"arm/fore" value="2.0"', '"arm/hand" value="2.0"')),
     "arm.cntr", "arm/hand", "nor a link"),
    (dict(cntr=ARM_CNTR.replace('"arm/fore" value="2.0"', '"robot2/fore" value="2.0"')),
     "arm.cntr", "robot2/fore", "no robot named"),
    (dict(attach='<InitialAttachedObstacle robot="arm" link="hand" obstacle="x"/>'),
     "arm.xml", "InitialAttachedObstacle", "no link \"hand\""),
])
def test_bad_physics_input_is_one_error_with_file_and_line(tmp_path, kwargs, file, fragment,
                                                           message):
    problem = _arm(tmp_path, **kwargs)
    with pytest.raises(ProblemError) as info:
        load_problem(problem)
    assert message in str(info.value) and file in str(info.value)
    assert info.value.line == _line(tmp_path / file, fragment)
    assert "\n" not in str(info.value)


def test_a_malformed_planner_value_odin_uses_is_an_error(tmp_path):
    problem = _arm(tmp_path)
    problem.write_text(problem.read_text().replace(">0.01<", ">0.0.1<"))
    with pytest.raises(ProblemError, match="0.0.1") as info:
        load_problem(problem)
    assert info.value.line == _line(problem, "PropagationStepSize")


# -- obstacles and the ground ---------------------------------------------------------------------
def test_collision_flags_and_2012_movable_scenes(tmp_path):
    (tmp_path / "box.urdf").write_text(
        '<?xml version="1.0"?><robot name="box"><link name="b"><inertial><mass value="2"/>'
        '</inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
        '</link></robot>')
    problem = _arm(tmp_path, obstacle='<Obstacle obstacle="box.urdf"><Home X="1" Y="1" Z="1" '
                   'WX="0" WY="0" WZ="1" TH="0"/><Collision enabled="false"/></Obstacle>')
    box = next(b for b in plan_problem(load_problem(problem)).bodies() if b.id == "box")
    assert box.no_collisions and box.mass == 2.0


def test_ground_option_for_any_problem_and_none_for_a_physics_one(tmp_path):
    problem = load_problem(_arm(tmp_path))
    without = plan_problem(problem, BuildDefaults(ground=False))
    # no Kautham physics: Odin's defaults, every one of them, and no ground plane
    assert not without.physics
    assert plan_steps(without, WorldStep)[0].parameters == default_parameters()
    assert not any(s.spec.shape == Shape.PLANE for s in plan_steps(without, ObjectStep))
    physics = plan_problem(problem)
    assert physics.physics and plan_steps(physics, WorldStep)[0].parameters["erp"] == 0.8


# -- a geometric problem's arm, a link without a mass ---------------------------------------------
TORSO = """<?xml version="1.0"?><robot name="torso"><link name="body"><collision><origin
 xyz="0 0 0.03"/><geometry><box size="0.24 0.24 0.06"/></geometry></collision></link></robot>"""
"""A static obstacle (no mass) around the lower 6 cm of the arm's base, clear of its links."""


def test_a_geometric_problems_arm_stands_where_its_base_is_put_inside_an_obstacle(tmp_path,
                                                                                 world):
    """A fixed-base arm whose base lies partly inside a static obstacle (as the YuMi's arm
    bases lie inside its torso), under a geometric planner: Kautham simulates nothing and the
    base stands where the problem puts it, so it is a fixed (kinematic) body, not a body held
    by a joint to the world that the obstacle's contact pushes away (the YuMi's arms moved
    13-20 mm, the whole arm with them). Under Kautham's chain planner (its physics) the base
    keeps the FIXED joint of Kautham's ODE environment."""
    (tmp_path / "torso.urdf").write_text(TORSO)
    torso = ('<Obstacle obstacle="torso.urdf"><Home X="0" Y="0" Z="0.05" WX="0" WY="0" WZ="1" '
             'TH="0"/></Obstacle>')
    plan = plan_problem(load_problem(_arm(tmp_path, obstacle=torso, planner=KINEMATIC)))
    assert not plan.physics
    entity = plan_steps(plan, EntityStep)[0].spec
    assert [o.fixed for o in entity.objects] == [True, False, False]
    assert "arm/<base>" not in {s.key for s in plan_steps(plan, JointStep)}
    world.execute(plan)
    links = ("arm/base", "arm/upper", "arm/fore")
    assert max(world.drift_mm(links, 2.0).values()) < 0.1
    physics = plan_problem(load_problem(_arm(tmp_path, obstacle=torso)))
    assert not plan_steps(physics, EntityStep)[0].spec.objects[0].fixed
    assert "arm/<base>" in {s.key for s in plan_steps(physics, JointStep)}


FINGER = """<?xml version="1.0"?><robot name="hand">
 <link name="palm"><inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001"
  ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.1 0.1 0.02"/>
  </geometry></collision></link>
 <link name="finger"><collision><origin xyz="0.05 0 0"/><geometry><box size="0.1 0.02 0.02"/>
  </geometry></collision></link>
 <joint name="knuckle" type="revolute"><parent link="palm"/><child link="finger"/><origin
  xyz="0.05 0 0"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="0.05"
  velocity="1"/></joint>
</robot>"""

FINGER_CNTR = """<?xml version="1.0"?><ControlSet>
 <Control name="hand/knuckle" eigValue="1"><DOF name="hand/finger" value="1"/></Control>
</ControlSet>"""


def test_a_urdf_link_without_inertial_weighs_its_shape_at_waters_density(tmp_path, world):
    """A finger without ``<inertial>`` (massless to URDF and to Kautham) on a 0.05 N m knuckle:
    4e-5 m^3 at 1000 kg/m^3 is 0.04 kg, 0.02 N m of gravity at its centre, which the held
    knuckle carries; at the 1 kg a link without a mass gets otherwise (0.49 N m) it sagged to
    its stop. An obstacle without a mass still gets 1 kg (Kautham's ODE environment's)."""
    problem = write_problem(
        tmp_path, {"hand.urdf": FINGER, "hand.cntr": FINGER_CNTR, "shelf.urdf": SHELF}, "hand.xml",
        '<?xml version="1.0"?><Problem><Robot robot="hand.urdf"><Home X="0" Y="0" Z="1" WX="0" '
        'WY="0" WZ="1" TH="0"/></Robot><Obstacle obstacle="shelf.urdf" movable="true"><Home '
        'X="0" Y="1" Z="0" WX="0" WY="0" WZ="1" TH="0"/></Obstacle><Controls robot="hand.cntr"/>'
        '<Planner><Parameters><Name>omplRRTConnect</Name></Parameters><Queries><Query><Init>'
        '0.5</Init><Goal>0.6</Goal></Query></Queries></Planner></Problem>')
    plan = plan_problem(load_problem(problem))
    bodies = {b.id: b for b in plan.bodies()}
    assert bodies["hand/finger"].mass == pytest.approx(1000 * 0.1 * 0.02 * 0.02)
    assert bodies["hand/palm"].mass == 0.5 and bodies["shelf"].mass == 1.0
    world.execute(plan)
    tip = world.position("hand/finger")
    world.run(2.0)
    assert np.linalg.norm(world.position("hand/finger") - tip) < 1e-3
