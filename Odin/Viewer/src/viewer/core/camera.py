"""A pinhole camera in the world frame (REP 103: z up) and its OpenGL matrices.

ROS-free and GL-free: the renderer loads these matrices, and tests use :meth:`Camera.project`
to compute where a point must appear in the image.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from viewer.errors import ViewerError

#: the direction (world frame) from the scene's centre towards a fitted camera's eye:
#: in front (+x), a little to the left (+y) and above (+z), looking back at the scene
FIT_DIRECTION_W = np.array([1.0, 0.55, 0.6]) / np.linalg.norm([1.0, 0.55, 0.6])
MIN_SIZE, MAX_SIZE = 16, 4096
#: rad, the narrowest vertical field of view: a camera fitted to the widest scene the Viewer
#: takes (geometry.MAX_EXTENT) stays at a finite distance (~1e15 m at the most extreme aspect)
MIN_FOV_Y = 1e-3


@dataclass(frozen=True)
class Camera:
    """eye_W, target_W: (3,) m, world frame; up_W: (3,) world frame, not parallel to the line
    of sight; fov_y: rad, vertical field of view; width, height: pixels."""
    eye_W: tuple = (3.0, 1.65, 1.8)
    target_W: tuple = (0.0, 0.0, 0.0)
    up_W: tuple = (0.0, 0.0, 1.0)
    fov_y: float = 0.8
    width: int = 640
    height: int = 480

    def __post_init__(self) -> None:
        for name in ("eye_W", "target_W", "up_W"):
            value = np.asarray(getattr(self, name), dtype=float).reshape(-1)
            if value.shape != (3,) or not np.all(np.isfinite(value)):
                raise ViewerError(f"camera {name[:-2]}: expected 3 finite numbers, got "
                                  f"{list(value)}")
            object.__setattr__(self, name, tuple(float(v) for v in value))
        sight = np.subtract(self.target_W, self.eye_W)
        if np.linalg.norm(sight) < 1e-9:
            raise ViewerError(f"camera target {self.target_W} equals eye {self.eye_W}")
        cross = np.linalg.norm(np.cross(sight / np.linalg.norm(sight), self.up_W))
        if np.linalg.norm(self.up_W) < 1e-9 or cross < 1e-6 * np.linalg.norm(self.up_W):
            raise ViewerError(f"camera up {self.up_W} is zero or parallel to the line of sight "
                              f"from {self.eye_W} to {self.target_W}")
        if not (math.isfinite(self.fov_y) and MIN_FOV_Y <= self.fov_y < math.pi):
            raise ViewerError(f"camera fov_y must be in [{MIN_FOV_Y:g}, pi) rad, got "
                              f"{self.fov_y}")
        for name in ("width", "height"):
            value = getattr(self, name)
            if int(value) != value or not MIN_SIZE <= value <= MAX_SIZE:
                raise ViewerError(f"image {name} must be an integer in {MIN_SIZE}..{MAX_SIZE} "
                                  f"pixels, got {value}")
            object.__setattr__(self, name, int(value))

    @property
    def aspect(self) -> float:
        return self.width / self.height

    def with_(self, **changes) -> "Camera":
        return replace(self, **changes)

    def view_matrix(self) -> np.ndarray:
        """(4, 4) world -> camera (OpenGL eye frame: x right, y up, looking along -z)."""
        eye = np.asarray(self.eye_W)
        forward = np.subtract(self.target_W, eye)
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, self.up_W)
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        M = np.eye(4)
        M[0, :3], M[1, :3], M[2, :3] = right, up, -forward
        M[:3, 3] = -M[:3, :3] @ eye
        return M

    def projection_matrix(self, near: float, far: float) -> np.ndarray:
        """(4, 4) OpenGL perspective projection (as gluPerspective)."""
        f = 1.0 / math.tan(self.fov_y / 2)
        P = np.zeros((4, 4))
        P[0, 0] = f / self.aspect
        P[1, 1] = f
        P[2, 2] = (far + near) / (near - far)
        P[2, 3] = 2 * far * near / (near - far)
        P[3, 2] = -1.0
        return P

    def project(self, points_W: Sequence) -> np.ndarray:
        """Pixel coordinates (n, 2) of points (n, 3) m world frame: column from the image's
        left edge, row from its top edge (pixel centres at .5). Points behind the camera get NaN."""
        pts = np.atleast_2d(np.asarray(points_W, dtype=float))
        eye = (self.view_matrix() @ np.c_[pts, np.ones(len(pts))].T).T
        depth = -eye[:, 2]
        f = 1.0 / math.tan(self.fov_y / 2)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_ndc = f / self.aspect * eye[:, 0] / depth
            y_ndc = f * eye[:, 1] / depth
        uv = np.c_[(x_ndc + 1) / 2 * self.width, (1 - y_ndc) / 2 * self.height]
        uv[depth <= 0] = np.nan
        return uv

    def fitted(self, centre_W: Sequence[float], radius: float) -> "Camera":
        """This camera moved to look at a sphere (centre m, radius m) from FIT_DIRECTION_W, the
        whole sphere in view; up is world z."""
        radius = max(float(radius), 1e-3)
        half_fov = min(self.fov_y, 2 * math.atan(math.tan(self.fov_y / 2) * self.aspect)) / 2
        distance = radius / math.sin(half_fov) * 1.05
        centre = np.asarray(centre_W, dtype=float)
        return replace(self, eye_W=tuple(centre + FIT_DIRECTION_W * distance),
                       target_W=tuple(centre), up_W=(0.0, 0.0, 1.0))
