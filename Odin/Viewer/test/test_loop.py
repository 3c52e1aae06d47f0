"""The render thread: it owns the scene and GL, runs callers' work in order, answers them, and
keeps rendering at its rate whatever they send."""
import threading
import time

import pytest

from viewer.core.pixels import is_hue, patch
from viewer.core.camera import Camera
from viewer.errors import ViewerError
from viewer.core.loop import RenderLoop
from viewer.core.renderer import Renderer
from viewer.core.scene import Scene, prepare_view


def make_loop(rate=50.0, frames=None, wanted=None):
    scene = Scene(Camera(width=160, height=120))

    def on_frame(frame, number):
        if frames is not None:
            frames.append((number, frame, threading.current_thread().name))
    return RenderLoop(scene, lambda: Renderer(160, 120), rate, on_frame, wanted)


def test_work_runs_on_the_render_thread_and_answers():
    with make_loop() as loop:
        name = loop.call(lambda scene, renderer: threading.current_thread().name)
        assert name == "viewer-render"
        request = prepare_view("ball", [0.5], [], (0, 0, 0.5), (1, 0, 0, 0), (1, 0, 0, 1))
        assert loop.call(lambda scene, _: scene.view(request)) is False
        frame = loop.call(lambda scene, renderer: renderer.render(scene))
        uv = loop.scene.camera.project([(0, 0, 0.5)])[0]
        assert is_hue(patch(frame, uv), 0)


def test_errors_come_back_to_the_caller_and_the_loop_goes_on():
    frames = []
    with make_loop(frames=frames) as loop:
        with pytest.raises(ViewerError, match="no object 'ghost'"):
            loop.call(lambda scene, _: scene.remove_object("ghost"))
        with pytest.raises(ZeroDivisionError):
            loop.call(lambda scene, _: 1 / 0)
        loop.post(lambda scene, _: 1 / 0)            # logged, not raised
        seen = len(frames)
        time.sleep(0.3)
        assert len(frames) > seen
        assert loop.call(lambda scene, _: len(scene)) == 0


def test_frames_come_at_the_rate_on_the_render_thread():
    frames = []
    with make_loop(rate=25.0, frames=frames):
        time.sleep(1.0)
    assert 20 <= len(frames) <= 27
    assert [n for n, _, _ in frames] == list(range(1, len(frames) + 1))
    assert {thread for _, _, thread in frames} == {"viewer-render"}


def test_no_frame_is_rendered_while_nobody_wants_one_and_work_still_runs():
    frames, watched = [], threading.Event()
    with make_loop(rate=50.0, frames=frames, wanted=watched.is_set) as loop:
        time.sleep(0.3)
        assert frames == []
        request = prepare_view("ball", [0.5], [], (0, 0, 0.5), (1, 0, 0, 0), (1, 0, 0, 1))
        assert loop.call(lambda scene, _: scene.view(request)) is False
        watched.set()
        time.sleep(0.3)
        assert len(frames) >= 5 and frames[0][0] == 1
        watched.clear()
        time.sleep(0.1)
        seen = len(frames)
        time.sleep(0.3)
        assert len(frames) == seen


def test_a_failing_wanted_question_renders_rather_than_stops():
    frames = []
    with make_loop(frames=frames, wanted=lambda: 1 / 0):
        time.sleep(0.3)
    assert len(frames) >= 5


def test_posted_updates_apply_in_order():
    with make_loop() as loop:
        request = prepare_view("ball", [0.5], [], (0, 0, 0), (1, 0, 0, 0), (1, 0, 0, 1))
        loop.call(lambda scene, _: scene.view(request))
        for z in range(10):
            loop.post(lambda scene, _, z=z: scene.update([("ball", (0, 0, z), (1, 0, 0, 0))]))
        assert loop.call(lambda scene, _: scene.pose_of("ball")[2, 3]) == 9


def test_calls_after_stop_are_refused():
    loop = make_loop()
    loop.start()
    loop.stop()
    loop.stop()
    with pytest.raises(ViewerError, match="not running"):
        loop.call(lambda scene, _: None)


def test_a_renderer_that_cannot_start_is_reported():
    def broken():
        raise RuntimeError("no OSMesa here")
    loop = RenderLoop(Scene(), broken, 25.0)
    with pytest.raises(ViewerError, match="no OSMesa here"):
        loop.start()


def test_work_posted_for_later_runs_after_its_delay_in_order_and_does_not_hold_up_other_work():
    ran = []
    with make_loop() as loop:
        started = time.monotonic()
        loop.post_later(0.4, lambda scene, _: ran.append(("first", time.monotonic() - started)))
        loop.post_later(0.4, lambda scene, _: ran.append(("second", time.monotonic() - started)))
        loop.post_later(0.4, lambda scene, _: 1 / 0)            # logged, the loop goes on
        assert loop.call(lambda scene, _: len(ran)) == 0         # not yet, and no wait for it
        assert time.monotonic() - started < 0.3
        deadline = time.monotonic() + 5
        while len(ran) < 2 and time.monotonic() < deadline:
            time.sleep(0.02)
        assert [name for name, _ in ran] == ["first", "second"]
        assert all(0.4 <= at < 2.0 for _, at in ran)
        assert loop.call(lambda scene, _: len(ran)) == 2
