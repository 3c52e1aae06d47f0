"""Each new subscriber of the world's ``~markers`` gets every geometry, and of ``/tf`` the last
transforms, intact, however busy the world is: subscribers arriving one after another while the
grasp scene (the TX90's and the hand's meshes: a marker set of megabytes) simulates.

rospy sends a new subscriber the topic's latched message on its own thread while the world's
loop publishes; a send that skipped the publisher's lock shared its buffer with them and came out
corrupt ("argument out of range" in the world's log, RViz drawing nothing: issue 19)."""
from __future__ import annotations

import threading
import time

import pytest

pytestmark = pytest.mark.forked

GRASP = "legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml"
SUBSCRIBERS = 12


class _FirstMessage:
    """A subscription (a connection of its own) that keeps the first message that ``wanted``
    accepts."""

    def __init__(self, topic: str, message_class, wanted=lambda message: True):
        import rospy
        self.message = None
        self._wanted = wanted
        self._got = threading.Event()
        self._subscriber = rospy.Subscriber(topic, message_class, self._keep, queue_size=10)

    def _keep(self, message) -> None:
        if self.message is None and self._wanted(message):
            self.message = message
            self._got.set()

    def wait(self, timeout: float):
        self._got.wait(timeout)
        self._subscriber.unregister()
        return self.message


@pytest.mark.slow
def test_every_new_subscriber_gets_all_markers_and_the_last_transforms(ros_master,
                                                                        kautham_dir):
    from tf2_msgs.msg import TFMessage
    from visualization_msgs.msg import Marker, MarkerArray

    from gui.core.translate import plan_problem
    from gui.core.kautham.problem import load_problem
    from gui.ros.client import WorldClient

    def full_set(message) -> bool:   # what a new subscriber gets after the latched change
        return bool(message.markers) and message.markers[0].action == Marker.DELETEALL

    world = ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_robot")
    client = WorldClient()
    client.execute(plan_problem(load_problem(kautham_dir / GRASP)))
    objects = len(client.world().objects)
    # cycles at the usual 25 Hz of one step each: the markers and transforms flow as at any
    # rate, and the arm's 40 steps a cycle would hold a core for the whole test
    client.set_step(steps_per_cycle=1, rate=25.0)
    client.start()
    counts = []
    try:
        for round_ in range(SUBSCRIBERS):
            # a new connection each round: the last subscription of this process went away
            markers = _FirstMessage("/virtual_world/markers", MarkerArray, full_set)
            transforms = _FirstMessage("/tf", TFMessage)
            full = markers.wait(timeout=30)
            assert full is not None, f"subscriber {round_}: no complete marker set in 30 s"
            counts.append(sum(m.action == Marker.ADD for m in full.markers))
            assert transforms.wait(timeout=30) is not None, f"subscriber {round_}: no /tf"
            time.sleep(0.2 * (round_ % 3))   # meet the loop at different points of its cycle
        assert client.world().simulating
    finally:
        client.close()
    assert counts[0] >= objects and set(counts) == {counts[0]}, (objects, counts)
    log = ros_master.log_text(world)
    assert "no markers for a new subscriber" not in log, log[-2000:]


def test_interactive_markers_follow_only_the_objects_that_moved(ros_master):
    """The world's interactive marker server (``~interactive``: RViz's drag and push handles)
    inserts a marker per movable object, moves it when its object moves, and sends nothing
    for objects that stay where their markers show them."""
    import rospy
    from visualization_msgs.msg import InteractiveMarkerUpdate
    from Messages.msg import Situation
    from world_client import WorldClient, box, sphere

    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.wait_for_service("/virtual_world/set_position")
    rospy.init_node("odin_test_client", anonymous=True, disable_signals=True)
    updates = []
    subscriber = rospy.Subscriber("/virtual_world/interactive/update", InteractiveMarkerUpdate,
                                  lambda message: updates.append(message), queue_size=100)
    # an update goes only to the subscribers connected when it is sent (RViz reads the rest
    # from update_full): build nothing before this one is connected
    deadline = time.monotonic() + 20
    while subscriber.get_num_connections() < 1 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert subscriber.get_num_connections() >= 1, "never connected to ~interactive/update"
    world = WorldClient()
    world.ok("build_object", object=box("floor", (4, 4, 0.1), (0, 0, -0.05), geometry_only=True))
    world.ok("build_object", object=sphere("still", 0.1, (-1, 0, 0.1)))
    world.ok("build_object", object=sphere("moved", 0.1, (1, 0, 0.1)))

    def inserted():
        return {m.name for u in updates for m in u.markers}
    deadline = time.monotonic() + 20
    while inserted() != {"still", "moved"} and time.monotonic() < deadline:
        time.sleep(0.1)
    assert inserted() == {"still", "moved"}
    time.sleep(1.0)                                 # the world paused: nothing moves
    before = len(updates)
    world.ok("set_position", situations=[Situation("moved", [1.0, 1.5, 0.1], [1, 0, 0, 0])])
    deadline = time.monotonic() + 10
    poses = []
    while not poses and time.monotonic() < deadline:
        time.sleep(0.1)
        poses = [p for u in updates[before:] for p in u.poses]
    assert [p.name for p in poses] == ["moved"]
    assert poses[0].pose.position.y == pytest.approx(1.5)
    time.sleep(1.0)
    assert [p.name for u in updates[before:] for p in u.poses] == ["moved"]   # once
    world.close()
