"""The pieces of the world's standard ROS topics that need no master: the world clock, object
frames, the tf and marker writers, robots, and the mirror that keeps them with a real Core."""
import io
import math

import numpy as np
import pytest
import rospy
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from Messages.msg import Robot as RobotMessage
from odin_common.defaults import COLLIDING_COLOR, DEFAULT_COLOR
from odin_common.interface import WORLD_FRAME, JointType, frame_id, robot_namespace
from odin_common.rotations import compose_poses, quaternion_to_matrix
from odin_common.specs import CompositeSpec, JointSpec, ObjectSpec, PartSpec
from virtual_world.core import Core
from virtual_world.errors import InvalidArgument, UnknownName
from virtual_world.portal.clock import WorldClock
from virtual_world.portal.frames import ObjectFrames
from virtual_world.portal.markers import GeometryMarkers, marker_shape
from virtual_world.portal.mirror import WorldMirror
from virtual_world.portal.robots import robot_message, robot_of
from virtual_world.portal.tf_writer import TfWriter


def _decode(message, cls):
    buffer = io.BytesIO()
    message.serialize(buffer)
    decoded = cls()
    decoded.deserialize(buffer.getvalue())
    return decoded


def _seconds(stamp) -> float:
    secs, nsecs = stamp
    return secs + nsecs * 1e-9


# -- the world clock ---------------------------------------------------------------------------

def test_the_clock_is_the_cores_time_until_that_goes_back():
    clock = WorldClock()
    assert [clock.stamp(t, 0.001, False) for t in (0.0, 0.04, 0.08)] == \
        [(0, 0), (0, 40_000_000), (0, 80_000_000)]


def test_a_new_scene_goes_on_one_step_after_the_last_stamp_and_at_the_same_pace():
    clock = WorldClock()
    clock.stamp(2.5, 0.001, False)
    assert _seconds(clock.stamp(0.0, 0.001, True)) == pytest.approx(2.501, abs=1e-9)
    assert _seconds(clock.stamp(0.04, 0.001, False)) == pytest.approx(2.541, abs=1e-9)
    assert clock.now(0.04) == pytest.approx(2.541, abs=1e-9)


def test_a_restore_to_an_earlier_time_never_sends_the_clock_back():
    clock = WorldClock()
    stamps = [clock.stamp(t, 0.01, False) for t in (0.0, 0.5, 1.0)]
    stamps += [clock.stamp(t, 0.01, True) for t in (0.5, 0.6)]   # restored to 0.5 s
    assert stamps == sorted(stamps) and len(set(stamps)) == len(stamps)


def test_a_change_while_paused_moves_the_stamp_by_a_nanosecond_and_stepping_takes_it_back():
    clock = WorldClock()
    assert clock.stamp(1.0, 0.001, False) == (1, 0)
    assert clock.stamp(1.0, 0.001, False) == (1, 0)          # nothing changed: same stamp
    assert clock.stamp(1.0, 0.001, True) == (1, 1)
    assert clock.stamp(1.0, 0.001, True) == (1, 2)
    assert clock.stamp(1.0, 0.001, False) == (1, 2)
    assert clock.stamp(1.04, 0.001, False) == (1, 40_000_000)   # the Core's time again


# -- frames ------------------------------------------------------------------------------------

def test_frame_ids_are_valid_tf_frames_named_after_the_ids():
    assert frame_id("TX90 SAHand Right/Palm") == "TX90_SAHand_Right/Palm"
    assert frame_id(">table#0>table#1") == "_table_0_table_1"
    assert frame_id("1:arm/base&arm/link1") == "1_arm/base_arm/link1"
    for weird in ("/a", "a/", "a//b", "//", "é", " "):
        frame = frame_id(weird)
        assert frame and not frame.startswith("/") and "//" not in frame
        assert not frame.endswith("/")
    assert robot_namespace("TX90 SAHand Right") == "TX90_SAHand_Right"
    assert robot_namespace("2DRR") == "robot_2DRR"


def _quaternion(angle, axis=(0, 0, 1)):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return (math.cos(angle / 2), *(math.sin(angle / 2) * axis))


def test_a_composites_frame_follows_its_first_part_and_a_taken_name_gets_a_suffix():
    frames = ObjectFrames()
    q = _quaternion(0.7)
    part = compose_poses(np.array([1.0, 2.0, 3.0]), np.array(q), np.array([0.5, 0, 0]),
                         np.array(_quaternion(0.3, (1, 0, 0))))
    assert frames.add(">a#0>a#1", ((1, 2, 3), q), [("a#0", part), ("a#1", ((9, 9, 9), q))],
                      static=False) == "_a_0_a_1"
    assert frames.add("_a_0_a_1", ((0, 0, 0), (1, 0, 0, 0)), [("_a_0_a_1", ((0, 0, 0),
                                                                            (1, 0, 0, 0)))],
                      static=True) == "_a_0_a_1_2"
    assert frames.add("world", ((0, 0, 0), (1, 0, 0, 0)),
                      [("world", ((0, 0, 0), (1, 0, 0, 0)))], static=False) == "world_2"
    # the composite moved: its part now elsewhere; the frame follows rigidly
    moved_p, moved_q = compose_poses(np.array([-1.0, 0, 0.5]), np.array(_quaternion(-1.2)),
                                     np.array([0.5, 0, 0]), np.array(_quaternion(0.3, (1, 0, 0))))
    (names, p, qs), (static_names, _, _) = frames.poses(
        ["a#0", "a#1", "_a_0_a_1", "world"],
        np.array([moved_p, (9, 9, 9), (0, 0, 0), (0, 0, 0)]),
        np.array([moved_q, q, (1, 0, 0, 0), (1, 0, 0, 0)]))
    assert names == ["_a_0_a_1", "world_2"] and static_names == ["_a_0_a_1_2"]
    assert p[0] == pytest.approx([-1.0, 0, 0.5])
    assert np.abs(quaternion_to_matrix(qs[0]) - quaternion_to_matrix(_quaternion(-1.2))).max() \
        < 1e-12


def test_a_robot_link_renames_its_objects_frame_and_places_it_where_the_robot_says():
    frames = ObjectFrames()
    frames.add("arm/link1", ((1, 0, 0), (1, 0, 0, 0)), [("arm/link1", ((1, 0, 0), (1, 0, 0, 0)))],
               static=False)
    frames.add("other", ((0, 0, 0), (1, 0, 0, 0)), [("other", ((0, 0, 0), (1, 0, 0, 0)))],
               static=False)
    with pytest.raises(InvalidArgument, match="already the frame of 'other'"):
        frames.check_links({"arm/link1": "other"})
    frames.check_links({"arm/link1": "arm/l1"})
    frames.set_link("arm/link1", "arm/l1", ((0, 0, -0.2), _quaternion(math.pi / 2)))
    (names, p, q), _ = frames.poses(["arm/link1", "other"], np.array([(1, 0, 0), (0, 0, 0)]),
                                    np.array([(1, 0, 0, 0), (1, 0, 0, 0)]))
    assert names == ["arm/l1", "other"]
    assert p[0] == pytest.approx([1, 0, -0.2])
    assert q[0] == pytest.approx(_quaternion(math.pi / 2))
    # the object's geometry seen from the link frame: the inverse offset
    (pose,) = frames.geometries_in_frame("arm/link1").values()
    assert pose[0] == pytest.approx([0, 0, 0.2])
    frames.unset_link("arm/link1")
    assert frames.frame("arm/link1") == "arm/link1"



def test_every_frames_pose_is_its_geometrys_composed_with_its_fixed_transform_bit_for_bit():
    """Moving and static frames are composed in one call: each row as if composed alone."""
    frames = ObjectFrames()
    rng = np.random.default_rng(7)
    names = ["absent"]
    for k in range(7):
        names.append(f"o{k}")
        geometry = (tuple(rng.normal(size=3)), _quaternion(rng.normal(), rng.normal(size=3)))
        frames.add(names[-1], ((0, 0, 0), (1, 0, 0, 0)), [(names[-1], geometry)],
                   static=k % 3 == 0)
    positions = rng.normal(size=(len(names), 3))
    quaternions = rng.normal(size=(len(names), 4))
    moving, static = frames.poses(names, positions, quaternions)
    assert moving[0] == ["o1", "o2", "o4", "o5"] and static[0] == ["o0", "o3", "o6"]
    for group in (moving, static):
        for frame, p, q in zip(*group):
            row, fixed = names.index(frame), frames._objects[frame]
            want_p, want_q = compose_poses(positions[row], quaternions[row], fixed.position,
                                           fixed.quaternion)
            assert p.tobytes() == want_p.tobytes() and q.tobytes() == want_q.tobytes()
    empty = ObjectFrames().poses(names, positions, quaternions)
    assert [len(g[0]) for g in empty] == [0, 0] and empty[0][1].shape == (0, 3)

# -- writers -----------------------------------------------------------------------------------

@pytest.mark.parametrize("frames", [[], ["a"], ["ball", "TX90_SAHand_Right/Palm", "x" * 300]])
def test_tf_messages_decode_as_ordinary_transforms_with_xyzw_quaternions(frames):
    writer = TfWriter()
    rng = np.random.default_rng(4)
    for stamp in (rospy.Time(3, 5), rospy.Time(7, 999)):   # the second reuses the layout
        positions = rng.normal(size=(len(frames), 3))
        quaternions = rng.normal(size=(len(frames), 4))
        decoded = _decode(writer.message(frames, positions, quaternions, stamp), TFMessage)
        assert [t.child_frame_id for t in decoded.transforms] == frames
        for i, t in enumerate(decoded.transforms):
            assert t.header.frame_id == WORLD_FRAME and t.header.stamp == stamp
            assert [t.transform.translation.x, t.transform.translation.y,
                    t.transform.translation.z] == positions[i].tolist()
            r = t.transform.rotation
            assert [r.w, r.x, r.y, r.z] == quaternions[i].tolist()


def _markers(message) -> list:
    return _decode(message, MarkerArray).markers


def test_markers_draw_each_shape_as_the_viewer_does():
    shapes = {"sphere": ([0.1], 0), "cylinder": ([0.1, 0.4], 0), "box": ([1, 2, 3], 0),
              "plane": ([], 6), "capsule": ([0.1, 0.3], 5),
              "tetra": ([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1], 0)}
    markers = GeometryMarkers()
    for name, (parameters, shape) in shapes.items():
        indices = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3] if name == "tetra" else []
        markers.add(name, parameters, indices, shape, (0, 0, 0, 0) if name == "box"
                    else (1, 0, 0, 1), "frame_" + name, ((1, 2, 3), (1, 0, 0, 0)))
    decoded = {m.text: m for m in _markers(markers.full()) if m.text}
    assert _markers(markers.full())[0].action == Marker.DELETEALL
    assert decoded["sphere"].type == Marker.SPHERE and decoded["sphere"].scale.x == 0.2
    assert decoded["cylinder"].type == Marker.CYLINDER
    assert (decoded["cylinder"].scale.x, decoded["cylinder"].scale.z) == (0.2, 0.4)
    assert decoded["box"].type == Marker.CUBE
    assert (decoded["box"].color.r, decoded["box"].color.a) == \
        pytest.approx((DEFAULT_COLOR[0], 1.0))
    assert decoded["plane"].type == Marker.CUBE and decoded["plane"].pose.position.z < 3
    assert decoded["capsule"].type == Marker.TRIANGLE_LIST
    tetra = decoded["tetra"]
    assert tetra.type == Marker.TRIANGLE_LIST and len(tetra.points) == 12
    assert (tetra.points[1].x, tetra.points[1].y) == (0, 1)      # corners of triangle 0, 2, 1
    for m in decoded.values():
        assert m.header.frame_id == "frame_" + m.text and m.frame_locked
        assert m.ns == "odin" and m.action == Marker.ADD


def test_marker_changes_hold_only_what_changed_and_grey_follows_collisions():
    markers = GeometryMarkers()
    markers.add("a", [0.1], [], 0, (1, 0, 0, 1), "a", ((0, 0, 0), (1, 0, 0, 0)))
    markers.add("b", [0.1], [], 0, (0, 1, 0, 1), "b", ((0, 0, 0), (1, 0, 0, 0)))
    assert [m.text for m in _markers(markers.take_changes())] == ["a", "b"]
    assert markers.take_changes() is None
    markers.set_colliding({"b"})
    (grey,) = _markers(markers.take_changes())
    assert grey.text == "b" and (grey.color.r, grey.color.g) == pytest.approx(COLLIDING_COLOR[:2])
    markers.set_colliding(set())
    (back,) = _markers(markers.take_changes())
    assert back.color.g == 1.0
    markers.remove(["a"])
    (deleted,) = _markers(markers.take_changes())
    assert deleted.action == Marker.DELETE and deleted.id == 1
    markers.clear()
    markers.add("c", [0.1], [], 0, (0, 0, 1, 1), "c", ((0, 0, 0), (1, 0, 0, 0)))
    assert [m.action for m in _markers(markers.take_changes())] == [Marker.DELETEALL, Marker.ADD]


def test_grey_follows_collisions_across_rebuilds_and_names_not_yet_drawn():
    pose = ((0, 0, 0), (1, 0, 0, 0))
    markers = GeometryMarkers()
    markers.set_colliding({"d"})                      # no marker yet: nothing to send
    assert markers.take_changes() is None
    markers.add("d", [0.1], [], 0, (1, 0, 0, 1), "d", pose)
    markers.take_changes()
    markers.set_colliding({"d"})                      # now drawn: it turns grey
    (grey,) = _markers(markers.take_changes())
    assert grey.color.g == pytest.approx(COLLIDING_COLOR[1])
    markers.add("d", [0.2], [], 0, (1, 0, 0, 1), "d", pose)   # rebuilt: its own colour
    assert _markers(markers.take_changes())[0].color.r == 1.0
    markers.set_colliding({"d"})                      # still colliding: grey again
    assert _markers(markers.take_changes())[0].color.g == pytest.approx(COLLIDING_COLOR[1])
    markers.set_colliding({"d"})
    assert markers.take_changes() is None             # nothing changed, nothing sent


def test_a_large_mesh_marker_is_simplified_as_the_viewer_draws_it():
    n = 200    # a 200 x 200 grid of 0.5 mm: 79,202 triangles
    x, y = np.meshgrid(np.linspace(0, 0.1, n), np.linspace(0, 0.1, n))
    vertices = np.c_[x.ravel(), y.ravel(), np.zeros(n * n)]
    k = np.arange(n * n).reshape(n, n)
    quads = np.c_[k[:-1, :-1].ravel(), k[1:, :-1].ravel(), k[1:, 1:].ravel(),
                  k[:-1, 1:].ravel()]
    indices = np.c_[quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]].ravel()
    shape = marker_shape(vertices.ravel(), indices, 0)
    assert shape.point_count < len(indices) / 2


def test_a_mesh_marker_is_made_once_per_mesh_content():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    indices = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]
    first = marker_shape(vertices.ravel(), indices, 0)
    assert marker_shape(tuple(vertices.ravel()), np.array(indices), 0) is first
    moved = marker_shape((vertices + 1).ravel(), indices, 0)
    assert moved is not first and moved.points != first.points


# -- robots and the mirror with a real Core ----------------------------------------------------

def _pendulum(core: Core, mirror: WorldMirror) -> str:
    for spec in (ObjectSpec("base", (0.1, 0.1, 0.1), position=(0, 0, 1), fixed=True),
                 ObjectSpec("bob", (0.05,), position=(0.5, 0, 1))):
        built = core.build_object(spec)
        mirror.built(built.id, core.object_spec(built.id), built.geometries)
    return core.add_joint(JointSpec(JointType.HINGE, "base", "bob", anchor=(0, 0, 1),
                                    axis1=(0, 1, 0)))


def test_a_declared_robot_renames_frames_publishes_its_joints_and_goes_with_its_objects():
    core, mirror = Core(), WorldMirror()
    joint = _pendulum(core, mirror)
    robot = robot_of(RobotMessage(name="my arm", links=["base_link", "link1"],
                                  objects=["base", "bob"], link_positions=[0] * 3 + [-0.5, 0, 0],
                                  joint_names=["shoulder"], joints=[joint],
                                  joint_offsets=[0.25]))
    mirror.set_robot(robot, {s.id: s.type for s in core.joint_states()})
    assert robot.namespace == "my_arm"
    assert mirror.frames.frames(["base", "bob"]) == ["my_arm/base_link", "my_arm/link1"]
    (changed,) = mirror.take_robot_changes()
    assert changed[0] == "set"
    markers = {m.text: m for m in _markers(mirror.markers.take_changes())}
    assert markers["bob"].header.frame_id == "my_arm/link1"
    assert markers["bob"].pose.position.x == pytest.approx(0.5)     # the link frame is at -0.5
    (states,) = mirror.robots.joint_states(core.joint_states())
    assert states[1:3] == (["shoulder"], [0.25])
    assert mirror.movable_objects() == []                           # links move by joints
    mirror.removed("bob", [joint])
    assert len(mirror.robots) == 0 and mirror.take_robot_changes()[0][0] == "remove"
    assert mirror.frames.frames(["base"]) == ["base"]


def test_a_robots_wheel_is_its_hinge2s_spin_named_by_joint_axes():
    """A car's wheel (a hinge-2: steering, then spin) is a URDF continuous joint: joint_axes
    1 makes its joint state the hinge-2's second value, the spin, not the steering."""
    core, mirror = Core(), WorldMirror()
    for spec in (ObjectSpec("chassis", (0.4, 0.2, 0.05), position=(0, 0, 1)),
                 ObjectSpec("wheel", (0.05, 0.02), position=(0, 0.15, 1))):
        built = core.build_object(spec)
        mirror.built(built.id, core.object_spec(built.id), built.geometries)
    hinge2 = core.add_joint(JointSpec(JointType.HINGE2, "chassis", "wheel", anchor=(0, 0.15, 1),
                                      axis1=(0, 0, 1), axis2=(0, 1, 0)))
    core.set_velocity("wheel", angular=(0, 3.0, 0))
    robot = robot_of(RobotMessage(name="car", links=["base", "wheel_link"],
                                  objects=["chassis", "wheel"], joint_names=["wheel_joint"],
                                  joints=[hinge2], joint_axes=b"\x01"))
    mirror.set_robot(robot, {s.id: s.type for s in core.joint_states()})
    assert robot_message(robot).joint_axes == [1]
    (state,) = [s for s in core.joint_states() if s.id == hinge2]
    (_, names, positions, rates), = mirror.robots.joint_states(core.joint_states())
    assert names == ["wheel_joint"]
    assert rates == [state.rates[1]] and abs(rates[0]) > 1.0 and positions == [state.positions[1]]


def test_set_robot_refuses_what_does_not_fit_the_world():
    core, mirror = Core(), WorldMirror()
    joint = _pendulum(core, mirror)
    types = {s.id: s.type for s in core.joint_states()}
    for fields, error in [
            (dict(links=["a"], objects=["nothing"]), UnknownName),
            (dict(links=["a"], objects=["bob"], joint_names=["j"], joints=["nope"]), UnknownName),
            (dict(links=["a", "b"], objects=["bob"]), InvalidArgument),
            (dict(links=["a", "a"], objects=["bob", "base"]), InvalidArgument),
            (dict(links=["a"], objects=["bob"], link_positions=[1, 2]), InvalidArgument),
            (dict(links=["a"], objects=["bob"], link_orientations=[2, 0, 0, 0]),
             InvalidArgument),
            (dict(links=["a"], objects=["bob"], joint_names=["j"], joints=[joint],
                  joint_offsets=[math.nan]), InvalidArgument),
            (dict(links=["a"], objects=["bob"], joint_names=["j"], joints=[joint],
                  joint_axes=[0, 0]), InvalidArgument),
            (dict(links=["a"], objects=["bob"], joint_names=["j"], joints=[joint],
                  joint_axes=[-1]), InvalidArgument),
            (dict(links=["a"], objects=["bob"], joint_names=["j"], joints=[joint],
                  joint_axes=[1]), InvalidArgument)]:
        with pytest.raises(error):
            mirror.set_robot(robot_of(RobotMessage(name="r", **fields)), types)
    assert len(mirror.robots) == 0 and mirror.frames.frames(["bob"]) == ["bob"]
    core.build_object(ObjectSpec("ball2", (0.05,), position=(3, 0, 1)))
    ball = core.add_joint(JointSpec(JointType.BALL, "ball2", "", anchor=(3, 0, 1.2)))
    with pytest.raises(InvalidArgument, match="ball"):
        mirror.robots.check(robot_of(RobotMessage(name="r", joint_names=["j"], joints=[ball])),
                            [], {s.id: s.type for s in core.joint_states()})
    mirror.set_robot(robot_of(RobotMessage(name="my arm", links=["l"], objects=["bob"])), types)
    with pytest.raises(InvalidArgument, match="already belong to robot 'my arm'"):
        mirror.set_robot(robot_of(RobotMessage(name="two", links=["l"], objects=["bob"])), types)
    with pytest.raises(InvalidArgument, match="namespace"):
        mirror.set_robot(robot_of(RobotMessage(name="my-arm", links=["l"], objects=["base"])),
                         types)


def test_a_composite_built_in_the_core_is_framed_at_its_own_origin():
    core, mirror = Core(), WorldMirror()
    spec = CompositeSpec(parts=(PartSpec("p#0", (0.1,), position=(0.3, 0, 0)),
                                PartSpec("p#1", (0.1, 0.1, 0.1), position=(-0.3, 0, 0))),
                         position=(1, 2, 3), orientation=_quaternion(0.5))
    built = core.build_composite(spec)
    mirror.built(built.id, core.object_spec(built.id), built.geometries)
    names, positions, quaternions = core.poses()
    (frames, p, q), _ = mirror.frames.poses(names, positions, quaternions)
    assert frames == ["_p_0_p_1"]
    assert p[0] == pytest.approx([1, 2, 3], abs=1e-12)
    assert q[0] == pytest.approx(_quaternion(0.5), abs=1e-12)
    assert mirror.movable_objects() == [built.id]
    assert mirror.objects[built.id].size == pytest.approx(0.8)
