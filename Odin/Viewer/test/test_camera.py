"""The camera model the renderer uses and the tests project with."""
import math

import numpy as np
import pytest

from viewer.core.camera import Camera
from viewer.errors import ViewerError


def test_target_projects_to_the_image_centre():
    cam = Camera(eye_W=(4, 1, 2), target_W=(0, 0, 0.5), width=640, height=480)
    np.testing.assert_allclose(cam.project([(0, 0, 0.5)])[0], (320, 240), atol=1e-9)


def test_world_z_is_up_in_the_image():
    cam = Camera(eye_W=(5, 0, 0), target_W=(0, 0, 0))
    (u0, v0), (u1, v1) = cam.project([(0, 0, 0), (0, 0, 1)])
    assert v1 < v0 and u1 == pytest.approx(u0)
    (uy, _), = cam.project([(0, 1, 0)])
    assert uy > u0  # standing on +x looking back at the origin, world +y is on the right


def test_projection_matches_the_opengl_matrices():
    cam = Camera(eye_W=(3, -2, 1.5), target_W=(0.2, 0.1, 0.3), fov_y=0.9, width=320, height=200)
    point = np.array([0.5, 0.4, 0.8, 1.0])
    clip = cam.projection_matrix(0.1, 50) @ cam.view_matrix() @ point
    ndc = clip[:3] / clip[3]
    expected = ((ndc[0] + 1) / 2 * 320, (1 - ndc[1]) / 2 * 200)
    np.testing.assert_allclose(cam.project([point[:3]])[0], expected, atol=1e-9)


def test_points_behind_the_camera_have_no_pixel():
    cam = Camera(eye_W=(5, 0, 0), target_W=(0, 0, 0))
    assert np.all(np.isnan(cam.project([(10, 0, 0)])))


def test_fitted_camera_sees_the_whole_sphere():
    cam = Camera(width=640, height=480).fitted((1, 2, 3), 0.5)
    np.testing.assert_allclose(cam.target_W, (1, 2, 3))
    edge_points = np.array([(1, 2, 3.5), (1, 2, 2.5), (1, 2.5, 3), (1, 1.5, 3)])
    uv = cam.project(edge_points)
    assert np.all((uv >= 0) & (uv <= [640, 480]))


@pytest.mark.parametrize("kwargs", [dict(eye_W=(0, 0, 0), target_W=(0, 0, 0)),
                                    dict(eye_W=(0, 0, 5), target_W=(0, 0, 0)),   # up parallel
                                    dict(fov_y=math.pi), dict(width=8), dict(height=5000),
                                    dict(eye_W=(math.nan, 0, 0))])
def test_bad_cameras_are_refused(kwargs):
    with pytest.raises(ViewerError):
        Camera(**kwargs)
