"""Specs to messages and back: the one place where odin_common.specs meet the generated
Messages classes (Object, Composite, Part, JointParameter, Situation).

Needs the generated message classes (the catkin workspace), not rospy or a master. Values pass
through unchanged: SI units, world frame, quaternions (w, x, y, z) on both sides.
"""
from __future__ import annotations

from typing import Sequence, Tuple

import numpy as np

from Messages.msg import Composite, JointParameter, Object, Part, Situation
from odin_common.specs import CompositeSpec, ObjectSpec, PartSpec


def _floats(values) -> list:
    return np.asarray(values, dtype=float).reshape(-1).tolist()


def _indices(values) -> list:
    return np.asarray(values, dtype=np.uint32).reshape(-1).tolist()


def object_message(spec: ObjectSpec) -> Object:
    return Object(name=spec.name, parameters=_floats(spec.parameters),
                  indices=_indices(spec.indices), mass=float(spec.mass),
                  inertia=_floats(spec.inertia), position=_floats(spec.position),
                  orientation=_floats(spec.orientation), color=_floats(spec.color),
                  fixed=bool(spec.fixed), geometry_only=bool(spec.geometry_only),
                  no_collisions=bool(spec.no_collisions))


def object_spec(message: Object) -> ObjectSpec:
    return ObjectSpec(name=message.name, parameters=tuple(message.parameters),
                      indices=tuple(message.indices), mass=message.mass,
                      inertia=tuple(message.inertia), position=tuple(message.position),
                      orientation=tuple(message.orientation), color=tuple(message.color),
                      fixed=message.fixed, geometry_only=message.geometry_only,
                      no_collisions=message.no_collisions)


def part_message(spec: PartSpec) -> Part:
    return Part(name=spec.name, parameters=_floats(spec.parameters),
                indices=_indices(spec.indices), mass=float(spec.mass),
                position=_floats(spec.position), orientation=_floats(spec.orientation),
                color=_floats(spec.color))


def part_spec(message: Part) -> PartSpec:
    return PartSpec(name=message.name, parameters=tuple(message.parameters),
                    indices=tuple(message.indices), mass=message.mass,
                    position=tuple(message.position), orientation=tuple(message.orientation),
                    color=tuple(message.color))


def composite_message(spec: CompositeSpec) -> Composite:
    return Composite(parts=[part_message(p) for p in spec.parts],
                     position=_floats(spec.position), orientation=_floats(spec.orientation),
                     fixed=bool(spec.fixed), geometry_only=bool(spec.geometry_only),
                     no_collisions=bool(spec.no_collisions))


def composite_spec(message: Composite) -> CompositeSpec:
    return CompositeSpec(parts=tuple(part_spec(p) for p in message.parts),
                         position=tuple(message.position),
                         orientation=tuple(message.orientation), fixed=message.fixed,
                         geometry_only=message.geometry_only,
                         no_collisions=message.no_collisions)


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


def situation_poses(messages) -> list:
    """Messages/Situation -> (name, position, quaternion)."""
    return [(m.name, tuple(m.position), tuple(m.orientation)) for m in messages]


__all__ = ["object_message", "object_spec", "part_message", "part_spec", "composite_message",
           "composite_spec", "parameter_messages", "parameter_triples", "situation_messages",
           "situation_poses"]
