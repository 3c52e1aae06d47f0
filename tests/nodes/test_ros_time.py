"""ROS time around the world (docs/ROS.md, "ROS time"): the world sets /use_sim_time unless it
is set, so that the nodes started after it run on the world clock, and keeps the wall clock
itself.

- robot_state_publisher run word for word as docs/ROS.md runs it, against a world simulating
  on its own, publishes its robot's frames at the world's stamps, equal to the world's own
  (KDL against Odin on a mobile base whose arm's joint origins turn about three axes at once),
  following the robot as its base and joints move; and it goes on when the world node is
  restarted (on the wall clock it published nothing for the restarted world: every joint
  state was older than the last it had published, and it warned that each was decades old);
- a node started after the world asks tf for "now" and gets the world's latest pose;
- the world, started on a master where /use_sim_time is already true (odin.launch), keeps the
  wall clock: paused, its interactive markers' keep-alive goes on;
- odin.launch sets the parameter (``use_sim_time:=false`` too), and the world leaves it so.

The robot is written here from Kautham's formats: a mobile base (its controls name X and Y)
with an arm of two hinges and a slider whose axes are not a frame's axes."""
from __future__ import annotations

import signal
import threading
import time

import numpy as np
import pytest

pytestmark = pytest.mark.forked

ROVER_URDF = """<?xml version="1.0"?>
<robot name="rover">
  <link name="base"><inertial><mass value="4"/><inertia ixx="0.033" iyy="0.057" izz="0.083"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.3 0.1"/></geometry></collision></link>
  <link name="shoulder"><inertial><mass value="0.5"/><inertia ixx="0.0003" iyy="0.0003"
    izz="0.0003" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.06 0.06 0.06"/></geometry></collision></link>
  <link name="upper"><inertial><origin xyz="0 0 0.12"/><mass value="0.3"/><inertia
    ixx="0.0006" iyy="0.0006" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.12"/><geometry><box size="0.04 0.04 0.14"/></geometry>
    </collision></link>
  <link name="fore"><inertial><origin xyz="0 0 0.05"/><mass value="0.2"/><inertia
    ixx="0.0002" iyy="0.0002" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.03 0.03 0.08"/></geometry>
    </collision></link>
  <link name="tool"><inertial><mass value="0.05"/><inertia ixx="0.00001" iyy="0.00001"
    izz="0.00001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.02"/></geometry></collision></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="shoulder"/>
    <origin xyz="0.1 0.05 0.12" rpy="0.3 -0.4 0.7"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="20" velocity="1"/></joint>
  <joint name="lift" type="revolute"><parent link="shoulder"/><child link="upper"/>
    <origin xyz="0 0 0.04" rpy="-0.6 0.5 0.2"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-2" upper="2" effort="20" velocity="1"/></joint>
  <joint name="reach" type="prismatic"><parent link="upper"/><child link="fore"/>
    <origin xyz="0 0 0.2" rpy="0.4 0.3 -0.5"/><axis xyz="0 0.6 0.8"/>
    <limit lower="-0.05" upper="0.15" effort="20" velocity="0.2"/></joint>
  <joint name="wrist" type="fixed"><parent link="fore"/><child link="tool"/>
    <origin xyz="0.01 0.02 0.12" rpy="0.5 0.6 0.7"/></joint>
</robot>
"""

ROVER_CONTROLS = """<?xml version="1.0"?><ControlSet>
 <Offset><DOF name="rover/X1" value="0"/><DOF name="rover/X2" value="0"/>
  <DOF name="rover/X3" value="0"/></Offset>
 <Control name="rover/x" eigValue="1"><DOF name="rover/X" value="1"/></Control>
 <Control name="rover/y" eigValue="1"><DOF name="rover/Y" value="1"/></Control>
 <Control name="rover/turn" eigValue="1"><DOF name="rover/shoulder" value="1"/></Control>
 <Control name="rover/lift" eigValue="1"><DOF name="rover/upper" value="1"/></Control>
 <Control name="rover/reach" eigValue="1"><DOF name="rover/fore" value="1"/></Control>
</ControlSet>
"""

ROVER_PROBLEM = """<?xml version="1.0"?>
<Problem>
 <Robot robot="rover.urdf"><Limits name="X" min="-2" max="2"/><Limits name="Y" min="-2" max="2"/>
  <Limits name="Z" min="0.05" max="0.05"/>
  <Home X="0" Y="0" Z="0.05" WX="0" WY="0" WZ="1" TH="0"/></Robot>
 <Controls robot="rover.cntr"/>
 <Planner><Parameters><Name>omplRRTConnect</Name></Parameters>
  <Queries><Query><Init>0.5 0.5 0.5 0.5 0.5</Init><Goal>0.6 0.4 0.7 0.3 0.6</Goal></Query>
  </Queries></Planner>
</Problem>
"""

#: rad/s, rad/s, m/s: the arm's joints while the test watches (a few seconds: within limits)
JOINT_SPEEDS = (0.3, -0.25, 0.02)
#: m/s, world frame: the mobile base's
BASE_SPEED = (0.08, -0.05, 0.0)
#: the world's joints are ODE's, solved to within its error (here about 5e-7 m and 0 rad):
#: robot_state_publisher's frames equal the world's within this; roll, pitch and yaw
#: composed in the wrong order put them 0.36 rad apart
TOLERANCE_M = 1e-4
TOLERANCE_RAD = 1e-3
MATCHED_STAMPS = 15
#: s of world clock the first world runs before it is restarted
RUN_BEFORE_RESTART = 3.0


def _rover_problem(folder):
    (folder / "rover.urdf").write_text(ROVER_URDF)
    (folder / "rover.cntr").write_text(ROVER_CONTROLS)
    path = folder / "rover.xml"
    path.write_text(ROVER_PROBLEM)
    return path


def _matrix(transform) -> np.ndarray:
    from odin_common.rotations import pose_matrix
    r, p = transform.rotation, transform.translation
    return pose_matrix((p.x, p.y, p.z), (r.w, r.x, r.y, r.z))


def _angle(rotation: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(rotation) - 1.0) / 2.0, -1.0, 1.0)))


class _History:
    """Every transform heard on a tf topic and its static twin: {child: {stamp (ns): (parent,
    (4, 4) pose of the child in the parent, m)}}."""

    def __init__(self, topic: str, static_topic: str):
        import rospy
        from tf2_msgs.msg import TFMessage
        self.by_child: dict = {}
        self._lock = threading.Lock()
        self._subscribers = [rospy.Subscriber(t, TFMessage, self._add, queue_size=1000)
                             for t in (topic, static_topic)]

    def _add(self, message) -> None:
        with self._lock:
            for t in message.transforms:
                self.by_child.setdefault(t.child_frame_id, {})[t.header.stamp.to_nsec()] = (
                    t.header.frame_id, _matrix(t.transform))

    def snapshot(self) -> dict:
        with self._lock:
            return {child: dict(stamps) for child, stamps in self.by_child.items()}

    def clear(self) -> None:
        with self._lock:
            self.by_child.clear()

    def close(self) -> None:
        for subscriber in self._subscribers:
            subscriber.unregister()


def _start_rover(client, problem):
    """Builds the rover's problem (as ``rosrun GUI load_problem`` does: WorldClient.execute),
    runs the world and sets its base and joints moving; returns the namespace, the links
    and, per moving link, its parent link (URDF names)."""
    from gui.core.kautham.problem import load_problem
    from gui.core.translate import plan_problem
    plan = plan_problem(load_problem(problem))
    ids = client.execute(plan)
    handle = plan.robots[0]
    namespace = ids["robots"][handle.name]
    robot = next(r for r in client.world().robots if r.name == handle.name)
    assert list(robot.joint_names) == ["turn", "lift", "reach"]
    client.start()
    client.set_velocities(handle.motor_ids, JOINT_SPEEDS)
    client.set_body_velocity(ids["bodies"]["rover/base"], linear=BASE_SPEED)
    model = handle.instance.model
    parents = {model.links[i].name: model.links[model.links[i].parent].name
               for i in model.movable_links()}
    return namespace, parents


def _follows(world: _History, rsp: _History, namespace: str, parents: dict,
             timeout: float = 40.0) -> list:
    """Waits for MATCHED_STAMPS stamps at which robot_state_publisher published every moving
    link's frame and the world its links' frames; checks that each of robot_state_publisher's
    frames equals the world's at that stamp; returns the stamps (ns), oldest first."""
    frames = {f"{namespace}/{child}": f"{namespace}/{parent}" for child, parent in
              parents.items()}
    deadline = time.monotonic() + timeout
    while True:
        ours, theirs = rsp.snapshot(), world.snapshot()
        stamps = sorted(set.intersection(*(set(ours.get(c, ())) & set(theirs.get(c, ())) &
                                           set(theirs.get(p, ())) for c, p in frames.items())))
        if len(stamps) >= MATCHED_STAMPS:
            break
        if time.monotonic() > deadline:
            heard = {c: len(ours.get(c, ())) for c in frames}
            raise AssertionError(
                f"robot_state_publisher's frames at {len(stamps)} of the world's stamps in "
                f"{timeout:g} s (frames heard from it: {heard})")
        time.sleep(0.1)
    for stamp in stamps:
        for child, parent in frames.items():
            frame, relative = ours[child][stamp]
            assert frame == parent
            from_world = np.linalg.inv(theirs[parent][stamp][1]) @ theirs[child][stamp][1]
            offset = float(np.linalg.norm(from_world[:3, 3] - relative[:3, 3]))
            turn = _angle(relative[:3, :3].T @ from_world[:3, :3])
            assert offset < TOLERANCE_M and turn < TOLERANCE_RAD, (
                f"{child} at {stamp} ns: {offset:.3g} m, {turn:.3g} rad from the world's")
    # it follows the robot: the joints moved between the first and the last of these stamps,
    # and so did the base, which robot_state_publisher does not place (the world does)
    first, last = stamps[0], stamps[-1]
    shoulder = f"{namespace}/shoulder"
    assert _angle(ours[shoulder][first][1][:3, :3].T @ ours[shoulder][last][1][:3, :3]) > 0.05
    base = f"{namespace}/base"
    assert np.linalg.norm(theirs[base][last][1][:3, 3] - theirs[base][first][1][:3, 3]) > 0.01
    return stamps


def _run_until(transforms: _History, frame: str, clock: float, timeout: float = 60.0) -> None:
    """Until ``frame`` was heard stamped ``clock`` (s, the world clock) or later."""
    deadline = time.monotonic() + timeout
    while max(transforms.snapshot().get(frame, {0: None})) < clock * 1e9:
        assert time.monotonic() < deadline, f"no {frame} at {clock:g} s in {timeout:g} s"
        time.sleep(0.1)


def test_robot_state_publisher_as_the_docs_run_it_follows_the_world_and_its_restart(
        ros_master, tmp_path):
    import rospy
    from gui.ros.client import WorldClient

    problem = _rover_problem(tmp_path)
    world_node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_robot")
    client = WorldClient()
    assert rospy.get_param("/use_sim_time") is True       # the world set it
    namespace, parents = _start_rover(client, problem)
    world = _History("/tf", "/tf_static")
    rsp = _History("/rsp/tf", "/rsp/tf_static")
    # docs/ROS.md's command, word for word but the namespace
    rsp_node = ros_master.popen(
        ["rosrun", "robot_state_publisher", "robot_state_publisher", f"__ns:={namespace}",
         f"_tf_prefix:={namespace}", "/tf:=/rsp/tf", "/tf_static:=/rsp/tf_static"],
        log_name="robot_state_publisher")
    _follows(world, rsp, namespace, parents)
    _run_until(rsp, f"{namespace}/shoulder", RUN_BEFORE_RESTART)
    # the fixed joint's frame (on /rsp/tf_static), and no complaint about old stamps
    tool = rsp.snapshot().get(f"{namespace}/tool")
    assert tool and next(iter(tool.values()))[0] == f"{namespace}/fore"
    assert "seconds old" not in ros_master.log_text(rsp_node)

    # the world node restarted (Ctrl-C), the problem loaded again: its clock starts afresh
    client.close()
    world_node.send_signal(signal.SIGINT)
    world_node.wait(30)
    world_node = ros_master.rosrun("VirtualWorld", "virtualWorld")
    rospy.wait_for_service("/virtual_world/set_robot", 30)   # (the master's would see the
    world.clear()                                            # first world's end as a death)
    rsp.clear()
    client = WorldClient()
    assert _start_rover(client, problem)[0] == namespace
    after = _follows(world, rsp, namespace, parents)
    assert after[0] < RUN_BEFORE_RESTART * 1e9, (
        f"robot_state_publisher's first frames for the restarted world are stamped "
        f"{after[0] * 1e-9:.3f} s: it dropped the world's joint states until its clock had "
        f"passed the first world's ({RUN_BEFORE_RESTART:g} s)")
    assert rsp_node.poll() is None, ros_master.log_text(rsp_node)[-2000:]
    assert world_node.poll() is None, ros_master.log_text(world_node)[-2000:]
    world.close()
    rsp.close()
    client.close()


def test_a_node_started_after_the_world_asks_tf_for_now(ros_master):
    """The idiom of ROS code: look a frame up at ``rospy.Time.now()``, waiting a little. On the
    wall clock "now" is decades after every stamp of the world's, and tf refuses to
    extrapolate into the future."""
    import rospy
    import tf2_ros
    from gui.ros.client import WorldClient
    from odin_common.specs import ObjectSpec

    ros_master.rosrun("VirtualWorld", "virtualWorld", "_simulate:=true")
    ros_master.wait_for_service("/virtual_world/build_object")
    client = WorldClient()
    buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(buffer)  # noqa: F841 - held: it fills buffer
    client.build_object(ObjectSpec("ball", (0.1,), position=(0.5, -0.25, 1.0)))
    # the world ran before the build, and this node's /clock can lag the world's on a busy
    # host: the ball falls from the world's own clock after the build, 0.5 s of it
    built = client.world().clock
    deadline = time.monotonic() + 20
    while rospy.Time.now().to_sec() < built + 0.5 and time.monotonic() < deadline:
        time.sleep(0.05)
    now = rospy.Time.now()
    assert built + 0.5 <= now.to_sec() < 3600, f"this node's time is {now.to_sec()} s"
    seen = buffer.lookup_transform("world", "ball", now, rospy.Duration(10))
    assert seen.header.stamp == now
    assert seen.transform.translation.z < 1.0 - 0.5 * 9.81 * 0.4 ** 2   # fallen for 0.5 s
    client.close()


def test_the_world_keeps_the_wall_clock_when_use_sim_time_is_already_true(ros_master):
    """As under roslaunch GUI odin.launch: /use_sim_time true before the world starts. The world
    publishes /clock and must run on while its clock stands still: paused, it answers and its
    interactive markers' keep-alive (a timer, 2 a second) goes on, which a node on /clock
    would hold back until the world runs."""
    import rospy
    from visualization_msgs.msg import InteractiveMarkerUpdate
    from gui.ros.client import WorldClient
    from odin_common.specs import ObjectSpec

    ros_master.run(["rosparam", "set", "/use_sim_time", "true"])
    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/build_object")
    client = WorldClient()
    client.build_object(ObjectSpec("ball", (0.1,), position=(0, 0, 1.0)))   # paused
    client.step_once(1)
    keep_alive = []
    rospy.Subscriber("/virtual_world/interactive/update", InteractiveMarkerUpdate,
                     lambda m: m.type == m.KEEP_ALIVE and keep_alive.append(time.monotonic()),
                     queue_size=100)
    start = time.monotonic()
    while len(keep_alive) < 4 and time.monotonic() < start + 10:
        time.sleep(0.05)
    assert len(keep_alive) >= 4, f"{len(keep_alive)} keep-alive messages in 10 s while paused"
    assert client.world().objects                     # and it answers
    assert rospy.get_param("/use_sim_time") is True   # as it was set
    client.close()


def test_odin_launch_sets_use_sim_time_and_the_world_leaves_a_false_one_alone(ros_master):
    """odin.launch sets /use_sim_time before its nodes start (``use_sim_time:=false`` keeps
    every node on the wall clock); the world sets it only where nobody has."""
    import rospy
    from gui.ros.client import WorldClient
    launch = ros_master.popen(["roslaunch", "GUI", "odin.launch", "viewer:=false",
                               "use_sim_time:=false"], log_name="roslaunch")
    ros_master.wait_for_service("/virtual_world/get_world", timeout=60)
    client = WorldClient()
    assert rospy.get_param("/use_sim_time") is False
    assert rospy.Time.now().to_sec() > 1e9          # this node too: the wall clock
    assert launch.poll() is None, ros_master.log_text(launch)[-3000:]
    client.close()
