"""The VirtualWorld node through ROS: every service, topic and timing rule of the Portal.

Each test has its own roscore (the ros_master fixture) and runs in a forked process, because
rospy.init_node works once per process.
"""
from __future__ import annotations

import math
import time

import pytest

pytestmark = pytest.mark.forked


@pytest.fixture
def world(ros_master):
    """A virtualWorld node (paused, default step values) and a client of it."""
    import rospy
    from world_client import WorldClient

    node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    rospy.init_node("odin_test_client", anonymous=True, disable_signals=True)
    client = WorldClient()
    yield client
    client.close()
    assert node.poll() is None, "virtualWorld died:\n" + ros_master.log_text(node)[-3000:]


def _height(client, name):
    return client.poses()[name][0][2]


def test_build_shapes_and_world_update(world):
    from Messages import msg
    from world_client import box, sphere

    assert world.ok("build_object", object=sphere("ball", 0.2, (0, 0, 2))).id == "ball"
    world.ok("build_object", object=msg.Object(
        name="can", parameters=[0.05, 0.2], mass=0.3, position=[1, 0, 1],
        orientation=[math.cos(0.3), math.sin(0.3), 0, 0]))
    world.ok("build_object", object=box("crate", (0.2, 0.3, 0.4), (2, 0, 1)))
    tetra = [0, 0, 0, 0.2, 0, 0, 0, 0.2, 0, 0, 0, 0.2]
    world.ok("build_object", object=msg.Object(
        name="tetra", parameters=tetra, indices=[0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3], mass=0.5,
        position=[3, 0, 1], orientation=[1, 0, 0, 0]))
    poses = world.poses()
    assert {"ball", "can", "crate", "tetra"} <= set(poses)
    assert poses["ball"][0] == pytest.approx((0, 0, 2))
    assert poses["can"][1] == pytest.approx((math.cos(0.3), math.sin(0.3), 0, 0), abs=1e-9)


def test_bad_requests_change_nothing_and_the_node_stays_up(world):
    from Messages import msg
    from world_client import sphere

    world.ok("build_object", object=sphere("ball"))
    nan = float("nan")
    bad = [
        msg.Object(),                                                         # empty
        sphere(""),                                                           # no name
        sphere("ball"),                                                       # duplicate
        sphere("a>b"),                                                        # reserved char
        msg.Object(name="q0", parameters=[0.1], mass=1, orientation=[0, 0, 0, 0]),
        msg.Object(name="q2", parameters=[0.1], mass=1, orientation=[2, 0, 0, 0]),
        sphere("m0", mass=0.0), sphere("mneg", mass=-1.0), sphere("nanpos", position=(nan, 0, 0)),
        sphere("nanr", radius=nan), sphere("negr", radius=-0.1),
        msg.Object(name="p4", parameters=[1, 2, 3, 4], mass=1, orientation=[1, 0, 0, 0]),
        msg.Object(name="mesh", parameters=[0] * 9, indices=[0, 1, 7], mass=1,
                   orientation=[1, 0, 0, 0]),
    ]
    for request in bad:
        response = world("build_object", object=request)
        assert not response.success and response.message, request
    assert set(world.poses()) == {"ball"}
    for name, fields in [
        ("remove_object", {"id": "nobody"}),
        ("set_joint", {"action": 0, "type": 1, "body1": "ball", "body2": "ghost"}),
        ("set_joint", {"action": 0, "type": 42, "body1": "ball"}),
        ("set_joint", {"action": 7, "id": "x"}),
        ("set_motor", {"joint": "nope"}),
        ("set_motor", {"remove": True, "id": "motor:none"}),
        ("set_position", {"situations": []}),
        ("set_position", {"situations": [msg.Situation("ghost", [0, 0, 0], [1, 0, 0, 0])]}),
        ("set_position", {"situations": [msg.Situation("ball", [nan, 0, 0], [1, 0, 0, 0])]}),
        ("set_velocity", {}),
        ("set_velocity", {"object": "ball", "set_linear": True, "linear": [nan, 0, 0]}),
        ("set_velocity", {"motors": ["motor:none"], "velocities": [1.0]}),
        ("set_external_force", {"object": "ghost", "vector": [0, 0, 1]}),
        ("set_external_force", {"object": "ball", "vector": [nan, 0, 0]}),
        ("set_external_force", {"remove": True, "id": "force:ball:7"}),
        ("set_joint_force", {"joint": "nope", "magnitudes": [1.0]}),
        ("set_world", {}),
        ("set_world", {"set_erp": True, "erp": 2.0}),
        ("set_world", {"set_gravity": True, "gravity": [0, 0, nan]}),
        ("set_step", {}),
        ("set_step", {"step": -1.0}),
        ("step_once", {"cycles": 10**7}),
    ]:
        response = world(name, **fields)
        assert not response.success and response.message, (name, fields)
    assert world.poses()["ball"][0] == pytest.approx((0, 0, 1))


def test_step_once_advances_exactly_one_cycle_while_paused(world):
    from world_client import sphere

    world.ok("build_object", object=sphere("ball", position=(0, 0, 10)))
    time.sleep(0.3)
    assert _height(world, "ball") == pytest.approx(10.0)          # paused: nothing moves
    response = world.ok("step_once", cycles=1)
    assert response.sim_time == pytest.approx(0.04)
    # semi-implicit Euler over 40 steps of 1 ms: z = z0 - g h^2 n (n + 1) / 2
    assert _height(world, "ball") == pytest.approx(10 - 9.81 * 1e-6 * 40 * 41 / 2, abs=1e-9)
    world.ok("start", simulate=True)
    assert not world("step_once").success                          # running: refused
    world.ok("start", simulate=False)


def test_start_runs_in_real_time_and_stop_freezes(world):
    import rospy
    from rosgraph_msgs.msg import Clock
    from world_client import sphere

    world.ok("build_object", object=sphere("ball", position=(0, 0, 100)))
    world.ok("start", simulate=True)
    first = rospy.wait_for_message("/clock", Clock, timeout=5).clock.to_sec()
    time.sleep(1.0)
    second = rospy.wait_for_message("/clock", Clock, timeout=5).clock.to_sec()
    assert 0.6 <= second - first <= 1.3        # default step values: real time
    assert world.ok("start", simulate=False).simulating is False
    frozen = _height(world, "ball")
    time.sleep(0.3)
    assert _height(world, "ball") == frozen


def test_set_step_combinations_return_the_values_in_force(world):
    response = world.ok("set_step", step=0.002)
    assert (response.step, response.steps_per_cycle, response.cycle_time) == \
        pytest.approx((0.002, 20, 0.04))
    response = world.ok("set_step", steps_per_cycle=10, cycle_time=0.05)
    assert (response.step, response.steps_per_cycle) == pytest.approx((0.005, 10))
    response = world.ok("set_step", step=0.001, steps_per_cycle=1, rate=10.0)   # table 10.1
    assert (response.cycle_time, response.rate) == pytest.approx((0.001, 10.0))
    assert world.ok("step_once").sim_time == pytest.approx(0.001)


def test_set_world_returns_values_in_force(world):
    response = world.ok("set_world", set_gravity=True, gravity=[0, 0, 0], set_erp=True, erp=0.5,
                        set_max_contacts=True, max_contacts=5, set_contact_less=True,
                        contact_less=True)
    assert list(response.gravity) == [0, 0, 0]
    assert (response.erp, response.max_contacts, response.contact_less) == (0.5, 5, True)
    response = world.ok("set_world", set_cfm=True, cfm=0.0)
    assert response.erp == 0.5 and response.cfm == 0.0              # earlier values kept
    response = world.ok("set_world", set_collision_mesh_tolerance=True,
                        collision_mesh_tolerance=0.004)
    assert response.collision_mesh_tolerance == 0.004
    refused = world("set_world", set_collision_mesh_tolerance=True,
                    collision_mesh_tolerance=4.0)                   # mm given as m
    assert not refused.success and "collision_mesh_tolerance" in refused.message
    assert refused.collision_mesh_tolerance == 0.004                # unchanged


def test_joints_motors_and_forces_are_named_and_removed_in_cascade(world):
    from world_client import box, sphere

    world.ok("set_world", set_gravity=True, gravity=[0, 0, 0])
    world.ok("build_object", object=box("base", (0.2, 0.2, 0.2), (0, 0, 1)))
    world.ok("build_object", object=sphere("tip", 0.05, (0.5, 0, 1)))
    joint = world.ok("set_joint", action=0, type=1, body1="base", body2="tip",
                     anchor=[0, 0, 1], axis1=[0, 0, 1]).id
    assert joint == "1:base&tip"
    assert not world("set_joint", action=0, type=0, body1="tip", body2="base").success  # 1/pair
    ground = world.ok("set_joint", action=0, type=8, body1="base", body2="").id
    assert ground == "8:base&"
    motor = world.ok("set_motor", joint=joint).id
    assert motor == "motor:" + joint
    first = world.ok("set_external_force", object="tip", kind=0, vector=[0, 1, 0]).id
    second = world.ok("set_external_force", object="tip", kind=0, vector=[0, 1, 0]).id
    assert (first, second) == ("force:tip:0", "force:tip:1")
    world.ok("set_external_force", remove=True, id=first)
    assert world.ok("set_external_force", object="tip", kind=0, vector=[0, 1, 0]).id == first
    world.ok("set_external_force", remove=True, id=first)
    world.ok("set_external_force", remove=True, id=second)
    joint_force = world.ok("set_joint_force", joint=joint, magnitudes=[0.1]).id
    assert joint_force == f"jointforce:{joint}:0"
    world.ok("set_joint_force", remove=True, id=joint_force)
    world.ok("set_velocity", motors=[motor], velocities=[1.0])
    world.ok("step_once", cycles=25)                       # one simulated second
    states = _joint_states()
    assert states[joint] == pytest.approx(1.0, rel=0.05)    # the motor turned the hinge
    world.ok("set_external_force", object="tip", kind=0, vector=[0, 0, 1])
    removed = world.ok("remove_object", id="tip").message
    assert joint in removed and motor in removed and "force:tip:0" in removed
    assert not world("set_velocity", motors=[motor], velocities=[1.0]).success
    assert set(world.poses()) == {"base"}


def _joint_states() -> dict:
    import rospy
    from sensor_msgs.msg import JointState
    message = rospy.wait_for_message("/virtual_world/joint_states", JointState, timeout=5)
    return dict(zip(message.name, message.position))


def test_composites_and_entities(world):
    from Messages import msg
    from world_client import sphere

    legs = [msg.Part(name=f"leg{i}", parameters=[0.03, 0.4], mass=0.2,
                     position=[x, y, -0.2], orientation=[1, 0, 0, 0])
            for i, (x, y) in enumerate([(0.4, 0.2), (-0.4, 0.2), (0.4, -0.2), (-0.4, -0.2)])]
    top = msg.Part(name="top", parameters=[1.0, 0.6, 0.05], mass=2.0, position=[0, 0, 0],
                   orientation=[1, 0, 0, 0])
    table = world.ok("build_composite", composite=msg.Composite(
        parts=[top] + legs, position=[0, 0, 0.45], orientation=[1, 0, 0, 0])).id
    assert table == ">top>leg0>leg1>leg2>leg3"
    poses = world.poses()
    assert {"top", "leg0", "leg3"} <= set(poses) and table not in poses
    assert poses["leg0"][0] == pytest.approx((0.4, 0.2, 0.25), abs=1e-9)
    response = world.ok("build_entity", objects=[sphere("a", position=(3, 0, 1)),
                                                 sphere("b", position=(3, 0, 1.15))],
                        internal_collisions=False)
    assert list(response.ids) == ["a", "b"] and response.id
    # all or nothing: the second member is a duplicate, so "c" is not built either
    assert not world("build_entity", objects=[sphere("c"), sphere("a")]).success
    assert "c" not in world.poses()
    world.ok("remove_object", id=table)
    assert "top" not in world.poses()


def test_contact_less_collisions_are_reported_with_depth(world):
    import rospy
    from Messages.msg import Collided
    from world_client import box, sphere, wait_until

    world.ok("set_world", set_contact_less=True, contact_less=True, set_gravity=True,
             gravity=[0, 0, 0])
    world.ok("build_object", object=box("wall", (0.2, 2, 2), (0, 0, 0)))
    world.ok("build_object", object=sphere("ball", 0.1, (0.25, 0, 0)))
    world.ok("set_velocity", object="ball", set_linear=True, linear=[-1.0, 0, 0])
    reports = []
    sub = rospy.Subscriber("/virtual_world/collided", Collided, reports.append)
    wait_until(lambda: sub.get_num_connections() > 0, timeout=30)
    world.ok("step_once", cycles=5)          # 0.2 s: the ball enters the wall, no contacts

    def pairs():
        return [pair for report in list(reports) for pair in report.pairs]
    try:                                     # the paused world reports what touches now
        wait_until(lambda: any(pair.depth > 0.05 for pair in pairs()), timeout=30)
    except TimeoutError:
        pass                                 # the asserts below say what came
    sub.unregister()
    pairs = pairs()
    assert pairs, "no collision reported"
    assert {pairs[-1].first, pairs[-1].second} == {"wall", "ball"}
    assert max(pair.depth for pair in pairs) > 0.05
    assert world.poses()["ball"][0][0] < 0.05      # passed into the wall: no contact joints


def test_documented_rosservice_call_examples_work_from_the_command_line(world, ros_master):
    result = ros_master.run(["rosservice", "call", "/virtual_world/build_object",
                             "{object: {name: cli, parameters: [0.1], mass: 1.0, "
                             "position: [0, 0, 1], orientation: [1, 0, 0, 0]}}"])
    assert "success: True" in result.stdout and 'id: "cli"' in result.stdout
    result = ros_master.run(["rosservice", "call", "/virtual_world/build_object",
                             "{object: {name: cli, parameters: [0.1], mass: 1.0, "
                             "position: [0, 0, 1], orientation: [1, 0, 0, 0]}}"])
    assert "success: False" in result.stdout
    result = ros_master.run(["rosservice", "call", "/virtual_world/step_once", "cycles: 2"])
    assert "success: True" in result.stdout and "sim_time: 0.08" in result.stdout


def test_a_viewer_started_late_receives_the_current_scene(world, ros_master):
    import rospy
    from Services.srv import SaveSnapshot
    from world_client import box

    world.ok("build_object", object=box("early", (0.5, 0.5, 0.5), (0, 0, 0.25),
                                        color=[0.9, 0.1, 0.1, 1]))
    ros_master.rosrun("Viewer", "viewer", f"_snapshot_dir:={ros_master.ros_home}")
    ros_master.wait_for_service("/viewer/save_snapshot")
    from PIL import Image
    import numpy as np
    from world_client import wait_until

    def red_pixels():   # the world's link looks for a Viewer every second
        response = rospy.ServiceProxy("/viewer/save_snapshot", SaveSnapshot)("late.png")
        assert response.success, response.message
        image = np.asarray(Image.open(response.path).convert("RGB")).astype(int)
        reddish = (image[..., 0] > 120) & (image[..., 1] < 90) & (image[..., 2] < 90)
        return reddish.sum() > 200

    wait_until(red_pixels, timeout=20, period=0.5)   # the early box in the late Viewer's frame


def test_a_restarted_viewer_receives_the_scene_again_over_new_connections(world, ros_master):
    """The world's link keeps its connections to the Viewer open between calls; when that
    Viewer is gone and another starts, the link connects to the new one and re-sends."""
    import rospy
    import numpy as np
    from PIL import Image
    from Services.srv import SaveSnapshot
    from world_client import box, wait_until

    def has(colour_channel):
        def check():
            response = rospy.ServiceProxy("/viewer/save_snapshot", SaveSnapshot)("again.png")
            assert response.success, response.message
            image = np.asarray(Image.open(response.path).convert("RGB")).astype(int)
            others = [image[..., c] for c in range(3) if c != colour_channel]
            strong = (image[..., colour_channel] > 120) & (others[0] < 90) & (others[1] < 90)
            return strong.sum() > 200
        return check

    world.ok("build_object", object=box("red", (0.5, 0.5, 0.5), (0, -0.6, 0.25),
                                        color=[0.9, 0.1, 0.1, 1]))
    first = ros_master.rosrun("Viewer", "viewer", f"_snapshot_dir:={ros_master.ros_home}")
    ros_master.wait_for_service("/viewer/save_snapshot")
    wait_until(has(0), timeout=20, period=0.5)
    world.ok("build_object", object=box("green", (0.5, 0.5, 0.5), (0, 0.6, 0.25),
                                        color=[0.1, 0.9, 0.1, 1]))   # over the open connection
    wait_until(has(1), timeout=20, period=0.5)
    first.terminate()
    first.wait(timeout=30)
    world.ok("build_object", object=box("blue", (0.5, 0.5, 0.5), (0, 0, 1.0),
                                        color=[0.1, 0.1, 0.9, 1]))   # while no Viewer is up
    ros_master.rosrun("Viewer", "viewer", f"_snapshot_dir:={ros_master.ros_home}")
    rospy.wait_for_service("/viewer/save_snapshot", timeout=30)  # (the first one is gone)
    wait_until(lambda: all(has(c)() for c in range(3)), timeout=30, period=0.5)


def test_start_up_parameters_are_read(ros_master):
    import rospy
    from std_msgs.msg import Float64
    from world_client import WorldClient

    ros_master.rosrun("VirtualWorld", "virtualWorld", "_rate:=10", "_step:=0.002",
                      "_steps_per_cycle:=5", "_contact_less:=true", "_gravity:=[0, 0, -1.5]",
                      "_max_contacts:=4", "_collision_mesh_tolerance:=0.003",
                      "_auto_disable:=true")
    ros_master.wait_for_service("/virtual_world/set_joint_force")
    rospy.init_node("odin_test_client", anonymous=True, disable_signals=True)
    client = WorldClient()
    assert client.ok("step_once").sim_time == pytest.approx(0.01)
    values = client.ok("set_world", set_erp=True, erp=0.2)
    assert values.contact_less and values.max_contacts == 4
    assert values.collision_mesh_tolerance == 0.003 and values.auto_disable is True
    assert list(values.gravity) == [0, 0, -1.5]
    step = client.ok("set_step", rate=10.0)
    assert (step.step, step.steps_per_cycle) == pytest.approx((0.002, 5))
    client.ok("start", simulate=True)
    time.sleep(1.5)
    rtf = rospy.wait_for_message("/virtual_world/real_time_factor", Float64, timeout=5).data
    assert rtf == pytest.approx(0.1, rel=0.3)   # 0.01 s simulated per 0.1 s cycle
    client.close()


def test_a_bad_start_up_parameter_ends_the_node_with_one_line(ros_master):
    node = ros_master.rosrun("VirtualWorld", "virtualWorld", "_erp:=7.0")
    assert node.wait(timeout=30) != 0
    log = ros_master.log_text(node)
    assert "erp" in log and "bad start-up parameter" in log


def test_refused_set_world_and_set_step_still_report_the_values_in_force(world):
    refused = world("set_step")
    assert not refused.success and refused.message
    assert (refused.step, refused.steps_per_cycle, refused.rate) == pytest.approx((0.001, 40, 25))
    refused = world("set_world", set_erp=True, erp=5.0)
    assert not refused.success and "erp" in refused.message
    assert refused.erp == pytest.approx(0.2) and list(refused.gravity) == [0, 0, -9.81]


def test_a_paused_contact_less_world_reports_what_touches_now(world):
    import rospy
    from Messages.msg import Collided, Situation
    from world_client import box, sphere

    world.ok("set_world", set_contact_less=True, contact_less=True)
    world.ok("build_object", object=box("wall", (0.2, 2, 2), (0, 0, 0), geometry_only=True))
    world.ok("build_object", object=sphere("ball", 0.1, (1, 0, 0)))
    world.ok("set_position", situations=[Situation("ball", [0.15, 0, 0], [1, 0, 0, 0])])
    for _ in range(3):   # every idle cycle, not only the first after the move
        report = rospy.wait_for_message("/virtual_world/collided", Collided, timeout=5)
        assert sorted(report.names) == ["ball", "wall"]
    world.ok("set_position", situations=[Situation("ball", [1, 0, 0], [1, 0, 0, 0])])
    time.sleep(0.2)
    assert rospy.wait_for_message("/virtual_world/collided", Collided, timeout=5).names == []
