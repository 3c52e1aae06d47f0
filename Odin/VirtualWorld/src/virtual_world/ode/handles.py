"""One Python owner per ODE handle: every world, space, joint group, body, geom, trimesh data
and joint is created here and freed by its owner.

Rules (dm_control / pymunk style):
  * every owner frees its handle exactly once: ``close()`` is idempotent and a
    ``weakref.finalize`` frees a forgotten owner when it is collected (never twice);
  * a child holds its parents strongly, so no parent is freed under a living child;
  * a parent frees its children's handles first when it closes, or when the collector
    finalizes it in whatever order (ODE's dWorldDestroy would otherwise destroy bodies and
    joints behind their owners' backs, and dBodyDestroy would turn attached geoms into static
    ones): the order is kept in handle records (_Handle) that hold no owner; spaces are
    created with cleanup off, so geoms are only ever destroyed by their owners;
  * a trimesh geom holds a lease on its trimesh data (``TriMeshDataCache``: one built data per
    mesh content, shared by every geom over that mesh, with the vertex and index arrays ODE
    does not copy) and returns it after the geom is freed; the data is freed once no geom
    holds it and the cache keeps it no longer.

Arguments are the Core's, already checked: ODE ends the process on bad input.
The destroy functions are looked up in ``DESTROYERS`` at call time so tests can spy on them.
"""
from __future__ import annotations

import collections
import weakref
from typing import Any, Callable, Dict, Iterable, Optional, Sequence, Tuple

import numpy as np

from odin_common.interface import JointType, MotorKind
from virtual_world.ode.bindings import ffi, lib
from virtual_world.ode.runtime import drains_ode_messages

DESTROYERS: Dict[str, Callable[[Any], None]] = {
    "world": lambda p: lib.dWorldDestroy(p),
    "space": lambda p: lib.dSpaceDestroy(p),
    "jointgroup": lambda p: lib.dJointGroupDestroy(p),
    "body": lambda p: lib.dBodyDestroy(p),
    "geom": lambda p: lib.dGeomDestroy(p),
    "trimeshdata": lambda p: lib.dGeomTriMeshDataDestroy(p),
    "joint": lambda p: lib.dJointDestroy(p),
}


class _Handle:
    """The record of one ODE handle that the owner's finalizer holds: what to free, the
    handles freed first (children, held strongly: the record outlives its owner) and after.

    The cyclic garbage collector may run the finalizers of a whole dropped scene in one pass,
    in any order, after clearing every weak reference into it: a world's finalizer must still
    free its bodies and joints first (dWorldDestroy frees them behind their owners' backs), so
    the order lives here, in records the collector leaves alone, not in the owners."""

    __slots__ = ("kind", "ptr", "keep", "parents", "children")

    def __init__(self, kind: str, ptr: Any, parents: Tuple["_Handle", ...], keep: Tuple[Any, ...]):
        self.kind = kind
        self.ptr = ptr
        self.keep = keep
        self.parents = parents
        self.children: Dict[int, "_Handle"] = {}
        for parent in parents:
            parent.children[id(self)] = self

    def free(self) -> None:
        """Frees the children, then this handle, then the owners it kept; once."""
        if self.ptr is None:
            return
        for child in list(self.children.values()):
            child.free()
        ptr, self.ptr = self.ptr, None
        DESTROYERS[self.kind](ptr)
        for parent in self.parents:
            parent.children.pop(id(self), None)
        for item in self.keep:  # what this handle kept (a trimesh's data) goes right after it
            if isinstance(item, (Owner, TriMeshLease)):
                item.close()
        self.keep = ()


class Owner:
    """Owns one ODE handle `ptr` of `kind` (a key of DESTROYERS).

    parents: owners that must outlive this one (held strongly); they close this one first.
    keep:    Python objects (cffi arrays, other owners) kept alive until the handle is freed.
    """

    __slots__ = ("kind", "_handle", "_parents", "_finalizer", "data", "__weakref__")

    def __init__(self, kind: str, ptr: Any, parents: Iterable["Owner"] = (),
                 keep: Tuple[Any, ...] = (), data: Any = None):
        if ptr == ffi.NULL:
            raise MemoryError(f"ODE returned NULL for a new {kind}")
        self.kind = kind
        self._parents = tuple(parents)
        self.data = data  # C memory the handle points at (a geom's OdinGeomInfo), kept alive
        self._handle = _Handle(kind, ptr, tuple(p._handle for p in self._parents), (*keep, data))
        self._finalizer = weakref.finalize(self, self._handle.free)
        self._finalizer.atexit = False  # ODE may already be closed at interpreter exit

    @property
    def ptr(self) -> Any:
        """The live C handle; raises if closed."""
        if self._handle.ptr is None:
            raise ValueError(f"{self.kind} handle already freed")
        return self._handle.ptr

    @property
    def closed(self) -> bool:
        return self._handle.ptr is None

    @property
    def address(self) -> int:
        """The handle's C address (how C code names it back to Python)."""
        return int(ffi.cast("uintptr_t", self.ptr))

    @drains_ode_messages
    def close(self) -> None:
        """Frees children first, then the handle; a second call does nothing."""
        self._finalizer.detach()
        self._handle.free()


# ---------------------------------------------------------------------------------- world

@drains_ode_messages
def new_world() -> Owner:
    return Owner("world", lib.dWorldCreate())


#: ODE's broad phases Odin can collide with: "sap" (sweep and prune, the default: its cost
#: per geom stays flat from 100 to 10,000 bodies, where the hash space's triples), "hash"
#: (the thesis's hash space). Both report every pair whose bounding boxes overlap, and
#: odin_step.c sorts the pairs before making contacts, so both give bit-identical results.
BROAD_PHASES = ("sap", "hash")


@drains_ode_messages
def new_space(broad_phase: str = "sap") -> Owner:
    """A space of ``broad_phase`` (BROAD_PHASES) that never destroys its geoms (their owners
    do)."""
    if broad_phase == "sap":
        space = lib.dSweepAndPruneSpaceCreate(ffi.NULL, lib.dSAP_AXES_XYZ)
    elif broad_phase == "hash":
        space = lib.dHashSpaceCreate(ffi.NULL)
    else:
        raise ValueError(f"no broad phase {broad_phase!r}; there are {BROAD_PHASES}")
    if space != ffi.NULL:
        lib.dSpaceSetCleanup(space, 0)
    return Owner("space", space)


@drains_ode_messages
def new_joint_group(world: Owner) -> Owner:
    return Owner("jointgroup", lib.dJointGroupCreate(0), parents=(world,))


# ---------------------------------------------------------------------------------- bodies

@drains_ode_messages
def new_body(world: Owner) -> Owner:
    return Owner("body", lib.dBodyCreate(world.ptr), parents=(world,))


# ---------------------------------------------------------------------------------- geoms

def new_geom(ptr: Any, space: Owner, serial: int, body: Optional[Owner] = None,
             keep: Tuple[Any, ...] = ()) -> Owner:
    """Adopts a freshly created geom in `space`, attached to `body` if any, with its
    OdinGeomInfo (``serial``: its number in the scene, in creation order; tag 0) as its data;
    ``owner.data`` is that info."""
    parents = (space,) if body is None else (space, body)
    info = ffi.new("OdinGeomInfo *", {"serial": serial, "tag": 0})
    owner = Owner("geom", ptr, parents=parents, keep=keep, data=info)
    lib.dGeomSetData(ptr, info)
    if body is not None:
        lib.dGeomSetBody(ptr, body.ptr)
    return owner


@drains_ode_messages
def new_primitive(space: Owner, kind: str, dims: Sequence[float], serial: int,
                  body: Optional[Owner] = None) -> Owner:
    """A sphere (radius), cylinder or capsule (radius, length along z) or box (sides x, y,
    z), m; or a plane (dims: a, b, c, d with a x + b y + c z = d, the normal unit; never on a
    body: ODE's planes are not placeable)."""
    if kind == "sphere":
        ptr = lib.dCreateSphere(space.ptr, dims[0])
    elif kind == "cylinder":
        ptr = lib.dCreateCylinder(space.ptr, dims[0], dims[1])
    elif kind == "capsule":
        ptr = lib.dCreateCapsule(space.ptr, dims[0], dims[1])
    elif kind == "box":
        ptr = lib.dCreateBox(space.ptr, dims[0], dims[1], dims[2])
    elif kind == "plane" and body is None:
        ptr = lib.dCreatePlane(space.ptr, *dims)
    else:
        raise ValueError(f"no ODE primitive {kind!r}" + (" on a body" if body else ""))
    return new_geom(ptr, space, serial, body)


@drains_ode_messages
def new_trimesh(space: Owner, vertices: np.ndarray, triangles: np.ndarray, serial: int,
                body: Optional[Owner] = None,
                meshes: Optional["TriMeshDataCache"] = None) -> Owner:
    """A trimesh geom over ``vertices`` (n, 3) m and ``triangles`` (m, 3) indices.

    Its trimesh data is leased from ``meshes`` (shared with every geom over the same mesh and
    kept for later ones), or built for this geom alone without a cache; the geom's owner
    returns the lease right after freeing the geom."""
    lease = (meshes or TriMeshDataCache(idle_triangles=0)).lease(vertices, triangles)
    ptr = lib.dCreateTriMesh(space.ptr, lease.data.ptr, ffi.NULL, ffi.NULL, ffi.NULL)
    if ptr == ffi.NULL:
        lease.close()
        raise MemoryError("ODE returned NULL for a new trimesh")
    return new_geom(ptr, space, serial, body, keep=(lease,))  # the lease goes after the geom


#: triangles of trimesh data no geom uses that a TriMeshDataCache keeps for later geoms by
#: default: the TX90 + hand + cans of Kautham's flagship problem collide with ~77,000 (14
#: data for 28 meshes; building them took ~0.45 s of every load); with its arrays a data
#: holds ~60 bytes a triangle, so at most ~60 MB stay idle
IDLE_TRIANGLES = 1_000_000


class _MeshEntry:
    """One built trimesh data (its owner keeps the arrays ODE points into) and its users."""

    __slots__ = ("data", "triangles", "users")

    def __init__(self, data: Owner, triangles: int):
        self.data = data
        self.triangles = triangles
        self.users = 0


class TriMeshLease:
    """A geom's hold on shared trimesh ``data`` (an Owner); ``close()`` (idempotent) gives
    it back to its cache."""

    __slots__ = ("data", "_cache", "_key")

    def __init__(self, cache: "TriMeshDataCache", key: Tuple[bytes, bytes], data: Owner):
        self.data = data
        self._cache = cache
        self._key = key

    def close(self) -> None:
        if self._cache is not None:
            cache, self._cache = self._cache, None
            cache._release(self._key)


class TriMeshDataCache:
    """Built trimesh data (dGeomTriMeshDataBuildDouble) per mesh content: the vertices
    (float64, m) and triangles (uint32) exactly as given, so a geom over shared data collides
    bit for bit as over its own. Data in use is shared; data no geom uses is kept, most
    recently released last, up to ``idle_triangles`` triangles (the same robot comes back
    after every New Scene), and freed when it falls out or on ``close()``. The only owner of
    each data: a geom holds a TriMeshLease, never the data itself."""

    def __init__(self, idle_triangles: int = IDLE_TRIANGLES):
        self.idle_triangles = idle_triangles
        self._entries: Dict[Tuple[bytes, bytes], _MeshEntry] = {}
        self._idle: "collections.OrderedDict[Tuple[bytes, bytes], None]" = \
            collections.OrderedDict()
        self._closed = False
        self.builds = 0  # data built so far (the others were shared or kept)

    def lease(self, vertices: np.ndarray, triangles: np.ndarray) -> TriMeshLease:
        """A lease on the data of ``vertices`` (n, 3) m and ``triangles`` (m, 3) indices,
        built now unless data of the very same arrays exists."""
        vertex_bytes = np.ascontiguousarray(vertices, dtype=np.float64).tobytes()
        index_bytes = np.ascontiguousarray(triangles, dtype=np.uint32).tobytes()
        key = (vertex_bytes, index_bytes)
        entry = self._entries.get(key)
        if entry is None:
            entry = self._entries[key] = _MeshEntry(_build_data(vertex_bytes, index_bytes),
                                                    len(index_bytes) // 12)
            self.builds += 1
        self._idle.pop(key, None)
        entry.users += 1
        return TriMeshLease(self, key, entry.data)

    def _release(self, key: Tuple[bytes, bytes]) -> None:
        entry = self._entries[key]
        entry.users -= 1
        if entry.users == 0:
            self._idle[key] = None
            self._trim(0 if self._closed else self.idle_triangles)

    def _trim(self, budget: int) -> None:
        """Frees the least recently released idle data until at most ``budget`` triangles
        of idle data are left."""
        idle = sum(self._entries[key].triangles for key in self._idle)
        while self._idle and idle > budget:
            key, _ = self._idle.popitem(last=False)
            entry = self._entries.pop(key)
            idle -= entry.triangles
            entry.data.close()

    @property
    def sizes(self) -> Tuple[int, int]:
        """(data held, of which idle)."""
        return len(self._entries), len(self._idle)

    def close(self) -> None:
        """Frees the idle data now, and any data still leased when its last geom goes."""
        self._closed = True
        self._trim(0)


def _build_data(vertex_bytes: bytes, index_bytes: bytes) -> Owner:
    """Trimesh data over read-only copies of the arrays: ODE keeps pointers to them without
    copying, so the data's owner keeps them alive (cffi buffers over the bytes: no per-value
    conversion)."""
    vertices = ffi.from_buffer("double[]", vertex_bytes)
    indices = ffi.from_buffer("dTriIndex[]", index_bytes)
    data = Owner("trimeshdata", lib.dGeomTriMeshDataCreate(), keep=(vertices, indices))
    lib.dGeomTriMeshDataBuildDouble(data.ptr, vertices, 3 * ffi.sizeof("double"),
                                    len(vertices) // 3, indices, len(indices),
                                    3 * ffi.sizeof("dTriIndex"))
    return data


# ---------------------------------------------------------------------------------- joints

_CREATE_JOINT = {
    JointType.BALL: lib.dJointCreateBall, JointType.HINGE: lib.dJointCreateHinge,
    JointType.SLIDER: lib.dJointCreateSlider, JointType.PISTON: lib.dJointCreatePiston,
    JointType.UNIVERSAL: lib.dJointCreateUniversal, JointType.HINGE2: lib.dJointCreateHinge2,
    JointType.PR: lib.dJointCreatePR, JointType.PU: lib.dJointCreatePU,
    JointType.FIXED: lib.dJointCreateFixed, JointType.PLANE2D: lib.dJointCreatePlane2D,
}
_CREATE_MOTOR = {MotorKind.ANGULAR: lib.dJointCreateAMotor,
                 MotorKind.LINEAR: lib.dJointCreateLMotor}


def _attached(ptr: Any, world: Owner, bodies: Sequence[Owner]) -> Owner:
    """Adopts a new joint and attaches it: bodies[0] is ODE's body 1; with one body, body 2 is
    the static world (NULL). Its feedback (``owner.data``, a dJointFeedback ODE fills at every
    step: the force and torque the joint applies to each body) is kept with it."""
    feedback = ffi.new("dJointFeedback *")
    owner = Owner("joint", ptr, parents=(world, *bodies), data=feedback)
    lib.dJointAttach(ptr, bodies[0].ptr, bodies[1].ptr if len(bodies) > 1 else ffi.NULL)
    lib.dJointSetFeedback(ptr, feedback)
    return owner


@drains_ode_messages
def new_joint(world: Owner, kind: JointType, bodies: Sequence[Owner]) -> Owner:
    """A joint of ``kind`` attached to one or two bodies (see _attached)."""
    return _attached(_CREATE_JOINT[kind](world.ptr, ffi.NULL), world, bodies)


@drains_ode_messages
def new_motor(world: Owner, kind: MotorKind, bodies: Sequence[Owner]) -> Owner:
    """An angular (dAMotor) or linear (dLMotor) motor attached like a joint."""
    return _attached(_CREATE_MOTOR[kind](world.ptr, ffi.NULL), world, bodies)
