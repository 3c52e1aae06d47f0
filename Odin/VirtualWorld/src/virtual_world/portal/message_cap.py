"""A cap on the size of every ROS message this process receives (service requests included).

rospy buffers a TCPROS message whole before deserialising it, whatever its 4-byte length
header announces, so one oversized request (a mesh of a billion triangles, a list of a billion
IDs) would grow the node's memory until the host gives way. rospy has no such cap of its own;
every received chunk passes through ``rospy.impl.tcpros_base.deserialize_messages`` with the
buffer so far, so wrapping it reads each message's length header as soon as its 4 bytes arrive:
a message that announces more than the cap is refused there, before its body is read, the
connection is dropped (the caller's call fails) and the node logs why. Nothing else changes.

The refusal is a TransportTerminated, not a DeserializationError: rospy's service handler turns
the latter into a TransportException it does not catch, and its thread then dies leaving the
socket open, so the caller would wait forever; a terminated transport is closed.
"""
from __future__ import annotations

import struct

import rospy
from rospy.exceptions import TransportTerminated
import rospy.impl.tcpros_base as tcpros_base

_ROSPY_DESERIALIZE = tcpros_base.deserialize_messages
_HEADER = struct.Struct("<I")


def cap_incoming_messages(max_bytes: int) -> None:
    """From now on every message this process receives may hold at most ``max_bytes``."""
    def capped(b, msg_queue, data_class, queue_size=None, max_msgs=None, start=0):
        _check_lengths(b, start, max_bytes, data_class)
        return _ROSPY_DESERIALIZE(b, msg_queue, data_class, queue_size=queue_size,
                                  max_msgs=max_msgs, start=start)
    tcpros_base.deserialize_messages = capped


def _check_lengths(buffer, start: int, max_bytes: int, data_class) -> None:
    """Raises TransportTerminated at the first length header in ``buffer`` (a BytesIO
    written up to its position) that announces more than ``max_bytes``."""
    end = buffer.tell()
    with buffer.getbuffer() as view:     # no copy: the buffer may already hold megabytes
        position = start
        while position + 4 <= end:
            (length,) = _HEADER.unpack_from(view, position)
            if length > max_bytes:
                what = getattr(data_class, "_type", "message")
                text = (f"refused a {what} of {length:,} bytes: the node's limit is "
                        f"{max_bytes:,} bytes (~max_request_mb)")
                rospy.logerr(text)
                raise TransportTerminated(text)
            position += 4 + length
