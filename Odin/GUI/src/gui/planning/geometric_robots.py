"""The robots of a geometric search (gui.planning.geometric) and the bounds its motion checks
rest on (ROS-free).

A ``PlannedRobot`` is one robot with controls: its slice of the control vector, the
configuration a control vector puts it in, its links' world poses, and

* how far a change of configuration moves any point of each link (``link_bounds``): along a
  straight segment of the control space each joint value changes monotonically (linear, then
  clamped to its limits), so no point of link i moves farther than ``sum_j |delta q_j| a_ij``
  (``a_ij``: for a revolute joint j at or above link i, a bound of the distance from j's axis
  to any point of link i; for a prismatic one, 1), plus, for a base the controls move, its
  translation and its turn's angle times link i's reach from the base's origin (the angle
  between the two ends' orientations: a turn the controls make along a straight segment is
  taken to be no longer than that);
* a capsule bounding each link's geometry (``capsules``, in its object's frame): a segment
  along the geometry's principal axis and the least radius that holds every vertex (a mesh's;
  a box's corners; the corners of a cylinder's, a sphere's or a capsule's bounding box), so it
  holds the convex hull of them, and so the whole geometry; and a box (``boxes``), the
  smaller of the one along the object's axes and the one along the points' principal axes.

``kinematics`` hands all of it to the Core's motion checker (virtual_world.core.motion), which
walks whole motions in C with the same arithmetic.
"""
from __future__ import annotations

import math
from typing import Dict, List, Sequence, Tuple

import numpy as np

from gui.core.kautham.controls import home_frame_limits, joint_limits, kuffner_quaternion
from gui.core.model import PRISMATIC, REVOLUTE
from gui.core.plan import BuildPlan
from gui.errors import PlanningError
from odin_common.rotations import quaternion_to_matrix
from virtual_world.core.motion import RobotKinematics


ROTATION_PER_UNIT = math.pi / 2
"""rad: the turn charged per unit of one of a base's three orientation DOFs (Kautham's
quaternion parameters): OMPL's SO(3) distance spans [0, pi/2]."""


class PlannedRobot:
    """One robot of the plan (``handle``: its gui.core.plan robot handle) and its slice
    ``part`` of the control vector. ``moved``: the indices (of ``handle.bodies``, one per
    link) of the links a control moves; ``moved_bodies``: their body IDs."""

    def __init__(self, handle, part: slice, specs: Dict[str, object]):
        self.handle = handle
        self.part = part
        model = handle.instance.model
        self.links = model.links
        self.movable = model.movable_links()
        self.moves_base = bool(handle.instance.controls.se3)
        radii = _body_radii(handle, specs)
        self.arms = _arm_matrix(model, self.movable, radii)       # (links, movable) m or 1
        self.reaches = np.array([_chain_length(model, 0, i) + _offset_length(model.links[0])
                                 + radii[i] for i in range(len(self.links))])
        moved = set(self.movable)
        for i, link in enumerate(self.links):         # a child of a moved link moves too
            if link.parent in moved:
                moved.add(i)
        if self.moves_base:
            moved = set(range(len(self.links)))
        self.moved = sorted(moved)
        self.moved_bodies = {handle.bodies[i].body_id for i in moved}
        self.capsules = np.array([_capsule(specs[body.body_id]) for body in handle.bodies])
        self.boxes = np.array([_box(specs[body.body_id]) for body in handle.bodies])
        self.boxed = np.array([_box_volume(b) < _capsule_volume(c)
                               for b, c in zip(self.boxes, self.capsules)])
        self._offsets = np.array([body.offset for body in handle.bodies])
        self._chain()
        self._map_controls()

    def _map_controls(self) -> None:
        """What ``configuration`` computes with, taken once from the robot's controls
        (gui.core.kautham.controls.ControlMap.configuration, whose values it gives)."""
        instance = self.handle.instance
        controls = instance.controls
        index = {name: i for i, name in enumerate(controls.dofs)}
        limits = [joint_limits(self.links[i]) for i in self.movable]
        self._dof_of_joint = np.array([index[self.links[i].name] for i in self.movable], int)
        self._joint_low = np.array([low for low, _ in limits], dtype=float)
        self._joint_span = np.array([high - low for low, high in limits], dtype=float)
        self._base_box = home_frame_limits(instance.base_pose, instance.limits) \
            if self.moves_base else None
        # a base the controls move but never turn (an R2 or R3 robot): its orientation once
        self._base_turns = bool(np.any(controls.matrix[3:6] != 0.0))
        p = np.clip(controls.offset, 0.0, 1.0)
        self._base_rotation = instance.base_pose[:3, :3] @ quaternion_to_matrix(
            kuffner_quaternion(*p[3:6]))

    def kinematics(self, size: int) -> RobotKinematics:
        """The tables the Core's motion checker computes with (virtual_world.core.motion):
        this robot's controls, chain, bounds and capsules as ``configuration``,
        ``object_frames`` and ``link_bounds`` use them; ``size``: the control vector's."""
        controls = self.handle.instance.controls
        start = self.part.start or 0
        stop = size if self.part.stop is None else self.part.stop
        return RobotKinematics(
            links=tuple(body.body_id for body in self.handle.bodies), part=(start, stop - start),
            offset=controls.offset, matrix=controls.matrix, dof_of_joint=self._dof_of_joint,
            joint_low=self._joint_low, joint_span=self._joint_span,
            joint_link=np.array(self.movable, dtype=int),
            base_pose=self.handle.instance.base_pose,
            base_box=self._base_box if self.moves_base else None,
            base_rotation=self._base_rotation if self.moves_base else None,
            base_turns=self._base_turns, fixed_part=self._fixed_part,
            first_part=self._first_part, second_part=self._second_part,
            rotational=self._rotational,
            parent=np.array([-1 if p is None else p for p in self._parents], dtype=int),
            offsets=self._offsets, arms=self.arms, reaches=self.reaches,
            capsules=self.capsules, boxes=self.boxes, boxed=self.boxed,
            moved=np.array(self.moved, dtype=int))

    def squared_control_lengths(self, size: int) -> np.ndarray:
        """(size,): per control of the vector, the square of how far a unit of it moves this
        robot in Kautham's OMPL metric (control_scales)."""
        matrix = self.handle.instance.controls.matrix
        squares = np.zeros(size)
        columns = np.arange(size)[self.part]
        squares[columns] += np.sum((matrix[self._dof_of_joint]
                                    * self._joint_span[:, None]) ** 2, axis=0)
        if self.moves_base:
            sides = self._base_box[:, 1] - self._base_box[:, 0]
            squares[columns] += np.sum((matrix[:3] * sides[:, None]) ** 2, axis=0)
            squares[columns] += np.sum((matrix[3:6] * ROTATION_PER_UNIT) ** 2, axis=0)
        return squares

    def control_equations(self, base_pose, joints, size: int) -> Tuple[np.ndarray, np.ndarray]:
        """(A (m, size), b (m,)): the linear equations ``A c = b`` a control vector c meets
        when ``configuration(c)`` is (``base_pose`` (4, 4) world, ``joints`` rad or m of the
        movable links), unclamped: a row per joint and, for a base the controls move, per
        coordinate of its position. PlanningError for a base the controls turn (its
        orientation is not linear in them)."""
        matrix = self.handle.instance.controls.matrix
        offset = self.handle.instance.controls.offset
        columns = np.arange(size)[self.part]
        span = self._joint_span[:, None]
        rows = [(span * matrix[self._dof_of_joint],
                 np.asarray(joints, dtype=float) - self._joint_low
                 - self._joint_span * (offset[self._dof_of_joint]
                                       - 0.5 * matrix[self._dof_of_joint].sum(axis=1)))]
        if self.moves_base:
            if self._base_turns:
                raise PlanningError(f"robot {self.handle.name}: a path that turns its base is "
                                    "not read as controls")
            home = self.handle.instance.base_pose
            local = home[:3, :3].T @ (np.asarray(base_pose, dtype=float)[:3, 3] - home[:3, 3])
            box = self._base_box
            sides = (box[:, 1] - box[:, 0])[:, None]
            rows.append((sides * matrix[:3], local - box[:, 0] - sides[:, 0]
                         * (offset[:3] - 0.5 * matrix[:3].sum(axis=1))))
        a = np.zeros((sum(len(r) for r, _ in rows), size))
        a[:, columns] = np.vstack([r for r, _ in rows])
        return a, np.concatenate([b for _, b in rows])

    def configuration(self, controls: np.ndarray):
        """(base pose (4, 4), joint values) the control vector puts this robot in."""
        instance = self.handle.instance
        c = np.asarray(controls, dtype=float)[self.part]
        p = np.minimum(np.maximum(
            instance.controls.offset + instance.controls.matrix @ (c - 0.5), 0.0), 1.0)
        joints = self._joint_low + p[self._dof_of_joint] * self._joint_span
        if not self.moves_base:
            return instance.base_pose, joints
        box = self._base_box
        position = box[:, 0] + p[:3] * (box[:, 1] - box[:, 0])
        if self._base_turns:
            local = np.eye(4)
            local[:3, 3] = position
            local[:3, :3] = quaternion_to_matrix(kuffner_quaternion(*p[3:6]))
            return instance.base_pose @ local, joints
        base = np.empty((4, 4))
        base[:3, :3] = self._base_rotation
        base[:3, 3] = instance.base_pose[:3, :3] @ position + instance.base_pose[:3, 3]
        base[3] = (0.0, 0.0, 0.0, 1.0)
        return base, joints

    def _chain(self) -> None:
        """Each link's motion from its parent's frame as A + v1 B + v2 C (4, 4 each), with
        (v1, v2) = (sin q, 1 - cos q) for a revolute joint (Rodrigues' formula between its
        ``pre`` and ``post``), (q, 0) for a prismatic one, (0, 0) for a fixed one: what
        gui.core.model's link_poses multiplies, in one array expression."""
        count = len(self.links)
        self._fixed_part = np.empty((count, 4, 4))
        self._first_part = np.zeros((count, 4, 4))
        self._second_part = np.zeros((count, 4, 4))
        self._rotational = np.zeros(count, dtype=bool)
        for i, link in enumerate(self.links):
            self._fixed_part[i] = link.pre @ link.post
            if not link.movable:
                continue
            axis = np.asarray(link.axis, dtype=float)
            first = np.zeros((4, 4))
            if link.joint == REVOLUTE:
                self._rotational[i] = True
                x, y, z = axis / np.linalg.norm(axis)
                first[:3, :3] = [[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]]
                self._second_part[i] = link.pre @ (first @ first) @ link.post
            else:
                first[:3, 3] = axis
            self._first_part[i] = link.pre @ first @ link.post
        self._parents = [link.parent for link in self.links]

    def object_frames(self, configuration) -> np.ndarray:
        """(links, 4, 4): the world pose of each body's object frame at ``configuration``
        (gui.core.model's link_poses, then each body's offset)."""
        base, joints = configuration
        q = np.zeros(len(self.links))
        q[self.movable] = joints
        first = np.where(self._rotational, np.sin(q), q)
        second = np.where(self._rotational, 1.0 - np.cos(q), 0.0)
        local = self._fixed_part + first[:, None, None] * self._first_part \
            + second[:, None, None] * self._second_part
        frames = np.empty_like(local)
        for i, parent in enumerate(self._parents):
            frames[i] = (base if parent is None else frames[parent]) @ local[i]
        return frames @ self._offsets

    def poses(self, configuration) -> list:
        """(body ID, position m, quaternion wxyz) of every link at ``configuration``."""
        base, joints = configuration
        return self.handle.situations(joints, base)

    def link_bounds(self, a, b) -> np.ndarray:
        """(links,) m: no point of each link moves farther than this along the straight
        segment of the control space from configuration ``a`` to ``b`` (module docstring)."""
        (base_a, q_a), (base_b, q_b) = a, b
        bounds = self.arms @ np.abs(np.asarray(q_b) - np.asarray(q_a)) if len(self.movable) \
            else np.zeros(len(self.links))
        if self.moves_base:
            bounds = bounds + float(np.linalg.norm(base_b[:3, 3] - base_a[:3, 3]))
            bounds = bounds + _angle(base_a[:3, :3], base_b[:3, :3]) * self.reaches
        return bounds

def _arm_matrix(model, movable: Sequence[int], radii: Sequence[float]) -> np.ndarray:
    """(links, movable): a_ij of the module docstring, 0 where joint j does not move link i."""
    arms = np.zeros((len(model.links), len(movable)))
    for column, j in enumerate(movable):
        for i in _descendants(model, j):
            prismatic = model.links[j].joint == PRISMATIC
            arms[i, column] = 1.0 if prismatic else _chain_length(model, j, i) + radii[i]
    return arms


def _body_radii(handle, specs: Dict[str, object]) -> List[float]:
    """Per link, m: the largest distance from the link frame's origin to any point of its
    body's geometry (``specs``: the plan's body specs by ID)."""
    return [float(np.linalg.norm(body.offset[:3, 3]))
            + float(np.max(np.linalg.norm(_spec_points(specs[body.body_id]), axis=1)))
            for body in handle.bodies]


def _spec_points(spec) -> np.ndarray:
    """(n, 3) m, the object's frame: points whose convex hull holds the body's geometry."""
    parts = getattr(spec, "parts", None)
    if parts is None:
        return _shape_points(spec)
    return np.vstack([_shape_points(p) @ quaternion_to_matrix(p.orientation).T
                      + np.asarray(p.position, dtype=float) for p in parts])


def _shape_points(shape) -> np.ndarray:
    """(n, 3) m, the shape's frame: its vertices, or its bounding box's corners."""
    from odin_common.interface import Shape, shape_of
    values = np.asarray(shape.parameters, dtype=float)
    kind = shape_of(len(values), shape.shape)
    if kind == Shape.MESH and values.size:
        return values.reshape(-1, 3)
    if kind == Shape.BOX:
        half = values[:3] / 2
    elif kind == Shape.SPHERE:
        half = np.full(3, values[0])
    elif kind == Shape.CYLINDER:
        half = np.array([values[0], values[0], values[1] / 2])
    elif kind == Shape.CAPSULE:
        half = np.array([values[0], values[0], values[1] / 2 + values[0]])
    else:
        raise PlanningError(f"a robot's link of shape {kind!r} cannot be bounded")
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    return signs * half


def _capsule(spec) -> np.ndarray:
    """(7,): end a, end b (m, the object's frame), radius (m) of a capsule holding the body's
    geometry (module docstring)."""
    points = _spec_points(spec)
    centre = points.mean(axis=0)
    offsets = points - centre
    axis = np.linalg.svd(offsets, full_matrices=False)[2][0] if len(points) > 1 \
        else np.array([0.0, 0.0, 1.0])
    along = offsets @ axis
    across = np.linalg.norm(offsets - np.outer(along, axis), axis=1)
    radius = float(np.max(across))
    # the shortest segment that comes within the radius of every point: a point is when the
    # segment meets its window [along - room, along + room] of the axis
    room = np.sqrt(np.maximum(radius ** 2 - across ** 2, 0.0))
    low, high = float(np.min(along + room)), float(np.max(along - room))
    if low > high:                   # one point of the axis meets every window
        low = high = (low + high) / 2
    ends = centre + np.outer([low, high], axis)
    radius = max(radius, float(np.max(_point_distances(points, ends[0], ends[1]))))
    return np.concatenate([ends[0], ends[1], [radius]])


def _box(spec) -> np.ndarray:
    """(15,): centre (3, m), rotation (3 x 3 row by row: the box's axes are its columns) and
    half sides (3, m) of a box holding the body's geometry, in the object's frame: the
    smaller of the box along the object's axes and the one along the points' principal
    axes."""
    points = _spec_points(spec)
    candidates = [np.eye(3)]
    if len(points) > 1:
        candidates.append(np.linalg.svd(points - points.mean(axis=0), full_matrices=False)[2].T)
    best = None
    for axes in candidates:
        local = points @ axes
        low, high = local.min(axis=0), local.max(axis=0)
        half = (high - low) / 2
        if best is None or np.prod(half) < np.prod(best[12:15]):
            best = np.concatenate([axes @ ((low + high) / 2), axes.ravel(), half])
    return best


def _box_volume(box: np.ndarray) -> float:
    return float(8.0 * np.prod(box[12:15]))


def _capsule_volume(capsule: np.ndarray) -> float:
    radius, length = capsule[6], float(np.linalg.norm(capsule[3:6] - capsule[:3]))
    return float(math.pi * radius ** 2 * (length + 4.0 * radius / 3.0))


def _point_distances(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n,) m: each point's distance to the segment a-b."""
    ab = b - a
    length2 = float(ab @ ab)
    t = np.clip((points - a) @ ab / length2, 0.0, 1.0) if length2 > 0 else np.zeros(len(points))
    return np.linalg.norm(points - (a + np.outer(t, ab)), axis=1)


def _chain_length(model, ancestor: int, link: int) -> float:
    """m: an upper bound of the distance from link ``ancestor``'s joint frame to link
    ``link``'s frame, whatever the joints between them (the lengths of their offsets, a
    prismatic joint's full travel)."""
    total = 0.0
    i = link
    while i is not None and i != ancestor:
        current = model.links[i]
        total += _offset_length(current)
        i = current.parent
    return total + float(np.linalg.norm(model.links[ancestor].post[:3, 3]))


def _offset_length(link) -> float:
    length = float(np.linalg.norm(link.pre[:3, 3]) + np.linalg.norm(link.post[:3, 3]))
    if link.movable and link.joint == PRISMATIC and link.limits is not None:
        length += max(abs(link.limits[0]), abs(link.limits[1]))
    return length


def _descendants(model, index: int) -> List[int]:
    out, frontier = [index], [index]
    while frontier:
        parent = frontier.pop()
        children = [i for i, link in enumerate(model.links) if link.parent == parent]
        out += children
        frontier += children
    return out


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    """rad: the angle of the rotation from ``a`` to ``b`` (3, 3)."""
    cosine = (np.trace(a.T @ b) - 1.0) / 2.0
    return float(math.acos(max(-1.0, min(1.0, cosine))))


def control_size(robots: Sequence[PlannedRobot]) -> int:
    """The search's control vector's length: a 2012 problem's robots end to end, a current
    problem's one vector they all share."""
    return max(r.part.stop or r.handle.instance.controls.size for r in robots)


def control_scales(robots: Sequence[PlannedRobot], size: int) -> np.ndarray:
    """(size,): per control, how far a unit of it moves the configuration in Kautham's OMPL
    metric (the Euclidean norm of the joints' values, rad or m, Kautham's links weighing 1;
    a base's translation, m; its turn, ROTATION_PER_UNIT per orientation DOF), summed over the
    robots it moves; a control that moves nothing counts 1e-6. Kautham plans in the
    configuration space, where its ``Range`` is measured; Odin plans in the control space:
    scaled by these, OMPL's distance there is Kautham's for controls that each move their own
    DOFs (gui.planning.geometric)."""
    squares = sum(robot.squared_control_lengths(size) for robot in robots)
    return np.maximum(np.sqrt(squares), 1e-6)


def robot_parts(plan: BuildPlan) -> List[Tuple[object, slice]]:
    """Each robot with controls and its slice of the query's control vector: a current
    problem's robots all map the whole vector, a 2012 problem's robots each the next
    ``size`` values in robot order (gui.core.kautham.problem's query)."""
    robots = [h for h in plan.robots if h.instance.controls is not None]
    if not robots:
        raise PlanningError("no robot of the problem has controls to plan with")
    if plan.problem.format != "2012":
        return [(h, slice(None)) for h in robots]
    parts, end = [], 0
    for handle in robots:
        size = handle.instance.controls.size
        parts.append((handle, slice(end, end + size)))
        end += size
    return parts


def planned_robots(plan: BuildPlan) -> List[PlannedRobot]:
    """The plan's robots with controls, in its order."""
    specs = {spec.id: spec for spec in plan.bodies()}
    return [PlannedRobot(h, part, specs) for h, part in robot_parts(plan)]
