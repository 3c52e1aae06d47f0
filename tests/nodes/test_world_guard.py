"""A world that cannot be killed by its inputs, through ROS: the issue's force of 1e300 N is
refused; a force within the limits that makes a light body diverge parks it, says so on
/diagnostics, and the node keeps answering and publishing finite poses."""
from __future__ import annotations

import math
import threading

import pytest

pytestmark = pytest.mark.forked


def test_a_diverging_body_is_parked_reported_and_the_world_runs_on(ros_master):
    import rospy
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
    from world_client import WorldClient, box, sphere

    node = ros_master.rosrun("VirtualWorld", "virtualWorld", "_simulate:=true")
    ros_master.wait_for_service("/virtual_world/set_external_force")
    rospy.init_node("odin_test_client", anonymous=True, disable_signals=True)
    errors, lock = [], threading.Lock()

    def on_diagnostics(message):
        with lock:
            errors.extend(s for s in message.status if s.level == DiagnosticStatus.ERROR)
    rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics)
    world = WorldClient()
    world.ok("build_object", object=box("ground", (4, 4, 0.2), (0, 0, -0.1), geometry_only=True))
    for i in range(10):
        world.ok("build_object", object=sphere(f"s{i}", 0.1, (0.05 * i, 0, 0.3 + 0.21 * i)))
    world.ok("build_object", object=sphere("dust", 0.01, (2, 2, 0.5), mass=1e-6))
    refused = world("set_external_force", object="s0", kind=0, vector=[0, 0, 1e300])
    assert not refused.success and "beyond the limit" in refused.message
    world.ok("set_external_force", object="dust", kind=0, vector=[1e7, 0, 0])
    deadline = rospy.Time.now() + rospy.Duration(10)
    while not errors and rospy.Time.now() < deadline:
        rospy.sleep(0.05)
    with lock:
        (error,) = errors
    assert "dust" in error.message and "parked" in error.message
    values = {kv.key: kv.value for kv in error.values}
    assert values["object"] == "dust" and "divergence_speed" in values["reason"]
    for _ in range(5):                     # still stepping and publishing, every pose finite
        poses = world.poses()
        assert all(math.isfinite(v) for p, q in poses.values() for v in (*p, *q))
    assert world.ok("get_world").sim_time > 0.2
    world.close()
    assert node.poll() is None, ros_master.log_text(node)[-2000:]


def room_mesh():
    """(vertices, triangles) flat lists: a 12 m x 6 m floor and two 3 m walls, closed boxes
    (outward counter-clockwise) in one mesh."""
    corners = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    box = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6,
           0, 6, 4, 1, 5, 7, 1, 7, 3]
    vertices, triangles = [], []
    for k, (sides, centre) in enumerate((((12, 6, 0.1), (0, 0, -0.05)),
                                         ((12, 0.1, 3), (0, 3, 1.5)), ((0.1, 6, 3), (6, 0, 1.5)))):
        vertices += [c * s / 2 + o for corner in corners for c, s, o in zip(corner, sides, centre)]
        triangles += [8 * k + i for i in box]
    return vertices, triangles


def test_a_body_too_light_in_rotation_for_its_size_is_refused_and_the_node_lives(ros_master):
    """Kautham's IOC lab layout (a 12 m room of 0.05 kg whose URDF inertia, scaled with its
    mesh, is 7e-8 kg m^2) under ODE's dense solver, loaded pieces resting on its floor: ODE
    aborted the node inside the step (issue 31's TIAGo warehouse). The room is refused, naming
    the limit; the rest is built and steps, and the node answers."""
    import rospy
    from world_client import WorldClient, box
    from Messages.msg import Object

    node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/step_once")
    rospy.init_node("odin_test_client", anonymous=True, disable_signals=True)
    world = WorldClient()
    world.ok("set_world", set_solver=True, solver=1, quickstep_iterations=20)
    vertices, triangles = room_mesh()
    refused = world("build_object", object=Object(
        name="room", parameters=vertices, indices=triangles, mass=0.05,
        inertia=[6.8e-8] * 3 + [0] * 3, center_of_mass=[0, 0, 0], position=[0, 0, 0],
        orientation=[1, 0, 0, 0]))
    assert not refused.success and "MIN_GYRATION_FRACTION" in refused.message
    for i in range(16):
        world.ok("build_object", object=box(f"b{i}", (1.0, 0.8, 0.7), (
            -5 + (i % 8) * 1.4, -2 + (i // 8) * 1.5, 0.349), mass=0.05))
    world.ok("step_once", cycles=10)
    assert world.ok("get_world").objects == [f"b{i}" for i in range(16)]
    world.close()
    assert node.poll() is None, ros_master.log_text(node)[-2000:]


def test_resource_limits_refuse_what_would_exhaust_memory_and_the_node_goes_on(ros_master):
    """~max_request_mb: a 2 MB mesh request against a 1 MB cap fails the call before the node
    reads its body; ~max_objects and ~max_snapshots refuse with a message; a bad limit stops
    the node at start with one line."""
    import rospy
    from world_client import WorldClient, sphere
    from gui.errors import ServiceError
    from Messages.msg import Object

    node = ros_master.rosrun("VirtualWorld", "virtualWorld", "_max_request_mb:=1",
                             "_max_objects:=2", "_max_snapshots:=1")
    ros_master.wait_for_service("/virtual_world/save_state")
    rospy.init_node("odin_test_client", anonymous=True, disable_signals=True)
    world = WorldClient()
    vertices = [float(i % 7) * 0.01 for i in range(3 * 90_000)]        # 2.1 MB of float64
    big = Object(name="big", parameters=vertices, indices=[0, 1, 2], mass=1.0,
                 position=[0, 0, 0], orientation=[1, 0, 0, 0])
    with pytest.raises(ServiceError, match="call failed"):   # the connection was dropped
        world("build_object", object=big)
    assert "limit is 1,048,576 bytes" in ros_master.log_text(node)
    world.ok("build_object", object=sphere("a"))
    world.ok("build_object", object=sphere("b", position=(1, 0, 1)))
    refused = world("build_object", object=sphere("c", position=(2, 0, 1)))
    assert not refused.success and "max_objects" in refused.message
    world.ok("save_state", name="one")
    refused = world("save_state", name="two")
    assert not refused.success and "max_snapshots" in refused.message
    assert world.ok("get_world").objects == ["a", "b"]
    world.close()
    assert node.poll() is None, ros_master.log_text(node)[-2000:]
    bad = ros_master.rosrun("VirtualWorld", "virtualWorld", "__name:=bad_world",
                            "_max_objects:=-5")
    assert bad.wait(timeout=30) == 2
    assert "max_objects=-5 must be a positive integer" in ros_master.log_text(bad)
