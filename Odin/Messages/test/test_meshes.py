"""odin_common.meshes: a mesh wound clockwise is turned to face outwards, one wound
counter-clockwise is left as it is."""
import numpy as np

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
