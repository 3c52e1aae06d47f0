"""The Viewer's Core without ROS and without OpenGL."""
import math

import numpy as np
import pytest

from viewer.core.camera import Camera
from viewer.errors import ViewerError
from viewer.core.geometry import GeometryCache
from viewer.core.scene import COLLIDING_COLOR, DEFAULT_COLOR, Scene, prepare_view

RED = (1.0, 0.0, 0.0, 1.0)
BLUE = (0.0, 0.0, 1.0, 1.0)


def ball_scene():
    scene = Scene()
    scene.view_object("ball", [0.2], position_W=(0, 0, 0.2), color=RED)
    scene.view_object("cube", [0.3, 0.3, 0.3], position_W=(1, 0, 0.15), color=BLUE)
    return scene


def situation(name, position, q=(1, 0, 0, 0)):
    return name, position, q


def test_objects_keep_their_colour_and_the_all_zero_colour_is_the_default():
    scene = ball_scene()
    scene.view_object("plain", [0.1], color=(0, 0, 0, 0))
    assert scene.color_of("ball") == RED and scene.color_of("plain") == DEFAULT_COLOR


def test_colliding_object_is_grey_until_an_update_that_does_not_list_it():
    scene = ball_scene()
    scene.collided(["ball", "ghost"])            # unknown names are ignored
    assert scene.color_of("ball") == COLLIDING_COLOR
    assert scene.color_of("cube") == BLUE
    scene.update([situation("ball", (0, 0, 0.3))])   # listed since the previous update
    assert scene.color_of("ball") == COLLIDING_COLOR
    scene.update([situation("ball", (0, 0, 0.4))])   # not listed since: original colour
    assert scene.color_of("ball") == RED


def test_collision_listed_every_cycle_stays_grey():
    scene = ball_scene()
    for _ in range(3):
        scene.collided(["cube"])
        scene.update([])
        assert scene.color_of("cube") == COLLIDING_COLOR
    scene.update([])
    assert scene.color_of("cube") == BLUE


def test_a_repeated_stamp_is_the_same_cycle_and_grey_lasts_until_a_new_one():
    # a paused world republishes its last cycle (same stamp) at its rate: however many repeats
    # reach the Viewer, the cycle's colouring stays; the next stamp ends it
    scene = ball_scene()
    scene.update([], stamp=0.230)
    scene.collided(["ball"], stamp=0.230)
    for _ in range(3):
        scene.update([situation("ball", (0, 0, 0.3))], stamp=0.230)
        scene.collided([], stamp=0.230)
        assert scene.color_of("ball") == COLLIDING_COLOR
    assert (scene.update_stamp, scene.collided_stamp) == (0.230, 0.230)
    scene.update([], stamp=0.231)        # listed since the previous cycle's update: grey
    assert scene.color_of("ball") == COLLIDING_COLOR
    scene.update([], stamp=0.232)
    assert scene.color_of("ball") == RED
    scene.new_scene()
    assert (scene.update_stamp, scene.collided_stamp) == (None, None)


def test_with_stamps_the_colours_follow_the_world_s_order_not_the_arrival_order():
    def cycle_after(arrivals):
        scene = ball_scene()
        scene.update([], stamp=0.001)
        for kind, stamp, names in arrivals:
            if kind == "update":
                scene.update([], stamp=stamp)
            else:
                scene.collided(names, stamp=stamp)
        return scene.color_of("ball"), scene.color_of("cube")
    in_order = [("update", 0.002, ()), ("collided", 0.002, ["ball"]),
                ("update", 0.003, ()), ("collided", 0.003, ["cube"])]
    collided_ahead = [("collided", 0.002, ["ball"]), ("collided", 0.003, ["cube"]),
                      ("update", 0.002, ()), ("update", 0.003, ())]
    collided_late = [("update", 0.002, ()), ("update", 0.003, ()),
                     ("collided", 0.002, ["ball"]), ("collided", 0.003, ["cube"])]
    grey_both = (COLLIDING_COLOR, COLLIDING_COLOR)
    assert cycle_after(in_order) == cycle_after(collided_ahead) == cycle_after(collided_late) \
        == grey_both
    # a cycle later the first one's collision is over, whatever the order
    assert cycle_after(in_order + [("update", 0.004, ())]) == (RED, COLLIDING_COLOR)
    assert cycle_after(collided_ahead + [("update", 0.004, ())]) == (RED, COLLIDING_COLOR)
    # a message older than the previous update's stamp comes too late to colour anything
    assert cycle_after(in_order[:2] + [("update", 0.003, ()), ("update", 0.004, ()),
                                       ("collided", 0.002, ["cube"])]) == (RED, BLUE)


def test_a_stamp_that_goes_back_starts_the_colouring_afresh():
    scene = ball_scene()
    scene.update([], stamp=5.0)
    scene.collided(["ball"], stamp=5.0)
    scene.update([], stamp=0.001)              # a bag played in a loop starts again
    scene.update([], stamp=0.002)
    assert scene.color_of("ball") == RED


def test_update_moves_known_objects_and_skips_unknown_names_and_bad_poses():
    scene = ball_scene()
    applied = scene.update([situation("ball", (1, 2, 3), (0, 0, 0, 1)),
                            situation("not_yet_viewed", (0, 0, 0)),
                            situation("cube", (math.nan, 0, 0)),
                            situation("cube", (0, 0, 0), (0, 0, 0, 0))])
    assert applied == 1
    np.testing.assert_allclose(scene.pose_of("ball")[:3, 3], (1, 2, 3))
    np.testing.assert_allclose(scene.pose_of("ball")[:3, :3], np.diag([-1, -1, 1]), atol=1e-12)
    np.testing.assert_allclose(scene.pose_of("cube")[:3, 3], (1, 0, 0.15))
    # a position of the wrong size among good ones: the good ones still move, one by one
    applied = scene.update([("ball", (4, 5, 6), (1, 0, 0, 0)), ("cube", (0, 0), (1, 0, 0, 0))])
    assert applied == 1
    np.testing.assert_allclose(scene.pose_of("ball"), [[1, 0, 0, 4], [0, 1, 0, 5],
                                                       [0, 0, 1, 6], [0, 0, 0, 1]])
    np.testing.assert_allclose(scene.pose_of("cube")[:3, 3], (1, 0, 0.15))


def test_viewing_an_existing_id_replaces_it():
    scene = ball_scene()
    assert scene.view_object("ball", [0.5], color=BLUE) is True
    assert len(scene) == 2 and scene.color_of("ball") == BLUE
    assert scene.draw_list()[0].geometry.radius == 0.5


def test_remove_and_new_scene():
    scene = ball_scene()
    scene.remove_object("ball")
    assert "ball" not in scene and len(scene) == 1
    with pytest.raises(ViewerError, match="no object 'ball'"):
        scene.remove_object("ball")
    scene.new_scene()
    assert len(scene) == 0 and scene.draw_list() == []


def test_bad_view_requests_are_refused_before_touching_the_scene():
    with pytest.raises(ViewerError, match="non-empty"):
        prepare_view("", [1.0], [], (0, 0, 0), (1, 0, 0, 0), RED)
    with pytest.raises(ViewerError, match="'m'.*no triangles"):
        prepare_view("m", [0] * 9, [], (0, 0, 0), (1, 0, 0, 0), RED)
    with pytest.raises(ViewerError, match="color"):
        prepare_view("c", [1.0], [], (0, 0, 0), (1, 0, 0, 0), (2, 0, 0, 1))
    with pytest.raises(ViewerError, match="quaternion"):
        prepare_view("q", [1.0], [], (0, 0, 0), (0, 0, 0, 0), RED)


def test_objects_of_the_same_content_share_one_cached_geometry_and_keep_their_own_poses():
    cache = GeometryCache()
    triangle = ([0, 0, 0, 1, 0, 0, 0, 1, 0], [0, 1, 2])
    scene = Scene()
    scene.view(prepare_view("left", *triangle, (-1, 0, 0), (1, 0, 0, 0), RED, cache=cache))
    scene.view(prepare_view("right", *triangle, (1, 0, 0), (1, 0, 0, 0), BLUE, cache=cache))
    left, right = sorted(scene.draw_list(), key=lambda item: item.id)
    assert left.geometry is right.geometry and cache.misses == 1
    assert (left.color, right.color) == (RED, BLUE)
    assert left.model_W[0, 3] == -1 and right.model_W[0, 3] == 1
    with pytest.raises(ViewerError, match="'bad'.*out of range"):
        prepare_view("bad", triangle[0], [0, 1, 5], (0, 0, 0), (1, 0, 0, 0), RED, cache=cache)


def test_adding_objects_refits_the_camera_unless_it_is_fixed():
    scene = Scene()
    scene.view_object("a", [0.5], position_W=(10, 0, 0))
    np.testing.assert_allclose(scene.camera.target_W, (10, 0, 0))
    scene.view_object("b", [0.5], position_W=(20, 0, 0))
    np.testing.assert_allclose(scene.camera.target_W, (15, 0, 0))
    uv = scene.camera.project([(9.5, 0, 0), (20.5, 0, 0)])
    assert np.all((uv >= 0) & (uv <= [640, 480]))

    fixed = Camera(eye_W=(0, -5, 1), target_W=(0, 0, 0))
    scene.set_camera(fixed, fixed=True)
    scene.view_object("c", [0.5], position_W=(30, 0, 0))
    assert scene.camera == fixed and not scene.fitting
    scene.set_camera(scene.camera, fixed=False)      # released: fits all three at once
    np.testing.assert_allclose(scene.camera.target_W, (20, 0, 0))


def test_bounds_and_clip_planes_hold_the_scene():
    scene = ball_scene()
    centre, radius = scene.bounds()
    for obj_centre, obj_radius in (((0, 0, 0.2), 0.2), ((1, 0, 0.15), 0.15 * math.sqrt(3))):
        assert np.linalg.norm(np.subtract(obj_centre, centre)) + obj_radius <= radius + 1e-9
    near, far = scene.clip_planes()
    distance = np.linalg.norm(np.subtract(scene.camera.eye_W, centre))
    assert 0 < near < distance - radius and far > distance + radius


def test_the_camera_fits_the_scene_without_its_infinite_plane():
    scene = Scene(Camera())
    scene.view_object("floor", [], position_W=(0, 0, 0), shape=6)
    assert scene.bounds() is None
    scene.view_object("ball", [0.5], position_W=(10, 0, 1))
    centre, radius = scene.bounds()
    np.testing.assert_allclose(centre, (10, 0, 1)) and radius == pytest.approx(0.5)
