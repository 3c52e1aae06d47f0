"""Shapes as the Core builds them: checked from Object/Part parameters (the thesis's
shape-by-parameter-count rule, odin_common.interface.shape_kind), and the mesh ODE collides
with (the given one, or its vertices clustered under the world's collision_mesh_tolerance).
Lengths in metres, in the object's (or part's) frame."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from odin_common import errors as common
from odin_common.interface import shape_kind
from odin_common.limits import shown
from odin_common.meshes import cluster_vertices
from virtual_world.errors import InvalidArgument

#: a mesh fewer cells across than this (its bounding box's longest side) collides as given:
#: clustered, it would keep too little of its shape to be worth the saving
MIN_CELLS_ACROSS = 6


@dataclass(frozen=True, eq=False)
class Shape:
    """A checked shape: kind "sphere" | "cylinder" | "box" | "capsule" | "plane" | "mesh";
    dims for primitives (m; none for a plane); vertices (n, 3) float64 m and triangles (m, 3)
    uint32 for meshes."""
    kind: str
    dims: Tuple[float, ...] = ()
    vertices: Optional[np.ndarray] = None
    triangles: Optional[np.ndarray] = None


def prepare_shape(what: str, parameters, indices, shape: int = 0) -> Shape:
    """The Shape of Object/Part ``parameters`` and ``indices`` asked for as ``shape``
    (odin_common.interface.Shape; 0: by the count of parameters); InvalidArgument naming
    ``what`` when they describe none (or a mesh whose every triangle is degenerate)."""
    try:
        values = np.array(parameters, dtype=float).reshape(-1)
        index_values = np.array(indices, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}: parameters/indices are not numbers") from None
    if not np.all(np.isfinite(values)):
        raise InvalidArgument(f"{what}: parameters {shown(list(parameters))} are not finite")
    try:
        kind = shape_kind(values.size, shape)
    except common.InvalidArgument as error:
        raise InvalidArgument(f"{what}: {error}") from None
    if kind != "mesh":
        if index_values.size:
            raise InvalidArgument(f"{what}: indices given for a primitive ({values.size} "
                                  "parameters)")
        if np.any(values <= 0):
            raise InvalidArgument(f"{what}: sizes {values.tolist()} must be positive")
        return Shape(kind, tuple(values.tolist()))
    return _mesh(what, values.reshape(-1, 3), index_values)


def _mesh(what: str, vertices: np.ndarray, index_values: np.ndarray) -> Shape:
    if index_values.size == 0 or index_values.size % 3:
        raise InvalidArgument(
            f"{what}: a mesh needs indices, 3 per triangle; got {index_values.size}")
    if not np.all(index_values == np.round(index_values)):
        raise InvalidArgument(f"{what}: mesh indices must be integers")
    low, high = index_values.min(), index_values.max()
    if low < 0 or high >= len(vertices):
        bad = low if low < 0 else high
        raise InvalidArgument(
            f"{what}: mesh index {int(bad)} out of range [0, {len(vertices) - 1}]")
    triangles = index_values.astype(np.uint32).reshape(-1, 3)
    corners = vertices[triangles]
    areas = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                           axis=1)
    if not np.any(areas > 1e-12 * max(float(np.ptp(vertices)), 1e-12) ** 2):
        raise InvalidArgument(f"{what}: every mesh triangle is degenerate")
    return Shape("mesh", (), np.ascontiguousarray(vertices), np.ascontiguousarray(triangles))


def collision_mesh(shape: Shape, tolerance: float) -> Tuple[np.ndarray, np.ndarray]:
    """The (vertices (n, 3) m, triangles (m, 3)) ODE collides with: the given mesh, or its
    vertices clustered at ``tolerance`` m (WorldParameters.collision_mesh_tolerance) when the
    mesh is at least MIN_CELLS_ACROSS cells across."""
    extent = float(np.ptp(shape.vertices, axis=0).max())
    if tolerance <= 0 or extent < MIN_CELLS_ACROSS * tolerance:
        return shape.vertices, shape.triangles
    vertices, indices = cluster_vertices(shape.vertices, shape.triangles, tolerance)
    if indices.size == 0:
        return shape.vertices, shape.triangles
    return vertices, indices.astype(np.uint32).reshape(-1, 3)
