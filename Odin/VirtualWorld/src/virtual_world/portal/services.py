"""The world's services as functions of their request messages, over a Core: what the Portal
serves through rospy, and what replay re-runs from a recording. No rospy here, only the
generated message classes; every rule is the Core's (a refusal is its OdinError).

``WorldServices`` needs a loop (the step values in force, ``simulate``, ``step_cycles``,
``sim_time``: virtual_world.core.loop.WorldLoop or a replay's stand-in) and a viewer sink
(``view``, ``remove``, ``new_scene``: the Portal's ViewerLink, or nothing for replay). Every
build, removal and New Scene that succeeded also goes to the ``mirror`` (portal.mirror: frames,
markers and robots for tf, RViz and the robots' topics), which Set Robot declares robots in.
"""
from __future__ import annotations

import time

import numpy as np
from geometry_msgs.msg import Vector3
from Messages.msg import CollisionPair

from odin_common import messages
from odin_common.interface import ForceKind, SetJointAction
from odin_common.limits import shown
from odin_common.specs import EntitySpec, JointSpec, MotorSpec
from odin_common.world_parameters import set_world_flags
from virtual_world.core import Core, long_calls, step_values
from virtual_world.core.actuation import SERVO_LISTS
from virtual_world.errors import InvalidArgument
from virtual_world.portal import conversions
from virtual_world.portal.mirror import WorldMirror
from virtual_world.portal.robots import robot_message, robot_of

#: Set World request flags -> the world parameters each applies (value fields follow it).
WORLD_FIELDS = set_world_flags()

#: services that only read: they change nothing and a recording leaves them out
READ_ONLY = frozenset({"get_world", "get_state", "check_collision"})
#: services that drive the loop: a recording holds the advances they caused instead
LOOP_CONTROL = frozenset({"start", "step_once"})


class NoViewer:
    """A viewer sink that shows nothing (replay)."""

    def view(self, requests) -> None:
        pass

    def remove(self, ids) -> None:
        pass

    def new_scene(self) -> None:
        pass


class WorldServices:
    """One method per world service (odin_common.interface.WORLD_SERVICES): request message ->
    the response's fields (``success`` aside)."""

    def __init__(self, core: Core, loop, viewer=NoViewer(), mirror: WorldMirror = None):
        self.core = core
        self.loop = loop
        self.viewer = viewer
        self.mirror = WorldMirror() if mirror is None else mirror
        #: whether the caller of the call being served has gone (the Portal sets it around
        #: each call: portal.caller); long calls stop then (core.long_calls)
        self.cancelled: long_calls.Cancel = long_calls.never

    def _built(self, *built) -> None:
        """Objects the Core built (core.Built each): to the Viewer and the mirror."""
        for member in built:
            self.viewer.view(conversions.view_requests(member.geometries))
            self.mirror.built(member.id, self.core.object_spec(member.id), member.geometries)

    def step_fields(self) -> dict:
        """The step values in force, as Set Step and Get World answer them."""
        values = self.loop.step_values
        return {"step": values.step, "steps_per_cycle": values.steps_per_cycle,
                "cycle_time": values.cycle_time, "rate": values.rate}

    def new_scene(self, request) -> dict:
        self.core.new_scene()
        self.viewer.new_scene()
        self.mirror.cleared()
        self._sync_loop_time()
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
        return dict(self.step_fields(), message=note)

    def step_once(self, request) -> dict:
        sim_time = self.loop.step_cycles(request.cycles, self.cancelled)
        return {"sim_time": sim_time, "message": f"{request.cycles or 1} cycle(s)"}

    def start(self, request) -> dict:
        self.loop.simulate = bool(request.simulate)
        return {"simulating": self.loop.simulate,
                "message": "simulating" if self.loop.simulate else "paused"}

    def build_object(self, request) -> dict:
        built = self.core.build_object(messages.object_spec(request.object))
        self._built(built)
        return {"id": built.id}

    def build_composite(self, request) -> dict:
        built = self.core.build_composite(messages.composite_spec(request.composite))
        self._built(built)
        return {"id": built.id}

    def build_entity(self, request) -> dict:
        built = self.core.build_entity(EntitySpec(
            request.name, [messages.object_spec(o) for o in request.objects],
            [messages.composite_spec(c) for c in request.composites],
            request.internal_collisions))
        self._built(*built.members)
        return {"id": built.name, "ids": built.ids}

    def remove_object(self, request) -> dict:
        removed = self.core.remove_object(request.id)
        self.viewer.remove(removed.geometries)
        self.mirror.removed(request.id, removed.joints)
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
            self.mirror.removed(joint_ids=[request.id, *removed.joints])
            also = [*removed.motors, *removed.forces]
            return {"id": request.id, "message": f"removed {request.id}"
                    + (f" and {', '.join(also)}" if also else "")}
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
        self.core.set_velocity(
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

    def set_servo(self, request) -> dict:
        motor_ids = list(request.motors)
        if not motor_ids:
            raise InvalidArgument("no motor given")
        if request.release:
            self.core.release_servos(motor_ids, request.drive)
            return {"message": f"released {len(motor_ids)} servo(s)"}
        if request.drive and not any(len(getattr(request, name)) for name in SERVO_LISTS):
            self.core.set_drive(motor_ids, request.drive)
            return {"message": f"drive of {len(motor_ids)} motor(s) set"}
        self.core.set_servo(motor_ids, request.targets, request.rates, request.gains,
                            request.max_speeds, request.max_forces, request.drive)
        return {"message": f"{len(motor_ids)} servo(s) set"}

    def set_surface(self, request) -> dict:
        self.core.set_surface(request.id, messages.surface_of(request.surface))
        return {"message": f"surface of {request.id} set"}

    def get_world(self, request) -> dict:
        core = self.core
        return {"parameters": messages.world_parameters_message(core.world_parameters),
                **self.step_fields(), "sim_time": core.sim_time,
                "simulating": self.loop.simulate, "objects": core.object_ids(),
                "entities": list(core.entities()), "joints": core.joint_ids(),
                "motors": core.motor_ids(), "body_forces": core.body_force_ids(),
                "joint_forces": core.joint_force_ids(), "snapshots": core.snapshot_names(),
                "frames": self.mirror.frames.frames(core.object_ids()),
                "robots": [robot_message(r) for r in self.mirror.robots],
                "clock": self.mirror.clock.now(core.sim_time),
                "message": f"{len(core.object_ids())} objects at {core.sim_time:g} s"}

    def set_robot(self, request) -> dict:
        if request.remove:
            robot = self.mirror.remove_robot(request.robot.name)
            return {"ros_namespace": robot.namespace,
                    "message": f"forgot robot {shown(robot.name)}"}
        robot = robot_of(request.robot)
        self.mirror.set_robot(robot, {s.id: s.type for s in self.core.joint_states()})
        return {"ros_namespace": robot.namespace,
                "message": f"robot {shown(robot.name)} in namespace /{robot.namespace}: "
                           f"{len(robot.links)} links, {len(robot.joints)} joints"}

    def get_state(self, request) -> dict:
        bodies, joints, motors = self.core.state(request.objects, request.joints,
                                                 request.motors)
        return {"bodies": [messages.body_state_message(b) for b in bodies],
                "masses": [b.mass for b in bodies],
                "centers_of_mass": [Vector3(*b.center_of_mass) for b in bodies],
                "inertias": [v for b in bodies for v in b.inertia],
                "joints": conversions.joint_data(joints),
                "reactions1": [conversions.wrench(j.force1, j.torque1) for j in joints],
                "reactions2": [conversions.wrench(j.force2, j.torque2) for j in joints],
                "motors": [m.id for m in motors], "motor_joints": [m.joint for m in motors],
                "motor_axes": [len(m.goals) for m in motors],
                "motor_goals": [v for m in motors for v in m.goals],
                "motor_max_forces": [v for m in motors for v in m.max_forces],
                "state_vector": self.core.body_state_vector().tolist(),
                "message": f"{len(bodies)} bodies, {len(joints)} joints, {len(motors)} motors"}

    def save_state(self, request) -> dict:
        self.core.save_state(request.name)
        return {"message": f"saved {shown(request.name)} at {self.core.sim_time:g} s"}

    def restore_state(self, request) -> dict:
        self.core.restore_state(request.name)
        self._sync_loop_time()
        return {"sim_time": self.core.sim_time, "message": f"restored {shown(request.name)}"}

    def reset(self, request) -> dict:
        self.core.reset()
        self._sync_loop_time()
        return {"sim_time": self.core.sim_time, "message": "reset to the last build"}

    def _sync_loop_time(self) -> None:
        """The loop publishes the Core's simulated time, which a snapshot put back."""
        self.loop.sim_time = self.core.sim_time

    def propagate(self, request) -> dict:
        if request.row:
            return self._propagate_row(request)
        goals = self.core.split_per_axis(list(request.motors), list(request.velocities))
        step = request.step or self.loop.step_values.step
        result = self.core.propagate(
            request.duration, step, motor_goals=goals,
            body_forces=[messages.body_force_arguments(f) for f in request.forces],
            start=request.start, keep=request.keep, start_state=request.start_state,
            cancelled=self.cancelled)
        if result.kept:
            self._sync_loop_time()
        return {"start_time": result.start_time, "step": result.step_size,
                "steps": result.steps,
                "states": [messages.body_state_message(s) for s in result.states],
                "collisions": conversions.collision_pairs(result.collisions),
                "first_times": [c.first_time for c in result.collisions],
                "wall_time": result.wall_time, "state": result.state.tolist(),
                "message": f"{result.steps} steps in {result.wall_time:.3g} s"
                           + (", kept" if result.kept else "")}

    def _propagate_row(self, request) -> dict:
        """Propagate with ``row``: a planner's control held over several propagations
        (Core.propagate_row), every one's state and pairs answered."""
        if request.start or request.motors or request.velocities or not len(request.start_state):
            raise InvalidArgument("row: give start_state, and neither a start snapshot nor "
                                  "motors (a planner sets its servos first)")
        step = request.step or self.loop.step_values.step
        pushes = []
        for force in request.forces:
            if force.kind != ForceKind.FORCE or force.at_point or force.vector_in_body_frame:
                raise InvalidArgument("row: forces only at the centre of mass, world frame")
            pushes.append((force.object, tuple(force.vector)))
        start_time = self.core.sim_time
        started = time.perf_counter()
        row = self.core.propagate_row(request.start_state, request.row, request.duration, step,
                                      pushes, keep=request.keep)
        wall = time.perf_counter() - started
        if request.keep:
            self._sync_loop_time()
        pairs = [pair for one in row for pair in one.pairs]
        return {"start_time": start_time, "step": step,
                "steps": sum(one.steps for one in row), "states": [],
                "collisions": [CollisionPair(first=a, second=b) for a, b in pairs],
                "first_times": [], "wall_time": wall, "state": row[-1].state.tolist(),
                "row_states": np.concatenate([one.state for one in row]).tolist(),
                "row_pairs": [len(one.pairs) for one in row],
                "message": f"a row of {len(row)} propagations in {wall:.3g} s"
                           + (", kept" if request.keep else "")}

    def check_collision(self, request) -> dict:
        pairs = self.core.check_collision(messages.situation_poses(request.situations))
        return {"pairs": conversions.collision_pairs(pairs),
                "message": f"{len(pairs)} colliding pair(s)"}

    def exempt_overlaps(self, request) -> dict:
        pairs = self.core.exempt_overlaps(request.min_depth)
        return {"pairs": conversions.collision_pairs(pairs),
                "message": f"{len(pairs)} pair(s) exempt until they part"}

    def set_joint_force(self, request) -> dict:
        if request.remove:
            self.core.remove_joint_force(request.id)
            return {"id": request.id, "message": f"removed {request.id}"}
        force_id = self.core.add_joint_force(request.joint, tuple(request.magnitudes))
        return {"id": force_id, "message": f"added {force_id}"}
