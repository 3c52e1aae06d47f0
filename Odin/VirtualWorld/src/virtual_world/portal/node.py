"""VirtualWorld's Portal: the ROS layer over the Core (thesis chapter 4).

Node ``virtual_world`` (``rosrun VirtualWorld virtualWorld``). Every name below is in the node's
private namespace, so ``~build_object`` is ``/virtual_world/build_object``. The Portal converts
messages and forwards them to the Core, whose rules decide; it answers every refusal with
``success: false`` and the Core's message, and changes nothing then.

Services (odin_common.interface.WORLD_SERVICES; Services/*, each answering ``success`` and
``message``): ``~new_scene``, ``~set_world``, ``~set_step``, ``~step_once``, ``~start``,
``~build_object``, ``~build_composite``, ``~build_entity``, ``~remove_object``,
``~set_joint``, ``~set_motor``, ``~set_position``, ``~set_velocity``, ``~set_external_force``,
``~set_joint_force``; and Odin's own: ``~get_world`` (what the world holds, the values in
force), ``~save_state``, ``~restore_state``, ``~reset`` (snapshots), ``~propagate`` (run under
controls without publishing, then back) and ``~check_collision`` (a synchronous query).

Topics published (every cycle, or at ``~rate`` per wall-clock second under ``~free_run``):
  ``~world_update``      Messages/SpaceDistribution: pose of every geometry (m, world frame,
                         quaternion (w, x, y, z));
  ``~collided``          Messages/Collided: contact-less policy only, the pairs that touched
                         since the last message, with depth (m) and contact points (while
                         paused: the pairs touching now, e.g. after Set Position);
  ``~contacts``          Messages/Collided: contact policy only, pairs in contact in the last
                         step;
  ``~joint_data``        Messages/JointsData: every joint's positions and rates per axis;
  ``/joint_states``      sensor_msgs/JointState: the same, one name per joint axis
                         (``<joint id>`` for one-axis joints, ``<joint id>/<axis>`` otherwise);
  ``/clock``             rosgraph_msgs/Clock: simulated time, for nodes with use_sim_time;
  ``~real_time_factor``  std_msgs/Float64: simulated s per wall-clock s over the last second.

Services called: ``<~viewer>/view_object``, ``/remove_object``, ``/new_scene`` (optional: see
``viewer_link``).

Parameters (read at start): the node's own (``virtual_world.portal.parameters``: ``~rate``,
``~step``, ``~steps_per_cycle``, ``~simulate``, ``~free_run``, ``~viewer``) and every world
parameter under its own name (``~gravity``, ``~erp``, ... odin_common.world_parameters), with
units and defaults in docs/parameters.md.
"""
from __future__ import annotations

import logging
import sys
import threading
import traceback
from typing import Callable

import rospy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from Messages.msg import Collided, JointsData, SpaceDistribution
from Services import srv
from odin_common import OdinError, messages
from odin_common.interface import WORLD_SERVICES, SetJointAction
from odin_common.specs import EntitySpec, JointSpec, MotorSpec
from odin_common.world_parameters import PARAMETERS, set_world_flags
from virtual_world.core import Core
from virtual_world.core import step_values
from virtual_world.core.loop import CycleReport, RealTimeFactor, WorldLoop
from virtual_world.errors import InvalidArgument
from virtual_world.portal import conversions
from virtual_world.portal.parameters import DEFAULTS
from virtual_world.portal.viewer_link import ViewerLink

_log = logging.getLogger("rosout")

#: Set World request flags -> the world parameters each applies (value fields follow it).
WORLD_FIELDS = set_world_flags()


class Portal:
    """Owns the Core, its loop thread, the ROS servers and publishers (thesis 4.1-4.6)."""

    def __init__(self):
        self.core = Core()
        values = self._initial_step_values()
        initial = self._initial_world_parameters()
        if initial:
            self.core.set_world_parameters(**initial)
        self.loop = WorldLoop(self.core_advance, self._publish, values,
                              simulate=bool(rospy.get_param("~simulate", DEFAULTS["simulate"])),
                              free_run=bool(rospy.get_param("~free_run", DEFAULTS["free_run"])))
        self._rtf = RealTimeFactor()
        self._poses_for_viewer: tuple = ()
        self._poses_lock = threading.Lock()
        self._writer = conversions.SpaceDistributionWriter()
        self.viewer = ViewerLink(rospy.get_param("~viewer", DEFAULTS["viewer"]),
                                 self._viewer_poses)
        self._advertise()
        self._serve()

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
        self.pub_joint_states = rospy.Publisher("/joint_states", JointState, queue_size=10)
        self.pub_clock = rospy.Publisher("/clock", Clock, queue_size=10)
        self.pub_rtf = rospy.Publisher("~real_time_factor", Float64, queue_size=10)

    def _serve(self) -> None:
        """One server per world service, each answered by the method of the same name."""
        self.servers = []
        for name, type_name in WORLD_SERVICES.items():
            service_class = getattr(srv, type_name)
            self.servers.append(rospy.Service(
                f"~{name}", service_class, self._guarded(service_class, getattr(self, name))))

    def _guarded(self, service_class, handler: Callable) -> Callable:
        """Runs ``handler(request) -> dict`` on the loop thread and turns the outcome into the
        service's response: an OdinError becomes ``success: false`` with its message, anything
        unexpected too (logged with its traceback); the node stays up either way. Set World and
        Set Step also report the values in force when they refuse."""
        response_class = service_class._response_class
        in_force = {srv.SetWorld: lambda: self.core.world_parameters.as_dict(),
                    srv.SetStep: self._step_fields}.get(service_class, dict)

        def serve(request):
            try:
                fields = self.loop.call(lambda: handler(request))
                return response_class(success=True, **fields)
            except OdinError as error:
                message = str(error)
            except Exception as error:
                _log.error("%s failed:\n%s", service_class._type, traceback.format_exc())
                message = f"internal error: {type(error).__name__}: {error}"
            # values in force are immutable snapshots: safe to read from this thread
            return response_class(success=False, message=message, **in_force())
        return serve

    # -- running ------------------------------------------------------------------------------
    def run(self) -> None:
        rospy.on_shutdown(self.loop.stop)
        try:
            self.loop.run()
        finally:
            self.viewer.close()
            self.core.close()

    def core_advance(self, step: float, count: int) -> float:
        self.core.step(step, count)
        return self.core.sim_time

    def _publish(self, report: CycleReport) -> None:
        rtf = self._rtf.add(report.wall_time, report.sim_time)
        if not report.publish_due:
            return
        stamp = rospy.Time.from_sec(report.sim_time)
        names, positions, quaternions = self.core.poses()
        with self._poses_lock:
            self._poses_for_viewer = (names, positions.copy(), quaternions.copy())
        self.pub_world.publish(self._writer.message(names, positions, quaternions, stamp))
        contact_less = self.core.world_parameters.contact_less
        if contact_less and not report.stepped:
            self.core.detect_collisions()   # paused: report what touches now, not nothing
        collisions = self.core.read_collisions()
        if contact_less:
            self.pub_collided.publish(conversions.collided_message(collisions, stamp))
        elif self.pub_contacts.get_num_connections() > 0:
            self.pub_contacts.publish(conversions.collided_message(collisions, stamp))
        self._publish_joints(stamp)
        self.pub_clock.publish(Clock(clock=stamp))
        self.pub_rtf.publish(Float64(rtf))

    def _publish_joints(self, stamp) -> None:
        states = self.core.joint_states()
        message = JointsData(joints=conversions.joint_data(states))
        message.header.stamp = stamp
        self.pub_joints.publish(message)
        self.pub_joint_states.publish(conversions.joint_state_message(states, stamp))

    def _viewer_poses(self) -> dict:
        """{geometry id: (position, orientation)} as of the last publication (any thread)."""
        with self._poses_lock:
            snapshot = self._poses_for_viewer
        if not snapshot:
            return {}
        names, positions, quaternions = snapshot
        return {name: (positions[i], quaternions[i]) for i, name in enumerate(names)}

    # -- services (run on the loop thread; return the response's fields) ----------------------
    def new_scene(self, request) -> dict:
        self.core.new_scene()
        self.viewer.new_scene()
        return {"message": "new scene"}

    def set_world(self, request) -> dict:
        changes = {name: getattr(request, name) for flag, names in WORLD_FIELDS.items()
                   if getattr(request, flag) for name in names}
        if "gravity" in changes:
            changes["gravity"] = tuple(changes["gravity"])
        parameters = self.core.set_world_parameters(**changes)
        return dict(parameters.as_dict(), message=f"set {', '.join(sorted(changes))}")

    def set_step(self, request) -> dict:
        values, note = step_values.resolve(self.loop.step_values, request.step,
                                           request.steps_per_cycle, request.cycle_time,
                                           request.rate)
        self.loop.step_values = values
        return dict(self._step_fields(), message=note)

    def _step_fields(self) -> dict:
        values = self.loop.step_values
        return {"step": values.step, "steps_per_cycle": values.steps_per_cycle,
                "cycle_time": values.cycle_time, "rate": values.rate}

    def step_once(self, request) -> dict:
        sim_time = self.loop.step_cycles(request.cycles)
        return {"sim_time": sim_time, "message": f"{request.cycles or 1} cycle(s)"}

    def start(self, request) -> dict:
        self.loop.simulate = bool(request.simulate)
        return {"simulating": self.loop.simulate,
                "message": "simulating" if self.loop.simulate else "paused"}

    def build_object(self, request) -> dict:
        built = self.core.build_object(messages.object_spec(request.object))
        self.viewer.view(conversions.view_requests(built.geometries))
        return {"id": built.id}

    def build_composite(self, request) -> dict:
        built = self.core.build_composite(messages.composite_spec(request.composite))
        self.viewer.view(conversions.view_requests(built.geometries))
        return {"id": built.id}

    def build_entity(self, request) -> dict:
        built = self.core.build_entity(EntitySpec(
            request.name, [messages.object_spec(o) for o in request.objects],
            [messages.composite_spec(c) for c in request.composites],
            request.internal_collisions))
        self.viewer.view(conversions.view_requests(built.geometries))
        return {"id": built.name, "ids": built.ids}

    def remove_object(self, request) -> dict:
        removed = self.core.remove_object(request.id)
        self.viewer.remove(removed.geometries)
        also = [*removed.joints, *removed.motors, *removed.forces]
        return {"message": f"removed {request.id}" + (f" and {', '.join(also)}" if also else "")}

    def set_joint(self, request) -> dict:
        parameters = messages.parameter_triples(request.parameters)
        if request.action == SetJointAction.CREATE:
            joint_id = self.core.add_joint(JointSpec(
                request.type, request.body1, request.body2, tuple(request.anchor),
                tuple(request.axis1), tuple(request.axis2), tuple(request.axis3), parameters,
                request.id))
            return {"id": joint_id, "message": f"created {joint_id}"}
        if request.action == SetJointAction.SET_PARAMETERS:
            self.core.set_joint_parameters(request.id, parameters)
            return {"id": request.id, "message": f"set {len(parameters)} parameter(s)"}
        if request.action == SetJointAction.REMOVE:
            removed = self.core.remove_joint(request.id)
            also = [*removed.motors, *removed.forces]
            return {"id": request.id,
                    "message": f"removed {request.id}" + (f" and {', '.join(also)}" if also else "")}
        raise InvalidArgument(f"unknown action {request.action} ("
                              + ", ".join(f"{a.name}={a.value}" for a in SetJointAction) + ")")

    def set_motor(self, request) -> dict:
        if request.remove:
            self.core.remove_motor(request.id)
            return {"id": request.id, "message": f"removed {request.id}"}
        motor_id = self.core.add_motor(MotorSpec(
            request.joint, request.kind, request.body1, request.body2, tuple(request.axes),
            tuple(request.axis_frames), tuple(request.max_forces), request.id))
        return {"id": motor_id, "message": f"created {motor_id}"}

    def set_position(self, request) -> dict:
        if not request.situations:
            raise InvalidArgument("no situation given")
        self.core.set_poses(messages.situation_poses(request.situations),
                            reset_velocity=request.reset_velocity)
        return {"message": f"moved {len(request.situations)} object(s)"}

    def set_velocity(self, request) -> dict:
        self.core.set_velocities(
            request.object, tuple(request.linear) if request.set_linear else None,
            tuple(request.angular) if request.set_angular else None, list(request.motors),
            list(request.velocities))
        return {"message": "velocities set"}

    def set_external_force(self, request) -> dict:
        if request.remove:
            self.core.remove_body_force(request.id)
            return {"id": request.id, "message": f"removed {request.id}"}
        force_id = self.core.add_body_force(
            request.object, request.kind, tuple(request.vector), request.vector_in_body_frame,
            request.at_point, tuple(request.point), request.point_in_body_frame)
        return {"id": force_id, "message": f"added {force_id}"}

    def get_world(self, request) -> dict:
        core, values = self.core, self.loop.step_values
        return {"parameters": messages.world_parameters_message(core.world_parameters),
                **self._step_fields(), "sim_time": core.sim_time,
                "simulating": self.loop.simulate, "objects": core.object_ids(),
                "entities": list(core.entities()), "joints": core.joint_ids(),
                "motors": core.motor_ids(), "body_forces": core.body_force_ids(),
                "joint_forces": core.joint_force_ids(), "snapshots": core.snapshot_names(),
                "message": f"{len(core.object_ids())} objects at {core.sim_time:g} s"}

    def save_state(self, request) -> dict:
        self.core.save_state(request.name)
        return {"message": f"saved {request.name!r} at {self.core.sim_time:g} s"}

    def restore_state(self, request) -> dict:
        self.core.restore_state(request.name)
        self._sync_loop_time()
        return {"sim_time": self.core.sim_time, "message": f"restored {request.name!r}"}

    def reset(self, request) -> dict:
        self.core.reset()
        self._sync_loop_time()
        return {"sim_time": self.core.sim_time, "message": "reset to the last build"}

    def _sync_loop_time(self) -> None:
        """The loop publishes the Core's simulated time, which a snapshot put back."""
        self.loop.sim_time = self.core.sim_time

    def propagate(self, request) -> dict:
        goals = self.core.split_motor_velocities(list(request.motors),
                                                 list(request.velocities))
        step = request.step or self.loop.step_values.step
        result = self.core.propagate(
            request.duration, step, motor_goals=goals,
            body_forces=[messages.body_force_arguments(f) for f in request.forces],
            start=request.start, keep=request.keep)
        if result.kept:
            self._sync_loop_time()
        return {"start_time": result.start_time, "step": result.step_size,
                "steps": result.steps,
                "states": [messages.body_state_message(s) for s in result.states],
                "collisions": conversions.collision_pairs(result.collisions),
                "first_times": [c.first_time for c in result.collisions],
                "wall_time": result.wall_time,
                "message": f"{result.steps} steps in {result.wall_time:.3g} s"
                           + (", kept" if result.kept else "")}

    def check_collision(self, request) -> dict:
        if not request.situations:
            raise InvalidArgument("no situation given")
        pairs = self.core.check_collision(messages.situation_poses(request.situations))
        return {"pairs": conversions.collision_pairs(pairs),
                "message": f"{len(pairs)} colliding pair(s)"}

    def set_joint_force(self, request) -> dict:
        if request.remove:
            self.core.remove_joint_force(request.id)
            return {"id": request.id, "message": f"removed {request.id}"}
        force_id = self.core.add_joint_force(request.joint, tuple(request.magnitudes))
        return {"id": force_id, "message": f"added {force_id}"}


def main() -> None:
    rospy.init_node("virtual_world")
    try:
        portal = Portal()
    except OdinError as error:
        rospy.logfatal("virtual_world: bad start-up parameter: %s", error)
        print(f"virtualWorld: bad start-up parameter: {error}", file=sys.stderr)
        sys.exit(2)
    rospy.loginfo("virtual_world ready: step %g s x %d per cycle at %g Hz",
                  portal.loop.step_values.step, portal.loop.step_values.steps_per_cycle,
                  portal.loop.step_values.rate)
    portal.run()
