"""Between the world's ROS messages and the Core's plain values; no rospy, only the generated
classes (specs to Object/Composite messages and back: odin_common.messages).

Units and frames pass through unchanged (SI, world frame, quaternions (w, x, y, z) on both
sides), so these functions only reshape.
"""
from __future__ import annotations

import struct
from typing import Sequence

import numpy as np

from Messages.msg import Collided, CollisionPair, JointData, ServoStates, SpaceDistribution
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Point, Vector3, Wrench
from sensor_msgs.msg import JointState
from Services.srv import ViewObjectRequest
from odin_common.packed import PrePacked, serialised, with_mesh_arrays
from virtual_world.core.arrays import flat_float64, uint32_array


def view_requests(geometries) -> list:
    """View Object requests for geometries as the Core built them (core.BuiltGeometry), or
    as they are now (at their present poses); each serialises itself from bytes made here
    (see PackedViewObjectRequest)."""
    requests = []
    for g in geometries:
        # the mesh arrays as the Core holds them: a list copy of a hand's meshes cost ~20 ms
        # to make and free again at each load
        request = PackedViewObjectRequest(g.name, g.parameters, g.indices, list(g.position),
                                          list(g.orientation), list(g.color), g.shape)
        request.pack(g.parameters, g.indices)
        requests.append(request)
    return requests


class PackedViewObjectRequest(PrePacked, ViewObjectRequest):
    """A View Object request sent as bytes made by ``pack`` (odin_common.packed): genpy packed
    the TX90 + hand's meshes one Python number at a time, ~30 ms of the world's Viewer thread
    at every load, holding the GIL its loop thread needed to answer the next requests; numpy's
    bytes of the arrays the Core made already (core.arrays) take ~1 ms."""

    def pack(self, parameters, indices) -> None:
        """Makes the bytes from the request's other fields and ``parameters``, ``indices``
        (the same numbers as its own, as the Core holds them)."""
        light = serialised(ViewObjectRequest(self.id, [], [], self.position, self.orientation,
                                             self.color, self.shape))
        index_values = uint32_array(indices)
        self.packed = with_mesh_arrays(
            light, self.id, flat_float64(parameters),
            np.asarray(indices, dtype=np.uint32) if index_values is None else index_values)


def collision_pairs(collisions) -> list:
    """Core collisions (first, second, depth, points) -> Messages/CollisionPair."""
    return [CollisionPair(c.first, c.second, c.depth, [Point(*point) for point in c.points],
                          [Vector3(*n) for n in c.normals], [Vector3(*f) for f in c.forces])
            for c in collisions]


def collided_message(collisions, stamp) -> Collided:
    """Core collisions -> Messages/Collided (each geometry named once in ``names``)."""
    message = Collided()
    message.header.stamp = stamp
    message.header.frame_id = "world"
    message.pairs = collision_pairs(collisions)
    message.names = list(dict.fromkeys(n for c in collisions for n in (c.first, c.second)))
    return message


def divergence_diagnostics(divergences, stamp) -> DiagnosticArray:
    """Core divergences -> diagnostic_msgs/DiagnosticArray, one ERROR status each."""
    message = DiagnosticArray()
    message.header.stamp = stamp
    for event in divergences:
        values = [KeyValue("object", event.id), KeyValue("reason", event.reason),
                  KeyValue("value", f"{event.value:.9g}"),
                  KeyValue("simulated time (s)", f"{event.time:.9g}")]
        for label, vector in (("position (m)", event.position),
                              ("velocity (m/s)", event.velocity),
                              ("angular velocity (rad/s)", event.angular)):
            values.append(KeyValue(label, " ".join(f"{v:.9g}" for v in vector)))
        message.status.append(DiagnosticStatus(
            level=DiagnosticStatus.ERROR, name="virtual_world: divergence guard",
            message=f"{event.id} diverged ({event.reason}) and was parked",
            hardware_id="virtual_world", values=values))
    return message


def servo_states_message(servos, stamp) -> ServoStates:
    message = ServoStates(motors=[s.id for s in servos], axes=[len(s.targets) for s in servos],
                          targets=[v for s in servos for v in s.targets],
                          positions=[v for s in servos for v in s.positions],
                          errors=[v for s in servos for v in s.errors])
    message.header.stamp = stamp
    return message


def wrench(force, torque) -> Wrench:
    return Wrench(Vector3(*force), Vector3(*torque))


def joint_data(states) -> list:
    return [JointData(state.id, state.type, list(state.positions), list(state.rates))
            for state in states]


def joint_state_message(states, stamp) -> JointState:
    """Core joint states -> sensor_msgs/JointState, one name per joint axis: ``<joint id>``
    for one-axis joints, ``<joint id>/<axis>`` otherwise."""
    message = JointState()
    message.header.stamp = stamp
    for state in states:
        for axis, (position, rate) in enumerate(zip(state.positions, state.rates), start=1):
            message.name.append(state.id if len(state.positions) == 1 else f"{state.id}/{axis}")
            message.position.append(position)
            message.velocity.append(rate)
    return message


class SpaceDistributionWriter:
    """Serialises SpaceDistribution from the Core's pose arrays without one Python object per
    geometry: the names are encoded once per scene and the 7 doubles of every geometry are
    scattered into that template with one vectorised copy. Subscribers receive an ordinary
    Messages/SpaceDistribution (the wire format is the same)."""

    _POSE_BYTES = 7 * 8

    def __init__(self):
        self._layout(())

    def message(self, names: Sequence[str], positions: np.ndarray, quaternions: np.ndarray,
                stamp) -> SpaceDistribution:
        if tuple(names) != self._names:
            self._layout(names)
        poses = np.ascontiguousarray(np.hstack([positions, quaternions]), dtype="<f8")
        body = np.frombuffer(self._template, dtype=np.uint8).copy()
        body[self._scatter] = poses.view(np.uint8).ravel()
        return _PreSerialised(stamp, body.tobytes())

    def _layout(self, names: Sequence[str]) -> None:
        chunks, offsets, cursor = [struct.pack("<I", len(names))], [], 4
        for name in names:
            encoded = name.encode("utf-8")
            chunk = struct.pack("<I", len(encoded)) + encoded
            chunks.append(chunk + bytes(self._POSE_BYTES))
            offsets.append(cursor + len(chunk))
            cursor += len(chunk) + self._POSE_BYTES
        self._names = tuple(names)
        self._template = bytearray(b"".join(chunks))
        starts = np.asarray(offsets, dtype=np.intp)
        self._scatter = (starts[:, None] + np.arange(self._POSE_BYTES)).ravel()


class _PreSerialised(SpaceDistribution):
    """A SpaceDistribution whose situations are already serialised (see the writer)."""

    __slots__ = ("_body",)

    def __init__(self, stamp, body: bytes):
        super().__init__()
        self.header.stamp = stamp
        self.header.frame_id = "world"
        self._body = body

    def serialize(self, buff) -> None:
        header = self.header
        frame = header.frame_id.encode("utf-8")
        buff.write(struct.pack("<3I", header.seq, header.stamp.secs, header.stamp.nsecs))
        buff.write(struct.pack("<I", len(frame)) + frame)
        buff.write(self._body)


__all__ = ["view_requests", "collision_pairs", "collided_message", "divergence_diagnostics",
           "servo_states_message", "wrench", "joint_data", "joint_state_message",
           "SpaceDistributionWriter"]
