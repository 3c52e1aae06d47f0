"""The GUI's client of the VirtualWorld: rospy service proxies, no Qt.

``WorldClient`` keeps one persistent ``rospy.ServiceProxy`` per world service (a round trip is
~0.05 ms persistent against ~1.2 ms fresh) and turns ``success: false`` (or a broken
connection) into ``gui.errors.WorldError`` carrying the world's message. ``execute(plan)``
sends a ``gui.core.build.BuildPlan``; ``run_position_path`` / ``run_velocity_path`` drive a robot.

The Qt window must not call these from its GUI thread (each call blocks until the world
answers): run them in a worker thread and signal the results back.

Requires ``rospy.init_node`` (done here with ``disable_signals=True`` unless already done).
"""
from __future__ import annotations

import time
from typing import Callable, Optional, Sequence

import numpy as np

from gui.core.build import (BuildPlan, CompositeRequest, EntityRequest, JointRequest, MotorRequest,
                       ObjectRequest, RobotHandle)
from gui.errors import WorldError

SET_JOINT_CREATE = 0


class WorldClient:
    """Calls ``<namespace>/<service>``; every method raises ``WorldError`` on refusal."""

    def __init__(self, namespace: str = "/virtual_world", timeout: float = 10.0,
                 node_name: str = "gui"):
        import rospy
        from Services import srv
        self._rospy = rospy
        self._srv = srv
        if not rospy.core.is_initialized():
            rospy.init_node(node_name, anonymous=True, disable_signals=True)
        self.namespace = namespace.rstrip("/")
        self._proxies: dict = {}
        try:
            rospy.wait_for_service(f"{self.namespace}/build_entity", timeout=timeout)
        except rospy.ROSException:
            raise WorldError(f"{self.namespace}", f"no VirtualWorld answering after {timeout:g} s "
                             "(is `rosrun VirtualWorld virtualWorld` running?)") from None

    _TYPES = {
        "new_scene": "NewScene", "set_world": "SetWorld", "set_step": "SetStep",
        "step_once": "StepOnce", "start": "Start", "build_object": "BuildObject",
        "build_composite": "BuildComposite", "build_entity": "BuildEntity",
        "remove_object": "RemoveObject", "set_joint": "SetJoint", "set_motor": "SetMotor",
        "set_position": "SetPosition", "set_velocity": "SetVelocity",
        "set_external_force": "SetExternalForce", "set_joint_force": "SetJointForce",
    }

    def call(self, service: str, /, **fields):
        """Calls one service with request ``fields``; returns the response or raises."""
        response = self.ask(service, **fields)
        if not response.success:
            raise WorldError(f"{self.namespace}/{service}", response.message)
        return response

    def ask(self, service: str, /, **fields):
        """Calls one service and returns its response, refused or not (a refused Set Step or
        Set World still reports the values in force); raises only if the call fails."""
        proxy = self._proxies.get(service)
        if proxy is None:
            service_class = getattr(self._srv, self._TYPES[service])
            proxy = self._rospy.ServiceProxy(f"{self.namespace}/{service}", service_class,
                                             persistent=True)
            self._proxies[service] = proxy
        try:
            response = proxy(proxy.request_class(**fields))
        except (self._rospy.ServiceException, OSError) as error:
            self._proxies.pop(service, None)
            raise WorldError(f"{self.namespace}/{service}", f"call failed: {error}") from None
        return response

    def close(self) -> None:
        for proxy in self._proxies.values():
            proxy.close()
        self._proxies.clear()

    # -- message conversion -------------------------------------------------------------------
    @staticmethod
    def object_msg(req: ObjectRequest):
        from Messages.msg import Object
        return Object(name=req.name, parameters=list(np.asarray(req.parameters, dtype=float)),
                      indices=list(np.asarray(req.indices, dtype=np.uint32)), mass=req.mass,
                      inertia=list(req.inertia), position=list(req.position),
                      orientation=list(req.orientation), color=list(req.color),
                      fixed=req.fixed, geometry_only=req.geometry_only,
                      no_collisions=req.no_collisions)

    @staticmethod
    def composite_msg(req: CompositeRequest):
        from Messages.msg import Composite, Part
        parts = [Part(name=p.name, parameters=list(np.asarray(p.parameters, dtype=float)),
                      indices=list(np.asarray(p.indices, dtype=np.uint32)), mass=p.mass,
                      position=list(p.position), orientation=list(p.orientation),
                      color=list(p.color)) for p in req.parts]
        return Composite(parts=parts, position=list(req.position),
                         orientation=list(req.orientation), fixed=req.fixed,
                         geometry_only=req.geometry_only, no_collisions=req.no_collisions)

    # -- services -----------------------------------------------------------------------------
    def new_scene(self) -> None:
        self.call("new_scene")

    def build_object(self, req: ObjectRequest) -> str:
        return self.call("build_object", object=self.object_msg(req)).id

    def build_composite(self, req: CompositeRequest) -> str:
        return self.call("build_composite", composite=self.composite_msg(req)).id

    def build_entity(self, req: EntityRequest) -> list:
        response = self.call("build_entity", name=req.name,
                             objects=[self.object_msg(o) for o in req.objects],
                             composites=[self.composite_msg(c) for c in req.composites],
                             internal_collisions=req.internal_collisions)
        return list(response.ids)

    def set_joint(self, req: JointRequest, body_ids: Optional[dict] = None) -> str:
        from Messages.msg import JointParameter
        ids = body_ids or {}
        params = [JointParameter(parameter=p, axis=a, value=v) for p, a, v in req.parameters]
        return self.call("set_joint", action=SET_JOINT_CREATE, type=req.type,
                         body1=ids.get(req.body1, req.body1), body2=ids.get(req.body2, req.body2),
                         anchor=list(req.anchor), axis1=list(req.axis1),
                         axis2=list(req.axis2), axis3=list(req.axis3), parameters=params).id

    def set_motor(self, joint_id: str, kind: int) -> str:
        return self.call("set_motor", joint=joint_id, kind=kind).id

    def set_position(self, situations: Sequence, reset_velocity: bool = True) -> None:
        """``situations``: (body ID, position (3,) m, quaternion (w, x, y, z))."""
        from Messages.msg import Situation
        self.call("set_position", situations=[
            Situation(name=n, position=list(p), orientation=list(q)) for n, p, q in situations],
            reset_velocity=reset_velocity)

    def set_velocity(self, motors: Sequence[str], velocities: Sequence[float]) -> None:
        self.call("set_velocity", motors=list(motors),
                  velocities=[float(v) for v in velocities])

    def publication_rate(self) -> float:
        """The world's publications per wall-clock second: an empty Set Step is refused but
        answers with the step values in force."""
        return float(self.ask("set_step").rate)

    # -- plans --------------------------------------------------------------------------------
    def execute(self, plan: BuildPlan,
                progress: Optional[Callable[[int, object, str], None]] = None) -> dict:
        """Sends every request of ``plan`` in order; returns the world's IDs:
        {"bodies": {planned body ID: world ID}, "joints": {joint key: world ID},
        "motors": {joint key: world motor ID}}.

        Joint and motor IDs the world returns replace the predicted ones in ``plan.robots``.
        Stops at the first refusal (``WorldError``); what was built before stays built."""
        bodies: dict = {}
        joints: dict = {}
        motors: dict = {}
        for k, step in enumerate(plan.steps, start=1):
            if isinstance(step, EntityRequest):
                members = list(step.objects) + list(step.composites)
                answer = self.build_entity(step)
                for member, got in zip(members, answer):
                    bodies[member.id] = got
                label = step.name
            elif isinstance(step, ObjectRequest):
                label = bodies[step.id] = self.build_object(step)
            elif isinstance(step, CompositeRequest):
                label = bodies[step.id] = self.build_composite(step)
            elif isinstance(step, JointRequest):
                label = joints[step.key] = self.set_joint(step, bodies)
            elif isinstance(step, MotorRequest):
                label = motors[step.joint_key] = self.set_motor(joints[step.joint_key],
                                                                step.kind)
            else:
                raise TypeError(f"unknown plan step {step!r}")
            if progress is not None:
                progress(k, step, label)
        for handle in plan.robots:
            for body in handle.bodies:
                body.body_id = bodies.get(body.body_id, body.body_id)
            if handle.joint_keys:
                handle.joint_ids = [joints[k] for k in handle.joint_keys]
                handle.motor_ids = [motors[k] for k in handle.joint_keys]
        return {"bodies": bodies, "joints": joints, "motors": motors}


def run_position_path(client: WorldClient, handle: RobotHandle, rows: np.ndarray,
                      rate: float, progress: Optional[Callable[[int], None]] = None,
                      sleep: Callable[[float], None] = time.sleep) -> None:
    """One Set Position (every link, by forward kinematics) per row, ``rate`` rows per
    second (thesis 7.4.3: the robot moves even while the simulation is paused)."""
    period = 1.0 / rate
    start = time.monotonic()
    for k, row in enumerate(rows, start=1):
        client.set_position(handle.situations(row), reset_velocity=True)
        if progress is not None:
            progress(k)
        delay = start + k * period - time.monotonic()
        if delay > 0 and k < len(rows):
            sleep(delay)


def run_velocity_path(client: WorldClient, handle: RobotHandle, rows: np.ndarray,
                      rate: float, progress: Optional[Callable[[int], None]] = None,
                      sleep: Callable[[float], None] = time.sleep, stop: bool = True) -> None:
    """One Set Velocity of every motor per row, ``rate`` rows per second (the world's
    publication rate: one row per cycle); the motors are stopped at the end unless ``stop``
    is False."""
    if not handle.motor_ids:
        raise WorldError("set_velocity", f"robot {handle.name} has no motors")
    period = 1.0 / rate
    start = time.monotonic()
    for k, row in enumerate(rows, start=1):
        client.set_velocity(handle.motor_ids, row)
        if progress is not None:
            progress(k)
        delay = start + k * period - time.monotonic()
        if delay > 0:
            sleep(delay)
    if stop:
        client.set_velocity(handle.motor_ids, np.zeros(len(handle.motor_ids)))
