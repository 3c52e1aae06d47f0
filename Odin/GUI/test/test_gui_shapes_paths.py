"""Shapes (vertex merging, Coin transforms, primitives) and path files."""
from __future__ import annotations

import math

import numpy as np
import pytest

from gui.errors import PathFileError, ShapeError
from gui.core.model import PRISMATIC, REVOLUTE
from gui.core.paths import DEGREES, double_precision, read_path, refine, to_si
from gui.core.shapes import merge_vertices, read_shape


def test_merge_vertices_merges_within_tolerance_and_drops_collapsed_triangles():
    a, b, c, d = (0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)
    jitter = 1e-9
    corners = np.array([[a, b, c], [b, d, (0 + jitter, 1 - jitter, 0)],
                        [a, (1e-9, 0, 0), c]], dtype=float)   # the last one collapses
    vertices, triangles = merge_vertices(corners, tolerance=1e-6)
    assert len(vertices) == 4
    assert triangles.shape == (2, 3) and triangles.dtype == np.uint32
    np.testing.assert_allclose(vertices[triangles[0]], [a, b, c], atol=1e-8)


def test_merge_vertices_is_fast_on_large_soups():
    rng = np.random.default_rng(1)
    points = rng.random((20000, 3))
    tri = rng.integers(0, len(points), (100000, 3))
    tri = tri[(tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])]
    import time
    started = time.perf_counter()
    vertices, triangles = merge_vertices(points[tri], 1e-9)
    assert time.perf_counter() - started < 2.0
    assert len(vertices) <= 20000 and len(triangles) == len(tri)


def test_coin_triangles_get_their_node_transforms(tmp_path):
    f = tmp_path / "t.iv"
    f.write_text("#Inventor V2.1 ascii\nSeparator {\n Material { diffuseColor 1 0 0 "
                 "transparency 0.25 }\n Translation { translation 10 0 0 }\n"
                 " Coordinate3 { point [ 0 0 0, 1 0 0, 0 1 0 ] }\n FaceSet { numVertices 3 }\n"
                 " Translation { translation 0 0 5 }\n Cylinder { radius 2 height 6 }\n}\n")
    shape = read_shape(f, 0.5)
    np.testing.assert_allclose(np.sort(shape.mesh.vertices, axis=0),
                               [[5, 0, 0], [5, 0, 0], [5.5, 0.5, 0]])
    assert shape.mesh.color == pytest.approx((1, 0, 0, 0.75))
    (cyl,) = shape.primitives
    assert cyl.kind == "cylinder" and cyl.parameters == pytest.approx((1.0, 3.0))
    np.testing.assert_allclose(cyl.pose[:3, 3], (5, 0, 2.5), atol=1e-6)
    # Inventor cylinders run along y; Odin's along z: the part's z is the file's y.
    np.testing.assert_allclose(cyl.pose[:3, 2], (0, 1, 0), atol=1e-6)


def test_shape_that_does_not_parse_or_is_empty(tmp_path):
    bad = tmp_path / "bad.iv"
    bad.write_text("#Inventor V2.1 ascii\nSeparator {\n  Cube { wdith 2 }\n}\n")
    with pytest.raises(ShapeError) as info:
        read_shape(bad)
    assert info.value.line == 3 and "bad.iv" in str(info.value)
    empty = tmp_path / "empty.iv"
    empty.write_text("#Inventor V2.1 ascii\nSeparator { }\n")
    with pytest.raises(ShapeError, match="no geometry"):
        read_shape(empty)


def test_stl_through_trimesh(kautham_dir):
    stl = (kautham_dir / "current_2025/demos/models/robots/tx90/meshes/collision/"
           "link_1.stl")
    shape = read_shape(stl, 1.0)
    assert shape.triangle_count > 1000 and not shape.primitives
    assert np.ptp(shape.mesh.vertices, axis=0).max() < 1.0   # metres


def test_path_file_rows_units_and_doubling(tmp_path):
    f = tmp_path / "p.txt"
    f.write_text("# a comment\n0 10 20\n\n90, 20, 40\n")
    rows = read_path(f, 3)
    assert rows.tolist() == [[0, 10, 20], [90, 20, 40]]
    si = to_si(rows, [REVOLUTE, REVOLUTE, PRISMATIC], DEGREES)
    assert si[1] == pytest.approx([math.pi / 2, math.radians(20), 0.04])
    assert double_precision(rows).tolist() == [[0, 10, 20], [45, 15, 30], [90, 20, 40]]
    assert len(refine(rows, 3)) == 9


def test_path_file_errors_name_the_line(tmp_path):
    f = tmp_path / "p.txt"
    f.write_text("0 1\n0 1 2\n")
    with pytest.raises(PathFileError) as info:
        read_path(f, 2)
    assert info.value.line == 2 and "expected 2" in str(info.value)
    f.write_text("0 1\n0 x\n")
    with pytest.raises(PathFileError, match="'x' is not a number") as info:
        read_path(f)
    assert info.value.line == 2


def test_task_file_confs_are_paths(kautham_dir):
    rows = read_path(kautham_dir / "current_2025/demos/OMPL_geo_demos/chess/"
                     "taskfile_kthconfig.xml")
    assert rows.shape[0] > 10 and rows.shape[1] > 6
