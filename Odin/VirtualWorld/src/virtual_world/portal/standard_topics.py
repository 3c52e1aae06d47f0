"""The world in the form the standard ROS tools read it (tf2, RViz, robot_state_publisher).

Published by the world node, every publication (``~rate``), from the WorldMirror:

  ``/tf``                 tf2_msgs/TFMessage: ``world`` -> every object's frame that moves
                          (odin_common.interface.frame_id of its ID; a robot's links:
                          "<namespace>/<link>"), stamped with the world clock; not sent again
                          while the clock stands still (tf refuses a repeated stamp), but a
                          new subscriber gets the last one at once (RViz started while the
                          world is paused sees every frame);
  ``/tf_static``          tf2_msgs/TFMessage, latched: ``world`` -> every static object's frame
                          (built ``geometry_only``), sent again only when they change;
  ``~markers``            visualization_msgs/MarkerArray: every geometry (portal.markers),
                          only what changed; a new subscriber first gets all of them (latched
                          too, so a late one also gets the last change);
  ``<ns>/joint_states``   sensor_msgs/JointState per robot declared with Set Robot: its own
                          joint names, positions (rad or m) and rates (rad/s or m/s);
                          advertised while the robot is declared, no longer once it leaves;
  ``<ns>/robot_description`` (a parameter, not a topic): the robot's URDF, set while the
                          robot is declared, deleted when it goes.
"""
from __future__ import annotations

import logging
import threading
from typing import Dict, Iterable

import rospy
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from virtual_world.portal.mirror import WorldMirror
from virtual_world.portal.tf_writer import TfWriter

_log = logging.getLogger("rosout")


class _SendsToNewSubscribers(rospy.SubscribeListener):
    """A listener that sends a message of its own to each new subscriber of ``publisher`` (set
    once the publisher exists: it takes its listener when made).

    rospy's ``peer_publish`` serialises into the one buffer the topic's ``publish`` uses, but
    without the lock that ``publish`` and the latched-message send take; sent unlocked, it
    met the latched message a new subscriber gets at the same moment and both came out
    corrupt (RViz under load drew no geometry: "argument out of range"). So every send here
    holds that lock (``Publisher.impl``'s, the one rospy's own ``publish`` takes)."""

    def __init__(self):
        super().__init__()
        self.publisher: rospy.Publisher | None = None

    def send_alone(self, peer_publish, message) -> None:
        """``peer_publish(message)`` holding the publisher's lock."""
        impl = self.publisher.impl
        impl.acquire()
        try:
            peer_publish(message)
        finally:
            impl.release()


class _FullMarkersOnSubscribe(_SendsToNewSubscribers):
    """Sends every marker to each new subscriber of ``~markers`` (the latched message alone is
    only the last change). The markers are computed on the world's loop thread, and rospy calls
    this on the thread that accepts every connection of the node (services too): so the work
    goes to a thread of its own, and a loop that is busy or not started yet never blocks the
    node's services. The markers are sent from the loop thread too, so that they reach the
    subscriber in order with the changes the loop publishes."""

    def __init__(self, markers, on_loop):
        super().__init__()
        self._markers = markers
        self._on_loop = on_loop

    def peer_subscribe(self, topic_name, topic_publish, peer_publish) -> None:
        threading.Thread(target=self._send, args=(topic_name, peer_publish),
                         name="markers-to-new-subscriber", daemon=True).start()

    def _send(self, topic_name, peer_publish) -> None:
        try:
            self._on_loop(lambda: self.send_alone(peer_publish, self._markers.full()))
        except Exception as error:   # the world stopping, the subscriber gone
            _log.warning("virtual_world: no markers for a new subscriber of %s: %s",
                         topic_name, error)


class _LastTfOnSubscribe(_SendsToNewSubscribers):
    """Sends the last /tf transforms to each new subscriber: while paused the world sends
    none. The message is made when a subscriber comes, from the last publication's arrays
    (``remember``: arrays the caller no longer changes), with a writer of its own (rospy
    calls this on its own thread): made at every publication for no subscriber, it had cost
    the free-running 100-sphere scene's loop 3 % of its time."""

    def __init__(self):
        super().__init__()
        self._last = None
        self._writer = TfWriter()
        self._lock = threading.Lock()

    def remember(self, frames, positions, quaternions, stamp) -> None:
        self._last = (tuple(frames), positions, quaternions, stamp)

    def peer_subscribe(self, topic_name, topic_publish, peer_publish) -> None:
        last = self._last
        if last is not None:
            with self._lock:
                message = self._writer.message(*last)
            self.send_alone(peer_publish, message)


class StandardTopics:
    """The publishers above; ``publish`` runs on the world's loop thread."""

    def __init__(self, mirror: WorldMirror, on_loop):
        """``on_loop(function)``: runs ``function`` on the world's loop thread (the Portal's
        ``loop.call``)."""
        self.mirror = mirror
        self._tf_listener = _LastTfOnSubscribe()
        self.pub_tf = rospy.Publisher("/tf", TFMessage, queue_size=100,
                                      subscriber_listener=self._tf_listener)
        self._tf_listener.publisher = self.pub_tf
        self.pub_tf_static = rospy.Publisher("/tf_static", TFMessage, queue_size=10, latch=True)
        markers_listener = _FullMarkersOnSubscribe(mirror.markers, on_loop)
        self.pub_markers = rospy.Publisher("~markers", MarkerArray, queue_size=100, latch=True,
                                           subscriber_listener=markers_listener)
        markers_listener.publisher = self.pub_markers
        self._tf = TfWriter()
        self._tf_static = TfWriter()
        self._static_published = None
        self._last_tf_stamp = None
        self._joint_states: Dict[str, rospy.Publisher] = {}

    def publish(self, stamp: rospy.Time, moving, static, joint_states,
                colliding: Iterable[str]) -> None:
        """One publication: the frames' poses (ObjectFrames.poses: moving and static), the
        Core's joint states, the geometries to draw grey."""
        self.apply_robot_changes()
        if stamp != self._last_tf_stamp:
            self._last_tf_stamp = stamp
            if moving[0]:
                self._tf_listener.remember(*moving, stamp)
                if self.pub_tf.get_num_connections() > 0:
                    self.pub_tf.publish(self._tf.message(*moving, stamp))
        self._publish_static(static, stamp)
        self.mirror.markers.set_colliding(colliding)
        changes = self.mirror.markers.take_changes()
        if changes is not None:
            self.pub_markers.publish(changes)
        self._publish_robot_joints(stamp, joint_states)

    def _publish_robot_joints(self, stamp: rospy.Time, joint_states) -> None:
        """Each robot's joint_states, built only for a robot whose topic has a subscriber."""
        heard = {namespace: publisher for namespace, publisher in self._joint_states.items()
                 if publisher.get_num_connections() > 0}
        if not heard:
            return
        for robot, joint_names, values, rates in self.mirror.robots.joint_states(joint_states):
            publisher = heard.get(robot.namespace)
            if publisher is not None:
                message = JointState(name=joint_names, position=values, velocity=rates)
                message.header.stamp = stamp
                publisher.publish(message)

    def _publish_static(self, static, stamp) -> None:
        frames, positions, quaternions = static
        key = (tuple(frames), positions.tobytes(), quaternions.tobytes())
        if key == self._static_published:
            return
        self._static_published = key
        self.pub_tf_static.publish(self._tf_static.message(frames, positions, quaternions,
                                                           stamp))

    def apply_robot_changes(self) -> None:
        """Each robot set or removed since the last call: its joint_states publisher and its
        robot_description parameter (the Portal calls this after every service that changed
        the world, so the parameter is there when Set Robot answers, and at publications).
        A robot that leaves (New Scene, Remove Object of one of its links, Set Robot remove, a
        new problem's load) takes both with it: its topic is no longer advertised (rostopic
        list, the master), and a subscriber left on it reconnects when a robot of that
        namespace comes back (the master tells it of the new publisher)."""
        for change, robot in self.mirror.take_robot_changes():
            namespace = f"/{robot.namespace}"
            try:
                if change == "set":
                    if robot.namespace not in self._joint_states:
                        self._joint_states[robot.namespace] = rospy.Publisher(
                            f"{namespace}/joint_states", JointState, queue_size=10)
                    rospy.set_param(f"{namespace}/robot_description", robot.description)
                    continue
                publisher = self._joint_states.pop(robot.namespace, None)
                if publisher is not None:
                    publisher.unregister()
                _delete_param(f"{namespace}/robot_description")
            except Exception as error:   # the master gone: the node goes on
                _log.warning("virtual_world: robot %s: master: %s", robot.name, error)

    def close(self) -> None:
        for publisher in self._joint_states.values():
            publisher.unregister()
        self._joint_states.clear()
        for robot in list(self.mirror.robots):
            try:
                rospy.delete_param(f"/{robot.namespace}/robot_description")
            except Exception:   # master gone at shutdown
                pass


def _delete_param(name: str) -> None:
    """Deletes the parameter ``name`` if it is set: one call to the master, where asking
    first made two on every New Scene's path."""
    try:
        rospy.delete_param(name)
    except KeyError:    # not set (a user may have deleted it)
        pass
