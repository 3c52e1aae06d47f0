"""Rendered pixels: objects appear where the camera model projects them, in their colour, grey
while colliding, gone once removed. Frames are saved under pytest's tmp_path for inspection."""
import math

import numpy as np
import pytest
from PIL import Image

from viewer.core.pixels import is_background, is_grey, is_hue, patch
from viewer.core.camera import Camera
from viewer.core.renderer import Renderer
from viewer.core.scene import Scene

RED, GREEN, BLUE = (1, 0, 0, 1), (0, 0.8, 0, 1), (0, 0, 1, 1)
S = math.sqrt(0.5)


@pytest.fixture(scope="module")
def renderer():
    with Renderer(320, 240) as r:
        yield r


def save(frame, tmp_path, name):
    Image.fromarray(frame).save(tmp_path / f"{name}.png")


def fixed_scene(**camera):
    cam = Camera(**{"eye_W": (4.0, 1.0, 2.0), "target_W": (0.0, 0.0, 0.3), "width": 320,
                    "height": 240, **camera})
    return Scene(cam, camera_fixed=True)


def test_objects_appear_where_they_project_in_their_colour(renderer, tmp_path):
    scene = fixed_scene()
    scene.view_object("ball", [0.3], position_W=(0, -0.8, 0.3), color=RED)
    scene.view_object("can", [0.2, 0.6], position_W=(0, 0.8, 0.3), color=GREEN)
    scene.view_object("box", [0.4, 0.4, 0.4], position_W=(-1.0, 0, 0.2), color=BLUE)
    frame = renderer.render(scene)
    save(frame, tmp_path, "three")
    assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8
    ball, can, box = scene.camera.project([(0, -0.8, 0.3), (0, 0.8, 0.3), (-1.0, 0, 0.2)])
    assert is_hue(patch(frame, ball), 0)
    assert is_hue(patch(frame, can), 1)
    assert is_hue(patch(frame, box), 2)
    # just outside the ball's silhouette (radius 0.3 at this distance) there is no red
    left_edge = scene.camera.project([(0, -0.8 - 0.45, 0.3)])[0]
    assert not is_hue(patch(frame, left_edge), 0)
    assert is_background(frame[2, 2], scene.background)   # top corner: sky


def test_z_is_up_and_the_quaternion_turns_a_bar(renderer, tmp_path):
    scene = fixed_scene(eye_W=(6.0, 0.0, 1.0), target_W=(0.0, 0.0, 1.0))
    # a bar 2 m long along its local x, turned 90 degrees about z: it must lie along world y
    scene.view_object("bar", [2.0, 0.1, 0.1], position_W=(0, 0, 1.0),
                      orientation_wxyz=(S, 0, 0, S), color=RED)
    scene.view_object("top", [0.15], position_W=(0, 0, 2.0), color=BLUE)
    frame = renderer.render(scene)
    save(frame, tmp_path, "bar")
    end_y, end_x, top, bottom = scene.camera.project([(0, 0.9, 1.0), (0.9, 0, 1.0),
                                                      (0, 0, 2.0), (0, 0, 0.0)])
    assert is_hue(patch(frame, end_y, 1), 0)
    assert top[1] < bottom[1]                         # z up: higher in the image
    assert is_hue(patch(frame, top), 2)


def test_collision_grey_and_back(renderer, tmp_path):
    scene = fixed_scene()
    scene.view_object("ball", [0.4], position_W=(0, 0, 0.4), color=RED)
    uv = scene.camera.project([(0, 0, 0.4)])[0]
    scene.collided(["ball"])
    grey = renderer.render(scene)
    save(grey, tmp_path, "colliding")
    assert is_grey(patch(grey, uv), scene.background)
    scene.update([("ball", (0, 0, 0.4), (1, 0, 0, 0))])
    assert is_grey(patch(renderer.render(scene), uv), scene.background)
    scene.update([("ball", (0, 0, 0.4), (1, 0, 0, 0))])
    back = renderer.render(scene)
    save(back, tmp_path, "not_colliding")
    assert is_hue(patch(back, uv), 0)


def test_removal_and_new_scene_clear_the_picture(renderer, tmp_path):
    scene = fixed_scene()
    scene.view_object("ball", [0.4], position_W=(0, 0, 0.4), color=RED)
    scene.view_object("cube", [0.5, 0.5, 0.5], position_W=(0, 1.2, 0.25), color=BLUE)
    ball, cube = scene.camera.project([(0, 0, 0.4), (0, 1.2, 0.25)])
    before = renderer.render(scene)
    assert is_hue(patch(before, ball), 0) and is_hue(patch(before, cube), 2)
    scene.remove_object("ball")
    after = renderer.render(scene)
    assert not np.any([is_hue(p, 0) for p in after.reshape(-1, 3)[::7]])
    assert is_hue(patch(after, cube), 2)
    scene.new_scene()
    empty = renderer.render(scene)
    save(empty, tmp_path, "empty")
    assert not any(is_hue(p, 2) or is_hue(p, 0) for p in empty.reshape(-1, 3)[::5])


def test_meshes_go_to_the_gpu_once_and_leave_with_their_object(renderer):
    scene = fixed_scene()
    tetra = [0, 0, 0, 0.6, 0, 0, 0, 0.6, 0, 0, 0, 0.6]
    scene.view_object("tet", tetra, [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3], color=GREEN)
    uploads = renderer.uploads
    frame = None
    for step in range(5):
        scene.update([("tet", (0, 0, 0.1 * step), (1, 0, 0, 0))])
        frame = renderer.render(scene)
    assert renderer.uploads == uploads + 1 and renderer.mesh_buffers == 1
    centroid = scene.camera.project([(0.15, 0.15, 0.4 + 0.15)])[0]
    assert is_hue(patch(frame, centroid, 1), 1)
    scene.remove_object("tet")
    renderer.render(scene)
    assert renderer.mesh_buffers == 0


def test_image_size_follows_the_camera(renderer):
    scene = fixed_scene(width=200, height=100)
    scene.view_object("ball", [0.3], position_W=(0, 0, 0.3), color=RED)
    frame = renderer.render(scene)
    assert frame.shape == (100, 200, 3)
    assert is_hue(patch(frame, scene.camera.project([(0, 0, 0.3)])[0]), 0)


def test_fitted_camera_frames_a_far_away_scene(renderer, tmp_path):
    scene = Scene(Camera(width=320, height=240))
    scene.view_object("a", [0.5], position_W=(100, 50, 3), color=RED)
    scene.view_object("b", [0.5], position_W=(104, 50, 3), color=BLUE)
    frame = renderer.render(scene)
    save(frame, tmp_path, "fitted")
    a, b = scene.camera.project([(100, 50, 3), (104, 50, 3)])
    assert is_hue(patch(frame, a), 0) and is_hue(patch(frame, b), 2)


def test_translucent_objects_blend(renderer):
    scene = fixed_scene()
    scene.view_object("glass", [0.4], position_W=(0, 0, 0.4), color=(0, 0, 1, 0.5))
    frame = renderer.render(scene)
    rgb = patch(frame, scene.camera.project([(0, 0, 0.4)])[0])
    assert rgb[2] > rgb[0] + 40 and rgb[0] > 30        # blue over the light background


def test_a_dense_mesh_far_away_is_drawn_at_a_coarser_level_in_its_colour(renderer,
                                                                                tmp_path):
    import trimesh
    ball = trimesh.creation.icosphere(subdivisions=5, radius=0.3)     # 20k triangles
    vertices, faces = np.asarray(ball.vertices).ravel(), np.asarray(ball.faces).ravel()
    frames, levels = [], []
    for name, eye in (("near", (0.7, 0.0, 0.3)), ("far", (15.0, 0.0, 0.3))):
        scene = fixed_scene(eye_W=eye, target_W=(0.0, 0.0, 0.3))
        scene.view_object("ball", vertices, faces, position_W=(0, 0, 0.3), color=RED)
        frames.append(renderer.render(scene))
        save(frames[-1], tmp_path, f"lod_{name}")
        levels.append(renderer._meshes and max(level for _, level in renderer._meshes))
        centre = scene.camera.project([(0, 0, 0.3)])[0]
        assert is_hue(patch(frames[-1], centre, 1), 0), name
    # near: a pixel is ~1.4 mm, the 1 mm level (0); at 15 m ~5 cm: the coarsest (32 mm)
    assert levels == [0, 5]
