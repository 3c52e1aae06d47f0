"""What a client asks the world to build, as plain values: one type per concept, shared by the
GUI's build plans, the VirtualWorld Core and the conversions to and from messages
(``odin_common.messages``). ROS-free; validation is the Core's.

SI units, world frame unless said; quaternions (w, x, y, z). Mesh ``parameters`` and
``indices`` may be flat numpy arrays (float64, uint32): a robot's meshes hold tens of
thousands of numbers, which tuples would copy for nothing.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

from odin_common.interface import (JointType, MotorKind, Shape, composite_id,
                                   default_joint_id, default_motor_id, shape_kind)
from odin_common.rotations import IDENTITY_WXYZ

NO_COLOR = (0.0, 0.0, 0.0, 0.0)
"""All zero: the Viewer's default colour."""


@dataclass(frozen=True)
class Surface:
    """Messages/Surface: contact properties of a surface; None: not set (the world's value).

    friction: Coulomb mu >= 0 (math.inf: infinite). friction2: mu along
    ``friction_direction`` (a unit vector in the geometry's own frame), for anisotropic
    friction. bounce: restitution in [0, 1], with bounce_velocity (m/s) the least incoming
    speed that bounces. stiffness (kp, N/m), with damping (kd, N s/m): a soft contact. Two
    surfaces in contact mix their values: the smaller friction, the larger restitution, the
    smaller bounce velocity, stiffness and damping in series (docs/INTERFACE.md)."""
    friction: Optional[float] = None
    friction2: Optional[float] = None
    friction_direction: Sequence[float] = (1.0, 0.0, 0.0)
    bounce: Optional[float] = None
    bounce_velocity: float = 0.0
    stiffness: Optional[float] = None
    damping: float = 0.0

    @property
    def is_set(self) -> bool:
        return any(v is not None for v in (self.friction, self.friction2, self.bounce,
                                           self.stiffness))


WORLD_SURFACE = Surface()
"""Nothing set: every contact value is the world's."""


class _OneShape:
    """What an ObjectSpec and a PartSpec, each one geometry, say of their shape."""
    parameters: Sequence[float]
    indices: Sequence[int]
    shape: int

    @property
    def kind(self) -> str:
        """"sphere", "cylinder", "box", "mesh", "capsule" or "plane"."""
        return shape_kind(len(self.parameters), self.shape)

    @property
    def triangle_count(self) -> int:
        return len(self.indices) // 3


@dataclass(frozen=True, eq=False)
class ObjectSpec(_OneShape):
    """Messages/Object: one object, a body with one geometry (or a static geometry).

    parameters: the shape by their number (odin_common.interface.shape_kind): 1 sphere radius;
        2 cylinder radius, length (along z); 3 box sides x, y, z; a multiple of 3 >= 9 mesh
        vertices (x, y, z, ...) in the object frame, m, with ``indices`` (3 per triangle).
    mass: kg > 0 (unused for geometry_only). inertia: () for the shape's own at uniform
        density, or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] kg m^2, object axes, about
        ``center_of_mass`` ([x, y, z] m, object frame; () the object's origin), which is then
        where the centre of mass is.
    position (m, world), orientation (w, x, y, z): the object's frame. color: RGBA in [0, 1].
    fixed: a kinematic body that forces and contacts never move. geometry_only: no body.
    no_collisions: collides with nothing (Kautham's <Collision enabled="false">).
    shape: odin_common.interface.Shape; BY_COUNT (0) follows the count rule above, the others
        name a shape (CAPSULE: radius, length; PLANE: no parameter, static only).
    surface: contact properties of its geometry (Surface).
    """
    name: str
    parameters: Sequence[float]
    indices: Sequence[int] = ()
    mass: float = 1.0
    inertia: Sequence[float] = ()
    position: Sequence[float] = (0.0, 0.0, 0.0)
    orientation: Sequence[float] = IDENTITY_WXYZ
    color: Sequence[float] = NO_COLOR
    fixed: bool = False
    geometry_only: bool = False
    no_collisions: bool = False
    shape: int = Shape.BY_COUNT
    surface: Surface = WORLD_SURFACE
    center_of_mass: Sequence[float] = ()

    @property
    def id(self) -> str:
        return self.name


@dataclass(frozen=True, eq=False)
class PartSpec(_OneShape):
    """Messages/Part: one geometry of a composite; pose in the composite's frame; shape (not a
    plane), mass, colour and surface as in ObjectSpec."""
    name: str
    parameters: Sequence[float]
    indices: Sequence[int] = ()
    mass: float = 1.0
    position: Sequence[float] = (0.0, 0.0, 0.0)
    orientation: Sequence[float] = IDENTITY_WXYZ
    color: Sequence[float] = NO_COLOR
    shape: int = Shape.BY_COUNT
    surface: Surface = WORLD_SURFACE


@dataclass(frozen=True, eq=False)
class CompositeSpec:
    """Messages/Composite: parts on one body; the pose of the composite's frame (world).
    Its ID is ">part1>part2..." (odin_common.interface.composite_id). inertia: () for the
    parts' shapes' own, or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] kg m^2 about ``center_of_mass``
    ([x, y, z] m, composite frame; () the origin), composite axes; the mass is the parts'."""
    parts: Sequence[PartSpec]
    position: Sequence[float] = (0.0, 0.0, 0.0)
    orientation: Sequence[float] = IDENTITY_WXYZ
    fixed: bool = False
    geometry_only: bool = False
    no_collisions: bool = False
    inertia: Sequence[float] = ()
    center_of_mass: Sequence[float] = ()

    @property
    def id(self) -> str:
        return composite_id([p.name for p in self.parts])

    @property
    def mass(self) -> float:
        return float(sum(p.mass for p in self.parts))

    @property
    def triangle_count(self) -> int:
        return sum(p.triangle_count for p in self.parts)


@dataclass(frozen=True, eq=False)
class EntitySpec:
    """Services/BuildEntity: objects and composites built together, all or nothing; without
    internal collisions no two of its geometries ever collide. name "" gives "entity<n>"."""
    name: str
    objects: Sequence[ObjectSpec] = ()
    composites: Sequence[CompositeSpec] = ()
    internal_collisions: bool = True

    @property
    def members(self) -> Tuple:
        """Objects, then composites: the order of the world's answer."""
        return tuple(self.objects) + tuple(self.composites)


@dataclass(frozen=True)
class JointSpec:
    """Services/SetJoint, action CREATE: a joint between two bodies, or a body and the static
    world (an ID "").

    anchor (m, world) is used by the types in interface.JOINT_USES_ANCHOR; axis1..axis3 (world,
    non-zero) as interface.JOINT_AXES_USED says; parameters: (JointParameter, axis 1..3, value)
    triples applied with the joint, all or nothing. id "" gives "<type>:<body1>&<body2>"."""
    type: JointType
    body1: str
    body2: str
    anchor: Sequence[float] = (0.0, 0.0, 0.0)
    axis1: Sequence[float] = (0.0, 0.0, 1.0)
    axis2: Sequence[float] = (1.0, 0.0, 0.0)
    axis3: Sequence[float] = (0.0, 1.0, 0.0)
    parameters: Sequence[Tuple[int, int, float]] = ()
    id: str = ""

    @property
    def default_id(self) -> str:
        return self.id or default_joint_id(self.type, self.body1, self.body2)


@dataclass(frozen=True)
class MotorSpec:
    """Services/SetMotor: an angular or linear motor on a joint (its bodies and, when ``axes``
    is empty, its axes) or between two bodies. axes: flat, 3 per axis (1..3 axes), world
    frame; axis_frames per axis (AxisFrame); max_forces per axis (N m or N; negative or empty:
    infinite). Motors start at zero goal speed. id "" gives "motor:<joint>"."""
    joint: str = ""
    kind: MotorKind = MotorKind.ANGULAR
    body1: str = ""
    body2: str = ""
    axes: Sequence[float] = ()
    axis_frames: Sequence[int] = ()
    max_forces: Sequence[float] = ()
    id: str = ""

    @property
    def default_id(self) -> str:
        return self.id or default_motor_id(self.joint, self.body1, self.body2)


__all__ = ["Surface", "WORLD_SURFACE", "NO_COLOR", "ObjectSpec", "PartSpec", "CompositeSpec",
           "EntitySpec", "JointSpec", "MotorSpec"]
