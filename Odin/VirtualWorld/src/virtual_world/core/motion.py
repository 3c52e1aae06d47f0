"""A geometric planner's motion check in one C call, ROS-free: a ``MotionChecker`` is made once
for a scene's robots, from their kinematics over the control space (``RobotKinematics``), and
then asked, thousands of times a second, whether the straight segment between two control
vectors is collision-free (odin_motion.c: forward kinematics, clearances and exact checks in C,
so a planner's motion validator enters Python once per motion).

What a motion's validity guarantees is gui.planning.geometric_world's (its module docstring):
no link a control moves goes deeper than half the resolution into anything along a valid
motion. Which pairs may touch is the step's rule, as for a CollisionProbe (probe.py).

Every table is checked here (shapes, indices, finite values within the world's extent), and
the C walk checks every frame it computes before ODE sees it (within the extent, a rigid
transform): no table makes ODE end the process. A checker is bound to the objects the scene
held when it was made and refuses every call once any is removed or added.
"""
from __future__ import annotations

import math
from typing import NamedTuple, Optional, Sequence, Tuple

import numpy as np

from odin_common.limits import shown
from virtual_world.core.probe import _object_ids, _orthonormal, _tiers, pairs_that_may_touch
from virtual_world.core.scene import Scene
from virtual_world.errors import CoreError, InvalidArgument
from virtual_world.ode.queries import MotionQuery


class RobotKinematics(NamedTuple):
    """One robot over the control vector (odin_step.h's OdinKinematicRobot says each array's
    role; m, rad; poses (4, 4) in the world or the parent's frame). ``links``: the object ID
    of each link's body, parents before children; ``part``: (start, length) of the robot's
    slice of the control vector; ``base_box`` (3, 2) and ``base_rotation`` (3, 3) are None
    when the controls do not move the base."""
    links: Tuple[str, ...]
    part: Tuple[int, int]
    offset: np.ndarray          # (dofs,)
    matrix: np.ndarray          # (dofs, part length)
    dof_of_joint: np.ndarray    # (joints,) int
    joint_low: np.ndarray       # (joints,)
    joint_span: np.ndarray      # (joints,)
    joint_link: np.ndarray      # (joints,) int
    base_pose: np.ndarray       # (4, 4)
    base_box: Optional[np.ndarray]
    base_rotation: Optional[np.ndarray]
    base_turns: bool
    fixed_part: np.ndarray      # (links, 4, 4)
    first_part: np.ndarray      # (links, 4, 4)
    second_part: np.ndarray     # (links, 4, 4)
    rotational: np.ndarray      # (links,) bool
    parent: np.ndarray          # (links,) int, -1: the base
    offsets: np.ndarray         # (links, 4, 4)
    arms: np.ndarray            # (links, joints)
    reaches: np.ndarray         # (links,)
    capsules: np.ndarray        # (links, 7)
    boxes: np.ndarray           # (links, 15)
    boxed: np.ndarray           # (links,) bool
    moved: np.ndarray           # ascending link indices


class MotionChecker:
    """The robots' motions over ``size`` controls checked against ``scene`` (module
    docstring); ``tiers`` (m, descending): the clearances a link's is found among;
    ``sweep_gap`` (m): the growth a translating link's swept box must allow; ``resolution``
    (m): the largest motion of a link between two configurations checked exactly."""

    def __init__(self, scene: Scene, robots: Sequence[RobotKinematics], size: int,
                 tiers: Sequence[float], sweep_gap: float, resolution: float):
        extent = scene.parameters.world_extent
        size = _count("size", size, 1, 10_000)
        robots = [_robot(r, size, extent) for r in robots]
        if not robots:
            raise InvalidArgument("robots: at least one")
        ids = _object_ids("links", scene, [i for r in robots for i in r.links])
        moved_ids = [r.links[k] for r in robots for k in r.moved]
        records = [scene.object(i) for i in moved_ids]
        static = [r.id for r in records if r.body is None]
        if static:
            raise InvalidArgument(f"moved: {shown(static[0])} has no body to move")
        index = {object_id: n for n, object_id in enumerate(ids)}
        moved = set(moved_ids)
        pairs = [(index[a], index[b]) for a, b in pairs_that_may_touch(scene, ids)
                 if a in moved or b in moved]
        self._scene, self._revision, self.size = scene, scene.revision, size
        self._query = MotionQuery(
            scene.c.struct, size, [_arrays(r) for r in robots], [r.body.ptr for r in records],
            np.array([r.com for r in records], dtype=float).reshape(-1, 3),
            [g.owner.ptr for r in records for g in r.geometries],
            [g.owner.address for i in ids for g in scene.object(i).geometries],
            np.array(pairs, dtype=int).reshape(-1, 2), _tiers(tiers, extent),
            _positive("sweep_gap", sweep_gap, extent), _positive("resolution", resolution, extent))

    def motion_valid(self, scene: Scene, a, b, deadline: Optional[float] = None
                     ) -> Tuple[bool, int, int]:
        """(whether the straight segment from control vector ``a``, a valid configuration,
        to ``b`` is collision-free; configurations checked exactly; clearance queries).
        ``deadline`` (time.monotonic() s; None: none): past it the walk stops and answers
        False (a search's time limit holds on heavy meshes)."""
        self._same_scene(scene)
        try:
            limit = float(deadline) if deadline is not None and math.isfinite(deadline) \
                else 0.0
            answer, checks, clearances = self._query.motion_valid(a, b, limit)
        except (TypeError, ValueError):
            raise InvalidArgument(f"a, b: {self.size} finite controls each") from None
        return _answer(answer, "a configuration between a and b", scene), checks, clearances

    def valid(self, scene: Scene, controls) -> bool:
        """Whether no link a control moves touches anything at the control vector's
        configuration (the step's pairs; what the walk checks exactly)."""
        self._same_scene(scene)
        try:
            answer = self._query.configuration_valid(controls)
        except (TypeError, ValueError):
            raise InvalidArgument(f"controls: {self.size} finite controls") from None
        return _answer(answer, "the configuration", scene)

    def _same_scene(self, scene: Scene) -> None:
        if scene is not self._scene or scene.revision != self._revision:
            raise InvalidArgument("the world's objects changed since this motion checker was "
                                  "made: make a new one")


def _answer(answer: int, what: str, scene: Scene) -> bool:
    """odin_motion.c's answer: 1 or 0, else the error it stands for."""
    if answer == -3:
        raise InvalidArgument("a control is not finite")
    if answer == -1:
        raise InvalidArgument(f"{what} puts a link beyond the world's extent "
                              f"({scene.parameters.world_extent:g} m) or its frame is not a "
                              "rigid transform")
    if answer < 0:
        raise CoreError("out of memory checking a motion")
    return bool(answer)


def _count(what: str, value, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) \
            or not low <= value <= high:
        raise InvalidArgument(f"{what}={shown(value)}: an integer in [{low}, {high}]")
    return int(value)


def _positive(what: str, value, extent: float) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}={shown(value)}: not a number") from None
    if not 0.0 < value <= extent:
        raise InvalidArgument(f"{what}={shown(value)}: positive, within the world's extent")
    return value


def _table(what: str, values, shape: Tuple[int, ...], bound: float) -> np.ndarray:
    """A float array of ``shape``, every value finite and within ``bound``."""
    try:
        array = np.asarray(values, dtype=float).reshape(shape)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}: not an array of shape {shape}") from None
    if array.size and not float(np.max(np.abs(array))) <= bound:
        raise InvalidArgument(f"{what}: every value finite and within {bound:g}")
    return array


def _indices(what: str, values, count: int, high: int) -> np.ndarray:
    """``count`` ints in [-1, high) (or [0, high) when a -1 makes no sense to the caller)."""
    try:
        array = np.asarray(values).reshape(count)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}: not {count} indices") from None
    if array.size and (not np.issubdtype(array.dtype, np.integer)
                       or int(array.min()) < -1 or int(array.max()) >= high):
        raise InvalidArgument(f"{what}: indices below {high}")
    return array.astype(int)


def _robot(r, size: int, extent: float) -> RobotKinematics:
    """``r`` checked: shapes agree, indices in range, parents before children, values finite
    and within the world's extent (m) or, for DOF values, within [-extent, extent]."""
    if not isinstance(r, RobotKinematics):
        raise InvalidArgument(f"robots: {shown(r)} is not a RobotKinematics")
    links = tuple(r.links)
    n = len(links)
    start, length = (_count("part start", r.part[0], 0, size - 1),
                     _count("part length", r.part[1], 1, size))
    if start + length > size:
        raise InvalidArgument(f"part {r.part}: beyond the {size} controls")
    offset = _table("offset", r.offset, (-1,), extent)
    dofs = len(offset)
    joints = len(np.asarray(r.joint_low).reshape(-1))
    parent = _indices("parent", r.parent, n, n)
    if n == 0 or np.any(parent >= np.arange(n)):
        raise InvalidArgument("parent: at least one link, each after its parent")
    dof_of_joint = _indices("dof_of_joint", r.dof_of_joint, joints, dofs)
    joint_link = _indices("joint_link", r.joint_link, joints, n)
    moved = _indices("moved", r.moved, -1, n)
    if np.any(dof_of_joint < 0) or np.any(joint_link < 0) or np.any(moved < 0) \
            or np.any(np.diff(moved) <= 0):
        raise InvalidArgument("dof_of_joint, joint_link, moved: indices, moved ascending")
    base_box, base_rotation = r.base_box, r.base_rotation
    if (base_box is None) != (base_rotation is None) or (base_box is not None and dofs < 6):
        raise InvalidArgument("base_box and base_rotation: both or neither (then 6 DOFs)")
    capsules = _table("capsules", r.capsules, (n, 7), extent)
    boxes = _table("boxes", r.boxes, (n, 15), extent)
    if np.any(capsules[:, 6] < 0) or np.any(boxes[:, 12:] < 0):
        raise InvalidArgument("capsules, boxes: radii and half sides not negative")
    _orthonormal("boxes", boxes[:, 3:12].reshape(-1, 3, 3))     # ODE is shown them, turned
    arms = _table("arms", r.arms, (n, joints), extent)
    reaches = _table("reaches", r.reaches, (n,), extent)
    if np.any(arms < 0) or np.any(reaches < 0):
        raise InvalidArgument("arms, reaches: bounds of motion, not negative")
    return r._replace(
        links=links, part=(start, length), offset=offset,
        matrix=_table("matrix", r.matrix, (dofs, length), extent),
        dof_of_joint=dof_of_joint, joint_low=_table("joint_low", r.joint_low, (joints,), extent),
        joint_span=_table("joint_span", r.joint_span, (joints,), extent), joint_link=joint_link,
        base_pose=_table("base_pose", r.base_pose, (4, 4), extent),
        base_box=None if base_box is None else _table("base_box", base_box, (3, 2), extent),
        base_rotation=None if base_rotation is None else _table(
            "base_rotation", base_rotation, (3, 3), 1.0 + 1e-9),
        fixed_part=_table("fixed_part", r.fixed_part, (n, 4, 4), extent),
        first_part=_table("first_part", r.first_part, (n, 4, 4), extent),
        second_part=_table("second_part", r.second_part, (n, 4, 4), extent),
        rotational=np.asarray(r.rotational, dtype=bool).reshape(n), parent=parent,
        offsets=_table("offsets", r.offsets, (n, 4, 4), extent),
        arms=arms, reaches=reaches, capsules=capsules, boxes=boxes,
        boxed=np.asarray(r.boxed, dtype=bool).reshape(n), moved=moved)


def _arrays(r: RobotKinematics) -> dict:
    """The C struct's fields (virtual_world.ode.queries.ROBOT_ARRAYS, ROBOT_COUNTS)."""
    moves_base = r.base_box is not None
    return {
        "n_links": len(r.links), "n_joints": len(r.joint_low), "n_dofs": len(r.offset),
        "part_start": r.part[0], "part_len": r.part[1], "moves_base": int(moves_base),
        "base_turns": int(bool(r.base_turns) and moves_base), "n_moved": len(r.moved),
        "offset": r.offset, "matrix": r.matrix, "dof_of_joint": r.dof_of_joint,
        "joint_low": r.joint_low, "joint_span": r.joint_span, "joint_link": r.joint_link,
        "base_pose": r.base_pose,
        "base_box": np.zeros(6) if r.base_box is None else r.base_box,
        "base_rotation": np.eye(3) if r.base_rotation is None else r.base_rotation,
        "fixed_part": r.fixed_part, "first_part": r.first_part,
        "second_part": r.second_part, "rotational": r.rotational, "parent": r.parent,
        "offsets": r.offsets, "arms": r.arms, "reaches": r.reaches, "capsules": r.capsules,
        "boxes": r.boxes, "boxed": r.boxed, "moved": r.moved,
    }
