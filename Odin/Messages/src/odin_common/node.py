"""What every Odin node does with rospy beyond its own Portal: start, outlive its master, and
take large requests as numpy arrays (``numpy_requests``).

The one module of ``odin_common`` that imports rospy (docs/ARCHITECTURE.md): the Portals of the
world and the Viewer, the GUI's window and its ROS clients share it, and nothing ROS-free
imports it.

rospy registers a node's publications, subscriptions and services with the master once, at
start. A master that is restarted (roscore killed, a host rebooted) comes back knowing nothing,
and rospy never registers again: the node runs on, but no new client can find its services and
no new subscriber its topics (connections already made survive; they are peer to peer).
``MasterWatch`` asks the master every ``period`` seconds whether it knows this node, and
registers everything again the way rospy does at start when it does not.
"""
from __future__ import annotations

import signal
import sys
import threading
import time
import xmlrpc.client
from typing import Callable, Optional

import rosgraph
import rospy
from rospy.impl.registration import RegManager, get_service_manager, get_topic_manager
from rospy.numpy_msg import numpy_msg

from odin_common.errors import NoMasterError
from odin_common.master_link import MasterRefusal, call_master


def init_ros_node(name: str, disable_signals: bool = False, poll: float = 0.5,
                  master_timeout: Optional[float] = None, wall_clock: bool = False) -> None:
    """``rospy.init_node(name)`` once the master answers, with rospy's own signal handling
    unless ``disable_signals`` (a Qt window handles Ctrl-C itself). With ``wall_clock`` the
    node's ROS time is the wall clock whatever ``/use_sim_time`` says (the world, which
    publishes /clock and must run on while its clock stands still; docs/ROS.md, "ROS time").

    rospy waits for a master that is not up yet only for the node's registration: a private
    parameter on the command line (``_eye:=[...]``) is set on the master first, and with no
    master that raises ConnectionRefusedError and the node dies. roscpp waits; so does every
    Odin node, so that nodes started together with roscore (a launch, a script, a test) come
    up in any order. Ctrl-C while waiting ends the node like any tool (``odin_common.tool.run``:
    130, no traceback); rospy turns a Ctrl-C during its own start into a ROSInitException
    ("Failed to initialize time"). ``master_timeout`` (s): a tool's wait for its master,
    ``NoMasterError`` after it (``wait_for_master``)."""
    wait_for_master(name, poll, master_timeout)
    try:
        # rospy's disable_rostime: no /clock subscription, rospy.Time.now() the wall clock
        rospy.init_node(name, disable_signals=disable_signals, disable_rostime=wall_clock)
    except rospy.ROSInitException:
        if rospy.core.is_shutdown_requested():
            raise KeyboardInterrupt from None
        raise
    prompt_shutdown()


def stop_on_signals(stop: Callable[[], None]) -> None:
    """SIGINT and SIGTERM call ``stop()`` and nothing else, for a node whose main thread runs
    its own loop (the world's): it stops the loop, and the node shuts rospy down once the
    loop has returned (``rospy.signal_shutdown``). ``stop`` must take no lock the main thread
    may hold: it runs inside whatever that thread was doing.

    rospy's own handler runs its whole shutdown there instead, closing every topic: a signal
    that came while the loop published (a topic's lock held) waited for that lock forever, and
    the world ignored Ctrl-C until it was killed."""
    def handler(signum, frame) -> None:
        stop()
    for number in (signal.SIGINT, signal.SIGTERM):
        signal.signal(number, handler)


def prompt_shutdown() -> None:
    """Lets rospy's shutdown (at exit, Ctrl-C) end without its half-second stall; call once
    after ``rospy.init_node``.

    rospy's registration thread waits on a condition in 0.5 s slices. Its pre-shutdown hook
    wakes it before the shutdown flag is raised, so the thread sees no shutdown, waits again,
    and ``signal_shutdown`` joins it for the whole slice: every rospy process took 0.6 s to
    exit. A shutdown hook, run once the flag is up, wakes it again."""
    for hook in list(rospy.core._preshutdown_hooks):
        manager = getattr(hook, "__self__", None)
        if isinstance(manager, RegManager):
            rospy.core.add_shutdown_hook(lambda _reason, m=manager: _wake(m.cond))


def _wake(cond: threading.Condition) -> None:
    with cond:
        cond.notify_all()


def wait_for_master(caller_id: str, poll: float = 0.5, timeout: Optional[float] = None,
                    quiet: bool = False) -> None:
    """Returns once the master at ROS_MASTER_URI answers, asking every ``poll`` seconds and,
    unless ``quiet``, saying once on stderr that it waits (roscpp's "waiting for master").

    A node (``timeout`` None) waits for ever. A tool gives a ``timeout`` (s): it waits that
    long, each question cut short at the deadline (a host that drops packets never refuses),
    then raises ``NoMasterError`` naming the URI."""
    uri = rosgraph.get_master_uri()
    deadline = None if timeout is None else time.monotonic() + max(0.0, timeout)
    said = False
    while True:
        left = None if deadline is None else max(0.05, deadline - time.monotonic())
        try:
            call_master(uri, caller_id, "getPid", timeout=left)
            return
        except (OSError, xmlrpc.client.Error, MasterRefusal):
            if deadline is not None and time.monotonic() >= deadline:
                raise NoMasterError(f"no ROS master answers at {uri} after {timeout:g} s "
                                    "(is roscore running? is ROS_MASTER_URI right?)") from None
            if not said and not quiet:
                print(f"{caller_id}: waiting for the ROS master at {uri}",
                      file=sys.stderr, flush=True)
                said = True
            time.sleep(poll if deadline is None else
                       max(0.0, min(poll, deadline - time.monotonic())))


#: MasterWatch's mark for a master that answered with an error (it knows nothing of the node)
MASTER_LOST = ("master", "")


def forgotten(missing_before: set, missing_now: set) -> bool:
    """Whether a registration is forgotten: missing from the master at two looks in a row."""
    return bool(missing_before & missing_now)


class MasterWatch:
    """A daemon thread that registers this node again with a master that forgot it, or any of
    its topics and services (a master restarted: ``_missing``), looking once a ``period`` (s).

    A registration counts as forgotten when it is missing at two looks in a row: rospy adds a
    new topic to its own lists a moment before it tells the master, and a look in between
    (a node that loads a problem makes a topic per robot) took that for a restarted master."""

    def __init__(self, period: float = 1.0):
        self.period = period
        self.registrations = 0          # times everything was registered again
        self._thread = threading.Thread(target=self._run, name="master_watch", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        name = rospy.get_name()
        master = rosgraph.Master(name)
        missing_before: set = set()
        while not rospy.is_shutdown():
            time.sleep(self.period)
            try:
                missing = self._missing(master, name)
            except (OSError, xmlrpc.client.Error):  # no master now: wait for one
                continue
            if forgotten(missing_before, missing):
                self._register_again(master)
                missing = set()
            missing_before = missing

    @staticmethod
    def _missing(master: rosgraph.Master, name: str) -> set:
        """The publications, subscriptions and services of this node the master lacks, as
        ("publication" | "subscription" | "service", name); {MASTER_LOST} when the master
        knows nothing of the node. Not only the node as a whole: a master that restarted
        while rospy was still registering the node's start-up knew its first topics (rospy
        retries those) and none of its services, and asking for the node found it."""
        try:
            publishers, subscribers, providers = master.getSystemState()
        except rosgraph.MasterError:
            return {MASTER_LOST}

        def unknown(kind: str, ours: list, state: list) -> set:
            known = {topic for topic, nodes in state if name in nodes}
            return {(kind, entry) for entry, _ in ours if entry not in known}
        topics, services = get_topic_manager(), get_service_manager()
        return (unknown("publication", topics.get_publications(), publishers)
                | unknown("subscription", topics.get_subscriptions(), subscribers)
                | unknown("service", services.get_services(), providers))

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


def numpy_requests(service_class):
    """``service_class`` (same type and MD5 sum, the same bytes on the wire) with
    rospy.numpy_msg requests: every array field arrives as a read-only numpy view of the
    received bytes. genpy unpacked the TX90 + hand's ~800,000 mesh numbers one Python object
    each, ~0.05 s of the world's and the Viewer's time at every load."""
    return type(service_class.__name__, (), {
        "_type": service_class._type, "_md5sum": service_class._md5sum,
        "_request_class": numpy_msg(service_class._request_class),
        "_response_class": service_class._response_class})
