"""Shapes and poses as the Viewer receives them, checked and turned into renderable geometry.

ROS-free and GL-free. Quaternions (w, x, y, z) become rotation matrices through
odin_common.rotations, like everywhere in Odin (:func:`rotation_from_wxyz`).

Shapes follow Messages/Object: the number of parameters decides the shape
(1 sphere radius, 2 cylinder radius and length along the local z axis, centred on the origin,
3 box side lengths x, y, z centred, 9 or more and a multiple of 3: triangle-mesh vertices with
3 indices per triangle). Lengths in metres, in the object's own (body) frame.
"""
from __future__ import annotations

import collections
import hashlib
import itertools
import math
import threading
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from odin_common.errors import InvalidArgument
from odin_common.defaults import PLANE_DRAWN_SIZE, PLANE_DRAWN_THICKNESS
from odin_common.interface import SHAPE_PARAMETERS, Shape, shape_of
from odin_common.limits import MIN_SIZE, shown
from odin_common.meshes import (DISPLAY_TOLERANCE, capsule_mesh, cluster_vertices,  # noqa: F401
                                display_mesh, unique_rows)
from odin_common.rotations import QUATERNION_TOLERANCE, quaternion_to_matrix, unit_quaternion
from odin_common.world_parameters import PARAMETER_INFO
from viewer.errors import ViewerError

_keys = itertools.count(1)

MAX_EXTENT = float(PARAMETER_INFO["world_extent"].high)
"""m: the farthest a position or a mesh vertex may be from the origin along any axis: the
widest ``world_extent`` a world may be set to, so that the Viewer takes every object any world
may hold (the world checks its own, narrower extent) and a camera fitted to them stays finite."""

MAX_SIZE = 2 * MAX_EXTENT
"""m: the largest dimension of a primitive (a world's is twice its extent); the smallest is
odin_common.limits.MIN_SIZE."""


def rotation_from_wxyz(quaternion_wxyz: Sequence[float], where: str = "orientation") -> np.ndarray:
    """Rotation matrix R_WB (3, 3) from a unit quaternion in ODE's order (w, x, y, z).

    A quaternion whose norm is within odin_common.rotations.QUATERNION_TOLERANCE of 1 is
    normalised; one that is not finite, not of length 4 or farther from unit length raises
    :class:`ViewerError`.
    """
    try:
        return quaternion_to_matrix(unit_quaternion(quaternion_wxyz, where))
    except InvalidArgument as error:
        raise ViewerError(str(error)) from None


def check_position(position_W: Sequence[float], where: str = "position") -> np.ndarray:
    """(3,) float, metres; raises :class:`ViewerError` unless three finite numbers."""
    p = np.asarray(position_W, dtype=float).reshape(-1)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ViewerError(f"{where}: expected 3 finite numbers (m), got {shown(p)}")
    if np.max(np.abs(p)) > MAX_EXTENT:
        raise ViewerError(f"{where}: {shown(p.tolist())} is farther than {MAX_EXTENT:g} m from "
                          "the origin along an axis (MAX_EXTENT)")
    return p


def pose_matrix(position_W: Sequence[float], quaternion_wxyz: Sequence[float],
                where: str = "pose") -> np.ndarray:
    """Homogeneous transform T_WB (4, 4) from a position (m) and a (w, x, y, z) quaternion."""
    T = np.eye(4)
    T[:3, :3] = rotation_from_wxyz(quaternion_wxyz, where=f"{where} orientation")
    T[:3, 3] = check_position(position_W, where=f"{where} position")
    return T


def pose_matrices(positions_W: np.ndarray, quaternions_wxyz: np.ndarray) -> tuple:
    """Many poses at once, as :func:`pose_matrix` makes each: (T_WB (n, 4, 4), valid (n,)
    bool) from positions (n, 3) m and quaternions (n, 4) (w, x, y, z). A pose is valid when
    its position is finite and within MAX_EXTENT and its quaternion finite, non-zero and within
    QUATERNION_TOLERANCE of unit length (then normalised); invalid ones are left identity."""
    positions = np.asarray(positions_W, dtype=float).reshape(-1, 3)
    quaternions = np.asarray(quaternions_wxyz, dtype=float).reshape(-1, 4)
    with np.errstate(invalid="ignore", over="ignore"):
        norms = np.linalg.norm(quaternions, axis=1)
        valid = (np.all(np.abs(positions) <= MAX_EXTENT, axis=1) & np.isfinite(norms)
                 & (norms > 0) & (np.abs(norms - 1.0) <= QUATERNION_TOLERANCE))
    poses = np.tile(np.eye(4), (len(positions), 1, 1))
    unit = quaternions[valid] / norms[valid, None]
    if len(unit):
        poses[valid, :3, :3] = np.moveaxis(quaternion_to_matrix(unit.T), -1, 0)
    poses[valid, :3, 3] = positions[valid]
    return poses, valid


@dataclass(frozen=True, eq=False)
class Geometry:
    """A shape ready to draw.

    kind: "sphere", "cylinder", "box" or "mesh".
    scale_B: (3,) factors applied to the kind's unit primitive (sphere radius 1, cylinder radius 1
        and length 1 along z, box of side 1, all centred); (1, 1, 1) for meshes.
    vertices_B, normals_B: (n, 3) float32, body frame, metres, and indices_B (3 m,) uint32, three
        per triangle; meshes only, empty for primitives.
    radius: m, radius of a sphere about the body origin that holds the whole shape.
    closed: the surface is closed and its triangles face outwards (counter-clockwise), so back
        faces are never seen: the renderer culls them and lights one side only.
    bounded: False for a plane (infinite in the world, drawn as a large floor): the camera
        fits the scene without it.
    key: unique per Geometry, so that a renderer can cache GPU buffers by it.
    levels: a large mesh's levels of detail (:class:`MeshLevels`); None for primitives and
        small meshes.
    """
    kind: str
    scale_B: tuple
    radius: float
    vertices_B: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))
    normals_B: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))
    indices_B: np.ndarray = field(default_factory=lambda: np.zeros(0, np.uint32))
    closed: bool = True
    bounded: bool = True
    key: int = field(default_factory=lambda: next(_keys))
    levels: "MeshLevels | None" = None

    @property
    def triangle_count(self) -> int:
        return len(self.indices_B) // 3

    def detail(self, cell: float) -> tuple:
        """(level, vertices_B, normals_B, indices_B) to draw this mesh with where detail finer
        than ``cell`` m is lost on screen (its levels of detail, :class:`MeshLevels`); level 0
        (these arrays) for a mesh without levels."""
        if self.levels is None:
            return 0, self.vertices_B, self.normals_B, self.indices_B
        return self.levels.for_cell(cell)


def _positive(values: Sequence[float], names: Sequence[str], shape: str) -> list:
    """The sizes (m), each finite and in [MIN_SIZE, MAX_SIZE]."""
    out = []
    for value, name in zip(values, names):
        if not math.isfinite(value) or not MIN_SIZE <= value <= MAX_SIZE:
            raise ViewerError(f"{shape} {name} must be a finite number in [{MIN_SIZE:g}, "
                              f"{MAX_SIZE:g}] m (MIN_SIZE, MAX_SIZE), got {shown(value)}")
        out.append(float(value))
    return out


# PLANE_DRAWN_SIZE, PLANE_DRAWN_THICKNESS (m): a plane (infinite in the world) is drawn as a
# square floor this wide, this thin, its top face on the plane (odin_common.interface)


def geometry_from_parameters(parameters: Sequence[float], indices: Sequence[int] = (),
                             shape: int = Shape.BY_COUNT) -> Geometry:
    """The shape that ``parameters`` (and, for meshes, ``indices``) describe, asked for as
    ``shape`` (odin_common.interface.Shape; 0: by their count); see the module doc.

    Raises :class:`ViewerError` for a wrong parameter count, sizes not finite or outside
    [MIN_SIZE, MAX_SIZE], mesh vertices beyond MAX_EXTENT, an empty mesh, an index count that
    is not a multiple of 3 or an index out of range.
    """
    params = np.asarray(parameters, dtype=float).reshape(-1)
    try:
        kind = shape_of(params.size, shape)
    except InvalidArgument as error:
        raise ViewerError(str(error)) from None
    names = [f"side {name}" if kind == Shape.BOX else name
             for name in SHAPE_PARAMETERS.get(kind, ())]
    if kind == Shape.SPHERE:
        (r,) = _positive(params, names, "sphere")
        return Geometry("sphere", (r, r, r), r)
    if kind == Shape.CYLINDER:
        r, length = _positive(params, names, "cylinder")
        return Geometry("cylinder", (r, r, length), math.hypot(r, length / 2))
    if kind == Shape.BOX:
        sides = _positive(params, names, "box")
        return Geometry("box", tuple(sides), 0.5 * math.sqrt(sum(s * s for s in sides)))
    if kind == Shape.CAPSULE:
        return capsule_geometry(*_positive(params, names, "capsule"))
    if kind == Shape.PLANE:
        return Geometry("box", (PLANE_DRAWN_SIZE, PLANE_DRAWN_SIZE, PLANE_DRAWN_THICKNESS), 0.0,
                        bounded=False)
    return mesh_geometry(params.reshape(-1, 3), indices)


def capsule_geometry(radius: float, length: float, slices: int = 32, stacks: int = 8
                     ) -> Geometry:
    """A capsule: a cylinder of ``length`` along z with hemispheres of ``radius`` at both
    ends, as one closed mesh (m; odin_common.meshes.capsule_mesh)."""
    return mesh_geometry(*capsule_mesh(radius, length, slices, stacks))


#: corners whose face turns more than this from the smoothed vertex normal get a vertex of
#: their own with the face's normal (hard edges stay hard, curved surfaces look smooth)
CREASE_ANGLE = math.radians(40.0)

#: Levels of detail: level k of a mesh clusters its vertices on a grid of
#: DISPLAY_TOLERANCE * 2**k m, k = 0 .. LOD_LEVELS - 1 (1 to 32 mm). Meshes of fewer
#: than LOD_MIN_TRIANGLES triangles are always drawn whole.
LOD_LEVELS = 6
LOD_MIN_TRIANGLES = 500


# Meshes of more than DISPLAY_DETAIL_TRIANGLES triangles are drawn with their vertices clustered
# at DISPLAY_TOLERANCE (odin_common.meshes.display_mesh, shared with the world's RViz markers).


def mesh_geometry(vertices_B: np.ndarray, indices: Sequence[int]) -> Geometry:
    """An indexed mesh from vertices (n, 3) m and triangle indices (3 per triangle), with
    area-weighted vertex normals split at creases sharper than ``CREASE_ANGLE``; large meshes
    are simplified for display (clustered at ``DISPLAY_TOLERANCE``). A closed mesh wound
    inwards (clockwise, as some Kautham VRML files are) is turned outwards, so that it is drawn
    as a closed one: back faces culled, one side lit (half the cost of an open one)."""
    vertices = np.asarray(vertices_B, dtype=float)
    if not np.all(np.abs(vertices) <= MAX_EXTENT):       # False for NaN too
        raise ViewerError(f"mesh vertices must be finite numbers within {MAX_EXTENT:g} m of "
                          "the origin along each axis (MAX_EXTENT)")
    idx = np.asarray(indices, dtype=np.int64).reshape(-1)
    if idx.size == 0:
        raise ViewerError(f"mesh with {len(vertices)} vertices has no triangles (empty indices)")
    if idx.size % 3:
        raise ViewerError(f"mesh indices come 3 per triangle; got {idx.size}")
    bad = (idx < 0) | (idx >= len(vertices))
    if np.any(bad):
        raise ViewerError(f"mesh index {int(idx[bad][0])} out of range: the mesh has "
                          f"{len(vertices)} vertices")
    winding = _closed_winding(vertices, idx.reshape(-1, 3))
    if winding < 0:
        idx = idx.reshape(-1, 3)[:, ::-1].reshape(-1)
    vertices, idx = display_mesh(vertices, idx)
    drawn = _shaded(vertices, idx)
    radius = float(np.max(np.linalg.norm(vertices[np.unique(idx)], axis=1)))
    levels = MeshLevels(vertices, idx, drawn) if len(idx) // 3 >= LOD_MIN_TRIANGLES else None
    return Geometry("mesh", (1.0, 1.0, 1.0), radius, vertices_B=drawn[0], normals_B=drawn[1],
                    indices_B=drawn[2], closed=winding != 0, levels=levels)


def _shaded(vertices: np.ndarray, idx: np.ndarray) -> tuple:
    """(vertices (n', 3) float32, normals (n', 3) float32, indices (3 t,) uint32) of an
    indexed mesh with area-weighted vertex normals, corners at creases sharper than
    CREASE_ANGLE given a vertex of their own with the face's normal."""
    corners = vertices[idx].reshape(-1, 3, 3)
    area_normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(area_normals, axis=1, keepdims=True)
    face_normals = np.where(lengths > 1e-20, area_normals / np.maximum(lengths, 1e-300),
                            [0.0, 0.0, 1.0])
    # per axis, the sums in corner order as np.add.at would make them, many times faster
    corner_normals = np.repeat(area_normals, 3, axis=0)
    vertex_normals = np.stack([np.bincount(idx, weights=corner_normals[:, k],
                                           minlength=len(vertices)) for k in range(3)], axis=1)
    norms = np.linalg.norm(vertex_normals, axis=1, keepdims=True)
    vertex_normals = vertex_normals / np.maximum(norms, 1e-300)
    corner_face = np.repeat(face_normals, 3, axis=0)
    sharp = np.einsum("ij,ij->i", vertex_normals[idx], corner_face) < math.cos(CREASE_ANGLE)
    out_idx = idx.copy()
    out_idx[sharp] = len(vertices) + np.arange(int(sharp.sum()))
    return (np.concatenate([vertices, vertices[idx[sharp]]]).astype(np.float32),
            np.concatenate([vertex_normals, corner_face[sharp]]).astype(np.float32),
            out_idx.astype(np.uint32))


class MeshLevels:
    """A mesh's levels of detail, each made the first time it is asked for: level k clusters
    the drawn mesh's vertices on a grid of DISPLAY_TOLERANCE * 2**k m
    (odin_common.meshes.cluster_vertices, which keeps the surface within a cell's diagonal of
    the mesh), so a mesh that covers few pixels is drawn with few triangles. On llvmpipe a
    frame's cost grows with its triangles: the SAH hand's 95k triangles, a few dozen pixels
    tall in the Viewer's default view, cost most of a frame."""

    def __init__(self, vertices: np.ndarray, idx: np.ndarray, level0: tuple):
        """``vertices``, ``idx``: the drawn mesh before shading; ``level0``: its shaded
        (vertices, normals, indices) (:func:`_shaded`)."""
        self._vertices = vertices
        self._idx = idx
        self._made: dict = {0: level0}

    def for_cell(self, cell: float) -> tuple:
        """(level, vertices, normals, indices) of the coarsest level whose grid is at most
        ``cell`` m; a level whose triangles all collapse is never used (the one before it
        is)."""
        wanted = 0
        while wanted + 1 < LOD_LEVELS and DISPLAY_TOLERANCE * 2 ** (wanted + 1) <= cell:
            wanted += 1
        for level in range(wanted, 0, -1):
            arrays = self._made.get(level)
            if arrays is None:
                arrays = self._made[level] = self._make(level)
            if arrays:
                return (level, *arrays)
        return (0, *self._made[0])

    def _make(self, level: int) -> tuple:
        vertices, idx = cluster_vertices(self._vertices, self._idx,
                                         DISPLAY_TOLERANCE * 2 ** level)
        return _shaded(vertices, idx) if idx.size else ()


def _closed_winding(vertices: np.ndarray, triangles: np.ndarray) -> int:
    """+1 when the surface is closed and wound outwards (counter-clockwise seen from outside),
    -1 when closed and wound inwards, 0 when open or wound inconsistently. Closed: with
    vertices at the same place taken as one, collapsed triangles left out and a repeated one
    counted once (CAD meshes have both), every edge is met as often in one direction as in
    the other (no boundary, neighbours wound alike). Wound: the sign of the enclosed volume."""
    t = _welded(vertices)[triangles]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])]
    if len(t) == 0:
        return 0
    first = np.argmin(t, axis=1)[:, None]          # a repeated triangle counts once
    t = np.take_along_axis(t, (first + np.arange(3)) % 3, axis=1)
    t = t[unique_rows(t, return_index=True)[1]]
    edges = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    n = int(t.max()) + 1
    forward = np.sort(edges[:, 0] * n + edges[:, 1])
    backward = np.sort(edges[:, 1] * n + edges[:, 0])
    if not np.array_equal(forward, backward):
        return 0
    corners = vertices[triangles]
    volume = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum()
    return 1 if volume > 0 else -1 if volume < 0 else 0


def _welded(vertices: np.ndarray) -> np.ndarray:
    """(n,) int64: for each vertex, the index of its position among the distinct positions
    (as np.unique(vertices, axis=0, return_inverse=True) numbers them, 3-5 times faster: a
    lexicographic sort of the coordinates instead of a sort of rows as records)."""
    if len(vertices) == 0:
        return np.zeros(0, np.int64)
    order = np.lexsort(vertices.T[::-1])            # by x, then y, then z
    ordered = vertices[order]
    starts = np.ones(len(vertices), bool)
    starts[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    welded = np.empty(len(vertices), np.int64)
    welded[order] = np.cumsum(starts) - 1
    return welded


# -- unit primitives, tessellated once ------------------------------------------------------

def unit_sphere(slices: int = 32, stacks: int = 16) -> tuple:
    """Radius-1 sphere: (vertices (n, 3), normals (n, 3), triangle indices (m,)), smooth."""
    theta = np.linspace(0.0, math.pi, stacks + 1)          # from +z down to -z
    phi = np.linspace(0.0, 2 * math.pi, slices + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    vertices = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    vertices = vertices.reshape(-1, 3)
    indices = []
    row = slices + 1
    for i in range(stacks):
        for j in range(slices):
            a, b = i * row + j, (i + 1) * row + j
            indices += [a, b, b + 1, a, b + 1, a + 1]
    return vertices.astype(np.float32), vertices.astype(np.float32), np.array(indices, np.uint32)


def unit_cylinder(slices: int = 32) -> tuple:
    """Radius 1, length 1 along z, centred: smooth side, flat caps."""
    phi = np.linspace(0.0, 2 * math.pi, slices + 1)
    ring = np.stack([np.cos(phi), np.sin(phi), np.zeros_like(phi)], -1)
    verts, norms, idx = [], [], []
    # side: rings at z = -1/2 and +1/2
    for z in (-0.5, 0.5):
        verts.append(ring + [0, 0, z])
        norms.append(ring)
    n = slices + 1
    for j in range(slices):
        a, b = j, n + j
        idx += [a, a + 1, b + 1, a, b + 1, b]
    base = 2 * n
    for z, sign in ((0.5, 1.0), (-0.5, -1.0)):
        centre = base
        verts.append(np.array([[0.0, 0.0, z]]))
        verts.append(ring + [0, 0, z])
        norms.append(np.tile([0.0, 0.0, sign], (n + 1, 1)))
        for j in range(slices):
            a, b = centre + 1 + j, centre + 2 + j
            idx += [centre, a, b] if sign > 0 else [centre, b, a]
        base += n + 1
    return (np.concatenate(verts).astype(np.float32), np.concatenate(norms).astype(np.float32),
            np.array(idx, np.uint32))


def unit_box() -> tuple:
    """Side 1, centred: 6 flat faces, outward normals, counter-clockwise."""
    verts, norms, idx = [], [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            normal = np.zeros(3)
            normal[axis] = sign
            u = np.zeros(3)
            u[(axis + 1) % 3] = 1.0
            v = np.cross(normal, u)
            centre = normal * 0.5
            start = len(verts)
            for du, dv in ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)):
                verts.append(centre + du * u + dv * v)
                norms.append(normal)
            idx += [start, start + 1, start + 2, start, start + 2, start + 3]
    return np.array(verts, np.float32), np.array(norms, np.float32), np.array(idx, np.uint32)


#: triangles a :class:`GeometryCache` keeps at most (about 60 bytes each with their levels of
#: detail): several problems' worth of meshes (the TX90 grasp scene has ~200,000)
GEOMETRY_CACHE_TRIANGLES = 2_000_000

#: geometries a :class:`GeometryCache` keeps at most, whatever their triangles: each costs
#: ~1 KB beyond its triangles, so many small distinct meshes (a client sending shapes of
#: random sizes) stay within ~4 MB; the largest scenes hold a few hundred
GEOMETRY_CACHE_ENTRIES = 4096


class GeometryCache:
    """Geometries built before, by content: the same parameters, indices and shape give the
    same Geometry object again, without building it (a mesh's welding, shading and
    clustering cost ~20 ms per 10,000 triangles). A world re-sends its whole scene on every
    problem load and on every Viewer restart; so does a bag of markers played in a loop.

    Only meshes are kept (capsules are meshes too): a primitive (sphere, cylinder, box,
    plane) costs microseconds to build and saves nothing, and every size sent would stay
    (a soak's thousands of random spheres and boxes grew the Viewer by ~0.8 KB each).
    Least recently used geometries go first once more than ``max_triangles`` or more than
    ``max_entries`` are kept. Thread-safe: service threads and the render thread share one.
    A Geometry is immutable (its levels of detail are made on the render thread only), so
    objects may share one."""

    def __init__(self, max_triangles: int = GEOMETRY_CACHE_TRIANGLES,
                 max_entries: int = GEOMETRY_CACHE_ENTRIES) -> None:
        self.max_triangles = max_triangles
        self.max_entries = max_entries
        self._geometries: "collections.OrderedDict[bytes, Geometry]" = collections.OrderedDict()
        self._triangles = 0
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    def __len__(self) -> int:
        return len(self._geometries)

    def geometry(self, parameters: Sequence[float], indices: Sequence[int] = (),
                 shape: int = Shape.BY_COUNT) -> Geometry:
        """:func:`geometry_from_parameters`, from the cache when built before. Refusals are
        raised every time (nothing is kept for them)."""
        key = _content_key(parameters, indices, shape)
        with self._lock:
            found = self._geometries.get(key)
            if found is not None:
                self._geometries.move_to_end(key)
                self.hits += 1
                return found
        built = geometry_from_parameters(parameters, indices, shape)
        with self._lock:
            self.misses += 1
            if built.kind != "mesh":
                return built                # nothing to save by keeping it
            if key not in self._geometries:
                self._geometries[key] = built
                self._triangles += built.triangle_count
                self._evict()
            return self._geometries[key]

    def _evict(self) -> None:
        while len(self._geometries) > 1 and (self._triangles > self.max_triangles
                                             or len(self._geometries) > self.max_entries):
            _, oldest = self._geometries.popitem(last=False)
            self._triangles -= oldest.triangle_count


def _content_key(parameters: Sequence[float], indices: Sequence[int], shape: int) -> bytes:
    """A digest of what decides a geometry: the shape asked for, the parameters as float64
    and the indices as int64 (the same values sent as a list, a tuple or an array give the
    same key)."""
    digest = hashlib.blake2b(digest_size=20)
    digest.update(int(shape).to_bytes(4, "little", signed=True))
    params = np.ascontiguousarray(np.asarray(parameters, dtype="<f8").reshape(-1))
    digest.update(params.size.to_bytes(8, "little"))
    digest.update(params)                   # the array's own buffer: no copy
    digest.update(np.ascontiguousarray(np.asarray(indices, dtype="<i8").reshape(-1)))
    return digest.digest()
