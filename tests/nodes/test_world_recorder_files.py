"""The world's recording (~record) is written to NAME.active and renamed onto NAME only when it
is closed whole: a full disk stops it with one error and never fails the world, leaves a bag
already at NAME as it was and no corrupt file under the name."""
from __future__ import annotations

import errno
import io
import logging
import os

import numpy as np
import pytest


class FillingFile(io.BufferedRandom):
    """A new file whose disk takes ``room`` bytes more, then answers ENOSPC."""

    def __init__(self, path, room: int) -> None:
        super().__init__(io.FileIO(os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL), "w+"))
        self.room = room

    def write(self, data) -> int:
        if len(data) > self.room:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        self.room -= len(data)
        return super().write(data)


def _record(path, advances: int, **kwargs):
    """A recording of ``advances`` advances of a ball; the Recorder, closed."""
    from odin_common.step_values import StepValues
    from odin_common.world_parameters import WorldParameters
    from virtual_world.portal.recorder import Recorder
    recorder = Recorder(str(path), WorldParameters(), StepValues(), **kwargs)
    names = [f"ball{i}" for i in range(50)]
    positions = [np.array([0.0, 0.0, 1.0])] * len(names)
    quaternions = [np.array([1.0, 0.0, 0.0, 0.0])] * len(names)
    for n in range(advances):
        recorder.advance(0.001, 1, 0.001 * (n + 1), names, positions, quaternions)
    recorder.close()
    return recorder


def _bag_entries(path) -> int:
    import rosbag
    with rosbag.Bag(str(path)) as bag:
        return bag.get_message_count()


def test_a_recording_is_named_only_once_closed_whole(tmp_path):
    recorder = _record(tmp_path / "run.bag", 20)
    assert recorder.failed is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.bag"]
    assert _bag_entries(tmp_path / "run.bag") == 21


def test_a_full_disk_stops_the_recording_with_one_error_and_keeps_the_older_bag(tmp_path,
                                                                              caplog):
    path = tmp_path / "run.bag"
    _record(path, 3)
    before = path.read_bytes()
    with caplog.at_level(logging.ERROR, logger="rosout"):
        recorder = _record(path, 2000,     # ~3 MB of poses: chunks reach the disk
                           open_file=lambda active: FillingFile(active, room=200_000))
    assert recorder.failed and "No space left on device" in recorder.failed
    assert str(path) + ".active" in recorder.failed
    errors = [r.getMessage() for r in caplog.records if r.levelno >= logging.ERROR]
    assert len(errors) == 1 and "recording stopped" in errors[0], errors
    assert path.read_bytes() == before          # the older recording, whole
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.bag", "run.bag.active"]


def test_a_symbolic_link_at_the_name_is_refused_at_start(tmp_path):
    from virtual_world.portal.recorder import RecordError
    precious = tmp_path / "precious"
    precious.write_bytes(b"keep")
    os.symlink(precious, tmp_path / "run.bag")
    with pytest.raises(RecordError, match="symbolic link"):
        _record(tmp_path / "run.bag", 1)
    assert precious.read_bytes() == b"keep"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["precious", "run.bag"]


@pytest.fixture
def tiny_tmpfs(tmpfs):
    """A 256 KiB tmpfs (the root conftest's ``tmpfs``)."""
    return tmpfs(256)


def test_a_real_full_disk_leaves_no_corrupt_bag_under_the_name(tiny_tmpfs):
    path = tiny_tmpfs / "run.bag"
    _record(path, 2)
    before = path.read_bytes()
    recorder = _record(path, 2000)
    assert recorder.failed and "No space left on device" in recorder.failed
    assert path.read_bytes() == before and _bag_entries(path) == 3


def test_a_recording_folder_that_cannot_be_made_is_one_start_up_error(tmp_path):
    from virtual_world.portal.recorder import RecordError
    in_the_way = tmp_path / "a_file"
    in_the_way.write_text("not a folder")
    with pytest.raises(RecordError, match=r"^cannot record to .*a_file.*: Not a directory$"):
        _record(in_the_way / "sub" / "run.bag", 1)
