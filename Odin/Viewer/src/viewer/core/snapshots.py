"""Rendered frames encoded: PNG files, always inside one folder (ROS 1 has no authentication,
so a caller must not be able to write anywhere else), and JPEG bytes for the compressed image
topic."""
from __future__ import annotations

import logging
import io
import os
import pathlib
import queue
import threading

import numpy as np
from PIL import Image

from viewer.errors import ViewerError

log = logging.getLogger(__name__)


def snapshot_path(folder: os.PathLike, name: str) -> pathlib.Path:
    """The file ``folder/name`` (".png" added if missing) for a plain file name.

    Refused with :class:`ViewerError`: empty names, names with a path separator or a NUL, ".",
    "..", absolute paths, and names whose target in ``folder`` is a symbolic link (checked again
    when the file is opened, see :func:`write_png`).
    """
    if not isinstance(name, str) or not name.strip():
        raise ViewerError(f"snapshot name must be a non-empty file name, got {name!r}")
    if "/" in name or "\\" in name or "\0" in name or name in (".", "..") or os.path.isabs(name):
        raise ViewerError(f"snapshot name {name!r} must be a plain file name inside the "
                          f"snapshot folder (no '/', no '..')")
    if not name.lower().endswith(".png"):
        name += ".png"
    folder = pathlib.Path(folder).resolve()
    path = folder / name
    if path.is_symlink():
        raise ViewerError(f"snapshot name {name!r} is a symbolic link in {folder}; refused")
    if path.resolve().parent != folder:
        raise ViewerError(f"snapshot name {name!r} leaves the snapshot folder {folder}")
    return path


def write_png(path: os.PathLike, frame: np.ndarray) -> pathlib.Path:
    """Writes ``frame`` (height, width, 3) uint8 RGB as PNG; never follows a symbolic link."""
    path = pathlib.Path(path)
    flags = os.O_WRONLY | os.O_CREAT | os.O_TRUNC | getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags, 0o644)
    except OSError as error:
        raise ViewerError(f"cannot write snapshot {path}: {error.strerror}") from None
    with os.fdopen(fd, "wb") as file:
        Image.fromarray(frame, "RGB").save(file, format="PNG", compress_level=1)
    return path


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


class FrameWriter:
    """Writes numbered frames ``frame_000001.png``, ``frame_000002.png``... into a folder on a
    thread of its own, so that PNG encoding never holds up rendering. Frames that arrive while
    ``max_pending`` are still waiting are dropped (and counted)."""

    def __init__(self, folder: os.PathLike, max_pending: int = 8) -> None:
        self.folder = pathlib.Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.written = 0
        self.dropped = 0
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
                write_png(self.folder / f"frame_{number:06d}.png", frame)
                self.written += 1
            except (ViewerError, OSError) as error:
                log.error("frame %d not written: %s", number, error)
