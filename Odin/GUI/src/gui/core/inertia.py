"""Which inertia a link's body gets: its file's, or its shape's (the world computes that).

A URDF ``<inertial>`` gives a tensor about the centre of mass. Odin uses it (``mode``
"auto", the default) when it is a rigid body's (positive definite, each principal moment at
most the sum of the other two) and, for a link made only of primitives, when each principal
moment is within ``placeholder_factor`` of the shape's at the same mass: a tensor further away
is a placeholder (the corpus's ODE demos carry 0.000036 kg m^2 for a 25 kg sphere of 0.25 m)
and the shape's inertia at uniform density is used instead, which is also what Kautham's ODE
environment does with every link (``dMassSet*Total`` of its shape). A link with a mesh keeps its
file's tensor (real robots' CAD inertias), unless the world would refuse it as far too light in
rotation for the link's geometry (``odin_common.limits.thin_inertia``: a placeholder scaled
down with its mesh, as the IOC lab layout's). ``mode`` "file" always uses a rigid body's tensor,
"shape" never. Every tensor set aside is listed (``gui.core.model.Ignored``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from gui.core.model import Ignored, LinkModel
from gui.core.geometry import Shape
from odin_common.limits import inertia_problem, primitive_corners

AUTO, FILE, SHAPE = "auto", "file", "shape"
INERTIA_MODES = (AUTO, FILE, SHAPE)


@dataclass(frozen=True)
class BodyInertia:
    """A body's given mass distribution in its own frame: ``inertia`` [Ixx, Iyy, Izz, Ixy, Ixz,
    Iyz] kg m^2 about ``center_of_mass`` (3,) m (ObjectSpec's / CompositeSpec's fields)."""
    inertia: Tuple[float, ...]
    center_of_mass: Tuple[float, ...]


def primitive_inertia(kind: str, parameters: Sequence[float], mass: float) -> np.ndarray:
    """(3, 3) kg m^2 of a primitive of ``mass`` about its centre, its own axes (cylinder along
    z), uniform density."""
    if kind == "sphere":
        return 0.4 * mass * parameters[0] ** 2 * np.eye(3)
    if kind == "box":
        x, y, z = parameters
        return mass / 12.0 * np.diag([y * y + z * z, x * x + z * z, x * x + y * y])
    if kind == "cylinder":
        r, length = parameters
        side = mass * (3 * r * r + length * length) / 12.0
        return np.diag([side, side, mass * r * r / 2.0])
    raise ValueError(f"no closed-form inertia for a {kind}")


def primitive_volume(kind: str, parameters: Sequence[float]) -> float:
    """m^3 of a sphere, cylinder or box."""
    if kind == "sphere":
        return 4.0 / 3.0 * np.pi * parameters[0] ** 3
    if kind == "cylinder":
        return np.pi * parameters[0] ** 2 * parameters[1]
    return float(np.prod(parameters))


def shape_inertia(shape: Shape, mass: float) -> Optional[np.ndarray]:
    """(3, 3) kg m^2 about the shape's centre of mass, the shape's axes, at uniform density
    (primitives sharing ``mass`` by volume); None for a shape with a mesh."""
    if shape is None or shape.mesh is not None or not shape.primitives:
        return None
    volumes = np.array([primitive_volume(p.kind, p.parameters) for p in shape.primitives])
    masses = mass * volumes / volumes.sum()
    centres = np.array([p.pose[:3, 3] for p in shape.primitives])
    centre = masses @ centres / mass
    total = np.zeros((3, 3))
    for prim, m, c in zip(shape.primitives, masses, centres):
        R = prim.pose[:3, :3]
        d = c - centre
        total += R @ primitive_inertia(prim.kind, prim.parameters, m) @ R.T \
            + m * (d @ d * np.eye(3) - np.outer(d, d))
    return total


def rigid_body_problem(tensor: np.ndarray) -> Optional[str]:
    """Why ``tensor`` is no rigid body's inertia (None when it is one)."""
    if not np.all(np.isfinite(tensor)):
        return "not finite"
    if not np.allclose(tensor, tensor.T):
        return "not symmetric"
    moments = np.linalg.eigvalsh(tensor)
    if moments[0] <= 0:
        return f"principal moments {moments.round(9).tolist()} are not all positive"
    if moments[2] > moments[0] + moments[1] + 1e-12 * moments[2]:
        return (f"principal moments {moments.round(9).tolist()} break the triangle "
                "inequality")
    return None


def shape_points(shape: Shape) -> np.ndarray:
    """(n, 3) m in the shape's frame: its mesh's vertices and its primitives' box corners
    (the points the world's check of a given inertia reads, odin_common.limits)."""
    points = [np.zeros((0, 3))]
    if shape is not None and shape.mesh is not None:
        points.append(np.asarray(shape.mesh.vertices, dtype=float))
    for prim in (shape.primitives if shape is not None else ()):
        corners = primitive_corners(prim.kind, prim.parameters)
        points.append(corners @ prim.pose[:3, :3].T + prim.pose[:3, 3])
    return np.concatenate(points)


def choose(link: LinkModel, owner: str, mass: float, offset: np.ndarray, mode: str = AUTO,
           placeholder_factor: float = 10.0) -> Tuple[Optional[BodyInertia], Optional[Ignored]]:
    """The inertia the body of ``link`` (named ``owner``, of ``mass`` kg) gets, in the body's
    frame ``offset`` (4, 4, in the link frame), or None for the shape's; and the Ignored entry
    when the file's tensor is set aside."""
    if mode not in INERTIA_MODES:
        raise ValueError(f"inertia mode {mode!r}: choose from {INERTIA_MODES}")
    inertial = link.inertial
    if mode == SHAPE or inertial is None or inertial.tensor is None:
        return None, None
    tensor = inertial.tensor * (mass / inertial.mass)
    what = f"<inertial> of link \"{link.name}\" ({owner})"
    problem = rigid_body_problem(tensor) or _thin(link, tensor, mass)
    if problem is not None:
        return None, Ignored(link.source, link.line, what, f"{problem}: the shape's inertia "
                             "is used")
    if mode == AUTO:
        own = shape_inertia(link.shape, mass)
        if own is not None and rigid_body_problem(own) is None:   # else nothing to compare
            given = np.linalg.eigvalsh(inertial.origin[:3, :3] @ tensor
                                       @ inertial.origin[:3, :3].T)
            expected = np.linalg.eigvalsh(own)
            ratio = float(np.max(np.maximum(given / expected, expected / given)))
            if ratio > placeholder_factor:
                return None, Ignored(
                    link.source, link.line, what,
                    f"principal moments {given.round(6).tolist()} kg m^2 are {ratio:.3g} times "
                    f"off the shape's {expected.round(6).tolist()} at {mass:g} kg (a "
                    "placeholder): the shape's inertia is used, as in Kautham's ODE "
                    "environment")
    to_body = np.linalg.inv(offset)
    frame = to_body @ inertial.origin
    R = frame[:3, :3]
    i = R @ tensor @ R.T
    return BodyInertia((i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]),
                       tuple(float(v) for v in frame[:3, 3])), None


def _thin(link: LinkModel, tensor: np.ndarray, mass: float) -> Optional[str]:
    """Why the world would refuse ``tensor`` for the link's shape, too light or too heavy in
    rotation (odin_common.limits.inertia_problem), in the inertial frame; None when it would
    not."""
    to_inertial = np.linalg.inv(link.inertial.origin)
    points = shape_points(link.shape) @ to_inertial[:3, :3].T + to_inertial[:3, 3]
    return inertia_problem(tensor, mass, points)


__all__ = ["shape_points", "AUTO", "FILE", "SHAPE", "INERTIA_MODES", "BodyInertia",
           "primitive_inertia", "primitive_volume", "shape_inertia", "rigid_body_problem",
           "choose"]
