"""Triangle-mesh simplification shared by the nodes: vertex clustering on a grid.

The VirtualWorld collides with meshes clustered at its ``collision_mesh_tolerance`` and the
Viewer draws large meshes clustered at its display tolerance. Clustering bounds the error: a
vertex moves at most one cell diagonal (sqrt(3) x the cell size), so the simplified surface
stays within that distance of the given one, whatever the mesh's topology. Measured on the
SAH hand's CAD meshes: clustered at 4 mm, its links stay within 2.7 mm of their surfaces
(the palm keeps 6,800 of 20,400 triangles); quadric edge-collapse decimation (the
fast-simplification package) strayed 7 mm at 3,000 triangles and 16 mm at 900.
"""
from __future__ import annotations

import math
from typing import Sequence, Tuple

import numpy as np

DISPLAY_TOLERANCE = 0.001
"""m: meshes of more than DISPLAY_DETAIL_TRIANGLES triangles are drawn (by the Viewer, and in
the world's RViz markers) with their vertices clustered on a grid of this size: detail finer
than a millimetre is below a pixel at the distances a robot scene is watched from, and CAD
meshes of hands carry a lot of it (the SAH hand's 150k triangles become about half). The
world's collision mesh has a tolerance of its own (the world parameter
collision_mesh_tolerance)."""
DISPLAY_DETAIL_TRIANGLES = 2000


def cluster_vertices(vertices: np.ndarray, indices: np.ndarray,
                     cell: float) -> Tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) m in the same cube of edge ``cell`` m become their mean; triangles
    (``indices``, 3 per triangle) that collapse or repeat are dropped, the rest keep their
    winding. Returns (vertices (k, 3) float64, indices (3 t,) int64); t may be 0 when the
    whole mesh fits in a few cells."""
    vertices = np.asarray(vertices, dtype=float).reshape(-1, 3)
    indices = np.asarray(indices, dtype=np.int64).reshape(-1)
    if not cell > 0:
        raise ValueError(f"cluster cell {cell!r} must be a positive length (m)")
    cells = np.floor(vertices / cell).astype(np.int64)
    _, cluster = unique_rows(cells, return_inverse=True)
    cluster = cluster.reshape(-1)
    count = int(cluster.max()) + 1
    # per axis, the sums in vertex order as np.add.at would make them, many times faster
    merged = np.stack([np.bincount(cluster, weights=vertices[:, k], minlength=count)
                       for k in range(3)], axis=1)
    merged /= np.bincount(cluster, minlength=count)[:, None]
    triangles = cluster[indices].reshape(-1, 3)
    keep = ((triangles[:, 0] != triangles[:, 1]) & (triangles[:, 1] != triangles[:, 2])
            & (triangles[:, 0] != triangles[:, 2]))
    triangles = triangles[keep]
    _, first = unique_rows(np.sort(triangles, axis=1), return_index=True)
    return merged, triangles[np.sort(first)].reshape(-1)


def unique_rows(rows: np.ndarray, **options):
    """``np.unique(rows, axis=0, **options)`` for an (n, 3) int64 array, the same answer in the
    same order: each row packed into one int64 that sorts as the row does (ten times faster
    than numpy's sort of rows as records, which set the time of loading a CAD hand), unless
    the rows' span does not fit in 63 bits."""
    if len(rows) == 0:
        return np.unique(rows, axis=0, **options)
    low = rows.min(axis=0)
    span = rows.max(axis=0) - low + 1
    if math.prod(int(n) for n in span) >= 2 ** 63:
        return np.unique(rows, axis=0, **options)
    shifted = rows - low
    keys = (shifted[:, 0] * span[1] + shifted[:, 1]) * span[2] + shifted[:, 2]
    return np.unique(keys, **options)


def display_mesh(vertices: np.ndarray, indices: Sequence[int]) -> Tuple[np.ndarray, np.ndarray]:
    """The mesh as it is drawn: clustered at DISPLAY_TOLERANCE when it has more than
    DISPLAY_DETAIL_TRIANGLES triangles (a mesh smaller than the tolerance keeps its triangles).
    Returns (vertices (k, 3) float64 m, indices (3 t,) int64)."""
    vertices = np.asarray(vertices, dtype=float).reshape(-1, 3)
    indices = np.asarray(indices, dtype=np.int64).reshape(-1)
    if indices.size > 3 * DISPLAY_DETAIL_TRIANGLES:
        simple_vertices, simple_indices = cluster_vertices(vertices, indices, DISPLAY_TOLERANCE)
        if simple_indices.size:
            return simple_vertices, simple_indices
    return vertices, indices


def facing_outwards(vertices: np.ndarray, indices: Sequence[int]) -> np.ndarray:
    """``indices`` (3 t,) with every triangle's winding reversed when the mesh's signed volume
    is negative (a mesh wound clockwise, as some Kautham VRML files are): renderers that light
    one side only (RViz's TRIANGLE_LIST) then light the outside. An open mesh is judged by the
    same sum, which is right for a mostly consistent one."""
    triangles = np.asarray(indices, dtype=np.int64).reshape(-1, 3)
    corners = np.asarray(vertices, dtype=float).reshape(-1, 3)[triangles]
    volume = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum()
    return (triangles[:, ::-1] if volume < 0 else triangles).reshape(-1)


def capsule_mesh(radius: float, length: float, slices: int = 32, stacks: int = 8
                 ) -> Tuple[np.ndarray, np.ndarray]:
    """A capsule as one closed mesh: a cylinder of ``length`` m along z with hemispheres of
    ``radius`` m at both ends. Returns (vertices (n, 3) m, indices (3 t,) int64), triangles
    counter-clockwise seen from outside."""
    rings = []   # (z, ring radius) between the poles, from the bottom up
    for k in range(1, stacks + 1):       # bottom hemisphere, to the equator
        a = -math.pi / 2 + k * math.pi / 2 / stacks
        rings.append((-length / 2 + radius * math.sin(a), radius * math.cos(a)))
    for k in range(stacks):              # top hemisphere, from the equator
        a = k * math.pi / 2 / stacks
        rings.append((length / 2 + radius * math.sin(a), radius * math.cos(a)))
    angles = np.linspace(0.0, 2 * math.pi, slices, endpoint=False)
    top = len(rings) * slices + 1
    vertices = np.array([(0.0, 0.0, -length / 2 - radius)]
                        + [(r * math.cos(t), r * math.sin(t), z) for z, r in rings
                           for t in angles] + [(0.0, 0.0, length / 2 + radius)])
    triangles = []
    for k in range(slices):              # the poles' fans, counter-clockwise seen outside
        triangles += [(0, 1 + (k + 1) % slices, 1 + k),
                      (top, top - slices + k, top - slices + (k + 1) % slices)]
    for ring in range(len(rings) - 1):
        for k in range(slices):
            a, b = 1 + ring * slices + k, 1 + ring * slices + (k + 1) % slices
            triangles += [(a, b, b + slices), (a, b + slices, a + slices)]
    return vertices, np.array(triangles, dtype=np.int64).reshape(-1)
