"""Homogeneous transforms, Denavit-Hartenberg frames and forward kinematics.

Every pose is a (4, 4) float array ``T_AB`` mapping coordinates in frame B to frame A
(column vectors, ``p_A = T_AB @ p_B``), lengths in metres, angles in radians. Quaternions
are (w, x, y, z), ODE's order; rotations and quaternions come from odin_common.rotations.
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from odin_common.rotations import axis_angle_matrix, matrix_to_quaternion


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


def pose_to_position_quaternion(T: np.ndarray) -> tuple[tuple[float, float, float],
                                                        tuple[float, float, float, float]]:
    return (tuple(float(v) for v in T[:3, 3]),
            tuple(float(v) for v in matrix_to_quaternion(T)))


def joint_motion(axis: np.ndarray, value: float, rotational: bool) -> np.ndarray:
    """The motion of a joint by ``value`` (rad or m) about/along ``axis`` (unit, joint frame)."""
    T = np.eye(4)
    if rotational:
        T[:3, :3] = axis_angle_matrix(axis, value)
    else:
        T[:3, 3] = np.asarray(axis, dtype=float) * value
    return T
