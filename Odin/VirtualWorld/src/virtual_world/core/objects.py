"""Objects, composites and entities: checked, built, moved and removed (thesis 4.2.1, 5.1).

An object is a body with one geometry; a composite is one body with several geometries
(parts placed in the composite's frame, their masses rotated, moved and added); either may be
geometry only (static, no body) or fixed (a kinematic body). An entity builds several at once,
all or nothing, optionally without collisions among its members. Every argument is checked
before the first ODE call.
"""
from __future__ import annotations

import collections
import threading
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Set, Tuple

import numpy as np

from odin_common import limits
from odin_common.interface import composite_id
from odin_common.limits import shown
from odin_common.rotations import quaternion_multiply, quaternion_to_matrix
from odin_common.specs import CompositeSpec, EntitySpec, ObjectSpec, PartSpec
from virtual_world.core import (exemptions, forces, guard, joints, motors, readout,
                                validation as check)
from virtual_world.core.arrays import float64_array, uint32_array
from virtual_world.core.mass import check_mass, mesh_digest, shape_mass
from virtual_world.core.records import (Built, BuiltEntity, BuiltGeometry, GeometryRecord,
                                        ObjectRecord, Removed)
from virtual_world.core.scene import Scene
from virtual_world.core.shapes import Shape, collision_mesh, prepare_shape
from virtual_world.errors import DuplicateName, InvalidArgument
from virtual_world.ode import bodies, handles
from virtual_world.ode.world import PoseReader

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


@dataclass(eq=False)
class _Part:
    """A checked geometry: shape and mass, pose in the object's frame, surface, what was
    given."""
    name: str
    shape: Shape
    mass: float
    position: np.ndarray
    orientation: np.ndarray
    color: Tuple[float, ...]
    parameters: Sequence[float]
    indices: Sequence[int]
    shape_asked: int
    surface: object   # odin_common.specs.Surface
    cache_key: Optional[Tuple[bytes, int]] = None    # a new mesh's _MESH_SHAPES key


@dataclass(eq=False)
class _Prepared:
    """A checked object or composite, ready for ODE: its parts and mass (centred)."""
    spec: object
    object_id: str
    parts: List[_Part]
    position: np.ndarray
    orientation: np.ndarray
    fixed: bool
    geometry_only: bool
    no_collisions: bool
    dmass: object               # dMass about the centre of mass, or None (geometry only)
    com: np.ndarray             # (3,) centre of mass in the object frame


# ---------------------------------------------------------------------------------- checks

def _part(what: str, given, mass: float, position, orientation,
          max_triangles: int = limits.MAX_MESH_TRIANGLES) -> _Part:
    """The checked geometry of an ObjectSpec or PartSpec ``given``; a mesh of more than
    ``max_triangles`` is refused before anything is converted, checked or cached."""
    try:
        triangles = len(given.indices) // 3
    except TypeError:
        triangles = 0       # prepare_shape names what is wrong with them
    check.at_most(f"{what}: mesh (max_mesh_triangles)", triangles, max_triangles, "triangles")
    shape, cache_key = _shape(what, given)
    surface = check.surface(what, given.surface)
    if shape.kind == "plane" and surface.friction2 is not None:
        raise InvalidArgument(f"{what}: anisotropic friction (friction2) on a plane is not "
                              "supported")
    return _Part(given.name, shape, mass, check.vector(f"{what}: position", position),
                 check.quaternion(f"{what}: orientation", orientation),
                 check.color(f"{what}: color", given.color),
                 given.parameters, given.indices, int(given.shape), surface, cache_key)


_MESH_SHAPES: "collections.OrderedDict[Tuple[bytes, int], Shape]" = collections.OrderedDict()
"""Meshes checked lately, by a digest of their exact parameters (float64 bytes) and indices
(uint32 bytes) and the shape asked: checking a mesh (its indices in range, not every triangle
degenerate) and converting a message's tuples took ~0.13 s of the TX90 + hand's Build Entity,
and the same robot comes back after every New Scene. Only meshes of objects that were built
are kept (``remember_shapes``): a refused request leaves the cache as it was; their arrays are
read-only, shared by every geometry built over them."""
_MESH_SHAPES_LOCK = threading.Lock()     # two Cores may build at once
#: bytes of vertex and triangle arrays the cache of checked meshes keeps at most (the TX90 +
#: hand + cans: ~4.5 MB)
MESH_SHAPE_BYTES = 64 * 2 ** 20


def _shape(what: str, given) -> Tuple[Shape, Optional[Tuple[bytes, int]]]:
    """prepare_shape of ``given``'s parameters, indices and shape, a mesh from _MESH_SHAPES
    when the very same one passed before; with the cache key to remember it by once built
    (None: not a mesh, or already cached)."""
    values, indices = float64_array(given.parameters), uint32_array(given.indices)
    if (values is None or indices is None or not indices.size
            or not isinstance(given.shape, int) or not np.all(np.isfinite(values))):
        return prepare_shape(what, given.parameters, given.indices, given.shape), None
    key = (mesh_digest(values, indices), int(given.shape))
    with _MESH_SHAPES_LOCK:
        shape = _MESH_SHAPES.get(key)
        if shape is not None:
            _MESH_SHAPES.move_to_end(key)     # most recently used last
            return shape, None
    shape = prepare_shape(what, values, indices, given.shape)
    if shape.kind != "mesh":
        return shape, None
    shape.vertices.flags.writeable = False
    shape.triangles.flags.writeable = False
    return shape, key


def remember_shapes(prepared: Sequence["_Prepared"]) -> None:
    """Keeps the meshes of objects just built in _MESH_SHAPES (never those of a refusal)."""
    with _MESH_SHAPES_LOCK:
        for p in prepared:
            for part in p.parts:
                if part.cache_key is not None:
                    _MESH_SHAPES[part.cache_key] = part.shape
        held = sum(s.vertices.nbytes + s.triangles.nbytes for s in _MESH_SHAPES.values())
        while len(_MESH_SHAPES) > 1 and held > MESH_SHAPE_BYTES:
            _, shape = _MESH_SHAPES.popitem(last=False)
            held -= shape.vertices.nbytes + shape.triangles.nbytes


def _given_mass(what: str, mass: float, inertia, center_of_mass):
    """The dMass of ``mass`` kg with a given ``inertia`` (6 values, kg m^2) about
    ``center_of_mass`` ((3,) m or empty: the origin), or None when no inertia is given (a
    centre of mass without an inertia is refused: the shape's inertia is about its own)."""
    if not len(inertia):
        if len(center_of_mass):
            raise InvalidArgument(f"{what}: center_of_mass needs an inertia")
        return None
    i = check.vector(f"{what}: inertia", inertia, 6)
    # before ODE forms its matrix: sums of such values would overflow to inf
    check.at_most(f"{what}: inertia (MAX_INERTIA)", float(np.max(np.abs(i))),
                  limits.MAX_INERTIA, "kg m^2")
    center = check.vector(f"{what}: center_of_mass", center_of_mass) \
        if len(center_of_mass) else np.zeros(3)
    matrix = np.array([[i[0], i[3], i[4]], [i[3], i[1], i[5]], [i[4], i[5], i[2]]])
    return bodies.mass_from_parameters(mass, center.tolist(), matrix)


def _centred(what: str, dmass) -> np.ndarray:
    """Moves ``dmass`` to its centre of mass, checks it; returns the centre (object frame)."""
    com = bodies.mass_center(dmass)
    bodies.center_mass(dmass)
    check_mass(what, dmass)
    return com


def _part_points(part: _Part) -> np.ndarray:
    """(n, 3) m, object frame: a mesh part's vertices, a primitive's bounding box corners."""
    if part.shape.kind == "mesh":
        local = part.shape.vertices
    else:
        local = limits.primitive_corners(part.shape.kind, part.shape.dims)
    return local @ quaternion_to_matrix(part.orientation).T + part.position


def _check_given_inertia(what: str, dmass, com: np.ndarray, parts: Sequence[_Part],
                         mass: float) -> None:
    """InvalidArgument when a given inertia (centred ``dmass``) is too light or too heavy in
    rotation for the parts' geometry and mass (odin_common.limits.inertia_problem): ODE's
    solver would then return non-finite velocities, and ODE aborts the process on those."""
    points = np.concatenate([_part_points(part) for part in parts]) - com
    problem = limits.inertia_problem(bodies.inertia_matrix(dmass), mass, points)
    if problem is not None:
        raise InvalidArgument(f"{what}: inertia: {problem}")


def prepare_object(spec: ObjectSpec,
                   max_triangles: int = limits.MAX_MESH_TRIANGLES) -> _Prepared:
    if not isinstance(spec, ObjectSpec):
        raise InvalidArgument(f"{shown(spec)} is not an ObjectSpec")
    name = check.name("object name", spec.name)
    what = f"object {shown(name)}"
    geometry_only = check.flag(f"{what}: geometry_only", spec.geometry_only)
    no_collisions = check.flag(f"{what}: no_collisions", spec.no_collisions)
    mass = check.number(f"{what}: mass", spec.mass)
    if geometry_only:   # no body: 0 or a mass a body could have, never a wrong one
        check.ignored_mass(what, mass)
    else:
        check.mass(what, mass)
    part = _part(what, spec, mass, (0.0, 0.0, 0.0), IDENTITY, max_triangles)
    if part.shape.kind == "plane" and not geometry_only:
        raise InvalidArgument(f"{what}: a plane is static: give geometry_only")
    position = check.vector(f"{what}: position", spec.position)
    orientation = check.quaternion(f"{what}: orientation", spec.orientation)
    fixed = check.flag(f"{what}: fixed", spec.fixed)
    given = _given_mass(what, mass, spec.inertia, spec.center_of_mass)
    dmass, com = None, np.zeros(3)
    if not geometry_only:
        dmass = given if given is not None else shape_mass(what, part.shape, mass)
        com = _centred(what, dmass)
        if given is not None:
            _check_given_inertia(what, dmass, com, [part], mass)
    return _Prepared(spec, name, [part], position, orientation, fixed, geometry_only,
                     no_collisions, dmass, com)


def prepare_composite(spec: CompositeSpec,
                      max_triangles: int = limits.MAX_MESH_TRIANGLES) -> _Prepared:
    if not isinstance(spec, CompositeSpec):
        raise InvalidArgument(f"{shown(spec)} is not a CompositeSpec")
    if len(spec.parts) == 0:
        raise InvalidArgument("a composite needs at least one part")
    parts = []
    for given in spec.parts:
        if not isinstance(given, PartSpec):
            raise InvalidArgument(f"{shown(given)} is not a PartSpec")
        name = check.name("part name", given.name)
        what = f"part {shown(name)}"
        mass = check.mass(what, check.number(f"{what}: mass", given.mass))
        part = _part(what, given, mass, given.position, given.orientation, max_triangles)
        if part.shape.kind == "plane":
            raise InvalidArgument(f"{what}: a plane cannot be a part of a composite")
        parts.append(part)
    object_id = composite_id([p.name for p in parts])
    what = f"composite {shown(object_id)}"
    position = check.vector(f"{what}: position", spec.position)
    orientation = check.quaternion(f"{what}: orientation", spec.orientation)
    fixed = check.flag("composite fixed", spec.fixed)
    geometry_only = check.flag("composite geometry_only", spec.geometry_only)
    no_collisions = check.flag("composite no_collisions", spec.no_collisions)
    dmass, com = None, np.zeros(3)
    given = _given_mass(what, sum(part.mass for part in parts), spec.inertia,
                        spec.center_of_mass)
    if not geometry_only:
        dmass = given
        if dmass is None:
            dmass = bodies.zero_mass()
            for part in parts:
                bodies.add_mass(dmass, shape_mass(f"part {shown(part.name)}", part.shape,
                                                  part.mass),
                                part.position.tolist(), part.orientation.tolist())
        com = _centred(f"object {shown(object_id)}", dmass)
        if given is not None:
            _check_given_inertia(f"object {shown(object_id)}", dmass, com, parts,
                                 sum(part.mass for part in parts))
    return _Prepared(spec, object_id, parts, position, orientation, fixed, geometry_only,
                     no_collisions, dmass, com)


def check_ranges(scene: Scene, prepared: Sequence[_Prepared]) -> None:
    """InvalidArgument for an object beyond the world's extent, a size outside the limits, a
    mesh of too many triangles, objects beyond the world's count (odin_common.limits,
    world_extent, the scene's ResourceLimits)."""
    extent, resources = scene.parameters.world_extent, scene.resources
    if len(scene.objects) + len(prepared) > resources.max_objects:
        raise InvalidArgument(f"{len(prepared)} more object(s) would exceed the world's limit "
                              f"of {resources.max_objects:,} objects (max_objects)")
    for p in prepared:
        what = f"object {shown(p.object_id)}"
        check.within_extent(f"{what}: position", p.position, extent)
        for part in p.parts:
            shape, where = part.shape, f"{what}: part {shown(part.name)}"
            check.within_extent(f"{where}: position", part.position, extent)
            if shape.kind == "mesh":
                check.at_most(f"{where}: mesh (max_mesh_triangles)", len(shape.triangles),
                              resources.max_mesh_triangles, "triangles")
                check.within_extent(f"{where}: a vertex", shape.vertices, extent)
            elif shape.dims:
                check.at_most(f"{where}: size", max(shape.dims), 2 * extent, "m")
                if min(shape.dims) < limits.MIN_SIZE:
                    raise InvalidArgument(f"{where}: size {shown(min(shape.dims))} m is below the "
                                          f"limit {limits.MIN_SIZE:g} m")


def check_new_names(scene: Scene, prepared: Sequence[_Prepared]) -> None:
    """DuplicateName if an object id or geometry name is taken (or given twice)."""
    seen: Set[str] = set()
    for name in (part.name for p in prepared for part in p.parts):
        if name in scene.geometries or name in seen:
            raise DuplicateName(f"geometry name {shown(name)} is already taken")
        seen.add(name)
    seen = set()
    for p in prepared:
        if p.object_id in scene.objects or p.object_id in seen:
            raise DuplicateName(f"object id {shown(p.object_id)} is already taken")
        seen.add(p.object_id)


# ---------------------------------------------------------------------------------- building

def build(scene: Scene, prepared: _Prepared, tag: int = 0) -> Built:
    """Creates the checked object in ODE: its body (at the centre of mass), its geoms."""
    p = prepared
    body = None
    if not p.geometry_only:
        body = handles.new_body(scene.c.world)
        com_W = p.position + quaternion_to_matrix(p.orientation) @ p.com
        bodies.configure_body(body.ptr, p.dmass, com_W.tolist(), p.orientation.tolist(),
                              kinematic=p.fixed)
    obj = ObjectRecord(p.object_id, p.spec, body, p.com, p.fixed)
    for part in p.parts:
        obj.geometries.append(_build_geometry(scene, p, part, body, tag))
    scene.add_object(obj)
    if body is not None and not p.fixed:
        scene.c.add_guarded(body.ptr)
    return Built(p.object_id, _built_geometries(obj.geometries))


def _build_geometry(scene: Scene, p: _Prepared, part: _Part, body, tag: int) -> GeometryRecord:
    shape = part.shape
    if shape.kind == "mesh":
        vertices, triangles = collision_mesh(shape, scene.parameters.collision_mesh_tolerance)
        geom = handles.new_trimesh(scene.c.space, vertices, triangles, scene.take_serial(),
                                   body, meshes=scene.meshes)
    elif shape.kind == "plane":
        geom = handles.new_primitive(scene.c.space, "plane", _plane(p.position, p.orientation),
                                     scene.take_serial())
    else:
        geom = handles.new_primitive(scene.c.space, shape.kind, shape.dims,
                                     scene.take_serial(), body)
    if body is not None:
        bodies.set_geom_offset(geom.ptr, (part.position - p.com).tolist(),
                               part.orientation.tolist())
    elif shape.kind != "plane":
        place_static(geom.ptr, p.position, p.orientation, part.position, part.orientation)
    bodies.set_geom_tag(geom, tag)
    bodies.set_surface(geom, part.surface)
    if p.no_collisions:
        bodies.exclude_from_collisions(geom.ptr)
    record = GeometryRecord(part.name, geom, p.object_id, part.position, part.orientation,
                            shape, part.parameters, part.indices, part.color, part.shape_asked,
                            part.surface)
    scene.add_geometry(record)
    return record


def _built_geometries(records: Sequence[GeometryRecord]) -> Tuple[BuiltGeometry, ...]:
    positions, quaternions = PoseReader([r.owner for r in records]).read()
    return tuple(BuiltGeometry(r.name, _flat_numbers(r.parameters, float),
                               _flat_numbers(r.indices, int), r.color,
                               tuple(positions[k].tolist()), tuple(quaternions[k].tolist()),
                               r.shape_asked)
                 for k, r in enumerate(records))


def _flat_numbers(values, kind: type):
    """``values`` as a flat tuple of ``kind`` (float or int), or a read-only flat numpy array
    of float64 (float) or uint32 (int). A message's array already is one and is kept as it
    is: converting a hand's meshes (~800,000 numbers) through numpy and back took ~0.25 s of
    every load; a numpy request's arrays (odin_common.node.numpy_requests) ~0.03 s more."""
    if type(values) is np.ndarray:
        flat = (float64_array if kind is float else uint32_array)(values)
        if flat is not None:
            flat = flat.view()
            flat.flags.writeable = False     # the view only: its owner's array stays as it was
            return flat
    if type(values) is tuple and set(map(type, values)) <= {kind}:
        return values
    return tuple(np.asarray(values, float if kind is float else np.int64).reshape(-1).tolist())


def _plane(position: np.ndarray, orientation: np.ndarray) -> Tuple[float, float, float, float]:
    """(a, b, c, d) of the plane through ``position`` whose normal is the object's z axis."""
    normal = quaternion_to_matrix(orientation)[:, 2]
    return (*normal.tolist(), float(normal @ position))


def place_static(geom, position: np.ndarray, orientation: np.ndarray,
                 part_position: np.ndarray, part_orientation: np.ndarray) -> None:
    """A static geom at the object's pose composed with its pose in the object frame; a plane
    through the object's position, normal to its z axis."""
    if bodies.is_plane(geom):
        a, b, c, d = _plane(position, orientation)
        bodies.place_plane(geom, (a, b, c), d)
        return
    bodies.set_geom_pose(geom, (position + quaternion_to_matrix(orientation) @ part_position)
                         .tolist(), quaternion_multiply(orientation, part_orientation).tolist())


def build_object(scene: Scene, spec: ObjectSpec) -> Built:
    return _build_one(scene, prepare_object(spec, scene.resources.max_mesh_triangles))


def build_composite(scene: Scene, spec: CompositeSpec) -> Built:
    return _build_one(scene, prepare_composite(spec, scene.resources.max_mesh_triangles))


def _build_one(scene: Scene, prepared: _Prepared) -> Built:
    """A prepared object or composite checked against the scene, then built."""
    check_ranges(scene, [prepared])
    check_new_names(scene, [prepared])
    built = build(scene, prepared)
    remember_shapes([prepared])
    return built


def build_entity(scene: Scene, spec: EntitySpec) -> BuiltEntity:
    """Builds an entity's members all or nothing; name "" gives "entity<n>"."""
    if not isinstance(spec, EntitySpec):
        raise InvalidArgument(f"{shown(spec)} is not an EntitySpec")
    internal = check.flag("internal_collisions", spec.internal_collisions)
    name = check.text("entity name", spec.name)
    name = check.name("entity name", name, allow_marker=True) if name else \
        _free_entity_name(scene)
    if name in scene.entities:
        raise DuplicateName(f"entity {shown(name)} already exists")
    count = len(spec.objects) + len(spec.composites)     # before preparing any of them
    if len(scene.objects) + count > scene.resources.max_objects:
        raise InvalidArgument(f"entity {shown(name)}: {count:,} more object(s) would exceed the "
                              f"world's limit of {scene.resources.max_objects:,} objects "
                              "(max_objects)")
    most = scene.resources.max_mesh_triangles
    prepared = [prepare_object(s, most) for s in spec.objects]
    prepared += [prepare_composite(s, most) for s in spec.composites]
    if not prepared:
        raise InvalidArgument(f"entity {shown(name)} has no objects")
    check_ranges(scene, prepared)
    check_new_names(scene, prepared)
    tag = 0
    if not internal:
        tag = scene.next_tag
        scene.next_tag += 1
    members: List[Built] = []
    try:
        for p in prepared:
            members.append(build(scene, p, tag))
    except Exception:
        for member in members:
            remove_object(scene, member.id)
        raise
    remember_shapes(prepared)
    for member in members:
        scene.objects[member.id].entity = name
    scene.entities[name] = [member.id for member in members]
    return BuiltEntity(name, tuple(members))


def _free_entity_name(scene: Scene) -> str:
    scene.entity_counter += 1
    while f"entity{scene.entity_counter}" in scene.entities:
        scene.entity_counter += 1
    return f"entity{scene.entity_counter}"


# ---------------------------------------------------------------------------------- removal

def remove_object(scene: Scene, object_id: str) -> Removed:
    """Removes an object with its joints, motors and forces; returns every removed id."""
    obj = scene.object(object_id)
    removed = Removed()
    for joint_id in sorted(obj.joints):
        removed += joints.remove_joint(scene, joint_id)
    for motor_id in sorted(obj.motors):
        motors.remove_motor(scene, motor_id)
        removed += Removed(motors=(motor_id,))
    if obj.forces:
        removed += Removed(forces=tuple(sorted(obj.forces)))
        forces.drop_body_forces(scene, obj.forces)
    names = tuple(g.name for g in obj.geometries)
    readout.carry_collisions(scene, set(names))
    exemptions.drop_geometries(scene, set(names))
    scene.drop_object(object_id)
    scene.parked.pop(object_id, None)
    guard.refresh(scene)        # before the body goes: C must never see a freed body
    for geometry in obj.geometries:
        scene.drop_geometry(geometry)
        geometry.owner.close()
    if obj.body is not None:
        obj.body.close()
    if obj.entity is not None:
        members = scene.entities[obj.entity]
        members.remove(object_id)
        if not members:
            del scene.entities[obj.entity]
    return removed + Removed(geometries=names)


# ---------------------------------------------------------------------------------- moving

def check_poses(scene: Scene, poses) -> list:
    """[(object record, position (3,), orientation (4,))] of (object id, position m world,
    orientation wxyz) items, each checked. More items than the scene has objects are refused
    before any is read, an unknown object at the first: a request's work is bounded by the
    world's size, not by what the request holds."""
    try:
        count = len(poses)
    except TypeError:
        raise InvalidArgument(f"poses={shown(poses)} is not a sequence") from None
    if count > len(scene.objects):
        raise InvalidArgument(f"{count:,} poses given; the world holds {len(scene.objects):,} "
                              "objects (each object at most once)")
    checked = []
    for item in poses:
        try:
            object_id, position, orientation = item
        except (TypeError, ValueError):
            raise InvalidArgument(f"{shown(item)} is not (id, position, orientation)") from None
        obj = scene.object(object_id)
        where = f"position of {shown(object_id)}"
        checked.append((obj, check.within_extent(where, check.vector(where, position),
                                                 scene.parameters.world_extent),
                        check.quaternion(f"orientation of {shown(object_id)}", orientation)))
    return checked


def set_poses(scene: Scene, poses: Sequence[Tuple[str, Sequence[float], Sequence[float]]],
              reset_velocity: bool = False) -> None:
    """Moves objects: (object id, position m world, orientation wxyz) each, all or nothing."""
    reset_velocity = check.flag("reset_velocity", reset_velocity)
    for obj, position, orientation in check_poses(scene, poses):
        if obj.body is not None:
            com_W = position + quaternion_to_matrix(orientation) @ obj.com
            bodies.set_body_pose(obj.body.ptr, com_W.tolist(), orientation.tolist())
            if reset_velocity:
                bodies.set_body_velocity(obj.body.ptr, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        else:
            for g in obj.geometries:
                place_static(g.owner.ptr, position, orientation, g.position, g.orientation)


def set_velocity(scene: Scene, object_id: str, linear=None, angular=None) -> None:
    """Linear velocity of the centre of mass (m/s) and/or angular velocity (rad/s), world
    frame; None keeps the current one. A fixed (kinematic) body then moves at it."""
    obj = scene.body_object(object_id, "set_velocity")
    linear, angular = check_velocities(scene, linear, angular)
    bodies.set_body_velocity(obj.body.ptr, None if linear is None else linear.tolist(),
                             None if angular is None else angular.tolist())


def set_surface(scene: Scene, name: str, surface) -> None:
    """The contact properties of an object's geometries (an object ID) or of one geometry (a
    composite part's name), from the next step on."""
    surface = check.surface(f"surface of {shown(name)}", surface)
    if name in scene.objects:
        geometries = scene.objects[name].geometries
    else:
        geometries = [scene.geometry(name)]
    if surface.friction2 is not None and any(g.shape.kind == "plane" for g in geometries):
        raise InvalidArgument(f"{shown(name)}: anisotropic friction (friction2) on a plane is not "
                              "supported")
    for geometry in geometries:
        bodies.set_surface(geometry.owner, surface)
        geometry.surface = surface


def check_velocities(scene: Scene, linear=None, angular=None):
    """(linear (3,) m/s or None, angular (3,) rad/s or None), checked: finite, and within the
    divergence guard's speeds (a faster body would be parked at once)."""
    p = scene.parameters
    if linear is not None:
        linear = check.vector("linear velocity", linear)
        check.at_most("linear velocity", float(np.linalg.norm(linear)), p.divergence_speed,
                      "m/s (divergence_speed)")
    if angular is not None:
        angular = check.vector("angular velocity", angular)
        check.at_most("angular velocity", float(np.linalg.norm(angular)),
                      p.divergence_angular_speed, "rad/s (divergence_angular_speed)")
    return linear, angular


def entity_members(scene: Scene) -> Dict[str, List[str]]:
    """Entity name -> ids of its objects still alive."""
    return {name: list(ids) for name, ids in scene.entities.items()}


__all__ = ["prepare_object", "prepare_composite", "build_object", "build_composite",
           "build_entity", "remove_object", "set_poses", "set_velocity", "place_static",
           "entity_members"]
