"""tf2_msgs/TFMessage from pose arrays without one Python object per frame (no rospy here).

The world publishes a transform per object every publication; building thousands of
TransformStamped objects at 25 Hz would cost more than the step. As SpaceDistributionWriter
does for world_update, the frame names are encoded once per layout, and each message scatters
the stamp and the 7 doubles of every transform into that template with one vectorised copy.
Subscribers receive an ordinary TFMessage (the wire format is the same). Quaternions come in as
Odin's (w, x, y, z) and leave as geometry_msgs' (x, y, z, w).
"""
from __future__ import annotations

import struct
from typing import Sequence

import numpy as np
from tf2_msgs.msg import TFMessage

from odin_common.interface import WORLD_FRAME
from odin_common.rotations import wxyz_to_xyzw


class TfWriter:
    """``message(frames, positions, quaternions, stamp)`` -> a TFMessage of transforms from
    ``parent`` (default the world frame) to each frame."""

    _POSE_BYTES = 7 * 8
    _STAMP_BYTES = 8

    def __init__(self, parent: str = WORLD_FRAME):
        self._parent = parent.encode("utf-8")
        self._lay_out(())

    def message(self, frames: Sequence[str], positions: np.ndarray, quaternions: np.ndarray,
                stamp) -> TFMessage:
        """``positions`` (n, 3) m and ``quaternions`` (n, 4) (w, x, y, z) of each frame in the
        parent frame; ``stamp`` a rospy.Time (or anything with secs and nsecs)."""
        if tuple(frames) != self._frames:
            self._lay_out(frames)
        body = np.frombuffer(self._template, dtype=np.uint8).copy()
        if self._frames:
            poses = np.ascontiguousarray(
                np.hstack([positions, wxyz_to_xyzw(quaternions)]), dtype="<f8")
            body[self._pose_scatter] = poses.view(np.uint8).ravel()
            stamp_bytes = np.frombuffer(struct.pack("<2I", stamp.secs, stamp.nsecs), np.uint8)
            body[self._stamp_scatter] = np.tile(stamp_bytes, len(self._frames))
        return _PreSerialisedTF(body.tobytes())

    def _lay_out(self, frames: Sequence[str]) -> None:
        parent = struct.pack("<I", len(self._parent)) + self._parent
        chunks, stamps, poses, cursor = [struct.pack("<I", len(frames))], [], [], 4
        for frame in frames:
            child = frame.encode("utf-8")
            head = struct.pack("<I", 0)                      # header.seq
            stamps.append(cursor + len(head))
            chunk = (head + bytes(self._STAMP_BYTES) + parent
                     + struct.pack("<I", len(child)) + child)
            poses.append(cursor + len(chunk))
            chunks.append(chunk + bytes(self._POSE_BYTES))
            cursor += len(chunk) + self._POSE_BYTES
        self._frames = tuple(frames)
        self._template = bytearray(b"".join(chunks))
        self._stamp_scatter = (np.asarray(stamps, dtype=np.intp)[:, None]
                               + np.arange(self._STAMP_BYTES)).ravel()
        self._pose_scatter = (np.asarray(poses, dtype=np.intp)[:, None]
                              + np.arange(self._POSE_BYTES)).ravel()


class _PreSerialisedTF(TFMessage):
    """A TFMessage already serialised by the writer."""

    __slots__ = ("_body",)

    def __init__(self, body: bytes):
        super().__init__()
        self._body = body

    def serialize(self, buff) -> None:
        buff.write(self._body)


__all__ = ["TfWriter"]
