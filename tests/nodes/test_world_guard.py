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
