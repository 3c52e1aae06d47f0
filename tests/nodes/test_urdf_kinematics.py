"""Odin's forward kinematics of URDF robots against an independent implementation: for every
URDF of the Kautham corpus with more than one link, the link poses Odin builds
(``RobotModel.link_poses``, what the build plans place the bodies by) at Home and at five random
joint configurations within the limits equal, within 1e-6 m and 1e-6 rad, the transforms
Debian's robot_state_publisher (KDL, with its own URDF parser) publishes on /tf for the same
URDF and joint values. A URDF origin whose roll, pitch and yaw are composed in the wrong order,
an axis taken in the wrong frame or a prismatic joint's sign would all show. A Kautham mobile
robot's world link poses (its base where its controls put it) are checked the same way, the
base carried by six joints for KDL: a base pose applied wrongly would show too.

Mimic joints: robot_state_publisher moves a mimic joint with its master (value x multiplier +
offset); Odin moves it on its own, so it is given that value. The whole corpus's URDFs
(tools/get_kautham.sh --all) are checked by `make corpus` (ODIN_WHOLE_CORPUS_TESTS=1)."""
from __future__ import annotations

import math
import os
import pathlib
import time

import numpy as np
import pytest
from test_ros_robots import _matrix, _Transforms

from gui.core.kautham.corpus import WHOLE_CORPUS_TESTS, whole_corpus_dir, whole_missing_message

pytestmark = pytest.mark.forked

CONFIGURATIONS = 5
TOLERANCE_M = 1e-6
TOLERANCE_RAD = 1e-6


class _StampedTransforms(_Transforms):
    """test_ros_robots's tf listener, keeping the stamp each transform carries."""

    def _add(self, message) -> None:
        with self._lock:
            for t in message.transforms:
                self.latest[t.child_frame_id] = (t.header.frame_id, t.header.stamp.to_sec(),
                                                 _matrix(t.transform))


def urdf_robots(folder: pathlib.Path) -> list:
    """The .urdf files under ``folder`` with more than one link that Odin reads."""
    from gui.core.kautham.urdf import read_urdf
    from gui.errors import ProblemError
    robots = []
    for path in sorted(folder.rglob("*.urdf")):
        try:
            model = read_urdf(path)
        except ProblemError:
            continue                  # a URDF Odin refuses says so elsewhere (problem_info)
        if len(model.links) > 1:
            robots.append((path, model))
    return robots


def _mimics(path: pathlib.Path) -> dict:
    """{mimic joint name: (master joint name, multiplier, offset)} of a URDF."""
    from gui.core.kautham.xmlfile import read_xml
    out = {}
    for joint in read_xml(path).findall("joint"):
        mimic = joint.find("mimic")
        if mimic is not None:
            out[joint.get("name")] = (mimic.get("joint"), mimic.number("multiplier", 1.0),
                                      mimic.number("offset", 0.0))
    return out


def configurations(model, mimics: dict, rng: np.random.Generator) -> list:
    """Home and CONFIGURATIONS random joint vectors within the limits (continuous joints
    within [-pi, pi]), mimic joints at their master's value."""
    names = model.joint_names()
    out = [model.home()]
    for _ in range(CONFIGURATIONS):
        values = []
        for i in model.movable_links():
            low, high = model.links[i].limits or (-math.pi, math.pi)
            values.append(rng.uniform(low, high))
        out.append(np.array(values))
    for values in out:
        for k, name in enumerate(names):
            if name in mimics and mimics[name][0] in names:
                master, multiplier, offset = mimics[name]
                values[k] = values[names.index(master)] * multiplier + offset
    return out


def _with_limits(path: pathlib.Path) -> str:
    """The URDF's text, a ``<limit>`` added to each revolute or prismatic joint without one:
    urdfdom (robot_state_publisher's parser) refuses those, Kautham and Odin read them (as
    continuous); limits do not move a link."""
    import xml.etree.ElementTree as ElementTree
    root = ElementTree.fromstring(path.read_bytes())
    for joint in root.iter("joint"):
        if joint.get("type") in ("revolute", "prismatic") and joint.find("limit") is None:
            ElementTree.SubElement(joint, "limit", lower="-10", upper="10", effort="0",
                                   velocity="0")
    return ElementTree.tostring(root, encoding="unicode")


def _angle(rotation: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(rotation) - 1.0) / 2.0, -1.0, 1.0)))


def _publisher(master, namespace: str, description: str):
    """Debian's robot_state_publisher for ``description`` in ``namespace``, its tf on the
    namespace's own topics: (the transforms it publishes, a latched joint_states publisher,
    its process)."""
    import rospy
    from sensor_msgs.msg import JointState
    rospy.set_param(f"/{namespace}/robot_description", description)
    transforms = _StampedTransforms(f"/{namespace}/tf", f"/{namespace}/tf_static")
    states = rospy.Publisher(f"/{namespace}/joint_states", JointState, queue_size=10,
                             latch=True)
    node = master.popen(["rosrun", "robot_state_publisher", "robot_state_publisher",
                         f"__ns:={namespace}", f"/tf:=/{namespace}/tf",
                         f"/tf_static:=/{namespace}/tf_static"],
                        log_name=f"robot_state_publisher_{namespace}")
    return transforms, states, node


def check_robot(path: pathlib.Path, model, master, namespace: str, seed: int) -> list:
    """Differences (text) between Odin's link poses and robot_state_publisher's for
    ``path``'s robot at Home and CONFIGURATIONS random configurations."""
    import rospy
    from sensor_msgs.msg import JointState
    transforms, states, node = _publisher(master, namespace, _with_limits(path))
    children = {model.links[i].name: model.links[model.links[i].parent].name
                for i in range(1, len(model.links))}
    names = model.joint_names()
    differences = []
    try:
        for k, values in enumerate(configurations(model, _mimics(path),
                                                  np.random.default_rng(seed))):
            stamp = 1000.0 + k
            states.publish(JointState(header=rospy.Header(stamp=rospy.Time.from_sec(stamp)),
                                      name=names, position=list(values)))
            seen = _wait_for(transforms, children, names, model, stamp, node, master)
            poses = model.link_poses(np.eye(4), values)
            index = {link.name: i for i, link in enumerate(model.links)}
            for child, parent in children.items():
                frame, _, relative = seen[child]
                odin = np.linalg.inv(poses[index[parent]]) @ poses[index[child]]
                offset = float(np.linalg.norm(odin[:3, 3] - relative[:3, 3]))
                turn = _angle(relative[:3, :3].T @ odin[:3, :3])
                if frame != parent or offset > TOLERANCE_M or turn > TOLERANCE_RAD:
                    differences.append(f"{path.name} configuration {k} {parent}->{child}: "
                                       f"{offset:.3g} m, {turn:.3g} rad (tf parent {frame})")
    finally:
        transforms.close()
        states.unregister()
        node.terminate()
        node.wait(10)
    return differences


def _wait_for(transforms, children: dict, names, model, stamp: float, node, master) -> dict:
    """The transforms of every child link, those of moving joints stamped ``stamp``."""
    moving = {model.links[i].name for i in model.movable_links()}
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        seen = transforms.snapshot()
        if all(c in seen and (c not in moving or seen[c][1] == stamp) for c in children):
            return seen
        if node.poll() is not None:
            raise AssertionError("robot_state_publisher died: " + master.log_text(node)[-2000:])
        time.sleep(0.02)
    missing = sorted(c for c in children if c not in transforms.snapshot())
    raise AssertionError(f"robot_state_publisher published no transforms of {missing} "
                         f"(stamp {stamp})")


def _check_folder(folder: pathlib.Path, master) -> int:
    import rospy
    if not rospy.core.is_initialized():
        rospy.init_node("kinematics_check", anonymous=True, disable_signals=True)
    robots = urdf_robots(folder)
    differences = []
    for k, (path, model) in enumerate(robots):
        namespace = f"robot_{folder.name}_{k}".replace("-", "_")
        differences += check_robot(path, model, master, namespace, seed=k)
    assert not differences, "\n".join(differences[:40])
    return len(robots)


COMPOUND = """<?xml version="1.0"?>
<robot name="compound">
  <link name="base"/>
  <link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <joint name="ja" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0.1 -0.2 0.3" rpy="0.3 -0.7 1.1"/><axis xyz="0.2 0.5 -0.8"/>
    <limit lower="-2" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="jb" type="prismatic"><parent link="a"/><child link="b"/>
    <origin xyz="0 0.4 0" rpy="-1.2 0.4 2.5"/><axis xyz="1 1 0"/>
    <limit lower="-0.3" upper="0.2" effort="1" velocity="1"/></joint>
  <joint name="jc" type="continuous"><parent link="b"/><child link="c"/>
    <origin xyz="0.05 0 -0.1" rpy="2.9 1.3 -0.4"/><axis xyz="0 0 1"/></joint>
  <joint name="jd" type="fixed"><parent link="a"/><child link="d"/>
    <origin xyz="0 0 0.2" rpy="0.5 0.6 0.7"/></joint>
</robot>
"""


def test_odin_s_urdf_link_poses_equal_robot_state_publisher_s(ros_master, kautham_dir,
                                                              tmp_path):
    """The corpus's URDF robots, and one written here whose origins turn about all three axes
    at once (the corpus's TX90 turns about one axis per joint: it cannot tell roll, pitch and
    yaw composed in the wrong order)."""
    (tmp_path / "compound.urdf").write_text(COMPOUND)
    assert _check_folder(kautham_dir, ros_master) >= 1
    assert _check_folder(tmp_path, ros_master) == 1



# -- a mobile base --------------------------------------------------------------------------
MOBILE_CONTROLS = """<?xml version="1.0"?><ControlSet>
 <Control name="rover/x" eigValue="1"><DOF name="rover/X" value="1"/></Control>
 <Control name="rover/y" eigValue="1"><DOF name="rover/Y" value="1"/></Control>
 <Control name="rover/z" eigValue="1"><DOF name="rover/Z" value="1"/></Control>
 <Control name="rover/r1" eigValue="1"><DOF name="rover/X1" value="1"/></Control>
 <Control name="rover/r2" eigValue="1"><DOF name="rover/X2" value="1"/></Control>
 <Control name="rover/r3" eigValue="1"><DOF name="rover/X3" value="1"/></Control>
 <Control name="rover/turn" eigValue="1"><DOF name="rover/shoulder" value="1"/></Control>
 <Control name="rover/lift" eigValue="1"><DOF name="rover/upper" value="1"/></Control>
 <Control name="rover/reach" eigValue="1"><DOF name="rover/fore" value="1"/></Control>
</ControlSet>
"""

MOBILE_PROBLEM = """<?xml version="1.0"?>
<Problem>
 <Robot robot="rover.urdf"><Limits name="X" min="-2" max="3"/><Limits name="Y" min="-1"
  max="2"/><Limits name="Z" min="0.1" max="1.5"/>
  <Home X="0.3" Y="-0.2" Z="0.1" WX="0.27" WY="0.53" WZ="0.8" TH="0.9"/></Robot>
 <Controls robot="rover.cntr"/>
 <Planner><Parameters><Name>omplRRTConnect</Name></Parameters>
  <Queries><Query><Init>0.5 0.5 0.5 0.2 0.3 0.4 0.5 0.5 0.5</Init>
   <Goal>0.6 0.4 0.7 0.8 0.1 0.6 0.3 0.6 0.2</Goal></Query></Queries></Planner>
</Problem>
"""

#: the joints that carry a mobile base for robot_state_publisher, from a link "world" (KDL
#: takes a floating or planar joint for a fixed one): its position, then yaw, pitch and roll
BASE_JOINTS = (("base_x", "prismatic", "1 0 0"), ("base_y", "prismatic", "0 1 0"),
               ("base_z", "prismatic", "0 0 1"), ("base_yaw", "continuous", "0 0 1"),
               ("base_pitch", "continuous", "0 1 0"), ("base_roll", "continuous", "1 0 0"))


def _on_base_joints(urdf: str, base: str) -> str:
    """``urdf`` with its ``base`` link carried by BASE_JOINTS from a new root link "world"."""
    import xml.etree.ElementTree as ElementTree
    root = ElementTree.fromstring(urdf)
    chain = ["world", *(f"carrier_{name}" for name, _, _ in BASE_JOINTS[:-1]), base]
    for link in chain[:-1]:
        ElementTree.SubElement(root, "link", name=link)
    for k, (name, kind, axis) in enumerate(BASE_JOINTS):
        joint = ElementTree.SubElement(root, "joint", name=name, type=kind)
        ElementTree.SubElement(joint, "parent", link=chain[k])
        ElementTree.SubElement(joint, "child", link=chain[k + 1])
        ElementTree.SubElement(joint, "axis", xyz=axis)
        if kind == "prismatic":
            ElementTree.SubElement(joint, "limit", lower="-100", upper="100", effort="0",
                                   velocity="0")
    return ElementTree.tostring(root, encoding="unicode")


def _base_joint_values(pose: np.ndarray) -> list:
    """BASE_JOINTS' values (m, m, m, rad, rad, rad) that put a base at ``pose`` (4, 4):
    R = Rz(yaw) Ry(pitch) Rx(roll), written out here."""
    R = pose[:3, :3]
    pitch = math.asin(-float(np.clip(R[2, 0], -1.0, 1.0)))
    return [*(float(v) for v in pose[:3, 3]), math.atan2(R[1, 0], R[0, 0]), pitch,
            math.atan2(R[2, 1], R[2, 2])]


def _in_world(seen: dict, frame: str) -> np.ndarray:
    """The pose (4, 4) of ``frame`` in "world", chaining the transforms ``seen``."""
    pose = np.eye(4)
    while frame != "world":
        frame, _, relative = seen[frame]
        pose = relative @ pose
    return pose


def test_a_kautham_mobile_base_s_link_poses_equal_robot_state_publisher_s(ros_master,
                                                                          tmp_path):
    """A mobile robot as Kautham models one: its base free in space, where its controls put
    it (X, Y, Z within the problem's limits, a rotation by Kuffner's quaternion, all from a
    Home that turns about three axes), an arm whose joint origins turn about three axes at
    once (tests/nodes/test_ros_time.py's rover, with a fixed tool). Odin's world pose of
    every link (``link_poses`` from the base pose of ``ControlMap.configuration``, what the
    build plan places the bodies by) at the query's start and goal and at random controls
    equals what KDL makes of the same base pose carried by six joints and the same joint
    values."""
    import rospy
    from sensor_msgs.msg import JointState
    from test_ros_time import ROVER_URDF

    from gui.core.kautham.problem import load_problem
    from gui.core.model import MOBILE
    (tmp_path / "rover.urdf").write_text(ROVER_URDF)
    (tmp_path / "rover.cntr").write_text(MOBILE_CONTROLS)
    (tmp_path / "rover.xml").write_text(MOBILE_PROBLEM)
    robot = load_problem(tmp_path / "rover.xml").robots[0]
    assert robot.kind == MOBILE
    model = robot.model
    rng = np.random.default_rng(7)
    configurations = [robot.start, robot.goal] + [
        robot.controls.configuration(robot, rng.uniform(0, 1, robot.controls.size))
        for _ in range(CONFIGURATIONS)]
    turns = [_angle(c.base_pose[:3, :3]) for c in configurations]
    assert min(turns) > 0.1          # every base turned (about an axis of its own)

    rospy.init_node("kinematics_check", anonymous=True, disable_signals=True)
    namespace = "mobile"
    transforms, states, node = _publisher(ros_master, namespace,
                                          _on_base_joints(ROVER_URDF, model.links[0].name))
    names = [name for name, _, _ in BASE_JOINTS] + model.joint_names()
    moving = {model.links[0].name} | {model.links[i].name for i in model.movable_links()}
    links = [link.name for link in model.links]
    differences = []
    for k, configuration in enumerate(configurations):
        stamp = 1000.0 + k
        states.publish(JointState(header=rospy.Header(stamp=rospy.Time.from_sec(stamp)),
                                  name=names, position=_base_joint_values(
                                      configuration.base_pose) + list(configuration.joints)))
        deadline = time.monotonic() + 20
        while True:
            seen = transforms.snapshot()
            if all(c in seen and (c not in moving or seen[c][1] == stamp) for c in links):
                break
            assert time.monotonic() < deadline and node.poll() is None, (
                f"robot_state_publisher's frames at {stamp}: {sorted(seen)}\n"
                + ros_master.log_text(node)[-2000:])
            time.sleep(0.02)
        odin = model.link_poses(configuration.base_pose, configuration.joints)
        for link, pose in zip(links, odin):
            kdl = _in_world(seen, link)
            offset = float(np.linalg.norm(pose[:3, 3] - kdl[:3, 3]))
            turn = _angle(kdl[:3, :3].T @ pose[:3, :3])
            if offset > TOLERANCE_M or turn > TOLERANCE_RAD:
                differences.append(f"configuration {k} {link}: {offset:.3g} m, {turn:.3g} rad")
    transforms.close()
    states.unregister()
    assert not differences, "\n".join(differences)

@pytest.mark.timeout(3600)
@pytest.mark.skipif(os.environ.get(WHOLE_CORPUS_TESTS) != "1",
                    reason=f"the whole Kautham corpus: `make corpus` runs it "
                    f"({WHOLE_CORPUS_TESTS}=1)")
def test_odin_s_urdf_link_poses_equal_robot_state_publisher_s_over_the_whole_corpus(
        ros_master):
    whole = whole_corpus_dir()
    if whole is None:
        pytest.fail(whole_missing_message())
    assert _check_folder(whole, ros_master) >= 20
