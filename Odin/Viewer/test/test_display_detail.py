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
