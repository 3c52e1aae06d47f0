"""Build Entity's request with its meshes written from numpy (gui.ros.client): byte for byte
what genpy writes for the same request, so the world reads the same entity."""
from __future__ import annotations

import io
import math

import numpy as np

from gui.ros.client import _packed_build_entity, packed_object
from odin_common.messages import composite_message, object_message
from odin_common.specs import CompositeSpec, EntitySpec, ObjectSpec, PartSpec, Surface
from Messages.msg import Object
from Services.srv import BuildEntityRequest


def _bytes(message) -> bytes:
    buffer = io.BytesIO()
    message.serialize(buffer)
    return buffer.getvalue()


def _mesh(n: int = 40, seed: int = 0):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, 3)), rng.integers(0, n, size=(2 * n, 3)).astype(np.uint32)


def _entity() -> EntitySpec:
    vertices, triangles = _mesh()
    arm = ObjectSpec(name="brazo/ünico", parameters=vertices.ravel(), indices=triangles.ravel(),
                     mass=2.5, inertia=(0.1, 0.2, 0.3, 0.0, 0.01, 0.0),
                     center_of_mass=(0.0, 0.1, 0.2), position=(1, 2, 3),
                     orientation=(math.sqrt(0.5), 0, 0, math.sqrt(0.5)), color=(1, 0, 0, 1),
                     fixed=True, no_collisions=True, shape=4,
                     surface=Surface(friction=math.inf, friction2=0.3, bounce=0.5,
                                     bounce_velocity=0.1, stiffness=1e5, damping=10.0))
    ball = ObjectSpec(name="ball", parameters=(0.25,), geometry_only=True)
    hand = CompositeSpec(parts=(PartSpec(name="palm", parameters=(0.1, 0.2, 0.3)),
                                PartSpec(name="finger", parameters=_mesh(9, 1)[0].ravel(),
                                         indices=_mesh(9, 1)[1].ravel())),
                         position=(0, 0, 1))
    return EntitySpec(name="TX90 é", objects=(arm, ball), composites=(hand,),
                      internal_collisions=False)


def test_a_packed_object_is_what_genpy_writes():
    for spec in _entity().objects:
        assert packed_object(spec) == _bytes(object_message(spec))


def test_a_packed_build_entity_request_is_what_genpy_writes_and_reads_back():
    spec = _entity()
    request = _packed_build_entity(spec)
    genpy = BuildEntityRequest(name=spec.name, objects=[object_message(o) for o in spec.objects],
                               composites=[composite_message(c) for c in spec.composites],
                               internal_collisions=False)
    assert _bytes(request) == _bytes(genpy)
    read = BuildEntityRequest().deserialize(_bytes(request))
    assert [o.name for o in read.objects] == ["brazo/ünico", "ball"]
    np.testing.assert_array_equal(read.objects[0].parameters, spec.objects[0].parameters)
    assert list(read.objects[0].indices) == list(spec.objects[0].indices)
    assert isinstance(request, BuildEntityRequest) and isinstance(read.objects[0], Object)


def test_an_entity_without_objects_packs_too():
    spec = EntitySpec(name="only composites", composites=_entity().composites)
    genpy = BuildEntityRequest(name=spec.name, objects=[],
                               composites=[composite_message(c) for c in spec.composites],
                               internal_collisions=True)
    assert _bytes(_packed_build_entity(spec)) == _bytes(genpy)


def test_a_pre_packed_request_without_its_bytes_serialises_as_genpy():
    from gui.ros.client import _PackedBuildEntity
    spec = _entity()
    fields = dict(name=spec.name, objects=[object_message(o) for o in spec.objects],
                  composites=[], internal_collisions=True)
    assert _bytes(_PackedBuildEntity(**fields)) == _bytes(BuildEntityRequest(**fields))
