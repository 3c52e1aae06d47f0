"""Objects through the Core: mass properties given or computed from a closed mesh, set against
closed forms, and what set_poses does to velocities."""
import math

import numpy as np
import pytest

from virtual_world.core import TORQUE, ObjectSpec
from virtual_world.errors import InvalidArgument

H = 0.001


def test_a_given_inertia_is_the_bodys_and_sets_its_angular_acceleration(core):
    """[Ixx, Iyy, Izz, Ixy, Ixz, Iyz] about the origin: the matrix mass_properties reports, and
    a torque tau gives the angular velocity h I^-1 tau after one step."""
    values = [2.0, 3.0, 4.0, 0.1, 0.2, 0.3]
    matrix = np.array([[2.0, 0.1, 0.2], [0.1, 3.0, 0.3], [0.2, 0.3, 4.0]])
    core.build_object(ObjectSpec("o", [0.2, 0.2, 0.2], mass=5.0, inertia=values))
    mass, com, inertia = core.mass_properties("o")
    assert mass == 5.0
    np.testing.assert_array_equal(com, 0.0)
    np.testing.assert_allclose(inertia, matrix, rtol=1e-12)
    tau = np.array([0.5, -1.0, 2.0])
    core.add_body_force("o", TORQUE, tau)
    core.step(H)
    np.testing.assert_allclose(core.body_state("o")[3], H * np.linalg.solve(matrix, tau),
                               rtol=1e-9)


@pytest.mark.parametrize("winding", [1, -1], ids=["outward", "inward"])
def test_a_closed_tetrahedron_has_its_exact_centre_and_inertia(core, winding):
    """The corner tetrahedron (0, a e_x, a e_y, a e_z) of mass m: centre of mass a/4 (1, 1, 1),
    inertia about it 3 m a^2 / 40 on the diagonal and m a^2 / 80 off it (from
    int x^2 dm = m a^2 / 10 and int x y dm = m a^2 / 20 about the corner). Its bounding box
    would put the centre at a/2 and the inertia elsewhere: the closed-mesh rule must be used,
    whichever way the faces wind."""
    a, m = 0.6, 4.0
    vertices = [0.0, 0.0, 0.0, a, 0.0, 0.0, 0.0, a, 0.0, 0.0, 0.0, a]
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])[:, ::winding]
    core.build_object(ObjectSpec("tet", vertices, faces.reshape(-1).tolist(), mass=m))
    mass, com, inertia = core.mass_properties("tet")
    assert mass == pytest.approx(m)
    np.testing.assert_allclose(com, (a / 4, a / 4, a / 4), atol=1e-12)
    expected = np.full((3, 3), m * a * a / 80) + np.eye(3) * (3 * m * a * a / 40 - m * a * a / 80)
    np.testing.assert_allclose(inertia, expected, atol=1e-12)


def test_a_closed_mesh_whose_surface_integrals_give_no_rigid_body_gets_its_bounding_box(core):
    """A 1 m cube and, 3 m away in the same mesh, a 0.5 m cube whose faces wind inward: closed
    and of positive volume, but its surface integrals give principal moments (-1.28, -1.28,
    0.18) kg m^2 per kg (the 2012 TX90's Tcp mesh was refused so, and its whole robot with
    it). The mesh gets the bounding box rule: a solid 3.75 x 1 x 1 m box centred on the box."""
    cube = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    outward = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                        [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    vertices = np.concatenate([cube * 0.5, cube * 0.25 + (3.0, 0.0, 0.0)])
    faces = np.concatenate([outward, outward[:, ::-1] + 8])
    m = 2.0
    core.build_object(ObjectSpec("odd", vertices.reshape(-1).tolist(),
                                 faces.reshape(-1).tolist(), mass=m))
    mass, com, inertia = core.mass_properties("odd")
    x, y, z = 3.75, 1.0, 1.0
    np.testing.assert_allclose(com, ((-0.5 + 3.25) / 2, 0.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(inertia, m / 12 * np.diag([y * y + z * z, x * x + z * z,
                                                          x * x + y * y]), atol=1e-12)


def test_set_poses_keeps_the_velocities_unless_told_to_reset_them(core):
    """A ball moving at (1, 2, 3) m/s and turning at (0.5, 0, -0.5) rad/s is moved: it keeps
    both velocities; moved with reset_velocity it is at rest, and stays where it was put."""
    core.build_object(ObjectSpec("ball", [0.1], mass=1.0))
    core.build_object(ObjectSpec("other", [0.1], mass=1.0, position=(5.0, 0.0, 0.0)))
    for name in ("ball", "other"):
        core.set_velocity(name, linear=(1.0, 2.0, 3.0), angular=(0.5, 0.0, -0.5))
    core.set_poses([("ball", (0.0, 0.0, 1.0), (1.0, 0.0, 0.0, 0.0))])
    np.testing.assert_allclose(core.body_state("ball")[2], (1.0, 2.0, 3.0))
    np.testing.assert_allclose(core.body_state("ball")[3], (0.5, 0.0, -0.5))
    turned = (math.cos(0.3), 0.0, math.sin(0.3), 0.0)
    core.set_poses([("ball", (0.0, 0.0, 2.0), turned)], reset_velocity=True)
    position, orientation, v, w = core.body_state("ball")
    np.testing.assert_array_equal(v, 0.0)
    np.testing.assert_array_equal(w, 0.0)
    core.step(H, 10)
    np.testing.assert_allclose(core.body_state("ball")[0], (0.0, 0.0, 2.0), atol=1e-15)
    np.testing.assert_allclose(core.body_state("other")[2], (1.0, 2.0, 3.0))   # untouched


def test_a_built_geometry_keeps_a_messages_arrays_and_flattens_any_other_sequence(core):
    """A message's float64[] and uint32[] arrive as tuples of floats and ints (or, from a
    numpy request, float64 and uint32 arrays): given back as they are (no copy of a large
    mesh; arrays flat and read-only); lists, other arrays and ints become flat float and int
    tuples."""
    corners = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    faces = (0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3)
    built = core.build_object(ObjectSpec("tetra", corners, faces)).geometries[0]
    assert built.parameters is corners and built.indices is faces
    box = core.build_object(ObjectSpec("box", [1, 2, 3], position=(3, 0, 0))).geometries[0]
    assert box.parameters == (1.0, 2.0, 3.0) and type(box.parameters[0]) is float
    given = np.array(corners, np.float32).reshape(4, 3), np.array(faces, np.int64)
    mesh = core.build_object(ObjectSpec("mesh", *given, position=(6, 0, 0))).geometries[0]
    assert mesh.parameters == corners and mesh.indices == faces
    assert {type(v) for v in mesh.parameters + mesh.indices} == {float, int}
    vertices, triangles = np.array(corners).reshape(4, 3), np.array(faces, np.uint32)
    kept = core.build_object(ObjectSpec("kept", vertices, triangles,
                                        position=(12, 0, 0))).geometries[0]
    assert kept.parameters.shape == (12,) and np.shares_memory(kept.parameters, vertices)
    assert kept.indices.dtype == np.uint32 and np.shares_memory(kept.indices, triangles)
    assert not kept.parameters.flags.writeable and vertices.flags.writeable


def _tetrahedron(scale: float = 1.0):
    corners = tuple(scale * v for v in (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0,
                                        0.0, 0.0, 1.0))
    return corners, (0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3)


def test_a_mesh_built_again_reuses_its_checked_shape_and_builds_the_same_body(core):
    """The same mesh after a New Scene (new tuples, the same numbers) is not checked again:
    its Shape is the one checked before, read-only, and the body is the same bit for bit."""
    corners, faces = _tetrahedron(0.37)
    core.build_object(ObjectSpec("tet", corners, faces, mass=2.0))
    first = core._scene.geometry("tet").shape
    before = core.mass_properties("tet")
    core.new_scene()
    core.build_object(ObjectSpec("tet", tuple(list(corners)), tuple(list(faces)), mass=2.0))
    again = core._scene.geometry("tet").shape
    assert again is first
    assert not again.vertices.flags.writeable and not again.triangles.flags.writeable
    for a, b in zip(before, core.mass_properties("tet")):
        assert np.asarray(a).tobytes() == np.asarray(b).tobytes()


def test_meshes_differing_in_one_bit_or_in_the_shape_asked_are_checked_apart(core):
    corners, faces = _tetrahedron()
    core.build_object(ObjectSpec("a", corners, faces))
    signed = (-0.0,) + corners[1:]
    core.build_object(ObjectSpec("b", signed, faces, position=(3, 0, 0)))
    a, b = core._scene.geometry("a").shape, core._scene.geometry("b").shape
    assert a is not b and np.signbit(b.vertices[0, 0]) and not np.signbit(a.vertices[0, 0])


def test_a_refused_mesh_is_refused_again_with_the_same_message(core):
    corners, _ = _tetrahedron()
    for _ in range(2):
        with pytest.raises(InvalidArgument, match=r"mesh index 7 out of range \[0, 3\]"):
            core.build_object(ObjectSpec("bad", corners, (0, 1, 7)))
    flat = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0)
    for _ in range(2):
        with pytest.raises(InvalidArgument, match="every mesh triangle is degenerate"):
            core.build_object(ObjectSpec("flat", flat, (0, 1, 2)))
    assert "bad" not in core._scene.objects and "flat" not in core._scene.objects
