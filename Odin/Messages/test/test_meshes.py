"""odin_common.meshes: a mesh wound clockwise is turned to face outwards, one wound
counter-clockwise is left as it is. Clustering packs rows into int64 keys to find unique
vertices and triangles fast; the answers must be numpy's own, in the same order (collision
meshes, and so the physics, depend on the clusters' order), including where the keys would
overflow."""
import numpy as np
import pytest

from odin_common import meshes
from odin_common.meshes import facing_outwards

# a tetrahedron, every triangle counter-clockwise seen from outside
VERTICES = np.array([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], dtype=float)
OUTWARD = np.array([0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3])


def _signed_volume(indices) -> float:
    corners = VERTICES[np.asarray(indices).reshape(-1, 3)]
    return float(np.einsum("ij,ij->i", corners[:, 0],
                           np.cross(corners[:, 1], corners[:, 2])).sum() / 6)


def test_an_outward_mesh_is_kept_and_an_inverted_one_reversed():
    assert _signed_volume(OUTWARD) > 0
    assert facing_outwards(VERTICES, OUTWARD).tolist() == OUTWARD.tolist()
    inverted = OUTWARD.reshape(-1, 3)[:, ::-1].reshape(-1)
    turned = facing_outwards(VERTICES, inverted)
    assert _signed_volume(turned) > 0
    assert sorted(map(tuple, np.sort(turned.reshape(-1, 3), axis=1))) == \
        sorted(map(tuple, np.sort(OUTWARD.reshape(-1, 3), axis=1)))


@pytest.mark.parametrize("scale", [1, 1_000, 2 ** 30])     # the last overflows 63 bits
def test_packed_rows_give_numpys_unique_rows(scale):
    rows = np.random.default_rng(7).integers(-scale, scale, size=(5000, 3), dtype=np.int64)
    rows[::7] = rows[3]                                      # repeated rows
    for option in ("return_inverse", "return_index"):
        expected = np.unique(rows, axis=0, **{option: True})[1].reshape(-1)
        got = meshes.unique_rows(rows, **{option: True})[1].reshape(-1)
        assert np.array_equal(got, expected), option


def test_no_rows():
    _, inverse = meshes.unique_rows(np.zeros((0, 3), np.int64), return_inverse=True)
    assert inverse.size == 0


def test_clustering_sums_vertices_as_add_at_does():
    """np.bincount's per-axis sums replace np.add.at: bit for bit the same means."""
    rng = np.random.default_rng(3)
    vertices = rng.normal(size=(4000, 3))
    indices = rng.integers(0, 4000, size=12000)
    merged, triangles = meshes.cluster_vertices(vertices, indices, 0.05)
    cells = np.floor(vertices / 0.05).astype(np.int64)
    _, cluster = np.unique(cells, axis=0, return_inverse=True)
    expected = np.zeros((cluster.max() + 1, 3))
    np.add.at(expected, cluster.reshape(-1), vertices)
    expected /= np.bincount(cluster.reshape(-1))[:, None]
    assert merged.tobytes() == expected.tobytes()
    assert triangles.size and triangles.max() < len(merged)
