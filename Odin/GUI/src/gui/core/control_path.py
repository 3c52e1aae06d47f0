"""Control paths: rows of Kautham controls, each applied for its duration to a robot the way
Kautham's ODE environment for that robot's kind does (ROS-free).

A control path file is plain text, one control step per line: the k control values c in
[0, 1] (the robot's controls in its control file's order), then the step's duration in
seconds, separated by spaces, tabs or commas; blank lines and lines starting with '#' are
skipped. A car's rows have two controls (steering, wheel speed), whatever its control file.

``MAPPING`` (below) says what a row does; docs/INTERFACE.md shows it (tools/interface_doc.py).
``run_control_path(port, handle, rows)`` applies rows through a ``gui.core.world_port.WorldPort``:
the world calls a row needs (servo targets, forces for its duration) and the state they depend
on; over a world node (``gui.ros.world_port``) each row is one Propagate of the world (paused)
for its duration, kept, as Kautham's propagation steps its ODE world. ``hold(port, handle)``
holds a robot where it is (what Ctrl-C leaves of a path).
"""
from __future__ import annotations

import math
import os
import pathlib
from dataclasses import dataclass
from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np

from gui.core.contacts import ContactLedger
from gui.core.kautham import environment
from gui.core.kautham.controls import control_parts
from gui.core.model import CAR, FREE_BODY, MOBILE
from gui.core.paths import read_rows
from gui.core.plan import ServoCommand
from gui.core.world_port import BodyState, WorldPort
from gui.errors import PathFileError
from odin_common.defaults import SERVO_MAX_SPEED
from odin_common.rotations import quaternion_to_matrix

MAPPING = """\
A control path is a list of rows, each k control values c in [0, 1] and a duration in
seconds (`rosrun GUI run_path PROBLEM --controls FILE`, the Motion tab's "Control path...").
Each row maps to the robot as Kautham maps a control sample (`Robot::control2Parameters`,
`parameter2Pose`): normalised DOF values p = offset + sum_k eigValue_k map_k (c_k - 0.5) from
the control file (`.cntr`, or the `.rob`'s `<ControlSet>`; a DOF it does not list has offset 0.5,
0 in a 2012 `.rob`'s own set, and no map), each clamped to [0, 1], then through the robot's
limits: a joint's value q = low + p (high - low) (a continuous joint's range is
[-2 pi, 2 pi]); the base's position low + p (high - low) per axis of the problem's `<Limits>`
box taken into the Home frame, and its orientation from X1, X2, X3 by Kuffner's uniform
quaternion (w = sqrt(1 - p1) cos(pi p3), x = sqrt(p1) sin(2 pi p2), y = sqrt(p1) cos(2 pi p2),
z = sqrt(1 - p1) sin(pi p3)), both in the Home frame. The query's `<Init>` and `<Goal>` map the
same way to the start the problem is built at and the goal.

For the row's duration the robot is then driven the way Kautham's ODE environment drives that
kind of robot:
- joints (a fixed-base chain, or a mobile robot's arm): Set Servo on each joint's motor toward
  q (the joint's URDF velocity limit as the servo's speed limit, its effort limit as the
  motor's force limit; Odin's servo defaults without them): Kautham's PlanarChainEnvironment
  sets motor speeds under a torque limit, which a servo does each step; the chain of a
  problem for Kautham's chain planner (KPIECEChainPlanner) moves as that environment moves
  it, at up to 1 rad/s under 7 N m per joint, whatever its URDF's limits;
- a free body (Kautham's 2D environments push the robot with a force): along each base axis
  the controls move, the constant force F = m (2 (x* - x0 - v0 d) / d^2), which would carry
  the base (mass m, at x0 with velocity v0 when the row starts) to the row's position x* in
  its duration d were nothing else acting, each component limited to m times
  `ControlDefaults.max_acceleration`; the base's orientation is not driven (Kautham's
  twoDRobotEnvironment samples the force itself, in [-20, 20] N per axis; a row here is a
  configuration, as Kautham's control samples through the `.cntr` are, and the force the one
  that reaches it); a base the build holds kinematic (a free-flying or mobile robot without
  Kautham's physics, ``RobotHandle.base_held``) gets instead the velocity (x* - x0) / d along
  those axes, which puts it there at the row's end, and is stopped after the last row;
- a car (two controls, CarEnvironment's): steering angle -0.5 + c1 rad, reached by each wheel
  hinge-2's first axis at a rate of 1/s per radian of error under 2 N m (a servo of gain 1),
  and wheel speed -5 + 15 c2 rad/s on its second axis under 50 N m.

The last row's servo settings stay in force after it (its forces act only for its duration).
A row whose values leave [0, 1] is refused with its file and line.

A problem of several robots has one control vector for all of them, as its query's `<Init>`
(`control_parts`): a 2012 problem's robots each have their own controls, end to end in robot
order; a current problem's share one control file, each robot mapping the whole vector. A
row of that vector and a duration drives every robot with controls at once, each its share,
in one Propagate per row; a row of one robot's controls and a duration (a 2012 problem's)
drives that robot alone, `run_path --robot`'s (the first robot by default). `--robot` with a
row of every robot's is refused: it would do nothing.

After each row `run_path --controls` prints where the link the planner tracks is (its body's
position, m, world: a held chain's tool, any other robot's base) and, for a problem with a
query, that link's distance to where the query's `<Goal>` puts it in the plane (x, y), the
planner's own metric (`gui.planning`); its last line gives the figure the path ends at
("ends d m from the goal"), which is the one `rosrun GUI plan` printed and wrote for the same
path when the robot starts where the problem builds it.
"""


@dataclass(frozen=True)
class ControlDefaults:
    """``max_acceleration``: m/s^2, a free body's control force limit per kg. ``servo_gain``:
    1/s (None: odin_common's default)."""
    max_acceleration: float = 10.0
    servo_gain: Optional[float] = None


@dataclass(frozen=True)
class ControlRow:
    """One control step: ``controls`` (k values in [0, 1]) for ``duration`` s."""
    controls: Tuple[float, ...]
    duration: float


@dataclass(frozen=True)
class Actuation:
    """What one row asks of the world: a servo command (or None), forces (body ID, (3,) N,
    world frame) acting for ``duration`` s, and a held base's velocity (body ID, (3,) m/s,
    world frame; None: none) for that time."""
    duration: float
    servo: Optional[ServoCommand] = None
    forces: Tuple[Tuple[str, Tuple[float, float, float]], ...] = ()
    base_velocity: Optional[Tuple[str, Tuple[float, float, float]]] = None


def control_size(handle) -> int:
    """How many controls a row of ``handle``'s robot has."""
    if handle.kind == CAR:
        return 2
    controls = handle.instance.controls
    if controls is None:
        raise PathFileError(f"robot {handle.name} has no controls (no control file and no "
                            "query to build them from)")
    return controls.size


def read_control_path(path: os.PathLike | str, size: int) -> List[ControlRow]:
    """The rows of a control path file for a robot of ``size`` controls (module docstring)."""
    p = pathlib.Path(path)
    rows, lines = read_rows(p, size + 1, f"{size} controls and a duration")
    out = []
    for values, line in zip(rows, lines):
        controls, duration = values[:size], float(values[size])
        if not np.all((controls >= 0.0) & (controls <= 1.0)):
            raise PathFileError(f"control values {controls.tolist()} are not all in [0, 1]",
                                p, line)
        if duration <= 0.0:
            raise PathFileError(f"duration {duration:g} s is not positive (the last value of "
                                "a row)", p, line)
        out.append(ControlRow(tuple(float(v) for v in controls), duration))
    return out


def read_control_paths(path: os.PathLike | str, handles: Sequence, legacy: bool,
                       robot: Optional[str] = None) -> List[Tuple[object, List[ControlRow]]]:
    """A control path for a problem's robots (``handles``: their gui.core.plan.RobotHandle,
    robots only, the problem's order; ``legacy``: a 2012 problem), as (handle, its rows) per
    robot it drives. A row of the problem's whole control vector and a duration drives every
    robot with controls, each its share (``gui.core.kautham.controls.control_parts``: a 2012
    problem's robots' controls end to end, a current problem's one set they all map; cars,
    whose rows are CarEnvironment's two controls, are not shared out); else a row is one
    robot's controls and a duration, ``robot``'s (the first by default)."""
    p = pathlib.Path(path)
    chosen = next((h for h in handles if robot in (None, h.name)), None)
    if chosen is None:
        raise PathFileError(f"no robot named {robot!r} (robots: "
                            + ", ".join(h.name for h in handles) + ")", p)
    by_instance = {id(h.instance): h for h in handles}
    parts = [(by_instance[id(i)], part) for i, part in
             control_parts([h.instance for h in handles], legacy)]
    if len(parts) > 1 and all(h.kind != CAR for h, _ in parts):
        every = max(part.stop for _, part in parts)
        width = read_rows(p)[0].shape[1]
        if width == every + 1:
            rows = read_control_path(p, every)
            return [(h, [ControlRow(r.controls[part], r.duration) for r in rows])
                    for h, part in parts]
        own = control_size(chosen)
        if width != own + 1:
            shared = "" if legacy else ", which every robot maps"
            raise PathFileError(f"{width} values a row, expected {every + 1} (the problem's "
                                f"{every} controls{shared}, and a duration) or {own + 1} "
                                f"({chosen.name}'s {own} controls and a duration)", p)
    return [(chosen, read_control_path(p, control_size(chosen)))]


def write_control_path(path: os.PathLike | str, rows: Sequence[ControlRow],
                       comments: Sequence[str] = ()) -> None:
    """Writes ``rows`` as a control path file (module docstring) that ``read_control_path``
    reads back exactly: each value in Python's shortest round-trip form; ``comments`` first,
    each a '#' line. Refuses rows of different sizes or with values out of range before
    writing anything; the file appears whole (written beside it, then renamed) or not at
    all."""
    if not rows:
        raise PathFileError("no rows to write", path)
    size = len(rows[0].controls)
    for k, row in enumerate(rows, start=1):
        if len(row.controls) != size:
            raise PathFileError(f"row {k} has {len(row.controls)} controls, row 1 {size}",
                                path)
        if not all(0.0 <= float(c) <= 1.0 for c in row.controls) or not row.duration > 0:
            raise PathFileError(f"row {k}: controls {list(row.controls)} not all in [0, 1] "
                                f"or duration {row.duration!r} s not positive", path)
    lines = [f"# {line}" for text in comments for line in str(text).splitlines()]
    lines += [" ".join(repr(float(v)) for v in (*row.controls, row.duration)) for row in rows]
    target = pathlib.Path(path)
    part = target.with_name(f".{target.name}.{os.getpid()}.part")
    try:                        # whole or not at all, also when Ctrl-C comes mid-write
        part.write_text("\n".join(lines) + "\n")
        os.replace(part, target)
    finally:
        part.unlink(missing_ok=True)


def actuation(handle, row: ControlRow, state: Optional[BodyState],
              defaults: ControlDefaults = ControlDefaults()) -> Actuation:
    """What ``row`` asks of the world for ``handle``'s robot; ``state``: its base body's when
    the row starts (needed for a free base)."""
    if handle.kind == CAR:
        return Actuation(row.duration, servo=_car_servo(handle, row.controls))
    controls = handle.instance.controls
    target = controls.configuration(handle.instance, row.controls)
    servo = _joint_servo(handle, target.joints, defaults) if handle.motor_ids else None
    forces, velocity = (), None
    if reads_base(handle):
        if handle.base_held:
            velocity = _base_velocity(handle, target.base_pose, state, row.duration,
                                      controls.moved_base_axes())
        else:
            forces = (_base_force(handle, target.base_pose, state, row.duration,
                                  controls.moved_base_axes(), defaults),)
    return Actuation(row.duration, servo, forces, velocity)


def reads_base(handle) -> bool:
    """Whether ``actuation`` of ``handle``'s robot depends on its base's state (a free or mobile
    base its controls move: a force or velocity toward the row's position); otherwise it
    depends on the row alone."""
    controls = handle.instance.controls
    return handle.kind in (FREE_BODY, MOBILE) and controls is not None and controls.se3 \
        and bool(controls.moved_base_axes())


def _joint_servo(handle, targets: np.ndarray, defaults: ControlDefaults) -> ServoCommand:
    relative = np.asarray(targets, dtype=float) - handle.built_at
    speeds = tuple(float(v) if v else SERVO_MAX_SPEED for v in handle.max_speeds)
    gains = (defaults.servo_gain,) * len(relative) if defaults.servo_gain else ()
    return ServoCommand(tuple(handle.motor_ids), tuple(float(v) for v in relative),
                        gains=gains, max_speeds=speeds)


def _car_servo(handle, controls: Sequence[float]) -> ServoCommand:
    low, high = environment.STEERING_RANGE
    turn = low + controls[0] * (high - low)
    low, high = environment.WHEEL_SPEED_RANGE
    speed = low + controls[1] * (high - low)
    wheels = len(handle.motor_ids)
    low, high = environment.STEERING_RANGE      # the steering error is never above this:
    steer_speed = environment.STEERING_GAIN * (high - low)   # the rate is never capped
    return ServoCommand(
        tuple(handle.motor_ids), (turn, 0.0) * wheels, rates=(0.0, speed) * wheels,
        gains=(environment.STEERING_GAIN, 0.0) * wheels,
        max_speeds=(steer_speed, abs(speed)) * wheels,
        max_forces=(environment.STEERING_MAX_TORQUE, environment.WHEEL_MAX_TORQUE) * wheels)


def _base_origin(handle, state: Optional[BodyState]) -> np.ndarray:
    """(3,) m, world: the base link's origin in the base body's ``state``."""
    if state is None:
        raise ValueError(f"{handle.name}: a free base needs its state to be driven")
    position, quaternion = state[0], state[1]
    pose = np.eye(4)
    pose[:3, :3] = quaternion_to_matrix(quaternion)
    pose[:3, 3] = position
    return (pose @ np.linalg.inv(handle.bodies[0].offset))[:3, 3]


def _base_velocity(handle, target_pose: np.ndarray, state: Optional[BodyState],
                   duration: float, axes: Sequence[int]) -> Tuple[str, tuple]:
    """A held (kinematic) base's velocity that puts it at the row's position along ``axes``
    when the row ends (nothing else moves it)."""
    base = _base_origin(handle, state)
    velocity = np.zeros(3)
    for i in axes:
        velocity[i] = (target_pose[i, 3] - base[i]) / duration
    return handle.bodies[0].body_id, tuple(float(v) for v in velocity)


def _base_force(handle, target_pose: np.ndarray, state: Optional[BodyState], duration: float,
                axes: Sequence[int], defaults: ControlDefaults) -> Tuple[str, tuple]:
    base = _base_origin(handle, state)
    velocity = state[2]             # the centre of mass's linear velocity (m/s)
    body = handle.bodies[0]
    mass = handle.base_mass
    force = np.zeros(3)
    limit = mass * defaults.max_acceleration
    for i in axes:
        wanted = mass * 2.0 * (target_pose[i, 3] - base[i] - velocity[i] * duration) \
            / duration ** 2
        force[i] = max(-limit, min(limit, wanted))
    return body.body_id, tuple(float(v) for v in force)


@dataclass
class RowResult:
    """After one row: its index, the base's position (m, world), the actuation used and the
    state of the watched body (``run_control_path``'s ``watch``; None: no body watched)."""
    index: int
    base_position: np.ndarray
    actuation: Actuation
    watched: Optional[BodyState] = None


def run_control_path(port: WorldPort, handle, rows: Sequence[ControlRow],
                     defaults: ControlDefaults = ControlDefaults(),
                     progress: Optional[Callable[[RowResult], None]] = None,
                     stop: Optional[Callable[[], bool]] = None,
                     watch: Optional[str] = None,
                     contacts: Optional[ContactLedger] = None,
                     others: Sequence[Tuple[object, Sequence[ControlRow]]] = ()
                     ) -> List[RowResult]:
    """Applies ``rows`` in order to ``handle``'s robot through ``port``; returns the base's
    position after each row, and the state of body ``watch`` (a world ID: the link a planner
    tracked) when given. ``stop()`` true (asked before each row) ends the path there: the
    rows run so far are returned. ``contacts``: told every pair met, s from the path's
    start. ``others``: more robots driven at the same time, each (handle, its rows: as many,
    of the same durations; one path's rows split per robot, ``read_control_paths``)."""
    robots = [(handle, rows), *others]
    for robot, its_rows in robots:
        size = control_size(robot)
        for k, row in enumerate(its_rows, start=1):
            if len(row.controls) != size:
                raise PathFileError(f"row {k} has {len(row.controls)} controls, robot "
                                    f"{robot.name} takes {size}")
        if len(its_rows) != len(rows):
            raise PathFileError(f"robot {robot.name} has {len(its_rows)} rows, robot "
                                f"{handle.name} {len(rows)}")
    base_id = handle.bodies[0].body_id
    results = []
    elapsed = 0.0
    for k, row in enumerate(rows, start=1):
        if stop is not None and stop():
            break
        acts = [_actuate(port, robot, its_rows[k - 1], defaults) for robot, its_rows in robots]
        act = acts[0]
        met = port.advance(row.duration, tuple(f for a in acts for f in a.forces))
        if contacts is not None:
            for first, second, depth, when in met:
                contacts.see(first, second, depth, elapsed + (when if math.isfinite(when)
                                                              else 0.0))
        elapsed += row.duration
        result = RowResult(k, port.body_state(base_id)[0], act,
                           None if watch is None else port.body_state(watch))
        results.append(result)
        if progress is not None:
            progress(result)
    for robot, _ in robots:             # a kinematic base keeps its velocity: it stops here
        if robot.base_held:
            port.set_body_velocity(robot.bodies[0].body_id, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    return results


def _actuate(port: WorldPort, handle, row: ControlRow, defaults: ControlDefaults) -> Actuation:
    """Sets what ``row`` asks of ``handle``'s robot for its duration (its servos, a held
    base's velocity) and returns the actuation, whose forces the caller applies."""
    act = actuation(handle, row, port.body_state(handle.bodies[0].body_id), defaults)
    if act.servo is not None:
        port.set_servo(act.servo)
    if act.base_velocity is not None:
        port.set_body_velocity(*act.base_velocity, (0.0, 0.0, 0.0))
    return act


def hold_servo(handle, present: Sequence[float]) -> ServoCommand:
    """Set Servo that holds ``handle``'s robot still: each joint's motor toward its
    ``present`` value (rad or m, Kautham's joint values: ``built_at`` plus what the world
    measures, one per joint of ``handle.joint_ids``) at no feed-forward rate; a car's wheels
    stopped, its steering straight."""
    if handle.kind == CAR:
        wheels = len(handle.motor_ids)
        low, high = environment.STEERING_RANGE
        return ServoCommand(
            tuple(handle.motor_ids), (0.0, 0.0) * wheels, rates=(0.0, 0.0) * wheels,
            gains=(environment.STEERING_GAIN, 0.0) * wheels,
            max_speeds=(environment.STEERING_GAIN * (high - low), SERVO_MAX_SPEED) * wheels,
            max_forces=(environment.STEERING_MAX_TORQUE, environment.WHEEL_MAX_TORQUE) * wheels)
    relative = np.asarray(present, dtype=float) - np.asarray(handle.built_at, dtype=float)
    speeds = tuple(float(v) if v else SERVO_MAX_SPEED for v in
                   (handle.max_speeds or [None] * len(relative)))
    return ServoCommand(tuple(handle.motor_ids), tuple(float(v) for v in relative),
                        rates=(0.0,) * len(relative), max_speeds=speeds)


def hold(port: WorldPort, handle) -> None:
    """Holds ``handle``'s robot where it is: its servos toward the joints' present values
    (``hold_servo``), a free base's velocity zero (what Ctrl-C leaves of a path)."""
    if handle.motor_ids and (handle.kind == CAR or
                             len(handle.motor_ids) == len(handle.joint_ids)):
        moved = port.joint_positions(handle.joint_ids)
        port.set_servo(hold_servo(handle, np.asarray(handle.built_at, dtype=float) + moved))
    if handle.kind in (FREE_BODY, MOBILE, CAR):
        port.set_body_velocity(handle.bodies[0].body_id, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


__all__ = ["MAPPING", "ControlDefaults", "ControlRow", "ServoCommand", "Actuation",
           "control_size", "read_control_path", "read_control_paths", "write_control_path",
           "actuation", "run_control_path", "RowResult", "hold_servo", "hold"]
