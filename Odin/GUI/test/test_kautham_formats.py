"""Kautham's semantics for each kind of file its public corpus holds beyond the 93 files the
other tests use (issue 31), each on small files written here from the format: the 2012
free-flyers' controls, <Joint> without <Joints>, a rotation about a zero axis, URDF numbers read
leniently, Collada meshes, multi-robot queries, and the XML files that are not problems."""
from __future__ import annotations

import contextlib
import io
import json
import math
import pathlib
import re

import numpy as np
import pytest

from gui.tools.problem_info import main as problem_info_main
from gui.core.kautham.problem import load_problem
from gui.core.kautham.robot_rob import read_dh_robot
from gui.core.kautham.urdf import read_urdf
from gui.core.model import FIXED_BASE, FREE_BODY, MOBILE
from gui.core.shapes import read_shape
from gui.errors import ProblemError
from kautham_files import two_link_urdf as _urdf

ROOT = pathlib.Path(__file__).resolve().parents[3]
CUBE_IV = "#Inventor V2.1 ascii\n\nSeparator { Cube { width 100 height 100 depth 100 } }\n"


def problem_info(path):
    """problem_info's exit status, stdout and stderr, run in this process."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = problem_info_main([str(path), "--indent", "0"])
    return status, out.getvalue(), err.getvalue()


def _write(folder: pathlib.Path, name: str, text: str) -> pathlib.Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def _rob(name: str, joints: str, control_set: str = "", wrapped: bool = True) -> str:
    body = f"<Joints size=\"9\">{joints}</Joints>" if wrapped else joints
    return (f'<?xml version="1.0"?>\n<Robot name="{name}" DHType="Modified" robType="Chain">\n'
            f'{body}\n{control_set}\n</Robot>\n')


def _joint(name: str, movable: bool, parent: str = "", low: float = 0.0, high: float = 0.0,
           d: float = 0.0) -> str:
    return (f'<Joint name="{name}" ivFile="cube.iv"><DHPars alpha="0" a="0" theta="0" '
            f'd="{d}"/><Description rotational="true" movable="{str(movable).lower()}"/>'
            f'<Limits Hi="{high}" Low="{low}"/><Parent name="{parent}"/></Joint>\n')


def _control_set(offsets: dict, controls: dict) -> str:
    """controls: {control name: {dof: value}}."""
    offset = "".join(f'<DOF name="{k}" value="{v}"/>' for k, v in offsets.items())
    body = "".join(f'<Control name="{c}" eigValue="1.0">'
                   + "".join(f'<DOF name="{k}" value="{v}"/>' for k, v in dofs.items())
                   + "</Control>" for c, dofs in controls.items())
    return f"<ControlSet size=\"{len(controls)}\"><Offset>{offset}</Offset>{body}</ControlSet>"


def _problem_2012(robots: str, init: str) -> str:
    return (f'<?xml version="1.0"?>\n<Problem>\n{robots}\n<Planner><Parameters><Name>PRM'
            f'</Name></Parameters><Queries><Query><Init>{init}</Init><Goal>{init}</Goal>'
            f'</Query></Queries></Planner>\n</Problem>\n')


# -- 2012 free-flyers -------------------------------------------------------------------------

def test_a_2012_free_flyer_whose_base_joint_is_marked_movable_moves_by_its_base_controls(
        tmp_path):
    """table.rob's kind: one "Base" joint marked movable and a control set over X and Z.
    Kautham gives a robot of n joints n - 1 joint coordinates (the first is the base), and its
    2012 offsets of the DOFs the set does not list are 0: X1 = X2 = X3 = 0 is no rotation."""
    _write(tmp_path, "cube.iv", CUBE_IV)
    _write(tmp_path, "table.rob", _rob("table", _joint("Base", movable=True), _control_set(
        {"X": 0.5, "Z": 0.5}, {"x": {"X": 1.0}, "z": {"Z": 1.0}})))
    problem = _write(tmp_path, "p.xml", _problem_2012(
        '<Robot robot="table.rob"><Limits name="X" min="-125" max="125"/>'
        '<Limits name="Z" min="-115" max="115"/>'
        '<Home X="-40" Y="0" Z="0" WX="0" WY="0" WZ="1" TH="0"/></Robot>', "1.0 0.5"))
    loaded = load_problem(problem)
    robot = loaded.instances[0]
    assert robot.model.movable_links() == [] and robot.kind == FREE_BODY
    assert robot.controls.names == ("x", "z")
    np.testing.assert_allclose(robot.start.base_pose[:3, 3], [0.125, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(robot.start.base_pose[:3, :3], np.eye(3), atol=1e-12)
    status, out, err = problem_info(problem)
    assert status == 0, err


def test_a_2012_control_set_leaves_the_joints_it_does_not_list_at_their_low_limit(tmp_path):
    """Kautham 2012 zeroes the offsets before reading <Offset>: a joint no control and no
    offset names has p = 0, its low limit (current Kautham's default is 0.5)."""
    _write(tmp_path, "cube.iv", CUBE_IV)
    joints = (_joint("Base", False) + _joint("J1", True, "Base", -90, 90, d=100)
              + _joint("J2", True, "J1", -45, 30))
    _write(tmp_path, "arm.rob", _rob("arm", joints, _control_set(
        {"J1": 0.5}, {"c": {"J1": 1.0}})))
    problem = _write(tmp_path, "p.xml", _problem_2012('<Robot robot="arm.rob"/>', "1.0"))
    robot = load_problem(problem).instances[0]
    np.testing.assert_allclose(robot.start.joints, [math.pi / 2, -math.pi / 4], atol=1e-12)


def test_a_2012_robot_that_is_a_bare_shape_has_kautham_s_six_base_controls(tmp_path):
    """Kautham 2012's FREEFLY robot: controls X, Y, Z, X1, X2, X3, identity, offsets 0.5."""
    _write(tmp_path, "cube.iv", CUBE_IV)
    problem = _write(tmp_path, "p.xml", _problem_2012(
        '<Robot robot="cube.iv"><Limits name="X" min="0" max="1000"/>'
        '<Limits name="Y" min="0" max="500"/><Home X="0" Y="0" Z="0" WX="0" WY="0" WZ="1" '
        'TH="0"/></Robot>', "1.0 0.5 0.5 0 0 0"))
    robot = load_problem(problem).instances[0]
    assert robot.controls.names == ("X", "Y", "Z", "X1", "X2", "X3")
    np.testing.assert_allclose(robot.start.base_pose[:3, 3], [1.0, 0.25, 0.0], atol=1e-12)
    np.testing.assert_allclose(robot.start.base_pose[:3, :3], np.eye(3), atol=1e-12)


# -- <Joint> without <Joints> -----------------------------------------------------------------

def test_joint_elements_directly_under_robot_are_the_robot_s_joints(tmp_path):
    _write(tmp_path, "cube.iv", CUBE_IV)
    joints = _joint("Base", False) + _joint("Shoulder", True, "Base", -22.5, 22.5, d=100)
    bare = read_dh_robot(_write(tmp_path, "bare.rob", _rob("hand", joints, wrapped=False)))
    wrapped = read_dh_robot(_write(tmp_path, "wrapped.rob", _rob("hand", joints)))
    assert [link.name for link in bare.links] == ["Base", "Shoulder"]
    assert bare.links[1].limits == wrapped.links[1].limits
    np.testing.assert_array_equal(bare.links[1].pre, wrapped.links[1].pre)


def test_joint_elements_both_inside_joints_and_under_robot_are_refused(tmp_path):
    _write(tmp_path, "cube.iv", CUBE_IV)
    text = _rob("hand", _joint("Base", False)).replace(
        "</Joints>", "</Joints>" + _joint("Extra", True, "Base", -1, 1))
    path = _write(tmp_path, "both.rob", text)
    with pytest.raises(ProblemError, match="both inside <Joints> and directly under"):
        read_dh_robot(path)


# -- a rotation about a zero axis -------------------------------------------------------------

def test_a_home_rotation_about_a_zero_axis_is_no_rotation_and_is_warned_about(tmp_path):
    """Kautham's SE3Conf::fromAxisToQuaternion multiplies the axis by sin(TH/2): a zero axis
    leaves a quaternion with no vector part, no rotation."""
    _write(tmp_path, "r.urdf", _urdf())
    problem = _write(tmp_path, "p.xml", '<?xml version="1.0"?>\n<Problem>\n'
                     '<Robot robot="r.urdf"><Home X="0.5" Y="0" Z="0.7" WX="0" WY="0" WZ="0" '
                     'TH="1.5707"/></Robot>\n</Problem>\n')
    loaded = load_problem(problem)
    pose = loaded.instances[0].base_pose
    np.testing.assert_allclose(pose[:3, :3], np.eye(3))
    np.testing.assert_allclose(pose[:3, 3], [0.5, 0.0, 0.7])
    assert any("zero axis" in i.why and i.line == 3 for i in loaded.ignored)
    status, out, err = problem_info(problem)
    assert status == 0, err
    assert [i["line"] for i in json.loads(out)["ignored"] if "zero axis" in i["why"]] == [3]


# -- URDF numbers read as Kautham reads them ---------------------------------------------------

def test_a_urdf_number_followed_by_other_text_is_its_leading_number_with_a_warning(tmp_path):
    """tiago_base_wheels.urdf's ixx="0.46 5": pugixml's as_double is C's strtod."""
    model = read_urdf(_write(tmp_path, "r.urdf", _urdf(ixx="0.46 5")))
    assert model.links[0].inertial.tensor[0, 0] == pytest.approx(0.46)
    notes = [i for i in model.ignored if 'ixx="0.46 5"' in i.what]
    assert len(notes) == 1 and "0.46" in notes[0].why and notes[0].line == 4


def test_a_urdf_number_that_does_not_start_with_a_number_is_an_error(tmp_path):
    with pytest.raises(ProblemError, match="'abc' is not a number") as info:
        read_urdf(_write(tmp_path, "r.urdf", _urdf(ixx="abc")))
    assert info.value.line == 4


def test_numbers_of_problem_and_rob_files_stay_strict(tmp_path):
    _write(tmp_path, "r.urdf", _urdf())
    problem = _write(tmp_path, "p.xml", '<?xml version="1.0"?>\n<Problem>\n'
                     '<Robot robot="r.urdf"><Home X="0.5 1"/></Robot>\n</Problem>\n')
    with pytest.raises(ProblemError, match="'0.5 1' is not a number"):
        load_problem(problem)


# -- Collada ---------------------------------------------------------------------------------

COLLADA = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="centimeter" meter="0.01"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries><geometry id="g" name="g"><mesh>
    <source id="g-pos"><float_array id="g-pos-array" count="12">0 0 0 1 0 0 0 2 0 0 0 3
      </float_array><technique_common><accessor source="#g-pos-array" count="4" stride="3">
      <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="g-vtx"><input semantic="POSITION" source="#g-pos"/></vertices>
    <triangles count="4"><input semantic="VERTEX" source="#g-vtx" offset="0"/>
      <p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles>
    <lines count="1"><input semantic="VERTEX" source="#g-vtx"/><p>0 1</p></lines>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n">
    <matrix>1 0 0 10 0 1 0 0 0 0 1 0 0 0 0 1</matrix>
    <instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""


def test_a_collada_mesh_is_read_with_its_node_transforms_and_without_unit_or_up_axis(
        tmp_path):
    """As Kautham's assimp import: node transforms applied, the root's unit and up axis not
    (a URDF scales such meshes itself); <lines> hold no surface and are left out, even one that
    pycollada alone refuses (an <input> without offset, as the IOC lab's cupboard has)."""
    shape = read_shape(_write(tmp_path, "tetra.dae", COLLADA))
    assert shape.triangle_count == 4 and not shape.primitives
    np.testing.assert_allclose(shape.mesh.vertices.min(axis=0), [10.0, 0.0, 0.0])
    np.testing.assert_allclose(shape.mesh.vertices.max(axis=0), [11.0, 2.0, 3.0])


def test_a_urdf_mirror_scale_mirrors_the_mesh_and_keeps_its_triangles_outward(tmp_path):
    """TIAGo's arm meshes: <mesh scale="1 -1 -1"> (and "1 1 -1", a true mirror)."""
    _write(tmp_path, "tetra.dae", COLLADA)
    plain = read_shape(tmp_path / "tetra.dae")
    for factors in ("1 -1 -1", "1 1 -1", "2 1 0.5"):
        geometry = f'<mesh filename="tetra.dae" scale="{factors}"/>'
        model = read_urdf(_write(tmp_path, "m.urdf", _urdf(geometry=geometry)))
        mesh = model.links[0].shape.mesh
        f = np.array([float(v) for v in factors.split()])
        np.testing.assert_allclose(mesh.vertices, plain.mesh.vertices * f)
        if np.prod(f) < 0:
            np.testing.assert_array_equal(mesh.triangles, plain.mesh.triangles[:, ::-1])
        else:
            np.testing.assert_array_equal(mesh.triangles, plain.mesh.triangles)


def test_a_primitive_cannot_be_scaled_unevenly_but_can_be_mirrored(tmp_path):
    _write(tmp_path, "cube.iv", CUBE_IV)
    mirrored = read_urdf(_write(tmp_path, "m.urdf", _urdf(
        geometry='<mesh filename="cube.iv" scale="0.001 0.001 -0.001"/>')))
    box = mirrored.links[0].shape.primitives[0]
    assert box.parameters == pytest.approx((0.1, 0.1, 0.1))
    assert np.linalg.det(box.pose[:3, :3]) == pytest.approx(1.0)
    with pytest.raises(ProblemError, match="cannot be scaled by"):
        read_urdf(_write(tmp_path, "u.urdf", _urdf(
            geometry='<mesh filename="cube.iv" scale="1 2 1"/>')))


def test_pycollada_is_pinned_in_the_requirements_at_the_version_installed():
    import collada
    from importlib.metadata import version
    pins = re.findall(r"^pycollada==(\S+)$", (ROOT / "tools" / "requirements.txt").read_text(),
                      re.M)
    assert pins == [version("pycollada")] and collada.Collada is not None


# -- multi-robot queries ----------------------------------------------------------------------

def test_a_2012_query_for_two_robots_is_split_between_them_in_robot_order(tmp_path):
    """IOC_Remote_Cell.xml's kind: a 13-value <Init> for robots of 7 and 6 controls (Kautham
    2012's WorkSpace::moveRobotsTo gives each robot its next getNumControls() values)."""
    _write(tmp_path, "cube.iv", CUBE_IV)
    joints = _joint("Base", False) + _joint("J1", True, "Base", -90, 90)
    _write(tmp_path, "a.rob", _rob("a", joints, _control_set(
        {"J1": 0.5, "Y": 0.5}, {"y": {"Y": 1.0}, "j": {"J1": 1.0}})))
    _write(tmp_path, "b.rob", _rob("b", joints, _control_set({"J1": 0.5}, {"j": {"J1": 1.0}})))
    robots = ('<Robot robot="a.rob"><Limits name="Y" min="-1000" max="1000"/></Robot>'
              '<Robot robot="b.rob"><Home X="1000"/></Robot>')
    loaded = load_problem(_write(tmp_path, "p.xml", _problem_2012(robots, "1.0 0.75 0.25")))
    a, b = loaded.instances
    np.testing.assert_allclose(a.start.base_pose[:3, 3], [0.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(a.start.joints, [math.pi / 4])
    np.testing.assert_allclose(b.start.joints, [-math.pi / 4])
    np.testing.assert_allclose(b.start.base_pose[:3, 3], [1.0, 0.0, 0.0])
    short = load_problem(_write(tmp_path, "q.xml", _problem_2012(robots, "1.0 0.75")))
    assert all(i.start is None for i in short.instances)
    assert any("2 values, the controls are 3 (y, j, j)" in i.why for i in short.ignored)


def test_kautham_reads_the_first_controls_element_only(tmp_path):
    _write(tmp_path, "r.urdf", _urdf())
    for name, joint in (("first.cntr", "arm"), ("second.cntr", "nope")):
        _write(tmp_path, name, f'<ControlSet><Control name="c"><DOF name="r/{joint}" '
               'value="1"/></Control></ControlSet>')
    problem = _write(tmp_path, "p.xml", '<?xml version="1.0"?>\n<Problem>\n'
                     '<Robot robot="r.urdf"/>\n<Controls robot="first.cntr"/>\n'
                     '<Controls robot="second.cntr"/>\n</Problem>\n')
    loaded = load_problem(problem)
    assert loaded.instances[0].controls.names == ("c",)
    assert any(i.what == "a second <Controls>" and i.line == 5 for i in loaded.ignored)


# -- files that are not problems ---------------------------------------------------------------

@pytest.mark.parametrize("root,says", [
    ('<Benchmark Name="e"><Problem File="p.xml" PlannerAlias="a"/></Benchmark>',
     "is a Kautham benchmark file (<Benchmark>: problems and planners to compare), not a "
     "problem: `rosrun GUI benchmark` reads it"),
    ("<Config><Problemfiles/></Config>", "is a Kautham configuration file"),
])
def test_files_that_mention_problem_but_are_not_problems_get_one_line_saying_what(
        tmp_path, root, says):
    path = _write(tmp_path, "f.xml", '<?xml version="1.0"?>\n' + root + "\n")
    status, out, err = problem_info(path)
    assert status == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"problem_info: error: {path}:2: {says}")


def test_a_2012_robot_whose_control_set_moves_its_base_is_mobile(tmp_path):
    """Kautham 2012 enables a robot's SE3 base when its .rob's <ControlSet> names X, Y, Z, X1,
    X2 or X3 in a control or the offset (Robot::setControlSet: se3Enabled): a hand or an arm
    on a free base, moved by the controls, not a fixed-base robot."""
    _write(tmp_path, "cube.iv", CUBE_IV)
    joints = _joint("Base", False) + _joint("J1", True, "Base", -90, 90, d=100)
    _write(tmp_path, "hand.rob", _rob("hand", joints, _control_set(
        {"Z": 0.5, "J1": 0.5}, {"z": {"Z": 1.0}, "j": {"J1": 1.0}})))
    _write(tmp_path, "offset.rob", _rob("offset", joints, _control_set(
        {"X": 0.5, "J1": 0.5}, {"j": {"J1": 1.0}})))
    _write(tmp_path, "arm.rob", _rob("arm", joints, _control_set(
        {"J1": 0.5}, {"j": {"J1": 1.0}})))
    for name, kind in [("hand", MOBILE), ("offset", MOBILE), ("arm", FIXED_BASE)]:
        controls = "0.5 0.5" if name == "hand" else "0.5"
        problem = _write(tmp_path, f"{name}.xml", _problem_2012(
            f'<Robot robot="{name}.rob"><Limits name="Z" min="0" max="500"/></Robot>',
            controls))
        assert load_problem(problem).instances[0].kind == kind, name
