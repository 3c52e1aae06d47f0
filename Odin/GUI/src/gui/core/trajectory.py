"""Time parametrisation of a path of waypoints within velocity and acceleration limits
(ROS-free).

``TIMING`` (below) says how; docs/INTERFACE.md shows it (tools/interface_doc.py).
``Trajectory.of(waypoints, speeds, accelerations, base_poses=..., base_limits=...)`` times a
path; ``trajectory.sample(t)`` gives the targets and rates at time t.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from odin_common.rotations import axis_angle_matrix, matrix_to_quaternion

TIMING = """\
A path (`rosrun GUI run_path PROBLEM --tracked FILE`, the Motion tab's "Tracked path...") is
timed segment by segment, straight lines in joint space between consecutive waypoints, the
robot at rest at every waypoint (so it never leaves the planner's collision-checked segments).
In a segment every joint moves together: q(t) = q_a + s(t) (q_b - q_a), where s goes from 0 to
1 along a trapezoidal speed profile (constant acceleration, cruise, constant deceleration;
a triangle when the segment is too short to reach cruise). Its peak rate and acceleration are
the largest that keep every joint within its limits: ds/dt <= min_j v_j / |q_b - q_a|_j and
d2s/dt2 <= min_j a_j / |q_b - q_a|_j, so the slowest joint sets the segment's duration and
all of them start and stop together. v_j is `TrackingDefaults.speed_fraction` of the joint's
speed limit (its URDF velocity, or `SERVO_MAX_SPEED`), leaving the servo room to correct;
a_j is `TrackingDefaults.acceleration` (Kautham's files give none). A free-flying base moves
the same way within `base_speed` (m/s), `base_acceleration`, `base_angular_speed` (rad/s) and
`base_angular_acceleration`: its position along the line, its orientation by slerp, both on the
segment's s(t). Waypoints that repeat are joined (a zero-length segment takes no time).
"""


@dataclass(frozen=True)
class Profile:
    """A rest-to-rest trapezoidal profile of s from 0 to 1: peak rate ``rate`` (1/s),
    acceleration ``acceleration`` (1/s^2), ``duration`` (s)."""
    rate: float
    acceleration: float
    duration: float

    @staticmethod
    def fastest(rate: float, acceleration: float) -> "Profile":
        if rate * rate / acceleration >= 1.0:           # a triangle: never reaches ``rate``
            peak = math.sqrt(acceleration)
            return Profile(peak, acceleration, 2.0 / peak)
        return Profile(rate, acceleration, 1.0 / rate + rate / acceleration)

    def at(self, t: float) -> Tuple[float, float]:
        """(s, ds/dt) at time t (clamped to [0, duration])."""
        t = min(max(t, 0.0), self.duration)
        ramp = self.rate / self.acceleration
        if t < ramp:
            return 0.5 * self.acceleration * t * t, self.acceleration * t
        left = self.duration - t
        if left < ramp:
            return 1.0 - 0.5 * self.acceleration * left * left, self.acceleration * left
        return 0.5 * self.rate * ramp + self.rate * (t - ramp), self.rate


@dataclass(frozen=True)
class BaseLimits:
    """A free-flying base's limits: m/s, m/s^2, rad/s, rad/s^2."""
    speed: float
    acceleration: float
    angular_speed: float
    angular_acceleration: float


@dataclass(frozen=True)
class Sample:
    """Targets at one time: ``joints`` (d,) rad or m and their ``rates`` (d,) rad/s or m/s;
    per free-flying base, ``base_pose`` (B, 4, 4) world, ``base_linear`` (B, 3) m/s and
    ``base_angular`` (B, 3) rad/s, world frame (None when no base is driven)."""
    joints: np.ndarray
    rates: np.ndarray
    base_pose: Optional[np.ndarray] = None
    base_linear: Optional[np.ndarray] = None
    base_angular: Optional[np.ndarray] = None


def _rotation_vector(R: np.ndarray) -> np.ndarray:
    """(3,) axis times angle (rad) of rotation matrix R."""
    w, x, y, z = matrix_to_quaternion(R)
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    s = math.sqrt(x * x + y * y + z * z)
    if s < 1e-12:
        return np.zeros(3)
    return np.array([x, y, z]) / s * 2.0 * math.atan2(s, w)


def rotation_error(R_target: np.ndarray, R_now: np.ndarray) -> np.ndarray:
    """(3,) rad, world frame: the rotation vector taking R_now to R_target."""
    return _rotation_vector(R_target @ R_now.T)


def _rotation(vector: np.ndarray) -> np.ndarray:
    angle = float(np.linalg.norm(vector))
    if angle < 1e-12:
        return np.eye(3)
    return axis_angle_matrix(vector / angle, angle)


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A timed path: waypoint ``times`` (n,) s from 0, ``waypoints`` (n, d), the ``profiles``
    of the n - 1 segments, and the free-flying bases' ``base_poses`` (n, B, 4, 4) or None."""
    times: np.ndarray
    waypoints: np.ndarray
    profiles: Tuple[Profile, ...]
    base_poses: Optional[np.ndarray] = None

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    @staticmethod
    def of(waypoints: np.ndarray, speeds: Sequence[float], accelerations: Sequence[float],
           base_poses: Optional[np.ndarray] = None,
           base_limits: Optional[BaseLimits] = None) -> "Trajectory":
        """Times ``waypoints`` (n, d) within per-joint ``speeds`` and ``accelerations`` (d,)
        (TIMING); ``base_poses`` (n, B, 4, 4), B free-flying bases, within ``base_limits``."""
        q = np.asarray(waypoints, dtype=float)
        v = np.asarray(speeds, dtype=float)
        a = np.asarray(accelerations, dtype=float)
        if q.ndim != 2 or len(q) == 0:
            raise ValueError("a trajectory needs at least one waypoint")
        if v.shape != (q.shape[1],) or a.shape != v.shape or np.any(v <= 0) or np.any(a <= 0):
            raise ValueError("one positive speed and acceleration per joint needed")
        if base_poses is not None and base_limits is None:
            raise ValueError("a moving base needs its limits")
        profiles, times = [], [0.0]
        for i in range(len(q) - 1):
            rate, acceleration = math.inf, math.inf
            for delta, speed, accel in zip(np.abs(q[i + 1] - q[i]), v, a):
                if delta > 0.0:
                    rate = min(rate, speed / delta)
                    acceleration = min(acceleration, accel / delta)
            for a_pose, b_pose in zip(*(() if base_poses is None else base_poses[i:i + 2])):
                distance = float(np.linalg.norm(b_pose[:3, 3] - a_pose[:3, 3]))
                angle = float(np.linalg.norm(rotation_error(b_pose[:3, :3], a_pose[:3, :3])))
                for delta, speed, accel in ((distance, base_limits.speed,
                                             base_limits.acceleration),
                                            (angle, base_limits.angular_speed,
                                             base_limits.angular_acceleration)):
                    if delta > 0.0:
                        rate = min(rate, speed / delta)
                        acceleration = min(acceleration, accel / delta)
            profile = Profile(0.0, 1.0, 0.0) if math.isinf(rate) else \
                Profile.fastest(rate, acceleration)
            profiles.append(profile)
            times.append(times[-1] + profile.duration)
        return Trajectory(np.array(times), q, tuple(profiles),
                          None if base_poses is None else np.asarray(base_poses, dtype=float))

    def segment(self, t: float) -> int:
        """The index of the segment running at time t (the last one after the end)."""
        if len(self.profiles) == 0:
            return 0
        return int(min(max(np.searchsorted(self.times, t, side="right") - 1, 0),
                       len(self.profiles) - 1))

    def sample(self, t: float) -> Sample:
        """The targets at time t s (the first waypoint before 0, the last after the end)."""
        if not self.profiles:
            return self._rest(0)
        if t >= self.duration:
            return self._rest(len(self.waypoints) - 1)
        i = self.segment(t)
        profile = self.profiles[i]
        if profile.duration <= 0.0:
            return self._rest(i + 1)
        s, rate = profile.at(t - self.times[i])
        delta = self.waypoints[i + 1] - self.waypoints[i]
        joints = self.waypoints[i] + s * delta
        if self.base_poses is None:
            return Sample(joints, rate * delta)
        poses, linear, angular = [], [], []
        for a, b in zip(self.base_poses[i], self.base_poses[i + 1]):
            turn = rotation_error(b[:3, :3], a[:3, :3])
            pose = np.eye(4)
            pose[:3, :3] = _rotation(s * turn) @ a[:3, :3]
            pose[:3, 3] = a[:3, 3] + s * (b[:3, 3] - a[:3, 3])
            poses.append(pose)
            linear.append(rate * (b[:3, 3] - a[:3, 3]))
            angular.append(rate * turn)
        return Sample(joints, rate * delta, np.array(poses), np.array(linear),
                      np.array(angular))

    def _rest(self, i: int) -> Sample:
        zeros = np.zeros(self.waypoints.shape[1])
        if self.base_poses is None:
            return Sample(self.waypoints[i].copy(), zeros)
        bases = len(self.base_poses[i])
        return Sample(self.waypoints[i].copy(), zeros, self.base_poses[i].copy(),
                      np.zeros((bases, 3)), np.zeros((bases, 3)))


__all__ = ["TIMING", "Profile", "BaseLimits", "Sample", "Trajectory", "rotation_error"]
