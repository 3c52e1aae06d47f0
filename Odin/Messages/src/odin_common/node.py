"""What every Odin node does with rospy beyond its own Portal: start, and outlive its master.

The one module of ``odin_common`` that imports rospy (docs/ARCHITECTURE.md): the Portals of the
world and the Viewer share it, and nothing ROS-free imports it.

rospy registers a node's publications, subscriptions and services with the master once, at
start. A master that is restarted (roscore killed, a host rebooted) comes back knowing nothing,
and rospy never registers again: the node runs on, but no new client can find its services and
no new subscriber its topics (connections already made survive; they are peer to peer).
``MasterWatch`` asks the master every ``period`` seconds whether it knows this node, and
registers everything again the way rospy does at start when it does not.
"""
from __future__ import annotations

import threading
import time
import xmlrpc.client

import rosgraph
import rospy
from rospy.impl.registration import get_service_manager, get_topic_manager


def init_ros_node(name: str) -> None:
    """``rospy.init_node(name)`` with rospy's own signal handling, except that Ctrl-C while
    the node still waits for its master ends it like any tool (``odin_common.tool.run``: 130,
    no traceback): rospy turns that Ctrl-C into a ROSInitException ("Failed to initialize
    time")."""
    try:
        rospy.init_node(name)
    except rospy.ROSInitException:
        if rospy.core.is_shutdown_requested():
            raise KeyboardInterrupt from None
        raise


class MasterWatch:
    """A daemon thread that registers this node again with a master that forgot it."""

    def __init__(self, period: float = 1.0):
        self.period = period
        self.registrations = 0          # times everything was registered again
        self._thread = threading.Thread(target=self._run, name="master_watch", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        name = rospy.get_name()
        master = rosgraph.Master(name)
        while not rospy.is_shutdown():
            time.sleep(self.period)
            try:
                master.lookupNode(name)
            except rosgraph.MasterError:          # the master answers and does not know us
                self._register_again(master)
            except (OSError, xmlrpc.client.Error):  # no master now: wait for one
                continue

    def _register_again(self, master: rosgraph.Master) -> None:
        """What rospy's RegManager.start does once: every publication, subscription and service
        with the master; each subscription is told the publishers the master knows."""
        node_uri = rospy.core.get_node_uri()
        topics, services = get_topic_manager(), get_service_manager()
        try:
            for topic, data_type in topics.get_publications():
                master.registerPublisher(topic, data_type, node_uri)
            for topic, data_type in topics.get_subscriptions():
                publishers = master.registerSubscriber(topic, data_type, node_uri)
                # rospy's own path for a master's news: the node's publisherUpdate
                xmlrpc.client.ServerProxy(node_uri).publisherUpdate(
                    master.caller_id, topic, publishers)
            for service, service_uri in services.get_services():
                master.registerService(service, service_uri, node_uri)
        except (OSError, xmlrpc.client.Error, rosgraph.MasterError) as error:
            rospy.logwarn("registering again with the restarted master failed (%s); "
                          "trying again", error)
            return
        self.registrations += 1
        rospy.logwarn("the master had restarted without this node: its topics and services "
                      "are registered again")
