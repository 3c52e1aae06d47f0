"""Kautham's controls: reading ``<ControlSet>`` (a .rob's, or a current ``.cntr`` file) and
mapping a control vector to a robot's configuration as Kautham does.

    <ControlSet> <Offset><DOF name value/>...</Offset>
                 <Control name eigValue><DOF name value/>...</Control>... </ControlSet>

DOF names are the robot's link names, and X, Y, Z (the base's position) and X1, X2, X3 (its
orientation); in ``.cntr`` files they are prefixed by the robot's name ("TX90/link_1"), in a
.rob bare ("Shoulder").

The mapping (Kautham's ``Robot::control2Parameters``, ``Robot::parameter2Pose``,
``Robot::deNormalizeSE3``, ``Link::parameter2Value``), for a control vector c in [0, 1]^k:

    p_dof = offset_dof + sum_k eigValue_k value_{dof,k} (c_k - 0.5)

with offset 0.5 for every DOF the file does not list (current Kautham's
``Problem::setRobotControls``), 0 in a 2012 robot's own ``<ControlSet>`` (Kautham 2012's
``Robot::Robot`` zeroes its offset matrix before reading ``<Offset>``); each p is then clamped
to [0, 1] (the controls are within bounds when no clamp was needed). Then, through the
robot's limits:

- a joint: q = low + p (high - low) (continuous joints: [-2 pi, 2 pi], Kautham's);
- the base, only when the control set names one of X..X3 for the robot (otherwise the base
  stays at Home): its position, in the Home frame, is low_H + p (high_H - low_H) per axis, the
  ``<Limits>`` box (world frame) taken into the Home frame corner by corner (an axis whose two
  corners agree maps to 0); its orientation is the unit quaternion of Kuffner's uniform
  sampling, x = sqrt(p_X1) sin(2 pi p_X2), y = sqrt(p_X1) cos(2 pi p_X2),
  z = sqrt(1 - p_X1) sin(pi p_X3), w = sqrt(1 - p_X1) cos(pi p_X3), also in the Home frame; the
  world pose is Home times that.
"""
from __future__ import annotations

import math
import pathlib
from dataclasses import dataclass
from typing import List, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from gui.core.kautham.xmlfile import Node, cut, read_xml
from gui.core.kinematics import translation
from gui.core.model import Configuration, Control, ControlSet, Instance
from gui.errors import ProblemError
from odin_common.rotations import quaternion_to_matrix

BASE_DOFS = ("X", "Y", "Z", "X1", "X2", "X3")
"""The base's DOFs in Kautham's order: position in the Home frame, then Kuffner's three."""
OFFSET_DEFAULT = 0.5
"""Kautham's offset of a DOF the control set does not list."""
LEGACY_OFFSET_DEFAULT = 0.0
"""Kautham 2012's offset of a DOF a .rob's own control set does not list."""
CONTINUOUS_LIMITS = (-2.0 * math.pi, 2.0 * math.pi)
"""rad: the range Kautham gives a URDF continuous joint."""
PAST_LIMIT_SLACK = 1e-9
"""How far past [0, 1] a DOF's normalised value may be and still count as within its limits
(``ControlMap.past_limits``): rounding of the mapping's sums, not a query's request."""


MAX_CONTROL_WEIGHT = 1e6
"""An offset, eigValue or DOF value of a control set, in size (Kautham's files: within 2).
A weight past it would only saturate the clamp of p to [0, 1], and weights near 1e308 make
their products infinite and p NaN (infinity times a control of 0.5 minus 0.5)."""


def _weight(node: Node, name: str, default: Optional[float] = None) -> float:
    """A control set's number, refused past MAX_CONTROL_WEIGHT."""
    value = node.number(name, default)
    if abs(value) > MAX_CONTROL_WEIGHT:
        raise node.error(f"<{node.tag} {name}=\"{cut(node.get(name))}\"> is beyond "
                         f"{MAX_CONTROL_WEIGHT:g} in size (MAX_CONTROL_WEIGHT)")
    return value


def parse_control_set(node: Node) -> ControlSet:
    offset = {}
    off = node.find("Offset")
    if off is not None:
        for dof in off.findall("DOF"):
            offset[dof.require("name").strip()] = _weight(dof, "value")
    controls = []
    for control in node.findall("Control"):
        values = {dof.require("name").strip(): _weight(dof, "value")
                  for dof in control.findall("DOF")}
        controls.append(Control(control.get("name", ""), _weight(control, "eigValue", 1.0),
                                values, control.line))
    return ControlSet(offset=offset, controls=controls, source=node.path, line=node.line)


def free_flyer_control_set() -> ControlSet:
    """The controls Kautham 2012 gives a robot that is a bare geometry file (``Robot::Robot``,
    libproblem/robot.cpp, the FREEFLY branch): one control per base DOF X, Y, Z, X1, X2, X3,
    in that order, each moving its DOF by 1 from the offset 0.5."""
    return ControlSet(offset={dof: 0.5 for dof in BASE_DOFS},
                      controls=[Control(dof, 1.0, {dof: 1.0}) for dof in BASE_DOFS],
                      source="(Kautham's free-flying robot controls)")


def read_cntr(path: pathlib.Path) -> ControlSet:
    root = read_xml(path, "control file")
    if root.tag != "ControlSet":
        raise root.error(f"expected a <ControlSet> element, found <{root.tag}>")
    return parse_control_set(root)


@dataclass(frozen=True, eq=False)
class ControlMap:
    """One robot's share of a control set: ``dofs`` (BASE_DOFS, then the robot's non-base
    links by name), ``offset`` (n_dofs,), ``matrix`` (n_dofs, k) with eigValue applied, and
    ``se3``: the set moves the base. ``names``: the k controls' names, the set's order."""
    robot: str
    names: Tuple[str, ...]
    dofs: Tuple[str, ...]
    offset: np.ndarray
    matrix: np.ndarray
    se3: bool
    source: str = ""

    @property
    def size(self) -> int:
        """k, the number of controls."""
        return len(self.names)

    def moved_base_axes(self) -> Tuple[int, ...]:
        """Indices 0..2 (X, Y, Z) of the base position DOFs some control moves."""
        return tuple(i for i in range(3) if np.any(self.matrix[i] != 0.0))

    def unclamped(self, controls: Sequence[float]) -> np.ndarray:
        """Normalised DOF values p (n_dofs,) for controls c (k,) before Kautham's clamp to
        [0, 1] (a value outside it asks for a DOF past its limits)."""
        c = np.asarray(controls, dtype=float)
        if c.shape != (self.size,):
            raise ValueError(f"{self.robot}: {self.size} controls expected, got {c.size}")
        return self.offset + self.matrix @ (c - 0.5)

    def parameters(self, controls: Sequence[float]) -> Tuple[np.ndarray, bool]:
        """Normalised DOF values p (n_dofs,) in [0, 1] for controls c (k,), and whether they
        were within bounds before clamping (Kautham's answer)."""
        p = self.unclamped(controls)
        within = bool(np.all((p >= 0.0) & (p <= 1.0)))
        return np.clip(p, 0.0, 1.0), within

    def past_limits(self, instance: Instance, controls: Sequence[float]) -> List["PastLimit"]:
        """The DOFs of ``instance`` (the robot this map is of) that controls c (k,) ask past
        their limits, which ``configuration`` clamps them into as Kautham does (the query's
        start or goal is then not the one written): its movable joints, and the base's DOFs
        when the set moves the base."""
        p = self.unclamped(controls)
        index = {name: i for i, name in enumerate(self.dofs)}
        model = instance.model
        past = []
        if self.se3:
            past.extend(PastLimit(dof, float(p[index[dof]])) for dof in BASE_DOFS
                        if _past(p[index[dof]]))
        for i, name in zip(model.movable_links(), model.joint_names()):
            link = model.links[i]
            value = p[index[link.name]]
            if _past(value):
                low, high = joint_limits(link)
                past.append(PastLimit(link.name, float(value), name,
                                      float(low + value * (high - low)),
                                      (float(low), float(high))))
        return past

    def configuration(self, instance: Instance, controls: Sequence[float]) -> Configuration:
        """The configuration controls c put ``instance`` in (module docstring)."""
        p, _ = self.parameters(controls)
        model = instance.model
        index = {name: i for i, name in enumerate(self.dofs)}
        joints = []
        for i in model.movable_links():
            link = model.links[i]
            low, high = joint_limits(link)
            joints.append(low + p[index[link.name]] * (high - low))
        base = instance.base_pose
        if self.se3:
            base = base_pose(instance.base_pose, instance.limits, p[:6])
        return Configuration(base, np.array(joints, dtype=float),
                             tuple(float(v) for v in controls))


class PastLimit(NamedTuple):
    """A DOF a control vector asks past its limits (``ControlMap.past_limits``): ``dof`` (a
    BASE_DOFS name or a link's), ``parameter`` (its normalised value before Kautham's clamp;
    [0, 1] is within the limits); for a joint, its ``joint`` name, the ``value`` asked (rad
    or m) and its ``limits`` (low, high; rad or m), None for a base DOF."""
    dof: str
    parameter: float
    joint: Optional[str] = None
    value: Optional[float] = None
    limits: Optional[Tuple[float, float]] = None


def _past(parameter: float) -> bool:
    return not -PAST_LIMIT_SLACK <= parameter <= 1.0 + PAST_LIMIT_SLACK


def joint_limits(link) -> Tuple[float, float]:
    """(low, high) the controls map a joint's [0, 1] onto (rad or m)."""
    if link.limits is not None:
        return link.limits
    if link.continuous or link.joint == "revolute":
        return CONTINUOUS_LIMITS
    raise ProblemError(f"joint \"{link.name}\" has no limits for the controls to map onto",
                       link.source, link.line)


def home_frame_limits(home: np.ndarray, limits: dict) -> np.ndarray:
    """(3, 2): the base's position limits in the Home frame, per axis (low, high), as
    Kautham's ``Robot::recalculateHomeLimits`` makes them (limits not given are 0)."""
    low_w = np.array([limits.get(a, (0.0, 0.0))[0] for a in "XYZ"], dtype=float)
    high_w = np.array([limits.get(a, (0.0, 0.0))[1] for a in "XYZ"], dtype=float)
    inverse = np.linalg.inv(home)
    low_h = inverse[:3, :3] @ low_w + inverse[:3, 3]
    high_h = inverse[:3, :3] @ high_w + inverse[:3, 3]
    out = np.stack([low_h, high_h], axis=1)
    out[low_h == high_h] = 0.0
    return out


def kuffner_quaternion(p1: float, p2: float, p3: float) -> Tuple[float, float, float, float]:
    """(w, x, y, z) of Kautham's ``SE3Conf::setCoordinates`` from three values in [0, 1]."""
    r1, r2 = math.sqrt(p1), math.sqrt(1.0 - p1)
    theta1, theta2 = 2.0 * math.pi * p2, math.pi * p3
    return (math.cos(theta2) * r2, math.sin(theta1) * r1, math.cos(theta1) * r1,
            math.sin(theta2) * r2)


def base_pose(home: np.ndarray, limits: dict, p: Sequence[float]) -> np.ndarray:
    """World pose (4, 4) of the base for its six normalised DOFs (X, Y, Z, X1, X2, X3)."""
    box = home_frame_limits(home, limits)
    position = box[:, 0] + np.asarray(p[:3], dtype=float) * (box[:, 1] - box[:, 0])
    local = translation(*position)
    local[:3, :3] = quaternion_to_matrix(kuffner_quaternion(*p[3:6]))
    return home @ local


def control_map(instance: Instance, control_set: ControlSet, prefixed: bool,
                robots: Optional[Sequence[Instance]] = None,
                offset_default: float = OFFSET_DEFAULT) -> Optional[ControlMap]:
    """``instance``'s share of ``control_set`` (None when no DOF of the set is the robot's).
    ``offset_default``: the offset of a DOF the set does not list (module docstring).

    ``prefixed``: DOF names are "robot/dof" (a .cntr file; "robot" is an instance's name or
    its model's, and one that is no robot of ``robots`` is an error, as in Kautham), else bare
    (a .rob's own set). A DOF name that is neither a base DOF nor a link of the robot is an
    error naming the file and line."""
    model = instance.model
    links = [link.name for link in model.links[1:]]
    dofs = BASE_DOFS + tuple(links)
    index = {name: i for i, name in enumerate(dofs)}
    offset = np.full(len(dofs), offset_default)
    matrix = np.zeros((len(dofs), len(control_set.controls)))
    mine = False
    se3 = False

    def own(name: str, line: Optional[int]) -> Optional[int]:
        nonlocal mine, se3
        if prefixed:
            robot, slash, dof = name.rpartition("/")
            if not slash:
                raise ProblemError(f"DOF name \"{name}\" is not \"robot/dof\"",
                                   control_set.source, line)
            if robots is not None and all(robot not in (r.name, r.model.name)
                                          for r in robots):
                # listed by instance name, once each: the names a path's --robot takes
                raise ProblemError(f"DOF \"{name}\": no robot named \"{robot}\" in the "
                                   f"problem (robots: {', '.join(r.name for r in robots)})",
                                   control_set.source, line)
            if robot != model.name and robot != instance.name:
                return None
        else:
            dof = name
        if dof not in index:
            raise ProblemError(f"DOF \"{name}\" is neither a base DOF ({', '.join(BASE_DOFS)}) "
                               f"nor a link of robot \"{instance.name}\"", control_set.source,
                               line)
        mine = True
        se3 = se3 or dof in BASE_DOFS
        return index[dof]

    for name, value in control_set.offset.items():
        k = own(name, control_set.line)
        if k is not None:
            offset[k] = value
    for column, control in enumerate(control_set.controls):
        for name, value in control.dofs.items():
            k = own(name, control.line)
            if k is not None:
                matrix[k, column] = control.eig_value * value
    if not mine:
        return None
    return ControlMap(instance.name, tuple(c.name for c in control_set.controls), dofs,
                      offset, matrix, se3, control_set.source)


def control_parts(robots: Sequence[Instance], legacy: bool) -> List[Tuple[Instance, slice]]:
    """Each of ``robots`` that has controls, with its slice of one control vector for all of
    them (a query's ``<Init>``/``<Goal>``, a ``.kps`` sample, a control path's row), in robot
    order. A current problem's robots share one control set (its .cntr), so each maps the
    whole vector; a 2012 problem's (``legacy``) each have their own (their .rob's) and take
    the next ``size`` values end to end (Kautham 2012's ``WorkSpace::moveRobotsTo``). The
    vector's length is the largest slice's end."""
    parts, end = [], 0
    for robot in robots:
        if robot.controls is None:
            continue
        size = robot.controls.size
        parts.append((robot, slice(end, end + size) if legacy else slice(0, size)))
        end += size if legacy else 0
    return parts


__all__ = ["BASE_DOFS", "OFFSET_DEFAULT", "LEGACY_OFFSET_DEFAULT", "CONTINUOUS_LIMITS",
           "PAST_LIMIT_SLACK", "parse_control_set", "free_flyer_control_set", "read_cntr",
           "ControlMap", "PastLimit",
           "joint_limits", "home_frame_limits", "kuffner_quaternion", "base_pose", "control_map",
           "control_parts"]
