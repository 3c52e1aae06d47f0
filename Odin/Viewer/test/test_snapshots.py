"""Snapshot files stay inside their folder, what is written is the frame, and a file is
written whole or not at all (a full disk leaves the old one as it was)."""
import errno
import logging
import os
import time

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


class FillingDisk:
    """An ``os.write`` of a disk that takes ``room`` bytes more (then ENOSPC), or any amount
    while ``full`` is False."""

    def __init__(self, room: int = 100) -> None:
        self.room = room
        self.full = True

    def write(self, fd: int, data) -> int:
        if not self.full:
            return os.write(fd, data)
        if self.room <= 0:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        taken = os.write(fd, bytes(data[:self.room]))
        self.room -= taken
        return taken


def test_a_full_disk_leaves_the_old_snapshot_whole_and_creates_nothing(tmp_path):
    kept = write_png(snapshot_path(tmp_path, "kept"), frame_of((0, 90, 0)))
    before = kept.read_bytes()
    disk = FillingDisk(room=50)
    with pytest.raises(ViewerError, match=r"^cannot write snapshot .*kept\.png: "
                                          r"No space left on device$"):
        write_png(kept, frame_of((200, 0, 0)), disk.write)
    with pytest.raises(ViewerError, match=r"fresh\.png: No space left on device$"):
        write_png(snapshot_path(tmp_path, "fresh"), frame_of((200, 0, 0)), disk.write)
    assert kept.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.png"]


def test_a_folder_gone_is_one_line_naming_the_file(tmp_path):
    path = snapshot_path(tmp_path / "gone", "shot")
    with pytest.raises(ViewerError, match=r"^cannot write snapshot .*gone/shot\.png: No such "
                                          r"file or directory$"):
        write_png(path, frame_of((1, 1, 1)))


def test_frame_writer_on_a_full_disk_warns_once_leaves_no_frames_and_resumes(tmp_path, caplog):
    disk = FillingDisk(room=0)
    writer = FrameWriter(tmp_path / "frames", max_pending=100, write=disk.write)
    with caplog.at_level(logging.WARNING, logger="viewer.core.snapshots"):
        for value in range(20):
            writer.put(frame_of((value, 0, 0)))
        while writer.failed < 20:
            time.sleep(0.01)
        assert list((tmp_path / "frames").iterdir()) == []
        disk.full = False
        writer.put(frame_of((99, 0, 0)))
        writer.close()
    frames = list((tmp_path / "frames").iterdir())
    assert [p.name for p in frames] == ["frame_000021.png"] and frames[0].stat().st_size > 0
    not_written = [r for r in caplog.records if "not written" in r.getMessage()]
    assert len(not_written) == 2, [r.getMessage() for r in caplog.records]
    assert "No space left on device" in not_written[0].getMessage()
    assert "written again from frame 21, after 20 not written" in not_written[1].getMessage()
    assert (writer.written, writer.failed) == (1, 20)


@pytest.mark.parametrize("name, problem", [
    ("s" * 300, "longer than 256 bytes"),                  # MAX_NAME_BYTES
    ("s" * 252, "longer than the 255 bytes a file name"),  # + ".png": over NAME_MAX
    ("é" * 127 + "x", "longer than the 255 bytes"),        # 255 bytes: ".png" makes 259
    ("two\nlines", "control character"),
    ("tab\there", "control character"),
])
def test_names_no_file_system_takes_are_refused_by_name_not_by_os_error(tmp_path, name,
                                                                         problem):
    with pytest.raises(ViewerError, match=problem) as refusal:
        snapshot_path(tmp_path, name)
    assert "\n" not in str(refusal.value) and len(str(refusal.value)) < 250
    assert list(tmp_path.iterdir()) == []


def test_the_longest_file_name_is_written(tmp_path):
    path = write_png(snapshot_path(tmp_path, "n" * 251), frame_of((5, 5, 5)))
    assert path.name == "n" * 251 + ".png" and path.stat().st_size > 0


@pytest.fixture
def tiny_tmpfs(tmpfs):
    """A 64 KiB tmpfs (the root conftest's ``tmpfs``)."""
    return tmpfs(64)


def test_a_real_full_disk_keeps_the_old_snapshot(tiny_tmpfs):
    kept = write_png(snapshot_path(tiny_tmpfs, "kept"), frame_of((0, 0, 200)))
    before = kept.read_bytes()
    noise = np.random.default_rng(7).integers(0, 256, (160, 160, 3), dtype=np.uint8)  # 75 KB
    for name in ("kept", "new"):
        with pytest.raises(ViewerError, match=r"\.png: No space left on device$"):
            write_png(snapshot_path(tiny_tmpfs, name), noise)
    assert kept.read_bytes() == before
    assert sorted(p.name for p in tiny_tmpfs.iterdir()) == ["kept.png"]
