"""Quaternions and rotation matrices: the one place where Odin turns one into the other.

Quaternions are (w, x, y, z), ODE's order, everywhere in Odin (messages, services, the Core,
the Viewer, the GUI). A rotation matrix ``R_AB`` (3, 3) maps coordinates in frame B to frame A
(column vectors, ``v_A = R_AB @ v_B``); the quaternion of ``R_AB`` rotates B's axes onto A's.

A quaternion given by a caller is accepted when its norm is within
:data:`QUATERNION_TOLERANCE` of 1 (then normalised): wide enough for values typed with three
decimals (``0.707, 0, 0, 0.707``), narrow enough to refuse a quaternion that is not meant to be
a rotation.
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from odin_common.errors import InvalidArgument

QUATERNION_TOLERANCE = 1e-3
"""A quaternion is accepted (and normalised) when | |q| - 1 | <= this."""

IDENTITY_WXYZ = (1.0, 0.0, 0.0, 0.0)


def unit_quaternion(quaternion_wxyz: Sequence[float], what: str = "orientation") -> np.ndarray:
    """(4,) float: the quaternion (w, x, y, z) normalised.

    Raises InvalidArgument (naming ``what``) unless it is 4 finite numbers whose norm is within
    QUATERNION_TOLERANCE of 1."""
    try:
        q = np.array(quaternion_wxyz, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}={quaternion_wxyz!r} is not a quaternion of 4 numbers "
                              "(w, x, y, z)") from None
    if q.shape != (4,):
        raise InvalidArgument(f"{what}={quaternion_wxyz!r} has {q.size} values, expected 4 "
                              "(w, x, y, z)")
    if not np.all(np.isfinite(q)):
        raise InvalidArgument(f"{what}={quaternion_wxyz!r} is not finite")
    norm = float(np.linalg.norm(q))
    if norm == 0.0:
        raise InvalidArgument(f"{what}={quaternion_wxyz!r} is a zero quaternion")
    if abs(norm - 1.0) > QUATERNION_TOLERANCE:
        raise InvalidArgument(f"{what}={quaternion_wxyz!r} is not a unit quaternion "
                              f"(w, x, y, z): norm {norm:.6g}")
    return q / norm


def quaternion_to_matrix(quaternion_wxyz: Sequence[float]) -> np.ndarray:
    """(3, 3) rotation matrix of a unit quaternion (w, x, y, z); not checked (see
    unit_quaternion for values from callers). A (4, ...) array gives (3, 3, ...): each
    quaternion's matrix (the Viewer's poses of a whole update at once)."""
    if np.ndim(quaternion_wxyz) > 1:
        w, x, y, z = np.asarray(quaternion_wxyz, dtype=float)
    else:
        # Python floats: the same IEEE arithmetic as numpy's scalars, several times faster (a
        # planner's propagation reads a few poses out of state vectors)
        w, x, y, z = map(float, quaternion_wxyz)
    return np.array([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                     2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                     2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]
                    ).reshape((3, 3) + np.shape(w))


def matrix_to_quaternion(rotation: np.ndarray) -> np.ndarray:
    """(4,) unit quaternion (w, x, y, z), w >= 0, of a rotation matrix (the top-left (3, 3) of
    ``rotation``, so a (4, 4) pose works too).

    Shepperd's method: the largest of w, x, y, z is computed from the diagonal and the others
    from off-diagonal sums, which keeps the division well away from zero."""
    m = np.asarray(rotation, dtype=float)[:3, :3]
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = (0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = ((m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s)
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s)
    q = np.array(q)
    q /= np.linalg.norm(q)
    return -q if q[0] < 0 else q


def quaternion_multiply(a_wxyz: Sequence[float], b_wxyz: Sequence[float]) -> np.ndarray:
    """(4,) the Hamilton product a b: the rotation b followed by a (R(a b) = R(a) R(b)); for
    arrays of quaternions (n, 4), (n, 4) the n products."""
    w1, x1, y1, z1 = np.moveaxis(np.asarray(a_wxyz, dtype=float), -1, 0)
    w2, x2, y2, z2 = np.moveaxis(np.asarray(b_wxyz, dtype=float), -1, 0)
    return np.stack([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2], axis=-1)


def axis_angle_matrix(axis: Sequence[float], angle: float) -> np.ndarray:
    """(3, 3) rotation of ``angle`` rad about ``axis`` (normalised here; a zero axis with a
    zero angle is the identity)."""
    a = np.asarray(axis, dtype=float)
    n = float(np.linalg.norm(a))
    if n == 0.0:
        if angle == 0.0:
            return np.eye(3)
        raise InvalidArgument(f"a rotation of {angle!r} rad about a zero axis")
    x, y, z = a / n
    c, s = math.cos(angle), math.sin(angle)
    C = 1.0 - c
    return np.array([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]])


def pose_matrix(position: Sequence[float], quaternion_wxyz: Sequence[float]) -> np.ndarray:
    """(4, 4) homogeneous transform of a position (m) and a unit quaternion (w, x, y, z)."""
    T = np.eye(4)
    T[:3, :3] = quaternion_to_matrix(quaternion_wxyz)
    T[:3, 3] = position
    return T


def compose_poses(position_a: np.ndarray, quaternion_a: np.ndarray, position_b: np.ndarray,
                  quaternion_b: np.ndarray) -> tuple:
    """Pose a then b, for arrays of poses: positions (n, 3) m, quaternions (n, 4) (w, x, y, z)
    (or single poses (3,), (4,)). With a = frame B in A and b = frame C in B, the result is
    frame C in A: (p_a + R(q_a) p_b, q_a q_b). Quaternions are not renormalised."""
    pa, qa = np.asarray(position_a, float), np.asarray(quaternion_a, float)
    pb, qb = np.asarray(position_b, float), np.asarray(quaternion_b, float)
    u = qa[..., 1:]
    t = 2.0 * np.cross(u, pb)
    return pa + pb + qa[..., :1] * t + np.cross(u, t), quaternion_multiply(qa, qb)


def invert_pose(position: Sequence[float], quaternion_wxyz: Sequence[float]) -> tuple:
    """The inverse of one pose (frame B in A -> frame A in B): ((3,) m, (4,) (w, x, y, z))."""
    q = np.asarray(quaternion_wxyz, dtype=float)
    conjugate = q * np.array([1.0, -1.0, -1.0, -1.0])
    return -(quaternion_to_matrix(conjugate) @ np.asarray(position, dtype=float)), conjugate


def wxyz_to_xyzw(quaternion_wxyz) -> np.ndarray:
    """Odin's (w, x, y, z) -> ROS geometry_msgs' (x, y, z, w); works on (..., 4) arrays."""
    return np.roll(np.asarray(quaternion_wxyz, dtype=float), -1, axis=-1)


def xyzw_to_wxyz(quaternion_xyzw) -> np.ndarray:
    """ROS geometry_msgs' (x, y, z, w) -> Odin's (w, x, y, z); works on (..., 4) arrays."""
    return np.roll(np.asarray(quaternion_xyzw, dtype=float), 1, axis=-1)


__all__ = ["QUATERNION_TOLERANCE", "IDENTITY_WXYZ", "unit_quaternion", "quaternion_to_matrix",
           "matrix_to_quaternion", "quaternion_multiply", "axis_angle_matrix", "pose_matrix",
           "compose_poses", "invert_pose", "wxyz_to_xyzw", "xyzw_to_wxyz"]
