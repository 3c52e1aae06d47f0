"""A View Object is checked whole before the scene or the camera changes: one bad request is
refused for its own reason, changes nothing, and the next good one is drawn."""
import math

import numpy as np
import pytest

from odin_common.limits import MIN_SIZE
from viewer.core.camera import MIN_FOV_Y, Camera
from viewer.core.geometry import MAX_EXTENT, MAX_SIZE
from viewer.core.scene import Scene, prepare_view
from viewer.errors import ViewerError

GREEN = (0.0, 1.0, 0.0, 1.0)
TETRAHEDRON = [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]
TETRA_INDICES = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]


def request(object_id="good", parameters=(0.3,), indices=(), position=(0.5, 0, 0.3),
            orientation=(1, 0, 0, 0), color=GREEN):
    return object_id, list(parameters), list(indices), position, orientation, color


BAD_REQUESTS = {
    "sphere of radius 1e300": (request(parameters=[1e300]), "sphere radius"),
    "box side over MAX_SIZE": (request(parameters=[1, 3 * MAX_SIZE, 1]), "box side y"),
    "cylinder thinner than MIN_SIZE": (request(parameters=[MIN_SIZE / 10, 1]),
                                       "cylinder radius"),
    "infinite capsule": (("good", [0.1, math.inf], [], (0, 0, 0), (1, 0, 0, 0), GREEN, 5),
                         "capsule length"),
    "position beyond the extent": (request(position=(0, -3 * MAX_EXTENT, 0)), "MAX_EXTENT"),
    "mesh vertex beyond the extent": (request(parameters=[*TETRAHEDRON[:-1], 2 * MAX_EXTENT],
                                              indices=TETRA_INDICES), "MAX_EXTENT"),
    "NaN mesh vertex": (request(parameters=[math.nan, *TETRAHEDRON[1:]], indices=TETRA_INDICES),
                        "mesh vertices"),
    "colour over 1": (request(color=(0, 2, 0, 1)), "in \\[0, 1\\]"),
    "NaN colour": (request(color=(0, math.nan, 0, 1)), "in \\[0, 1\\]"),
    "NaN orientation": (request(orientation=(math.nan, 0, 0, 0)), "orientation"),
}


def scene_with_one_object() -> Scene:
    scene = Scene()
    scene.view(prepare_view("first", [0.2], [], (0, 0, 0.2), (1, 0, 0, 0), GREEN))
    return scene


@pytest.mark.parametrize("case", sorted(BAD_REQUESTS))
def test_a_refused_view_changes_nothing_and_the_next_one_is_drawn(case):
    arguments, reason = BAD_REQUESTS[case]
    scene = scene_with_one_object()
    camera = scene.camera
    with pytest.raises(ViewerError, match=reason):
        scene.view(prepare_view(*arguments))
    assert scene.ids == ["first"] and scene.camera == camera
    scene.view(prepare_view(*request("next")))
    assert scene.ids == ["first", "next"] and scene.camera != camera
    assert all(np.isfinite(scene.camera.eye_W))


def test_a_view_whose_camera_fit_fails_changes_neither_the_scene_nor_the_camera(monkeypatch):
    scene = scene_with_one_object()
    camera = scene.camera

    def no_fit(self, centre, radius):
        raise ViewerError("camera eye: expected 3 finite numbers, got [inf, inf, inf]")
    monkeypatch.setattr(Camera, "fitted", no_fit)
    with pytest.raises(ViewerError, match="camera eye"):
        scene.view(prepare_view(*request("second")))
    assert scene.ids == ["first"] and scene.camera == camera


@pytest.mark.parametrize("width, height", [(4096, 16), (16, 4096), (640, 480)])
def test_the_widest_scene_the_viewer_takes_gives_a_finite_camera(width, height):
    scene = Scene(Camera(fov_y=MIN_FOV_Y, width=width, height=height))
    for n, corner in enumerate([(1, 1, 1), (-1, -1, -1), (1, -1, 1), (-1, 1, -1)]):
        position = tuple(MAX_EXTENT * c for c in corner)
        scene.view(prepare_view(f"box{n}", [MAX_SIZE] * 3, [], position, (1, 0, 0, 0), GREEN))
    far_mesh = [MAX_EXTENT if v else -MAX_EXTENT for v in TETRAHEDRON]
    scene.view(prepare_view("mesh", far_mesh, TETRA_INDICES, (MAX_EXTENT,) * 3, (1, 0, 0, 0),
                            GREEN))
    assert len(scene) == 5 and all(np.isfinite(scene.camera.eye_W))
    near, far = scene.clip_planes()
    assert 0 < near < far < math.inf


def test_a_field_of_view_narrower_than_the_least_is_refused_and_fitting_goes_on():
    scene = scene_with_one_object()
    with pytest.raises(ViewerError, match="fov_y"):
        scene.set_camera(scene.camera.with_(fov_y=1e-300))
    scene.view(prepare_view(*request("after")))
    assert scene.ids == ["first", "after"] and all(np.isfinite(scene.camera.eye_W))


@pytest.mark.parametrize("object_id, problem", [
    ("nul\0inside", "control character"), ("two\nlines", "control character"),
    ("tab\tin", "control character"), ("x" * 257, "longer than 256 bytes"),
    ("", "non-empty"),
])
def test_object_ids_that_are_no_names_are_refused(object_id, problem):
    scene = scene_with_one_object()
    with pytest.raises(ViewerError, match=problem) as refusal:
        scene.view(prepare_view(*request(object_id)))
    assert len(str(refusal.value)) < 200 and "\n" not in str(refusal.value)
    assert scene.ids == ["first"]


def test_a_huge_colour_array_is_quoted_short():
    with pytest.raises(ViewerError, match="array of 100,000 values") as refusal:
        prepare_view(*request(color=np.full(100_000, 0.5)))
    assert len(str(refusal.value)) < 200
