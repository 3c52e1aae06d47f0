"""World parameters of the VirtualWorld Core: one documented frozen dataclass of defaults."""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Tuple

from virtual_world.errors import InvalidArgument

QUICKSTEP = 0
"""dWorldQuickStep: iterative (SOR-LCP), O(m) in the constraint rows; handles piles."""
WORLDSTEP = 1
"""dWorldStep: the thesis's "big matrix" solver, O(m^3); on piles it manages a few steps per
second and reports LCP internal errors (platform notes), so it is not the default."""


@dataclass(frozen=True)
class WorldParameters:
    """Simulation parameters (thesis 5.2), all SI units, world frame.

    gravity:                 (3,) m/s^2.
    erp:                     global error reduction parameter, [0, 1].
    cfm:                     global constraint force mixing, >= 0.
    max_angular_speed:       rad/s cap of every body's angular speed; 0 = unlimited.
    contact_max_correcting_velocity: m/s cap of the velocity contacts use to remove
                             penetration; 0 = unlimited.
    contact_surface_layer:   m a body may sink into another before contacts push back, >= 0.
    linear_damping, angular_damping: fraction of velocity removed per step, [0, 1].
    linear_damping_threshold, angular_damping_threshold: speeds (m/s, rad/s) below which no
                             damping applies, >= 0.
    max_contacts:            contact points per colliding geom pair, 1..64 (default 3).
    friction:                Coulomb mu of contacts, >= 0; negative = infinite (dInfinity).
    bounce:                  restitution of contacts, [0, 1]; 0 disables bouncing.
    bounce_velocity:         m/s, the minimum incoming speed for a bounce, >= 0.
    solver:                  QUICKSTEP (0) or WORLDSTEP (1).
    quickstep_iterations:    iterations of QuickStep, >= 1.
    contact_less:            collision policy: False creates contacts; True only records the
                             colliding pairs (thesis 5.5.2) until read_collisions().
    collision_mesh_tolerance: m, >= 0. A mesh built while it is positive collides as its
                             vertices clustered on a grid of this cell size (within sqrt(3)
                             cells of the given surface; odin_common.meshes); 0 = as given.
                             Mass, inertia and the Viewer's picture always use the given mesh;
                             meshes already built keep the collision mesh they were built with,
                             and a mesh fewer than 6 cells across collides as given.
                             CAD meshes of robot hands carry tens of thousands of triangles,
                             and ODE's mesh colliders cost in proportion to the triangles near
                             a contact.
    """

    gravity: Tuple[float, float, float] = (0.0, 0.0, -9.81)
    erp: float = 0.2
    cfm: float = 1e-5
    max_angular_speed: float = 0.0
    contact_max_correcting_velocity: float = 0.0
    contact_surface_layer: float = 0.001
    linear_damping: float = 0.0
    linear_damping_threshold: float = 0.01
    angular_damping: float = 0.0
    angular_damping_threshold: float = 0.01
    max_contacts: int = 3
    friction: float = 1.0
    bounce: float = 0.0
    bounce_velocity: float = 0.1
    solver: int = QUICKSTEP
    quickstep_iterations: int = 20
    contact_less: bool = False
    collision_mesh_tolerance: float = 0.0

    def replace(self, **changes) -> "WorldParameters":
        """A validated copy with `changes`; unknown keys raise InvalidArgument."""
        names = {f.name for f in dataclasses.fields(self)}
        unknown = sorted(set(changes) - names)
        if unknown:
            raise InvalidArgument(f"unknown world parameter(s) {unknown}; known: {sorted(names)}")
        if "gravity" in changes:
            changes["gravity"] = _vector("gravity", changes["gravity"])
        new = dataclasses.replace(self, **changes)
        new.validate()
        return new

    def validate(self) -> None:
        """Raises InvalidArgument naming the first bad field."""
        _vector("gravity", self.gravity)
        for name in ("erp", "cfm", "max_angular_speed", "contact_max_correcting_velocity",
                     "contact_surface_layer", "linear_damping", "linear_damping_threshold",
                     "angular_damping", "angular_damping_threshold", "friction", "bounce",
                     "bounce_velocity", "collision_mesh_tolerance"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise InvalidArgument(f"world parameter {name}={value!r} is not a number")
            if not math.isfinite(value):
                raise InvalidArgument(f"world parameter {name}={value!r} is not finite")
            if name != "friction" and value < 0:
                raise InvalidArgument(f"world parameter {name}={value!r} is negative")
        for name in ("erp", "linear_damping", "angular_damping", "bounce",
                     "collision_mesh_tolerance"):   # a tolerance above 1 m is mm taken for m
            if getattr(self, name) > 1:
                raise InvalidArgument(f"world parameter {name}={getattr(self, name)!r} is above 1")
        for name, low, high in (("max_contacts", 1, 64), ("quickstep_iterations", 1, 100000),
                                ("solver", 0, 1)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
                raise InvalidArgument(
                    f"world parameter {name}={value!r} must be an integer in [{low}, {high}]")
        if not isinstance(self.contact_less, bool):
            raise InvalidArgument(f"world parameter contact_less={self.contact_less!r} is not a bool")


def _vector(name: str, value) -> Tuple[float, float, float]:
    try:
        values = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{name}={value!r} is not a 3-vector") from None
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise InvalidArgument(f"{name}={value!r} is not a finite 3-vector")
    return values
