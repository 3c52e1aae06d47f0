"""Robot descriptions (gui.core.robot_description) against the real Kautham corpus: the URDF of
every robot, forward kinematics as robot_state_publisher computes it (written here, from the
URDF text alone), puts every link where the Kautham model and the world's bodies put it; a
URDF robot keeps its file, its names and its meshes; a .rob robot gets a valid URDF with its
limits and its meshes as STL files."""
from __future__ import annotations

import math
import pathlib
import struct
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from gui.core.translate import plan_problem
from gui.core.kautham.corpus import corpus_dir
from gui.core.kautham.problem import load_problem
from gui.core.robot_description import describe_robot
from odin_common.rotations import pose_matrix

pytestmark = pytest.mark.usefixtures("kautham_dir")
KAUTHAM = corpus_dir() or pathlib.Path("/no-kautham-corpus")   # paths for collection only
PROBLEMS = ["legacy_2012/examples/TRO/2DRR_obstacle.xml",
            "legacy_2012/examples/Kuka_two_columns.xml",
            "legacy_2012/examples/Staubli_R6_two_columns.xml",
            "legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml",
            "current_2025/demos/OMPL_geo_demos/TX90_IOC/OMPL_RRTConnect_TX90_TwoCan.xml"]
URDF_TX90 = PROBLEMS[-1]
HAND = PROBLEMS[3]


# -- URDF forward kinematics, written here from the URDF specification ---------------------
def _rpy(roll, pitch, yaw) -> np.ndarray:
    def rot(axis, a):
        c, s = math.cos(a), math.sin(a)
        R = np.eye(3)
        i, j = [(1, 2), (0, 2), (0, 1)][axis]
        R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
        if axis == 1:          # about y the signs of the sines swap
            R[i, j], R[j, i] = s, -s
        return R
    return rot(2, yaw) @ rot(1, pitch) @ rot(0, roll)


def _numbers(element, name, default):
    if element is None or element.get(name) is None:
        return np.asarray(default, float)
    return np.asarray([float(v) for v in element.get(name).split()])


def _urdf_poses(urdf: str, values: dict, root_pose: np.ndarray) -> dict:
    """{link: world pose} for joint ``values`` (child = parent @ origin @ motion(axis, q))."""
    robot = ET.fromstring(urdf)
    joints = {}
    for joint in robot.findall("joint"):
        origin = joint.find("origin")
        T = np.eye(4)
        T[:3, :3] = _rpy(*_numbers(origin, "rpy", (0, 0, 0)))
        T[:3, 3] = _numbers(origin, "xyz", (0, 0, 0))
        axis = _numbers(joint.find("axis"), "xyz", (1, 0, 0))
        joints[joint.find("child").get("link")] = (joint, T, axis / np.linalg.norm(axis))
    poses = {}

    def pose(link):
        if link not in poses:
            if link not in joints:
                poses[link] = root_pose
            else:
                joint, origin, axis = joints[link]
                q = values.get(joint.get("name"), 0.0)
                motion = np.eye(4)
                if joint.get("type") in ("revolute", "continuous"):
                    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]],
                                  [-axis[1], axis[0], 0]])
                    motion[:3, :3] = np.eye(3) + math.sin(q) * K + (1 - math.cos(q)) * K @ K
                elif joint.get("type") == "prismatic":
                    motion[:3, 3] = axis * q
                parent = joint.find("parent").get("link")
                poses[link] = pose(parent) @ origin @ motion
        return poses[link]

    for link in robot.findall("link"):
        pose(link.get("name"))
    return poses


def _link_in_object(description, k) -> np.ndarray:
    return pose_matrix(description.link_positions[3 * k:3 * k + 3],
                       description.link_orientations[4 * k:4 * k + 4])


@pytest.mark.parametrize("problem", PROBLEMS)
def test_the_urdf_puts_every_link_where_the_model_and_the_world_bodies_are(problem, tmp_path):
    plan = plan_problem(load_problem(KAUTHAM / problem))
    rng = np.random.default_rng(7)
    for handle in plan.robots:
        description = describe_robot(handle, tmp_path)
        model = handle.instance.model
        assert description.objects == tuple(b.body_id for b in handle.bodies)
        assert description.joints == tuple(handle.joint_ids)
        assert len(description.joint_names) == len(set(description.joint_names))
        for _ in range(3):
            q = handle.home + rng.uniform(-0.4, 0.4, len(handle.home))
            links = model.link_poses(handle.instance.base_pose, q)
            # the world's object of each link sits at link @ offset; the URDF link frame is
            # where the description says in that object
            expected = [T @ body.offset @ _link_in_object(description, k)
                        for k, (T, body) in enumerate(zip(links, handle.bodies))]
            # the world's joint values are q - the configuration the robot was built in (the
            # query's start in a current problem, else Home); the offsets give q back
            world_values = q - handle.built_at
            values = {name: offset + v for name, offset, v in zip(
                description.joint_names, description.joint_offsets, world_values)}
            poses = _urdf_poses(description.urdf, values, expected[0])
            for k, link in enumerate(description.links):
                assert np.abs(poses[link] - expected[k]).max() < 1e-9, (problem, link)


def test_a_urdf_robot_keeps_its_file_names_and_meshes(tmp_path):
    handle = plan_problem(load_problem(KAUTHAM / URDF_TX90)).robots[0]
    description = describe_robot(handle, tmp_path)
    assert not description.generated
    robot = ET.fromstring(description.urdf)
    given = ET.parse(handle.instance.model.source).getroot()
    assert [j.get("name") for j in robot.findall("joint")] == \
        [j.get("name") for j in given.findall("joint")]
    assert description.joint_names == ("joint_1", "joint_2", "joint_3", "joint_4", "joint_5",
                                       "joint_6")
    meshes = [m.get("filename") for m in robot.iter("mesh")]
    assert meshes and all(m.startswith("file:///") and pathlib.Path(m[7:]).is_file()
                          for m in meshes)
    assert list(tmp_path.iterdir()) == []      # nothing generated


def test_a_rob_robot_gets_a_valid_urdf_with_its_limits_and_stl_meshes(tmp_path):
    handle = plan_problem(load_problem(KAUTHAM / HAND)).robots[0]
    description = describe_robot(handle, tmp_path)
    assert description.generated
    robot = ET.fromstring(description.urdf)
    names = [link.get("name") for link in robot.findall("link")]
    assert len(names) == len(set(names)) == len(handle.bodies)
    assert all(name.replace("_", "a").isalnum() for name in names)
    model = handle.instance.model
    joints = {j.get("name"): j for j in robot.findall("joint")}
    for index in model.movable_links():
        joint = joints[description.links[index]]
        link = model.links[index]
        if link.limits is None:
            assert joint.get("type") == "continuous"
        else:
            limit = joint.find("limit")
            assert (float(limit.get("lower")), float(limit.get("upper"))) == \
                pytest.approx(link.limits)
    meshes = [m.get("filename") for m in robot.iter("mesh")]
    assert meshes, "the hand's links are meshes"
    for uri in set(meshes):
        data = pathlib.Path(uri[len("file://"):]).read_bytes()
        count, = struct.unpack_from("<I", data, 80)
        assert len(data) == 84 + 50 * count and count > 0
    # a second description reuses the same files
    assert describe_robot(handle, tmp_path).urdf == description.urdf
    assert len(list(tmp_path.iterdir())) == len(set(meshes))


def test_without_a_mesh_folder_a_generated_urdf_keeps_its_primitives_only(tmp_path):
    handle = plan_problem(load_problem(KAUTHAM / PROBLEMS[0])).robots[0]
    description = describe_robot(handle, None)
    assert not list(ET.fromstring(description.urdf).iter("mesh"))
