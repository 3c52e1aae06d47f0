"""Mass properties of shapes: primitives by ODE's formulas, triangle meshes from trimesh (never
ODE's dMassSetTrimesh, which is wrong for meshes whose origin is not their centre of mass),
and the checks that keep ODE from seeing mass no rigid body has.

Meshes:
  * closed mesh (``is_watertight``): normals repaired (``trimesh.repair.fix_normals``), an
    inverted mesh turned outside-out, density = mass / |volume|; the exact centre of mass and
    inertia about it follow (trimesh's surface-integral formulas);
  * open mesh (or one that stays non-volumetric after the repair, or whose surface integrals
    give no rigid body's inertia, as a closed but self-intersecting mesh's do: the 2012 TX90's
    Tcp; a third of Kautham's link meshes are open or hold several bodies): the mesh's
    axis-aligned bounding box as a solid
    box of the given mass, centred on the box. (The convex hull would be tighter but needs
    scipy, which Odin does not depend on.) A mesh flat in one direction gets a flat box's
    inertia; one flat in two directions is an error.
The result is expressed in the mesh's own frame.
"""
from __future__ import annotations

import hashlib
import sys
import threading
from typing import TYPE_CHECKING, Dict, NamedTuple, Optional

import numpy as np

from virtual_world.core.shapes import Shape
from virtual_world.errors import InvalidArgument
from virtual_world.ode import bodies
from virtual_world.ode.runtime import log

if TYPE_CHECKING:
    import trimesh


class MeshMass(NamedTuple):
    """mass: kg; center: (3,) m, mesh frame; inertia: (3,3) kg m^2 about `center`, mesh axes;
    rule: "closed" or "bounding box" (which rule gave the figures)."""
    mass: float
    center: np.ndarray
    inertia: np.ndarray
    rule: str


def _solid(mesh: trimesh.Trimesh, mass: float):
    if mesh.volume < 0:
        mesh.invert()
    volume = float(mesh.volume)
    if not np.isfinite(volume) or volume <= 1e-15 * max(mesh.scale, 1e-12) ** 3:
        return None
    mesh.density = mass / volume
    center, inertia = np.asarray(mesh.center_mass, float), np.asarray(mesh.moment_inertia, float)
    if not (np.all(np.isfinite(center)) and _rigid(inertia)):
        return None     # a closed but self-intersecting mesh: no solid's figures
    return center, inertia


def _rigid(inertia: np.ndarray) -> bool:
    """Whether ``inertia`` (3, 3) is a rigid body's: finite, positive definite, principal
    moments meeting the triangle inequality."""
    if not np.all(np.isfinite(inertia)):
        return False
    principal = np.linalg.eigvalsh(inertia)
    return principal[0] > 0 and principal[0] + principal[1] >= principal[2] * (1 - 1e-9)


_PRELOAD: Optional[threading.Thread] = None


def preload_trimesh() -> None:
    """Starts importing trimesh (with scipy: ~0.4 s) on a thread of its own, for a node that
    has just started serving: imported on the first mesh instead, it was more than half of a
    fresh world's first load of the TX90 + hand (0.58 of 1.0 s of Core time). Imported at
    start-up on the node's own thread, it had been a third of every world node's start-up,
    and most worlds never build a mesh. Only this thread imports it: ``mesh_mass`` waits for
    it first (two threads importing the same modules at once can deadlock)."""
    global _PRELOAD
    if _PRELOAD is None and "trimesh" not in sys.modules:
        _PRELOAD = threading.Thread(target=_import_trimesh, name="preload trimesh", daemon=True)
        _PRELOAD.start()


def join_preload(timeout: Optional[float] = None) -> None:
    """Waits for ``preload_trimesh``'s import (a node exiting lets it end first: a daemon
    thread cut off mid-import at interpreter shutdown can abort the process)."""
    if _PRELOAD is not None:
        _PRELOAD.join(timeout)


def _import_trimesh() -> None:
    try:
        import trimesh  # noqa: F401
    except Exception:   # mesh_mass imports it again and raises where a mesh needs it
        pass


def mesh_mass(vertices: np.ndarray, triangles: np.ndarray, mass: float) -> MeshMass:
    """Mass properties of a mesh: vertices (n,3) m, triangles (m,3) indices, mass kg > 0."""
    join_preload()
    import trimesh
    mesh = trimesh.Trimesh(np.asarray(vertices, float), np.asarray(triangles, np.int64),
                           process=True, validate=False)
    if mesh.is_watertight:
        trimesh.repair.fix_normals(mesh)
        if mesh.is_volume:
            solid = _solid(mesh, mass)
            if solid is not None:
                return MeshMass(mass, solid[0], solid[1], "closed")
    low, high = np.asarray(vertices, float).min(axis=0), np.asarray(vertices, float).max(axis=0)
    x, y, z = high - low
    if sum(side > 0 for side in (x, y, z)) < 2:
        raise InvalidArgument(f"mesh is degenerate (bounding box sides {x}, {y}, {z})")
    inertia = mass / 12.0 * np.diag([y * y + z * z, x * x + z * z, x * x + y * y])
    return MeshMass(mass, (low + high) / 2.0, inertia, "bounding box")


_MESH_MASS_CACHE: Dict[bytes, MeshMass] = {}
"""LRU of unit-mass mesh properties (the same robot's meshes come back on every New Scene),
keyed by a digest of the mesh's bytes: an entry costs ~200 bytes however large the mesh (keyed
by the bytes themselves, a refused 50 MB mesh had stayed in memory)."""
_MESH_MASS_CACHE_SIZE = 256


def mesh_digest(vertices: np.ndarray, triangles: np.ndarray) -> bytes:
    """A 32-byte digest of a mesh's exact vertices and triangles (their dtypes' bytes)."""
    digest = hashlib.blake2b(digest_size=32)
    digest.update(np.ascontiguousarray(vertices).view(np.uint8).reshape(-1))
    digest.update(b"|")
    digest.update(np.ascontiguousarray(triangles).view(np.uint8).reshape(-1))
    return digest.digest()


def _unit_mesh_mass(what: str, shape: Shape) -> MeshMass:
    key = mesh_digest(shape.vertices, shape.triangles)
    unit = _MESH_MASS_CACHE.pop(key, None)
    if unit is None:  # mass properties of a unit mass scale linearly with the mass
        unit = mesh_mass(shape.vertices, shape.triangles, 1.0)
        if unit.rule != "closed":
            log.info("%s: open mesh, inertia from its %s", what, unit.rule)
    _MESH_MASS_CACHE[key] = unit  # most recently used last
    while len(_MESH_MASS_CACHE) > _MESH_MASS_CACHE_SIZE:
        del _MESH_MASS_CACHE[next(iter(_MESH_MASS_CACHE))]
    return unit


def shape_mass(what: str, shape: Shape, mass: float):
    """dMass of ``shape`` with total ``mass`` kg, in the shape's frame (its centre of mass may
    be off the origin)."""
    if shape.kind != "mesh":
        return bodies.primitive_mass(shape.kind, shape.dims, mass)
    unit = _unit_mesh_mass(what, shape)
    return bodies.mass_from_parameters(mass, unit.center.tolist(), unit.inertia * mass)


def check_mass(what: str, dmass) -> None:
    """InvalidArgument unless the (centred) dMass is one a rigid body can have: inertia
    positive definite, principal moments meeting the triangle inequality, and ODE agreeing."""
    matrix = bodies.inertia_matrix(dmass)
    if not np.all(np.isfinite(matrix)) or np.min(np.linalg.eigvalsh(matrix)) <= 0:
        raise InvalidArgument(f"{what}: inertia {matrix.tolist()} is not positive definite")
    principal = np.linalg.eigvalsh(matrix)
    if principal[0] + principal[1] < principal[2] * (1 - 1e-9):
        raise InvalidArgument(f"{what}: principal moments {principal.tolist()} break the "
                              "triangle inequality (no rigid body has them)")
    if not bodies.mass_is_valid(dmass):
        raise InvalidArgument(f"{what}: ODE rejects the mass parameters (dMassCheck)")
