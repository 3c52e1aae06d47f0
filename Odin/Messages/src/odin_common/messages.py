"""Specs to messages and back: the one place where odin_common.specs meet the generated
Messages classes (Object, Composite, Part, JointParameter, Situation).

Needs the generated message classes (the catkin workspace), not rospy or a master. Values pass
through unchanged: SI units, world frame, quaternions (w, x, y, z) on both sides.
"""
from __future__ import annotations

import collections.abc
from typing import Sequence, Tuple

import numpy as np

import math

from Messages.msg import (BodyForce, BodyState, Composite, JointParameter, Object, Part,
                          Situation, Surface as SurfaceMessage, WorldParameters)
from odin_common import world_parameters
from odin_common.specs import CompositeSpec, ObjectSpec, PartSpec, Surface


def _floats(values) -> list:
    return np.asarray(values, dtype=float).reshape(-1).tolist()


def _indices(values) -> list:
    return np.asarray(values, dtype=np.uint32).reshape(-1).tolist()


def surface_message(surface: Surface) -> SurfaceMessage:
    m = SurfaceMessage()
    if surface.friction is not None:
        m.set_friction = True
        m.friction = -1.0 if math.isinf(surface.friction) else float(surface.friction)
    if surface.friction2 is not None:
        m.set_friction2 = True
        m.friction2 = float(surface.friction2)
        m.friction_direction = _floats(surface.friction_direction)
    if surface.bounce is not None:
        m.set_bounce = True
        m.bounce = float(surface.bounce)
        m.bounce_velocity = float(surface.bounce_velocity)
    if surface.stiffness is not None:
        m.set_softness = True
        m.stiffness = float(surface.stiffness)
        m.damping = float(surface.damping)
    return m


def surface_of(m: SurfaceMessage) -> Surface:
    """Messages/Surface -> Surface (a negative friction is infinite)."""
    friction = None
    if m.set_friction:
        friction = math.inf if m.friction < 0 else m.friction
    return Surface(friction=friction,
                   friction2=m.friction2 if m.set_friction2 else None,
                   friction_direction=tuple(m.friction_direction) if m.set_friction2
                   else (1.0, 0.0, 0.0),
                   bounce=m.bounce if m.set_bounce else None,
                   bounce_velocity=m.bounce_velocity if m.set_bounce else 0.0,
                   stiffness=m.stiffness if m.set_softness else None,
                   damping=m.damping if m.set_softness else 0.0)


def object_message(spec: ObjectSpec) -> Object:
    return Object(name=spec.name, parameters=_floats(spec.parameters),
                  indices=_indices(spec.indices), mass=float(spec.mass),
                  inertia=_floats(spec.inertia), position=_floats(spec.position),
                  orientation=_floats(spec.orientation), color=_floats(spec.color),
                  fixed=bool(spec.fixed), geometry_only=bool(spec.geometry_only),
                  no_collisions=bool(spec.no_collisions), shape=int(spec.shape),
                  surface=surface_message(spec.surface),
                  center_of_mass=_floats(spec.center_of_mass))


def _mesh_numbers(values):
    """A message's parameters or indices as a spec holds them: a numpy array as it came
    (a service's numpy requests: odin_common.node.numpy_requests), anything else a tuple."""
    return values if isinstance(values, np.ndarray) else tuple(values)


def object_spec(message: Object) -> ObjectSpec:
    return ObjectSpec(name=message.name, parameters=_mesh_numbers(message.parameters),
                      indices=_mesh_numbers(message.indices), mass=message.mass,
                      inertia=tuple(message.inertia), position=tuple(message.position),
                      orientation=tuple(message.orientation), color=tuple(message.color),
                      fixed=message.fixed, geometry_only=message.geometry_only,
                      no_collisions=message.no_collisions, shape=message.shape,
                      surface=surface_of(message.surface),
                      center_of_mass=tuple(message.center_of_mass))


def part_message(spec: PartSpec) -> Part:
    return Part(name=spec.name, parameters=_floats(spec.parameters),
                indices=_indices(spec.indices), mass=float(spec.mass),
                position=_floats(spec.position), orientation=_floats(spec.orientation),
                color=_floats(spec.color), shape=int(spec.shape),
                surface=surface_message(spec.surface))


def part_spec(message: Part) -> PartSpec:
    return PartSpec(name=message.name, parameters=_mesh_numbers(message.parameters),
                    indices=_mesh_numbers(message.indices), mass=message.mass,
                    position=tuple(message.position), orientation=tuple(message.orientation),
                    color=tuple(message.color), shape=message.shape,
                    surface=surface_of(message.surface))


def composite_message(spec: CompositeSpec) -> Composite:
    return Composite(parts=[part_message(p) for p in spec.parts],
                     position=_floats(spec.position), orientation=_floats(spec.orientation),
                     fixed=bool(spec.fixed), geometry_only=bool(spec.geometry_only),
                     no_collisions=bool(spec.no_collisions), inertia=_floats(spec.inertia),
                     center_of_mass=_floats(spec.center_of_mass))


def composite_spec(message: Composite) -> CompositeSpec:
    return CompositeSpec(parts=tuple(part_spec(p) for p in message.parts),
                         position=tuple(message.position),
                         orientation=tuple(message.orientation), fixed=message.fixed,
                         geometry_only=message.geometry_only,
                         no_collisions=message.no_collisions, inertia=tuple(message.inertia),
                         center_of_mass=tuple(message.center_of_mass))


def parameter_messages(parameters: Sequence[Tuple[int, int, float]]) -> list:
    """(parameter, axis, value) triples -> Messages/JointParameter."""
    return [JointParameter(parameter=int(p), axis=int(a), value=float(v))
            for p, a, v in parameters]


def parameter_triples(messages) -> list:
    """Messages/JointParameter -> (parameter, axis, value) triples."""
    return [(m.parameter, m.axis, m.value) for m in messages]


def situation_messages(poses) -> list:
    """(name, position (3,) m, quaternion (w, x, y, z)) -> Messages/Situation."""
    return [Situation(name=name, position=_floats(position), orientation=_floats(orientation))
            for name, position, orientation in poses]


class _SituationPoses(collections.abc.Sequence):
    """Messages/Situation -> (name, position, quaternion), each converted when it is read: a
    request of 100,000 situations naming unknown objects is refused at the first one (and
    its count at once) without a copy of them all."""

    def __init__(self, messages):
        self._messages = messages

    def __len__(self) -> int:
        return len(self._messages)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[k] for k in range(*index.indices(len(self)))]
        m = self._messages[index]
        return (m.name, tuple(m.position), tuple(m.orientation))


def situation_poses(messages) -> Sequence:
    """Messages/Situation -> a sequence of (name, position, quaternion), converted lazily."""
    return _SituationPoses(messages)


def world_parameters_message(parameters: world_parameters.WorldParameters) -> WorldParameters:
    return WorldParameters(**parameters.as_dict())


def world_parameters_of(message: WorldParameters) -> world_parameters.WorldParameters:
    values = {info.name: getattr(message, info.name) for info in world_parameters.PARAMETERS}
    values["gravity"] = tuple(values["gravity"])
    return world_parameters.WorldParameters(**values)


def body_state_message(state) -> BodyState:
    """Anything with id, position, orientation, linear, angular -> Messages/BodyState."""
    return BodyState(id=state.id, position=_floats(state.position),
                     orientation=_floats(state.orientation), linear=_floats(state.linear),
                     angular=_floats(state.angular))


def body_force_arguments(message: BodyForce) -> dict:
    """Messages/BodyForce -> the keyword arguments of a body force (the Core's
    add_body_force)."""
    return dict(object_id=message.object, kind=message.kind, vector=tuple(message.vector),
                vector_in_body_frame=message.vector_in_body_frame, at_point=message.at_point,
                point=tuple(message.point), point_in_body_frame=message.point_in_body_frame)


def body_force_message(object_id: str, kind: int, vector, vector_in_body_frame: bool = False,
                       at_point: bool = False, point=(0.0, 0.0, 0.0),
                       point_in_body_frame: bool = False) -> BodyForce:
    return BodyForce(object=object_id, kind=int(kind), vector=_floats(vector),
                     vector_in_body_frame=bool(vector_in_body_frame), at_point=bool(at_point),
                     point=_floats(point), point_in_body_frame=bool(point_in_body_frame))


__all__ = ["surface_message", "surface_of", "world_parameters_message", "world_parameters_of",
           "body_state_message", "body_force_arguments", "body_force_message", "object_message",
           "object_spec", "part_message", "part_spec", "composite_message", "composite_spec",
           "parameter_messages", "parameter_triples", "situation_messages", "situation_poses"]
