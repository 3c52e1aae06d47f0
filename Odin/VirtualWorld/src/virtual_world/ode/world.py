"""One ODE world as odin_step.c runs it: the world, its space (sweep and prune) and contact
group, the contact settings, and the arrays of persistent actions the C step loop applies.

``CWorld`` owns an ``OdinWorld`` struct (memory Python's, allocated with ffi.new) and the three
scene handles; the arrays of body forces, joint forces, motor goals and kinematic links are
rebuilt from plain tuples whenever they change, and always before a handle they point at is
freed (C must never see a freed handle). Collision records come back as geom addresses,
which the Core names.
"""
from __future__ import annotations

from typing import List, Sequence, Tuple

import numpy as np

from odin_common.defaults import (AUTO_SOLVER_ARTICULATION_ROWS, AUTO_SOLVER_MAX_ISLAND_ROWS,
                                  AUTO_SOLVER_MAX_ROWS)
from odin_common.interface import DivergencePolicy
from odin_common.world_parameters import WorldParameters
from virtual_world.ode import handles
from virtual_world.ode.bindings import ffi, lib
from virtual_world.ode.runtime import drains_ode_messages

BodyForce = Tuple  # (body ptr, torque, vector_in_body, at_point, point_in_body, vector, point)
JointForce = Tuple  # (joint ptr, ODE joint type, magnitudes)
MotorGoal = Tuple  # (motor ptr, MotorKind, velocities)
KinematicLink = Tuple  # (body ptr, parent body ptr or None, parent's index or -1, motor slot,
#                         joint ptr, ODE joint type)
Divergence = Tuple  # (body address, reason, value, position, velocity, angular, step)
Record = Tuple  # (geom address 1, geom address 2, depth m, points ((x, y, z), ...) m,
#                  the step count when first seen, normals (unit, pushing geom 1), forces on
#                  geom 1 (N, world; () when not measured))


class CWorld:
    """The C side of one scene; ``close()`` frees every handle in it (idempotent)."""

    def __init__(self, parameters: WorldParameters):
        self.world = handles.new_world()
        self.space = handles.new_space()
        self.contacts = handles.new_joint_group(self.world)
        self.struct = ffi.new("OdinWorld *")
        s = self.struct
        s.world, s.space, s.contact_group = self.world.ptr, self.space.ptr, self.contacts.ptr
        self._arrays = {}          # keeps the action arrays alive while C points at them
        # odin_world_propagate's buffers, kept from call to call (a planner propagates
        # thousands of times a second): its forces, the pairs it hands back and their count
        self._pushes = ffi.new("OdinBodyForce[]", 4)
        self._pairs = ffi.new("uintptr_t[]", 2 * _PAIRS_KEPT)
        self._pair_count = ffi.new("int *")
        self.apply(parameters)

    @drains_ode_messages
    def apply(self, p: WorldParameters) -> None:
        """The world parameters in ODE's world and the contact settings."""
        world, inf = self.world.ptr, lib.dInfinity
        lib.dWorldSetGravity(world, *p.gravity)
        lib.dWorldSetERP(world, p.erp)
        lib.dWorldSetCFM(world, p.cfm)
        lib.dWorldSetMaxAngularSpeed(world, p.max_angular_speed or inf)
        lib.dWorldSetContactMaxCorrectingVel(world, p.contact_max_correcting_velocity or inf)
        lib.dWorldSetContactSurfaceLayer(world, p.contact_surface_layer)
        lib.dWorldSetLinearDamping(world, p.linear_damping)
        lib.dWorldSetLinearDampingThreshold(world, p.linear_damping_threshold)
        lib.dWorldSetAngularDamping(world, p.angular_damping)
        lib.dWorldSetAngularDampingThreshold(world, p.angular_damping_threshold)
        lib.dWorldSetQuickStepNumIterations(world, p.quickstep_iterations)
        s = self.struct
        s.max_contacts = p.max_contacts
        s.mu = inf if p.friction < 0 else p.friction
        s.bounce = p.bounce
        s.bounce_vel = p.bounce_velocity
        s.contact_less = int(p.contact_less)
        s.solver = int(p.solver)
        s.auto_step_rows = AUTO_SOLVER_MAX_ROWS
        s.auto_rows = AUTO_SOLVER_MAX_ISLAND_ROWS
        s.auto_articulation_rows = AUTO_SOLVER_ARTICULATION_ROWS
        s.max_speed = p.divergence_speed
        s.max_spin = p.divergence_angular_speed
        s.extent = p.world_extent
        s.stop_on_divergence = int(p.divergence_policy == DivergencePolicy.PARK_AND_PAUSE)
        s.auto_disable = int(p.auto_disable)
        lib.odin_world_sync_auto_disable(s)
        # every body meets new parameters awake (gravity turned, a surface changed), and with
        # auto-disabling off nothing else would ever wake a sleeper
        lib.odin_world_wake(s)

    @property
    def max_contacts(self) -> int:
        return int(self.struct.max_contacts)

    @property
    def rand_seed(self) -> int:
        """The world's state of ODE's random generator (QuickStep's constraint order)."""
        return int(self.struct.rand_seed)

    @rand_seed.setter
    def rand_seed(self, value: int) -> None:
        self.struct.rand_seed = value

    @property
    def last_solver(self) -> int:
        """The solver the last step used: 0 QuickStep, 1 dWorldStep."""
        return int(self.struct.last_solver)

    @property
    def last_island_rows(self) -> tuple:
        """The auto solver's measure of the last step (0, 0 under an explicit solver, when the
        small-system clause held or with nothing articulated): the largest island's constraint rows
        and the most rows of non-contact joints in one island (odin_step.c measure_islands)."""
        return int(self.struct.island_rows), int(self.struct.articulated_rows)

    @drains_ode_messages
    def wake(self) -> None:
        """Wakes every dynamic body (a request changed the world: see odin_world_wake)."""
        lib.odin_world_wake(self.struct)

    @drains_ode_messages
    def restart_rest_counts(self) -> None:
        """Every dynamic body's rest count starts again, sleepers stay asleep (a Save State
        under auto_disable: see odin_world_restart_rest_counts)."""
        lib.odin_world_restart_rest_counts(self.struct)

    @property
    def sleeping(self) -> int:
        """Dynamic bodies that ODE's auto-disabling has put to sleep."""
        return int(lib.odin_world_sleeping(self.struct))

    @property
    def step_count(self) -> int:
        """Steps taken since the scene began."""
        return int(self.struct.step_count)

    @step_count.setter
    def step_count(self, value: int) -> None:
        self.struct.step_count = value

    @property
    def record_every_step(self) -> bool:
        return bool(self.struct.record_every_step)

    @record_every_step.setter
    def record_every_step(self, value: bool) -> None:
        self.struct.record_every_step = int(value)

    # -- persistent actions ------------------------------------------------------------------
    def set_body_forces(self, forces: Sequence[BodyForce]) -> None:
        array = ffi.new("OdinBodyForce[]", max(len(forces), 1))
        for f, (body, torque, v_body, at_point, p_body, vector, point) in zip(array, forces):
            f.body = body
            f.torque, f.vector_in_body, f.at_point, f.point_in_body = (
                int(torque), int(v_body), int(at_point), int(p_body))
            f.vector = list(vector)
            f.point = list(point)
        self._install("forces", array, len(forces))

    def set_joint_forces(self, forces: Sequence[JointForce]) -> None:
        array = ffi.new("OdinJointForce[]", max(len(forces), 1))
        for f, (joint, ode_type, magnitudes) in zip(array, forces):
            f.joint = joint
            f.type = ode_type
            for k, value in enumerate(magnitudes):
                f.magnitude[k] = value
        self._install("joint_forces", array, len(forces))

    def set_motor_goals(self, goals: Sequence[MotorGoal]) -> None:
        """Every motor's goal speeds, in slots 0..n-1 (update_motor_goal(slot, ...) later)."""
        array = ffi.new("OdinMotorGoal[]", max(len(goals), 1))
        for g, (motor, kind, velocities) in zip(array, goals):
            g.motor = motor
            g.kind = int(kind)
            g.naxes = len(velocities)
            for k, value in enumerate(velocities):
                g.velocity[k] = value
        self._install("motors", array, len(goals))

    def set_kinematic_links(self, links: Sequence[KinematicLink]) -> None:
        """The kinematic drive's links, parents first (odin_step.h OdinKinematicLink); each
        link's direction is read from the joint (+1 when the link is its ODE body 1)."""
        if not links and not self.struct.n_kinematic:
            return      # none before, none now: every propagation of a planner comes here
        array = ffi.new("OdinKinematicLink[]", max(len(links), 1))
        for k, (body, parent, parent_link, slot, joint, joint_type) in zip(array, links):
            k.body, k.parent = body, parent if parent is not None else ffi.NULL
            k.parent_link, k.motor, k.joint, k.joint_type = parent_link, slot, joint, joint_type
            k.direction = 1.0 if lib.dJointGetBody(joint, 0) == body else -1.0
        self._install("kinematic", array, len(links))

    @drains_ode_messages
    def set_guarded(self, bodies: Sequence) -> None:
        """The bodies the divergence guard checks after every step (the dynamic ones)."""
        array = ffi.new("dBodyID[]", max(2 * len(bodies), 16))
        array[0:len(bodies)] = list(bodies)
        self._install("guarded", array, len(bodies))
        lib.odin_world_sync_auto_disable(self.struct)   # an unparked body kept its old flag

    def add_guarded(self, body) -> None:
        """One more body for the guard, at the end of the list: amortised O(1) (the array
        doubles when full), so building n bodies costs O(n), not O(n^2)."""
        s, array = self.struct, self._arrays.get("guarded")
        count = int(s.n_guarded)
        if array is None or count >= len(array):
            self.set_guarded([s.guarded[i] for i in range(count)] + [body])
            return
        array[count] = body
        s.n_guarded = count + 1

    def divergences(self) -> List[Divergence]:
        """The bodies the guard parked since the last call (body address, reason, value,
        position, velocity, angular velocity, step count), forgotten once read."""
        s = self.struct
        if not s.n_diverged:
            return []
        out = [(int(ffi.cast("uintptr_t", d.body)), int(d.reason), float(d.value),
                tuple(d.position), tuple(d.velocity), tuple(d.angular), int(d.step))
               for d in (s.diverged[i] for i in range(s.n_diverged))]
        lib.odin_world_clear_divergences(s)
        return out

    def update_motor_goal(self, slot: int, velocities: Sequence[float]) -> None:
        goal = self._arrays["motors"][slot]
        for k, value in enumerate(velocities):
            goal.velocity[k] = value

    def update_servo(self, slot: int, servo) -> None:
        """Puts a motor in servo mode (``servo``: joint ptr, ODE joint type, components,
        signs, targets, rates, gains, max speeds, in the joint's reported units), or back to
        its velocity goals (None)."""
        goal = self._arrays["motors"][slot]
        if servo is None:
            goal.servo = 0
            return
        joint, joint_type, components, signs, targets, rates, gains, speeds = servo
        goal.joint, goal.joint_type = joint, joint_type
        for k, (c, sign) in enumerate(zip(components, signs)):
            goal.component[k] = c
            goal.sign[k] = sign
            goal.target[k] = sign * targets[k]
            goal.target_rate[k] = rates[k]
            goal.gain[k] = gains[k]
            goal.max_speed[k] = speeds[k]
        goal.read = 0           # its first step reads the turn nearest the target (odin_step.h)
        goal.servo = 1

    def servo_positions(self, slot: int, signs: Sequence[float]) -> Tuple[float, ...]:
        """The joint values a servo read when the last step began, in reported units."""
        goal = self._arrays["motors"][slot]
        return tuple(sign * goal.position[k] for k, sign in enumerate(signs))

    # -- exempt pairs -------------------------------------------------------------------------
    def set_exemptions(self, keys: Sequence[int], limits: Sequence[float],
                       live: Sequence[float], depth: float) -> None:
        """The pairs that do not collide until they have parted (odin_step.h: OdinWorld's
        exempt_keys): their keys (serial << 32 | serial, ascending), the depth (m) each may
        reach, each one's state (1.0 exempt, 0.0 parted) and the depth (m) at most which a
        pair has parted."""
        keys = np.array(keys, dtype=np.uint64)
        limits = np.array(limits, dtype=np.float64)
        live = np.array(live, dtype=np.float64)
        seen = np.zeros(max(len(keys), 1), dtype=np.uint8)
        s, some = self.struct, len(keys) > 0
        s.exempt_keys = ffi.from_buffer("uint64_t[]", keys) if some else ffi.NULL
        s.exempt_limit = ffi.from_buffer("double[]", limits) if some else ffi.NULL
        s.exempt_live = ffi.from_buffer("double[]", live) if some else ffi.NULL
        s.exempt_seen = ffi.from_buffer("unsigned char[]", seen)
        s.exempt_depth = depth
        s.n_exempt = len(keys)
        self._arrays["exempt"] = (keys, limits, live, seen)

    @property
    def exempt_live(self) -> np.ndarray:
        """Each exempt pair's state now (1.0 exempt, 0.0 parted), a copy."""
        arrays = self._arrays.get("exempt")
        return arrays[2].copy() if arrays else np.empty(0)

    @exempt_live.setter
    def exempt_live(self, values: np.ndarray) -> None:
        arrays = self._arrays.get("exempt")
        if arrays:
            arrays[2][:] = values

    def _install(self, field: str, array, count: int) -> None:
        setattr(self.struct, field, array)
        setattr(self.struct, "n_" + field, count)
        self._arrays[field] = array

    # -- stepping and read-out ---------------------------------------------------------------
    @drains_ode_messages
    def step(self, step_size: float, count: int) -> int:
        """``count`` steps in one C call (odin_step.c: collide, actions, step, empty, guard);
        returns the steps taken (fewer when the guard parked a body under the pausing
        policy)."""
        return int(lib.odin_world_step(self.struct, step_size, count))

    @drains_ode_messages
    def propagate(self, bodies: "BodyArray", start: np.ndarray,
                  forces: Sequence[Tuple[object, Sequence[float]]], step_size: float,
                  count: int) -> Tuple[np.ndarray, int, bytes]:
        """One planner's propagation in one C call (odin_step.h, odin_world_propagate): from
        the body state vector ``start`` (float64, contiguous, ``bodies``' layout) under
        ``forces`` ((body ptr, force N world, at the centre of mass) each, this call only),
        ``count`` steps recording every step's pairs. Returns (the state vector reached, the
        steps taken or -1 - i when value i of ``start`` cannot be put back, the recorded
        pairs' geom addresses as raw uintptr_t pairs); the world stays in the state reached,
        its collision records forgotten."""
        pushes = self._filled_pushes(forces)
        out = np.empty(start.size)
        taken = lib.odin_world_propagate(
            self.struct, bodies.array, bodies.count, ffi.from_buffer("double[]", start),
            pushes, len(forces), step_size, count, ffi.from_buffer("double[]", out),
            self._pairs, _PAIRS_KEPT, self._pair_count)
        count = self._pair_count[0]
        if not count:
            return out, taken, b""
        pairs = self._pairs
        if count > _PAIRS_KEPT:        # more than the buffer holds: all of them, then
            pairs = ffi.new("uintptr_t[]", 2 * count)
            lib.odin_world_record_pairs(self.struct, pairs, count)
            lib.odin_world_clear_records(self.struct)
        return out, taken, ffi.buffer(pairs, count * _PAIR_BYTES)[:]

    def _filled_pushes(self, forces: Sequence[Tuple[object, Sequence[float]]]):
        """This world's OdinBodyForce array holding ``forces`` ((body ptr, force) each)."""
        pushes = self._pushes
        if len(forces) > len(pushes):
            pushes = self._pushes = ffi.new("OdinBodyForce[]", len(forces))
        for f, (body, vector) in zip(pushes, forces):
            f.body = body
            f.vector = vector
        return pushes

    @drains_ode_messages
    def propagate_checked(self, bodies: "BodyArray", rule, start: np.ndarray,
                          forces: Sequence[Tuple[object, Sequence[float]]], step_size: float,
                          steps: int, count: int, stop_at_invalid: bool, states: np.ndarray,
                          tracked: np.ndarray) -> int:
        """A planner's ``count`` propagations of ``steps`` steps in a row, checked by
        ``rule`` (an ``OdinPlanRule *``), in one C call (odin_step.h, odin_plan_propagate):
        from the body state vector ``start`` under ``forces`` (as ``propagate``'s), each
        state and its verdict into a row of ``states`` (float64, C order, each row the state
        vector then 1.0 invalid or 0.0), the tracked link's origin (m) and velocity (m/s) into
        a row of ``tracked`` (float64, C order, 6 a row). Returns the propagations made, or
        -1 - i when value i of ``start`` cannot be put back; the records are forgotten."""
        pushes = self._filled_pushes(forces)
        return int(lib.odin_plan_propagate(
            self.struct, bodies.array, bodies.count, rule, ffi.from_buffer("double[]", start),
            pushes, len(forces), step_size, steps, count, int(stop_at_invalid),
            ffi.from_buffer("double[]", states, require_writable=True), states.shape[1],
            ffi.from_buffer("double[]", tracked, require_writable=True)))

    @drains_ode_messages
    def detect(self, any_policy: bool = False) -> None:
        """Records what touches now, without stepping or contacts: under the contact-less
        policy, or under either when ``any_policy`` (a collision query)."""
        lib.odin_world_detect(self.struct, int(any_policy))

    @property
    def last_step_contacts(self) -> int:
        return int(self.struct.last_step_contacts)

    def records(self) -> List[Record]:
        """The collision records of the C loop (pairs of geom addresses)."""
        s = self.struct
        out = []
        for i in range(s.n_records):
            r = s.records[i]
            points = tuple(tuple(r.points[k]) for k in range(r.npoints))
            normals = tuple(tuple(r.normals[k]) for k in range(r.npoints))
            forces = tuple(tuple(r.forces[k]) for k in range(r.npoints)) if r.has_forces else ()
            out.append((int(ffi.cast("uintptr_t", r.g1)), int(ffi.cast("uintptr_t", r.g2)),
                        float(r.depth), points, int(r.first_step), normals, forces))
        return out

    def clear_records(self) -> None:
        lib.odin_world_clear_records(self.struct)

    @drains_ode_messages
    def close(self) -> None:
        """Frees every handle of the scene and the record buffers; idempotent."""
        if self.world.closed:
            return
        s = self.struct
        for field in ("forces", "joint_forces", "motors", "kinematic", "guarded"):
            setattr(s, field, ffi.NULL)
            setattr(s, "n_" + field, 0)
        s.exempt_keys = s.exempt_limit = s.exempt_live = s.exempt_seen = ffi.NULL
        s.n_exempt = 0
        self._arrays.clear()
        lib.odin_world_clear_records(s)
        lib.odin_world_free_buffers(s)
        self.space.close()        # every geom (children first)
        self.contacts.close()
        self.world.close()        # every body, joint and motor left
        s.world = s.space = s.contact_group = ffi.NULL


_PAIRS_KEPT = 256
"""Collision records a propagation hands back in its buffer at once (more take a second
call)."""
_PAIR_BYTES = 2 * ffi.sizeof("uintptr_t")
"""Bytes of one record's geom pair."""


class BodyArray:
    """A fixed list of bodies in one C array (a body state vector's bodies, in its order)."""

    def __init__(self, bodies: Sequence):
        self.count = len(bodies)
        self.array = ffi.new("dBodyID[]", list(bodies) or 1)


class PoseReader:
    """Reads the world poses of a fixed list of geoms in one C call."""

    def __init__(self, geoms: Sequence):
        self.count = len(geoms)
        self._array = ffi.new("dGeomID[]", [g.ptr for g in geoms] or 1)

    def read(self) -> Tuple[np.ndarray, np.ndarray]:
        """(positions (n, 3) m, quaternions (n, 4) (w, x, y, z)), world frame."""
        positions = np.empty((self.count, 3))
        quaternions = np.empty((self.count, 4))
        if self.count:
            lib.odin_read_poses(self._array, self.count,
                                ffi.cast("double *", ffi.from_buffer(positions)),
                                ffi.cast("double *", ffi.from_buffer(quaternions)))
        return positions, quaternions
