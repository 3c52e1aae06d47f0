"""Odin's shapes, in metres: a triangle ``Mesh``, ``Primitive``s (sphere, cylinder, box) and the
``Shape`` of one geometry file holding both, in the file's (link's) frame; values with the
rigid and scaling maps a model applies to them. The readers of geometry files return them
(``gui.core.shapes``), the shape cache stores them (``gui.core.shape_cache``)."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Optional

import numpy as np

from gui.core.kautham.units import lengths_problem, scale_problem
from gui.errors import ShapeError

DEFAULT_COLOR = (0.0, 0.0, 0.0, 0.0)
"""RGBA all zero: the Viewer's default colour (a file that gives none)."""


@dataclass(frozen=True, eq=False)
class Mesh:
    """A triangle mesh: ``vertices`` (N, 3) float64, m; ``triangles`` (M, 3) uint32,
    counter-clockwise seen from outside as the file gives them."""
    vertices: np.ndarray
    triangles: np.ndarray
    color: tuple = DEFAULT_COLOR


@dataclass(frozen=True, eq=False)
class Primitive:
    """A sphere, cylinder (along its frame's z) or box; ``parameters`` as in Object.msg (m);
    ``pose`` (4, 4): the primitive's frame in the shape's frame."""
    kind: str
    parameters: tuple
    pose: np.ndarray
    color: tuple = DEFAULT_COLOR


@dataclass(frozen=True, eq=False)
class Shape:
    """What one geometry file holds, in metres, in the file's (link's) frame."""
    source: str
    mesh: Optional[Mesh] = None
    primitives: tuple = field(default_factory=tuple)

    @property
    def triangle_count(self) -> int:
        return 0 if self.mesh is None else int(len(self.mesh.triangles))

    @property
    def is_empty(self) -> bool:
        return self.mesh is None and not self.primitives

    def transformed(self, T: np.ndarray) -> "Shape":
        """The same shape with every coordinate mapped through the rigid pose ``T``."""
        mesh = self.mesh
        if mesh is not None:
            v = mesh.vertices @ T[:3, :3].T + T[:3, 3]
            mesh = replace(mesh, vertices=v)
        prims = tuple(replace(p, pose=T @ p.pose) for p in self.primitives)
        return replace(self, mesh=mesh, primitives=prims)

    def scaled(self, factors) -> "Shape":
        """The shape with x, y, z multiplied by ``factors`` (3,), which may differ and be
        negative (a URDF ``<mesh scale="1 -1 -1">``): a mirrored mesh keeps its triangles
        counter-clockwise seen from outside. A sphere, cylinder or box cannot stretch unevenly:
        factors of different sizes are a ``ShapeError`` when the shape has one."""
        f = np.asarray(factors, dtype=float)
        for factor in f:
            problem = scale_problem(abs(float(factor)))
            if problem is not None:
                raise ShapeError(f"scale {tuple(float(v) for v in f)}: each factor's size "
                                 f"{problem}", self.source)
        mesh = self.mesh
        if mesh is not None:
            check_lengths(mesh.vertices, f"a vertex scaled by {tuple(float(v) for v in f)}",
                          self.source, float(np.max(np.abs(f))))
            triangles = mesh.triangles if np.prod(f) > 0 else mesh.triangles[:, ::-1].copy()
            mesh = replace(mesh, vertices=mesh.vertices * f, triangles=triangles)
        size = float(abs(f[0]))
        if self.primitives and not np.allclose(np.abs(f), size, rtol=1e-9, atol=0.0):
            raise ShapeError(f"a sphere, cylinder or box cannot be scaled by {tuple(f)} "
                             "(factors of different sizes)", self.source)
        for p in self.primitives:
            check_lengths(np.append(p.parameters, p.pose[:3, 3]), "a sphere, cylinder or "
                          f"box scaled by {size:g}", self.source, size)
        return replace(self, mesh=mesh,
                       primitives=tuple(_mirrored(p, np.sign(f), size) for p in self.primitives))

    def with_color(self, color: tuple) -> "Shape":
        mesh = None if self.mesh is None else replace(self.mesh, color=tuple(color))
        prims = tuple(replace(p, color=tuple(color)) for p in self.primitives)
        return replace(self, mesh=mesh, primitives=prims)

    def merged(self, other: "Shape") -> "Shape":
        """Both shapes in one (meshes concatenated, primitives appended)."""
        mesh = self.mesh
        if other.mesh is not None:
            if mesh is None:
                mesh = other.mesh
            else:
                tri = np.vstack([mesh.triangles, other.mesh.triangles + len(mesh.vertices)])
                mesh = Mesh(np.vstack([mesh.vertices, other.mesh.vertices]),
                            tri.astype(np.uint32), mesh.color)
        return Shape(self.source, mesh, self.primitives + other.primitives)


def _mirrored(primitive: Primitive, signs: np.ndarray, size: float) -> Primitive:
    """``primitive`` scaled by ``size`` and mirrored by the axis signs (+-1, 3). A mirror is
    improper, a pose cannot be: the primitive is symmetric about its own x = 0 plane (a
    sphere, a box, a cylinder along z), so mirroring it there too keeps its shape and makes
    the rotation proper."""
    pose = primitive.pose.copy()
    pose[:3, :3] = np.diag(signs) @ pose[:3, :3]
    if np.prod(signs) < 0:
        pose[:3, :3] = pose[:3, :3] @ np.diag([-1.0, 1.0, 1.0])
    pose[:3, 3] = signs * pose[:3, 3] * size
    return replace(primitive, pose=pose,
                   parameters=tuple(float(v) * size for v in primitive.parameters))


def check_lengths(values, what: str, source, scale: float = 1.0) -> None:
    """A ShapeError naming ``source`` and ``what`` unless ``values`` times ``scale`` are
    lengths a model may hold (gui.core.kautham.units.lengths_problem)."""
    problem = lengths_problem(values, scale)
    if problem is not None:
        raise ShapeError(f"{what} {problem}", source)
