"""Snapshots of a scene's dynamic state, put back bit for bit.

A snapshot holds everything a step reads that calls can change: every body's pose and
velocities (ODE's own numbers, odin_state.c), static geometries' poses, every joint's and
motor's parameters, motor goals, persistent body and joint forces, simulated time and the
step count, the world's state of ODE's random generator (QuickStep's constraint order), the
collisions recorded but not yet read, which bodies the divergence guard had parked, which
links the kinematic drive moved and which exempt pairs had not yet parted (core.exemptions).
Putting one back, then stepping as before, gives bit-identical poses and velocities (tests/
compare raw float64 bytes).

A snapshot belongs to the scene's contents when it was taken (its objects, joints, motors and
exempt pairs): it can be put back while they are the same, and is refused otherwise. World
parameters are not state: they stay as they are.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, Tuple

import numpy as np

from odin_common import limits
from odin_common.interface import JOINT_PARAMETER_AXES, JOINT_PARAMETERS, MOTOR_PARAMETERS
from odin_common.limits import shown, shown_list
from virtual_world.core import exemptions, forces, guard, kinematic, motors, readout
from virtual_world.core.records import BodyForceRecord, Collision, JointForceRecord
from virtual_world.core.scene import Scene
from virtual_world.errors import InvalidArgument, UnknownName
from virtual_world.ode import bodies
from virtual_world.ode import joints as ode_joints

Contents = Tuple[Tuple[str, ...], Tuple[str, ...], Tuple[str, ...], Tuple]


@dataclass(frozen=True, eq=False)
class Snapshot:
    """A scene's dynamic state (see the module's docstring); private to the Core."""
    contents: Contents                          # object, joint, motor ids, exempt pairs
    body_ids: Tuple[str, ...]
    body_states: np.ndarray                     # (n, bodies.BODY_STATE_SIZE)
    static_names: Tuple[str, ...]               # geometries without a body
    static_poses: np.ndarray                    # (k, 15)
    joint_parameters: Tuple[Tuple[str, int, int, float], ...]
    motor_parameters: Tuple[Tuple[str, int, int, float], ...]
    motor_goals: Dict[str, Tuple[float, ...]]
    servos: Dict[str, object]                   # motor id -> records.Servo or None
    body_forces: Dict[str, BodyForceRecord]
    joint_forces: Dict[str, JointForceRecord]
    carried: Dict[Tuple[str, str], Collision]
    sim_time: float
    step_count: int
    rand_seed: int
    parked: Tuple[str, ...]                     # objects the divergence guard had parked
    kinematic: Dict[str, str]                   # the kinematic drive's links (motor -> object)
    exempt_live: np.ndarray                     # exempt pairs' states (core.exemptions)


_ITEM_BYTES = 100
"""Bytes a snapshot's Python item (a tuple, a dict entry, an ID) is counted as: an estimate
of CPython's object and container overhead."""


def size_bytes(snapshot: Snapshot) -> int:
    """What ``snapshot`` holds in memory, estimated (bytes): its arrays, and _ITEM_BYTES per
    item of its tuples and dicts."""
    arrays = (snapshot.body_states.nbytes + snapshot.static_poses.nbytes
              + snapshot.exempt_live.nbytes)
    items = sum(len(part) for part in (
        *snapshot.contents, snapshot.body_ids, snapshot.static_names,
        snapshot.joint_parameters, snapshot.motor_parameters, snapshot.motor_goals,
        snapshot.servos, snapshot.body_forces, snapshot.joint_forces, snapshot.carried,
        snapshot.parked, snapshot.kinematic))
    return arrays + _ITEM_BYTES * items


def check_room(held: Dict[str, Snapshot], name: str, snapshot: Snapshot) -> None:
    """InvalidArgument when keeping ``snapshot`` under ``name`` (replacing one so named) would
    make the saved states ``held`` hold more than limits.MAX_SNAPSHOT_MB."""
    size = size_bytes(snapshot)
    others = sum(size_bytes(s) for n, s in held.items() if n != name)
    if others + size > limits.MAX_SNAPSHOT_MB * 2 ** 20:
        raise InvalidArgument(f"snapshot {shown(name)}: {size / 2 ** 20:.3g} MB more than the "
                              f"{others / 2 ** 20:.4g} MB of saved states held exceeds "
                              f"{limits.MAX_SNAPSHOT_MB:,} MB (MAX_SNAPSHOT_MB); remove some "
                              "first")


def named(scene: Scene, name: str) -> Snapshot:
    """The snapshot saved under ``name``; UnknownName (listing the saved ones) otherwise."""
    snapshot = scene.snapshots.get(name) if isinstance(name, str) else None
    if snapshot is None:
        raise UnknownName(f"no snapshot {shown(name)} (saved: "
                          f"{shown_list(sorted(scene.snapshots))})")
    return snapshot


def contents(scene: Scene) -> Contents:
    return tuple(scene.objects), tuple(scene.joints), tuple(scene.motors), scene.exempt_pairs


def take(scene: Scene) -> Snapshot:
    """The scene's dynamic state now."""
    readout.carry_collisions(scene, set())
    body_ids = tuple(i for i, o in scene.objects.items() if o.body is not None)
    statics = [g for o in scene.objects.values() if o.body is None for g in o.geometries]
    return Snapshot(
        contents=contents(scene), body_ids=body_ids,
        body_states=bodies.read_states([scene.objects[i].body.ptr for i in body_ids]),
        static_names=tuple(g.name for g in statics),
        static_poses=np.array([bodies.static_geom_pose(g.owner.ptr) for g in statics]
                              ).reshape(-1, 15),
        joint_parameters=_joint_parameters(scene), motor_parameters=_motor_parameters(scene),
        motor_goals={i: tuple(m.velocity) for i, m in scene.motors.items()},
        servos={i: m.servo for i, m in scene.motors.items()},
        body_forces=dict(scene.body_forces), joint_forces=dict(scene.joint_forces),
        carried=dict(scene.carried), sim_time=scene.sim_time,
        step_count=scene.c.step_count, rand_seed=scene.c.rand_seed,
        parked=tuple(scene.parked), kinematic=dict(scene.kinematic),
        exempt_live=exemptions.live(scene))


def _joint_parameters(scene: Scene):
    return tuple((joint.id, parameter, axis,
                  ode_joints.joint_parameter(joint.owner.ptr, joint.type, parameter, axis))
                 for joint in scene.joints.values()
                 for parameter in sorted(JOINT_PARAMETERS.get(joint.type, ()))
                 for axis in range(1, JOINT_PARAMETER_AXES[joint.type] + 1))


def _motor_parameters(scene: Scene):
    return tuple((motor.id, parameter, axis,
                  ode_joints.motor_parameter(motor.owner.ptr, motor.kind, parameter, axis))
                 for motor in scene.motors.values() for parameter in sorted(MOTOR_PARAMETERS)
                 for axis in range(1, motor.naxes + 1))


def check_fits(scene: Scene, snapshot: Snapshot, what: str) -> None:
    """InvalidArgument unless the scene holds what it held when ``snapshot`` was taken."""
    now = contents(scene)
    if now == snapshot.contents:
        return
    changes = []
    labels = ("objects", "joints", "motors", "exempt pairs")
    for label, then, present in zip(labels, snapshot.contents, now):
        then_set, present_set = set(then), set(present)    # once: scenes hold 100,000s
        added = [i for i in present if i not in then_set]
        gone = [i for i in then if i not in present_set]
        if added:
            changes.append(f"{label} added since: {shown_list(added, 5)}")
        if gone:
            changes.append(f"{label} removed since: {shown_list(gone, 5)}")
    raise InvalidArgument(f"{what}: the scene changed since it was taken ("
                          + "; ".join(changes or ["built in another order"]) + ")")


def put_back(scene: Scene, snapshot: Snapshot) -> None:
    """Puts the scene's dynamic state back as ``snapshot`` holds it (check_fits first)."""
    guard.set_parked(scene, snapshot.parked)
    kinematic.install(scene, snapshot.kinematic)
    bodies.write_states([scene.objects[i].body.ptr for i in snapshot.body_ids],
                        snapshot.body_states)
    for name, pose in zip(snapshot.static_names, snapshot.static_poses):
        bodies.set_static_geom_pose(scene.geometries[name].owner.ptr, pose)
    for joint_id, parameter, axis, value in snapshot.joint_parameters:
        joint = scene.joints[joint_id]
        ode_joints.set_joint_parameter(joint.owner.ptr, joint.type, parameter, axis, value)
    for motor_id, parameter, axis, value in snapshot.motor_parameters:
        motor = scene.motors[motor_id]
        ode_joints.set_motor_parameter(motor.owner.ptr, motor.kind, parameter, axis, value)
    for motor_id, goals in snapshot.motor_goals.items():
        scene.motors[motor_id].velocity = list(goals)
        scene.motors[motor_id].servo = snapshot.servos[motor_id]
    motors.rebuild_goals(scene)
    forces.replace_all(scene, snapshot.body_forces, snapshot.joint_forces)
    scene.c.clear_records()
    scene.carried = dict(snapshot.carried)
    scene.sim_time = snapshot.sim_time
    scene.c.step_count = snapshot.step_count
    scene.c.rand_seed = snapshot.rand_seed
    exemptions.put_live(scene, snapshot.exempt_live)
