"""The loaded scene, ROS-free: robots and obstacles as kinematic trees of links with shapes.

Every value is SI (m, rad, kg) and every pose a (4, 4) array (see ``gui.core.kinematics``).

A link's frame in its parent's frame is ``pre @ motion(q) @ post``, where ``motion`` rotates
about (revolute) or slides along (prismatic) ``axis`` (a unit vector in the joint frame
``pre``) by the joint value q; a fixed link has q = 0. This covers both DH conventions and URDF:
- Standard DH (Rz(theta) Tz(d) Tx(a) Rx(alpha)): pre = PreTrans Rz(theta0) [Tz(d0) if
  prismatic], axis z, post = [Tz(d)] Tx(a) Rx(alpha);
- Modified DH (Rx(alpha) Tx(a) Rz(theta) Tz(d)): pre = PreTrans Rx(alpha) Tx(a) Rz(theta0)
  [Tz(d0) if prismatic], axis z, post = [Tz(d)];
- URDF: pre = the joint's origin, axis = the joint's axis, post = identity.
Kautham's joint value adds to the DH theta (or d) of the table (its "zero offset").

The Home configuration (the one a problem is built in) puts every joint at 0 clamped into its
limits, as Kautham's ``Link::setValue`` clamps.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np

from gui.core.kinematics import joint_motion
from gui.core.shapes import Shape

FIXED, REVOLUTE, PRISMATIC = "fixed", "revolute", "prismatic"


@dataclass(eq=False)
class LinkModel:
    """One rigid link. ``shape`` is in the link's frame (m)."""
    name: str
    parent: Optional[int]          # index of the parent link in ``RobotModel.links``; None: base
    pre: np.ndarray                # (4, 4) parent frame -> joint frame
    post: np.ndarray               # (4, 4) moved joint frame -> link frame
    joint: str = FIXED             # FIXED, REVOLUTE or PRISMATIC
    axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    limits: Optional[tuple] = None  # (low, high) rad or m; None: unlimited
    mass: Optional[float] = None   # kg; None: unknown (the build's default is used)
    shape: Optional[Shape] = None
    source: str = ""               # file that defined the link
    line: Optional[int] = None     # its line there

    @property
    def movable(self) -> bool:
        return self.joint != FIXED

    def home_value(self) -> float:
        if not self.movable or self.limits is None:
            return 0.0
        low, high = self.limits
        return float(min(max(0.0, low), high))


@dataclass(eq=False)
class ControlSet:
    """Kautham's controls: ``offset`` and ``controls`` map normalised parameters in [0, 1]
    to joint values: p_dof = offset_dof + sum_k value_{dof,k} (u_k - 0.5), then
    q = low + p (high - low) (Kautham's ``Robot::control2Pose``)."""
    offset: dict                      # dof name -> value
    controls: list                    # [(name, {dof name: value})]
    source: str = ""


@dataclass(eq=False)
class RobotModel:
    """A kinematic tree; links are listed parents first."""
    name: str
    links: list
    source: str
    kind: str = "rob"                # "rob" (DH), "urdf" or "shape" (a bare geometry file)
    dh_type: Optional[str] = None    # "Standard" or "Modified" for DH robots
    controls: Optional[ControlSet] = None

    def movable_links(self) -> list:
        return [i for i, link in enumerate(self.links) if link.movable]

    def home(self) -> np.ndarray:
        """Joint values of the movable links (``movable_links`` order) at Home."""
        return np.array([self.links[i].home_value() for i in self.movable_links()])

    def link_poses(self, base_pose: np.ndarray,
                   values: Optional[Sequence[float]] = None) -> list:
        """World poses (4, 4) of every link for the movable-joint ``values`` (Home when
        None)."""
        movable = self.movable_links()
        q = np.zeros(len(self.links))
        if values is None:
            values = self.home()
        values = np.asarray(values, dtype=float)
        if len(values) != len(movable):
            raise ValueError(f"{self.name} has {len(movable)} movable joints, "
                             f"got {len(values)} values")
        q[movable] = values
        poses = []
        for i, link in enumerate(self.links):
            parent = base_pose if link.parent is None else poses[link.parent]
            T = parent @ link.pre
            if link.movable:
                T = T @ joint_motion(link.axis, q[i], link.joint == REVOLUTE)
            poses.append(T @ link.post)
        return poses

    def joint_frames(self, base_pose: np.ndarray, values: Optional[Sequence[float]] = None
                     ) -> list:
        """World pose of each link's joint frame (``parent @ pre``) for ``values``: the
        joint's anchor is its origin, its axis ``R @ link.axis``."""
        poses = self.link_poses(base_pose, values)
        return [(base_pose if link.parent is None else poses[link.parent]) @ link.pre
                for link in self.links]


@dataclass(eq=False)
class Instance:
    """A robot or obstacle placed in the problem."""
    name: str
    role: str                        # "robot" or "obstacle"
    model: RobotModel
    base_pose: np.ndarray            # (4, 4) world pose of the base frame
    movable: bool = True             # obstacles: a body (True) or static geometry (False)
    collision: bool = True           # <Collision Enable="false"> gives False
    source: str = ""
    line: Optional[int] = None


@dataclass(eq=False)
class Problem:
    source: str
    format: str                      # "2012" or "current"
    instances: list

    @property
    def robots(self) -> list:
        return [i for i in self.instances if i.role == "robot"]

    @property
    def obstacles(self) -> list:
        return [i for i in self.instances if i.role == "obstacle"]
