"""The Core: the virtual world of the thesis's chapter 5, ROS-free.

``Core`` holds one Scene behind one re-entrant lock (rospy serves calls on threads of its
own) and forwards each request to the module of its topic: objects, joints, motors,
actuation (Set Velocity and Set Servo), forces, snapshots, propagation (state vectors and
propagations), readout. It owns the world parameters and the step. Every argument is checked
before any ODE call, so an error raised here means nothing changed; the rules of the world
live in the Core, never in a Portal.

Conventions: SI units; world frame unless said; quaternions (w, x, y, z). An object's frame is
the one its spec's pose gives; "body frame" in this API means the object's frame (ODE's body
sits at the centre of mass with the same axes). Fixed bodies are ODE kinematic bodies: never
moved by forces or contacts, infinite mass for them.
"""
from __future__ import annotations

import threading
from typing import Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from odin_common.interface import ServoDrive, Solver
from odin_common.limits import ResourceLimits, shown
from odin_common.specs import CompositeSpec, EntitySpec, JointSpec, MotorSpec, ObjectSpec
from odin_common.world_parameters import WorldParameters
from virtual_world.core import (actuation, checked_propagation, exemptions, forces, guard, joints,
                                long_calls, motion, motors, objects, probe, propagation, readout,
                                snapshots, validation as check)
from virtual_world.core.requests import changes_contents, changes_state, disturbs, locked
from virtual_world.core.records import (Built, BuiltEntity, Collision, Divergence,
                                        JointReaction, JointState, MotorState, ObjectState,
                                        Propagation, Removed, ServoState,
                                        StatePropagation)
from virtual_world.core.checked_propagation import CheckedRow, PlanRule
from virtual_world.core.scene import Scene
from virtual_world.errors import Closed, InvalidArgument
from virtual_world.ode import bodies
from virtual_world.ode.handles import TriMeshDataCache
from virtual_world.ode.runtime import init_ode


class Core:
    """The virtual world: objects, joints, motors, forces, collisions and the step."""

    def __init__(self, parameters: Optional[WorldParameters] = None,
                 resources: ResourceLimits = ResourceLimits()):
        """``parameters``: the world's (WorldParameters()); ``resources``: what the world may
        hold (objects, mesh triangles, snapshots), kept across New Scenes."""
        init_ode()
        parameters = WorldParameters() if parameters is None else parameters
        if not isinstance(parameters, WorldParameters):
            raise InvalidArgument(f"parameters={shown(parameters)} is not a WorldParameters")
        if not isinstance(resources, ResourceLimits):
            raise InvalidArgument(f"resources={shown(resources)} is not a ResourceLimits")
        check.shared(parameters.validate)
        self._lock = threading.RLock()
        self.resources = resources
        # built trimesh data outlives the scene: the same meshes come back after New Scene
        self._meshes = TriMeshDataCache()
        self._scene: Optional[Scene] = Scene(parameters, resources, self._meshes)

    # ------------------------------------------------------------------ lifetime

    @locked
    def new_scene(self) -> None:
        """Frees every object, joint, motor and force and starts an empty world with the
        same world parameters; sim_time restarts at 0."""
        parameters = self._scene.parameters
        self._scene.close()
        self._scene = Scene(parameters, self.resources, self._meshes)

    def close(self) -> None:
        """Frees everything; idempotent. Any later call but close() raises Closed."""
        with self._lock:
            if self._scene is not None:
                self._scene.close()
                self._scene = None
                self._meshes.close()

    def __enter__(self) -> "Core":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: modules may be gone
            pass

    # ------------------------------------------------------------------ world parameters

    @property
    def world_parameters(self) -> WorldParameters:
        """The values in force (an immutable snapshot, safe to read from any thread)."""
        return self._parameters

    @property
    def _parameters(self) -> WorldParameters:
        scene = self._scene
        if scene is None:
            raise Closed("Core is closed (world_parameters)")
        return scene.parameters

    @locked
    def set_world_parameters(self, **changes) -> WorldParameters:
        """Checks every change, then applies them all; returns the values in force.
        At least one change; switching the collision policy forgets recorded collisions."""
        if not changes:
            raise InvalidArgument("no world parameter given (Set World: set at least one "
                                  "set_* flag)")
        scene = self._scene
        new = check.shared(scene.parameters.replace, **changes)
        if new.contact_less != scene.parameters.contact_less:
            readout.forget_collisions(scene)
        scene.c.apply(new)
        scene.parameters = new
        return new

    # ------------------------------------------------------------------ objects

    @changes_contents
    def build_object(self, spec: ObjectSpec) -> Built:
        """Creates one object (see ObjectSpec); returns its id and geometries as built."""
        return objects.build_object(self._scene, spec)

    @changes_contents
    def build_composite(self, spec: CompositeSpec) -> Built:
        """Creates a composite: its parts are geometries on one body placed at the centre of
        mass (part masses rotated, translated and added); its id is ">part1>part2..."."""
        return objects.build_composite(self._scene, spec)

    @changes_contents
    def build_entity(self, spec: EntitySpec) -> BuiltEntity:
        """Builds objects and composites as one entity, all or nothing (see EntitySpec)."""
        return objects.build_entity(self._scene, spec)

    @locked
    def entities(self) -> Dict[str, List[str]]:
        """Entity name -> ids of its objects still alive."""
        return objects.entity_members(self._scene)

    @changes_contents
    def remove_object(self, object_id: str) -> Removed:
        """Removes an object with its joints, motors and forces; returns every removed id."""
        return objects.remove_object(self._scene, object_id)

    @locked
    def object_ids(self) -> List[str]:
        return list(self._scene.objects)

    @locked
    def object_spec(self, object_id: str):
        """The ObjectSpec or CompositeSpec the object was built from."""
        return self._scene.object(object_id).spec

    @locked
    def geometry_names(self, object_id: str) -> List[str]:
        """Names of the object's geometries (one, or a composite's parts)."""
        return [g.name for g in self._scene.object(object_id).geometries]

    @disturbs
    def set_surface(self, name: str, surface) -> None:
        """The contact properties (odin_common.specs.Surface) of an object's geometries (an
        object ID) or of one part of a composite (its geometry name), from now on; how two
        surfaces mix in a contact: Messages/Surface."""
        objects.set_surface(self._scene, name, surface)

    @locked
    def collision_triangle_count(self, geometry_name: str) -> int:
        """Triangles ODE collides with for a mesh geometry (fewer than given when it was built
        under a collision_mesh_tolerance); 0 for a primitive."""
        geometry = self._scene.geometry(geometry_name)
        if geometry.shape.kind != "mesh":
            return 0
        return bodies.triangle_count(geometry.owner.ptr)

    @disturbs
    def set_poses(self, poses: Sequence[Tuple[str, Sequence[float], Sequence[float]]],
                  reset_velocity: bool = False) -> None:
        """Moves objects: (object id, position m world, orientation wxyz) each, all or
        nothing. reset_velocity zeroes the bodies' linear and angular velocities. Servos on
        joints of moved objects then hold the joints where they were put."""
        objects.set_poses(self._scene, poses, reset_velocity)
        motors.retarget_servos(self._scene, {object_id for object_id, *_ in poses})

    @disturbs
    def set_velocity(self, object_id: str = "", linear=None, angular=None,
                     motors: Sequence[str] = (), velocities: Sequence[float] = ()) -> None:
        """Set Velocity: an object's linear velocity of the centre of mass (m/s, world) and/or
        angular velocity (rad/s, world), None keeping the current one, and/or goal speeds of
        ``motors`` (rad/s or m/s; ``velocities`` one flat list, each motor taking as many
        values as it has axes, in order; a servo given a speed leaves servo mode). At least
        an object with one of its velocities, or motors; all checked before any is set."""
        actuation.set_velocity(self._scene, object_id, linear, angular, motors, velocities)

    # ------------------------------------------------------------------ joints and motors

    @changes_contents
    def add_joint(self, spec: JointSpec) -> str:
        """Creates a joint and sets its parameters, all or nothing (see JointSpec); returns
        its id. PLANE2D keeps body1 in the plane z = 0 (body2 must be ""); FIXED keeps the
        bodies' present relative pose; one joint per pair of bodies."""
        return joints.create_joint(self._scene, spec)

    @locked
    def joint_ids(self) -> List[str]:
        return list(self._scene.joints)

    @disturbs
    def set_joint_parameters(self, joint_id: str,
                             parameters: Sequence[Tuple[int, int, float]]) -> None:
        """(parameter, axis 1..3, value) triples on a joint or a motor, all or nothing (see
        joints.set_joint_parameters for the ranges); at least one."""
        if len(parameters) == 0:
            raise InvalidArgument(f"no parameter to set on {shown(joint_id)}")
        joints.set_joint_parameters(self._scene, joint_id, parameters)

    @changes_contents
    def remove_joint(self, joint_id: str) -> Removed:
        """Removes a joint with its motors and joint forces."""
        return joints.remove_joint(self._scene, joint_id)

    @locked
    def joint_states(self) -> List[JointState]:
        """Positions and rates of every joint, per axis (see JointState)."""
        return joints.joint_states(self._scene)

    @changes_contents
    def add_motor(self, spec: MotorSpec) -> str:
        """Creates a motor (see MotorSpec) at zero goal speed; returns its id."""
        return motors.create_motor(self._scene, spec)

    @locked
    def motor_ids(self) -> List[str]:
        return list(self._scene.motors)

    @locked
    def motor_axis_counts(self, motor_ids: Sequence[str]) -> List[int]:
        """Number of axes of each motor (how many goal speeds it takes); unknown ids raise."""
        return motors.axis_counts(self._scene, motor_ids)

    @locked
    def split_per_axis(self, motor_ids: Sequence[str], values: Sequence[float]
                       ) -> Dict[str, Tuple[float, ...]]:
        """{motor id: its goal speeds} from one flat list (Propagate's request: each motor
        takes as many values as it has axes, in order)."""
        if len(motor_ids) == 0 and len(values) == 0:
            return {}
        return motors.split_per_axis(self._scene, motor_ids, values)

    @disturbs
    def set_servo(self, motors: Sequence[str], targets: Sequence[float],
                  rates: Sequence[float] = (), gains: Sequence[float] = (),
                  max_speeds: Sequence[float] = (), max_forces: Sequence[float] = (),
                  drive: int = ServoDrive.UNCHANGED) -> None:
        """Set Servo: servo mode for ``motors``, each tracking a position target on its
        joint's axes. The lists are flat, one value per motor axis in the motors' order:
        ``targets`` (rad or m); optional, empty meaning not given: ``rates`` (feed-forward,
        rad/s or m/s; 0), ``gains`` (1/s; defaults.SERVO_GAIN), ``max_speeds`` (rad/s or
        m/s; defaults.SERVO_MAX_SPEED), ``max_forces`` (N m or N; the motor's as it is).
        ``drive`` (ServoDrive) for their joints (core.kinematic: KINEMATIC, the links follow
        the servos' law exactly). All checked before anything changes."""
        actuation.set_servo(self._scene, motors, {
            "targets": targets, "rates": rates, "gains": gains, "max_speeds": max_speeds,
            "max_forces": max_forces}, drive)

    @disturbs
    def release_servos(self, motor_ids: Sequence[str],
                       drive: int = ServoDrive.UNCHANGED) -> None:
        """Motors back from servo mode to speed goals, at zero; ``drive`` as set_servo's."""
        actuation.release_servos(self._scene, motor_ids, drive)

    @disturbs
    def set_drive(self, motor_ids: Sequence[str], drive: int) -> None:
        """The drive (ServoDrive) of the motors' joints alone, all or nothing: KINEMATIC, the
        links beyond them follow the motors' commanded speeds exactly (core.kinematic)."""
        actuation.set_drive(self._scene, motor_ids, drive)

    @locked
    def kinematic_links(self) -> Dict[str, str]:
        """{motor id: the object it drives kinematically}, parents first."""
        return dict(self._scene.kinematic)

    @locked
    def servo_states(self) -> List[ServoState]:
        """Every servo's targets, its joint's values when the last step began, and errors."""
        return motors.servo_states(self._scene)

    @locked
    def motor_goals(self) -> Dict[str, List[float]]:
        """Every motor's goal speeds per axis (rad/s or m/s)."""
        return {motor_id: list(m.velocity) for motor_id, m in self._scene.motors.items()}

    @changes_contents
    def remove_motor(self, motor_id: str) -> None:
        motors.remove_motor(self._scene, motor_id)

    # ------------------------------------------------------------------ forces

    @disturbs
    def add_body_force(self, object_id: str, kind: int, vector,
                       vector_in_body_frame: bool = False, at_point: bool = False,
                       point=(0.0, 0.0, 0.0), point_in_body_frame: bool = False) -> str:
        """A persistent force (N) or torque (N m) on an object's body, re-applied before every
        step until removed: the vector in the world or the object's frame; a force acts at
        the centre of mass or at ``point`` (m, world or object frame). Returns
        "force:<object>:<n>" or "torque:<object>:<n>"."""
        return forces.add_body_force(self._scene, object_id, kind, vector,
                                     vector_in_body_frame, at_point, point, point_in_body_frame)

    @disturbs
    def remove_body_force(self, force_id: str) -> None:
        forces.remove_body_force(self._scene, force_id)

    @locked
    def body_force_ids(self) -> List[str]:
        return list(self._scene.body_forces)

    @disturbs
    def add_joint_force(self, joint_id: str, magnitudes: Sequence[float]) -> str:
        """A persistent force/torque along a joint's axes, applied before every step until
        removed (odin_common.interface.JOINT_FORCE_MAGNITUDES). Returns
        "jointforce:<joint>:<n>"."""
        return forces.add_joint_force(self._scene, joint_id, magnitudes)

    @disturbs
    def remove_joint_force(self, force_id: str) -> None:
        forces.remove_joint_force(self._scene, force_id)

    @locked
    def joint_force_ids(self) -> List[str]:
        return list(self._scene.joint_forces)

    # ------------------------------------------------------------------ snapshots

    @locked
    def save_state(self, name: str) -> None:
        """Keeps the whole dynamic state under ``name`` (replacing a snapshot of that name):
        poses, velocities, joint and motor parameters, motor goals, persistent forces,
        simulated time (core.snapshots), which bodies sleep. New Scene forgets every snapshot.
        Under auto_disable it also starts every body's rest count again, as putting the state
        back does (ODE's count is out of reach), so that both step on alike."""
        name = check.name("snapshot name", name, allow_marker=True)
        held, limit = self._scene.snapshots, self.resources.max_snapshots
        if name not in held and len(held) >= limit:
            raise InvalidArgument(f"snapshot {shown(name)}: the world holds {len(held)} snapshots, "
                                  f"the limit (max_snapshots); remove one first")
        snapshot = snapshots.take(self._scene)
        snapshots.check_room(held, name, snapshot)
        if self._scene.parameters.auto_disable:    # (no snapshot holds ODE's rest counts)
            self._scene.c.restart_rest_counts()
        held[name] = snapshot

    @changes_state
    def restore_state(self, name: str) -> None:
        """Puts back the state saved under ``name``: stepping on from it gives bit-identical
        results to stepping on from when it was saved. Refused when the scene's objects,
        joints or motors are no longer those it was saved with."""
        snapshot = snapshots.named(self._scene, name)
        snapshots.check_fits(self._scene, snapshot, f"snapshot {shown(name)}")
        snapshots.put_back(self._scene, snapshot)

    @locked
    def snapshot_names(self) -> List[str]:
        return list(self._scene.snapshots)

    @locked
    def remove_state(self, name: str) -> None:
        snapshots.named(self._scene, name)
        del self._scene.snapshots[name]

    @locked
    def body_state_vector(self) -> np.ndarray:
        """The bodies' dynamic state as one flat float64 vector, for planners that keep
        states themselves (OMPL): ODE's random generator state (QuickStep's constraint order),
        then per body with a body (object order) its raw record (position, quaternion wxyz,
        rotation matrix, linear and angular velocity, enabled: ``BODY_STATE_SIZE`` values,
        m, m/s, rad/s, world frame; odin_common.interface.BODY_STATE_FIELDS), then one value
        per exempt pair (``exempt_overlaps``: 1.0 exempt, 0.0 parted; none without them).
        ``set_body_state_vector`` puts it back bit for bit. Motors, servos and persistent
        forces are not in it: they stay as they are."""
        return propagation.state_vector(self._scene)

    @changes_state
    def set_body_state_vector(self, vector: Sequence[float]) -> None:
        """Puts back a vector read by ``body_state_vector`` (the same objects), bit for bit:
        stepping on from it gives the results stepping on from when it was read gave. Under
        auto_disable the bodies' rest counts start again here (ODE's count is in no vector),
        so a body about to fall asleep may sleep some steps later than it did."""
        scene = self._scene
        propagation.put_state_vector(scene, propagation.checked_state_vector(scene, vector))

    @locked
    def checked_state_vector(self, vector: Sequence[float]) -> np.ndarray:
        """``vector`` as contiguous float64 when it is a body state vector of this world (its
        size, finite values, a 32-bit generator state); InvalidArgument otherwise."""
        return propagation.checked_state_vector(self._scene, vector)

    @locked
    def reset(self) -> None:
        """Back to the state right after the last build or removal (of an object, joint or
        motor): the poses, velocities, parameters, goals, forces and simulated time the world
        had then."""
        scene = self._scene
        if scene.contents_changed or scene.reset_point is None:
            return   # nothing has changed the state since the last build
        snapshots.put_back(scene, scene.reset_point)

    @changes_state
    def propagate(self, duration: float, step_size: float,
                  motor_goals: Optional[Mapping[str, Sequence[float]]] = None,
                  body_forces: Sequence[Mapping] = (), start: str = "",
                  keep: bool = False,
                  start_state: Optional[Sequence[float]] = None,
                  read_states: bool = True,
                  cancelled: Optional[long_calls.Cancel] = None) -> Propagation:
        """Runs the world for ``duration`` s in steps of ``step_size`` s, as fast as it goes:
        from the snapshot ``start``, or from the body state vector ``start_state``
        (``body_state_vector``'s; the rest of the state as it is now), or from now; under
        ``motor_goals`` ({motor id: goal speeds}) and ``body_forces`` (each the keyword arguments of
        add_body_force), recording every pair that collides on the way. Then the world goes back to
        the state it had before the call, unless ``keep``; the forces act during the propagation
        only. ``read_states`` False leaves the answer's ``states`` empty (a planner reads the state
        vector alone). Everything is checked before anything changes. ``cancelled``
        (core.long_calls): asked between pieces of the run; when it says the caller has gone
        the world goes back to the state before the call, as after a refusal, kept or not,
        and long_calls.Cancelled is raised."""
        return propagation.propagate(self._scene, duration, step_size, motor_goals, body_forces,
                                     start, keep, start_state, read_states, cancelled)

    @changes_state
    def propagate_state(self, start_state: Sequence[float], duration: float, step_size: float,
                        forces: Sequence[Tuple[str, Sequence[float]]] = ()) -> StatePropagation:
        """A planner's propagation, all in one C call: from the body state vector
        ``start_state`` (``body_state_vector``'s), ``duration`` s in steps of ``step_size``
        s under ``forces`` ((object id, force N, world frame, at the centre of mass) each, for
        this call only), recording the pairs that collide on the way; the world stays in the
        state reached. The states and pairs are bit for bit those of ``propagate`` from
        ``start_state`` with these forces as body forces and ``keep`` (tests/ compare them);
        its answer holds only what a planner reads. Everything is checked first."""
        return propagation.propagate_state(self._scene, start_state, duration, step_size,
                                           forces)

    @changes_state
    def propagate_row(self, start_state: Sequence[float], count: int, duration: float,
                      step_size: float, forces: Sequence[Tuple[str, Sequence[float]]] = (),
                      keep: bool = False) -> List[StatePropagation]:
        """A planner's control held over ``count`` propagations, in one call: each
        ``propagate_state`` of ``duration`` s from the state the one before reached (bit for
        bit those calls one by one: the first from ``start_state``), under ``forces`` in each;
        every one's answer, in order. The world goes back to the state before the call unless
        ``keep``. Everything is checked first."""
        return propagation.propagate_row(self._scene, start_state, count, duration, step_size,
                                         forces, keep)

    @locked
    def plan_rule(self, roles: Mapping[str, int], forbidden: Sequence[Tuple[int, int]],
                  tracked_body: str, tracked_offset: Sequence[float],
                  bounds: Sequence[Sequence[float]], max_speed: float) -> PlanRule:
        """A control planner's validity rule, held in C for ``propagate_checked`` while
        the world keeps its objects: ``roles`` {object id: role 1..15} (others: role 0),
        ``forbidden`` the pairs of roles (either order) that may not collide; the tracked
        link on ``tracked_body``'s body at ``tracked_offset`` (3,) m in its frame, whose origin
        must stay within ``bounds`` ((3, 2) m, world, low and high per axis) and the body's
        linear velocity within ``max_speed`` m/s per axis. Everything is checked first."""
        return checked_propagation.plan_rule(self._scene, roles, forbidden, tracked_body,
                                             tracked_offset, bounds, max_speed)

    @changes_state
    def propagate_checked(self, rule: PlanRule, start_state: Sequence[float], duration: float,
                          step_size: float, forces: Sequence[Tuple[str, Sequence[float]]] = (),
                          count: int = 1, states: Optional[np.ndarray] = None,
                          tracked: Optional[np.ndarray] = None,
                          stop_at_invalid: bool = True) -> CheckedRow:
        """``count`` planner's propagations in a row, in one C call, each judged by
        ``rule`` (``plan_rule``): each ``propagate_state`` of ``duration`` s from the state
        the one before reached (bit for bit: the first from ``start_state``), under
        ``forces``; invalid when a pair of roles the rule forbids collided on the way or the
        tracked link ended out of its bounds; with ``stop_at_invalid`` the row ends after the
        first invalid one. Row i of ``states`` ((count, state size + 1) float64, given or
        made) gets the i-th state reached and then 1.0 (invalid) or 0.0, row i of ``tracked``
        ((count, 6)) the tracked link's origin (m) and body velocity (m/s), world frame: arrays
        may be a planner's own memory. The world stays in the state reached. Everything is
        checked first."""
        return checked_propagation.propagate_checked(self._scene, rule, start_state, count,
                                                     duration, step_size, forces, states,
                                                     tracked, stop_at_invalid)

    @changes_contents
    def exempt_overlaps(self, min_depth: float) -> List[Collision]:
        """The pairs inside each other now deeper than ``min_depth`` m, where a part has a
        body, do not collide until they have parted (no deeper than ``min_depth``, or apart,
        at a step's collide pass); they replace the exempt pairs before (core.exemptions).
        What a loader asks after building a problem that places parts inside each other.
        Returns the pairs exempted (names, depth, points)."""
        min_depth = check.number("min_depth", min_depth)
        if min_depth < 0:
            raise InvalidArgument(f"min_depth={shown(min_depth)} m must not be negative")
        return exemptions.exempt(self._scene, min_depth)

    @locked
    def check_collision(self, poses: Sequence[Tuple[str, Sequence[float], Sequence[float]]]
                        ) -> List[Collision]:
        """The pairs that collide with the objects at ``poses`` ((object id, position m,
        orientation wxyz) each; the others where they are), without stepping and whatever the
        collision policy: names, deepest depth and points. The world is left as it was."""
        scene = self._scene
        moved = list(dict.fromkeys(obj for obj, _, _ in objects.check_poses(scene, poses)))
        bodies_moved = [o for o in moved if o.body is not None]
        statics = [g for o in moved if o.body is None for g in o.geometries]
        saved_bodies = bodies.read_states([o.body.ptr for o in bodies_moved])
        saved_statics = [bodies.static_geom_pose(g.owner.ptr) for g in statics]
        try:
            objects.set_poses(scene, poses)
            found = readout.touching_now(scene)
        finally:
            bodies.write_states([o.body.ptr for o in bodies_moved], saved_bodies)
            for g, pose in zip(statics, saved_statics):
                bodies.set_static_geom_pose(g.owner.ptr, pose)
        return found

    @locked
    def collision_probe(self, moved: Sequence[str], apart: Sequence[str] = (),
                        tiers: Sequence[float] = (0.1,)) -> probe.CollisionProbe:
        """A geometric planner's probe (virtual_world.core.probe) of the objects ``moved``
        (each with a body), whose ``clearances`` do not ask against the objects ``apart``
        and find the largest clear growth among ``tiers`` (m, descending)."""
        return probe.CollisionProbe(self._scene, moved, apart, tiers)

    @locked
    def pairs_that_may_touch(self, object_ids: Sequence[str]) -> List[Tuple[str, str]]:
        """The pairs of the objects ``object_ids`` a step may collide (not of one body, one
        entity without internal collisions, or bodies a joint joins), whatever their poses."""
        return probe.pairs_that_may_touch(self._scene, object_ids)

    @changes_state
    def probe_touching(self, collision_probe: probe.CollisionProbe, poses
                       ) -> Optional[Tuple[str, str]]:
        """The probe's objects put at ``poses`` ((n, 4, 4) object frames, m, world; they stay
        there): the first pair of geometry names touching one of them, or None."""
        return collision_probe.touching(self._scene, poses)

    @locked
    def probe_clearances(self, collision_probe: probe.CollisionProbe, bounds, needed=None
                         ) -> np.ndarray:
        """Lower bounds (m) of the distances of capsules and boxes to the world but the
        probe's ``apart`` objects, up to ``needed`` (CollisionProbe.clearances)."""
        return collision_probe.clearances(self._scene, bounds, needed)

    @locked
    def motion_checker(self, robots: Sequence[motion.RobotKinematics], size: int,
                       tiers: Sequence[float], sweep_gap: float, resolution: float
                       ) -> motion.MotionChecker:
        """A geometric planner's motion checker (virtual_world.core.motion) of ``robots``
        over ``size`` controls: clearances among ``tiers`` (m, descending), a translating
        link's sweep free when it can grow by ``sweep_gap`` (m), no link moving more than
        ``resolution`` (m) between configurations checked exactly."""
        return motion.MotionChecker(self._scene, robots, size, tiers, sweep_gap, resolution)

    @changes_state
    def motion_valid(self, checker: motion.MotionChecker, a, b,
                     deadline: Optional[float] = None) -> Tuple[bool, int, int]:
        """(whether the straight segment of the control space from ``a`` (valid) to ``b``
        is collision-free; configurations checked exactly; clearance queries), False once
        time.monotonic() passes ``deadline``. The moved links stay where the check last put
        them."""
        return checker.motion_valid(self._scene, a, b, deadline)

    @changes_state
    def configuration_valid(self, checker: motion.MotionChecker, controls) -> bool:
        """Whether no link a control moves touches anything at the control vector's
        configuration (MotionChecker.valid; the links stay there)."""
        return checker.valid(self._scene, controls)

    # ------------------------------------------------------------------ step and read-out

    @changes_state
    def step(self, step_size: float, count: int = 1) -> None:
        """Runs ``count`` steps of ``step_size`` s, all in one C call: collide (contacts or
        recording), body forces, joint forces and motor goals, (Quick)Step, empty contacts."""
        step_size = check.step_size(step_size)
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
            raise InvalidArgument(f"count={shown(count)} must be a positive integer")
        count = check.step_count(count, f"count={shown(count)}")
        scene = self._scene
        if not scene.parameters.contact_less:
            scene.carried = {}
        taken = scene.c.step(step_size, int(count))
        scene.sim_time += step_size * taken
        guard.collect(scene, step_size)

    @property
    def body_count(self) -> int:
        """Bodies that step (objects with a body): what a step's work grows with."""
        with self._lock:
            scene = self._scene
            return 0 if scene is None else scene.body_array().count

    @locked
    def take_divergences(self) -> List[Divergence]:
        """The bodies the divergence guard parked since the last call (each reported once)."""
        found, self._scene.divergences = self._scene.divergences, []
        return found

    @locked
    def parked_objects(self) -> List[str]:
        """The objects the divergence guard parked (kinematic, still, colliding with nothing)."""
        return list(self._scene.parked)

    @locked
    def sleeping_objects(self) -> List[str]:
        """The objects ODE's auto-disabling has put to sleep (world parameter auto_disable):
        not stepped until an awake body touches them or a request changes the world."""
        scene = self._scene
        return [object_id for object_id in guard.guarded(scene)
                if not bodies.is_awake(scene.objects[object_id].body.ptr)]

    @locked
    def detect_collisions(self) -> None:
        """Contact-less policy: collision detection on the present poses without a step, so
        that read_collisions() reports what touches now in a paused world whose objects were
        moved (Set Position). Does nothing under the contact policy."""
        self._scene.c.detect()

    @property
    def sim_time(self) -> float:
        """Simulated seconds since the scene began."""
        return self._scene.sim_time

    @property
    def last_step_contacts(self) -> int:
        """Contact joints created in the last step."""
        return self._scene.c.last_step_contacts

    @property
    def last_step_solver(self) -> Solver:
        """The solver the last step used: QUICKSTEP or WORLDSTEP (the auto solver's choice)."""
        return Solver(self._scene.c.last_solver)

    @property
    def last_step_island_rows(self) -> Tuple[int, int]:
        """What the auto solver measured before the last step: the largest island's
        constraint rows and the most rows of non-contact joints (motors and limits included)
        in one island; 0, 0 under an explicit solver, when the small-system clause held and when
        no awake body has a joint other than a contact (the islands are not searched)."""
        return self._scene.c.last_island_rows

    @locked
    def poses(self) -> Tuple[List[str], np.ndarray, np.ndarray]:
        """Every geometry (composite parts one by one, static ones too): names, positions
        (n, 3) m and quaternions (n, 4) wxyz, world frame; read in one C call."""
        return readout.poses(self._scene)

    @locked
    def body_state(self, object_id: str) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(position of the object origin m, orientation wxyz, linear velocity of the centre of
        mass m/s, angular velocity rad/s), world frame."""
        return readout.body_state(self._scene, object_id)

    @locked
    def mass_properties(self, object_id: str) -> Tuple[float, np.ndarray, np.ndarray]:
        """(mass kg, centre of mass (3,) m in the object frame, inertia (3,3) kg m^2 about the
        centre of mass, object axes) as ODE holds them."""
        return readout.mass_properties(self._scene, object_id)

    @locked
    def state(self, objects: Sequence[str] = (), joints: Sequence[str] = (),
              motors: Sequence[str] = ()) -> Tuple[List[ObjectState], List[JointReaction],
                                                   List[MotorState]]:
        """Get State: for the objects, joints and motors named (each list empty: all of them),
        their states: poses, velocities, mass and inertia; joint positions, rates and the
        force and torque each joint applied to its bodies in the last step; motor goals and
        maximum forces. Unknown names raise before anything is read, and a list longer than
        what the world holds before any name is (the answer may not outgrow the world)."""
        scene = self._scene
        for what, names, held in (("objects", objects, len(scene.objects)),
                                  ("joints", joints, len(scene.joints)),
                                  ("motors", motors, len(scene.motors))):
            if len(names) > held:
                raise InvalidArgument(f"{len(names):,} {what} asked for; the world holds "
                                      f"{held:,} (each at most once)")
        for object_id in objects:
            scene.body_object(object_id, "state")
        for joint_id in joints:
            scene.joint(joint_id)
        for motor_id in motors:
            scene.motor(motor_id)
        return (readout.object_states(scene, objects), readout.joint_reactions(scene, joints),
                readout.motor_states(scene, motors))

    @locked
    def read_collisions(self) -> List[Collision]:
        """Colliding geometry pairs (names sorted within a pair), deepest depth and points.
        Contact-less policy: every pair seen since the last read; reading clears the set.
        Contact policy: the pairs that had contacts in the last step."""
        return readout.read_collisions(self._scene)


__all__ = ["Core"]
