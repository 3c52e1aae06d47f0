"""Tracked execution: a Kautham plan (``gui.core.kautham.solutions``) timed within the joints'
limits (``gui.core.trajectory``) and followed by the world's joint servos under full physics,
with a report of how well it was followed (ROS-free).

Every ``period`` s of simulated time (a multiple of the world's step, 0.01 s by default):
each robot's servos get the trajectory's target at the middle of the coming period and, as
feed-forward, its mean rate over the period (Set Servo; the servo's speed is
clamp(rate + gain (target - q), +-limit) each step, under the joint's effort limit); a
free-flying base gets the velocity rate + ``base_gain`` error (linear and angular, world frame)
and a force cancelling gravity on the robot's mass, as a velocity servo of its own (a base the
build holds kinematic, outside Kautham's physics, moves at that velocity exactly); a planar
mobile base under Kautham's physics (``_planar_base``) stands on its floor instead: servoed
along x, y and about z only, with the gain that closes the error within the period, its
height and tilt left to its floor and its weight uncancelled; then the
world runs the period with contacts on (one kept Propagate), and the joints are read.
Attach/detach events become a FIXED joint between the link's body and the obstacle's, made and
removed at their waypoint's time (the robot is at rest there); an obstacle the build holds
where the problem puts it (``BuildPlan.holds``) is let go as it is attached and held again
where it is left. The path starts where the robot
is: its present configuration is the first waypoint, the path's first sample (a ``.kps``
query's ``Init``) the second. A robot farther from that sample than ``start_tolerance`` (rad
or m: the largest difference of a joint, of a base's coordinate or of its rotation) is refused
before anything moves (``AwayFromStart``: "the robot is 1.8 rad from the path's start"),
unless the run is asked to move it there first (``run_path --tracked --from-here``): that move
is then the report's first segment, timed as the path's are. After the last waypoint the
targets are held ``settle`` s; the servos stay on afterwards (they hold the goal).

The report: ``goal_error`` (largest joint error from the last waypoint when execution ends,
rad or m; a base's position error in m and its rotation error in rad count as joints),
``tracking_error_max`` (the largest along the way, against the trajectory's value at the same
time), ``duration_s`` (simulated, trajectory and settling), the collisions the path made (pairs of
geometries, first time, deepest depth) apart from the contacts the scene rested on when it
began (``support``; ``gui.core.contacts``), per-joint series of target, actual and error, the
``segments`` run (the move to the path's start, with how far it was; the path; the settling;
each with its start and end, s) and a ``.kps`` file's ``query`` (its Init and Goal samples).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from gui.core.contacts import ContactLedger
from gui.core.control_path import ServoCommand
from gui.core.kautham.solutions import ATTACH, Solution
from gui.core.model import MOBILE, PRISMATIC
from gui.core.translate.joints import HALF_TURN
from gui.core.trajectory import BaseLimits, Trajectory, rotation_error
from gui.core.world_port import WorldPort
from gui.errors import GuiError, PathFileError
from odin_common.defaults import SERVO_GAIN, SERVO_MAX_SPEED
from odin_common.rotations import quaternion_to_matrix


@dataclass(frozen=True)
class TrackingDefaults:
    """How a path is timed and followed. ``speed_fraction``: of each joint's speed limit the
    trajectory uses (the rest is the servo's room to correct); ``acceleration``: rad/s^2 or
    m/s^2 per joint; ``gain``: the servos' position gain, 1/s; the free-flying base's limits
    (m/s, m/s^2, rad/s, rad/s^2) and ``base_gain`` (1/s); ``period``: s between servo updates
    (rounded to whole world steps); ``settle``: s the last target is held;
    ``start_tolerance``: rad or m, how far the robot may be from the path's first sample for
    the path to run from where it is (module docstring)."""
    speed_fraction: float = 0.8
    acceleration: float = 2.0
    gain: float = SERVO_GAIN
    base_speed: float = 0.5
    base_acceleration: float = 1.0
    base_angular_speed: float = 1.0
    base_angular_acceleration: float = 2.0
    base_gain: float = 10.0
    period: float = 0.01
    settle: float = 0.5
    start_tolerance: float = 0.01

    def base_limits(self) -> BaseLimits:
        return BaseLimits(self.base_speed, self.base_acceleration, self.base_angular_speed,
                          self.base_angular_acceleration)


class AwayFromStart(GuiError):
    """The robot is farther from the path's first sample than ``TrackingDefaults.
    start_tolerance``: ``distance`` (in ``unit``, "rad" or "m") on channel ``channel``
    ("robot/joint", "robot/base x"...)."""

    def __init__(self, distance: float, unit: str, channel: str):
        self.distance, self.unit, self.channel = distance, unit, channel
        super().__init__(f"the robot is {distance:.3g} {unit} from the path's start "
                         f"({channel})")


@dataclass
class _Robot:
    """One robot of the run: its handle, its columns in the stacked joint vector, its base's
    index among the free-flying bases (None: base not driven); ``turning``: per movable joint,
    whether the world reads it only up to whole turns (``_turning``, taken once);
    ``planar``: its base is a planar mobile base on its floor (``_planar_base``)."""
    handle: object
    columns: slice
    base: Optional[int]
    turning: np.ndarray = field(init=False)
    planar: bool = field(init=False)

    def __post_init__(self) -> None:
        self.turning = _turning(self.handle)
        self.planar = _planar_base(self.handle)


@dataclass
class _Event:
    time: float
    action: str
    link_body: str
    obstacle_body: str
    label: str


@dataclass
class TrackingReport:
    """What a tracked execution did (module docstring); ``to_json()`` for the summary."""
    source: str
    format: str
    goal_error: float
    tracking_error_max: float
    duration_s: float
    trajectory_s: float
    settle_s: float
    period_s: float
    wall_time_s: float
    collisions: List[dict]            # made by the path (gui.core.contacts)
    events: List[dict]
    names: List[str]
    units: List[str]
    times: np.ndarray
    targets: np.ndarray               # (ticks, channels)
    actuals: np.ndarray
    segments: List[dict] = field(default_factory=list)
    query: Optional[dict] = None
    start_tolerance: float = TrackingDefaults.start_tolerance
    support: List[dict] = field(default_factory=list)      # rested on (gui.core.contacts)
    contacts: str = ""                                     # ContactLedger.describe()

    @property
    def errors(self) -> np.ndarray:
        return self.actuals - self.targets

    def start_move(self) -> str:
        """", after a 1.8 rad move to its start (2.10 s)" when the run began by moving a robot
        farther than ``start_tolerance`` to the path's start (``from_here``), else ""."""
        move = self.segments[0] if self.segments else None
        if move is None or move["distance"] <= self.start_tolerance:
            return ""
        return (f", after a {move['distance']:.3g} {move['unit']} move to its start "
                f"({move['end_s'] - move['start_s']:.2f} s)")

    @property
    def real_time_factor(self) -> float:
        return self.duration_s / self.wall_time_s if self.wall_time_s > 0 else math.inf

    def to_json(self) -> dict:
        return dict(
            source=self.source, format=self.format, goal_error=self.goal_error,
            tracking_error_max=self.tracking_error_max, duration_s=self.duration_s,
            trajectory_s=self.trajectory_s, settle_s=self.settle_s, period_s=self.period_s,
            wall_time_s=self.wall_time_s, real_time_factor=self.real_time_factor,
            collisions=self.collisions, support=self.support, events=self.events,
            segments=self.segments,
            query=self.query, units=dict(angle="rad", length="m", time="s"),
            series=dict(time=self.times.tolist(), joints=[
                dict(name=n, unit=u, target=self.targets[:, k].tolist(),
                     actual=self.actuals[:, k].tolist(), error=self.errors[:, k].tolist())
                for k, (n, u) in enumerate(zip(self.names, self.units))]))


def _channels(robots: Sequence[_Robot]) -> Tuple[List[str], List[str]]:
    names, units = [], []
    for r in robots:
        model = r.handle.instance.model
        for i, joint in zip(model.movable_links(), model.joint_names()):
            names.append(f"{r.handle.name}/{joint}")
            units.append("m" if model.links[i].joint == PRISMATIC else "rad")
        if r.base is not None:
            names += [f"{r.handle.name}/base {a}" for a in "xyz"] + \
                [f"{r.handle.name}/base rotation"]
            units += ["m", "m", "m", "rad"]
    return names, units


def _events(plan, solution: Solution, times: np.ndarray) -> List[_Event]:
    """The solution's events with their times (waypoint k of the file is k + 1 here: the
    present configuration comes first) and bodies, all checked before anything runs."""
    bodies = {_instance_of(b): b.id for b in plan.bodies()}
    out = []
    for e in solution.events:
        handle = plan.robot(e.robot)
        names = [link.name for link in handle.instance.model.links]
        link_body = handle.bodies[names.index(e.link)].body_id
        if e.obstacle not in bodies:
            raise PathFileError(f"obstacle \"{e.obstacle}\" is static geometry in this build: "
                                "it cannot be attached", solution.source, e.line)
        out.append(_Event(float(times[e.index + 1]), e.action, link_body, bodies[e.obstacle],
                          f"{e.action} {e.obstacle} {'to' if e.action == ATTACH else 'from'} "
                          f"{e.robot}/{e.link}"))
    return out


def _instance_of(body) -> str:
    """The instance a planned body belongs to: an object's name, a composite's parts'
    ("name#k", gui.core.bodies' naming)."""
    if hasattr(body, "name"):
        return body.name
    return body.parts[0].name.split("#")[0]


def _planar_base(handle) -> bool:
    """Whether a robot's base is a planar mobile base standing on its floor: a mobile robot
    under Kautham's physics (its base a free dynamic body) whose controls move the base along
    x and y, never along z (Kautham's mobile bases: ``Limits`` Z min = max). Its floor, not a
    servo, carries its weight and holds its height and tilt (``_drive_base``)."""
    controls = handle.instance.controls
    return (handle.kind == MOBILE and not handle.base_held and controls is not None
            and controls.se3 and 2 not in controls.moved_base_axes())


def _turning(handle) -> np.ndarray:
    """Per movable joint of a robot (its plan handle), whether the world reads it only up to
    whole turns: a revolute joint whose range (none: unlimited) passes +-pi from where it was
    built, which ODE's hinge angle in [-pi, pi] cannot tell apart (its servo takes the turn
    nearest its target: odin_step.h)."""
    model = handle.instance.model
    built = np.asarray(handle.built_at, dtype=float)
    out = []
    for k, i in enumerate(model.movable_links()):
        link = model.links[i]
        limits = link.limits
        out.append(link.joint != PRISMATIC and (
            limits is None or limits[0] - built[k] < -HALF_TURN
            or limits[1] - built[k] > HALF_TURN))
    return np.array(out, dtype=bool)


def _nearest_turns(values: np.ndarray, reference: np.ndarray, turning: np.ndarray
                   ) -> np.ndarray:
    """``values`` with each turning one (``_turning``) the whole turns from it nearest its
    ``reference`` (rad): the same configuration, read as the path means it."""
    turns = np.round((reference - values) / (2.0 * math.pi))
    return np.where(turning, values + 2.0 * math.pi * turns, values)


def _present(port: WorldPort, robot: _Robot) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    """A robot's joint values (rad / m) and base pose (4, 4 world) now."""
    h = robot.handle
    joints = np.asarray(h.built_at, dtype=float).copy()
    if len(joints):
        joints = joints + port.joint_positions(h.joint_ids)
    base = None
    if robot.base is not None:
        position, quaternion, _, _ = port.body_state(h.bodies[0].body_id)
        body = np.eye(4)
        body[:3, :3] = quaternion_to_matrix(quaternion)
        body[:3, 3] = position
        base = body @ np.linalg.inv(h.bodies[0].offset)
    return joints, base


def plan_tracking(port: WorldPort, plan, solution: Solution,
                  defaults: TrackingDefaults = TrackingDefaults(), from_here: bool = False):
    """(robots, trajectory, events) for ``solution`` from the robots' present state;
    ``AwayFromStart`` when a robot is farther from the path's first sample than
    ``defaults.start_tolerance`` unless ``from_here`` (module docstring)."""
    robots, columns, start, waypoints, bases, base_start = [], 0, [], [], [], []
    speeds = []
    for name, path in solution.paths.items():
        handle = plan.robot(name)
        n = path.joints.shape[1]
        if n and len(handle.motor_ids) != n:
            raise PathFileError(f"robot {name} has {len(handle.motor_ids)} motors for {n} "
                                "joints: it cannot be servoed", solution.source)
        base = None
        if path.base_poses is not None:
            base = len(bases)
            bases.append(path.base_poses)
        robot = _Robot(handle, slice(columns, columns + n), base)
        robots.append(robot)
        columns += n
        joints, base_pose = _present(port, robot)
        if n:
            joints = _nearest_turns(joints, path.joints[0], robot.turning)
        start.append(joints)
        if base_pose is not None:
            base_start.append(base_pose)
        waypoints.append(path.joints)
        speeds += [defaults.speed_fraction * (v or SERVO_MAX_SPEED) for v in
                   (handle.max_speeds or [None] * n)]
    q = np.vstack([np.concatenate(start)[None, :], np.hstack(waypoints)])
    base_poses = None
    if bases:
        base_poses = np.concatenate([np.array(base_start)[None], np.stack(bases, axis=1)])
    trajectory = Trajectory.of(q, speeds, [defaults.acceleration] * q.shape[1], base_poses,
                               defaults.base_limits())
    distance, unit, channel = start_offset(robots, trajectory)
    if distance > defaults.start_tolerance and not from_here:
        raise AwayFromStart(distance, unit, channel)
    return robots, trajectory, _events(plan, solution, trajectory.times)


def start_offset(robots: Sequence[_Robot], trajectory: Trajectory) -> Tuple[float, str, str]:
    """(distance, its unit, its channel): how far the trajectory's first waypoint (where the
    robots are) is from its second (the path's first sample), the channel that differs most
    (``_compare``'s channels: joints, a base's coordinates and its rotation)."""
    present, first = trajectory.sample(0.0), trajectory.sample(float(trajectory.times[1]))
    names, units = _channels(robots)
    differences = []
    for r in robots:
        differences.extend(np.abs(first.joints[r.columns] - present.joints[r.columns]))
        if r.base is not None:
            a, b = present.base_pose[r.base], first.base_pose[r.base]
            differences.extend(np.abs(b[:3, 3] - a[:3, 3]))
            differences.append(float(np.linalg.norm(rotation_error(b[:3, :3], a[:3, :3]))))
    if not differences:
        return 0.0, "rad", ""
    k = int(np.argmax(differences))
    return float(differences[k]), units[k], names[k]


def _segments(robots: Sequence[_Robot], trajectory: Trajectory, done_s: float) -> List[dict]:
    """The report's segments: the move to the path's start (with its distance), the path,
    the settling; each clipped to the ``done_s`` s run."""
    distance, unit, channel = start_offset(robots, trajectory)
    reached, end = float(trajectory.times[1]), trajectory.duration
    out = [dict(what="to the path's start", start_s=0.0, end_s=min(reached, done_s),
                distance=distance, unit=unit, channel=channel),
           dict(what="path", start_s=min(reached, done_s), end_s=min(end, done_s))]
    if done_s > end:
        out.append(dict(what="settle", start_s=end, end_s=done_s))
    return out


def execute_tracked(port: WorldPort, plan, solution: Solution,
                    defaults: TrackingDefaults = TrackingDefaults(),
                    progress: Optional[Callable[[float, float], None]] = None,
                    real_time: bool = False, sleep: Callable[[float], None] = time.sleep,
                    stop: Optional[Callable[[], bool]] = None,
                    from_here: bool = False) -> TrackingReport:
    """Runs ``solution`` on ``plan``'s robots through ``port`` (module docstring).
    ``progress(t, duration)`` after each period; ``real_time``: each period takes at least
    its simulated time of wall-clock time. ``stop()`` true (asked before each period) ends
    the run there: the report covers the periods run (``duration_s``). ``from_here``: a
    robot away from the path's start is moved there first (else ``AwayFromStart``)."""
    robots, trajectory, events = plan_tracking(port, plan, solution, defaults, from_here)
    step = port.step_values().step
    period = step * max(1, round(defaults.period / step))
    ticks = int(math.ceil((trajectory.duration + defaults.settle) / period - 1e-9))
    names, units = _channels(robots)
    weights = _base_weights(port, robots)
    gravity = port.gravity()
    made: Dict[Tuple[str, str], str] = {}
    holds = plan.holds()
    contacts = ContactLedger(port.check_collision([]))
    times, targets, actuals = [], [], []
    pending = sorted(events, key=lambda e: e.time)
    started = time.monotonic()
    done = 0
    for k in range(ticks):
        if stop is not None and stop():
            break
        done = k + 1
        t = k * period
        while pending and pending[0].time <= t + 1e-9:
            _apply(port, pending.pop(0), made, holds)
        middle, end = trajectory.sample(t + 0.5 * period), trajectory.sample(t + period)
        rates = (end.joints - trajectory.sample(t).joints) / period
        forces = []
        for r in robots:
            if r.columns.stop > r.columns.start:
                port.set_servo(_servo(r.handle, middle.joints[r.columns],
                                      rates[r.columns], defaults))
            if r.base is not None:
                force = _drive_base(port, r, middle, end, weights[r.handle.name], gravity,
                                    defaults, period)
                if force is not None:
                    forces.append(force)
        wall = time.monotonic()
        for first, second, depth, when in port.advance(period, forces):
            contacts.see(first, second, depth, t + (when if math.isfinite(when) else 0.0))
        if real_time:
            sleep(max(0.0, period - (time.monotonic() - wall)))
        target, actual = _compare(port, robots, end)
        times.append(t + period)
        targets.append(target)
        actuals.append(actual)
        if progress is not None:
            progress(t + period, ticks * period)
    wall_time = time.monotonic() - started
    targets, actuals = np.array(targets), np.array(actuals)
    errors = np.abs(actuals - targets)
    final = trajectory.sample(trajectory.duration)
    goal_target, goal_actual = _compare(port, robots, final)
    return TrackingReport(
        solution.source, solution.format,
        goal_error=float(np.max(np.abs(goal_actual - goal_target), initial=0.0)),
        tracking_error_max=float(np.max(errors, initial=0.0)),
        duration_s=done * period, trajectory_s=trajectory.duration,
        settle_s=max(0.0, done * period - trajectory.duration), period_s=period,
        wall_time_s=wall_time,
        collisions=contacts.made, support=contacts.support, contacts=contacts.describe(),
        events=[dict(time_s=e.time, what=e.label) for e in events],
        names=names, units=units, times=np.array(times), targets=targets, actuals=actuals,
        segments=_segments(robots, trajectory, done * period),
        start_tolerance=defaults.start_tolerance,
        query=None if solution.query is None else dict(init=solution.query.init,
                                                       goal=solution.query.goal))


def _servo(handle, targets: np.ndarray, rates: np.ndarray,
           defaults: TrackingDefaults) -> ServoCommand:
    relative = targets - np.asarray(handle.built_at, dtype=float)
    speeds = [float(v) if v else SERVO_MAX_SPEED for v in
              (handle.max_speeds or [None] * len(relative))]
    return ServoCommand(tuple(handle.motor_ids), tuple(float(v) for v in relative),
                        rates=tuple(float(v) for v in rates),
                        gains=(defaults.gain,) * len(relative), max_speeds=tuple(speeds))


def _base_weights(port: WorldPort, robots: Sequence[_Robot]) -> Dict[str, float]:
    return {r.handle.name: port.masses([b.body_id for b in r.handle.bodies])
            for r in robots if r.base is not None}


def _drive_base(port: WorldPort, robot: _Robot, middle, end, mass: float,
                gravity: np.ndarray, defaults: TrackingDefaults, period: float
                ) -> Optional[Tuple[str, tuple]]:
    """Sets the base body's velocity toward its target; returns the gravity-cancelling force
    (the robot's whole mass, on the base body). A planar base (``_Robot.planar``) is servoed
    along x, y and about z only: its vertical and tilting velocities stay what contacts and
    gravity make them, and no force cancels its weight, which its floor carries (cancelled,
    the floor's push lifted a cart 7.6 mm and tilted it 0.04 rad as its arm swung)."""
    body = robot.handle.bodies[0]
    position, quaternion, linear_now, angular_now = port.body_state(body.body_id)
    target = middle.base_pose[robot.base] @ body.offset
    # a planar base's gain is deadbeat: the velocity that closes the whole error within the
    # period, for the floor's friction takes up to mu g h of it every step (a gain of 10/s
    # left a cart dragged 9 mm behind its target)
    gain = 1.0 / period if robot.planar else defaults.base_gain
    linear = end.base_linear[robot.base] + gain * (target[:3, 3] - position)
    angular = end.base_angular[robot.base] + gain * rotation_error(
        target[:3, :3], quaternion_to_matrix(quaternion))
    if robot.planar:
        linear[2] = linear_now[2]
        angular[:2] = angular_now[:2]
        port.set_body_velocity(body.body_id, linear, angular)
        return None
    port.set_body_velocity(body.body_id, linear, angular)
    return body.body_id, tuple(float(v) for v in -mass * gravity)


def _compare(port: WorldPort, robots: Sequence[_Robot], sample) -> Tuple[np.ndarray,
                                                                            np.ndarray]:
    """(target, actual) per channel: joints, then per driven base x y z and the rotation
    (target's entry 0, actual's entry the angle between them)."""
    target, actual = [], []
    for r in robots:
        joints, base = _present(port, r)
        wanted = sample.joints[r.columns]
        target.append(wanted)
        actual.append(_nearest_turns(joints, wanted, r.turning) if len(joints) else joints)
        if r.base is not None:
            wanted = sample.base_pose[r.base]
            angle = float(np.linalg.norm(rotation_error(wanted[:3, :3], base[:3, :3])))
            target.append(np.concatenate([wanted[:3, 3], [0.0]]))
            actual.append(np.concatenate([base[:3, 3], [angle]]))
    return np.concatenate(target), np.concatenate(actual)


def _apply(port: WorldPort, event: _Event, made: Dict[Tuple[str, str], str],
           holds: Dict[str, str]) -> None:
    """Makes or removes the event's attachment. An obstacle held where the problem put it
    (``holds``: ``BuildPlan.holds``, "" while attached) is let go when attached and held again
    where it is left."""
    key = (event.link_body, event.obstacle_body)
    if event.action == ATTACH:
        if key not in made:
            if holds.get(event.obstacle_body):
                port.detach(holds[event.obstacle_body])
                holds[event.obstacle_body] = ""
            made[key] = port.attach(*key)
    elif key in made:
        port.detach(made.pop(key))
        if event.obstacle_body in holds and not any(
                obstacle == event.obstacle_body for _, obstacle in made):
            holds[event.obstacle_body] = port.attach(event.obstacle_body, "")


__all__ = ["TrackingDefaults", "TrackingReport", "AwayFromStart", "plan_tracking",
           "start_offset", "execute_tracked"]
