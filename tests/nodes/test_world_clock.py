"""One simulated time across New Scene (docs/ROS.md): the world's stamps never go back, and
every topic of one publication carries the same one (world_update, /clock, /tf, a robot's
joint_states); a tf2 listener and a ``use_sim_time`` node run through several New Scenes
without seeing time go back; and roslaunch GUI odin.launch builds a problem."""
from __future__ import annotations

import collections
import threading
import time

import numpy as np
import pytest

pytestmark = pytest.mark.forked

PENDULUM_URDF = """<?xml version="1.0"?>
<robot name="pendulum">
  <link name="pivot"/>
  <link name="bob"/>
  <joint name="swing" type="continuous">
    <parent link="pivot"/><child link="bob"/><axis xyz="0 1 0"/>
  </joint>
</robot>
"""


def _scene(client) -> None:
    """A static pivot and a ball hanging from it on a hinge, declared as a robot."""
    from gui.core.robot_description import RobotDescription
    from odin_common.interface import JointType
    from odin_common.specs import JointSpec, ObjectSpec
    client.build_object(ObjectSpec("pivot", (0.05, 0.05, 0.05), position=(0, 0, 1.5),
                                   fixed=True))
    client.build_object(ObjectSpec("ball", (0.1,), position=(0.5, 0, 1.5)))
    joint = client.add_joint(JointSpec(JointType.HINGE, "ball", "pivot", anchor=(0, 0, 1.5),
                                       axis1=(0, 1, 0)))
    client.set_robot(RobotDescription(
        name="pendulum", urdf=PENDULUM_URDF, links=("pivot", "bob"), objects=("pivot", "ball"),
        link_positions=(), link_orientations=(), joint_names=("swing",), joints=(joint,),
        joint_axes=(), joint_offsets=(), generated=False))


class _Stamps:
    """Every stamp received on each topic, in arrival order."""

    def __init__(self):
        import rospy
        from Messages.msg import SpaceDistribution
        from rosgraph_msgs.msg import Clock
        from sensor_msgs.msg import JointState
        from tf2_msgs.msg import TFMessage
        self.by_topic = collections.defaultdict(list)
        self._lock = threading.Lock()
        self._subscribers = [
            rospy.Subscriber("/clock", Clock, self._add, "clock", queue_size=1000),
            rospy.Subscriber("/virtual_world/world_update", SpaceDistribution, self._add,
                             "world_update", queue_size=1000),
            rospy.Subscriber("/tf", TFMessage, self._add, "tf", queue_size=1000),
            rospy.Subscriber("/pendulum/joint_states", JointState, self._add, "joint_states",
                             queue_size=1000)]

    def _add(self, message, topic) -> None:
        if topic == "clock":
            stamp = message.clock
        elif topic == "tf":
            stamp = message.transforms[0].header.stamp if message.transforms else None
        else:
            stamp = message.header.stamp
        if stamp is not None:
            with self._lock:
                self.by_topic[topic].append(stamp.to_nsec())

    def latest(self, topic: str):
        with self._lock:
            values = self.by_topic[topic]
            return values[-1] if values else None

    def wait_for_the_clock(self, after, timeout: float = 30.0) -> None:
        """Until world_update carried a stamp later than ``after`` (ns; None: any) and /clock
        caught up with it. The world's publishers drop the oldest message a subscriber has not
        yet taken once their queues fill (world_update keeps 50, joint_states 10): a test that
        sends Step Once in a burst on a loaded host would lose stamps to that, so it paces its
        steps by what arrived."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            update, clock = self.latest("world_update"), self.latest("clock")
            if update is not None and (after is None or update > after) and clock == update:
                return
            time.sleep(0.005)
        raise TimeoutError(f"world_update {update} and /clock {clock} after {after}")

    def step(self, client) -> None:
        """One Step Once of 2 steps, paced by its publication's arrival."""
        before = self.latest("world_update")
        client.step_once(2)
        self.wait_for_the_clock(before)

    def close(self) -> None:
        for subscriber in self._subscribers:
            subscriber.unregister()


def test_time_never_goes_back_across_new_scenes_for_tf_and_sim_time_nodes(ros_master):
    ros_master.run(["rosparam", "set", "/use_sim_time", "true"])
    ros_master.rosrun("VirtualWorld", "virtualWorld", "_simulate:=false")
    ros_master.wait_for_service("/virtual_world/set_robot")
    import rospy
    import tf2_ros
    from gui.ros.client import WorldClient
    client = WorldClient()          # init_node: this node runs on simulated time
    assert rospy.get_param("/use_sim_time") is True
    stamps = _Stamps()
    buffer = tf2_ros.Buffer(cache_time=rospy.Duration(600))
    listener = tf2_ros.TransformListener(buffer)  # noqa: F841 - held: it fills buffer while it lives

    # a use_sim_time node: sleeps on /clock the whole time; rospy raises if time goes back
    sleeper_errors, slept, stop = [], [], threading.Event()

    def sleeper():
        while not stop.is_set():
            try:
                before = rospy.get_time()
                rospy.sleep(0.01)
                slept.append((before, rospy.get_time()))
            except rospy.exceptions.ROSTimeMovedBackwardsException as error:
                sleeper_errors.append(str(error))
            except rospy.exceptions.ROSInterruptException:
                return
    thread = threading.Thread(target=sleeper, daemon=True)
    thread.start()

    lookups = []
    stamps.wait_for_the_clock(None)
    for scene in range(3):
        client.new_scene()
        _scene(client)
        # the robot's joint_states topic is advertised anew with each scene: step until this
        # subscriber is connected to it again (a message came), then count the 15 steps
        heard = len(stamps.by_topic["joint_states"])
        deadline = time.monotonic() + 30
        while len(stamps.by_topic["joint_states"]) == heard and time.monotonic() < deadline:
            stamps.step(client)
        for _ in range(15):
            stamps.step(client)
        time.sleep(0.3)
        # tf answers the ball's latest pose: its buffer was never reset by a jump back
        latest = buffer.lookup_transform("world", "pendulum/bob", rospy.Time(0),
                                         rospy.Duration(5))
        lookups.append(latest.header.stamp.to_nsec())
    stop.set()
    client.step_once(2)             # wakes the sleeper
    thread.join(5)
    stamps.close()
    client.close()

    assert sleeper_errors == []
    assert all(after >= before for before, after in slept) and len(slept) > 10
    assert lookups == sorted(lookups) and len(set(lookups)) == 3
    for topic in ("clock", "world_update", "tf", "joint_states"):
        values = np.array(stamps.by_topic[topic])
        assert len(values) > 30, topic
        assert np.all(np.diff(values) >= 0), f"{topic} went back"
    # one publication, one stamp: each stamp on /clock, /tf and joint_states is a world_update
    # stamp (each subscription began at its own moment: compare while all four were connected).
    # /clock is compared this way round because this test is itself a use_sim_time node: rospy
    # reads /clock for the process's own time through a connection made with a receive queue
    # of one message, which every /clock subscriber of the process shares, so a read that finds
    # two Clock messages keeps the newer only: the test sees a sample of /clock, not all of it.
    first = max(min(stamps.by_topic[t]) for t in stamps.by_topic)
    last = min(max(stamps.by_topic[t]) for t in stamps.by_topic)
    assert last - first > 1e9

    def seen(topic):
        return {s for s in stamps.by_topic[topic] if first <= s <= last}
    assert seen("clock") <= seen("world_update")
    assert seen("tf") <= seen("world_update") and seen("joint_states") <= seen("world_update")
    assert len(seen("tf")) > 10 and len(seen("joint_states")) > 10   # (a loaded host drops some)


def test_roslaunch_starts_odin_and_builds_a_problem(ros_master, kautham_dir):
    problem = kautham_dir / "legacy_2012/examples/TRO/2DRR_obstacle.xml"
    launch = ros_master.popen(["roslaunch", "GUI", "odin.launch", "viewer:=false",
                               f"problem:={problem}"], log_name="roslaunch")
    ros_master.wait_for_service("/virtual_world/get_world", timeout=60)
    from gui.ros.client import WorldClient
    client = WorldClient()
    deadline = time.monotonic() + 60
    while not client.world().robots and time.monotonic() < deadline:
        assert launch.poll() is None, ros_master.log_text(launch)[-3000:]
        time.sleep(0.5)
    inventory = client.world()
    assert [r.name for r in inventory.robots] == ["2D-Robot"]
    assert "2D-Robot/Base" in inventory.objects
    client.close()
