"""The topics the GUI window reads, subscribed in one place, no Qt.

Topics (names relative to the world's and the Viewer's namespaces):
  ``<world>/world_update`` Messages/SpaceDistribution;
  ``<world>/joint_data``   Messages/JointsData;
  ``<world>/joint_states`` sensor_msgs/JointState (world joint IDs);
  ``<viewer>/image``       sensor_msgs/Image (one message queued, a 4 MB buffer: a frame).

Each message goes as it is to its callback, on rospy's threads: a callback must only hand it
on (gui.window.ros_link turns them into Qt signals). Requires ``rospy.init_node``.
"""
from __future__ import annotations

from typing import Callable

from odin_common.interface import VIEWER_NAMESPACE, WORLD_NAMESPACE


class WindowTopics:
    """The window's four subscriptions; ``close`` ends them."""

    def __init__(self, on_world_update: Callable, on_joint_data: Callable,
                 on_joint_states: Callable, on_image: Callable,
                 world: str = WORLD_NAMESPACE, viewer: str = VIEWER_NAMESPACE):
        import rospy
        from sensor_msgs.msg import Image, JointState

        from Messages.msg import JointsData, SpaceDistribution
        world = world.rstrip("/")
        self._subscribers = [
            rospy.Subscriber(f"{world}/world_update", SpaceDistribution, on_world_update,
                             queue_size=2),
            rospy.Subscriber(f"{world}/joint_data", JointsData, on_joint_data, queue_size=2),
            rospy.Subscriber(f"{world}/joint_states", JointState, on_joint_states,
                             queue_size=2),
            rospy.Subscriber(f"{viewer.rstrip('/')}/image", Image, on_image,
                             queue_size=1, buff_size=4 << 20),
        ]

    def close(self) -> None:
        for subscriber in self._subscribers:
            subscriber.unregister()
        self._subscribers.clear()
