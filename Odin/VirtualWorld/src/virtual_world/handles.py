"""One Python owner per ODE handle (world, space, joint group, body, geom, trimesh data, joint).

Rules (dm_control / pymunk style):
  * every owner frees its handle exactly once: ``close()`` is idempotent and a
    ``weakref.finalize`` frees a forgotten owner when it is collected (never twice);
  * a child holds its parents strongly, so no parent is freed under a living child;
  * a parent holds its children weakly and closes them first when it closes (ODE's
    dWorldDestroy would otherwise destroy bodies and joints behind their owners' backs, and
    dBodyDestroy would turn attached geoms into static ones); spaces are created with
    cleanup off, so geoms are only ever destroyed by their owners;
  * a trimesh geom keeps its vertex and index arrays (ODE does not copy them) and its trimesh
    data owner alive, and frees that data after the geom.

The destroy functions are looked up in ``DESTROYERS`` at call time so tests can spy on them.
"""
from __future__ import annotations

import weakref
from typing import Any, Callable, Dict, Iterable, Optional, Tuple

from virtual_world.ode.bindings import ffi, lib

DESTROYERS: Dict[str, Callable[[Any], None]] = {
    "world": lambda p: lib.dWorldDestroy(p),
    "space": lambda p: lib.dSpaceDestroy(p),
    "jointgroup": lambda p: lib.dJointGroupDestroy(p),
    "body": lambda p: lib.dBodyDestroy(p),
    "geom": lambda p: lib.dGeomDestroy(p),
    "trimeshdata": lambda p: lib.dGeomTriMeshDataDestroy(p),
    "joint": lambda p: lib.dJointDestroy(p),
}


def _free(kind: str, ptr: Any, keep: Tuple[Any, ...]) -> None:
    DESTROYERS[kind](ptr)
    for item in keep:  # owners kept by this handle (a trimesh's data) go right after it
        if isinstance(item, Owner):
            item.close()


class Owner:
    """Owns one ODE handle `ptr` of `kind` (a key of DESTROYERS).

    parents: owners that must outlive this one (held strongly); they close this one first.
    keep:    Python objects (cffi arrays, other owners) kept alive until the handle is freed.
    """

    __slots__ = ("kind", "_ptr", "_parents", "_children", "_finalizer", "__weakref__")

    def __init__(self, kind: str, ptr: Any, parents: Iterable["Owner"] = (),
                 keep: Tuple[Any, ...] = ()):
        if ptr == ffi.NULL:
            raise MemoryError(f"ODE returned NULL for a new {kind}")
        self.kind = kind
        self._ptr = ptr
        self._parents = tuple(parents)
        self._children: "weakref.WeakSet[Owner]" = weakref.WeakSet()
        for parent in self._parents:
            parent._children.add(self)
        self._finalizer = weakref.finalize(self, _free, kind, ptr, tuple(keep))
        self._finalizer.atexit = False  # ODE may already be closed at interpreter exit

    @property
    def ptr(self) -> Any:
        """The live C handle; raises if closed."""
        if self._ptr is None:
            raise ValueError(f"{self.kind} handle already freed")
        return self._ptr

    @property
    def closed(self) -> bool:
        return self._ptr is None

    def close(self) -> None:
        """Frees children first, then the handle; a second call does nothing."""
        if self._ptr is None:
            return
        for child in list(self._children):
            child.close()
        self._ptr = None
        self._finalizer()
        for parent in self._parents:
            parent._children.discard(self)


def new_world() -> Owner:
    return Owner("world", lib.dWorldCreate())


def new_space() -> Owner:
    space = lib.dHashSpaceCreate(ffi.NULL)
    if space != ffi.NULL:
        lib.dSpaceSetCleanup(space, 0)
    return Owner("space", space)


def new_joint_group(world: Owner) -> Owner:
    return Owner("jointgroup", lib.dJointGroupCreate(0), parents=(world,))


def new_body(world: Owner) -> Owner:
    return Owner("body", lib.dBodyCreate(world.ptr), parents=(world,))


def new_geom(ptr: Any, space: Owner, body: Optional[Owner] = None,
             keep: Tuple[Any, ...] = ()) -> Owner:
    """Adopts a freshly created geom in `space`, attached (by the caller) to `body` if any."""
    parents = (space,) if body is None else (space, body)
    return Owner("geom", ptr, parents=parents, keep=keep)


def new_trimesh(space: Owner, vertices: Any, indices: Any, body: Optional[Owner] = None) -> Owner:
    """A trimesh geom over cffi arrays `vertices` (double[3n]) and `indices` (dTriIndex[3m]).

    The geom's owner keeps both arrays and the trimesh data owner alive; the data is freed
    right after the geom."""
    data = Owner("trimeshdata", lib.dGeomTriMeshDataCreate(), keep=(vertices, indices))
    lib.dGeomTriMeshDataBuildDouble(data.ptr, vertices, 3 * ffi.sizeof("double"),
                                    len(vertices) // 3, indices, len(indices),
                                    3 * ffi.sizeof("dTriIndex"))
    ptr = lib.dCreateTriMesh(space.ptr, data.ptr, ffi.NULL, ffi.NULL, ffi.NULL)
    if ptr == ffi.NULL:
        data.close()
        raise MemoryError("ODE returned NULL for a new trimesh")
    return new_geom(ptr, space, body, keep=(vertices, indices, data))  # data freed after geom


def new_joint(ptr: Any, world: Owner, bodies: Iterable[Owner] = ()) -> Owner:
    return Owner("joint", ptr, parents=(world, *bodies))
