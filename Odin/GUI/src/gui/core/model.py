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

The Home configuration puts every joint at 0 clamped into its limits, as Kautham's
``Link::setValue`` clamps. A problem is built at its start (``Instance.start``: the query's
``<Init>`` mapped through the controls, Kautham's start) where it has one, at Home otherwise.

These records are what other tools read a robot from (the robot_description generator among
them): per link its name, parent, joint (name, type, axis, limits, effort and speed limits,
damping and friction), mass properties, shape and contact surface. Nothing here is in file
units: lengths are m, angles rad, masses kg.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np

from gui.core.geometry import Shape
from gui.core.kinematics import joint_motion
from odin_common.specs import WORLD_SURFACE, Surface

FIXED, REVOLUTE, PRISMATIC = "fixed", "revolute", "prismatic"


@dataclass(frozen=True, eq=False)
class Inertial:
    """A link's mass properties as its file gives them (URDF ``<inertial>``): ``mass`` kg;
    ``origin`` (4, 4) the centre of mass frame in the link frame; ``tensor`` (3, 3) kg m^2,
    the inertia about the centre of mass in the axes of ``origin`` (None: the file gives no
    tensor, or an all-zero one)."""
    mass: float
    origin: np.ndarray
    tensor: Optional[np.ndarray] = None


@dataclass(eq=False)
class LinkModel:
    """One rigid link and the joint that moves it relative to its parent. ``shape`` is in the
    link's frame (m).

    ``joint_name`` names that joint as the file does (URDF: the ``<joint name>``; .rob: the
    link's name, which Kautham's controls use). ``continuous``: a URDF joint without limits.
    ``effort``: the joint's force limit (N m, or N for a prismatic joint; None: none given);
    ``velocity``: its speed limit (rad/s or m/s; None: none given); ``damping`` (N m s/rad or
    N s/m) and ``friction`` (N m or N): URDF ``<dynamics>``. ``inertial``: the file's mass
    properties (None: none given); ``mass`` is its mass, or the .rob's, or None. ``surface``:
    the link's contact coefficients (URDF ``<contact_coefficients>``), the world's when unset.
    ``planner_weight``: a .rob ``<Weight>``, a weight Kautham's planners give the joint in
    distances (not a mass)."""
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
    joint_name: str = ""
    continuous: bool = False
    effort: Optional[float] = None
    velocity: Optional[float] = None
    damping: float = 0.0
    friction: float = 0.0
    inertial: Optional[Inertial] = None
    surface: Surface = WORLD_SURFACE
    planner_weight: Optional[float] = None

    @property
    def movable(self) -> bool:
        return self.joint != FIXED

    def home_value(self) -> float:
        if not self.movable or self.limits is None:
            return 0.0
        low, high = self.limits
        return float(min(max(0.0, low), high))


@dataclass(frozen=True)
class Control:
    """One ``<Control name eigValue>`` of a control set: how much each DOF moves per unit of
    this control, ``dofs`` {DOF name as the file writes it: value} (eigValue not applied)."""
    name: str
    eig_value: float
    dofs: dict
    line: Optional[int] = None


@dataclass(eq=False)
class ControlSet:
    """Kautham's controls as a file writes them (a .cntr, or a .rob's ``<ControlSet>``):
    ``offset`` {DOF name: value} and ``controls`` in file order. DOF names are "robot/dof" in
    .cntr files, bare in a .rob. ``gui.core.kautham.controls.ControlMap`` turns a set into one
    robot's mapping: p_dof = offset_dof + sum_k eig_k value_{dof,k} (c_k - 0.5), then the
    robot's limits (Kautham's ``Robot::control2Parameters`` and ``parameter2Pose``)."""
    offset: dict
    controls: list                    # [Control]
    source: str = ""
    line: Optional[int] = None


@dataclass(frozen=True, eq=False)
class Configuration:
    """Where a robot is: ``base_pose`` (4, 4) world pose of its base frame and ``joints`` the
    values of its movable joints (rad or m, ``RobotModel.movable_links()`` order).
    ``controls``: the control values it came from (Kautham's sample, in [0, 1]), if any."""
    base_pose: np.ndarray
    joints: np.ndarray
    controls: Optional[tuple] = None


@dataclass(eq=False)
class RobotModel:
    """A kinematic tree; links are listed parents first (``links[0]`` is the base). A .rob
    ``<ControlSet>`` is kept in ``controls``. ``ignored``: what its files hold that Odin does
    not use (``Ignored``)."""
    name: str
    links: list
    source: str
    kind: str = "rob"                # "rob" (DH), "urdf" or "shape" (a bare geometry file)
    dh_type: Optional[str] = None    # "Standard" or "Modified" for DH robots
    controls: Optional[ControlSet] = None
    ignored: list = field(default_factory=list)
    free_base: bool = False          # the file declares a free-flying base (.rob Freeflying)

    def movable_links(self) -> list:
        return [i for i, link in enumerate(self.links) if link.movable]

    def joint_names(self) -> list:
        """The names of the movable joints (``movable_links()`` order)."""
        return [self.links[i].joint_name or self.links[i].name for i in self.movable_links()]

    def children(self, index: int) -> list:
        """Indices of the links whose parent is link ``index``."""
        return [i for i, link in enumerate(self.links) if link.parent == index]

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


@dataclass(frozen=True)
class Ignored:
    """Something a problem (or a file it references) holds that Odin does not use: ``what``
    (the element or value), ``why``, and where (``source`` file, ``line``)."""
    source: str
    line: Optional[int]
    what: str
    why: str

    def describe(self) -> dict:
        return dict(file=self.source, line=self.line, what=self.what, why=self.why)

    def __str__(self) -> str:
        where = f"{self.source}:{self.line}" if self.line else self.source
        return f"{where}: {self.what}: {self.why}"


def warn_once(ignored, logger_name: str = "gui.core") -> None:
    """Logs each Ignored entry as a warning, once per (file, what) in the list."""
    log = logging.getLogger(logger_name)
    seen = set()
    for item in ignored:
        key = (item.source, item.what)
        if key not in seen:
            seen.add(key)
            log.warning("not used: %s", item)


# Robot kinds: how the world builds and drives a robot (Kautham's ODE environments)
FIXED_BASE = "fixed base"            # a chain or tree whose base is held (a manipulator)
FREE_BODY = "free body"              # one free link (Kautham's 2D/free-flying robots)
MOBILE = "mobile"                    # a free base with joints (the controls move the base)
CAR = "car"                          # a base on wheels, each on a hinge-2 (CarEnvironment)


@dataclass(eq=False)
class Instance:
    """A robot or obstacle placed in the problem.

    ``base_pose``: the base frame at Home. ``limits``: the base's position limits, world frame,
    {"X" | "Y" | "Z": (min, max) m} (Kautham's ``<Limits>``). ``kind``: a robot's kind
    (FIXED_BASE, FREE_BODY, MOBILE, CAR; "" for obstacles). ``controls``: the robot's control
    mapping (``gui.core.kautham.controls.ControlMap``) or None. ``start`` / ``goal``: the
    query's configurations (None: no query); a robot is built at ``start``."""
    name: str
    role: str                        # "robot" or "obstacle"
    model: RobotModel
    base_pose: np.ndarray            # (4, 4) world pose of the base frame
    movable: bool = True             # obstacles: a body (True) or static geometry (False)
    collision: bool = True           # <Collision enabled|Enable="false"> gives False
    source: str = ""
    line: Optional[int] = None
    limits: dict = field(default_factory=dict)
    kind: str = ""
    controls: Optional[object] = None
    start: Optional[Configuration] = None
    goal: Optional[Configuration] = None


@dataclass(frozen=True)
class Attachment:
    """``<InitialAttachedObstacle robot link obstacle>``: the obstacle rides on the link
    (instance names)."""
    robot: str
    link: str
    obstacle: str
    source: str = ""
    line: Optional[int] = None


@dataclass(frozen=True)
class PlannerPhysics:
    """What a Kautham ODE planner's parameters ask of the simulation (None: not given): ``erp``
    and ``cfm`` ("Error Reduction Parameter", "Constraint Force Mixing": Kautham gives them to
    every contact), ``max_contacts`` ("Max Contacts": contact points per pair) and ``step``
    ("PropagationStepSize", s: ODE's step in Kautham's propagation)."""
    erp: Optional[float] = None
    cfm: Optional[float] = None
    max_contacts: Optional[int] = None
    step: Optional[float] = None


@dataclass(frozen=True)
class PlannerSearch:
    """What a Kautham ODE planner's parameters ask of a search (None: not given; the planning
    bridge, gui.planning, uses them): ``min_control_steps`` / ``max_control_steps`` ("Min/Max
    Control Steps": how many propagation steps a control is held), ``goal_bias`` ("Goal
    Bias"), ``max_speed`` ("Max Speed", m/s) and ``time_limit`` ("_Max Planning Time", s)."""
    min_control_steps: Optional[int] = None
    max_control_steps: Optional[int] = None
    goal_bias: Optional[float] = None
    max_speed: Optional[float] = None
    time_limit: Optional[float] = None


@dataclass(frozen=True)
class Planner:
    """The problem's ``<Planner>``: its ``name``; ``physics``: one of Kautham's ODE planners,
    which simulate the problem (a ground plane, dynamic obstacles: ``Problem.physics``);
    ``settings``: the physics its parameters ask for; ``search``: what they ask of a
    planner's search; ``geometric``: a geometric planner's parameters Odin uses, (field,
    value) pairs (gui.core.kautham.problem.PLANNER_GEOMETRIC; gui.planning.geometric)."""
    name: str
    physics: bool
    settings: PlannerPhysics = PlannerPhysics()
    search: PlannerSearch = PlannerSearch()
    geometric: tuple = ()
    source: str = ""
    line: Optional[int] = None


@dataclass(eq=False)
class Problem:
    """A loaded problem: every robot and obstacle (``instances``), its planner (or None), the
    obstacles attached to robot links, and what Odin does not use (``ignored``, each warned
    about once when loaded)."""
    source: str
    format: str                      # "2012" or "current"
    instances: list
    planner: Optional[Planner] = None
    attachments: list = field(default_factory=list)
    ignored: list = field(default_factory=list)

    @property
    def physics(self) -> bool:
        """Kautham simulates this problem with ODE (one of its physics planners)."""
        return self.planner is not None and self.planner.physics

    @property
    def robots(self) -> list:
        return [i for i in self.instances if i.role == "robot"]

    @property
    def obstacles(self) -> list:
        return [i for i in self.instances if i.role == "obstacle"]
