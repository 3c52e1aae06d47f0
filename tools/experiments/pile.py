"""Experiment 2 (thesis 10.2, table 10.2): collisions with contacts.

Scene: ``legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml`` as the GUI loads it; its two
cans, stacked on the table at z 0.56 / 0.68 m, are made movable bodies (the loader builds 2012
scene objects as static geometry): cylinder primitives of the mesh's size (radius 0.0317 m,
length 0.1206 m), 0.35 kg each. The third can ("cangoal") stays static geometry.

The pile is moved by Set Position to the table's corner nearest to the robot, within the arm's
reach (-0.30, 1.00), as the thesis "positioned the cans by simply changing their position".
The robot is put in a starting pose by Set Position of every link (forward kinematics of a
configuration found by inverse kinematics: fingers pointing away from the robot at the height
of the bottom can, 0.14 rad beside the pile). Then its base motor ("Shoulder") turns at
0.1 rad/s into the pile; it is stopped after 3.5 s; the run ends at 4 s (the floor slab of the scene ends at x = 0 and
a can rolling past it would fall for ever). The cans are knocked down, fall off the
table under gravity, hit the floor and bounce (bounce 0.5 in Set World).

World: table 10.2 adapted to SI (contacts, 40 steps of 1 ms per cycle, 25 Hz, gravity
(0, 0, -9.81), surface layer 0.001 m), the damping values read per second (see
docs/EXPERIMENTS.md), ODE's exact solver (dWorldStep, the thesis's) so that the arm does not
sag, bounce 0.5 above 0.1 m/s.

Outcome (summary.json): how far each can moved (m), whether it hit the floor and bounced,
contact counts per simulated second.
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
FLOOR_TOP = -0.006   # m, the ICRA09 scene's floor (a 10 mm slab centred at z = -0.011)

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


def run(frames: bool = True) -> dict:
    p = dict(PARAMETERS)
    problem, plan = common.load_plan(common.EXAMPLES / PROBLEM)
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
        s.client.set_position(handle.situations(q))
        shoulder = handle.motor_ids[handle.joint_keys.index(f"{ROBOT}/Shoulder")]
        per_s = 1.0 / (WORLD["step"] * WORLD["steps_per_cycle"])
        every = p["frame_every_cycles"]
        s.cycle_and_frame()
        s.client.set_velocity([shoulder], [p["base_speed_rad_s"]])
        total = int(round(p["duration_s"] * per_s))
        stop_at = int(round(p["base_turns_s"] * per_s))
        while s.cycles < total:
            if s.cycles == stop_at:
                s.client.set_velocity([shoulder], [0.0])
            if (s.cycles + 1) % every == 0:
                s.cycle_and_frame()
            else:
                s.cycle(1)
        s.finish()
        facts = analyse(s, p)
        facts["starting_configuration_rad"] = [round(float(v), 6) for v in q[:6]]
        common.write_summary(s, facts, p)
    return facts


def analyse(s: "common.Session", p: dict) -> dict:
    cans = {}
    for name in CANS:
        t, xyz, _ = s.trajectory(name)
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
    return {"outcome": {"cans": cans}, "contacts": s.contact_rates()}


def verdict(facts: dict) -> tuple:
    """Both cans knocked off the table; at least one lands on the floor slab and bounces
    (a can thrown past the slab's edge at x = 0 is reported as such)."""
    cans = facts["outcome"]["cans"]
    ok = all(c["moved_m"] > 0.2 and c["knocked_off_the_table"] for c in cans.values()) and any(
        c["hit_ground"] and c["bounced"] for c in cans.values())
    lines = [f"{name}: moved {c['moved_m']:.3f} m, knocked off the table: "
             f"{c['knocked_off_the_table']}, hit the floor: {c['hit_ground']} "
             f"(at {c['hit_ground_at_s']} s), bounced: {c['bounced']}, fell past the floor's "
             f"edge: {c['fell_past_the_floor_edge']}" for name, c in cans.items()]
    lines.append(f"contacts: {facts['contacts']}")
    return ok, lines
