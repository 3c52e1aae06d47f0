"""Experiment 2 (thesis 10.2, table 10.2): collisions with contacts.

Scene: ``legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml`` as the GUI loads it; its two
cans, stacked on the table at z 0.56 / 0.68 m, are made movable bodies (the loader builds 2012
scene objects as static geometry): cylinder primitives of the mesh's size (radius 0.0317 m,
length 0.1206 m), 0.35 kg each. The third can ("cangoal") stays static geometry.

The pile is moved by Set Position to the table's corner nearest to the robot, within the arm's
reach (-0.30, 1.00), as the thesis "positioned the cans by simply changing their position".
The robot is put in a starting pose by Set Position of every link (forward kinematics of a
configuration found by inverse kinematics: fingers pointing away from the robot at the height
of the bottom can, 0.14 rad beside the pile). After the first cycle (its frame shows the start)
its base motor ("Shoulder") turns at 0.1 rad/s into the pile, from 0.04 s until it is stopped
at 3.52 s (cycle 88, 3.5 s after the start rounded to a cycle); the run ends at 4 s (the floor
slab of the scene ends at x = 0 and a can rolling past it would fall for ever). The cans are
knocked down, fall off the table under gravity, hit the floor and bounce (bounce 0.5 in Set
World).

World: table 10.2 adapted to SI (contacts, 40 steps of 1 ms per cycle, 25 Hz, gravity
(0, 0, -9.81), surface layer 0.001 m), the damping values read per second (see
docs/EXPERIMENTS.md), ODE's exact solver (dWorldStep, the thesis's) so that the arm does not
sag, bounce 0.5 above 0.1 m/s.

Outcome (summary.json): when the arm reaches the pile by the geometry (``arm_reaches_pile``:
the arm's meshes turned about the Shoulder axis into the cans' cylinders, without the
collision engine) and when the first hand-can contact is reported (within CONTACT_WINDOW_S of
it); when each can falls (after that contact); how far each can moved (m), whether it hit the
floor and bounced; contact counts per simulated second.
"""
from __future__ import annotations

import math

import numpy as np

import common
import ik

PROBLEM = "TX90_RHand_ICRA10_5PMD_TwoCan.xml"
ROBOT = "TX90 SAHand Right"
CANS = ("can", "can_2")
PALM_LINK = 7
FLOOR_TOP = common.FLOOR_TOP

PARAMETERS = {
    "can_mass_kg": 0.35,
    "can_radius_m": 0.0317,
    "can_length_m": 0.1206,
    "can_centres_m": {"can": [-0.35, 1.18, 0.6815], "can_2": [-0.35, 1.18, 0.5606]},
    "pile_moved_to_m": {"can": [-0.30, 1.00, 0.6815], "can_2": [-0.30, 1.00, 0.5606]},
    "can_colors": {"can": [0.85, 0.15, 0.1, 1.0], "can_2": [0.15, 0.35, 0.85, 1.0]},
    "start_angle_offset_rad": -0.14,
    "hand_radius_m": 1.05,
    "hand_height_m": 0.58,
    "base_speed_rad_s": 0.1,
    "base_turns_s": 3.5,
    "duration_s": 4.0,
    "frame_every_cycles": 4,
}
WORLD = {
    "contact_less": False, "steps_per_cycle": 40, "rate": 25.0, "step": 0.001,
    "gravity": [0.0, 0.0, -9.81], "linear_damping": 0.0005, "linear_damping_threshold": 0.0,
    "angular_damping": 0.0002, "angular_damping_threshold": 0.0,
    "contact_surface_layer": 0.001, "bounce": 0.5, "bounce_velocity": 0.1, "solver": 1,
    "free_run": True,
}
CAMERA = common.Camera(eye=(0.55, 0.35, 1.25), target=(-0.30, 1.05, 0.35))


def starting_pose(handle, can_xy, p) -> np.ndarray:
    """Joint values: the fingertips at ``hand_radius_m`` from the base axis, the row of fingers
    vertical, ``start_angle_offset_rad`` from the pile (negative: clockwise of it, since a
    positive motor goal turns the base anticlockwise, like a positive joint value)."""
    from make_grasp_paths import hand_target
    model, base = handle.instance.model, handle.instance.base_pose
    angle = math.atan2(can_xy[1], can_xy[0]) + p["start_angle_offset_rad"]
    point = np.array([p["hand_radius_m"] * math.cos(angle), p["hand_radius_m"] * math.sin(angle),
                      p["hand_height_m"]])
    offset = np.eye(4)
    offset[:3, 3] = (0.0, -0.02, 0.23)     # between the middle fingers' last phalanges
    q = handle.home.copy()
    q[:6] = [angle, 0.9, 0.9, 0.0, 1.0, 0.0]
    q, position_error, angle_error = ik.solve(model, base, q, PALM_LINK, offset,
                                              hand_target(point), list(range(6)))
    if position_error > 1e-3 or angle_error > 1e-2:
        raise common.ExperimentError(f"no starting pose: IK off by {position_error:.3g} m, "
                                     f"{angle_error:.3g} rad")
    return q


#: points on the arm's surface are compared with the cans' cylinders at most this far apart (m):
#: 0.5 mm, 5 ms of the hand's travel at 1.05 m from the axis and 0.1 rad/s
SURFACE_SPACING_M = 0.0005


def arm_reaches_pile(plan, handle, q: np.ndarray, p: dict) -> dict:
    """The base turn (rad) after which the arm's surface first enters each can's cylinder at
    its place on the table, from the link meshes placed by forward kinematics of ``q`` and the
    cans' size, without the collision engine. Turning the Shoulder joint moves every link
    behind it rigidly about the joint's axis (found by forward kinematics of ``q`` and of ``q``
    with the Shoulder 1 mrad further); a point of the surface at distance r from that axis
    enters a can's circle (centre at distance d, radius R, seen along the axis) where the law of
    cosines puts it, a turn of (angle of the can - arccos((r^2 + d^2 - R^2) / (2 r d)) - the
    point's angle), provided its height is within the can's. The cans are taken upright and
    still at ``pile_moved_to_m``."""
    model, base = handle.instance.model, handle.instance.base_pose
    shoulder = handle.joint_keys.index(f"{ROBOT}/Shoulder")
    link = model.movable_links()[shoulder]
    turned = np.array(q, float)
    turned[shoulder] += 1e-3
    before, after = model.link_poses(base, q)[link], model.link_poses(base, turned)[link]
    motion = after @ np.linalg.inv(before)           # the rigid turn of 1 mrad, world frame
    axis = np.array([motion[2, 1] - motion[1, 2], motion[0, 2] - motion[2, 0],
                     motion[1, 0] - motion[0, 1]])
    axis /= np.linalg.norm(axis)                      # anticlockwise about +axis as q grows
    if axis[2] < 0.9999:
        raise common.ExperimentError(f"the Shoulder turns about {axis.round(4).tolist()}, "
                                     "not the vertical the cans stand along")
    centre = np.linalg.lstsq((np.eye(3) - motion[:3, :3])[:2, :2], motion[:2, 3],
                             rcond=None)[0]           # where the axis crosses z = 0
    meshes = common.mesh_bodies(plan)
    moving = [body for body, pose_before, pose_after in zip(
        handle.bodies, model.link_poses(base, q), model.link_poses(base, turned))
        if not np.allclose(pose_before, pose_after)]
    situations = {body: (position, quaternion) for body, position, quaternion
                  in handle.situations(q)}
    radius, half = p["can_radius_m"], p["can_length_m"] / 2
    first = {}
    for name in CANS:
        cx, cy, cz = p["pile_moved_to_m"][name]
        offset = np.array([cx, cy]) - centre
        d, can_angle = float(np.hypot(*offset)), math.atan2(offset[1], offset[0])
        best = (math.inf, None)
        for body in moving:
            vertices, triangles = meshes[body.body_id]
            corners = common.in_world(vertices, *situations[body.body_id])
            tri = corners[triangles]
            r_tri = np.hypot(tri[..., 0] - centre[0], tri[..., 1] - centre[1])
            near = (tri[..., 2].max(1) >= cz - half) & (tri[..., 2].min(1) <= cz + half) & \
                (r_tri.max(1) >= d - radius - 0.01) & (r_tri.min(1) <= d + radius + 0.01)
            if not near.any():
                continue
            points = common.surface_points(corners, triangles[near], SURFACE_SPACING_M)
            r = np.hypot(points[:, 0] - centre[0], points[:, 1] - centre[1])
            ok = (np.abs(points[:, 2] - cz) <= half) & (np.abs(r - d) <= radius)
            if not ok.any():
                continue
            r, angle = r[ok], np.arctan2(points[ok, 1] - centre[1], points[ok, 0] - centre[0])
            inside = np.hypot(points[ok, 0] - cx, points[ok, 1] - cy) <= radius
            if inside.any():
                raise common.ExperimentError(f"{body.body_id} starts inside {name}")
            spread = np.arccos(np.clip((r ** 2 + d ** 2 - radius ** 2) / (2 * r * d), -1, 1))
            turn = np.mod(can_angle - spread - angle, 2 * math.pi)
            k = int(np.argmin(turn))
            if turn[k] < best[0]:
                best = (float(turn[k]), body.body_id)
        first[name] = {"turn_rad": round(best[0], 6), "link": best[1]}
    return {"axis_at_m": [round(float(v), 6) for v in centre], "cans": first,
            "spacing_m": SURFACE_SPACING_M}


def run(frames: bool = True) -> dict:
    p = dict(PARAMETERS)
    problem, plan = common.load_plan(common.EXAMPLES / PROBLEM, WORLD)
    for name in CANS:
        common.replace_step(plan, name, common.cylinder_can(
            name, p["can_centres_m"][name], p["can_mass_kg"], p["can_colors"][name],
            p["can_radius_m"], p["can_length_m"]))
    with common.Session("pile", WORLD, CAMERA, track=set(CANS), frames=frames,
                        contacts=True) as s:
        s.client.execute(plan)
        handle = plan.robots[0]
        s.client.set_position([(name, p["pile_moved_to_m"][name], (1.0, 0.0, 0.0, 0.0))
                               for name in CANS])
        q = starting_pose(handle, p["pile_moved_to_m"]["can"], p)
        reach = arm_reaches_pile(plan, handle, q, p)
        s.client.set_position(handle.situations(q))
        shoulder = handle.motor_ids[handle.joint_keys.index(f"{ROBOT}/Shoulder")]
        per_s = 1.0 / (WORLD["step"] * WORLD["steps_per_cycle"])
        every = p["frame_every_cycles"]
        s.cycle_and_frame()
        s.client.set_velocities([shoulder], [p["base_speed_rad_s"]])
        turn_started = s.sim_time                      # 0.04 s: after the first cycle's frame
        total = int(round(p["duration_s"] * per_s))
        stop_at = int(round(p["base_turns_s"] * per_s))
        while s.cycles < total:
            if s.cycles == stop_at:
                s.client.set_velocities([shoulder], [0.0])
            if (s.cycles + 1) % every == 0:
                s.cycle_and_frame()
            else:
                s.cycle(1)
        s.finish()
        facts = analyse(s, p, reach, turn_started)
        facts["starting_configuration_rad"] = [round(float(v), 6) for v in q[:6]]
        common.write_summary(s, facts, p)
    return facts


#: a can has fallen once its centre is this far below its place on the pile (m): rocking on
#: the pile moves it up and down by under 2 mm; toppled onto the table it is 29 mm (bottom can)
#: or more (top can) lower
FALL_M = 0.01
#: the first hand/arm-can contact is reported within this window (s) of the moment the
#: geometry says the arm reaches the pile (measured: 37 ms after it): contacts are those of
#: each cycle's last step, so a touch that begins inside a 40 ms cycle shows at its end (0 to
#: +40 ms); and the pile does not stand still before the hit (it rocks from the first cycle:
#: before the hand comes the bottom can's centre strays up to 3.5 mm from its place, the top
#: one's 9.0 mm; 1 mm is 9.5 ms of the hand's travel at 1.05 m from the axis and 0.1 rad/s):
#: one more cycle either way for the bottom can, which the fingers reach at the same turn as
#: the top one and which is the first reported
CONTACT_WINDOW_S = (-0.04, 0.08)


def analyse(s: "common.Session", p: dict, reach: dict, turn_started: float) -> dict:
    with s.record.lock:
        pairs = dict(s.record.contact_pairs)
    robot = f"{ROBOT}/"
    hand_cycles = sorted(t for t, listed in pairs.items() if any(
        (a in CANS and b.startswith(robot)) or (b in CANS and a.startswith(robot))
        for a, b in listed))
    first_contact = hand_cycles[0] if hand_cycles else None
    first_pairs = sorted(f"{a} & {b}" for a, b in pairs.get(first_contact, [])
                         if (a in CANS) != (b in CANS) and robot in a + b)
    first_turn = min(c["turn_rad"] for c in reach["cans"].values())
    reaches_at = round(turn_started + first_turn / p["base_speed_rad_s"], 6)
    lag = round(first_contact - reaches_at, 6) if first_contact is not None else None
    cans = {}
    for name in CANS:
        t, xyz, _ = s.trajectory(name)
        place = np.array(p["pile_moved_to_m"][name])
        fallen = np.nonzero(xyz[:, 2] < place[2] - FALL_M)[0]
        falls_at = float(t[fallen[0]]) if len(fallen) else None
        before = t < first_contact if first_contact is not None else np.ones(len(t), bool)
        rocking = float(np.hypot(*(xyz[before, :2] - place[:2]).T).max()) if before.any() \
            else None
        bottom = xyz[:, 2] - p["can_length_m"] / 2   # the lowest point when upright
        over_floor = (xyz[:, 0] <= 0.0) & (xyz[:, 0] >= -1.5) & (xyz[:, 1] >= 0.0) \
            & (xyz[:, 1] <= 2.5)
        # on the floor slab: centre within a can's half-length (+ 3 cm) of its top
        on_floor = over_floor & (xyz[:, 2] < FLOOR_TOP + 0.09) & (xyz[:, 2] > FLOOR_TOP)
        first = int(np.argmax(on_floor)) if on_floor.any() else None
        bounced = False
        if first is not None:
            after = xyz[first:, 2]
            low = np.minimum.accumulate(after)
            bounced = bool((after - low).max() > 0.01)
        cans[name] = {
            "arm_enters_its_cylinder_at_s": round(
                turn_started + reach["cans"][name]["turn_rad"] / p["base_speed_rad_s"], 6),
            "first_arm_link_to_enter": reach["cans"][name]["link"],
            "rocking_before_the_hand_m": round(rocking, 4) if rocking is not None else None,
            "falls_at_s": falls_at,
            "falls_after_the_hand_touches_the_pile": bool(
                falls_at is not None and first_contact is not None and falls_at > first_contact),
            "moved_m": round(float(np.linalg.norm(xyz[-1] - xyz[0])), 4),
            "start_m": [round(float(v), 4) for v in xyz[0]],
            "end_m": [round(float(v), 4) for v in xyz[-1]],
            "hit_ground": first is not None,
            "hit_ground_at_s": float(t[first]) if first is not None else None,
            "bounced": bounced,
            "knocked_off_the_table": bool(xyz[:, 2].min() < 0.5 - 0.1),
            "fell_past_the_floor_edge": bool(xyz[-1, 2] < FLOOR_TOP - 0.2),
            "lowest_bottom_z_m": round(float(bottom.min()), 4),
            "z_every_cycle_m": [round(float(v), 4) for v in xyz[:, 2]],
        }
    low, high = CONTACT_WINDOW_S
    return {"outcome": {
        "cans": cans,
        "base_turns_from_s": round(turn_started, 6),
        "arm_reaches_pile_at_s": reaches_at,
        "first_hand_contact_s": first_contact,
        "first_hand_contact_pairs": first_pairs,
        "first_hand_contact_lag_s": lag,
        "contact_window_s": [low, high],
        "hand_contact_when_the_arm_reaches_the_pile": bool(
            lag is not None and low - 1e-9 <= lag <= high + 1e-9),
        "cycles_with_hand_can_contacts": len(hand_cycles),
    }, "contacts": s.contact_rates(), "geometry": reach}


def verdict(facts: dict) -> tuple:
    """(outcome held, one line per fact) for run.py; the test asserts the same facts. The
    hand's first contact with the pile comes when the geometry says the turning arm reaches it;
    each can falls after it; both are knocked off the table, land on the floor slab and bounce
    (a can thrown past the slab's edge at x = 0 is reported as such)."""
    o = facts["outcome"]
    cans = o["cans"]
    ok = o["hand_contact_when_the_arm_reaches_the_pile"] and all(
        c["falls_after_the_hand_touches_the_pile"] and c["moved_m"] > 0.2
        and c["knocked_off_the_table"] and c["hit_ground"] and c["bounced"]
        and not c["fell_past_the_floor_edge"] for c in cans.values())
    lines = [f"the arm reaches the pile at {o['arm_reaches_pile_at_s']} s (geometry, turning "
             f"from {o['base_turns_from_s']} s); first hand contact reported at "
             f"{o['first_hand_contact_s']} s ({', '.join(o['first_hand_contact_pairs'])}), "
             f"{o['first_hand_contact_lag_s']} s later (window {o['contact_window_s']} s)"]
    lines += [f"{name}: falls at {c['falls_at_s']} s, moved {c['moved_m']:.3f} m, knocked off "
              f"the table: {c['knocked_off_the_table']}, hit the floor: {c['hit_ground']} "
              f"(at {c['hit_ground_at_s']} s), bounced: {c['bounced']}, fell past the floor's "
              f"edge: {c['fell_past_the_floor_edge']}" for name, c in cans.items()]
    lines.append(f"contacts: {facts['contacts']}")
    return ok, lines
