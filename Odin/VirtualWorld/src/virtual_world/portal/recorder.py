"""A recording of what changed a world (the world node's ``~record``): a rosbag that holds, in
the order they happened, the values the world started with, every state-changing request that
succeeded, and every advance of the world with the poses after it. ``replay`` re-runs it in a
fresh Core and compares every pose bit for bit.

Topics (bag times are the wall-clock times of the entries, strictly increasing, so a reader
gets them in the order they happened):
  ``/odin/record/start``     Messages/RecordStart: world parameters and step values at start;
  ``/odin/record/<service>`` the request message of each state-changing call that succeeded
                             (Services/<Type>Request; odin_common.interface.WORLD_SERVICES);
  ``/odin/record/advance``   Messages/Advance: steps taken and the poses after them.

The bag is written as it goes to ``NAME.active`` beside it (rosbag record's convention; created
new, never through a symbolic link) and becomes ``NAME`` only when it is closed whole: flushed
to the disk, then renamed onto the name. A write that fails (a full disk) stops the recording
with one error naming the file and the cause, and never fails the world: ``NAME`` (a recording
of an earlier run included) is left as it was, and what was recorded stays in ``NAME.active``
(``rosbag reindex`` reads a bag that was never closed).
"""
from __future__ import annotations

import io
import logging
import os
import pathlib
import stat
import time
from typing import Callable, Optional

import rospy

from Messages.msg import Advance, RecordStart, Situation
from odin_common import messages
from odin_common.errors import OdinError
from odin_common.step_values import StepValues
from odin_common.world_parameters import WorldParameters

PREFIX = "/odin/record/"
START = PREFIX + "start"
ADVANCE = PREFIX + "advance"
ACTIVE_SUFFIX = ".active"
"""What a recording's name ends with while it is written (rosbag record's)."""

_log = logging.getLogger("rosout")


class RecordError(OdinError):
    """A recording cannot be started (its folder, its file, the disk)."""


def open_new_file(path: pathlib.Path) -> io.BufferedRandom:
    """``path`` created new for reading and writing (O_EXCL: never an existing file, never
    through a symbolic link)."""
    flags = os.O_RDWR | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
    return os.fdopen(os.open(path, flags, 0o644), "w+b")


class Recorder:
    """Writes one recording; ``close()`` finishes the bag (idempotent). ``open_file(path)``
    makes the file written to (``open_new_file``; tests give one that fills up)."""

    def __init__(self, path: str, parameters: WorldParameters, values: StepValues,
                 open_file: Callable[[pathlib.Path], io.IOBase] = open_new_file):
        given = pathlib.Path(path).expanduser()
        self.path = given.parent.resolve() / given.name   # the name itself: never resolved
        self.active = self.path.with_name(self.path.name + ACTIVE_SUFFIX)
        self.failed: Optional[str] = None      # why the recording stopped, once it has
        self._last = 0
        self._bag = None
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            if stat.S_ISLNK(_lstat_mode(self.path)):
                raise RecordError(f"cannot record to {self.path}: it is a symbolic link")
            file = open_file(self.active)
        except OSError as error:
            raise RecordError(f"cannot record to {_failed_file(error, self.active)}: "
                              f"{error.strerror or error}") from None
        # imported on the first recording: its crypto imports were 0.14 s of every node's start
        import rosbag
        self._file = file
        try:
            self._bag = rosbag.Bag(file, "w")
        except (OSError, rosbag.ROSBagException) as error:
            file.close()
            _remove_quietly(self.active)
            raise RecordError(f"cannot record to {self.active}: {_cause(error)}") from None
        self._write(START, RecordStart(messages.world_parameters_message(parameters),
                                       values.step, values.steps_per_cycle, values.rate))
        if self.failed is not None:
            self.close()
            _remove_quietly(self.active)
            raise RecordError(self.failed)

    def request(self, service: str, request) -> None:
        self._write(PREFIX + service, request)

    def advance(self, step: float, steps: int, sim_time: float, names, positions,
                quaternions) -> None:
        situations = [Situation(name, p.tolist(), q.tolist())
                      for name, p, q in zip(names, positions, quaternions)]
        self._write(ADVANCE, Advance(step, steps, sim_time, situations))

    def _write(self, topic: str, message) -> None:
        if self._bag is None or self.failed is not None:
            return
        now = max(time.time_ns(), self._last + 1)     # strictly increasing: the order is kept
        self._last = now
        try:
            self._bag.write(topic, message, rospy.Time(nsecs=now))
        except Exception as error:  # rosbag's own errors or the disk's: the world goes on
            self._fail(error)

    def _fail(self, error: BaseException) -> None:
        """Stops the recording, saying once why and where what was recorded is."""
        self.failed = f"cannot write the recording {self.active}: {_cause(error)}"
        _log.error("virtual_world: recording stopped: %s; %s keeps what was recorded "
                   "before (rosbag reindex), %s is not written", self.failed, self.active.name,
                   self.path.name)

    def close(self) -> None:
        """Finishes the bag and renames it onto its name; after a failure, leaves it as
        ``NAME.active`` and the name as it was."""
        if self._bag is None:
            return
        bag, self._bag = self._bag, None
        try:
            bag.close()
            if self.failed is None:
                _fsync(self.active)
                os.replace(self.active, self.path)
        except Exception as error:  # a full disk at the index: the world still closes
            if self.failed is None:
                self._fail(error)
            try:
                self._file.close()      # rosbag leaves it open when its close fails
            except OSError:
                pass                    # the same full disk, said already


def _cause(error: BaseException) -> str:
    return getattr(error, "strerror", None) or str(error) or type(error).__name__


def _failed_file(error: OSError, default: pathlib.Path) -> str:
    return error.filename if isinstance(error.filename, str) else str(default)


def _lstat_mode(path: pathlib.Path) -> int:
    """The mode of ``path`` itself (0 when there is nothing there)."""
    try:
        return os.lstat(path).st_mode
    except FileNotFoundError:
        return 0


def _fsync(path: pathlib.Path) -> None:
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _remove_quietly(path: pathlib.Path) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass
