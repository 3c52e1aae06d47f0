"""The GUI Core against the real Kautham corpus: every problem loads, DH poses match tables
written here, scene objects land where <Location> says, bad inputs give one clear error."""
from __future__ import annotations

import json
import math
import pathlib
import shutil
import subprocess
import sys

import numpy as np
import pytest

from gui.core.plan import EntityStep, JointStep
from gui.core.translate import BuildDefaults, plan_problem
from odin_common.specs import CompositeSpec
from gui.errors import ProblemError, ShapeError
from gui.core.kautham.corpus import corpus_dir
from gui.core.kautham.problem import load_problem
from gui.core.kautham.robot_rob import read_dh_robot

# every test here reads the corpus: without it they skip (or fail under CI) like the rest
pytestmark = pytest.mark.usefixtures("kautham_dir")
KAUTHAM = corpus_dir() or pathlib.Path("/no-kautham-corpus")   # paths for collection only
LEGACY = KAUTHAM / "legacy_2012" / "examples"
CURRENT = KAUTHAM / "current_2025" / "demos"
SCRIPTS = pathlib.Path(__file__).resolve().parents[1] / "scripts"

LEGACY_PROBLEMS = ["Kuka_two_columns.xml", "Staubli_R6_two_columns.xml",
                   "Staubli_R6_two_columns_without_planner.xml",
                   "TX90_RHand_ICRA10_5PMD_TwoCan.xml", "TRO/2DRR_obstacle.xml"]
CURRENT_PROBLEMS = ["OMPL_geo_demos/TX90_IOC/OMPL_RRTConnect_TX90_TwoCan.xml",
                    "OMPL_ode_demos/Sphere/Sphere.xml", "OMPL_ode_demos/Sphere/k-PMPSphere.xml"]


# -- independent DH matrices (written here, not imported) -----------------------------------
def _rz(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def _rx(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def _tr(x, y, z):
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def modified(alpha, a, theta, d):     # Craig: Rx(alpha) Tx(a) Rz(theta) Tz(d)
    return _rx(alpha) @ _tr(a, 0, 0) @ _rz(theta) @ _tr(0, 0, d)


def standard(alpha, a, theta, d):     # Rz(theta) Tz(d) Tx(a) Rx(alpha)
    return _rz(theta) @ _tr(0, 0, d) @ _tr(a, 0, 0) @ _rx(alpha)


# TX90.rob, in degrees and mm as the file gives them: (alpha, a, theta, d)
TX90_DH = [(0, 0, 0, 0), (0, 0, 0, 478), (-90, 50, -90, 50), (0, 425, 90, 0),
           (90, 0, 0, 425), (-90, 0, 0, 0), (90, 0, 0, 100)]


def tx90_poses(base, q_deg):
    poses, T = [], base
    for k, (alpha, a, theta, d) in enumerate(TX90_DH):
        extra = q_deg[k - 1] if k else 0.0
        T = T @ modified(math.radians(alpha), a / 1000, math.radians(theta + extra), d / 1000)
        poses.append(T)
    return poses


def _axis_angle(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
    return m


# -- every problem loads -----------------------------------------------------------------------
@pytest.mark.parametrize("name", LEGACY_PROBLEMS)
def test_every_legacy_problem_loads_and_plans(name):
    problem = load_problem(LEGACY / name)
    assert problem.format == "2012"
    plan = plan_problem(problem)
    assert plan.robots and plan.steps
    for step in plan.steps:
        for m in step.bodies:
            assert len(m.orientation) == 4
            assert abs(np.linalg.norm(m.orientation) - 1) < 1e-9


@pytest.mark.parametrize("name", CURRENT_PROBLEMS)
def test_every_current_problem_loads_and_plans(name):
    problem = load_problem(CURRENT / name)
    assert problem.format == "current"
    assert plan_problem(problem).steps


def test_example_rob_template_is_refused_clearly():
    with pytest.raises(ProblemError) as info:
        read_dh_robot(LEGACY / "robots" / "example.rob")
    assert "example.rob" in str(info.value) and info.value.line is not None


# -- kinematics -------------------------------------------------------------------------------
def test_tx90_link_poses_match_the_dh_table_at_home_and_elsewhere():
    problem = load_problem(LEGACY / "Staubli_R6_two_columns.xml")
    robot = problem.robots[0]
    base = _tr(-0.3, 0.4, 0.0) @ _axis_angle((0, 0, 1), math.pi)   # <Home> of the problem
    np.testing.assert_allclose(robot.base_pose, base, atol=1e-12)
    for q_deg in ([0.0] * 6, [10.0, -20.0, 30.0, 45.0, -60.0, 90.0]):
        got = robot.model.link_poses(robot.base_pose, np.radians(q_deg))
        for mine, expected in zip(got, tx90_poses(base, q_deg)):
            np.testing.assert_allclose(mine, expected, atol=1e-12)


def test_hand_tree_with_pretrans_matches_the_table():
    problem = load_problem(LEGACY / "TX90_RHand_ICRA10_5PMD_TwoCan.xml")
    model = problem.robots[0].model
    names = [link.name for link in model.links]
    home = model.home()
    poses = model.link_poses(np.eye(4))
    tcp = tx90_poses(np.eye(4), [0.0] * 6)[-1]
    palm = tcp                                  # Palm: DH all zero, limits 0..0
    thumb = palm @ _tr(-0.003, 0.0271, 0.0)     # PreTrans, TH=0; limits -90..0: home 0
    thumb_base = thumb @ _tr(-0.006, 0.0869, 0.097) @ _axis_angle(
        (0.419, -0.419, 0.805), math.radians(102.31))
    prox = thumb_base @ modified(math.radians(-90), 0, 0, 0)
    # Thumb-Med's limits are -75..-4 degrees: Home clamps its 0 to -4 (Kautham clamps too).
    med = prox @ modified(0, 0.0678, math.radians(-4.0), 0)
    for name, expected in [("Palm", palm), ("Thumb", thumb), ("Thumb-Base", thumb_base),
                           ("Thumb-Prox", prox), ("Thumb-Med", med)]:
        np.testing.assert_allclose(poses[names.index(name)], expected, atol=1e-9)
    assert model.links[names.index("Thumb-Med")].home_value() == pytest.approx(
        math.radians(-4.0))
    assert len(home) == 24


def test_standard_dh_variant(tmp_path):
    robots = tmp_path / "robots"
    shutil.copytree(LEGACY / "robots" / "2DRR", robots / "2DRR")
    text = (LEGACY / "robots" / "2DRR.rob").read_text().replace('DHType="Modified"',
                                                                 'DHType="Standard"')
    text = text.replace('<DHPars alpha="0.0" a="100.0" theta="0.0" d="0.0"  >',
                        '<DHPars alpha="30.0" a="100.0" theta="10.0" d="20.0"  >', 1)
    (robots / "2DRR.rob").write_text(text)
    model = read_dh_robot(robots / "2DRR.rob", scale=2.0)
    q = [0.3, -0.4, 0.0]
    T0 = standard(0, 0, 0, 0)
    T1 = T0 @ standard(0, 0, q[0], 0)
    T2 = T1 @ standard(math.radians(30), 0.2, math.radians(10) + q[1], 0.04)
    T3 = T2 @ standard(0, 0.2, 0.0, 0)
    for got, expected in zip(model.link_poses(np.eye(4), q), [T0, T1, T2, T3]):
        np.testing.assert_allclose(got, expected, atol=1e-12)


def test_urdf_tx90_follows_its_joint_origins():
    problem = load_problem(CURRENT / CURRENT_PROBLEMS[0])
    robot = problem.robots[0]
    base = _tr(-0.2005, 0.2301, 0) @ _axis_angle((0, 0, 1), 3.1415926536)
    q = [0.1, 0.2, -0.3, 0.4, 0.5, -0.6]
    axes = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (0, 0, 1), (0, 1, 0), (0, 0, 1)]
    origins = [(0, 0, 0.478), (0.05, 0, 0), (0, 0.05, 0.425), (0, 0, 0), (0, 0, 0.425),
               (0, 0, 0.1)]
    T, expected = base, [base]
    for o, a, v in zip(origins, axes, q):
        T = T @ _tr(*o) @ _axis_angle(a, v)
        expected.append(T)
    for got, exp in zip(robot.model.link_poses(robot.base_pose, q), expected):
        np.testing.assert_allclose(got, exp, atol=1e-9)
    assert [link.mass for link in robot.model.links][0] == pytest.approx(10.733459)


# -- scene placement --------------------------------------------------------------------------
def _bodies(plan):
    out = {}
    for m in plan.bodies():
        out[m.id] = m
    return out


def test_cans_table_and_columns_land_where_location_says():
    plan = plan_problem(load_problem(LEGACY / "TX90_RHand_ICRA10_5PMD_TwoCan.xml"))
    bodies = _bodies(plan)
    q90 = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0, 0)
    for name, position in [("cangoal", (-0.47, 1.1, 0.56)), ("can", (-0.35, 1.18, 0.68)),
                           ("can_2", (-0.35, 1.18, 0.56))]:
        assert bodies[name].position == pytest.approx(position, abs=1e-12)
        assert bodies[name].orientation == pytest.approx(q90, abs=1e-12)
        assert bodies[name].geometry_only and bodies[name].triangle_count > 1000
    # The table scene: two Inventor cubes placed by their Transform nodes (mm -> m).
    table = next(b for k, b in bodies.items() if "sceneRevistaICRA09" in k)
    assert isinstance(table, CompositeSpec) and table.geometry_only
    top = table.parts[0]
    assert top.parameters == pytest.approx((1.5, 2.5, 0.01), rel=1e-6)
    assert top.position == pytest.approx((-0.75, 1.25, -0.011), abs=1e-9)

    plan = plan_problem(load_problem(LEGACY / "Kuka_two_columns.xml"))
    columns = _bodies(plan)[">" + ">".join(f"columns#{k}" for k in range(6))]
    assert columns.position == pytest.approx((0.25, 0.0, 0.0), abs=1e-12)
    # Location: TH=0 about x; the column's cylinder (radius 8 x scale 18 mm) stands along z.
    cylinder = columns.parts[1]
    assert cylinder.parameters == pytest.approx((0.144, 1.08), rel=1e-6)
    R = np.array(__import__("odin_common.rotations", fromlist=["x"]).quaternion_to_matrix(
        cylinder.orientation))
    assert abs(R[:, 2] @ (0, 0, 1)) == pytest.approx(1.0, abs=1e-3)


def test_current_format_obstacles_use_home_in_metres():
    plan = plan_problem(load_problem(CURRENT / CURRENT_PROBLEMS[0]))
    bodies = _bodies(plan)
    # can.urdf puts its mesh 0.065 m up its own z; Home rotates x by 90 degrees.
    assert bodies["can"].position == pytest.approx((-0.35, 1.18, 0.56), abs=1e-9)
    assert not bodies["can"].geometry_only and bodies["can"].mass == pytest.approx(0.05)
    assert bodies["irontable"].geometry_only
    assert bodies["irontable"].parameters == pytest.approx((1.5, 2.5, 0.01), rel=1e-6)
    assert bodies["irontable"].position == pytest.approx((-0.75, 1.25, -0.011), abs=1e-9)


def test_robot_plan_joints_motors_and_names():
    # at Home (all joints 0): a joint's stops are relative to the angle it is built at
    plan = plan_problem(load_problem(LEGACY / "Staubli_R6_two_columns.xml"),
                        BuildDefaults(start_at_query=False))
    joints = [s.spec for s in plan.steps if isinstance(s, JointStep)]
    base = _bodies(plan)["TX90/Base"]
    assert base.fixed and all(j.body1 and j.body2 for j in joints)   # no joint to the world
    hinges = [j for j in joints if j.type == 1]
    assert [j.body2 for j in hinges] == ["TX90/Shoulder", "TX90/ForeArm", "TX90/Elbow",
                                         "TX90/Arm", "TX90/Wrist", "TX90/Tcp"]
    # Shoulder: the joint axis is world z through the base, sent reversed because ODE's angle
    # is body1's (the parent's) rotation relative to body2; stops from the limits (+-180 deg).
    assert hinges[0].axis1 == pytest.approx((0, 0, -1), abs=1e-12)
    assert hinges[0].anchor[:2] == pytest.approx((-0.3, 0.4), abs=1e-12)
    assert dict((p, v) for p, _, v in hinges[0].parameters) == pytest.approx(
        {0: -math.pi, 1: math.pi})
    handle = plan.robots[0]
    assert handle.motor_ids == ["motor:" + j.default_id for j in hinges]


# -- bad input --------------------------------------------------------------------------------
@pytest.fixture
def corpus(tmp_path):
    """A writable copy of the 2012 examples (the originals are never touched)."""
    dest = tmp_path / "examples"
    shutil.copytree(LEGACY, dest)
    return dest


def _expect(path, *fragments, line=None, kind=ProblemError):
    with pytest.raises(kind) as info:
        plan_problem(load_problem(path))
    text = str(info.value)
    for f in fragments:
        assert f in text, text
    if line is not None:
        assert info.value.line == line, text
    assert "\n" not in text
    return info.value


def test_missing_problem_and_missing_robot_file(corpus):
    _expect(corpus / "nope.xml", "nope.xml", "not found")
    p = corpus / "Kuka_two_columns.xml"
    text = p.read_text()
    p.write_text(text.replace("robots/KukaLWR.rob", "robots/Missing.rob"))
    _expect(p, "Kuka_two_columns.xml", "Missing.rob", "not found",
            line=_line_of(text, "<Robot "))


def _line_of(text, fragment):
    return text[:text.index(fragment)].count("\n") + 1


def test_malformed_xml_names_the_line(corpus):
    p = corpus / "robots" / "TX90.rob"
    text = p.read_text()
    fragment = 'd="478.0"  ></DHPars>'
    p.write_text(text.replace(fragment, 'd="478.0"  ></DHPar>'))
    _expect(corpus / "Staubli_R6_two_columns.xml", "TX90.rob", "malformed XML",
            line=_line_of(text, fragment))


@pytest.mark.parametrize("element,old,new", [
    ("robots/TX90.rob", 'd="478.0"', 'd="0.01.0"'),             # a DH parameter
    ("robots/TX90.rob", 'Hi="147.5"', 'Hi="147.5.0"'),          # a limit
    ("Staubli_R6_two_columns.xml", 'Y="400.0"', 'Y="4OO"'),     # the robot's Home
    ("Kuka_two_columns.xml", 'X="250.0"', 'X="2 50"'),          # a scene's Location
])
def test_malformed_numbers_odin_uses_are_errors(corpus, element, old, new):
    target = corpus / element
    text = target.read_text()
    line = _line_of(text, old)
    target.write_text(text.replace(old, new, 1))
    problem = "Kuka_two_columns.xml" if "Kuka" in element else "Staubli_R6_two_columns.xml"
    _expect(corpus / problem, target.name, repr(new.split('"')[1]), line=line)


def test_quirks_in_values_odin_does_not_use_are_read_past(corpus):
    rob = corpus / "robots" / "TX90.rob"
    rob.write_text(rob.read_text().replace('rho_t="1.0"', 'rho_t="0.01.0"'))
    p = corpus / "Staubli_R6_two_columns.xml"
    p.write_text(p.read_text().replace(">0.1000000015<", ">0.01.0<")
                 .replace('<Init dim="6">', '<Init dim="six">'))
    assert plan_problem(load_problem(p)).steps


def test_unknown_dh_type(corpus):
    rob = corpus / "robots" / "KukaLWR.rob"
    text = rob.read_text()
    rob.write_text(text.replace('DHType="Modified"', 'DHType="Craig"'))
    _expect(corpus / "Kuka_two_columns.xml", "KukaLWR.rob", "Craig",
            line=_line_of(text, "<Robot "))


def test_a_link_file_that_does_not_parse(corpus):
    wrl = corpus / "robots" / "rtx90" / "elbow.wrl"
    text = wrl.read_text()
    wrl.write_text(text.replace("rotation 1 0 0", "bogusField 1 0 0", 1))
    error = _expect(corpus / "Staubli_R6_two_columns.xml", "elbow.wrl", "bogusField",
                    kind=ShapeError)
    assert error.line == _line_of(text, "rotation 1 0 0")


def test_problem_with_relative_parent_paths_and_free_flying_robot(corpus):
    (corpus / "TRO" / "free.xml").write_text(
        '<?xml version="1.0"?>\n<Problem>\n <Robot robot="../scenes/can.wrl" scale="1000">\n'
        '  <Home X="100" Y="0" Z="0" WX="0" WY="0" WZ="1" TH="90"/>\n </Robot>\n'
        ' <Scene scene="../robots/2DRR.rob" scale="1"><Location X="0" Y="500" Z="0" WX="0" '
        'WY="0" WZ="1" TH="0"/></Scene>\n</Problem>\n')
    plan = plan_problem(load_problem(corpus / "TRO" / "free.xml"))
    built = plan.steps[2]                  # after the world's Set World and Set Step
    entity = built.spec
    assert isinstance(built, EntityStep) and len(entity.objects) == 1
    assert entity.objects[0].fixed     # a free flyer without Kautham's physics: held
    assert entity.objects[0].position == pytest.approx((0.1, 0, 0))
    assert plan.robots[0].joint_keys == []
    # the .rob scene: a movable obstacle with joints but no fixed base joint
    joints = [s.spec for s in plan.steps if isinstance(s, JointStep)]
    assert joints and all(j.body1 != "" for j in joints)


# -- problem_info CLI ---------------------------------------------------------------------------
def _run(*args):
    return subprocess.run([sys.executable, str(SCRIPTS / "problem_info"), *map(str, args)],
                          capture_output=True, text=True, timeout=120)


def test_problem_info_prints_json():
    result = _run(LEGACY / "TX90_RHand_ICRA10_5PMD_TwoCan.xml")
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    bodies = {b["name"]: b for b in info["bodies"]}
    assert len([b for b in bodies if b.startswith("TX90 SAHand Right/")]) == 25
    assert bodies["can"]["position"] == pytest.approx([-0.35, 1.18, 0.68])
    assert bodies["TX90 SAHand Right/Palm"]["triangles"] > 10000
    assert bodies["TX90 SAHand Right/Palm"]["mass"] == 1.0
    joints = {j["name"]: j for j in info["joints"]}
    assert joints["TX90 SAHand Right/Shoulder"]["type"] == "hinge"
    assert joints["TX90 SAHand Right/Shoulder"]["limits"] == pytest.approx([-math.pi, math.pi])
    assert "TX90 SAHand Right/<base>" not in joints    # the base is a fixed body instead


def test_problem_info_does_not_import_rospy():
    code = ("import sys; from gui.tools.problem_info import main; import io, contextlib\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    main([{str(LEGACY / 'TRO/2DRR_obstacle.xml')!r}])\n"
            "assert 'rospy' not in sys.modules, 'rospy imported'")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_the_gui_core_imports_neither_rospy_nor_qt():
    code = ("import importlib, pkgutil, sys\n"
            "import gui.core\n"
            "names = [m.name for m in pkgutil.walk_packages(gui.core.__path__, 'gui.core.')]\n"
            "for name in names:\n"
            "    importlib.import_module(name)\n"
            "print(len(names))\n"
            "found = [m for m in ('rospy', 'PyQt5') if m in sys.modules]\n"
            "assert not found, f'gui.core imported {found}'")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert int(result.stdout) >= 12     # build, kinematics, model, paths, shapes, kautham.*


def test_problem_info_error_is_one_line_with_file_and_line(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text('<?xml version="1.0"?>\n<Problem>\n  <Robot robot="x.rob">\n</Problem>\n')
    result = _run(bad)
    assert result.returncode != 0
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and f"{bad}:4:" in lines[0], result.stderr


def test_collision_disabled_scene_objects_reach_the_world_as_no_collisions(corpus):
    (corpus / "nocollide.xml").write_text(
        '<?xml version="1.0"?>\n<Problem>\n'
        ' <Scene scene="scenes/can.wrl" scale="1000"><Location X="0" Y="0" Z="0" WX="0" '
        'WY="0" WZ="1" TH="0"/><Collision Enable="false"/></Scene>\n'
        ' <Scene scene="scenes/columns.iv" scale="18"><Location X="250" Y="0" Z="0" WX="1" '
        'WY="0" WZ="0" TH="0"/></Scene>\n</Problem>\n')
    bodies = _bodies(plan_problem(load_problem(corpus / "nocollide.xml")))
    assert bodies["can"].no_collisions
    assert not any(b.no_collisions for name, b in bodies.items() if name != "can")
    from odin_common.messages import object_message
    assert object_message(bodies["can"]).no_collisions
