"""Which inertia a link's body gets (gui.core.inertia): a file's tensor the world would refuse as
far too light in rotation for the link's geometry (odin_common.limits.thin_inertia) is set
aside, listed, and the shape's is used; a CAD tensor within the limit is kept."""
import numpy as np

from gui.core import inertia
from gui.core.model import Inertial, LinkModel
from gui.core.geometry import Mesh, Primitive, Shape


def room_link(moment: float) -> LinkModel:
    """A link whose mesh spans a 12 m x 6 m x 3 m box, 0.05 kg with ``moment`` kg m^2 about
    each axis (Kautham's IOC lab layout, scaled 0.01 with its URDF's placeholder inertia)."""
    corners = np.array([[x, y, z] for x in (0, 12) for y in (0, 6) for z in (0, 3)], float)
    mesh = Mesh(corners, np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5]], np.uint32))
    return LinkModel(name="layout", parent=None, pre=np.eye(4), post=np.eye(4), mass=0.05,
                     shape=Shape(source="layout.dae", mesh=mesh), source="layout.urdf",
                     inertial=Inertial(0.05, np.eye(4), np.eye(3) * moment))


def test_a_file_inertia_far_too_light_for_the_mesh_is_set_aside_for_the_shapes():
    given, ignored = inertia.choose(room_link(6.8e-8), "layout", 0.05, np.eye(4))
    assert given is None
    assert "MIN_GYRATION_FRACTION" in ignored.why and "<inertial>" in ignored.what


def test_a_file_inertia_within_the_limit_is_kept_for_a_mesh_link():
    given, ignored = inertia.choose(room_link(0.5), "layout", 0.05, np.eye(4))
    assert ignored is None and given.inertia[:3] == (0.5, 0.5, 0.5)


def test_shape_points_are_the_mesh_vertices_and_the_primitives_box_corners():
    pose = np.eye(4)
    pose[:3, 3] = (1, 0, 0)
    shape = Shape(source="s", primitives=(Primitive("cylinder", (0.1, 0.4), pose),))
    points = inertia.shape_points(shape)
    assert points.shape == (8, 3)
    np.testing.assert_allclose(points.min(0), (0.9, -0.1, -0.2))
    np.testing.assert_allclose(points.max(0), (1.1, 0.1, 0.2))
