"""Persistent forces (thesis 5.4.2, 5.4.3): forces and torques on bodies and along joints,
re-applied by the C step loop before every step until removed.

Units: N and N m. Body forces: the vector in the world or the object's frame, acting at the
centre of mass or at a point (world or object frame; ODE's body frame is the object's frame
shifted to the centre of mass). Joint forces follow ODE's convention: a positive magnitude
acts on body1 along (about) +axis and the reaction on body2.
"""
from __future__ import annotations

import math
from typing import Callable, Dict, Iterable, NamedTuple, Sequence, Tuple

import numpy as np

from odin_common import limits
from odin_common.interface import JOINT_FORCE_MAGNITUDES, ForceKind
from odin_common.limits import shown
from virtual_world.core import validation as check
from virtual_world.core.records import BodyForceRecord, JointForceRecord
from virtual_world.core.scene import Scene
from virtual_world.errors import InvalidArgument, UnknownName, Unsupported
from virtual_world.ode.joints import ODE_JOINT_TYPE


def add_body_force(scene: Scene, object_id: str, kind: int, vector,
                   vector_in_body_frame: bool = False, at_point: bool = False,
                   point=(0.0, 0.0, 0.0), point_in_body_frame: bool = False) -> str:
    """Adds a persistent force or torque; returns "force:<object>:<n>" or
    "torque:<object>:<n>", n the first free number."""
    if isinstance(kind, bool) or kind not in set(ForceKind):
        raise InvalidArgument(f"force kind {shown(kind)} is not FORCE (0) or TORQUE (1)")
    kind = ForceKind(kind)
    obj = scene.body_object(object_id, "force")
    vector = np.array(checked_vector(object_id, kind, vector))
    vector_in_body_frame = check.flag("vector_in_body_frame", vector_in_body_frame)
    at_point = check.flag("at_point", at_point)
    point = check.within_extent("force point", check.vector("force point", point),
                                scene.parameters.world_extent)
    point_in_body_frame = check.flag("point_in_body_frame", point_in_body_frame)
    if kind == ForceKind.TORQUE and at_point:
        raise InvalidArgument("a torque has no point of application (at_point=True)")
    if at_point and point_in_body_frame:
        point = point - obj.com  # object frame -> ODE body frame (centre of mass)
    return _keep(scene, _BODY, f"{kind.name.lower()}:{object_id}",
                 BodyForceRecord(object_id, kind, vector_in_body_frame, at_point,
                                 point_in_body_frame, vector, point))


def checked_vector(object_id: str, kind: ForceKind, vector) -> Tuple[float, float, float]:
    """A force (N) or torque (N m) on ``object_id``: three finite numbers, at most
    limits.MAX_FORCE. In Python floats: a planner checks one every step."""
    try:
        x, y, z = vector
        x, y, z = float(x), float(y), float(z)
    except (TypeError, ValueError):
        raise InvalidArgument(f"force vector={shown(vector)} is not a vector of 3 "
                              "numbers") from None
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
        raise InvalidArgument(f"force vector={shown(vector)} is not finite")
    magnitude = math.sqrt(x * x + y * y + z * z)
    if magnitude > limits.MAX_FORCE:
        check.at_most(f"{kind.name.lower()} on {shown(object_id)}", magnitude, limits.MAX_FORCE,
                      "N" if kind == ForceKind.FORCE else "N m")
    return x, y, z


def remove_body_force(scene: Scene, force_id: str) -> None:
    _remove(scene, _BODY, force_id)


def drop_body_forces(scene: Scene, force_ids: Iterable[str]) -> None:
    """Forgets body forces (their object is going) and hands C the rest."""
    _drop(scene, _BODY, force_ids)


def add_joint_force(scene: Scene, joint_id: str, magnitudes: Sequence[float]) -> str:
    """Adds a persistent force/torque along a joint's axes (interface.JOINT_FORCE_MAGNITUDES
    says which per type); returns "jointforce:<joint>:<n>"."""
    joint = scene.joint(joint_id)
    if joint.type not in JOINT_FORCE_MAGNITUDES:
        raise Unsupported(f"ODE has no force or torque for {joint.type.label} joint "
                          f"{shown(joint_id)}")
    count = len(JOINT_FORCE_MAGNITUDES[joint.type])
    try:
        n_values = len(magnitudes)
    except TypeError:
        raise InvalidArgument(f"magnitudes {shown(magnitudes)} is not a sequence") from None
    if n_values != count:
        raise InvalidArgument(f"a {joint.type.label} joint force takes {count} magnitude(s); "
                              f"got {shown(list(magnitudes))}")
    values = check.vector("joint force magnitudes", magnitudes, count)
    check.at_most(f"joint force on {shown(joint_id)}", float(np.max(np.abs(values))),
                  limits.MAX_FORCE, "N or N m")
    return _keep(scene, _JOINT, f"jointforce:{joint_id}", JointForceRecord(joint_id, values))


def remove_joint_force(scene: Scene, force_id: str) -> None:
    _remove(scene, _JOINT, force_id)


def drop_joint_forces(scene: Scene, force_ids: Iterable[str]) -> None:
    """Forgets joint forces (their joint is going) and hands C the rest."""
    _drop(scene, _JOINT, force_ids)


def replace_all(scene: Scene, body_forces: Dict[str, BodyForceRecord],
                joint_forces: Dict[str, JointForceRecord]) -> None:
    """Every persistent force becomes one of these (a snapshot put back): the records, the
    ids on their objects and joints, and C's arrays."""
    scene.body_forces = dict(body_forces)
    scene.joint_forces = dict(joint_forces)
    for kind in (_BODY, _JOINT):
        records = kind.records(scene)
        for owner in kind.owners(scene).values():
            owner.forces = {i for i, f in records.items() if kind.owner_id(f) == owner.id}
        kind.to_c(scene)


def _body_forces_to_c(scene: Scene) -> None:
    scene.c.set_body_forces([
        (scene.objects[f.object_id].body.ptr, f.kind, f.vector_in_body_frame, f.at_point,
         f.point_in_body_frame, f.vector.tolist(), f.point.tolist())
        for f in scene.body_forces.values()])


def _joint_forces_to_c(scene: Scene) -> None:
    scene.c.set_joint_forces([
        (scene.joints[f.joint_id].owner.ptr, ODE_JOINT_TYPE[scene.joints[f.joint_id].type],
         f.magnitudes.tolist()) for f in scene.joint_forces.values()])


class _Kind(NamedTuple):
    """One kind of persistent force, kept alike: its records by force ID, the objects or
    joints they act on (each with the set ``forces`` of its force IDs), and C's copy."""
    noun: str                                   # in errors: "body force", "joint force"
    records: Callable[[Scene], dict]            # {force ID: record}
    owners: Callable[[Scene], dict]             # {object or joint ID: its record}
    owner_id: Callable[[object], str]           # record -> the ID it acts on
    to_c: Callable[[Scene], None]               # hands C every record of the kind


_BODY = _Kind("body force", lambda scene: scene.body_forces, lambda scene: scene.objects,
              lambda record: record.object_id, _body_forces_to_c)
_JOINT = _Kind("joint force", lambda scene: scene.joint_forces, lambda scene: scene.joints,
               lambda record: record.joint_id, _joint_forces_to_c)


def _keep(scene: Scene, kind: _Kind, prefix: str, record) -> str:
    """Keeps ``record`` under "<prefix>:<n>", n the first free number; returns that ID."""
    records = kind.records(scene)
    owner = kind.owners(scene)[kind.owner_id(record)]
    if len(owner.forces) >= limits.MAX_FORCES_PER_OWNER:
        raise InvalidArgument(f"{shown(kind.owner_id(record))} holds {len(owner.forces)} "
                              f"forces, the most one may (MAX_FORCES_PER_OWNER): remove one "
                              "first")
    force_id = _free_id(records, prefix)
    records[force_id] = record
    owner.forces.add(force_id)
    kind.to_c(scene)
    return force_id


def _remove(scene: Scene, kind: _Kind, force_id: str) -> None:
    records = kind.records(scene)
    if force_id not in records:
        raise UnknownName(f"no {kind.noun} {shown(force_id)}")
    kind.owners(scene)[kind.owner_id(records[force_id])].forces.discard(force_id)
    _drop(scene, kind, [force_id])


def _drop(scene: Scene, kind: _Kind, force_ids: Iterable[str]) -> None:
    records = kind.records(scene)
    for force_id in list(force_ids):
        del records[force_id]
    kind.to_c(scene)


def _free_id(taken, prefix: str) -> str:
    n = 0
    while f"{prefix}:{n}" in taken:
        n += 1
    return f"{prefix}:{n}"
