"""A scene: one ODE world and the records that name what is in it.

The topic modules (objects, joints, motors, forces, readout) work on a Scene; the Core (world.py)
holds one, behind its lock, and replaces it on New Scene. Dictionaries keep insertion order,
which is the order of every listing the Core gives.
"""
from __future__ import annotations

from typing import Dict, FrozenSet, List, Optional, Tuple

from odin_common.limits import ResourceLimits, shown
from odin_common.world_parameters import WorldParameters
from virtual_world.core.records import (BodyForceRecord, Collision, GeometryRecord,
                                        JointForceRecord, JointRecord, MotorRecord, ObjectRecord)
from virtual_world.errors import Unsupported, UnknownName
from virtual_world.ode.handles import TriMeshDataCache
from virtual_world.ode.world import BodyArray, CWorld, PoseReader


PAIR_NAMES_KEPT = 4096
"""Sets of colliding pairs Scene.pair_names remembers (then it starts again)."""


class Scene:
    """The ODE world (``c``) and every record of what it holds."""

    def __init__(self, parameters: WorldParameters, resources: ResourceLimits,
                 meshes: Optional[TriMeshDataCache] = None):
        """``meshes``: the trimesh data this scene's mesh geoms share (the Core's, kept across
        New Scenes); None: each geom builds its own."""
        self.parameters = parameters
        self.resources = resources
        self.meshes = meshes
        self.c = CWorld(parameters)
        self.objects: Dict[str, ObjectRecord] = {}
        self.geometries: Dict[str, GeometryRecord] = {}
        self.geometry_names: Dict[int, str] = {}        # geom C address -> geometry name
        self.joints: Dict[str, JointRecord] = {}
        self.pairs: Dict[FrozenSet[str], str] = {}       # {body1, body2} -> joint id
        self.motors: Dict[str, MotorRecord] = {}
        self.motor_slots: Dict[str, int] = {}           # motor id -> slot in C's goal array
        self.kinematic: Dict[str, str] = {}             # kinematic drive: motor id -> link
        self.body_forces: Dict[str, BodyForceRecord] = {}
        self.joint_forces: Dict[str, JointForceRecord] = {}
        self.entities: Dict[str, List[str]] = {}
        self.next_tag = 1                               # geom tag of the next entity
        self.next_serial = 1                            # serial of the next geom
        self.revision = 0                               # objects or geometries added/dropped
        self.entity_counter = 0                         # n of the last "entity<n>"
        self.carried: Dict[Tuple[str, str], Collision] = {}   # collisions kept in Python
        self.sim_time = 0.0                             # s since the scene began
        self.snapshots: Dict[str, object] = {}          # name -> snapshots.Snapshot
        self.reset_point: Optional[object] = None       # the state right after the last build
        self.contents_changed = True                    # a build or removal since reset_point
        self.exempt_pairs: Tuple = ()                   # core.exemptions.ExemptPair, key order
        self.exempt_depth = 0.0                         # m: no deeper, an exempt pair parts
        self.parked: Dict[str, object] = {}             # object id -> records.Divergence
        self.divergences: List[object] = []             # records.Divergence not yet taken
        self._pose_reader: Optional[PoseReader] = None
        self._pose_names: List[str] = []
        self._bodies: Optional[BodyArray] = None
        self._pair_names: Dict[bytes, Tuple[Tuple[str, str], ...]] = {}

    def close(self) -> None:
        """Frees every ODE handle of the scene; idempotent."""
        self.c.close()
        self._pose_reader = None
        self._bodies = None

    # -- look-ups that refuse unknown names --------------------------------------------------
    def object(self, object_id: str) -> ObjectRecord:
        try:
            return self.objects[object_id]
        except (KeyError, TypeError):
            raise UnknownName(f"no object {shown(object_id)}") from None

    def body_object(self, object_id: str, what: str) -> ObjectRecord:
        """The object, which must have a body (``what`` names the request)."""
        obj = self.object(object_id)
        if obj.body is None:
            raise Unsupported(f"{what}: object {shown(object_id)} is geometry only (no body)")
        return obj

    def joint(self, joint_id: str) -> JointRecord:
        try:
            return self.joints[joint_id]
        except (KeyError, TypeError):
            raise UnknownName(f"no joint {shown(joint_id)}") from None

    def motor(self, motor_id: str) -> MotorRecord:
        try:
            return self.motors[motor_id]
        except (KeyError, TypeError):
            raise UnknownName(f"no motor {shown(motor_id)}") from None

    def geometry(self, name: str) -> GeometryRecord:
        try:
            return self.geometries[name]
        except (KeyError, TypeError):
            raise UnknownName(f"no geometry named {shown(name)}") from None

    # -- objects, their bodies in one C array for state vectors ------------------------------
    def add_object(self, record: ObjectRecord) -> None:
        self.objects[record.id] = record
        self._bodies = None
        self.revision += 1

    def drop_object(self, object_id: str) -> None:
        del self.objects[object_id]
        self._bodies = None
        self.revision += 1

    def body_array(self) -> BodyArray:
        """Every object's body, in object order (a body state vector's order), rebuilt after
        a build or a removal."""
        if self._bodies is None:
            self._bodies = BodyArray([o.body.ptr for o in self.objects.values()
                                      if o.body is not None])
        return self._bodies

    # -- geometries, in one C array for pose read-out ---------------------------------------
    def take_serial(self) -> int:
        """The next geom's serial: geoms are numbered in creation order, so the same calls
        give the same numbers (odin_step.c orders contacts by them)."""
        serial = self.next_serial
        self.next_serial += 1
        return serial

    def add_geometry(self, record: GeometryRecord) -> None:
        self.revision += 1
        self.geometries[record.name] = record
        self.geometry_names[record.owner.address] = record.name
        self._pose_reader = None
        self._pair_names = {}

    def drop_geometry(self, record: GeometryRecord) -> None:
        self.revision += 1
        del self.geometry_names[record.owner.address]
        del self.geometries[record.name]
        self._pose_reader = None
        self._pair_names = {}       # a new geom may come at a freed one's address

    def pair_names(self, raw: bytes) -> Tuple[Tuple[str, str], ...]:
        """The geometry pairs of collision records given as raw geom address pairs (C's
        uintptr_t, CWorld.propagate's): names sorted within a pair and the pairs sorted.
        Remembered until a geometry comes or goes: a planner meets the same few sets of
        pairs again and again."""
        pairs = self._pair_names.get(raw)
        if pairs is None:
            names = self.geometry_names
            found = []
            for address1, address2 in zip(*[iter(memoryview(raw).cast("N"))] * 2):
                first, second = names[address1], names[address2]
                found.append((first, second) if first <= second else (second, first))
            pairs = tuple(sorted(found))
            if len(self._pair_names) >= PAIR_NAMES_KEPT:
                self._pair_names = {}
            self._pair_names[raw] = pairs
        return pairs

    def pose_reader(self) -> Tuple[List[str], PoseReader]:
        """(geometry names, a reader of their poses), rebuilt after a build or a removal."""
        if self._pose_reader is None:
            self._pose_names = list(self.geometries)
            self._pose_reader = PoseReader([self.geometries[n].owner for n in self._pose_names])
        return self._pose_names, self._pose_reader
