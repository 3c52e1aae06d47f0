"""Kautham problems behave in Odin as they do in Kautham: the physics demos of the corpus
(Sphere.xml, k-PMPSphere.xml) built on the world's Core, and the formats the corpus lacks (a
car, a chain, attachments, controls) on files written here from Kautham's formats.

Expected values come from Kautham's own rules written out here (its control mapping, its ODE
environment's constants), not from the code under test."""
from __future__ import annotations

import json
import math
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from gui.core.plan import EntityStep, JointStep, MotorStep, ObjectStep, StepSizeStep, WorldStep
from gui.core.translate import BuildDefaults, plan_problem
from gui.core.control_path import ControlRow, read_control_path, run_control_path
from gui.core.kautham.corpus import corpus_dir
from gui.core.kautham.problem import load_problem
from gui.core.model import CAR, FIXED_BASE, FREE_BODY, MOBILE
from gui.errors import PathFileError, ProblemError
from gui_core_world import CorePort, CoreWorld
from odin_common.interface import JointParameter, JointType, Shape
from odin_common.world_parameters import WorldParameters

KAUTHAM = corpus_dir() or pathlib.Path("/no-kautham-corpus")
SPHERE_DIR = KAUTHAM / "current_2025" / "demos" / "OMPL_ode_demos" / "Sphere"
SCRIPTS = pathlib.Path(__file__).resolve().parents[1] / "scripts"
WALL = 4.8 - 0.25          # the inner faces of the arena's walls (centre 4.8, 0.5 thick)


def _default_parameters() -> dict:
    """Odin's documented world parameters, gravity as a tuple (as a plan carries it)."""
    return {**WorldParameters().as_dict(), "gravity": WorldParameters().gravity}


def _steps(plan, kind):
    return [s for s in plan.steps if isinstance(s, kind)]


@pytest.fixture
def world():
    w = CoreWorld()
    yield w
    w.close()


# -- the corpus's ODE demos --------------------------------------------------------------------
@pytest.mark.usefixtures("kautham_dir")
@pytest.mark.parametrize("name", ["Sphere.xml", "k-PMPSphere.xml"])
def test_sphere_demos_get_kautham_world_ground_and_dynamic_obstacles(name):
    plan = plan_problem(load_problem(SPHERE_DIR / name))
    world, step = _steps(plan, WorldStep), _steps(plan, StepSizeStep)
    # Kautham's ODE world (gravity -9.8), the planner's ERP 0.5 and Max Contacts 3; its CFM
    # 0.3 would sink the 25 kg sphere metres deep: the world keeps Kautham's 1e-5, listed
    own = {"gravity": (0.0, 0.0, -9.8), "erp": 0.5, "cfm": 1e-5, "max_contacts": 3}
    assert set(world[0].own) == set(own)
    # every other world parameter at its documented default, whatever the world held
    assert world[0].parameters == {**_default_parameters(), **own}
    assert step[0].step == pytest.approx(0.03)
    assert any("Constraint Force Mixing" in i.what for i in plan.ignored)
    ground = _steps(plan, ObjectStep)[0].spec
    assert ground.shape == Shape.PLANE and ground.geometry_only and ground.position == (0, 0, 0)
    masses = {b.id: b.mass for b in plan.bodies() if not b.geometry_only}
    assert masses.pop("SphereDE") == 25.0
    assert masses["cubeDE1"] == 0.5 and masses["wallb1"] == 2.0   # their URDF masses
    assert len(masses) == len(plan.problem.obstacles)             # every obstacle a body


@pytest.mark.usefixtures("kautham_dir")
@pytest.mark.parametrize("name,init,goal", [
    ("Sphere.xml", (0.544, 0.433, 0.4), (0.426, 0.578, 0.4)),
    ("k-PMPSphere.xml", (0.349, 0.678, 0.4), (0.689, 0.242, 0.4))])
def test_the_sphere_starts_at_its_query_init_inside_the_walls(name, init, goal):
    problem = load_problem(SPHERE_DIR / name)
    robot = problem.robots[0]
    assert robot.kind == FREE_BODY
    # sp3.cntr: offsets 0.5, one control per X, Y, Z; <Limits> X, Y in [-5, 5], Z in [-1, 2]
    # around a Home without rotation: p = c, position = min + p (max - min)
    def where(c):
        return np.array([-5 + 10 * c[0], -5 + 10 * c[1], -1 + 3 * c[2]])
    np.testing.assert_allclose(robot.start.base_pose[:3, 3], where(init), atol=1e-12)
    np.testing.assert_allclose(robot.goal.base_pose[:3, 3], where(goal), atol=1e-12)
    assert np.all(np.abs(robot.start.base_pose[:2, 3]) < WALL)
    body = next(b for b in plan_problem(problem).bodies() if b.id == "SphereDE")
    np.testing.assert_allclose(body.position, where(init), atol=1e-12)   # not Home (10, 10)


@pytest.mark.usefixtures("kautham_dir")
@pytest.mark.parametrize("name", ["Sphere.xml", "k-PMPSphere.xml"])
def test_everything_rests_on_the_ground(world, name):
    plan = plan_problem(load_problem(SPHERE_DIR / name))
    world.execute(plan)
    world.run(2.0)
    for body in plan.bodies():
        if body.geometry_only:
            continue
        # boxes: half their height above the ground; the sphere: its radius
        half = body.parameters[0] if len(body.parameters) == 1 else body.parameters[2] / 2
        z = world.position(body.id)[2]
        assert z == pytest.approx(half, abs=0.003), f"{body.id} at z {z:.4f}, not resting"
        assert world.speed(body.id) < 1e-2, f"{body.id} still moves"
    sphere = world.position("SphereDE")
    assert np.all(np.abs(sphere[:2]) < WALL)


@pytest.mark.usefixtures("kautham_dir")
def test_a_control_row_pushes_the_sphere_toward_its_goal(world):
    plan = plan_problem(load_problem(SPHERE_DIR / "Sphere.xml"))
    world.execute(plan)
    world.run(1.0)
    handle = plan.robot()
    goal = handle.goal.base_pose[:2, 3]
    before = np.linalg.norm(world.position("SphereDE")[:2] - goal)
    results = run_control_path(CorePort(world), handle,
                               [ControlRow(handle.goal.controls, 0.3)] * 12)
    distances = [np.linalg.norm(r.base_position[:2] - goal) for r in results]
    assert distances[0] < before - 0.2            # the first row already moves it toward it
    assert distances[-1] < 0.02, distances        # and the rows bring it there
    # a force only along the controlled axes, none beyond m x 10 m/s^2 per axis
    force = np.array(results[0].actuation.forces[0][1])
    assert np.all(np.abs(force) <= 25.0 * 10.0 + 1e-9)


# -- problem_info ------------------------------------------------------------------------------
@pytest.mark.usefixtures("kautham_dir")
def test_problem_info_lists_what_odin_does_not_use_and_warns_once_each():
    result = subprocess.run([sys.executable, str(SCRIPTS / "problem_info"),
                             str(SPHERE_DIR / "Sphere.xml")], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    whats = [i["what"] for i in info["ignored"]]
    assert any('"Control Dimensions"' in w for w in whats)  # a planning parameter unused
    assert not any('"Goal Bias"' in w for w in whats)       # the planning bridge uses it
    assert any("Constraint Force Mixing" in w for w in whats)
    assert any("<inertial>" in w for w in whats)             # the placeholder inertias
    warnings = [line for line in result.stderr.splitlines()
                if line.startswith("problem_info: warning:")]
    assert len(warnings) == len(set(warnings)) == len(info["ignored"])
    robot = info["robots"][0]
    assert robot["kind"] == "free body" and robot["start"]["controls"] == [0.544, 0.433, 0.4]
    assert info["world"]["parameters"]["gravity"] == [0.0, 0.0, -9.8]


# -- legacy problems are built as before ---------------------------------------------------------
@pytest.mark.usefixtures("kautham_dir")
def test_a_2012_problem_gets_no_physics_and_is_built_at_its_query_start():
    plan = plan_problem(load_problem(KAUTHAM / "legacy_2012" / "examples" /
                                     "Staubli_R6_two_columns.xml"))
    assert not plan.physics
    # no physics of Kautham's, but the whole world still set: every default, no ground plane
    (world,), (step,) = _steps(plan, WorldStep), _steps(plan, StepSizeStep)
    assert world.parameters == _default_parameters() and world.own == ()
    assert (step.step, step.steps_per_cycle, step.rate) == (0.001, 40, 25.0)
    assert not any(s.spec.shape == Shape.PLANE for s in _steps(plan, ObjectStep))
    # where Kautham 2012 leaves it after loading: at the query's <Init>, which
    # Problem::createCSpaceFromFile collision-checks by moving the robots there
    handle = plan.robot()
    start = np.asarray(handle.start.joints, dtype=float)
    assert not np.allclose(start, handle.home)
    np.testing.assert_allclose(handle.built_at, start)
    bodies = {b.id: b for b in plan.bodies()}
    for body_id, position, _ in handle.situations(start):
        np.testing.assert_allclose(bodies[body_id].position, position, atol=1e-12)
    # --at-home: the .rob's Home, as the thesis's tool built every 2012 robot
    at_home = plan_problem(plan.problem, BuildDefaults(start_at_query=False)).robot()
    np.testing.assert_allclose(at_home.built_at, at_home.home)


# -- formats the corpus lacks: files written from Kautham's formats -------------------------------
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
    (folder / "car.urdf").write_text(
        '<?xml version="1.0"?><robot name="SimpleCar"><link name="base_link"><inertial><mass '
        'value="2"/><inertia ixx="0.02" iyy="0.06" izz="0.08" ixy="0" ixz="0" iyz="0"/>'
        '</inertial><collision><geometry><box size="0.6 0.3 0.1"/></geometry></collision>'
        f'</link>{wheels}</robot>')
    for name in ("cubeDE1", "wall1"):      # one Kautham lets a robot push, one it doesn't
        (folder / f"{name}.urdf").write_text(
            f'<?xml version="1.0"?><robot name="{name}"><link name="base"><inertial><mass '
            'value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" '
            'iyz="0"/></inertial><collision><geometry><box size="0.2 0.2 0.2"/></geometry>'
            '</collision></link></robot>')
    problem = folder / "car.xml"
    problem.write_text(
        '<?xml version="1.0"?><Problem><Robot robot="car.urdf"><Home X="0" Y="0" Z="0.11" '
        'WX="0" WY="0" WZ="1" TH="0"/></Robot><Obstacle obstacle="cubeDE1.urdf"><Home X="0" '
        'Y="3" Z="0.1" WX="0" WY="0" WZ="1" TH="0"/></Obstacle><Obstacle obstacle="wall1.urdf">'
        '<Home X="0" Y="-3" Z="0.1" WX="0" WY="0" WZ="1" TH="0"/></Obstacle><Planner>'
        f'<Parameters><Name>{planner}</Name><Parameter name="PropagationStepSize">0.01'
        '</Parameter></Parameters></Planner></Problem>')
    return problem


def _yaw(world) -> float:
    """rad: the car's heading about +z."""
    w, _, _, z = world.core.body_state("SimpleCar/base_link")[1]
    return 2 * math.atan2(z, w)


def test_a_kautham_car_gets_carenvironment_wheels_and_friction(tmp_path):
    plan = plan_problem(load_problem(_car(tmp_path)))
    handle = plan.robot()
    assert handle.kind == CAR
    entity = _steps(plan, EntityStep)[0].spec
    assert not any(o.fixed for o in entity.objects)            # a free, dynamic base
    wheels = [s.spec for s in _steps(plan, JointStep) if s.owner == "SimpleCar"]
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
    friction = {o.name: o.surface.friction for s in _steps(plan, (EntityStep, ObjectStep))
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
    port = CorePort(world)
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
    wheels = [s.spec for s in _steps(plan, JointStep) if s.owner == "SimpleCar"]
    for joint in wheels:     # reversed, as a robot's hinges: body1's turn relative to body2
        front = joint.anchor[0] > 0
        assert joint.axis1 == pytest.approx((0, 0, -1.0 if front else 1.0))
        assert joint.axis2 == pytest.approx((0, -1.0, 0))
    assert _steps(plan, ObjectStep)[0].spec.surface.friction is None    # the world's
    world.execute(plan)
    world.run(0.5)
    handle = plan.robot()
    port = CorePort(world)
    straight = run_control_path(port, handle, [ControlRow((0.5, 0.6), 1.0)])
    assert straight[0].base_position[0] == pytest.approx(0.32, abs=0.03)
    turn = run_control_path(port, handle, [ControlRow((1.0, 0.6), 0.5)] * 3)
    assert _yaw(world) > 0.1                                        # yawed left (+z)
    assert turn[-1].base_position[1] > 0.03                         # and went left


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


KINEMATIC = "omplRRTConnect"
"""A planner of Kautham's without physics: the problem's URDF is simulated as it says."""


def _arm(folder: pathlib.Path, damping=2.0, friction=0.5, query="<Init>0.75 0.25</Init>"
         "<Goal>0.25 0.75</Goal>", obstacle="", attach="", cntr=ARM_CNTR,
         planner="KPIECEChainPlanner") -> pathlib.Path:
    """The two-link arm's problem in ``folder`` (Kautham's chain planner: its physics; a
    planner without physics, such as omplRRTConnect, builds the URDF's own joints)."""
    (folder / "arm.urdf").write_text(ARM.replace("DAMPING", str(damping))
                                     .replace("FRICTION", str(friction)))
    (folder / "arm.cntr").write_text(cntr)
    problem = folder / "arm.xml"
    problem.write_text(ARM_PROBLEM.replace("QUERY", query).replace("OBSTACLE", obstacle)
                       .replace("ATTACH", attach).replace("PLANNER", planner))
    return problem


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
    joints = {s.key: s.spec for s in _steps(plan, JointStep)}
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
    motors = {(s.joint_key, s.purpose): s for s in _steps(plan, MotorStep)}
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
    motors = {(s.joint_key, s.purpose): s.spec for s in _steps(plan, MotorStep)}
    assert set(motors) == {("arm/upper", ""), ("arm/fore", "")}
    assert all(spec.max_forces == (7.0,) for spec in motors.values())
    handle = plan.robot()
    assert handle.max_speeds == [1.0, 1.0] and handle.max_forces == [7.0, 7.0]
    assert any(i.what == '<dynamics> of joint "upper"' for i in plan.ignored)
    # both joints 2 rad and more from their targets: each turns at the environment's speed
    world.execute(plan)
    run_control_path(CorePort(world), handle, [ControlRow(handle.goal.controls, 0.01)] * 30)
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
    run_control_path(CorePort(world), handle, [ControlRow(handle.goal.controls, 0.5)] * 6)
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
    joint = next(s.spec for s in _steps(plan, JointStep) if s.key == "arm/fore+box")
    assert joint.type == JointType.FIXED and joint.body2 == "box"
    box = next(b for b in plan.bodies() if b.id == "box")
    assert not box.geometry_only                       # a body, to ride the link
    world.execute(plan)
    handle = plan.robot()
    fore_before, box_before = world.position("arm/fore"), world.position("box")
    run_control_path(CorePort(world), handle, [ControlRow(handle.goal.controls, 0.5)] * 4)
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


def test_collision_flags_and_2012_movable_scenes(tmp_path):
    (tmp_path / "box.urdf").write_text(
        '<?xml version="1.0"?><robot name="box"><link name="b"><inertial><mass value="2"/>'
        '</inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
        '</link></robot>')
    problem = _arm(tmp_path, obstacle='<Obstacle obstacle="box.urdf"><Home X="1" Y="1" Z="1" '
                   'WX="0" WY="0" WZ="1" TH="0"/><Collision enabled="false"/></Obstacle>')
    box = next(b for b in plan_problem(load_problem(problem)).bodies() if b.id == "box")
    assert box.no_collisions and box.mass == 2.0


@pytest.mark.usefixtures("kautham_dir")
def test_2012_scene_movable_attribute_overrides_the_kind_of_file(tmp_path):
    examples = tmp_path / "examples"
    import shutil
    shutil.copytree(KAUTHAM / "legacy_2012" / "examples" / "scenes", examples / "scenes")
    shutil.copytree(KAUTHAM / "legacy_2012" / "examples" / "robots", examples / "robots")
    (examples / "p.xml").write_text(
        '<?xml version="1.0"?><Problem><Robot robot="robots/2DRR.rob"/>'
        '<Scene scene="scenes/columns.iv" scale="1" movable="true"><Location X="500" Y="0" '
        'Z="0" WX="0" WY="0" WZ="1" TH="0"/></Scene>'
        '<Scene scene="robots/2DRR.rob" scale="1" movable="false"><Location X="0" Y="900" '
        'Z="0" WX="0" WY="0" WZ="1" TH="0"/></Scene></Problem>')
    plan = plan_problem(load_problem(examples / "p.xml"))
    columns = next(b for b in plan.bodies() if "columns" in b.id)
    assert not columns.geometry_only and columns.mass == pytest.approx(1.0)
    scene_robot = [b for b in plan.bodies() if b.id.startswith("2DRR/")]
    assert scene_robot and all(b.geometry_only for b in scene_robot)
    # the .rob's <Weight> is a planner weight, not a mass: the links get the default 1 kg
    robot = [b for b in plan.bodies() if b.id.startswith("2D-Robot/")]
    assert all(b.mass == pytest.approx(1.0) for b in robot)
    assert any("<Weight>" in i.what for i in plan.ignored)


def test_ground_option_for_any_problem_and_none_for_a_physics_one(tmp_path):
    problem = load_problem(_arm(tmp_path))
    without = plan_problem(problem, BuildDefaults(ground=False))
    # no Kautham physics: Odin's defaults, every one of them, and no ground plane
    assert not without.physics
    assert _steps(without, WorldStep)[0].parameters == _default_parameters()
    assert not any(s.spec.shape == Shape.PLANE for s in _steps(without, ObjectStep))
    physics = plan_problem(problem)
    assert physics.physics and _steps(physics, WorldStep)[0].parameters["erp"] == 0.8


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

ROVER_CNTR = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="rover/X1" value="0"/><DOF name="rover/X2" value="0"/>
  <DOF name="rover/X3" value="0"/></Offset>
 <Control name="rover/x" eigValue="1"><DOF name="rover/X" value="1"/></Control>
 <Control name="rover/y" eigValue="1"><DOF name="rover/Y" value="1"/></Control>
 <Control name="rover/pan" eigValue="1"><DOF name="rover/mast" value="1"/></Control>
</ControlSet>"""


def _rover(folder: pathlib.Path) -> pathlib.Path:
    (folder / "rover.urdf").write_text(ROVER)
    (folder / "rover.cntr").write_text(ROVER_CNTR)
    problem = folder / "rover.xml"
    problem.write_text(
        '<?xml version="1.0"?><Problem><Robot robot="rover.urdf"><Limits name="X" min="-2" '
        'max="2"/><Limits name="Y" min="-2" max="2"/><Limits name="Z" min="0.05" max="0.05"/>'
        '<Home X="0" Y="0" Z="0.05" WX="0" WY="0" WZ="1" TH="0"/></Robot>'
        '<Controls robot="rover.cntr"/><Planner><Parameters><Name>omplRRTConnect</Name>'
        '</Parameters><Queries><Query><Init>0.5 0.5 0.5</Init><Goal>0.75 0.25 0.9</Goal>'
        '</Query></Queries></Planner></Problem>')
    return problem


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
    entity = _steps(plan, EntityStep)[0].spec
    assert not any(o.fixed for o in entity.objects)
    assert [s.spec.type for s in _steps(plan, JointStep)] == [JointType.HINGE]  # no base joint
    assert next(b for b in plan.bodies() if b.id == "rover/base").surface.friction == 0.1
    world.execute(plan)
    world.run(0.5)
    handle = plan.robot()
    results = run_control_path(CorePort(world), handle,
                               [ControlRow(handle.goal.controls, 0.5)] * 8)
    assert np.linalg.norm(results[-1].base_position[:2] - (1.0, -1.0)) < 0.03
    pan = {j.id: j.positions[0] for j in world.core.joint_states()}[handle.joint_ids[0]]
    assert pan + handle.built_at[0] == pytest.approx(1.2, abs=0.02)


CRATE = """<?xml version="1.0"?><robot name="crate"><link name="base"><inertial><mass
 value="0.05"/><inertia ixx="0.000683" iyy="0.000683" izz="0.000683" ixy="0" ixz="0" iyz="0"/>
 </inertial><collision><geometry><box size="0.3 0.3 0.3"/></geometry></collision></link>
</robot>"""

SHELF = """<?xml version="1.0"?><robot name="shelf"><link name="base"><collision><geometry>
 <box size="1 0.4 0.02"/></geometry></collision></link></robot>"""


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
    entity = _steps(plan, EntityStep)[0].spec
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
    results = run_control_path(CorePort(world), handle,
                               [ControlRow(handle.goal.controls, 0.5)] * 2)
    np.testing.assert_allclose(results[0].base_position[:2], (1.0, -1.0), atol=1e-6)
    world.run(1.0)
    np.testing.assert_allclose(world.position("rover/base")[:2], (1.0, -1.0), atol=1e-6)


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
    entity = _steps(plan, EntityStep)[0].spec
    assert [o.fixed for o in entity.objects] == [True, False, False]
    assert "arm/<base>" not in {s.key for s in _steps(plan, JointStep)}
    world.execute(plan)
    links = ("arm/base", "arm/upper", "arm/fore")
    assert max(world.drift_mm(links, 2.0).values()) < 0.1
    physics = plan_problem(load_problem(_arm(tmp_path, obstacle=torso)))
    assert not _steps(physics, EntityStep)[0].spec.objects[0].fixed
    assert "arm/<base>" in {s.key for s in _steps(physics, JointStep)}


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
    (tmp_path / "hand.urdf").write_text(FINGER)
    (tmp_path / "hand.cntr").write_text(FINGER_CNTR)
    (tmp_path / "shelf.urdf").write_text(SHELF)
    problem = tmp_path / "hand.xml"
    problem.write_text(
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


# -- a problem's world is the problem's (issue 28) ------------------------------------------------
@pytest.mark.usefixtures("kautham_dir")
def test_an_experiments_own_world_replaces_the_defaults_and_keeps_the_problems_other_values():
    from gui.core.world_settings import with_values
    plan = plan_problem(load_problem(SPHERE_DIR / "Sphere.xml"))
    plan.set_world(with_values(plan.world, {"solver": 1, "gravity": [0.0, 0.0, -1.62],
                                            "steps_per_cycle": 10, "free_run": True}))
    (world,), (step,) = _steps(plan, WorldStep), _steps(plan, StepSizeStep)
    assert world.parameters == {**_default_parameters(), "erp": 0.5, "cfm": 1e-5,
                                "max_contacts": 3, "solver": 1, "gravity": (0.0, 0.0, -1.62)}
    assert set(world.own) == {"gravity", "erp", "cfm", "max_contacts", "solver"}
    assert (step.step, step.steps_per_cycle) == (pytest.approx(0.03), 10)
    assert plan.world.parameters == world.parameters and plan.steps[0] is world


@pytest.mark.usefixtures("kautham_dir")
def test_a_robot_with_joints_ends_its_plan_held_by_its_servos_unless_asked_not_to():
    from gui.core.plan import HoldStep
    problem = load_problem(KAUTHAM / "legacy_2012" / "examples" / "Kuka_two_columns.xml")
    plan = plan_problem(problem)
    hold = plan.steps[-1]
    assert isinstance(hold, HoldStep) and hold.owner == "KukaLWR"
    assert hold.joint_keys == tuple(plan.robot().joint_keys) and len(hold.joint_keys) == 7
    assert not _steps(plan_problem(problem, BuildDefaults(hold_start=False)), HoldStep)
