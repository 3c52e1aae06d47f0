"""Snapshot files stay inside their folder, and what is written is the frame."""
import os

import numpy as np
import pytest
from PIL import Image

from viewer.errors import ViewerError
from viewer.core.snapshots import FrameWriter, snapshot_path, write_png


def frame_of(colour, size=(24, 32)):
    frame = np.zeros((*size, 3), np.uint8)
    frame[:] = colour
    frame[0, 0] = (1, 2, 3)            # a marker: row 0 is the top
    return frame


def test_plain_names_land_in_the_folder_with_png_added(tmp_path):
    assert snapshot_path(tmp_path, "grasp") == tmp_path.resolve() / "grasp.png"
    assert snapshot_path(tmp_path, "a.PNG") == tmp_path.resolve() / "a.PNG"


@pytest.mark.parametrize("name", ["", "   ", "../x", "..", ".", "/etc/passwd", "sub/x",
                                  "a\\b", "nul\0byte", "../../tmp/evil.png"])
def test_names_that_escape_are_refused(tmp_path, name):
    with pytest.raises(ViewerError):
        snapshot_path(tmp_path, name)


def test_symlinks_are_refused_and_not_followed(tmp_path):
    outside = tmp_path / "outside.png"
    outside.write_bytes(b"precious")
    folder = tmp_path / "snaps"
    folder.mkdir()
    os.symlink(outside, folder / "trap.png")
    with pytest.raises(ViewerError, match="symbolic link"):
        snapshot_path(folder, "trap")
    with pytest.raises(ViewerError):      # even if the link appears after the check
        write_png(folder / "trap.png", frame_of((255, 0, 0)))
    assert outside.read_bytes() == b"precious"


def test_written_png_holds_the_frame(tmp_path):
    frame = frame_of((10, 200, 30))
    path = write_png(snapshot_path(tmp_path, "f"), frame)
    np.testing.assert_array_equal(np.asarray(Image.open(path).convert("RGB")), frame)


def test_frame_writer_numbers_frames_in_order(tmp_path):
    writer = FrameWriter(tmp_path / "frames", max_pending=100)
    for value in (50, 100, 150):
        writer.put(frame_of((value, 0, 0)))
    writer.close()
    names = sorted(p.name for p in (tmp_path / "frames").iterdir())
    assert names == ["frame_000001.png", "frame_000002.png", "frame_000003.png"]
    third = np.asarray(Image.open(tmp_path / "frames" / "frame_000003.png"))
    assert tuple(third[5, 5]) == (150, 0, 0) and writer.written == 3 and writer.dropped == 0
