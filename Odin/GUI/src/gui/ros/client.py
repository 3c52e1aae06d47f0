"""The GUI's client of the VirtualWorld: rospy service proxies, no Qt.

``WorldClient`` calls the world's services (``odin_common.interface.WORLD_SERVICES``) through
one ``gui.ros.services.ServiceCaller`` (a persistent proxy per service) and offers one typed
method per thing a tool or the window asks of the world: requests go in as odin_common specs,
enums and plain values (SI units, world frame, quaternions (w, x, y, z)), answers come back as
IDs, ``WorldParameters`` or ``StepValues``. A refusal (``success: false``) or a broken
connection raises ``gui.errors.WorldError`` carrying the world's message. ``execute(plan)``
sends a ``gui.core.plan.BuildPlan`` (each step sends itself, then declares each robot it built
with Set Robot: its robot_description, namespace and joint names, gui.core.robot_description);
``run_position_path`` / ``run_velocity_path`` drive a robot, ``run_position_rows`` /
``run_velocity_rows`` several (their bases too) at once. Messages are built only by
``odin_common.messages`` and here.

The Qt window must not call these from its GUI thread (each call blocks until the world
answers): run them in a worker thread and signal the results back (gui.window.worker).

Requires ``rospy.init_node`` (done here with ``disable_signals=True`` unless already done);
importing this module does not import rospy (only the generated message classes).
"""
from __future__ import annotations

import dataclasses
import logging
import os
import time
from typing import Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from gui.core.overlaps import goal_overlaps, goal_warning, overlap_warning
from gui.core.paths import RobotRows
from gui.core.plan import BuildPlan, BuiltIds, RobotHandle
from gui.core.world_port import Built, Progress, build
from gui.core.robot_description import RobotDescription, describe_robot
from gui.errors import WorldError
from gui.ros.services import ServiceCaller, join_ros_graph
from gui.ros.world_port import ClientWorldPort
from Services.srv import BuildEntityRequest
from odin_common.errors import InvalidArgument
from odin_common.limits import ResourceLimits
from odin_common.interface import WORLD_NAMESPACE, WORLD_SERVICES, ForceKind, SetJointAction
from odin_common.messages import (body_force_message, composite_message, object_message,
                                  parameter_messages, situation_messages, world_parameters_of)
from odin_common.packed import COUNT, PrePacked, serialised, string_size, with_mesh_arrays
from odin_common.specs import CompositeSpec, EntitySpec, JointSpec, MotorSpec, ObjectSpec
from odin_common.step_values import StepValues
from odin_common.world_parameters import (PARAMETER_INFO, PARAMETERS, ParameterInfo,
                                          WorldParameters, set_world_flags)


def _floats(values) -> list:
    return [float(v) for v in np.asarray(values, dtype=float).reshape(-1)]


def _field(info: ParameterInfo, value):
    """A world parameter as Set World's request field holds it."""
    if info.kind == "vector":
        return _floats(value)
    if info.kind == "int":
        return int(value)
    if info.kind == "bool":
        return bool(value)
    return float(value)


def _world_parameters(response) -> WorldParameters:
    """Set World's answer -> the WorldParameters in force."""
    values = {}
    for info in PARAMETERS:
        value = _field(info, getattr(response, info.name))
        values[info.name] = tuple(value) if info.kind == "vector" else value
    return WorldParameters(**values)


class WorldRobot(NamedTuple):
    """A robot the world holds (declared with Set Robot): its ROS namespace, its links' world
    objects and its joints' own names with their world joints."""
    name: str
    namespace: str
    links: Tuple[str, ...]
    objects: Tuple[str, ...]
    joint_names: Tuple[str, ...]
    joints: Tuple[str, ...]


class WorldInventory(NamedTuple):
    """Get World's answer: the values in force and the IDs of what the world holds (``frames``:
    each object's tf frame; ``clock``: s, the world clock of its last publication)."""
    parameters: WorldParameters
    step_values: StepValues
    sim_time: float
    simulating: bool
    objects: Tuple[str, ...]
    entities: Tuple[str, ...]
    joints: Tuple[str, ...]
    motors: Tuple[str, ...]
    body_forces: Tuple[str, ...]
    joint_forces: Tuple[str, ...]
    snapshots: Tuple[str, ...]
    frames: Tuple[str, ...] = ()
    robots: Tuple[WorldRobot, ...] = ()
    clock: float = 0.0


class PropagationResult(NamedTuple):
    """Propagate's answer: start (s), step (s), steps, the final state {object ID: (position,
    orientation, linear, angular)}, collisions (first, second, depth m, first time s) and the
    wall time (s)."""
    start_time: float
    step: float
    steps: int
    states: Dict[str, tuple]
    collisions: Tuple[tuple, ...]
    wall_time: float


def _step_values(response) -> StepValues:
    return StepValues(step=float(response.step), steps_per_cycle=int(response.steps_per_cycle),
                      rate=float(response.rate))


class WorldClient:
    """Calls ``<namespace>/<service>``; every method raises ``WorldError`` on refusal."""

    def __init__(self, namespace: str = WORLD_NAMESPACE, timeout: float = 10.0,
                 node_name: str = "gui"):
        join_ros_graph(node_name)
        self._caller = ServiceCaller(namespace, WORLD_SERVICES, WorldError)
        self.namespace = self._caller.namespace
        self._caller.wait("build_entity", timeout,
                          f"no VirtualWorld answering after {timeout:g} s "
                          "(is `rosrun VirtualWorld virtualWorld` running?)")

    def call(self, service: str, /, **fields):
        """Calls one service with request ``fields``; returns the response or raises."""
        return self._caller.call(service, **fields)

    def ask(self, service: str, /, **fields):
        """Calls one service and returns its response, refused or not (a refused Set Step or
        Set World still reports the values in force); raises only if the call fails."""
        return self._caller.ask(service, **fields)

    def close(self) -> None:
        self._caller.close()

    # -- the scene and the simulation ----------------------------------------------------------
    def new_scene(self) -> None:
        """New Scene: removes every object, joint, motor and force (parameters stay)."""
        self.call("new_scene")

    def set_world(self, **changes) -> WorldParameters:
        """Set World with the world parameters ``changes`` (names, units and ranges:
        odin_common.world_parameters.PARAMETERS, e.g. ``gravity=(0, 0, -1.62), erp=0.1``), all
        or nothing; returns the parameters in force. Set World applies some parameters in pairs
        (bounce with bounce_velocity, solver with quickstep_iterations): the one of a pair not
        given keeps its value in force."""
        if not changes:
            raise InvalidArgument("Set World: no world parameter given")
        unknown = sorted(set(changes) - set(PARAMETER_INFO))
        if unknown:
            raise InvalidArgument(f"Set World: unknown world parameter(s) {unknown}; known: "
                                  f"{[p.name for p in PARAMETERS]}")
        flags = set_world_flags()
        partners = {name for given in changes for name in flags[PARAMETER_INFO[given].set_flag]
                    if name not in changes}
        values = dict(changes)
        if partners:
            in_force = self.world_parameters()
            values.update({name: getattr(in_force, name) for name in partners})
        fields = {}
        for name, value in values.items():
            info = PARAMETER_INFO[name]
            fields[info.set_flag] = True
            fields[name] = _field(info, value)
        return _world_parameters(self.call("set_world", **fields))

    def world(self) -> "WorldInventory":
        """Get World: what the world holds and the values in force."""
        r = self.call("get_world")
        return WorldInventory(world_parameters_of(r.parameters), _step_values(r),
                              float(r.sim_time), bool(r.simulating), tuple(r.objects),
                              tuple(r.entities), tuple(r.joints), tuple(r.motors),
                              tuple(r.body_forces), tuple(r.joint_forces), tuple(r.snapshots),
                              tuple(r.frames), tuple(
                                  WorldRobot(b.name, b.ros_namespace, tuple(b.links),
                                             tuple(b.objects), tuple(b.joint_names),
                                             tuple(b.joints)) for b in r.robots),
                              float(r.clock))

    def world_parameters(self) -> WorldParameters:
        """The world parameters in force."""
        return self.world().parameters

    def resource_limits(self) -> ResourceLimits:
        """What the world node may hold (its ``~max_objects``, ``~max_mesh_triangles``...
        private parameters, read once when it started; the defaults where it was given
        none), read from the parameter server."""
        import rospy
        defaults = ResourceLimits()
        try:
            values = {f.name: rospy.get_param(f"{self.namespace}/{f.name}",
                                              getattr(defaults, f.name))
                      for f in dataclasses.fields(ResourceLimits)}
        except (OSError, rospy.ROSException) as error:
            raise WorldError(self.namespace, f"its limits cannot be read from the parameter "
                             f"server: {error}") from None
        return ResourceLimits(**values)

    def set_step(self, step: Optional[float] = None, steps_per_cycle: Optional[int] = None,
                 cycle_time: Optional[float] = None, rate: Optional[float] = None) -> StepValues:
        """Set Step with the values given (s, steps, s, Hz; None: not given); the world resolves
        the others (thesis 4.5) and answers the values in force. Nothing given is refused."""
        fields = {}
        if step is not None:
            fields["step"] = float(step)
        if steps_per_cycle is not None:
            fields["steps_per_cycle"] = int(steps_per_cycle)
        if cycle_time is not None:
            fields["cycle_time"] = float(cycle_time)
        if rate is not None:
            fields["rate"] = float(rate)
        return _step_values(self.call("set_step", **fields))

    def step_values(self) -> StepValues:
        """The step values in force."""
        return self.world().step_values

    def publication_rate(self) -> float:
        """The world's publications per wall-clock second (Hz)."""
        return self.step_values().rate

    def step_once(self, cycles: int = 1) -> float:
        """Step Once: advances a paused world ``cycles`` Portal cycles; returns the simulated
        time after them (s)."""
        return float(self.call("step_once", cycles=int(cycles)).sim_time)

    def start(self) -> bool:
        """Start: the simulation advances by itself; returns the state in force (True)."""
        return bool(self.call("start", simulate=True).simulating)

    def pause(self) -> bool:
        """Start with simulate false; returns the state in force (False)."""
        return bool(self.call("start", simulate=False).simulating)

    # -- objects ---------------------------------------------------------------------------
    def build_object(self, spec: ObjectSpec) -> str:
        """Build Object; returns its ID."""
        return self.call("build_object", object=object_message(spec)).id

    def build_composite(self, spec: CompositeSpec) -> str:
        """Build Composite; returns its ID (">part1>part2...")."""
        return self.call("build_composite", composite=composite_message(spec)).id

    def build_entity(self, spec: EntitySpec) -> Built:
        """Build Entity (all or nothing); returns its name and its members' IDs."""
        response = self._caller.send("build_entity", _packed_build_entity(spec))
        return Built(response.id, tuple(response.ids))

    def remove_object(self, object_id: str) -> None:
        """Remove Object, with its joints, motors and forces."""
        self.call("remove_object", id=object_id)

    def set_position(self, situations: Sequence, reset_velocity: bool = True) -> None:
        """Set Position of bodies at once. ``situations``: (body ID, position (3,) m world,
        quaternion (w, x, y, z)); ``reset_velocity`` also zeroes their velocities."""
        self.call("set_position", situations=situation_messages(situations),
                  reset_velocity=bool(reset_velocity))

    def set_body_velocity(self, object_id: str, linear: Optional[Sequence[float]] = None,
                          angular: Optional[Sequence[float]] = None) -> None:
        """Set Velocity of one object: ``linear`` (3,) m/s and/or ``angular`` (3,) rad/s,
        world frame (None: unchanged)."""
        fields = dict(object=object_id)
        if linear is not None:
            fields.update(set_linear=True, linear=_floats(linear))
        if angular is not None:
            fields.update(set_angular=True, angular=_floats(angular))
        self.call("set_velocity", **fields)

    def add_body_force(self, object_id: str, kind: ForceKind, vector: Sequence[float],
                       vector_in_body_frame: bool = False, at_point: bool = False,
                       point: Sequence[float] = (0.0, 0.0, 0.0),
                       point_in_body_frame: bool = False) -> str:
        """Set External Force: a persistent force (N, at the centre of mass or at ``point``, m)
        or torque (N m) on an object, world or body frame; returns its ID."""
        return self.call("set_external_force", object=object_id, kind=int(ForceKind(kind)),
                         vector=_floats(vector),
                         vector_in_body_frame=bool(vector_in_body_frame),
                         at_point=bool(at_point), point=_floats(point),
                         point_in_body_frame=bool(point_in_body_frame)).id

    def remove_body_force(self, force_id: str) -> None:
        self.call("set_external_force", remove=True, id=force_id)

    # -- joints and motors -----------------------------------------------------------------
    def add_joint(self, spec: JointSpec) -> str:
        """Set Joint, action CREATE; returns the joint's ID."""
        return self.call("set_joint", action=int(SetJointAction.CREATE), id=spec.id,
                         type=int(spec.type), body1=spec.body1, body2=spec.body2,
                         anchor=_floats(spec.anchor), axis1=_floats(spec.axis1),
                         axis2=_floats(spec.axis2), axis3=_floats(spec.axis3),
                         parameters=parameter_messages(spec.parameters)).id

    def set_joint_parameters(self, joint_id: str, parameters: Sequence) -> None:
        """Set Joint, action SET_PARAMETERS: (JointParameter, axis 1..3, value) triples on a
        joint or a motor, all or nothing."""
        self.call("set_joint", action=int(SetJointAction.SET_PARAMETERS), id=joint_id,
                  parameters=parameter_messages(parameters))

    def remove_joint(self, joint_id: str) -> None:
        """Set Joint, action REMOVE (its motors and forces go with it)."""
        self.call("set_joint", action=int(SetJointAction.REMOVE), id=joint_id)

    def add_motor(self, spec: MotorSpec) -> str:
        """Set Motor; returns the motor's ID."""
        return self.call("set_motor", id=spec.id, joint=spec.joint, kind=int(spec.kind),
                         body1=spec.body1, body2=spec.body2, axes=_floats(spec.axes),
                         axis_frames=[int(f) for f in spec.axis_frames],
                         max_forces=_floats(spec.max_forces)).id

    def remove_motor(self, motor_id: str) -> None:
        self.call("set_motor", remove=True, id=motor_id)

    def set_velocities(self, motors: Sequence[str], velocities: Sequence[float]) -> None:
        """Set Velocity: the goal speeds of ``motors``, one per motor axis in order (rad/s
        angular, m/s linear)."""
        self.call("set_velocity", motors=list(motors), velocities=_floats(velocities))

    def add_joint_force(self, joint_id: str, magnitudes: Sequence[float]) -> str:
        """Set Joint Force: persistent magnitudes along the joint's axes (N m rotations, N
        translations; odin_common.interface.JOINT_FORCE_MAGNITUDES); returns its ID."""
        return self.call("set_joint_force", joint=joint_id, magnitudes=_floats(magnitudes)).id

    def remove_joint_force(self, force_id: str) -> None:
        self.call("set_joint_force", remove=True, id=force_id)

    # -- plans --------------------------------------------------------------------------------
    # -- planners: snapshots, propagation, collision queries ----------------------------------
    def save_state(self, name: str) -> None:
        """Save State: the whole dynamic state kept under ``name``."""
        self.call("save_state", name=name)

    def restore_state(self, name: str) -> float:
        """Restore State; returns the simulated time after it (s)."""
        return float(self.call("restore_state", name=name).sim_time)

    def reset(self) -> float:
        """Reset to the state right after the last build; returns the simulated time (s)."""
        return float(self.call("reset").sim_time)

    def body_kinematics(self, object_id: str) -> Tuple[np.ndarray, np.ndarray, np.ndarray,
                                                       np.ndarray]:
        """Get State of one body: position (m, world), orientation (w, x, y, z, world), linear
        velocity (m/s, world) and angular velocity (rad/s, world)."""
        b = self.call("get_state", objects=[object_id]).bodies[0]
        return (np.array(b.position), np.array(b.orientation), np.array(b.linear),
                np.array(b.angular))

    def masses(self, object_ids: Sequence[str]) -> Tuple[float, ...]:
        """Get State: each object's mass (kg), in order (none asked: none)."""
        if not len(object_ids):             # Get State's empty list asks for every body
            return ()
        return tuple(float(m) for m in self.call("get_state", objects=list(object_ids)).masses)

    def joint_positions(self, joint_ids: Sequence[str]) -> np.ndarray:
        """Get State: each joint's first axis position (rad or m), in order."""
        if not len(joint_ids):
            return np.empty(0)
        response = self.call("get_state", joints=list(joint_ids))
        return np.array([j.positions[0] for j in response.joints], dtype=float)

    def set_servo(self, command) -> None:
        """Set Servo from a gui.core.control_path.ServoCommand (motors, targets rad or m,
        rates, gains 1/s, speed limits, force limits)."""
        self.call("set_servo", **command.request_fields())

    def set_drive(self, motors: Sequence[str], drive: int) -> None:
        """Set Servo's drive alone (odin_common.interface.ServoDrive) for the motors' joints:
        KINEMATIC, the links follow the commanded speeds exactly; DYNAMIC, motors push them."""
        self.call("set_servo", motors=list(motors), drive=int(drive))

    def propagate(self, duration: float, step: float = 0.0,
                  motor_goals: Optional[Dict[str, Sequence[float]]] = None,
                  forces: Sequence[dict] = (), start: str = "", keep: bool = False
                  ) -> "PropagationResult":
        """Propagate: ``duration`` s (steps of ``step`` s, 0: the world's) from the snapshot
        ``start`` (or now) under ``motor_goals`` ({motor id: goal speeds}) and ``forces`` (each
        the keyword arguments of odin_common.messages.body_force_message); the world goes back
        unless ``keep``."""
        goals = motor_goals or {}
        r = self.call("propagate", start=start, duration=float(duration), step=float(step),
                      motors=list(goals), velocities=[float(v) for g in goals.values()
                                                      for v in g],
                      forces=[body_force_message(**f) for f in forces], keep=bool(keep))
        states = {s.id: (tuple(s.position), tuple(s.orientation), tuple(s.linear),
                         tuple(s.angular)) for s in r.states}
        collisions = tuple((c.first, c.second, c.depth, t)
                           for c, t in zip(r.collisions, r.first_times))
        return PropagationResult(float(r.start_time), float(r.step), int(r.steps), states,
                                 collisions, float(r.wall_time))

    def check_collision(self, poses: Sequence) -> list:
        """Check Collision for ``poses`` ((object ID, position m, quaternion (w, x, y, z))):
        [(first, second, depth m)] of the pairs that would collide; the world is unchanged."""
        r = self.call("check_collision", situations=situation_messages(poses))
        return [(p.first, p.second, p.depth) for p in r.pairs]

    def exempt_overlaps(self, min_depth: float) -> list:
        """Exempt Overlaps: the pairs inside each other deeper than ``min_depth`` m (where a
        part has a body) do not collide until they have moved apart; [(first, second, depth
        m)] of those pairs."""
        r = self.call("exempt_overlaps", min_depth=min_depth)
        return [(p.first, p.second, p.depth) for p in r.pairs]

    def check_configuration(self, handle: RobotHandle, values: Sequence[float]) -> list:
        """Check Collision for a robot at joint ``values`` (rad / m, the robot's movable joints
        in order), every link placed by forward kinematics."""
        return self.check_collision(handle.situations(values))

    def set_robot(self, description: RobotDescription) -> str:
        """Set Robot: declares a robot over objects and joints the world holds (its
        robot_description, link frames and joint names; gui.core.robot_description); returns
        its ROS namespace."""
        from Messages.msg import Robot
        d = description
        message = Robot(name=d.name, description=d.urdf, links=list(d.links),
                        objects=list(d.objects), link_positions=_floats(d.link_positions),
                        link_orientations=_floats(d.link_orientations),
                        joint_names=list(d.joint_names), joints=list(d.joints),
                        joint_axes=list(d.joint_axes), joint_offsets=_floats(d.joint_offsets))
        return self.call("set_robot", robot=message).ros_namespace

    def remove_robot(self, name: str) -> None:
        """Set Robot with ``remove``: the world forgets the robot (its objects stay)."""
        from Messages.msg import Robot
        self.call("set_robot", robot=Robot(name=name), remove=True)

    def execute(self, plan: BuildPlan, progress: Optional[Progress] = None,
                mesh_dir: Optional[str] = None, ids: Optional[BuiltIds] = None) -> dict:
        """Sends every step of ``plan`` in order, then declares each robot it built (Set
        Robot); returns the world's IDs: {"bodies": {planned body ID: world ID}, "joints":
        {joint key: world ID}, "motors": {joint key: world motor ID}, "robots": {robot name:
        namespace}}. ``progress(k, step, answer)`` after each step. ``mesh_dir``: where
        generated robot descriptions' meshes go (default ``robot_mesh_dir()``).

        Joint and motor IDs the world returns replace the predicted ones in ``plan.robots``.
        Stops at the first refusal (``WorldError``); what was built before stays built, its
        world IDs in ``ids`` when given (gui.planning.rehearsal.load_scene, which builds a
        plan all or nothing, removes them). Parts built inside each other
        (``gui.core.overlaps``) are warned about once and answered as "overlaps": [Overlap];
        in a problem Kautham never simulates they are exempt until they have moved apart
        ("overlaps_exempt": True). The pairs the query's goal would put inside each other are
        warned about too and answered as "goal_overlaps" (gui.core.overlaps.goal_overlaps)."""
        ids, overlaps, exempt = build(ClientWorldPort(self), plan, progress, ids)
        folder = robot_mesh_dir() if mesh_dir is None else mesh_dir
        namespaces = {handle.name: self.set_robot(describe_robot(handle, folder))
                      for handle in plan.robots}
        log = logging.getLogger("gui.core.overlaps")
        if overlaps:
            log.warning(overlap_warning(plan.problem.source, overlaps, exempt))
        at_goal = goal_overlaps(self, plan, overlaps)
        if at_goal:
            log.warning(goal_warning(plan.problem.source, at_goal))
        return {**ids.as_dict(), "robots": namespaces, "overlaps": overlaps,
                "overlaps_exempt": exempt, "goal_overlaps": at_goal}


# -- requests whose meshes go out as numpy bytes -----------------------------------------
# genpy serialises a float64[] or uint32[] field from a Python list (a float object per
# number, packed one by one): for the TX90 hand's entity, 800,000 numbers, 0.17 s of
# load_problem's CPU. Here an Object's mesh arrays are written from numpy instead
# (odin_common.packed). This relies on BuildEntity's request beginning with name, objects,
# pinned byte for byte to genpy by Odin/GUI/test/test_packed_requests.py.


def packed_object(spec: ObjectSpec) -> bytes:
    """Object (Messages/Object) ``spec`` serialised as genpy would, its parameters (float64)
    and indices (uint32) written from numpy arrays."""
    light = serialised(object_message(dataclasses.replace(spec, parameters=(), indices=())))
    return with_mesh_arrays(light, spec.name, np.asarray(spec.parameters, dtype=float),
                            np.asarray(spec.indices, dtype=np.uint32))


def _packed_build_entity(spec: EntitySpec) -> "_PackedBuildEntity":
    """Build Entity's request for ``spec``, its objects packed (:func:`packed_object`)."""
    request = _PackedBuildEntity(
        name=spec.name, objects=[],
        composites=[composite_message(c) for c in spec.composites],
        internal_collisions=bool(spec.internal_collisions))
    rest = serialised(request)
    head = string_size(spec.name)
    parts = [packed_object(o) for o in spec.objects]
    request.packed = b"".join((rest[:head], COUNT.pack(len(parts)), *parts,
                               rest[head + COUNT.size:]))
    return request


class _PackedBuildEntity(PrePacked, BuildEntityRequest):
    """A Build Entity request sent as bytes made beforehand (odin_common.packed.PrePacked)."""


def robot_mesh_dir() -> str:
    """Where generated robot descriptions' meshes are written: ``$ROS_HOME/odin/robot_meshes``
    (``~/.ros`` without ROS_HOME). Their ``file://`` URIs resolve on this machine only
    (docs/ROS.md: several machines)."""
    import rospkg
    return os.path.join(rospkg.get_ros_home(), "odin", "robot_meshes")


def present_base(client: WorldClient, handle: RobotHandle) -> np.ndarray:
    """(4, 4), world: where the robot's base link is now. A base that can move (a free body,
    a mobile base, a car) is read from the world; a held one is where it was built."""
    from gui.core.model import CAR, FREE_BODY, MOBILE
    from gui.core.paths import base_link_pose
    if handle.kind not in (FREE_BODY, MOBILE, CAR):
        return np.array(handle.base_pose, dtype=float)
    position, quaternion, _, _ = client.body_kinematics(handle.bodies[0].body_id)
    return base_link_pose(handle, position, quaternion)


def rows_to_send(client: WorldClient, paths: Sequence, handles: Dict[str, RobotHandle],
                 double: int = 0, first_row: Optional[object] = None) -> List[RobotRows]:
    """Each of ``paths`` (gui.core.paths.RobotPath, of the robots ``handles`` names) with its
    rows as sent and where its base is in the world now (``present_base``: a base the rows do
    not carry stays there); with ``first_row`` (gui.core.paths.JumpOptions), a position
    path's first row checked against where its robot is (a base's columns against its
    position now), before its precision is doubled ``double`` times. Every robot is checked
    before the caller sends any row."""
    from gui.core.paths import check_first_row, present_joints, refine
    out = []
    for path in paths:
        handle = handles[path.robot]
        base = present_base(client, handle)
        if first_row is not None:
            check_first_row(path, np.concatenate([base[list(path.base_axes), 3],
                                                  present_joints(client, handle)]), first_row)
        rows = refine(path.rows, double) if double else path.rows
        out.append(RobotRows(handle, rows, path.base_axes, base))
    return out


def run_position_path(client: WorldClient, handle: RobotHandle, rows: np.ndarray,
                      rate: float, progress: Optional[Callable[[int], None]] = None,
                      sleep: Callable[[float], None] = time.sleep) -> None:
    """One Set Position (every link, by forward kinematics) per row of ``handle``'s movable
    joints, its base where it was built, ``rate`` rows per second (thesis 7.4.3: the robot
    moves even while the simulation is paused)."""
    run_position_rows(client, [RobotRows(handle, np.asarray(rows, dtype=float))], rate,
                      progress, sleep)


def run_position_rows(client: WorldClient, robots: Sequence[RobotRows], rate: float,
                      progress: Optional[Callable[[int], None]] = None,
                      sleep: Callable[[float], None] = time.sleep) -> None:
    """One Set Position per row of every robot's links and bases at once
    (``gui.core.paths.RobotRows.situations``), ``rate`` rows per second."""
    period = 1.0 / rate
    start = time.monotonic()
    count = len(robots[0].rows)
    for k in range(count):
        client.set_position([s for robot in robots for s in robot.situations(k)],
                            reset_velocity=True)
        if progress is not None:
            progress(k + 1)
        delay = start + (k + 1) * period - time.monotonic()
        if delay > 0 and k + 1 < count:
            sleep(delay)


def run_velocity_path(client: WorldClient, handle: RobotHandle, rows: np.ndarray,
                      rate: float, progress: Optional[Callable[[int], None]] = None,
                      sleep: Callable[[float], None] = time.sleep, stop: bool = True) -> None:
    """One Set Velocity of every motor per row, ``rate`` rows per second (the world's
    publication rate: one row per cycle); the motors are stopped at the end unless ``stop``
    is False."""
    run_velocity_rows(client, [RobotRows(handle, np.asarray(rows, dtype=float))], rate,
                      progress, sleep, stop)


def run_velocity_rows(client: WorldClient, robots: Sequence[RobotRows], rate: float,
                      progress: Optional[Callable[[int], None]] = None,
                      sleep: Callable[[float], None] = time.sleep, stop: bool = True) -> None:
    """Per row, one Set Velocity of every robot's motors at once and one of each base whose
    columns the rows carry (``gui.core.paths.RobotRows``), ``rate`` rows per second; all
    stopped at the end (``stop_velocity_rows``) unless ``stop`` is False."""
    motors = [m for robot in robots for m in robot.handle.motor_ids]
    for robot in robots:
        if robot.speeds(0).size and not robot.handle.motor_ids:
            raise WorldError("set_velocity", f"robot {robot.handle.name} has no motors")
    period = 1.0 / rate
    start = time.monotonic()
    for k in range(len(robots[0].rows)):
        if motors:
            client.set_velocities(motors, np.concatenate([r.speeds(k) for r in robots]))
        for robot in robots:
            base = robot.base_velocity(k)
            if base is not None:
                client.set_body_velocity(base[0], linear=base[1])
        if progress is not None:
            progress(k + 1)
        delay = start + (k + 1) * period - time.monotonic()
        if delay > 0:
            sleep(delay)
    if stop:
        stop_velocity_rows(client, robots)


def stop_velocity_rows(client: WorldClient, robots: Sequence[RobotRows]) -> None:
    """Stops what a velocity path drives: every robot's motors (speed 0) and the bases whose
    columns it carries (linear and angular velocity 0)."""
    motors = [m for robot in robots for m in robot.handle.motor_ids]
    if motors:
        client.set_velocities(motors, np.zeros(len(motors)))
    for robot in robots:
        if robot.base_axes:
            client.set_body_velocity(robot.handle.bodies[0].body_id, linear=(0.0, 0.0, 0.0),
                                     angular=(0.0, 0.0, 0.0))
