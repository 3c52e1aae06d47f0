"""A shape -> the spec of the world body that carries it (ROS-free).

A mesh alone becomes a mesh object (vertices in the shape's frame); one primitive alone a
primitive object whose body sits at the primitive's pose in the shape's frame; anything else a
composite whose frame is the shape's frame (one part per primitive, one for the mesh, parts
named "name#k"), its mass shared among its parts in proportion to their volumes. Used for a
problem's links (``gui.core.translate``) and for an object read from a file (the Objects tab).

Lengths are m, masses kg; positions and quaternions (w, x, y, z) are world frame.
"""
from __future__ import annotations

import dataclasses
from typing import Tuple

import numpy as np

from gui.core import inertia as inertia_rule
from gui.core.kinematics import pose_to_position_quaternion
from gui.core.plan import BodySpec
from gui.core.geometry import Shape
from odin_common.specs import CompositeSpec, ObjectSpec, PartSpec, Surface


def shape_to_body(name: str, shape: Shape, link_pose: np.ndarray, mass: float,
                  static: bool) -> Tuple[BodySpec, np.ndarray]:
    """The spec (object or composite) for a shape whose frame is at ``link_pose`` ((4, 4),
    world frame) with ``mass`` kg (``static``: geometry only, no body), and the body's pose in
    that frame ((4, 4): identity but for a lone primitive)."""
    pieces = _pieces(shape)
    if len(pieces) == 1:
        kind, params, indices, offset, color, _ = pieces[0]
        position, quaternion = pose_to_position_quaternion(link_pose @ offset)
        spec = ObjectSpec(name=name, parameters=params, indices=indices, mass=mass,
                          position=position, orientation=quaternion, color=tuple(color),
                          geometry_only=static)
        return spec, offset
    total = sum(p[5] for p in pieces) or 1.0
    parts = []
    for k, (kind, params, indices, offset, color, volume) in enumerate(pieces):
        position, quaternion = pose_to_position_quaternion(offset)
        parts.append(PartSpec(name=f"{name}#{k}", parameters=params, indices=indices,
                              mass=max(mass * volume / total, mass * 1e-6),
                              position=position, orientation=quaternion, color=tuple(color)))
    position, quaternion = pose_to_position_quaternion(link_pose)
    return CompositeSpec(parts=tuple(parts), position=position, orientation=quaternion,
                         geometry_only=static), np.eye(4)


def _pieces(shape: Shape) -> list:
    """(kind, parameters, triangle indices, pose in the shape's frame, colour, volume m^3)
    of the shape's mesh, then of each of its primitives."""
    pieces = []
    if shape.mesh is not None:
        mesh = shape.mesh
        pieces.append(("mesh", np.ascontiguousarray(mesh.vertices, dtype=np.float64).ravel(),
                       np.ascontiguousarray(mesh.triangles, dtype=np.uint32).ravel(),
                       np.eye(4), mesh.color, _volume("mesh", (), mesh.vertices, mesh.triangles)))
    for prim in shape.primitives:
        pieces.append((prim.kind, tuple(prim.parameters), (), prim.pose, prim.color,
                       _volume(prim.kind, prim.parameters)))
    return pieces


def shape_volume(shape: Shape) -> float:
    """m^3: the sum of the shape's pieces' volumes (a closed mesh's own, an open or flat
    mesh's bounding box's, each primitive's)."""
    return float(sum(piece[5] for piece in _pieces(shape)))


def _volume(part_kind: str, parameters: tuple, vertices=None, triangles=None) -> float:
    """m^3: a primitive's, or a closed mesh's; the box around an open or flat mesh's."""
    if part_kind != "mesh":
        return inertia_rule.primitive_volume(part_kind, parameters)
    tri = np.take(vertices, triangles, axis=0)     # as vertices[triangles], 2-3 times faster
    signed = float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6)
    if abs(signed) > 0:
        return abs(signed)
    extent = vertices.max(0) - vertices.min(0)
    return float(np.prod(np.maximum(extent, 1e-6)))


def with_surface(spec: BodySpec, surface: Surface) -> BodySpec:
    """``spec`` with the contact ``surface`` on its object or on every part (unchanged when
    the surface sets nothing)."""
    if not surface.is_set:
        return spec
    if isinstance(spec, ObjectSpec):
        return dataclasses.replace(spec, surface=surface)
    return dataclasses.replace(spec, parts=tuple(dataclasses.replace(p, surface=surface)
                                                 for p in spec.parts))
