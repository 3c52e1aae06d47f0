"""VirtualWorld's Portal: the ROS layer over the Core (thesis chapter 4).

Node ``virtual_world`` (``rosrun VirtualWorld virtualWorld``). Every name below is in the node's
private namespace, so ``~world_update`` is ``/virtual_world/world_update``. The Portal converts
messages and forwards them to the Core, whose rules decide; it answers every refusal with
``success: false`` and the Core's message, and changes nothing then.

Services: one server per entry of odin_common.interface.WORLD_SERVICES (its name under ``~``
-> its type in the Services package: the thesis's, then Odin's own), each answering
``success`` and ``message`` and served by the method of the same name of
portal.services.WorldServices; docs/INTERFACE.md describes each, with an example. (The table
is the one list: tests/system/test_layout_doc.py keeps this docstring from naming them.)

Topics published (every cycle, or at ``~rate`` per wall-clock second under ``~free_run``),
all stamped with the world clock (portal.clock: simulated time that never goes back, also
across New Scene, Restore State and Reset):
  ``~world_update``      Messages/SpaceDistribution: pose of every geometry (m, world frame,
                         quaternion (w, x, y, z));
  ``~collided``          Messages/Collided: contact-less policy only, the pairs that touched
                         since the last message, with depth (m) and contact points (while
                         paused: the pairs touching now, e.g. after Set Position);
  ``~contacts``          Messages/Collided: contact policy only, pairs in contact in the last
                         step;
  ``~joint_data``        Messages/JointsData: every joint's positions and rates per axis;
  ``~joint_states``      sensor_msgs/JointState: the same, one name per joint axis
                         (``<joint id>`` for one-axis joints, ``<joint id>/<axis>`` otherwise);
  ``/clock``             rosgraph_msgs/Clock: the world clock, for nodes with use_sim_time;
  ``~real_time_factor``  std_msgs/Float64: simulated s per wall-clock s over the last second;
  ``~servo_states``     Messages/ServoStates: every servo's targets, positions and errors
                         (while there is a servo);
  ``/diagnostics``       diagnostic_msgs/DiagnosticArray: an ERROR for each body the divergence
                         guard parked (the object, why, its values), when it happens;
  ``/tf``, ``/tf_static``, ``~markers``, ``<robot>/joint_states`` and the
                         ``<robot>/robot_description`` parameters: portal.standard_topics;
  ``~interactive/*``     interactive markers of the movable objects: portal.interaction.

Services called: ``<~viewer>/view_object``, ``/remove_object``, ``/new_scene`` (optional: see
``viewer_link``).

Parameters (read at start): the node's own (``virtual_world.portal.parameters``: ``~rate``,
``~step``, ``~steps_per_cycle``, ``~simulate``, ``~free_run``, ``~viewer``, ``~record``: a
rosbag of what changed the world, see ``recorder``; ``~push_speed``; the resource limits
``~max_objects``, ``~max_mesh_triangles``, ``~max_snapshots``, ``~max_request_mb``) and every world
parameter under its own name (``~gravity``, ``~erp``, ... odin_common.world_parameters), with
units and defaults in docs/parameters.md.

Parameter set: ``/use_sim_time`` to true at start, unless set already (``offer_world_clock``:
the nodes started afterwards take their time from ``/clock``); the node itself keeps the wall
clock.
"""
from __future__ import annotations

import logging
import sys
import threading
from typing import Callable

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from Messages.msg import Collided, JointsData, ServoStates, SpaceDistribution
from Services import srv
from odin_common import OdinError, replies
from odin_common.interface import WORLD_SERVICES, DivergencePolicy
from odin_common.limits import ResourceLimits
from odin_common.node import MasterWatch, init_ros_node, numpy_requests, stop_on_signals
from odin_common.world_parameters import PARAMETERS
from virtual_world.core import Core, mass, step_values
from virtual_world.core.loop import CycleReport, RealTimeFactor, WorldLoop
from virtual_world.portal import caller, conversions, message_cap, publish_queue
from virtual_world.portal.interaction import InteractiveObjects
from virtual_world.portal.mirror import WorldMirror
from virtual_world.portal.parameters import DEFAULTS, RESOURCE_PARAMETERS
from virtual_world.portal.recorder import Recorder
from virtual_world.portal.services import READ_ONLY, WorldServices
from virtual_world.portal.standard_topics import StandardTopics
from virtual_world.portal.viewer_link import ViewerLink

_log = logging.getLogger("rosout")

class Portal:
    """Owns the Core, its loop thread, the ROS servers and publishers (thesis 4.1-4.6)."""

    def __init__(self):
        resources = ResourceLimits(**{name: rospy.get_param(f"~{name}", DEFAULTS[name])
                                      for name in RESOURCE_PARAMETERS})
        message_cap.cap_incoming_messages(resources.max_request_mb * 2 ** 20)
        publish_queue.queue_without_yield()
        self.core = Core(resources=resources)
        values = self._initial_step_values()
        initial = self._initial_world_parameters()
        if initial:
            self.core.set_world_parameters(**initial)
        self.loop = WorldLoop(self.core_advance, self._publish, values,
                              simulate=bool(rospy.get_param("~simulate", DEFAULTS["simulate"])),
                              free_run=bool(rospy.get_param("~free_run", DEFAULTS["free_run"])),
                              bodies=lambda: self.core.body_count)
        self._rtf = RealTimeFactor()
        self._poses_for_viewer: tuple = ()
        self._poses_lock = threading.Lock()
        self._writer = conversions.SpaceDistributionWriter()
        self.viewer = ViewerLink(rospy.get_param("~viewer", DEFAULTS["viewer"]),
                                 self._viewer_poses)
        self.mirror = WorldMirror()
        self.services = WorldServices(self.core, self.loop, self.viewer, self.mirror)
        record = rospy.get_param("~record", DEFAULTS["record"])
        self.recorder = Recorder(record, self.core.world_parameters, values) if record else None
        self._advertise()
        self.topics = StandardTopics(self.mirror, self.loop.call)
        self._serve()
        self.interaction = InteractiveObjects(
            self.mirror, self.serve, float(rospy.get_param("~push_speed",
                                                           DEFAULTS["push_speed"])))

    # -- start-up ---------------------------------------------------------------------------
    @staticmethod
    def _initial_step_values() -> step_values.StepValues:
        values, _ = step_values.resolve(
            step_values.StepValues(), step=float(rospy.get_param("~step", DEFAULTS["step"])),
            steps_per_cycle=int(rospy.get_param("~steps_per_cycle",
                                                DEFAULTS["steps_per_cycle"])),
            rate=float(rospy.get_param("~rate", DEFAULTS["rate"])))
        return values

    @staticmethod
    def _initial_world_parameters() -> dict:
        return {p.name: rospy.get_param(f"~{p.name}") for p in PARAMETERS
                if rospy.has_param(f"~{p.name}")}

    def _advertise(self) -> None:
        self.pub_world = rospy.Publisher("~world_update", SpaceDistribution, queue_size=50)
        # Collided says what touched since the previous message: a subscriber that lags
        # behind a burst of Step Once cycles must get every one, so its queue is deep
        self.pub_collided = rospy.Publisher("~collided", Collided, queue_size=1000)
        self.pub_contacts = rospy.Publisher("~contacts", Collided, queue_size=1000)
        self.pub_joints = rospy.Publisher("~joint_data", JointsData, queue_size=10)
        self.pub_joint_states = rospy.Publisher("~joint_states", JointState, queue_size=10)
        self.pub_clock = rospy.Publisher("/clock", Clock, queue_size=10)
        self.pub_rtf = rospy.Publisher("~real_time_factor", Float64, queue_size=10)
        self.pub_diagnostics = rospy.Publisher("/diagnostics", DiagnosticArray, queue_size=10)
        self.pub_servos = rospy.Publisher("~servo_states", ServoStates, queue_size=50)

    def _serve(self) -> None:
        """One server per world service, each answered by the method of the same name."""
        self.servers = []
        self._answers: dict = {}
        for name, type_name in WORLD_SERVICES.items():
            service_class = getattr(srv, type_name)
            self._answers[name] = self._guarded(service_class, self._handler(name))
            served = numpy_requests(service_class) if name in NUMPY_REQUESTS else service_class
            self.servers.append(caller.WatchedService(f"~{name}", served,
                                                      self._answers[name]))

    def serve(self, name: str, request):
        """Answers ``request`` as the service ``name`` does over ROS (any thread)."""
        return self._answers[name](request)

    def _handler(self, name: str) -> Callable:
        """The service's handler, which also notes that a state-changing request succeeded
        (the world clock), puts robots' descriptions on the parameter server at once (Set
        Robot, removals, New Scene) and records it (``~record``)."""
        handle = getattr(self.services, name)
        if name in READ_ONLY:
            return handle

        def handle_and_note(request) -> dict:
            fields = handle(request)
            self.mirror.changed = True
            self.topics.apply_robot_changes()
            if self.recorder is not None:
                self.recorder.request(name, request)
            return fields
        return handle_and_note

    def _guarded(self, service_class, handler: Callable) -> Callable:
        """Runs ``handler(request) -> dict`` on the loop thread and turns the outcome into the
        service's response (odin_common.replies.guarded); the node stays up either way. Set
        World and Set Step also report the values in force when they refuse."""
        # values in force are immutable snapshots: safe to read from the server's thread
        in_force = {srv.SetWorld: lambda: self.core.world_parameters.as_dict(),
                    srv.SetStep: self.services.step_fields}.get(service_class, dict)
        return replies.guarded(service_class,
                               lambda request: self.loop.call(self._watched(handler, request)),
                               in_force)

    def _watched(self, handler: Callable, request) -> Callable[[], dict]:
        """``handler(request)`` for the loop thread, with the services told how to ask whether
        this call's caller has gone (portal.caller; watched from rospy's thread, here)."""
        gone = caller.watch()

        def run() -> dict:
            self.services.cancelled = gone
            try:
                return handler(request)
            finally:
                self.services.cancelled = caller.never
        return run

    # -- running ------------------------------------------------------------------------------
    def run(self) -> None:
        rospy.on_shutdown(self.loop.stop)
        try:
            self.loop.run()
        finally:
            if self.recorder is not None:
                self.recorder.close()
            self.topics.close()
            self.interaction.close()
            self.viewer.close()
            self.core.close()

    def core_advance(self, step: float, count: int) -> float:
        before = self.core.sim_time
        self.core.step(step, count)
        taken = round((self.core.sim_time - before) / step)
        if self.recorder is not None:
            self.recorder.advance(step, taken, self.core.sim_time, *self.core.poses())
        self._report_divergences()
        return self.core.sim_time

    def _report_divergences(self) -> None:
        """Each body the divergence guard parked: an ERROR on /diagnostics and in the log;
        under the pausing policy the simulation pauses (the world keeps answering)."""
        found = self.core.take_divergences()
        if not found:
            return
        for event in found:
            _log.error("virtual_world: %s diverged at %.6g s (%s, %s); parked",
                       event.id, event.time, event.reason, event.value)
        self.pub_diagnostics.publish(conversions.divergence_diagnostics(
            found, rospy.Time.from_sec(self.mirror.clock.now(self.core.sim_time))))
        if self.core.world_parameters.divergence_policy == DivergencePolicy.PARK_AND_PAUSE:
            self.loop.simulate = False

    def _publish(self, report: CycleReport) -> None:
        rtf = self._rtf.add(report.wall_time, report.sim_time)
        if not report.publish_due:
            return
        stamp = rospy.Time(*self.mirror.clock.stamp(
            report.sim_time, self.loop.step_values.step, self.mirror.changed))
        self.mirror.changed = False
        names, positions, quaternions = self.core.poses()
        with self._poses_lock:
            self._poses_for_viewer = (names, positions.copy(), quaternions.copy())
        self.pub_world.publish(self._writer.message(names, positions, quaternions, stamp))
        collisions = self._publish_collisions(report.stepped, stamp)
        states = self._publish_joints(stamp)
        servos = self.core.servo_states() if _heard(self.pub_servos) else ()
        if servos:
            self.pub_servos.publish(conversions.servo_states_message(servos, stamp))
        self.pub_clock.publish(Clock(clock=stamp))
        self.pub_rtf.publish(Float64(rtf))
        self._publish_standard(stamp, names, positions, quaternions, states, collisions)

    def _publish_collisions(self, stepped: bool, stamp) -> list:
        """Contact-less policy: ~collided, every publication; the pairs are returned (the
        markers draw them grey). Contact policy: ~contacts, only while someone listens, and
        nothing returned. Under the contact policy the Core's collisions are those of the
        last step whether or not they are read, so the node reads them only for a listener
        (reading the 100-sphere scene's hundred resting contacts each publication had cost
        it about a twentieth of its stepping time)."""
        if self.core.world_parameters.contact_less:
            if not stepped:
                self.core.detect_collisions()   # paused: report what touches now, not nothing
            collisions = self.core.read_collisions()
            self.pub_collided.publish(conversions.collided_message(collisions, stamp))
            return collisions
        if _heard(self.pub_contacts):
            self.pub_contacts.publish(conversions.collided_message(
                self.core.read_collisions(), stamp))
        return []

    def _publish_joints(self, stamp) -> list:
        """~joint_data and ~joint_states, each built only for a listener (rospy sends nothing
        to no one, but the node would build a message object per joint for nothing); the
        joint states are returned for the robots' own topics."""
        states = self.core.joint_states()
        if _heard(self.pub_joints):
            message = JointsData(joints=conversions.joint_data(states))
            message.header.stamp = stamp
            self.pub_joints.publish(message)
        if _heard(self.pub_joint_states):
            self.pub_joint_states.publish(conversions.joint_state_message(states, stamp))
        return states

    def _publish_standard(self, stamp, names, positions, quaternions, states,
                          collisions) -> None:
        """tf, markers, robots' joint states, interactive markers (portal.standard_topics,
        portal.interaction)."""
        moving, static = self.mirror.frames.poses(names, positions, quaternions)
        colliding = {n for c in collisions for n in (c.first, c.second)}
        self.topics.publish(stamp, moving, static, states, colliding)
        if self.interaction.due():
            movable = self.mirror.movable_objects()
            by_frame = {frame: (p, q) for frame, p, q in zip(*moving)}
            self.interaction.sync({o: by_frame[f] for o, f in zip(
                movable, self.mirror.frames.frames(movable)) if f in by_frame})

    def _viewer_poses(self) -> dict:
        """{geometry id: (position, orientation)} as of the last publication (any thread)."""
        with self._poses_lock:
            snapshot = self._poses_for_viewer
        if not snapshot:
            return {}
        names, positions, quaternions = snapshot
        return {name: (positions[i], quaternions[i]) for i, name in enumerate(names)}


#: services whose requests arrive with their arrays as numpy views of the received bytes
#: (odin_common.node.numpy_requests): a build's meshes, whose numbers the Core takes as
#: arrays (odin_common.specs)
NUMPY_REQUESTS = frozenset({"build_object", "build_composite", "build_entity"})


def _heard(publisher: rospy.Publisher) -> bool:
    """Whether ``publisher`` has a subscriber now (a message for none is not even built)."""
    return publisher.get_num_connections() > 0


#: the ROS parameter every node reads once, when it starts: true makes its ROS time /clock's
USE_SIM_TIME = "/use_sim_time"


def offer_world_clock() -> bool:
    """Makes the world clock the ROS time of the nodes started from now on, as ROS's simulators
    do (gazebo_ros, stage_ros): sets ``/use_sim_time`` to true unless someone set it already
    (``rosparam set /use_sim_time false`` before the world starts keeps every node on the wall
    clock). Returns the value in force.

    The world's stamps are simulated time starting near 0: a node on the wall clock takes them
    for decades old (robot_state_publisher warns so every 10 s), publishes nothing for a
    restarted world (robot_state_publisher: its stamps are older than the last it published),
    keeps a restarted world's frames out of its tf buffer as old data, and cannot ask tf for
    "now" (docs/ROS.md, "ROS time")."""
    if not rospy.has_param(USE_SIM_TIME):
        rospy.set_param(USE_SIM_TIME, True)
        rospy.loginfo("virtual_world: %s set to true: nodes started from now on take their "
                      "time from the world clock (/clock)", USE_SIM_TIME)
    value = bool(rospy.get_param(USE_SIM_TIME))
    if not value:
        rospy.logwarn("virtual_world: %s is false: nodes keep the wall clock, decades "
                      "ahead of the world's stamps", USE_SIM_TIME)
    return value


def main() -> None:
    # the loop runs on this thread: Ctrl-C and SIGTERM only stop it (stop_on_signals). The
    # world keeps the wall clock whatever /use_sim_time says: it publishes /clock, and a node
    # on /clock would wait for ever in any sleep or timer while the world is paused
    init_ros_node("virtual_world", disable_signals=True, wall_clock=True)
    offer_world_clock()
    asked = threading.Event()
    stop_on_signals(asked.set)                  # while the portal is being made
    MasterWatch()
    try:
        portal = Portal()
    except OdinError as error:
        rospy.logfatal("virtual_world: bad start-up parameter: %s", error)
        print(f"virtualWorld: bad start-up parameter: {error}", file=sys.stderr)
        sys.exit(2)
    rospy.loginfo("virtual_world ready: step %g s x %d per cycle at %g Hz",
                  portal.loop.step_values.step, portal.loop.step_values.steps_per_cycle,
                  portal.loop.step_values.rate)
    stop_on_signals(portal.loop.stop)
    if asked.is_set():
        portal.loop.stop()
    mass.preload_trimesh()                      # the services are up: now, for the first meshes
    try:
        portal.run()
    finally:
        mass.join_preload(timeout=30.0)
    rospy.signal_shutdown("the world loop stopped")
