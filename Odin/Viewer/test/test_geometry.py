"""Shapes, poses and the one place where ODE's (w, x, y, z) quaternion becomes a rotation."""
import math
import tracemalloc

import numpy as np
import pytest

from viewer.errors import ViewerError
from viewer.core.geometry import (GeometryCache, _welded,
                                  geometry_from_parameters, pose_matrices,
                                  pose_matrix, rotation_from_wxyz, unit_box, unit_cylinder,
                                  unit_sphere)
from odin_common import OdinError

S = math.sqrt(0.5)


def test_identity_quaternion_is_w_first():
    np.testing.assert_allclose(rotation_from_wxyz((1, 0, 0, 0)), np.eye(3), atol=1e-12)


def test_quarter_turn_about_z_takes_x_to_y():
    R = rotation_from_wxyz((S, 0, 0, S))        # (w, x, y, z): 90 degrees about z
    np.testing.assert_allclose(R @ [1, 0, 0], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(R @ [0, 0, 1], [0, 0, 1], atol=1e-12)


def test_half_turn_about_x_read_in_ode_order():
    # (0, 1, 0, 0) is 180 degrees about x in (w, x, y, z); read as (x, y, z, w) it would be
    # 180 degrees about y, which sends x to -x instead of keeping it.
    R = rotation_from_wxyz((0, 1, 0, 0))
    np.testing.assert_allclose(R @ [1, 0, 0], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(R @ [0, 0, 1], [0, 0, -1], atol=1e-12)


def test_nearly_unit_quaternion_is_normalised():
    R = rotation_from_wxyz((1.0005, 0, 0, 0))   # within QUATERNION_TOLERANCE
    np.testing.assert_allclose(R, np.eye(3), atol=1e-12)


@pytest.mark.parametrize("q", [(0, 0, 0, 0), (2, 0, 0, 0), (math.nan, 0, 0, 1), (1, 0, 0),
                               (math.inf, 0, 0, 0)])
def test_bad_quaternions_are_refused(q):
    with pytest.raises(ViewerError):
        rotation_from_wxyz(q)


def test_pose_matrix_and_nan_position():
    T = pose_matrix((1, 2, 3), (S, 0, 0, S))
    np.testing.assert_allclose(T @ [1, 0, 0, 1], [1, 3, 3, 1], atol=1e-12)
    with pytest.raises(ViewerError, match="position"):
        pose_matrix((0, math.nan, 0), (1, 0, 0, 0))


def test_viewer_error_is_an_odin_error():
    assert issubclass(ViewerError, OdinError)


def test_shape_follows_parameter_count():
    assert geometry_from_parameters([0.5]).kind == "sphere"
    cylinder = geometry_from_parameters([0.1, 2.0])
    assert cylinder.kind == "cylinder" and cylinder.scale_B == (0.1, 0.1, 2.0)
    box = geometry_from_parameters([1, 2, 3])
    assert box.kind == "box" and box.radius == pytest.approx(0.5 * math.sqrt(14))
    mesh = geometry_from_parameters([0, 0, 0, 1, 0, 0, 0, 1, 0], [0, 1, 2])
    assert mesh.kind == "mesh" and mesh.triangle_count == 1
    np.testing.assert_allclose(mesh.normals_B, [[0, 0, 1]] * 3)


@pytest.mark.parametrize("params, indices, match", [
    ([], [], "0 parameters"),
    ([1, 2, 3, 4], [], "4 parameters"),
    ([0] * 10, [0, 1, 2], "10 parameters"),
    ([-1.0], [], "radius"),
    ([0.1, 0.0], [], "length"),
    ([1, math.nan, 1], [], "side y"),
    ([0, 0, 0, 1, 0, 0, 0, 1, 0], [], "no triangles"),
    ([0, 0, 0, 1, 0, 0, 0, 1, 0], [0, 1], "3 per triangle"),
    ([0, 0, 0, 1, 0, 0, 0, 1, 0], [0, 1, 3], "index 3 out of range"),
    ([0, 0, 0, 1, 0, 0, 0, math.nan, 0], [0, 1, 2], "finite"),
])
def test_bad_shapes_are_refused(params, indices, match):
    with pytest.raises(ViewerError, match=match):
        geometry_from_parameters(params, indices)


@pytest.mark.parametrize("build", [unit_sphere, unit_cylinder, unit_box])
def test_unit_primitives_have_outward_counter_clockwise_triangles(build):
    vertices, normals, indices = build()
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1, atol=1e-6)
    tri = vertices[indices.reshape(-1, 3)].astype(float)
    face_normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    centre = tri.mean(axis=1)
    keep = np.linalg.norm(face_normal, axis=1) > 1e-9   # poles of the sphere are degenerate
    assert np.all(np.einsum("ij,ij->i", face_normal[keep], centre[keep]) > 0)
    assert np.abs(vertices).max() == pytest.approx(1.0 if build is unit_sphere else
                                                  (1.0 if build is unit_cylinder else 0.5))


CUBE_VERTICES = [x for i in range(8) for x in ((i & 1) - 0.5, (i >> 1 & 1) - 0.5,
                                                  (i >> 2 & 1) - 0.5)]
CUBE_TRIANGLES = [0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                  2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5]


def test_cube_mesh_is_closed_and_keeps_hard_edges():
    cube = geometry_from_parameters(CUBE_VERTICES, CUBE_TRIANGLES)
    assert cube.closed and cube.triangle_count == 12
    normals = cube.normals_B[cube.indices_B]
    # every corner of a cube is a crease: each corner carries its face's axis-aligned normal
    np.testing.assert_allclose(np.sort(np.abs(normals), axis=1), [[0, 0, 1]] * 36, atol=1e-6)


def _outward_share(geometry) -> float:
    """Share of the triangles whose winding normal points away from the origin."""
    corners = geometry.vertices_B[geometry.indices_B].reshape(-1, 3, 3).astype(float)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    return float(np.mean(np.einsum("ij,ij->i", normals, corners.mean(axis=1)) > 0))


def test_a_closed_mesh_wound_inwards_is_turned_outwards_and_drawn_closed():
    inverted = np.array(CUBE_TRIANGLES).reshape(-1, 3)[:, ::-1].ravel()
    cube = geometry_from_parameters(CUBE_VERTICES, inverted)
    assert cube.closed and _outward_share(cube) == 1.0
    normals = cube.normals_B[cube.indices_B].astype(float)
    centres = cube.vertices_B[cube.indices_B].astype(float)
    assert np.all(np.einsum("ij,ij->i", normals, centres) > 0)    # lit from outside


def test_open_or_inconsistently_wound_meshes_are_not_closed():
    assert not geometry_from_parameters(CUBE_VERTICES, CUBE_TRIANGLES[:-3]).closed
    one_flipped = np.array(CUBE_TRIANGLES).reshape(-1, 3)
    one_flipped[0] = one_flipped[0, ::-1]
    assert not geometry_from_parameters(CUBE_VERTICES, one_flipped.ravel()).closed


def test_repeated_triangles_and_unwelded_corners_keep_a_mesh_closed():
    # CAD meshes repeat a few triangles; STL-like soups repeat each corner per triangle
    repeated = CUBE_TRIANGLES + CUBE_TRIANGLES[:3]
    assert geometry_from_parameters(CUBE_VERTICES, repeated).closed
    corners = np.array(CUBE_VERTICES).reshape(-1, 3)[CUBE_TRIANGLES]
    soup = geometry_from_parameters(corners.ravel(), range(len(corners)))
    assert soup.closed


def test_finely_tessellated_surface_is_smooth():
    # a fan of 16 triangles around a shallow cone apex: one shared, averaged normal at the apex
    ring = [(math.cos(a), math.sin(a), -0.1) for a in np.linspace(0, 2 * math.pi, 16,
                                                                  endpoint=False)]
    vertices = [0.0, 0.0, 0.0] + [c for p in ring for c in p]
    triangles = [k for i in range(16) for k in (0, 1 + i, 1 + (i + 1) % 16)]
    mesh = geometry_from_parameters(vertices, triangles)
    apex = mesh.normals_B[mesh.indices_B[0::3]]
    np.testing.assert_allclose(apex, [[0, 0, 1]] * 16, atol=1e-6)


def test_a_capsule_is_one_closed_mesh_of_its_size():
    from viewer.core.geometry import capsule_geometry
    g = geometry_from_parameters([0.05, 0.3], shape=5)
    assert g.kind == "mesh" and g.closed and g.radius == pytest.approx(0.2, rel=1e-3)
    z = g.vertices_B[:, 2]
    assert z.min() == pytest.approx(-0.2, abs=1e-6) and z.max() == pytest.approx(0.2, abs=1e-6)
    rim = np.hypot(g.vertices_B[:, 0], g.vertices_B[:, 1])
    assert rim.max() == pytest.approx(0.05, rel=1e-3)
    assert capsule_geometry(0.05, 0.3).triangle_count == g.triangle_count


def test_a_plane_is_a_large_unbounded_floor():
    g = geometry_from_parameters([], shape=6)
    assert g.kind == "box" and not g.bounded and g.scale_B[2] < 0.01 and g.scale_B[0] >= 50


@pytest.mark.parametrize("parameters,shape", [([0.1], 5), ([1.0], 6), ([0.1, 0.2], 9),
                                              ([0.1, -0.2], 5)])
def test_a_named_shape_with_the_wrong_parameters_is_refused(parameters, shape):
    with pytest.raises(ViewerError):
        geometry_from_parameters(parameters, shape=shape)


def test_the_cache_gives_the_geometry_built_before_for_the_same_content():
    cache = GeometryCache()
    first = cache.geometry(CUBE_VERTICES, CUBE_TRIANGLES)
    # the same numbers as a tuple and as arrays (what rospy and a marker give) are the same
    again = cache.geometry(tuple(CUBE_VERTICES), np.array(CUBE_TRIANGLES, np.uint32))
    assert again is first and (cache.misses, cache.hits) == (1, 1)
    built = geometry_from_parameters(CUBE_VERTICES, CUBE_TRIANGLES)
    np.testing.assert_array_equal(first.vertices_B, built.vertices_B)
    np.testing.assert_array_equal(first.indices_B, built.indices_B)
    assert first.closed == built.closed and first.radius == built.radius


def test_the_cache_tells_apart_shapes_sizes_and_windings():
    cache = GeometryCache()
    inverted = np.array(CUBE_TRIANGLES).reshape(-1, 3)[:, ::-1].ravel()
    geometries = [cache.geometry([0.5]), cache.geometry([0.6]), cache.geometry([0.5, 0.5]),
                  cache.geometry([0.05, 0.3], shape=5), cache.geometry([0.05, 0.3]),
                  cache.geometry(CUBE_VERTICES, CUBE_TRIANGLES),
                  cache.geometry(CUBE_VERTICES, inverted)]
    assert len({id(g) for g in geometries}) == len(geometries) == cache.misses
    assert [g.kind for g in geometries[2:5]] == ["cylinder", "mesh", "cylinder"]


def test_the_cache_refuses_bad_content_every_time_and_keeps_nothing_for_it():
    cache = GeometryCache()
    for _ in range(2):
        with pytest.raises(ViewerError, match="out of range"):
            cache.geometry([0, 0, 0, 1, 0, 0, 0, 1, 0], [0, 1, 3])
        with pytest.raises(ViewerError, match=r"in \[1e-06, "):
            cache.geometry([-1.0])
    assert len(cache) == 0


def test_the_cache_forgets_the_least_recently_used_beyond_its_triangles():
    cache = GeometryCache(max_triangles=24)         # two cubes of 12 triangles
    cube = cache.geometry(CUBE_VERTICES, CUBE_TRIANGLES)
    shifted = [v + 1.0 for v in CUBE_VERTICES]
    other = cache.geometry(shifted, CUBE_TRIANGLES)
    assert cache.geometry(CUBE_VERTICES, CUBE_TRIANGLES) is cube     # now the most recent
    third = [v + 2.0 for v in CUBE_VERTICES]
    cache.geometry(third, CUBE_TRIANGLES)                            # pushes out `other`
    assert cache.geometry(CUBE_VERTICES, CUBE_TRIANGLES) is cube
    assert cache.geometry(shifted, CUBE_TRIANGLES) is not other
    assert len(cache) == 2


def test_the_cache_keeps_no_primitive_so_random_sizes_do_not_grow_it():
    # the soak's clients build spheres and boxes of random sizes: each one kept cost ~0.8 KB
    # for nothing (a primitive is built in microseconds), 48 MB in 10 minutes
    cache = GeometryCache()
    rng = np.random.default_rng(11)
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        for k in range(4000):
            sizes = rng.uniform(0.02, 0.4, size=1 + 2 * (k % 2))        # spheres and boxes
            cache.geometry(sizes)
        cache.geometry([0.05, 0.3], shape=2)                            # a cylinder
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert len(cache) == 0
    assert grown < 300_000, f"{grown} bytes kept for 4,001 primitives"


def test_the_cache_forgets_the_least_recently_used_beyond_its_entries():
    cache = GeometryCache(max_entries=5)            # few triangles each: the count bounds it
    triangles = [cache.geometry([0, 0, 0, 1, 0, 0, 0, 1, float(k)], [0, 1, 2])
                 for k in range(1, 9)]
    assert len(cache) == 5
    assert cache.geometry([0, 0, 0, 1, 0, 0, 0, 1, 8.0], [0, 1, 2]) is triangles[-1]
    assert cache.geometry([0, 0, 0, 1, 0, 0, 0, 1, 1.0], [0, 1, 2]) is not triangles[0]
    assert len(cache) == 5


def test_poses_made_together_are_the_poses_made_one_by_one_and_bad_ones_are_flagged():
    rng = np.random.default_rng(3)
    quaternions = rng.normal(size=(6, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1, keepdims=True)
    quaternions[1] *= 1.0005                        # within the tolerance: normalised
    quaternions[2] *= 1.01                          # too far from unit length
    quaternions[3] = 0.0                            # no rotation at all
    positions = rng.normal(size=(6, 3))
    positions[4, 1] = np.nan
    quaternions[5, 0] = np.inf
    poses, valid = pose_matrices(positions, quaternions)
    assert valid.tolist() == [True, True, False, False, False, False]
    for k in (0, 1):
        np.testing.assert_allclose(poses[k], pose_matrix(positions[k], quaternions[k]),
                                   atol=1e-15)
    for k in range(2, 6):
        with pytest.raises(ViewerError):
            pose_matrix(positions[k], quaternions[k])
    assert pose_matrices(np.zeros((0, 3)), np.zeros((0, 4)))[0].shape == (0, 4, 4)


def test_welding_takes_vertices_at_the_same_place_as_one_as_np_unique_does():
    rng = np.random.default_rng(5)
    vertices = rng.integers(0, 4, size=(3000, 3)).astype(float) * 0.25
    vertices[::7, 2] = -0.0                       # -0.0 and 0.0 are one place
    welded = _welded(vertices)
    _, reference = np.unique(vertices, axis=0, return_inverse=True)
    pairs = set(zip(welded.tolist(), reference.ravel().tolist()))
    assert len(pairs) == len(set(welded.tolist())) == len(set(reference.ravel().tolist()))
    for index in np.unique(welded):               # one place per welded index
        assert len(np.unique(vertices[welded == index] + 0.0, axis=0)) == 1
    assert _welded(np.zeros((0, 3))).shape == (0,)
