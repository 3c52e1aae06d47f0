"""The Viewer node against requests and disks that would break it: each refusal is one line
naming what was wrong, changes nothing (the scene, the camera, the files), and the next good
request works."""
from __future__ import annotations

import pathlib
import time

import numpy as np
import pytest
from PIL import Image as PilImage

from test_viewer_node import Client, start_viewer
from viewer.core.pixels import is_hue, patch

pytestmark = pytest.mark.forked


def sphere(client, name, radius, position=(0.0, 0.0, 0.4), color=(0.0, 1.0, 0.0, 1.0)):
    return client.view(id=name, parameters=[radius], indices=[], position=position,
                       orientation=[1, 0, 0, 0], color=color)


def test_hostile_views_and_snapshot_names_are_refused_by_name_and_change_nothing(
        ros_master, tmp_path):
    start_viewer(ros_master, tmp_path)
    client = Client()
    assert sphere(client, "first", 0.3).success
    camera = client.camera()
    refused = {
        "sphere radius": sphere(client, "huge", 1e307),
        "position": sphere(client, "far", 0.3, position=(0.0, 9e15, 0.0)),
        "control character": sphere(client, "new\nline", 0.3),
        "longer than 256 bytes": sphere(client, "n" * 400, 0.3),
    }
    for reason, answer in refused.items():
        assert not answer.success and reason in answer.message, answer.message
        assert "internal error" not in answer.message and "\n" not in answer.message
    assert client.camera() == camera            # no refused request moved it
    snaps = tmp_path / "snaps"
    for name, reason in (("p" * 300, "longer than 256 bytes"),
                         ("q" * 253, "longer than the 255 bytes"),
                         ("nul\0name", "control character")):
        answer = client.snapshot(name=name)
        assert not answer.success and reason in answer.message, answer.message
        assert "internal error" not in answer.message and len(answer.message) < 300
    assert list(snaps.iterdir()) == []

    # the next good View Object is drawn and fits the camera, the world's mirror included
    assert sphere(client, "second", 0.3, position=(0.0, 1.0, 0.4),
                  color=(0.0, 0.0, 1.0, 1.0)).success
    refitted = client.camera()
    assert refitted != camera
    shot = client.snapshot(name="after")
    assert shot.success, shot.message
    frame = np.asarray(PilImage.open(shot.path).convert("RGB"))
    for position, channel in (((0.0, 0.0, 0.4), 1), ((0.0, 1.0, 0.4), 2)):
        assert is_hue(patch(frame, refitted.project([position])[0]), channel)


@pytest.fixture
def tiny_tmpfs(tmpfs):
    """A 48 KiB tmpfs (the root conftest's ``tmpfs``)."""
    return tmpfs(48)


def _wait_for(predicate, timeout: float = 20.0):
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, "condition not met in time"
        time.sleep(0.05)


def test_frames_on_a_full_disk_leave_no_empty_file_warn_once_and_resume(ros_master, tmp_path,
                                                                       tiny_tmpfs):
    ros_master.rosrun("Viewer", "viewer", "_width:=160", "_height:=120", "_rate:=20",
                      f"_snapshot_dir:={tiny_tmpfs}", "_snapshot_every:=1")
    ros_master.wait_for_service("/viewer/set_camera")
    node_log = pathlib.Path(ros_master.env["ROS_LOG_DIR"]) / "viewer.log"   # Python logging's

    def log_text() -> str:
        return node_log.read_text(errors="replace") if node_log.exists() else ""
    _wait_for(lambda: "not written" in log_text())
    kept = {p.name: p.read_bytes() for p in tiny_tmpfs.glob("frame_*.png")}
    assert kept and all(kept.values()), "a frame file is empty"
    time.sleep(2.0)                            # 40 more frames fail meanwhile
    log = log_text()
    assert log.count("[viewer.core.snapshots][WARNING]") == 1, log[-2000:]
    assert "No space left on device" in log
    assert {p.name for p in tiny_tmpfs.iterdir()} == set(kept)   # no new or temporary file
    assert all(p.read_bytes() == kept[p.name] for p in tiny_tmpfs.iterdir())

    for name in sorted(kept)[:-1]:            # room again: frames are written again
        (tiny_tmpfs / name).unlink()
    _wait_for(lambda: "written again" in log_text())
    _wait_for(lambda: len(set(p.name for p in tiny_tmpfs.glob("frame_*.png")) - set(kept)) > 0)
    assert all(p.stat().st_size > 0 for p in tiny_tmpfs.glob("frame_*.png"))


def test_a_snapshot_folder_that_cannot_be_made_stops_the_node_with_one_line(ros_master,
                                                                             tmp_path):
    in_the_way = tmp_path / "a_file"
    in_the_way.write_text("not a folder")
    node = ros_master.rosrun("Viewer", "viewer", f"_snapshot_dir:={in_the_way / 'snaps'}")
    assert node.wait(timeout=60) == 1
    log = ros_master.log_text(node)
    assert "Traceback" not in log, log[-2000:]
    fatal = [line for line in log.splitlines() if "~snapshot_dir" in line]
    assert fatal and "cannot make the folder: Not a directory" in fatal[0], log[-2000:]
