"""The world node against hostile values, through ROS: a Build Object whose inertia no body of
its mass and size can have (ODE had ended the process at the next Step Once), colours out of
[0, 1], a negative mass on geometry, a name of a megabyte, a Set Position of more situations
than objects and a Propagate of too much work are each refused in one short line, and the
node steps and answers afterwards."""
from __future__ import annotations

import pytest

pytestmark = pytest.mark.forked


def test_hostile_requests_are_refused_in_a_line_and_the_world_steps_on(ros_master):
    import rospy
    from Messages.msg import Situation
    from world_client import WorldClient, box, sphere

    node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/step_once")
    rospy.init_node("odin_test_client", anonymous=True, disable_signals=True)
    world = WorldClient()
    world.ok("build_object", object=sphere("ball", 0.15, (0, 0, 1)))
    heavy = sphere("heavy", 0.15, (1, 0, 1))
    heavy.inertia = [1e250, 1e250, 1e250, 0.0, 0.0, 0.0]
    refusals = [world("build_object", object=heavy)]
    refusals.append(world("build_object", object=sphere("pink", 0.1, (2, 0, 1),
                                                        color=[1.0, 0.5, 3.0, 1.0])))
    refusals.append(world("build_object", object=box("wall", (1, 1, 1), (0, 3, 0.5),
                                                     geometry_only=True, mass=-1.0)))
    refusals.append(world("build_object", object=sphere("n" * 2 ** 20, 0.1, (3, 0, 1))))
    refusals.append(world("set_position", situations=[
        Situation(name=f"ghost{k}", position=[0, 0, 0], orientation=[1, 0, 0, 0])
        for k in range(1000)]))
    for k in range(30):
        world.ok("build_object", object=sphere(f"m{k}", 0.05, (k * 0.2, 5, 1)))
    refusals.append(world("propagate", duration=500.0, step=0.001))
    for refused in refusals:
        assert not refused.success and "\n" not in refused.message
        assert len(refused.message) < 400 and "internal error" not in refused.message
    world.ok("step_once", cycles=5)
    assert world.ok("get_world").objects == ["ball"] + [f"m{k}" for k in range(30)]
    assert node.poll() is None


CALL_AND_GO = """
import rospy
from Services.srv import Propagate
rospy.init_node("odin_impatient_client", anonymous=True, disable_signals=True)
print("calling", flush=True)
rospy.ServiceProxy("/virtual_world/propagate", Propagate)(duration=20.0, step=0.001)
"""


def test_a_long_propagate_stops_when_its_caller_has_gone(ros_master):
    """A Propagate of ~1,000 s of work (10 spheres resting on the ground under QuickStep at
    100,000 iterations, ~50 ms a step, 20,000 steps: far within MAX_BODY_STEPS_PER_CALL)
    whose client gives up after a second and exits: the world notices the closed
    connection between pieces, puts the state back and answers Get World within seconds,
    its simulated time as before the call."""
    import subprocess
    import sys
    import threading
    import time

    import rospy
    from world_client import WorldClient, box, sphere

    node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/propagate")
    rospy.init_node("odin_test_client", anonymous=True, disable_signals=True)
    world = WorldClient()
    world.ok("set_world", set_solver=True, solver=0, quickstep_iterations=100_000)
    world.ok("build_object", object=box("ground", (20, 20, 0.2), (0, 0, -0.1),
                                        geometry_only=True))
    for k in range(10):
        world.ok("build_object", object=sphere(f"p{k}", 0.1, (k * 0.5, 0, 0.1)))
    client = subprocess.Popen([sys.executable, "-c", CALL_AND_GO], env=ros_master.env,
                              stdout=subprocess.PIPE, text=True)
    try:
        assert client.stdout.readline().strip() == "calling"
        time.sleep(1.5)                     # the call is under way: the world is busy
    finally:
        client.kill()                       # gone: its connection closes
        client.wait(10)
    answered = {}
    asked = time.monotonic()
    thread = threading.Thread(target=lambda: answered.update(world=world("get_world")),
                              daemon=True)
    thread.start()
    thread.join(15.0)
    assert "world" in answered, "the world still runs the propagation of a caller gone"
    assert time.monotonic() - asked < 10.0
    assert answered["world"].success and answered["world"].sim_time == 0.0
    assert node.poll() is None
