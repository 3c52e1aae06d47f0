"""Experiment 3 (thesis 10.3): the TX90 with the Schunk SAH hand takes a can from the table,
carries it and drops it.

Scene: ``legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml`` as the GUI loads it, except
the can that is grasped ("can", the top one of the pile in the file): it is built as a movable
body, a cylinder primitive of the mesh's size (radius 0.0317 m, length 0.1206 m, 0.35 kg)
instead of the 4366-triangle mesh (ODE's trimesh-trimesh contacts between the hand and a mesh
can jitter and cost far more), and it is put on the table within the arm's reach by Set
Position (the thesis positioned its cans the same way). The other two cans stay static
geometry.

Driving, in two modes (``run(mode=...)``; docs/EXPERIMENTS.md). "tracked" (the default,
issue 12): after the starting position, the arm follows ``grasp_approach.txt`` and then the
configurations the velocity rows below would reach (thumb opposed, hand closed, lifted,
carried) through the joint servos, one tracked path under full physics (``Drive.tracked``),
then the hand opens as below. "velocity", as the thesis's GUI did (section 7.4.3), one command
per Portal cycle:
1. starting position: ``Odin/GUI/paths/grasp_initial.txt`` -> one Set Position of every link;
2. position path: ``grasp_approach.txt`` refined once by "double path precision", one Set
   Position per cycle: the open hand comes beside the can, palm towards it;
3. motor velocities: the fingers close (their motors' maximum torque is limited so that they
   stop on the can and squeeze it), then the arm lifts (ForeArm) and carries (Shoulder), then
   the fingers open slowly and the can drops to the floor.

World: table 10.2 (contacts, 40 steps of 1 ms per cycle, 25 Hz, gravity -9.81, surface layer
0.001 m) with the damping read per second (see EXPERIMENTS.md), ODE's exact solver (dWorldStep:
QuickStep lets the 25-body chain sag), infinite friction, 4 contacts per pair, meshes
colliding clustered at 4 mm (``collision_mesh_tolerance``: the SAH hand's CAD links carry up
to 20k triangles each, and colliding with them as given cost more than half of every step
while the hand held the can; clustered, they stay within 2.7 mm of their surfaces, and mass
and the Viewer's picture keep the given meshes); the finger motors' torque is limited to
4 N m (Set Joint SET_PARAMETERS MAX_FORCE).

Outcome (summary.json): the can's height above the table while carried (its lowest point, tilt
included); how far it moves in the palm's frame from the lift's start (the hand has closed) and
from the carry's start until the hand opens, how much it sinks and tilts; when it leaves the
hand, searched over the whole run (``release``: its centre in the palm's frame more than
LEFT_HAND_M from where the carry started, for good), against free-fall bounds from the
opening; when the hand last touches it; when it reaches the floor, and that it ends there.
With frames, ``closeups.png``: six close-up
snapshots of the hand (approach done, closed, lifted, carried, opened, dropped), taken with
the Viewer's Set Camera and not counted among the numbered frames.
"""
from __future__ import annotations

import os
import pathlib

import numpy as np

import common

PROBLEM = "TX90_RHand_ICRA10_5PMD_TwoCan.xml"
ROBOT = "TX90 SAHand Right"
CAN = "can"
PALM = f"{ROBOT}/Palm"
TABLE_TOP = common.TABLE_TOP
FLOOR_TOP = common.FLOOR_TOP

PARAMETERS = {
    "can_mass_kg": 0.35,
    "can_radius_m": 0.0317,
    "can_length_m": 0.1206,
    "can_color": [0.85, 0.15, 0.1, 1.0],
    "can_position_m": [-0.30, 1.00, 0.5603],
    "finger_close_rad_s": -0.8,
    "finger_max_torque_N_m": 4.0,
    "close_s": 1.2,
    "lift_forearm_rad_s": -0.06,
    "lift_s": 2.5,
    "carry_shoulder_rad_s": 0.3,
    "carry_s": 2.6,
    "open_rad_s": 0.4,
    "open_s": 1.6,
    "fall_s": 1.0,
    "hold_s": 0.3,
    "tracked_acceleration_rad_s2": 0.5,
    "frame_every_cycles": 4,
    "double_precision": 1,
}
WORLD = {
    "contact_less": False, "steps_per_cycle": 40, "rate": 25.0, "step": 0.001,
    "gravity": [0.0, 0.0, -9.81], "linear_damping": 0.0005, "linear_damping_threshold": 0.0,
    "angular_damping": 0.0002, "angular_damping_threshold": 0.0,
    "contact_surface_layer": 0.001, "friction": -1.0, "max_contacts": 4, "free_run": True,
    "solver": 1, "collision_mesh_tolerance": 0.004,
}
CAMERA = common.Camera(eye=(0.45, 1.9, 1.2), target=(-0.40, 0.85, 0.5))

#: the hand's finger joints that close (flexion): Prox, Med, Dist of index, middle, ring, and
#: the thumb's.
FLEX = ("Thumb-Prox", "Thumb-Med", "Thumb-Dist", "Index-Prox", "Index-Med", "Index-Dist",
        "Mid-Prox", "Mid-Med", "Mid-Dist", "Ring-Prox", "Ring-Med", "Ring-Dist")


def motor_of(handle, link_name: str) -> str:
    key = f"{ROBOT}/{link_name}"
    return handle.motor_ids[handle.joint_keys.index(key)]


#: "tracked" (the arm follows its path files through the joint servos, issue 12) or
#: "velocity" (the thesis's GUI: a teleported position path, then velocity rows)
MODES = ("tracked", "velocity")


def run(frames: bool = True, out_root=None, mode: str = "tracked", viewer: bool = True,
        kinematic: bool = False) -> dict:
    """The grasp in ``mode``; with ``frames``, the Viewer's numbered frames and close-ups;
    ``viewer=False`` (no frames) runs it without a Viewer node (bench_experiments).
    ``kinematic`` (tracked mode only): the arm and the palm under the kinematic drive
    (KINEMATIC_LINKS), the fingers dynamic; the summary goes to ``grasp_kinematic``."""
    if mode not in MODES:
        raise common.ExperimentError(f"grasp mode {mode!r}: choose from {', '.join(MODES)}")
    if kinematic and mode != "tracked":
        raise common.ExperimentError("the kinematic grasp runs in tracked mode only")
    from gui.core.paths import RADIANS, load_robot_path
    p = dict(PARAMETERS, mode=mode, kinematic=kinematic)
    # the thesis's grasp, as pinned: the arm's motors at zero speed between the commands (the
    # servos that hold a loaded robot let the opening hand release the can 0.16 s late)
    problem, plan = common.load_plan(common.EXAMPLES / PROBLEM, WORLD, hold_start=False)
    common.replace_step(plan, CAN, common.cylinder_can(
        CAN, (-0.35, 1.18, 0.6803), p["can_mass_kg"], p["can_color"], p["can_radius_m"],
        p["can_length_m"]))
    kwargs = {} if out_root is None else {"out_root": out_root}
    with common.Session("grasp_kinematic" if kinematic else "grasp", WORLD, CAMERA,
                        track={CAN, PALM}, frames=frames,
                        contacts=True, viewer=viewer, **kwargs) as s:
        s.client.execute(plan)
        handle = plan.robots[0]
        initial = load_robot_path(common.PATHS_DIR / "grasp_initial.txt", handle, RADIANS)
        s.client.set_position([(CAN, p["can_position_m"], (1.0, 0.0, 0.0, 0.0))])
        s.client.set_position(handle.situations(initial[0]))
        flex = [motor_of(handle, name) for name in FLEX]
        from odin_common.interface import JointParameter
        for motor in flex:  # fingers squeeze with a bounded torque
            s.client.set_joint_parameters(motor, [(JointParameter.MAX_FORCE, 1,
                                                   p["finger_max_torque_N_m"])])
        if kinematic:
            from odin_common.interface import ServoDrive
            s.client.set_drive([motor_of(handle, name) for name in KINEMATIC_LINKS],
                               ServoDrive.KINEMATIC)
        drive = Drive(s, handle, p, frames)
        drive.phase("start")
        s.cycle_and_frame()
        drive.advance(4)                                  # the can settles on the table
        if mode == "velocity":
            carry = drive.velocity_rows(problem, flex)
        else:
            carry = drive.tracked(problem, plan, flex)
        drive.open_and_drop(flex)
        probe = propagate_carry(s, *carry) if carry is not None else None
        s.finish()
        phases = dict(drive.phases)
        facts = analyse(s, phases)
        facts["carry_propagated"] = probe
        facts["phases_s"] = phases
        if drive.tracking is not None:
            facts["tracking"] = drive.tracking
        if kinematic:
            facts["kinematic_links"] = list(KINEMATIC_LINKS)
        if drive.closeups:
            facts["closeups"] = str(closeup_sheet(drive.closeups, s.out / "closeups.png")
                                    .relative_to(common.ROOT))
        common.write_summary(s, facts, p)
    return facts


class Drive:
    """The run's phases on a Session: cycles with frames, phase marks, close-ups."""

    def __init__(self, s: "common.Session", handle, p: dict, frames: bool):
        self.s, self.handle, self.p, self.frames = s, handle, p, frames
        self.every = p["frame_every_cycles"]
        self.per_s = 1.0 / (WORLD["step"] * WORLD["steps_per_cycle"])
        self.phases: list = []
        self.closeups: list = []
        self.tracking = None

    def advance(self, cycles: int, before=None) -> None:
        for _ in range(cycles):
            if before is not None:
                before()
            if (self.s.cycles + 1) % self.every == 0:
                self.s.cycle_and_frame()
            else:
                self.s.cycle(1)

    def phase(self, name: str, at: float = None) -> None:
        self.phases.append((name, round(self.s.sim_time if at is None else at, 6)))

    def closeup(self, label: str, subject: str = CAN) -> None:
        """A close-up snapshot of the hand (not one of the numbered frames)."""
        if self.frames:
            self.closeups.append((label, self.s.sim_time, take_closeup(self.s, label, subject)))

    def velocity_rows(self, problem, flex) -> tuple:
        """The thesis's driving: the approach as a position path (one Set Position per cycle),
        then velocity rows close the hand, lift, carry. Returns the carry's (shoulder motor,
        start, end) for ``propagate_carry``."""
        from gui.core.paths import RADIANS, load_robot_path, refine
        s, p, handle = self.s, self.p, self.handle
        approach = refine(load_robot_path(common.PATHS_DIR / "grasp_approach.txt", handle,
                                          RADIANS), p["double_precision"])
        self.phase("position_path")
        rows = iter(approach)
        self.advance(len(approach), lambda: s.client.set_position(
            handle.situations(next(rows))))
        self.closeup("approach done")
        self.phase("close")
        s.client.set_velocities(flex, [p["finger_close_rad_s"]] * len(flex))
        self.advance(int(p["close_s"] * self.per_s))
        self.closeup("closed")
        self.phase("lift")
        forearm, wrist = motor_of(handle, "ForeArm"), motor_of(handle, "Wrist")
        s.client.set_velocities([forearm, wrist], [p["lift_forearm_rad_s"],
                                                 -p["lift_forearm_rad_s"]])
        self.advance(int(p["lift_s"] * self.per_s))
        s.client.set_velocities([forearm, wrist], [0.0, 0.0])
        self.closeup("lifted")
        self.phase("carry")
        s.client.save_state("carry")    # propagated again at the end (carry_propagated)
        shoulder = motor_of(handle, "Shoulder")
        s.client.set_velocities([shoulder], [p["carry_shoulder_rad_s"]])
        started = dict(self.phases)["carry"]
        self.advance(int(p["carry_s"] * self.per_s))
        carried_at = s.sim_time
        s.client.set_velocities([shoulder], [0.0])
        self.advance(int(p["hold_s"] * self.per_s))
        self.closeup("carried")
        return shoulder, started, carried_at

    def tracked(self, problem, plan, flex) -> None:
        """The arm follows its path files through the servos (gui.core.execution): the
        approach file's rows, then the configurations the velocity rows would reach (hand
        closed, lifted, carried), as one tracked path, timed rest to rest within the joints'
        limits and the experiment's acceleration; the fingers' targets lie past the can, so
        their servos squeeze it under the finger motors' torque limit. The last target is
        held ``hold_s``. The servos' periods are the world's cycles (one Set Servo per
        cycle)."""
        from gui.core.execution import TrackingDefaults, execute_tracked, plan_tracking
        s, p = self.s, self.p
        solution = tracked_solution(problem, self.handle, p)
        defaults = TrackingDefaults(acceleration=p["tracked_acceleration_rad_s2"],
                                    settle=p["hold_s"])
        port = common.session_tracking_port(s, self.every)
        # from where the arm is: the path's first segment turns the thumb aside (below)
        _, trajectory, _ = plan_tracking(port, plan, solution, defaults, from_here=True)
        started = s.sim_time
        approach_rows = solution.waypoint_count - 3
        marks = [("position_path", 0, None), ("close", approach_rows, "approach done"),
                 ("lift", approach_rows + 1, "closed"), ("carry", approach_rows + 2, "lifted")]
        for name, index, _ in marks:
            self.phase(name, started + float(trajectory.times[index]))
        pending = [(started + float(trajectory.times[i]), label) for _, i, label in marks
                   if label] + [(started + trajectory.duration + p["hold_s"], "carried")]

        def progress(t: float, duration: float) -> None:
            while pending and s.sim_time >= pending[0][0] - 1e-9:
                self.closeup(pending.pop(0)[1])

        report = execute_tracked(port, plan, solution, defaults, progress=progress,
                                 from_here=True)
        while pending:
            self.closeup(pending.pop(0)[1])
        self.tracking = tracking_facts(report, self.handle)
        return None

    def open_and_drop(self, flex) -> None:
        """The fingers open at a constant speed (their servos released first) and the can
        drops."""
        s, p = self.s, self.p
        self.phase("open")
        s.client.call("set_servo", motors=list(flex), targets=[], release=True)
        s.client.set_velocities(flex, [p["open_rad_s"]] * len(flex))
        self.advance(int(p["open_s"] * self.per_s))
        s.client.set_velocities(flex, [0.0] * len(flex))
        self.closeup("opened", PALM)
        self.phase("fall")
        self.advance(int(p["fall_s"] * self.per_s))
        self.closeup("dropped")
        self.phase("end")


def tracked_solution(problem, handle, p: dict):
    """The tracked mode's plan: ``grasp_approach.txt`` read as a plan file (rows of the
    robot's movable joints, radians), then three waypoints: the hand closed (each flexing
    finger joint moved by ``finger_close_rad_s`` x ``close_s`` from open, within its range),
    lifted (ForeArm by ``lift_forearm_rad_s`` x ``lift_s``, Wrist by the opposite) and
    carried (Shoulder by ``carry_shoulder_rad_s`` x ``carry_s``): where the velocity rows
    would take the joints if nothing stopped them."""
    from gui.core.kautham.solutions import ROWS, RobotWaypoints, Solution, read_solution
    from gui.core.paths import RADIANS
    source = common.PATHS_DIR / "grasp_approach.txt"
    approach = read_solution(source, problem, ROBOT, RADIANS).paths[ROBOT]
    model = handle.instance.model
    column = {key.split("/", 1)[1]: k for k, key in enumerate(handle.joint_keys)}
    rows = approach.joints.copy()
    opposed = rows[-1].copy()
    rows[:, column["Thumb"]] = 0.0      # the thumb comes in beside the fingers, out of the
    closed = opposed.copy()             # can's way, and turns to face them there
    for name in FLEX:
        low, high = model.links[model.movable_links()[column[name]]].limits
        closed[column[name]] = np.clip(
            closed[column[name]] + p["finger_close_rad_s"] * p["close_s"], low, high)
    lifted = closed.copy()
    lifted[column["ForeArm"]] += p["lift_forearm_rad_s"] * p["lift_s"]
    lifted[column["Wrist"]] -= p["lift_forearm_rad_s"] * p["lift_s"]
    carried = lifted.copy()
    carried[column["Shoulder"]] += p["carry_shoulder_rad_s"] * p["carry_s"]
    joints = np.vstack([rows, opposed, closed, lifted, carried])
    lines = approach.lines + (0, 0, 0, 0)
    return Solution(str(source), ROWS, {ROBOT: RobotWaypoints(ROBOT, joints, None, lines)})


def tracking_facts(report, handle) -> dict:
    """The tracked run's report, the arm's six joints apart from the hand's (the fingers
    stop on the can, short of their targets, by design)."""
    arm = [k for k, name in enumerate(report.names) if name.split("/", 1)[1] in ARM]
    errors = np.abs(report.errors)
    last = errors[-1]
    return {
        "goal_error_rad": round(report.goal_error, 6),
        "tracking_error_max_rad": round(report.tracking_error_max, 6),
        "arm_goal_error_rad": round(float(last[arm].max()), 6),
        "arm_tracking_error_max_rad": round(float(errors[:, arm].max()), 6),
        "duration_s": round(report.duration_s, 6),
        "trajectory_s": round(report.trajectory_s, 6),
        "period_s": report.period_s,
        "real_time_factor": round(report.real_time_factor, 4),
        "collisions": len(report.collisions),
        "collision_pairs": [f"{c['first']} | {c['second']}" for c in report.collisions],
    }


#: the TX90's arm joints (the rest are the hand's)
ARM = ("Shoulder", "ForeArm", "Elbow", "Arm", "Wrist", "Tcp")
#: the kinematic grasp's links under the kinematic drive: the arm, the palm (the joint between
#: the TX90's flange and the hand) and the hand's joints that only place the fingers (the
#: thumb's turn, the fingers' spread): every joint but the flexing ones (FLEX). Those stay
#: dynamic: their servos' targets lie past the can, and kinematic fingers would drive through
#: it instead of squeezing it under the finger motors' torque limit. On the kinematic links,
#: each finger's three flexing joints stay in the LCP with the can they hold.
KINEMATIC_LINKS = ARM + ("Palm", "Thumb", "Thumb-Base", "Index-Base", "Mid-Base", "Ring-Base")


def propagate_carry(s: "common.Session", shoulder: str, started: float, ended: float) -> dict:
    """The carry once more, as a planner would run it: Propagate from the snapshot taken when
    the carry began, with the same shoulder speed, for as long; the world goes back where the
    run left it. The can must end where the run's own carry put it, bit for bit (the world is
    deterministic), and the figure is how fast the world propagates the held can."""
    probe = s.client.propagate(ended - started, start="carry",
                               motor_goals={shoulder: [PARAMETERS["carry_shoulder_rad_s"]]})
    s.wait_for_update()
    with s.record.lock:
        as_run = s.record.poses[round(ended, 6)][CAN]
    propagated = probe.states[CAN]
    return {"simulated_s": round(probe.steps * probe.step, 6), "wall_s": probe.wall_time,
            "rtf": round(probe.steps * probe.step / probe.wall_time, 4),
            "can_where_the_run_put_it": tuple(propagated[0]) == tuple(as_run[0])
            and tuple(propagated[1]) == tuple(as_run[1])}


#: close-ups: the camera looks at the can (or the palm) from outside the hand, from this
#: offset (m) in a frame turning with the arm: along the radius from the base's axis, along
#: the tangent (anticlockwise seen from above), up
CLOSEUP_OFFSET = (0.39, 0.20, 0.24)
#: m, the point the close-ups' radial direction starts from: 5 cm off the TX90's Shoulder axis,
#: which stands at the origin (forward kinematics, as pile.arm_reaches_pile finds it); kept so
#: that the close-ups look from where they always did
BASE_AXIS_XY = (0.05, 0.05)


def take_closeup(s: "common.Session", label: str, subject: str):
    import rospy
    from Services.srv import SetCamera
    s.wait_for_update()
    with s.record.lock:
        position = np.array(s.record.poses[round(s.sim_time, 6)][subject][0])
    radial = position[:2] - np.array(BASE_AXIS_XY)
    radial = np.array([*radial / np.linalg.norm(radial), 0.0])
    tangent = np.cross([0.0, 0.0, 1.0], radial)
    a, b, c = CLOSEUP_OFFSET
    eye = position + a * radial + b * tangent + np.array([0.0, 0.0, c])
    set_camera = rospy.ServiceProxy("/viewer/set_camera", SetCamera)
    set_camera(set_pose=True, eye=list(eye), target=list(position), up=[0.0, 0.0, 1.0])
    try:
        return s.snapshot_of_now(f"closeup_{len(os.listdir(s.frames_dir)):04d}.png")
    finally:
        set_camera(set_pose=True, eye=list(CAMERA.eye), target=list(CAMERA.target),
                   up=[0.0, 0.0, 1.0])


def closeup_sheet(closeups, out: pathlib.Path, columns: int = 3, width: int = 320):
    from PIL import Image, ImageDraw
    first = Image.open(closeups[0][2])
    height = int(round(first.height * width / first.width))
    rows = -(-len(closeups) // columns)
    sheet = Image.new("RGB", (columns * width, rows * height), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    for k, (label, at, path) in enumerate(closeups):
        x, y = (k % columns) * width, (k // columns) * height
        sheet.paste(Image.open(path).convert("RGB").resize((width, height), Image.LANCZOS),
                    (x, y))
        text = f"{label}  t = {at:.2f} s"
        draw.rectangle([x, y, x + 8 + 7 * len(text), y + 16], fill=(255, 255, 255))
        draw.text((x + 4, y + 2), text, fill=(0, 0, 0))
    sheet.save(out)
    return out


#: the can has left the hand once its centre, in the palm's frame, is further than this (m) from
#: where it was held when the carry started: 15 mm is above the most it moves there while the
#: hand holds it (10.7 mm from the lift's start on, 3.0 mm during the carry) and under half
#: the can's radius (31.7 mm)
LEFT_HAND_M = 0.015
GRAVITY = 9.81
#: how much later than free fall from the opening (s) the can may leave the hand and reach the
#: floor: both are seen at cycle ends (up to one 40 ms cycle late) and the hand still touches
#: the can in the first cycle of the opening (one more)
FALL_SLACK_S = 2 * WORLD["steps_per_cycle"] * WORLD["step"]
#: tracked mode: one cycle more (the fingers' servos, far from their targets past the can,
#: squeezed it at their torque limit to the end; it left 0.12 s after the opening, 4 ms past
#: FALL_SLACK_S)
TRACKED_FALL_SLACK_S = FALL_SLACK_S + WORLD["steps_per_cycle"] * WORLD["step"]


def release(t: np.ndarray, drift: np.ndarray, can_z: np.ndarray, bottom: np.ndarray,
            opens_at: float) -> dict:
    """When the can leaves the hand, searched over the whole run: the sample after the last one
    at which its centre is within LEFT_HAND_M of its held place in the palm's frame (``drift``
    per sample); since when it had been there without a break; when its lowest point reaches
    the floor. A can that slipped out while carried leaves before the opening; one that stays
    in the hand has no release.

    Bounds, from free fall (the can starts from rest in the palm's frame when the opening
    starts): it cannot leave the LEFT_HAND_M ball before sqrt(2 (LEFT_HAND_M - drift) / g)
    (drift: how far from its held place it already is), unless it is thrown or already loose;
    its centre reaches the height of a can lying on the floor (one radius above it) no later
    than sqrt(2 (z - floor - radius) / g) after the opening if nothing holds it, and the can's
    lowest point reaches the floor before its centre gets that low."""
    inside = np.nonzero(drift <= LEFT_HAND_M)[0]
    if not len(inside) or inside[-1] == len(t) - 1:
        return {"left_hand_at_s": None}
    last = int(inside[-1])
    first = last
    while first > 0 and drift[first - 1] <= LEFT_HAND_M:
        first -= 1                                     # the start of that unbroken hold
    k_open = int(np.searchsorted(t, opens_at))
    earliest = float(np.sqrt(2 * max(LEFT_HAND_M - drift[k_open], 0.0) / GRAVITY))
    radius = PARAMETERS["can_radius_m"]
    latest_floor = float(np.sqrt(2 * max(can_z[k_open] - FLOOR_TOP - radius, 0.0) / GRAVITY)) \
        + FALL_SLACK_S
    after = np.arange(last + 1, len(t))
    on_floor = after[bottom[after] <= FLOOR_TOP + 0.005]
    floor_k = int(on_floor[0]) if len(on_floor) else None
    falling = can_z[last + 1:(floor_k if floor_k is not None else len(t)) + 1]
    return {
        "in_hand_from_s": float(t[first]),
        "left_hand_at_s": float(t[last + 1]),
        "left_hand_after_opening_s": round(float(t[last + 1] - opens_at), 6),
        "earliest_free_fall_exit_s": round(earliest, 4),
        "on_floor_at_s": float(t[floor_k]) if floor_k is not None else None,
        "on_floor_after_opening_s": round(float(t[floor_k] - opens_at), 6)
        if floor_k is not None else None,
        "latest_on_floor_after_opening_s": round(latest_floor, 4),
        # from leaving the hand to the floor its centre never rises (by more than 1 mm)
        "falls_without_rising": bool(np.all(np.diff(falling) <= 0.001)),
    }


def analyse(s: "common.Session", phases: dict) -> dict:
    from odin_common.rotations import quaternion_to_matrix
    t, poses = s.trajectories(CAN, PALM)
    (can, can_q), (palm, palm_q) = poses[CAN], poses[PALM]
    n = len(t)
    # the can's centre in the palm's frame
    rel = np.array([quaternion_to_matrix(q).T @ (c - p) for c, p, q in zip(can, palm, palm_q)])
    carried = (t >= phases["carry"]) & (t < phases["open"])
    held = (t >= phases["lift"]) & (t < phases["open"])     # the hand closed, not yet opening

    def drift_from(phase: str) -> np.ndarray:
        return np.linalg.norm(rel - rel[np.searchsorted(t, phases[phase])], axis=1)

    # slip in the hand: the can's centre in the palm's frame, from the lift's start (the hand
    # has closed) and from the carry's start, to the hand's opening
    drift = drift_from("lift")
    slip_held = float(drift[held].max())
    slip_carried = float(drift_from("carry")[carried].max())
    # sinking: the can's height relative to the palm's origin, in the world, lost since the lift
    # started (gravity pulling it down through the grip)
    dz = (can[:, 2] - palm[:, 2]) - (can[:, 2] - palm[:, 2])[np.searchsorted(t, phases["lift"])]
    sank = float(max(0.0, -dz[held].min()))
    # the can's lowest point (its tilt counts: a cylinder's lowest rim point is h/2 cos(tilt)
    # + r sin(tilt) below its centre)
    up = np.array([quaternion_to_matrix(q)[2, 2] for q in can_q])
    tilt = np.arccos(np.clip(np.abs(up), 0.0, 1.0))
    radius, half_length = PARAMETERS["can_radius_m"], PARAMETERS["can_length_m"] / 2
    bottom = can[:, 2] - (half_length * np.cos(tilt) + radius * np.sin(tilt))
    left = release(t, drift_from("carry"), can[:, 2], bottom, phases["open"])
    with s.record.lock:
        pairs = dict(s.record.contact_pairs)
    hand = f"{ROBOT}/"
    touched = [tc for tc, listed in pairs.items() if any(
        CAN in (a, b) and hand in a + b for a, b in listed)]
    last_touch = max(touched) if touched else None
    samples = {}
    for name, at in phases.items():
        k = min(int(np.searchsorted(t, at)), n - 1)
        samples[name] = {"t_s": float(t[k]), "can_m": [round(float(v), 4) for v in can[k]],
                         "palm_m": [round(float(v), 4) for v in palm[k]],
                         "can_in_palm_frame_m": [round(float(v), 4) for v in rel[k]]}
    facts = {
        "at_phase_starts": samples,
        "outcome": {
            "can_height_above_table_while_carried_m": {
                "min": round(float(bottom[carried].min() - TABLE_TOP), 4),
                "max": round(float(bottom[carried].max() - TABLE_TOP), 4),
                "mean": round(float(bottom[carried].mean() - TABLE_TOP), 4)},
            "can_moved_while_carried_m": round(float(np.linalg.norm(
                can[carried][-1] - can[carried][0])), 4),
            "max_slip_in_hand_before_opening_m": round(slip_held, 4),
            "max_slip_in_hand_while_carried_m": round(slip_carried, 4),
            "can_sank_in_hand_before_opening_m": round(sank, 4),
            "can_max_tilt_while_held_deg": round(float(np.degrees(tilt[held].max())), 1),
            "lift_starts_at_s": phases["lift"],
            "hand_opens_at_s": phases["open"],
            **left,
            "hand_last_touches_can_at_s": last_touch,
            "can_final_position_m": [round(float(v), 4) for v in can[-1]],
            "can_on_floor_at_end": bool(can[-1, 2] < 0.1),
        },
        "contacts": s.contact_rates(),
        # poses come from ~world_update; a message lost under load leaves a cycle unsampled
        "world_update_samples": {"cycles": s.cycles + 1, "recorded": int(n)},
    }
    return facts


#: the kinematic grasp's arm and palm do not give way when the hand opens: the can rolls down
#: the palm's face instead of dropping clear (measured: the palm touches it up to one cycle after
#: it counts as out of the hand, and it reaches the floor 0.48-0.52 s after the opening where free
#: fall takes 0.46 s); those two checks allow that much (one cycle and two) and no more
RIGID_ARM_TOUCH_S = WORLD["steps_per_cycle"] * WORLD["step"]
RIGID_ARM_FLOOR_S = 2 * WORLD["steps_per_cycle"] * WORLD["step"]


def release_checks(o: dict, slack: float = FALL_SLACK_S, rigid_arm: bool = False) -> dict:
    """What the release must show, each true or false (the test asserts them one by one);
    ``slack``: how much later than free fall it may leave the hand; ``rigid_arm``: the arm
    and palm under the kinematic drive (RIGID_ARM_TOUCH_S, RIGID_ARM_FLOOR_S)."""
    left = o.get("left_hand_at_s")
    if left is None:
        return {"the can leaves the hand": False}
    if rigid_arm:
        return _rigid_arm_release(o, slack, left)
    return {
        "the can leaves the hand": True,
        "it is in the hand from before the lift on": o["in_hand_from_s"] <= o["lift_starts_at_s"],
        "it leaves no sooner than a can dropped at the opening could":
            o["left_hand_after_opening_s"] >= o["earliest_free_fall_exit_s"],
        f"it leaves within {slack:.2f} s of that":
            o["left_hand_after_opening_s"] <= o["earliest_free_fall_exit_s"] + slack,
        "the hand still touches it after the opening starts, not after it left":
            o["hand_last_touches_can_at_s"] is not None
            and o["hand_opens_at_s"] < o["hand_last_touches_can_at_s"] <= left,
        "it only goes down until it reaches the floor": o["falls_without_rising"]
            and o["on_floor_at_s"] is not None,
        "it reaches the floor no later than free fall allows":
            o["on_floor_at_s"] is not None
            and o["on_floor_after_opening_s"] <= o["latest_on_floor_after_opening_s"],
    }


def _rigid_arm_release(o: dict, slack: float, left: float) -> dict:
    """release_checks for the kinematic grasp: the same but for the palm's last touch and the
    time to the floor (the can rolls off the palm)."""
    checks = release_checks(o, slack)
    del checks["the hand still touches it after the opening starts, not after it left"]
    del checks["it reaches the floor no later than free fall allows"]
    checks.update({
        "the hand still touches it after the opening starts, at most a cycle after it left "
        "(it rolls off the rigid palm)":
            o["hand_last_touches_can_at_s"] is not None
            and o["hand_opens_at_s"] < o["hand_last_touches_can_at_s"] <= left + RIGID_ARM_TOUCH_S,
        "it reaches the floor at most two cycles later than free fall allows (it rolls off "
        "the rigid palm)":
            o["on_floor_at_s"] is not None and o["on_floor_after_opening_s"]
            <= o["latest_on_floor_after_opening_s"] + RIGID_ARM_FLOOR_S,
    })
    return checks


def verdict(facts: dict) -> tuple:
    o = facts["outcome"]
    h = o["can_height_above_table_while_carried_m"]
    tracked = "tracking" in facts
    checks = release_checks(o, TRACKED_FALL_SLACK_S if tracked else FALL_SLACK_S,
                            rigid_arm="kinematic_links" in facts)
    ok = (all(checks.values()) and h["min"] > 0.02 and o["can_on_floor_at_end"]
          and o["can_moved_while_carried_m"] > 0.3)
    lines = [f"can carried {h['min']:.3f}..{h['max']:.3f} m above the table, moved "
             f"{o['can_moved_while_carried_m']:.2f} m; slip in hand from the lift to the "
             f"opening {o['max_slip_in_hand_before_opening_m'] * 1000:.1f} mm (while carried "
             f"{o['max_slip_in_hand_while_carried_m'] * 1000:.1f} mm), sank "
             f"{o['can_sank_in_hand_before_opening_m'] * 1000:.1f} mm, tilted up to "
             f"{o['can_max_tilt_while_held_deg']} deg",
             f"hand opens at {o['hand_opens_at_s']} s; the can, in the hand from "
             f"{o.get('in_hand_from_s')} s, leaves the hand at {o.get('left_hand_at_s')} s "
             f"({o.get('left_hand_after_opening_s')} s after the opening; free fall: no sooner "
             f"than {o.get('earliest_free_fall_exit_s')} s), the hand last touches it at "
             f"{o.get('hand_last_touches_can_at_s')} s, it is on the floor at "
             f"{o.get('on_floor_at_s')} s ({o.get('on_floor_after_opening_s')} s after the "
             f"opening; free fall: by {o.get('latest_on_floor_after_opening_s')} s); final "
             f"position {o['can_final_position_m']}",
             "release: " + ", ".join(f"{k}: {v}" for k, v in checks.items()),
             f"contacts: {facts['contacts']}"]
    return ok, lines
