"""Experiment 1 (thesis 10.1, table 10.1): collisions without contacts.

The KUKA LWR of ``legacy_2012/examples/Kuka_two_columns.xml`` lies at rest, horizontal (its
Home configuration, all joints 0, stretches the arm along +x at z = 0.31 m; it is set with the
initial-position mechanism: one Set Position of every link by forward kinematics). There is no
gravity. A can (``scenes/can.wrl``, scale 1000 as in the TX90 problem, i.e. the mesh in metres,
built as a movable body of 0.35 kg, coloured red so that its greying shows) starts above the
robot's tip and moves straight down by Set Velocity (-0.5 m/s). Its axis is offset from the
tip's flange so that its side grazes the flange face by a few millimetres: the pair starts to
touch, then the can slides past and stops touching.

World parameters of table 10.1: contact-less policy, 1 step per cycle, 10 fps, step 0.001 s,
gravity (0, 0, 0), contact surface layer 0.

Outcome (summary.json): the only pair ever reported is (can, KukaLWR/Link7); it is reported
on one unbroken run of cycles, with its start and stop times and its maximum depth; the start
and stop are where the geometry puts them (``geometric_contact``: the two meshes and the can's
prescribed motion, without the collision engine), within LAG_WINDOW_S; the Viewer's frames
show the can and the link grey exactly while they touch (pixels are read: the can's red pixels
vanish and the link's pixels turn the Viewer's collision grey).
"""
from __future__ import annotations

import math

import numpy as np

import common

PROBLEM = "Kuka_two_columns.xml"
CAN_FILE = "scenes/can.wrl"
TIP = "KukaLWR/Link7"
CAN = "can"

PARAMETERS = {
    "can_mass_kg": 0.35,
    "can_color": [0.85, 0.15, 0.1, 1.0],
    "can_start_m": [0.5967, 0.40, 0.5103],   # centre: bottom 0.1 m above the tip's top
    "can_velocity_m_s": [0.0, 0.0, -0.5],
    "robot_configuration_rad": [0.0] * 7,    # horizontal (the Home configuration)
    "duration_s": 0.8,
    "frame_every_cycles": 25,
}
WORLD = {  # table 10.1
    "contact_less": True, "steps_per_cycle": 1, "rate": 10.0, "step": 0.001,
    "gravity": [0.0, 0.0, 0.0], "contact_surface_layer": 0.0, "free_run": True,
}
CAMERA = common.Camera(eye=(0.62, -0.02, 0.45), target=(0.575, 0.40, 0.32))


def can_request(position, mass: float, color):
    """The can as a movable mesh body (ObjectSpec), oriented as the TX90 problem places it
    (axis z)."""
    from gui.core.bodies import shape_to_body
    from gui.core.kinematics import pose_from_axis_angle
    from gui.core.shapes import read_shape
    shape = read_shape(common.EXAMPLES / CAN_FILE, 1.0)  # scale 1000 of a mm problem: metres
    pose = pose_from_axis_angle(position, (1.0, 0.0, 0.0), math.pi / 2)
    request, _ = shape_to_body(CAN, shape, pose, mass, static=False)
    from dataclasses import replace
    return replace(request, color=tuple(color))


def run(frames: bool = True) -> dict:
    p = dict(PARAMETERS)
    problem, plan = common.load_plan(common.EXAMPLES / PROBLEM, WORLD)
    geometry = geometric_contact(plan, p)
    with common.Session("contactless", WORLD, CAMERA, track={CAN, TIP},
                        frames=frames) as s:
        s.client.execute(plan)
        robot = plan.robots[0]
        s.client.set_position(robot.situations(np.array(p["robot_configuration_rad"])))
        s.client.build_object(can_request(p["can_start_m"], p["can_mass_kg"], p["can_color"]))
        s.client.set_body_velocity(CAN, linear=p["can_velocity_m_s"])
        cycles = int(round(p["duration_s"] / WORLD["step"]))
        s.cycle_and_frame()
        while s.cycles < cycles:
            if (s.cycles + 1) % p["frame_every_cycles"] == 0:
                s.cycle_and_frame()
            else:
                s.cycle(1)
        s.finish()
        facts = analyse(s, geometry)
        common.write_summary(s, facts, p)
    return facts


#: grid of the vertical columns in which the two meshes are compared (m): 0.05 mm, a tenth of
#: the can's travel in one 1 ms step
COLUMN_GRID_M = 0.00005


def column_extents(vertices: np.ndarray, triangles: np.ndarray, xs: np.ndarray,
                   ys: np.ndarray) -> tuple:
    """For every vertical line (xs[i], ys[j]), the lowest and highest z at which it crosses the
    mesh's triangles ((len(xs), len(ys)) arrays; +inf / -inf where it misses the mesh)."""
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    low = np.full(X.shape, np.inf)
    high = np.full(X.shape, -np.inf)
    for a, b, c in vertices[triangles]:
        i0, i1 = np.searchsorted(xs, min(a[0], b[0], c[0])), \
            np.searchsorted(xs, max(a[0], b[0], c[0]), "right")
        j0, j1 = np.searchsorted(ys, min(a[1], b[1], c[1])), \
            np.searchsorted(ys, max(a[1], b[1], c[1]), "right")
        det = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1])
        if i0 >= i1 or j0 >= j1 or abs(det) < 1e-18:
            continue                      # no grid line inside, or a vertical triangle
        px, py = X[i0:i1, j0:j1] - c[0], Y[i0:i1, j0:j1] - c[1]
        l1 = ((b[1] - c[1]) * px + (c[0] - b[0]) * py) / det
        l2 = ((c[1] - a[1]) * px + (a[0] - c[0]) * py) / det
        inside = (l1 >= 0) & (l2 >= 0) & (l1 + l2 <= 1)
        z = l1 * a[2] + l2 * b[2] + (1 - l1 - l2) * c[2]
        np.minimum(low[i0:i1, j0:j1], np.where(inside, z, np.inf), out=low[i0:i1, j0:j1])
        np.maximum(high[i0:i1, j0:j1], np.where(inside, z, -np.inf), out=high[i0:i1, j0:j1])
    return low, high


def geometric_contact(plan, p: dict) -> dict:
    """When the moving can's mesh first and last overlaps the tip link's mesh, from the two
    meshes as the GUI sends them and the can's prescribed motion, without the collision engine.

    The link's mesh is placed by forward kinematics of ``robot_configuration_rad``, the can's
    at ``can_start_m`` and moved by ``can_velocity_m_s`` (straight down: no gravity, no
    contacts, so its motion is exactly the one set). In every vertical line through both
    meshes' footprints the link's solid spans [a_low, a_high] and the can's, at time 0,
    [b_low, b_high]; moving down at speed v the can overlaps the link in that line from
    (b_low - a_high) / v to (b_high - a_low) / v. The first and last of these over all lines
    are the times. The can's own mesh matters: can.wrl is a drinks can, bevelled at both ends
    (at the grazing line its bottom is 5.8 mm above its lowest point); a cylinder of its size
    would overlap the link from 0.217 s to 0.584 s instead of 0.228 s to 0.563 s."""
    velocity = np.asarray(p["can_velocity_m_s"], float)
    if velocity[0] != 0.0 or velocity[1] != 0.0 or velocity[2] >= 0.0:
        raise common.ExperimentError(f"geometric_contact handles a can moving straight down, "
                                     f"not {velocity.tolist()} m/s")
    speed = -velocity[2]
    meshes = common.mesh_bodies(plan)
    robot = plan.robots[0]
    pose = {body: (position, quaternion) for body, position, quaternion
            in robot.situations(np.array(p["robot_configuration_rad"]))}[TIP]
    link_v, link_t = meshes[TIP]
    link_v = common.in_world(link_v, *pose)
    can = can_request(p["can_start_m"], p["can_mass_kg"], p["can_color"])
    can_v = common.in_world(np.asarray(can.parameters, float).reshape(-1, 3), can.position,
                            can.orientation)
    can_t = np.asarray(can.indices, np.int64).reshape(-1, 3)
    low_xy = np.maximum(link_v[:, :2].min(0), can_v[:, :2].min(0))
    high_xy = np.minimum(link_v[:, :2].max(0), can_v[:, :2].max(0))
    if np.any(low_xy > high_xy):
        raise common.ExperimentError("the can's path never crosses the tip link's footprint")
    h = COLUMN_GRID_M
    xs = np.arange(low_xy[0], high_xy[0] + h / 2, h)
    ys = np.arange(low_xy[1], high_xy[1] + h / 2, h)
    a_low, a_high = column_extents(link_v, link_t, xs, ys)
    b_low, b_high = column_extents(can_v, can_t, xs, ys)
    both = np.isfinite(a_low) & np.isfinite(b_low)
    if not both.any():
        raise common.ExperimentError("no vertical line crosses both the can and the tip link")
    axis_xy = np.asarray(p["can_start_m"][:2], float)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    reach = np.hypot(X - axis_xy[0], Y - axis_xy[1])
    return {
        "start_s": round(float((b_low - a_high)[both].min() / speed), 6),
        "stop_s": round(float((b_high - a_low)[both].max() / speed), 6),
        # how far the link reaches into the can's outline, seen from above
        "depth_m": round(float(np.hypot(*(can_v[:, :2] - axis_xy).T).max()
                               - reach[both].min()), 6),
        "columns": int(both.sum()),
        "grid_m": h,
    }


#: how much later than the geometry the Collided messages may show the start and the stop: one
#: Portal cycle is one 1 ms step, and the cycle stamped t collides the poses at its step's
#: start (t - 1 ms), so a pair that starts (stops) touching at time g is first reported (first
#: missing) in the cycle stamped between g + 1 ms and g + 2 ms (measured: 1.547 and 1.586 ms).
#: The window is [0, 2 ms]: between Step Once calls the paused world also publishes at its
#: ~rate, colliding the poses after the step under the stamp t, so a start can show 0 to 1 ms
#: after g when such a publication falls between the first two cycles of the contact; plus
#: 0.1 ms for the column grid (0.05 mm of the can's travel).
LAG_WINDOW_S = (0.0, 2 * WORLD["step"])
LAG_SLACK_S = 0.0001


def analyse(s: "common.Session", geometry: dict) -> dict:
    with s.record.lock:
        collided = dict(s.record.collided)
    times = sorted(collided)
    pairs_seen = sorted({(a, b) for t in times for a, b, _ in collided[t]})
    pair = tuple(sorted((CAN, TIP)))
    touching = [t for t in times if any((a, b) == pair for a, b, _ in collided[t])]
    depth = max((d for t in times for a, b, d in collided[t] if (a, b) == pair), default=0.0)
    step = WORLD["step"]
    runs = 0
    previous = None
    for t in touching:
        if previous is None or t - previous > 1.5 * step:
            runs += 1
        previous = t
    reports = sum(len(collided[t]) for t in times)
    start = touching[0] if touching else None
    stop = round(touching[-1] + step, 6) if touching else None   # first cycle without the pair
    start_lag = round(start - geometry["start_s"], 6) if touching else None
    stop_lag = round(stop - geometry["stop_s"], 6) if touching else None
    low, high = LAG_WINDOW_S[0] - LAG_SLACK_S, LAG_WINDOW_S[1] + LAG_SLACK_S
    facts = {
        "outcome": {
            "pairs_reported": [list(p) for p in pairs_seen],
            "only_the_can_and_tip": pairs_seen == [pair],
            "collision_start_s": start,
            "collision_stop_s": stop,
            "collision_runs": runs,
            "geometric_start_s": geometry["start_s"],
            "geometric_stop_s": geometry["stop_s"],
            "start_lag_s": start_lag,
            "stop_lag_s": stop_lag,
            "lag_window_s": [LAG_WINDOW_S[0], LAG_WINDOW_S[1]],
            "start_and_stop_as_the_geometry_says": bool(
                touching and low <= start_lag <= high and low <= stop_lag <= high),
            "max_depth_m": round(depth, 6),
            "geometric_depth_m": geometry["depth_m"],
            "collided_messages": len(times),
            "cycles": s.cycles,
            "collision_reports_per_sim_s": round(reports / s.sim_time, 3) if s.sim_time else 0,
        },
    }
    if s.frame_paths:
        facts["frames"] = frame_colours(s, set(touching))
    return facts


def frame_colours(s: "common.Session", touching: set) -> dict:
    """Reads each frame's pixels against whether the pair touched in the frame's cycle or the
    one before (the Viewer keeps a colour through the next update): inside the can's image
    (its centre and radius projected) the share of red pixels; in a patch on the tip's flange
    its brightness against the first frame (the flange is drawn 0.2 grey, the Viewer's
    collision colour is 0.35 grey: about 1.75 times brighter)."""
    from PIL import Image
    step = WORLD["step"]
    times, positions, _ = s.trajectory(CAN)
    rows = []
    tip_u, tip_v = project(np.array([0.553, 0.362, 0.31]), CAMERA)
    base = None
    for path, t in zip(s.frame_paths, s.frame_times):
        image = np.asarray(Image.open(path).convert("RGB")).astype(float)
        k = int(np.argmin(np.abs(times - t)))
        cu, cv = project(positions[k], CAMERA)
        ru = abs(project(positions[k] + [0.025, 0, 0], CAMERA)[0] - cu)
        can = image[max(cv - ru, 0):cv + ru + 1, max(cu - ru, 0):cu + ru + 1].reshape(-1, 3)
        r, g, b = can[:, 0], can[:, 1], can[:, 2]
        red_share = float(((r > 60) & (r > 1.8 * g) & (r > 1.8 * b)).mean()) if len(can) else 0.0
        patch = image[tip_v - 2:tip_v + 3, tip_u - 2:tip_u + 3].reshape(-1, 3).mean(0)
        brightness = float(patch.mean())
        if base is None:
            base = brightness
        touched = round(t, 6) in touching or round(t - step, 6) in touching
        rows.append({"frame": path.name, "t_s": round(t, 6), "touching": touched,
                     "can_red_share": round(red_share, 3),
                     "tip_patch_rgb": [round(float(c), 1) for c in patch],
                     "tip_brightness_ratio": round(brightness / base, 3) if base else None})
    touching_rows = [r for r in rows if r["touching"]]
    free_rows = [r for r in rows if not r["touching"]]
    return {
        "per_frame": rows,
        "frames_touching": len(touching_rows),
        "frames_free": len(free_rows),
        "can_grey_exactly_while_touching": bool(touching_rows) and all(
            r["can_red_share"] < 0.02 for r in touching_rows) and all(
            r["can_red_share"] > 0.3 for r in free_rows),
        "tip_grey_exactly_while_touching": bool(touching_rows) and all(
            r["tip_brightness_ratio"] > 1.4 for r in touching_rows) and all(
            abs(r["tip_brightness_ratio"] - 1) < 0.1 for r in free_rows),
    }


def project(point_W: np.ndarray, camera: "common.Camera", fov_y: float = 0.8) -> tuple:
    """Pixel (u, v) of a world point for the Viewer's pinhole camera (z up)."""
    eye, target = np.asarray(camera.eye, float), np.asarray(camera.target, float)
    forward = target - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = point_W - eye
    x, y, z = d @ right, d @ up, d @ forward
    f = (camera.height / 2) / math.tan(fov_y / 2)
    return int(round(camera.width / 2 + f * x / z)), int(round(camera.height / 2 - f * y / z))


def verdict(facts: dict) -> tuple:
    """(outcome held, one line per fact) for run.py and the tests."""
    o = facts["outcome"]
    ok = (o["only_the_can_and_tip"] and o["collision_runs"] == 1 and o["max_depth_m"] > 0
          and o["collided_messages"] >= o["cycles"] and o["start_and_stop_as_the_geometry_says"])
    lines = [f"pairs reported: {o['pairs_reported']}",
             f"pair collides from {o['collision_start_s']} s to {o['collision_stop_s']} s "
             f"({o['collision_runs']} run), max depth {o['max_depth_m'] * 1000:.2f} mm",
             f"the meshes overlap from {o['geometric_start_s']} s to {o['geometric_stop_s']} s "
             f"(geometry): reported {o['start_lag_s']} s and {o['stop_lag_s']} s later (window "
             f"{o['lag_window_s']} s), reach {o['geometric_depth_m'] * 1000:.2f} mm into the "
             f"can's outline",
             f"{o['collided_messages']} Collided messages for {o['cycles']} cycles"]
    frames = facts.get("frames")
    if frames:
        ok = ok and frames["can_grey_exactly_while_touching"] and \
            frames["tip_grey_exactly_while_touching"]
        lines.append(f"frames: {frames['frames_touching']} touching, {frames['frames_free']} "
                     f"free; can grey exactly while touching: "
                     f"{frames['can_grey_exactly_while_touching']}; tip grey exactly while "
                     f"touching: {frames['tip_grey_exactly_while_touching']}")
    return ok, lines
