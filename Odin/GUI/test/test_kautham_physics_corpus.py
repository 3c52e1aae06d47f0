"""The corpus's Kautham problems behave in Odin as they do in Kautham: the physics demos
(Sphere.xml, k-PMPSphere.xml) built on the world's Core and read by problem_info, the 2012
problems built as before, and a problem's world kept as the problem's.

Expected values come from Kautham's own rules written out here (its control mapping, its ODE
environment's constants), not from the code under test."""
from __future__ import annotations

import json
import pathlib
import shutil
import subprocess
import sys

import numpy as np
import pytest

from gui.core.plan import HoldStep, ObjectStep, StepSizeStep, WorldStep
from gui.core.translate import BuildDefaults, plan_problem
from gui.core.control_path import ControlRow, run_control_path
from gui.core.kautham.corpus import corpus_dir
from gui.core.kautham.problem import load_problem
from gui.core.model import FREE_BODY
from gui.core.world_settings import with_values
from kautham_files import default_parameters, plan_steps
from odin_common.interface import Shape

KAUTHAM = corpus_dir() or pathlib.Path("/no-kautham-corpus")
SPHERE_DIR = KAUTHAM / "current_2025" / "demos" / "OMPL_ode_demos" / "Sphere"
SCRIPTS = pathlib.Path(__file__).resolve().parents[1] / "scripts"
WALL = 4.8 - 0.25          # the inner faces of the arena's walls (centre 4.8, 0.5 thick)


# -- the corpus's ODE demos --------------------------------------------------------------------
@pytest.mark.usefixtures("kautham_dir")
@pytest.mark.parametrize("name", ["Sphere.xml", "k-PMPSphere.xml"])
def test_sphere_demos_get_kautham_world_ground_and_dynamic_obstacles(name):
    plan = plan_problem(load_problem(SPHERE_DIR / name))
    world, step = plan_steps(plan, WorldStep), plan_steps(plan, StepSizeStep)
    # Kautham's ODE world (gravity -9.8), the planner's ERP 0.5 and Max Contacts 3; its CFM
    # 0.3 would sink the 25 kg sphere metres deep: the world keeps Kautham's 1e-5, listed
    own = {"gravity": (0.0, 0.0, -9.8), "erp": 0.5, "cfm": 1e-5, "max_contacts": 3}
    assert set(world[0].own) == set(own)
    # every other world parameter at its documented default, whatever the world held
    assert world[0].parameters == {**default_parameters(), **own}
    assert step[0].step == pytest.approx(0.03)
    assert any("Constraint Force Mixing" in i.what for i in plan.ignored)
    ground = plan_steps(plan, ObjectStep)[0].spec
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
    results = run_control_path(world, handle,
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
                if line.startswith("problem_info: warning: not used: ")]
    assert len(warnings) == len(set(warnings)) == len(info["ignored"])
    # and the one line load_problem writes too: the sphere starts 5 cm into the ground
    others = [line for line in result.stderr.splitlines() if line not in warnings]
    assert len(others) == 1 and "SphereDE in ground by 50.0 mm" in others[0], others
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
    (world,), (step,) = plan_steps(plan, WorldStep), plan_steps(plan, StepSizeStep)
    assert world.parameters == default_parameters() and world.own == ()
    assert (step.step, step.steps_per_cycle, step.rate) == (0.001, 40, 25.0)
    assert not any(s.spec.shape == Shape.PLANE for s in plan_steps(plan, ObjectStep))
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


@pytest.mark.usefixtures("kautham_dir")
def test_2012_scene_movable_attribute_overrides_the_kind_of_file(tmp_path):
    examples = tmp_path / "examples"
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


# -- a problem's world is the problem's (issue 28) ------------------------------------------------
@pytest.mark.usefixtures("kautham_dir")
def test_an_experiments_own_world_replaces_the_defaults_and_keeps_the_problems_other_values():
    plan = plan_problem(load_problem(SPHERE_DIR / "Sphere.xml"))
    plan.set_world(with_values(plan.world, {"solver": 1, "gravity": [0.0, 0.0, -1.62],
                                            "steps_per_cycle": 10, "free_run": True}))
    (world,), (step,) = plan_steps(plan, WorldStep), plan_steps(plan, StepSizeStep)
    assert world.parameters == {**default_parameters(), "erp": 0.5, "cfm": 1e-5,
                                "max_contacts": 3, "solver": 1, "gravity": (0.0, 0.0, -1.62)}
    assert set(world.own) == {"gravity", "erp", "cfm", "max_contacts", "solver"}
    assert (step.step, step.steps_per_cycle) == (pytest.approx(0.03), 10)
    assert plan.world.parameters == world.parameters and plan.steps[0] is world


@pytest.mark.usefixtures("kautham_dir")
def test_a_robot_with_joints_ends_its_plan_held_by_its_servos_unless_asked_not_to():
    problem = load_problem(KAUTHAM / "legacy_2012" / "examples" / "Kuka_two_columns.xml")
    plan = plan_problem(problem)
    hold = plan.steps[-1]
    assert isinstance(hold, HoldStep) and hold.owner == "KukaLWR"
    assert hold.joint_keys == tuple(plan.robot().joint_keys) and len(hold.joint_keys) == 7
    assert not plan_steps(plan_problem(problem, BuildDefaults(hold_start=False)), HoldStep)
