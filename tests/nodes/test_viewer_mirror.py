"""The world's mirror in the Viewer (virtual_world.portal.viewer_link, the Viewer's marker
intake) holds the world's objects: a marker taken late never removes an object View Object
brought, and after churn (many builds, removals and New Scenes fast, IDs used again) the
Viewer holds what the world holds, without a restart."""
from __future__ import annotations

import random
import time

import pytest

pytestmark = pytest.mark.forked

IDS = [f"churn{i}" for i in range(24)]


def _viewer_holds(view, remove, world_ids: set) -> tuple:
    """(IDs of the world's the Viewer lacks, IDs the Viewer holds that the world has not),
    asked of the Viewer itself: View Object of an ID it holds answers "replaced", Remove
    Object of an ID it does not hold is refused. (Changes the Viewer: ask once, at the end.)"""
    missing, extra = [], []
    for name in IDS:
        if name in world_ids:
            answer = view(id=name, parameters=[0.1], indices=[], position=[0, 0, 1],
                          orientation=[1, 0, 0, 0], color=[0, 0, 0, 0])
            assert answer.success, answer.message
            if not answer.message.startswith("replaced"):
                missing.append(name)
        elif remove(id=name).success:
            extra.append(name)
    return missing, extra


def _marker(name: str, action: int, x: float):
    from visualization_msgs.msg import Marker
    marker = Marker(type=Marker.SPHERE, action=action, text=name)
    marker.scale.x = marker.scale.y = marker.scale.z = 0.2
    marker.color.r, marker.color.a = 1.0, 1.0
    marker.pose.position.x = x
    marker.pose.orientation.w = 1.0
    return marker


def test_a_late_marker_deletion_leaves_an_object_view_object_brought(ros_master, tmp_path):
    """A world removes X and builds X again within the markers' grace (1 s): the Viewer had
    taken X from its marker, View Object replaced it, and the marker's DELETE must not take
    the world's X away."""
    import rospy
    from visualization_msgs.msg import Marker, MarkerArray
    from test_viewer_node import Client, start_viewer
    start_viewer(ros_master, tmp_path)
    client = Client()
    markers = rospy.Publisher("/test_world/markers", MarkerArray, queue_size=10)
    deadline = time.monotonic() + 10
    while not markers.get_num_connections():
        assert time.monotonic() < deadline, "the Viewer does not subscribe to markers"
        time.sleep(0.05)

    def taken_from_markers(name: str, timeout: float = 10.0) -> None:
        """Until the Viewer holds ``name`` (its camera, re-fitted on every add, moved)."""
        before = client.camera()
        deadline = time.monotonic() + timeout
        while client.camera() == before:
            assert time.monotonic() < deadline, f"the Viewer never took {name} from markers"
            time.sleep(0.05)

    markers.publish(MarkerArray(markers=[_marker("x", Marker.ADD, 0.0)]))
    taken_from_markers("x")
    answer = client.ball(name="x", radius=0.3, color=(0.0, 0.0, 1.0, 1.0))
    assert answer.success and answer.message.startswith("replaced"), answer.message
    markers.publish(MarkerArray(markers=[_marker("x", Marker.DELETE, 0.0),
                                         _marker("sentinel", Marker.ADD, 5.0)]))
    taken_from_markers("sentinel")       # the DELETE before it was taken too
    assert client.remove(id="x").success, "the marker's DELETE removed View Object's x"


@pytest.mark.slow
def test_the_viewer_mirror_converges_to_the_world_after_churn(ros_master, tmp_path):
    import rospy
    from Services import srv
    from world_client import WorldClient, sphere
    ros_master.rosrun("VirtualWorld", "virtualWorld")
    ros_master.rosrun("Viewer", "viewer", "_width:=64", "_height:=48",
                      f"_snapshot_dir:={tmp_path / 'snaps'}")
    ros_master.wait_for_service("/virtual_world/set_servo")
    ros_master.wait_for_service("/viewer/set_camera")
    rospy.init_node("churn_test", anonymous=True, disable_signals=True)
    world = WorldClient()
    view = rospy.ServiceProxy("/viewer/view_object", srv.ViewObject)
    remove = rospy.ServiceProxy("/viewer/remove_object", srv.ViewerRemoveObject)
    held: set = set()
    rng = random.Random(39)
    deadline = time.monotonic() + 8.0
    while time.monotonic() < deadline:
        name = rng.choice(IDS)
        if rng.random() < 0.02:
            world.ok("new_scene")
            held.clear()
        elif name in held:
            world.ok("remove_object", id=name)
            held.discard(name)
        else:
            world.ok("build_object", object=sphere(name, 0.05, (rng.uniform(-1, 1), 0, 1)))
            held.add(name)
        if rng.random() < 0.05:
            time.sleep(rng.uniform(0.2, 1.2))     # pauses: markers land between changes
    time.sleep(4.0)    # the link's check period and the markers' grace, several times over
    missing, extra = _viewer_holds(view, remove, held)
    assert (missing, extra) == ([], []), f"world holds {sorted(held)}"
