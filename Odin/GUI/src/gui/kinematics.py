"""Homogeneous transforms, Denavit-Hartenberg frames and forward kinematics.

Every pose is a (4, 4) float array ``T_AB`` mapping coordinates in frame B to frame A
(column vectors, ``p_A = T_AB @ p_B``), lengths in metres, angles in radians. Quaternions
are (w, x, y, z), ODE's order.
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np


def identity() -> np.ndarray:
    return np.eye(4)


def translation(x: float, y: float, z: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def rot_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    T = np.eye(4)
    T[1, 1], T[1, 2], T[2, 1], T[2, 2] = c, -s, s, c
    return T


def rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    T = np.eye(4)
    T[0, 0], T[0, 1], T[1, 0], T[1, 1] = c, -s, s, c
    return T


def axis_angle_matrix(axis: Sequence[float], angle: float) -> np.ndarray:
    """(3, 3) rotation of ``angle`` rad about ``axis`` (normalised here; a zero axis with a
    zero angle is the identity)."""
    a = np.asarray(axis, dtype=float)
    n = float(np.linalg.norm(a))
    if n == 0.0:
        if angle == 0.0:
            return np.eye(3)
        raise ValueError("a rotation of a non-zero angle about a zero axis")
    x, y, z = a / n
    c, s = math.cos(angle), math.sin(angle)
    C = 1.0 - c
    return np.array([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]])


def pose_from_axis_angle(position: Sequence[float], axis: Sequence[float],
                         angle: float) -> np.ndarray:
    """Kautham's pose: position (m) and an axis-angle rotation (rad)."""
    T = np.eye(4)
    T[:3, :3] = axis_angle_matrix(axis, angle)
    T[:3, 3] = position
    return T


def rpy_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """URDF's fixed-axis roll (x), pitch (y), yaw (z): R = Rz(yaw) Ry(pitch) Rx(roll)."""
    return (axis_angle_matrix((0, 0, 1), yaw) @ axis_angle_matrix((0, 1, 0), pitch)
            @ axis_angle_matrix((1, 0, 0), roll))


def dh_standard(alpha: float, a: float, theta: float, d: float) -> np.ndarray:
    """Standard DH: Rz(theta) Tz(d) Tx(a) Rx(alpha)."""
    return rot_z(theta) @ translation(0, 0, d) @ translation(a, 0, 0) @ rot_x(alpha)


def dh_modified(alpha: float, a: float, theta: float, d: float) -> np.ndarray:
    """Modified (Craig) DH: Rx(alpha) Tx(a) Rz(theta) Tz(d)."""
    return rot_x(alpha) @ translation(a, 0, 0) @ rot_z(theta) @ translation(0, 0, d)


def quaternion_from_matrix(R: np.ndarray) -> tuple[float, float, float, float]:
    """Unit quaternion (w, x, y, z) of a rotation matrix (the top-left 3x3 of ``R``), w >= 0."""
    m = np.asarray(R, dtype=float)[:3, :3]
    t = m[0, 0] + m[1, 1] + m[2, 2]
    if t > 0.0:
        s = math.sqrt(t + 1.0) * 2.0
        q = (0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2.0
        q = ((m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s)
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2.0
        q = ((m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s)
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2.0
        q = ((m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s)
    q = np.array(q)
    q /= np.linalg.norm(q)
    if q[0] < 0:
        q = -q
    return tuple(float(v) for v in q)


def matrix_from_quaternion(q: Sequence[float]) -> np.ndarray:
    """(3, 3) rotation of a quaternion (w, x, y, z) (normalised here)."""
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def pose_to_position_quaternion(T: np.ndarray) -> tuple[tuple[float, float, float],
                                                        tuple[float, float, float, float]]:
    return tuple(float(v) for v in T[:3, 3]), quaternion_from_matrix(T)


def joint_motion(axis: np.ndarray, value: float, rotational: bool) -> np.ndarray:
    """The motion of a joint by ``value`` (rad or m) about/along ``axis`` (unit, joint frame)."""
    T = np.eye(4)
    if rotational:
        T[:3, :3] = axis_angle_matrix(axis, value)
    else:
        T[:3, 3] = np.asarray(axis, dtype=float) * value
    return T
