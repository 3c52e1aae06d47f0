"""VirtualWorld's Portal: the ROS layer over the Core (thesis chapter 4).

Node ``virtual_world`` (``rosrun VirtualWorld virtualWorld``). Every name below is in the node's
private namespace, so ``~build_object`` is ``/virtual_world/build_object``.

Services (Services/*, each answering ``success`` and ``message``; bad requests change nothing):
  ``~new_scene`` NewScene, ``~set_world`` SetWorld, ``~set_step`` SetStep, ``~step_once``
  StepOnce, ``~start`` Start, ``~build_object`` BuildObject, ``~build_composite``
  BuildComposite, ``~build_entity`` BuildEntity, ``~remove_object`` RemoveObject,
  ``~set_joint`` SetJoint, ``~set_motor`` SetMotor, ``~set_position`` SetPosition,
  ``~set_velocity`` SetVelocity, ``~set_external_force`` SetExternalForce,
  ``~set_joint_force`` SetJointForce.

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

Parameters (read at start):
  ``~rate`` (25.0 Hz), ``~step`` (0.001 s), ``~steps_per_cycle`` (40), ``~simulate`` (false),
  ``~contact_less`` (false), ``~free_run`` (false: cycles back to back for batch work),
  ``~viewer`` ("/viewer": namespace of the Viewer's services), and the world parameters of
  Set World under the same names: ``~gravity`` ([0, 0, -9.81] m/s^2), ``~erp``, ``~cfm``,
  ``~max_angular_speed``, ``~contact_max_correcting_velocity``, ``~contact_surface_layer``,
  ``~linear_damping``, ``~linear_damping_threshold``, ``~angular_damping``,
  ``~angular_damping_threshold``, ``~max_contacts``, ``~friction``, ``~bounce``,
  ``~bounce_velocity``, ``~solver`` (0 QuickStep, 1 dWorldStep), ``~quickstep_iterations``,
  ``~collision_mesh_tolerance`` (0 m: meshes collide as given).
"""
from __future__ import annotations

import logging
import math
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
from odin_common import OdinError

from virtual_world import conversions, step_values
from virtual_world.core import Core
from virtual_world.errors import InvalidArgument
from virtual_world.loop import CycleReport, RealTimeFactor, WorldLoop
from virtual_world.viewer_link import ViewerLink

_log = logging.getLogger("rosout")

#: Set World request fields -> Core world parameters (value fields follow their set_ flag).
WORLD_FIELDS = {
    "set_gravity": ("gravity",), "set_erp": ("erp",), "set_cfm": ("cfm",),
    "set_max_angular_speed": ("max_angular_speed",),
    "set_contact_max_correcting_velocity": ("contact_max_correcting_velocity",),
    "set_contact_surface_layer": ("contact_surface_layer",),
    "set_linear_damping": ("linear_damping",),
    "set_linear_damping_threshold": ("linear_damping_threshold",),
    "set_angular_damping": ("angular_damping",),
    "set_angular_damping_threshold": ("angular_damping_threshold",),
    "set_max_contacts": ("max_contacts",), "set_friction": ("friction",),
    "set_bounce": ("bounce", "bounce_velocity"),
    "set_solver": ("solver", "quickstep_iterations"),
    "set_contact_less": ("contact_less",),
    "set_collision_mesh_tolerance": ("collision_mesh_tolerance",),
}


class Portal:
    """Owns the Core, its loop thread, the ROS servers and publishers (thesis 4.1-4.6)."""

    def __init__(self):
        self.core = Core()
        values = self._initial_step_values()
        self.core.set_world_parameters(**self._initial_world_parameters())
        self.loop = WorldLoop(self.core_advance, self._publish, values,
                              simulate=bool(rospy.get_param("~simulate", False)),
                              free_run=bool(rospy.get_param("~free_run", False)))
        self._rtf = RealTimeFactor()
        self._poses_for_viewer: dict = {}
        self._poses_lock = threading.Lock()
        self._writer = conversions.SpaceDistributionWriter()
        self.viewer = ViewerLink(rospy.get_param("~viewer", "/viewer"), self._viewer_poses)
        self._advertise()
        self._serve()

    # -- start-up ---------------------------------------------------------------------------
    @staticmethod
    def _initial_step_values() -> step_values.StepValues:
        values, _ = step_values.resolve(
            step_values.StepValues(), step=float(rospy.get_param("~step", 0.001)),
            steps_per_cycle=int(rospy.get_param("~steps_per_cycle", 40)),
            rate=float(rospy.get_param("~rate", 25.0)))
        return values

    @staticmethod
    def _initial_world_parameters() -> dict:
        names = {name for fields in WORLD_FIELDS.values() for name in fields}
        return {name: rospy.get_param(f"~{name}") for name in sorted(names)
                if rospy.has_param(f"~{name}")}

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
        handlers = {
            "new_scene": (srv.NewScene, self.new_scene),
            "set_world": (srv.SetWorld, self.set_world),
            "set_step": (srv.SetStep, self.set_step),
            "step_once": (srv.StepOnce, self.step_once),
            "start": (srv.Start, self.start),
            "build_object": (srv.BuildObject, self.build_object),
            "build_composite": (srv.BuildComposite, self.build_composite),
            "build_entity": (srv.BuildEntity, self.build_entity),
            "remove_object": (srv.RemoveObject, self.remove_object),
            "set_joint": (srv.SetJoint, self.set_joint),
            "set_motor": (srv.SetMotor, self.set_motor),
            "set_position": (srv.SetPosition, self.set_position),
            "set_velocity": (srv.SetVelocity, self.set_velocity),
            "set_external_force": (srv.SetExternalForce, self.set_external_force),
            "set_joint_force": (srv.SetJointForce, self.set_joint_force),
        }
        self.servers = [rospy.Service(f"~{name}", service_class,
                                      self._guarded(service_class, handler))
                        for name, (service_class, handler) in handlers.items()]

    def _guarded(self, service_class, handler: Callable) -> Callable:
        """Runs ``handler(request) -> dict`` on the loop thread and turns the outcome into the
        service's response: an OdinError becomes ``success: false`` with its message, anything
        unexpected too (logged with its traceback); the node stays up either way. Set World and
        Set Step also report the values in force when they refuse."""
        response_class = service_class._response_class
        in_force = {srv.SetWorld: lambda: self._world_fields(self.core.world_parameters),
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
        joint_state = JointState()
        joint_state.header.stamp = stamp
        for state in states:
            for axis, (position, rate) in enumerate(zip(state.positions, state.rates), start=1):
                name = state.id if len(state.positions) == 1 else f"{state.id}/{axis}"
                joint_state.name.append(name)
                joint_state.position.append(position)
                joint_state.velocity.append(rate)
        self.pub_joint_states.publish(joint_state)

    def _viewer_poses(self) -> dict:
        """{geometry id: (position, orientation)} as of the last publication (any thread)."""
        with self._poses_lock:
            snapshot = self._poses_for_viewer
        if not snapshot:
            return {}
        names, positions, quaternions = snapshot
        return {name: (positions[i], quaternions[i]) for i, name in enumerate(names)}

    def _current_poses(self, ids) -> dict:
        """{geometry id: (position, orientation)} now, for the given ids (loop thread)."""
        names, positions, quaternions = self.core.poses()
        wanted = set(ids)
        return {name: (positions[i], quaternions[i]) for i, name in enumerate(names)
                if name in wanted}

    # -- services (run on the loop thread; return the response's fields) ----------------------
    def new_scene(self, request) -> dict:
        self.core.new_scene()
        self.viewer.new_scene()
        return {"message": "new scene"}

    def set_world(self, request) -> dict:
        changes = {}
        for flag, fields in WORLD_FIELDS.items():
            if getattr(request, flag):
                for field in fields:
                    value = getattr(request, field)
                    changes[field] = tuple(value) if field == "gravity" else value
        if not changes:
            raise InvalidArgument("no parameter selected: set at least one set_* flag")
        parameters = self.core.set_world_parameters(**changes)
        return dict(self._world_fields(parameters), message=f"set {', '.join(sorted(changes))}")

    @staticmethod
    def _world_fields(parameters) -> dict:
        names = {name for fields in WORLD_FIELDS.values() for name in fields}
        fields = {name: getattr(parameters, name) for name in names}
        fields["gravity"] = list(fields["gravity"])
        return fields

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
        if self.loop.simulate:
            raise InvalidArgument("the simulation is running: pause it (Start false) to step once")
        cycles = request.cycles or 1
        if cycles > 100_000:
            raise InvalidArgument(f"cycles must be at most 100000, got {cycles}")
        for _ in range(cycles):
            self.loop.advance_cycle()
        return {"sim_time": self.loop.sim_time, "message": f"{cycles} cycle(s)"}

    def start(self, request) -> dict:
        self.loop.simulate = bool(request.simulate)
        return {"simulating": self.loop.simulate,
                "message": "simulating" if self.loop.simulate else "paused"}

    def build_object(self, request) -> dict:
        spec = conversions.object_spec(request.object)
        object_id = self.core.build_object(spec)
        self._show(conversions.shapes_of_object(spec))
        return {"id": object_id}

    def build_composite(self, request) -> dict:
        spec = conversions.composite_spec(request.composite)
        object_id = self.core.build_composite(spec)
        self._show(conversions.shapes_of_composite(spec))
        return {"id": object_id}

    def build_entity(self, request) -> dict:
        objects = [conversions.object_spec(o) for o in request.objects]
        composites = [conversions.composite_spec(c) for c in request.composites]
        name, ids = self.core.build_entity(request.name, objects, composites,
                                           request.internal_collisions)
        shapes = [s for spec in objects for s in conversions.shapes_of_object(spec)]
        shapes += [s for spec in composites for s in conversions.shapes_of_composite(spec)]
        self._show(shapes)
        return {"id": name, "ids": ids}

    def _show(self, shapes) -> None:
        poses = self._current_poses(shape[0] for shape in shapes)
        self.viewer.view(conversions.view_requests(shapes, poses))

    def remove_object(self, request) -> dict:
        removed = self.core.remove_object(request.id)
        self.viewer.remove(removed.geometries)
        also = [*removed.joints, *removed.motors, *removed.forces]
        return {"message": f"removed {request.id}" + (f" and {', '.join(also)}" if also else "")}

    def set_joint(self, request) -> dict:
        parameters = [(p.parameter, p.axis, p.value) for p in request.parameters]
        if request.action == srv.SetJointRequest.CREATE:
            joint_id = self.core.create_joint(request.type, request.body1, request.body2,
                                              tuple(request.anchor), tuple(request.axis1),
                                              tuple(request.axis2), tuple(request.axis3),
                                              joint_id=request.id)
            if parameters:
                try:
                    self.core.set_joint_parameters(joint_id, parameters)
                except OdinError:
                    self.core.remove_joint(joint_id)  # all or nothing
                    raise
            return {"id": joint_id, "message": f"created {joint_id}"}
        if request.action == srv.SetJointRequest.SET_PARAMETERS:
            if not parameters:
                raise InvalidArgument("SET_PARAMETERS needs at least one parameter")
            self.core.set_joint_parameters(request.id, parameters)
            return {"id": request.id, "message": f"set {len(parameters)} parameter(s)"}
        if request.action == srv.SetJointRequest.REMOVE:
            removed = self.core.remove_joint(request.id)
            also = [*removed.motors, *removed.forces]
            return {"id": request.id,
                    "message": f"removed {request.id}" + (f" and {', '.join(also)}" if also else "")}
        raise InvalidArgument(f"unknown action {request.action} (CREATE=0, SET_PARAMETERS=1, "
                              "REMOVE=2)")

    def set_motor(self, request) -> dict:
        if request.remove:
            self.core.remove_motor(request.id)
            return {"id": request.id, "message": f"removed {request.id}"}
        motor_id = self.core.create_motor(request.id, request.joint, request.body1,
                                          request.body2, request.kind, tuple(request.axes),
                                          tuple(request.axis_frames), tuple(request.max_forces))
        return {"id": motor_id, "message": f"created {motor_id}"}

    def set_position(self, request) -> dict:
        if not request.situations:
            raise InvalidArgument("no situation given")
        poses = [(s.name, tuple(s.position), tuple(s.orientation)) for s in request.situations]
        self.core.set_poses(poses, reset_velocity=request.reset_velocity)
        return {"message": f"moved {len(poses)} object(s)"}

    def set_velocity(self, request) -> dict:
        if len(request.motors) == 0 and not request.object:
            raise InvalidArgument("nothing to set: give an object or motors")
        if request.object and not (request.set_linear or request.set_angular):
            raise InvalidArgument(f"object {request.object!r} given without set_linear or "
                                  "set_angular")
        if request.object:
            self.core.geometry_names(request.object)  # unknown object: refuse before any change
            _check_finite("linear", request.linear)
            _check_finite("angular", request.angular)
        if request.motors:
            self.core.set_motor_velocities(self._motor_goals(request.motors, request.velocities))
        if request.object:
            self.core.set_velocity(request.object,
                                   tuple(request.linear) if request.set_linear else None,
                                   tuple(request.angular) if request.set_angular else None)
        return {"message": "velocities set"}

    def _motor_goals(self, motors, velocities) -> dict:
        """Splits the flat velocity list over the motors by their number of axes."""
        counts = self.core.motor_axis_counts(motors)
        if sum(counts) != len(velocities):
            raise InvalidArgument(f"{len(velocities)} velocities for motors with {sum(counts)} "
                                  "axes in all")
        goals, cursor = {}, 0
        for motor_id, count in zip(motors, counts):
            goals[motor_id] = tuple(velocities[cursor:cursor + count])
            cursor += count
        return goals

    def set_external_force(self, request) -> dict:
        if request.remove:
            self.core.remove_body_force(request.id)
            return {"id": request.id, "message": f"removed {request.id}"}
        force_id = self.core.add_body_force(
            request.object, request.kind, tuple(request.vector), request.vector_in_body_frame,
            request.at_point, tuple(request.point), request.point_in_body_frame)
        return {"id": force_id, "message": f"added {force_id}"}

    def set_joint_force(self, request) -> dict:
        if request.remove:
            self.core.remove_joint_force(request.id)
            return {"id": request.id, "message": f"removed {request.id}"}
        force_id = self.core.add_joint_force(request.joint, tuple(request.magnitudes))
        return {"id": force_id, "message": f"added {force_id}"}


def _check_finite(name: str, vector) -> None:
    if not all(math.isfinite(v) for v in vector):
        raise InvalidArgument(f"{name} must be finite, got {list(vector)}")


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
