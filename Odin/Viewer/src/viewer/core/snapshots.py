"""Rendered frames encoded: PNG files, always inside one folder (ROS 1 has no authentication,
so a caller must not be able to write anywhere else) and each written whole or not at all (a
full disk leaves an older file of the name as it was: :func:`write_file`), and JPEG bytes for
the compressed image topic."""
from __future__ import annotations

import io
import logging
import math
import os
import pathlib
import queue
import secrets
import stat
import threading
import time
from typing import Callable, Optional

import numpy as np
from PIL import Image

from odin_common.errors import InvalidArgument
from odin_common.limits import check_name, shown
from viewer.errors import ViewerError

log = logging.getLogger(__name__)


#: bytes of a file name (without its folder): what Linux file systems take (NAME_MAX)
NAME_MAX_BYTES = 255

#: the name of a file while it is being written, in the folder of the file it becomes (a
#: dot file, so that nothing reading the folder's frames takes it for one); short, so that
#: any name that fits NAME_MAX_BYTES has a temporary file that fits too
_TEMPORARY_PREFIX = ".odin-writing-"

Write = Callable[[int, bytes], int]
"""How bytes reach a file descriptor (``os.write``): tests inject one that fills up."""


def snapshot_path(folder: os.PathLike, name: str) -> pathlib.Path:
    """The file ``folder/name`` (".png" added if missing) for a plain file name.

    Refused with :class:`ViewerError` (an OdinError): names that are no valid name
    (odin_common.limits.check_name: empty, over MAX_NAME_BYTES, a control character such as
    NUL or a newline), names with a path separator, ".", "..", names whose file name (with
    ".png") is over NAME_MAX_BYTES, and names whose target in ``folder`` is a symbolic link
    (checked again when the file is written, see :func:`write_png`).
    """
    try:
        check_name("snapshot name", name)
    except InvalidArgument as error:
        raise ViewerError(str(error)) from None
    if not name.strip() or "/" in name or "\\" in name or name in (".", ".."):
        raise ViewerError(f"snapshot name {shown(name)} must be a plain file name inside the "
                          f"snapshot folder (no '/', no '..')")
    if not name.lower().endswith(".png"):
        name += ".png"
    if len(name.encode("utf-8", "surrogatepass")) > NAME_MAX_BYTES:
        raise ViewerError(f"snapshot name {shown(name)} is longer than the {NAME_MAX_BYTES} "
                          "bytes a file name may have (with its '.png')")
    folder = pathlib.Path(folder).resolve()
    path = folder / name
    try:
        if path.is_symlink():
            raise ViewerError(f"snapshot name {name!r} is a symbolic link in {folder}; refused")
        if path.resolve().parent != folder:
            raise ViewerError(f"snapshot name {name!r} leaves the snapshot folder {folder}")
    except OSError as error:
        raise ViewerError(f"cannot write snapshot {path}: {error.strerror}") from None
    return path


def encode_png(frame: np.ndarray) -> bytes:
    """``frame`` (height, width, 3) uint8 RGB as PNG bytes."""
    buffer = io.BytesIO()
    Image.fromarray(frame, "RGB").save(buffer, format="PNG", compress_level=1)
    return buffer.getvalue()


def write_png(path: os.PathLike, frame: np.ndarray, write: Optional[Write] = None
              ) -> pathlib.Path:
    """Writes ``frame`` (height, width, 3) uint8 RGB as PNG (:func:`write_file`)."""
    return write_file(path, encode_png(frame), "snapshot", write)


def write_file(path: os.PathLike, data: bytes, what: str = "file",
               write: Optional[Write] = None) -> pathlib.Path:
    """Puts ``data`` at ``path`` whole or not at all: written to a new temporary file in the
    same folder (O_EXCL, never through a symbolic link), flushed to the disk, then renamed
    onto ``path``. A full disk or any other failure leaves a file already at ``path`` as it
    was, creates nothing, and raises :class:`ViewerError` naming ``what``, the file and the
    cause ("No space left on device"). A symbolic link at ``path`` is refused (the rename
    would replace the link, never write where it points). ``write``: ``os.write`` by default.
    """
    path = pathlib.Path(path)
    temporary = None
    try:
        if stat.S_ISLNK(_lstat_mode(path)):
            raise ViewerError(f"cannot write {what} {path}: it is a symbolic link; refused")
        temporary, fd = _new_temporary(path.parent)
        try:
            _write_all(fd, data, write or os.write)
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(temporary, path)
        temporary = None
    except OSError as error:
        raise ViewerError(f"cannot write {what} {path}: "
                          f"{error.strerror or error}") from None
    finally:
        if temporary is not None:
            _remove_quietly(temporary)
    return path


def _lstat_mode(path: pathlib.Path) -> int:
    """The mode of ``path`` itself (0 when there is nothing there)."""
    try:
        return os.lstat(path).st_mode
    except FileNotFoundError:
        return 0


def _new_temporary(folder: pathlib.Path) -> tuple:
    """(path, descriptor) of a new, empty file of a name no one else holds in ``folder``."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
    while True:
        temporary = folder / f"{_TEMPORARY_PREFIX}{secrets.token_hex(6)}"
        try:
            return temporary, os.open(temporary, flags, 0o644)
        except FileExistsError:
            continue      # 48 random bits taken already: draw again


def _write_all(fd: int, data: bytes, write: Write) -> None:
    view = memoryview(data)
    while view:
        view = view[write(fd, view):]


def _remove_quietly(path: pathlib.Path) -> None:
    try:
        os.unlink(path)
    except OSError as error:   # nothing more to do about it than to say so
        log.error("cannot remove the unfinished file %s: %s", path, error.strerror)


JPEG_QUALITY = 80
"""image_transport's default JPEG quality (compressed_image_transport's ``jpeg_quality``)."""

COMPRESSED_FORMAT = "rgb8; jpeg compressed bgr8"
"""sensor_msgs/CompressedImage ``format`` as compressed_image_transport writes it for an rgb8
image (its encoder works in OpenCV's BGR order; the JPEG itself is plain), so that
``image_transport republish compressed`` and rqt_image_view decode it."""


def encode_jpeg(frame: np.ndarray, quality: int = JPEG_QUALITY) -> bytes:
    """``frame`` (height, width, 3) uint8 RGB as JPEG bytes (about 1/20 of the raw frame)."""
    buffer = io.BytesIO()
    Image.fromarray(frame, "RGB").save(buffer, format="JPEG", quality=quality)
    return buffer.getvalue()


#: s between two warnings that frames are not being written (a full disk fails every frame)
FRAME_WARNING_PERIOD = 60.0


class FrameWriter:
    """Writes numbered frames ``frame_000001.png``, ``frame_000002.png``... into a folder on a
    thread of its own, so that PNG encoding never holds up rendering. Frames that arrive while
    ``max_pending`` are still waiting are dropped (and counted). A frame that cannot be written
    (a full disk) leaves no file and is counted in ``failed``; the failures are one warning per
    FRAME_WARNING_PERIOD s, and frames are written again as soon as the disk takes them.
    ``write``: how bytes reach a file (``os.write``; tests inject a full disk)."""

    def __init__(self, folder: os.PathLike, max_pending: int = 8,
                 write: Optional[Write] = None) -> None:
        self.folder = pathlib.Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.written = 0
        self.dropped = 0
        self.failed = 0
        self._write = write
        self._failing_since: Optional[int] = None     # failures so far when they began
        self._warned_at = -math.inf                    # time.monotonic() of the last warning
        self._queue: queue.Queue = queue.Queue(maxsize=max_pending)
        self._number = 0
        self._thread = threading.Thread(target=self._run, name="viewer-frames", daemon=True)
        self._thread.start()

    def put(self, frame: np.ndarray) -> None:
        self._number += 1
        try:
            self._queue.put_nowait((self._number, frame))
        except queue.Full:
            self._number -= 1
            self.dropped += 1

    def close(self, timeout: float = 10.0) -> None:
        """Writes what is queued, then stops the thread (idempotent)."""
        if self._thread.is_alive():
            self._queue.put(None)
            self._thread.join(timeout)

    def _run(self) -> None:
        while True:
            item = self._queue.get()
            if item is None:
                return
            number, frame = item
            try:
                write_png(self.folder / f"frame_{number:06d}.png", frame, self._write)
            except ViewerError as error:
                self._failed(number, error)
            else:
                self._written(number)

    def _failed(self, number: int, error: ViewerError) -> None:
        self.failed += 1
        if self._failing_since is None:
            self._failing_since = self.failed - 1
        now = time.monotonic()
        if now - self._warned_at >= FRAME_WARNING_PERIOD:
            self._warned_at = now
            log.warning("frame %d not written (%d frames not written since the last one "
                        "written; warned again in %g s at most): %s", number,
                        self.failed - self._failing_since, FRAME_WARNING_PERIOD, error)

    def _written(self, number: int) -> None:
        self.written += 1
        if self._failing_since is not None:
            log.warning("frames are written again from frame %d, after %d not written",
                        number, self.failed - self._failing_since)
            self._failing_since = None
            self._warned_at = -math.inf
