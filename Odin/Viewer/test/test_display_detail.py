"""Large meshes are drawn simplified, within the display tolerance of the original."""
import numpy as np
import trimesh

from odin_common.meshes import cluster_vertices
from viewer.core.geometry import DISPLAY_TOLERANCE, mesh_geometry


def test_dense_mesh_is_simplified_within_tolerance():
    dense = trimesh.creation.icosphere(subdivisions=6, radius=0.03)   # 82k triangles
    vertices, indices = np.asarray(dense.vertices), np.asarray(dense.faces).reshape(-1)
    geometry = mesh_geometry(vertices, indices)
    assert geometry.triangle_count < 0.5 * len(dense.faces)
    radii = np.linalg.norm(geometry.vertices_B.astype(float), axis=1)
    assert np.all(np.abs(radii - 0.03) < DISPLAY_TOLERANCE)
    assert geometry.closed


def test_small_meshes_are_drawn_as_given():
    box = trimesh.creation.box((0.1, 0.2, 0.3))
    geometry = mesh_geometry(np.asarray(box.vertices), np.asarray(box.faces).reshape(-1))
    assert geometry.triangle_count == 12


def test_clustering_drops_collapsed_and_repeated_triangles():
    vertices = np.array([[0, 0, 0], [1e-5, 0, 0], [0.01, 0, 0], [0, 0.01, 0]], float)
    indices = np.array([0, 1, 2,   0, 2, 3,   1, 2, 3])
    merged, triangles = cluster_vertices(vertices, indices, cell=0.001)
    assert len(merged) == 3 and triangles.size == 3


def test_levels_of_detail_coarsen_with_the_cell_and_stay_near_the_surface():
    dense = trimesh.creation.icosphere(subdivisions=5, radius=0.05)   # 20k triangles
    geometry = mesh_geometry(np.asarray(dense.vertices), np.asarray(dense.faces).reshape(-1))
    level0, *arrays0 = geometry.detail(0.0)
    assert level0 == 0 and arrays0[2] is geometry.indices_B
    counts = []
    for cell in (0.002, 0.004, 0.008):
        level, vertices, normals, indices = geometry.detail(cell)
        assert DISPLAY_TOLERANCE * 2 ** level <= cell < DISPLAY_TOLERANCE * 2 ** (level + 1)
        used = vertices[np.unique(indices)].astype(float)
        radii = np.linalg.norm(used, axis=1)
        assert np.all(np.abs(radii - 0.05) < np.sqrt(3) * cell), cell
        assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-5)
        counts.append(len(indices) // 3)
        assert geometry.detail(cell)[3] is indices            # made once
    assert geometry.triangle_count > counts[0] > counts[1] > counts[2] > 0


def test_a_level_whose_triangles_all_collapse_is_never_drawn():
    small = trimesh.creation.icosphere(subdivisions=4, radius=0.004)   # 5k triangles, 8 mm
    geometry = mesh_geometry(np.asarray(small.vertices), np.asarray(small.faces).reshape(-1))
    level, _, _, indices = geometry.detail(1.0)
    assert len(indices) >= 3 and DISPLAY_TOLERANCE * 2 ** level < 0.008


def test_small_meshes_have_no_levels():
    box = trimesh.creation.box((0.1, 0.2, 0.3))
    geometry = mesh_geometry(np.asarray(box.vertices), np.asarray(box.faces).reshape(-1))
    assert geometry.levels is None and geometry.detail(1.0)[0] == 0
