"""Messages serialised with their mesh arrays written from numpy.

genpy serialises a float64[] or uint32[] field from Python numbers, packing one object at a
time: a robot's meshes (~800,000 numbers for the TX90 + hand) took a tenth of a second at each
end of a load. Messages/Object and Services/ViewObject's request both begin with a string
(name, id), a float64[] (parameters) and a uint32[] (indices): ``with_mesh_arrays`` writes
those two arrays into genpy's bytes of the same message serialised without them, and a
``PrePacked`` message class sends such bytes as its serialisation. Tests pin the result to
genpy byte for byte (Odin/GUI/test/test_packed_requests.py,
Odin/VirtualWorld/test/test_conversions.py).

At the receiving end, odin_common.node.numpy_requests makes a service whose requests arrive
with their arrays as numpy views of the received bytes (rospy.numpy_msg).
"""
from __future__ import annotations

import io
import struct

import numpy as np

COUNT = struct.Struct("<I")
"""An array's length or a string's byte count, as ROS serialises it."""


def serialised(message) -> bytes:
    """``message``'s bytes as genpy writes them."""
    buffer = io.BytesIO()
    message.serialize(buffer)
    return buffer.getvalue()


def string_size(text: str) -> int:
    """Bytes of a serialised string field: its length and its UTF-8 bytes."""
    return COUNT.size + len(text.encode("utf-8"))


def with_mesh_arrays(light: bytes, name: str, parameters: np.ndarray,
                     indices: np.ndarray) -> bytes:
    """``light`` (genpy's bytes of a message beginning with the string ``name`` and an empty
    float64[] and uint32[]) with ``parameters`` (float64, flat) and ``indices`` (uint32, flat)
    in those two arrays."""
    values = np.ascontiguousarray(parameters, dtype="<f8").reshape(-1)
    index_values = np.ascontiguousarray(indices, dtype="<u4").reshape(-1)
    head = string_size(name)
    return b"".join((light[:head], COUNT.pack(values.size), values.tobytes(),
                     COUNT.pack(index_values.size), index_values.tobytes(),
                     light[head + 2 * COUNT.size:]))


class PrePacked:
    """Mixed into a generated message class (before it): once ``packed`` is set, those bytes
    are the message's serialisation (rospy checks the class with isinstance, and receivers
    read an ordinary message). No ``__slots__``: genpy checks keyword fields against the
    class's own."""

    packed = None

    def serialize(self, buff) -> None:
        if self.packed is None:
            super().serialize(buff)
        else:
            buff.write(self.packed)
