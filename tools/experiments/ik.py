"""Numeric inverse kinematics over Odin's DH model (gui.core.model.RobotModel), numpy only.

Damped least squares on the pose error of one link frame (position m, orientation as the
rotation vector of R_target R^T, rad), with a finite-difference Jacobian over the chosen joints.
Good enough to make path files; not a real-time solver.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np


def rotation_vector(R: np.ndarray) -> np.ndarray:
    """The axis * angle (rad) of a (3, 3) rotation."""
    cos = np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)
    angle = np.arccos(cos)
    if angle < 1e-9:
        return np.zeros(3)
    if np.pi - angle < 1e-6:
        w, v = np.linalg.eigh((R + R.T) / 2)
        return v[:, np.argmax(w)] * angle
    return angle / (2 * np.sin(angle)) * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0],
                                                   R[1, 0] - R[0, 1]])


def frame_of(model, base_pose: np.ndarray, q: np.ndarray, link: int,
             offset: np.ndarray) -> np.ndarray:
    """World pose (4, 4) of ``offset`` (a pose in link ``link``'s frame) for joints ``q``."""
    return model.link_poses(base_pose, q)[link] @ offset


def solve(model, base_pose: np.ndarray, q0: Sequence[float], link: int, offset: np.ndarray,
          target: np.ndarray, joints: Sequence[int], iterations: int = 300,
          tolerance: float = 1e-5, damping: float = 1e-3) -> tuple:
    """Joint values (all movable joints, only ``joints`` indices changed) putting ``offset``
    in link ``link`` at ``target`` (4, 4); returns (q, position error m, angle error rad).
    Joint limits of the model are respected by clamping."""
    q = np.array(q0, dtype=float)
    movable = model.movable_links()
    limits = [model.links[i].limits or (-np.inf, np.inf) for i in movable]

    def error(qv):
        T = frame_of(model, base_pose, qv, link, offset)
        return np.concatenate([target[:3, 3] - T[:3, 3],
                               rotation_vector(target[:3, :3] @ T[:3, :3].T)])

    e = error(q)
    for _ in range(iterations):
        if np.linalg.norm(e[:3]) < tolerance and np.linalg.norm(e[3:]) < tolerance:
            break
        J = np.zeros((6, len(joints)))
        for k, j in enumerate(joints):
            dq = q.copy()
            dq[j] += 1e-6
            J[:, k] = (e - error(dq)) / 1e-6
        step = J.T @ np.linalg.solve(J @ J.T + damping * np.eye(6), e)
        q[list(joints)] += np.clip(step, -0.2, 0.2)
        for k, j in enumerate(joints):
            q[j] = np.clip(q[j], limits[j][0], limits[j][1])
        e = error(q)
    return q, float(np.linalg.norm(e[:3])), float(np.linalg.norm(e[3:]))
