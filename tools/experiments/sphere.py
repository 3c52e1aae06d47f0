"""Past the thesis (issue 11): Kautham's ODE sphere demo driven by a control path, as Kautham's
own ODE environment would run it.

Scene: ``current_2025/demos/OMPL_ode_demos/Sphere/Sphere.xml`` exactly as the GUI loads it
(``rosrun GUI load_problem``): Kautham's ODE world (gravity -9.8 m/s^2, the planner's ERP 0.5
and Max Contacts 3, 30 ms steps from its PropagationStepSize, one step per cycle), an infinite
ground plane at z = 0, every obstacle a dynamic body with its URDF mass (four 0.5 kg blocks
near the centre, four 2 kg walls 9 m long whose inner faces are 4.55 m from the centre), and
the robot, a 25 kg sphere of radius 0.25 m, at the query's ``<Init>`` (controls 0.544 0.433 0.4
through ``sp3.cntr`` and the robot's ``<Limits>``: (0.44, -0.67, 0.2) m; its ``<Home>`` is
(10, 10, 0), outside the walls).

The world first runs ``settle_s`` so that everything comes to rest on the ground. Then a
control path: rows of the sphere's three controls (x, y, z in [0, 1]: position -5 + 10 c in x
and y, -1 + 3 c in z) and a duration, along a route around the blocks through three corners of
the arena to the query's ``<Goal>``, at ``speed_m_s``, one row per ``row_s``, then
``hold_rows`` rows at the goal. Each row is applied as ``gui.core.control_path`` applies it to
a free body (a force on the sphere for the row's duration, docs/INTERFACE.md), here as a
persistent Set External Force added at the row's start and removed at its end, the world
advanced by Step Once cycle by cycle so that the Viewer sees every cycle.

Outcome (summary.json): after settling, each body's height above the ground against the one
its shape rests at, and its speed; where the sphere starts against the query's start; the
sphere's distance to each row's target, to each corner of the route and to the goal at the end;
whether it stayed inside the walls and rolling on the ground (in contact with it every cycle);
how far the blocks and walls moved.
"""
from __future__ import annotations

import math

import numpy as np

import common

PROBLEM = common.KAUTHAM_DIR / "current_2025" / "demos" / "OMPL_ode_demos" / "Sphere" / \
    "Sphere.xml"
SPHERE = "SphereDE"
GROUND = "ground"

PARAMETERS = {
    "settle_s": 1.0,
    "route_corners_m": [[3.5, -3.5], [3.5, 3.5], [-3.5, 3.5]],
    "speed_m_s": 1.5,
    "row_s": 0.3,
    "hold_rows": 6,
    "z_control": 0.4,              # the query's own: a target 5 cm below the sphere's centre
    "frame_every_cycles": 5,
    "walls_inner_face_m": 4.55,    # wall centres at 4.8 m, 0.5 m thick
}
#: what the plan does not set: contacts (the ground holds the scene), batch stepping
WORLD = {"contact_less": False, "free_run": True}
CAMERA = common.Camera(eye=(0.0, -9.0, 9.5), target=(0.0, 0.4, 0.0))

#: a body at rest lies within this of the height its shape rests at (m); ODE's contacts let
#: it sink by about the surface layer
REST_TOLERANCE_M = 0.005
#: ... and moves slower than this (m/s)
REST_SPEED_M_S = 0.01


def control_value(x: float, low: float, high: float) -> float:
    """The control c in [0, 1] that sp3.cntr (offset 0.5, map 1) and a limit [low, high] map
    to ``x``: p = 0.5 + (c - 0.5) = c, x = low + p (high - low)."""
    return (x - low) / (high - low)


def route(start, corners, goal, step_m: float) -> np.ndarray:
    """(n, 2) targets along the polyline start -> corners -> goal, at most ``step_m`` apart,
    each leg ending on its corner."""
    points = [np.asarray(start, float)] + [np.asarray(c, float) for c in corners] + \
        [np.asarray(goal, float)]
    out = []
    for a, b in zip(points[:-1], points[1:]):
        n = max(1, math.ceil(np.linalg.norm(b - a) / step_m))
        out += [a + (b - a) * k / n for k in range(1, n + 1)]
    return np.array(out)


def control_rows(handle, targets: np.ndarray, p: dict) -> list:
    """The control path: one row per (x, y) target, ``row_s`` each."""
    from gui.core.control_path import ControlRow
    limits = handle.instance.limits
    return [ControlRow((control_value(x, *limits["X"]), control_value(y, *limits["Y"]),
                        p["z_control"]), p["row_s"]) for x, y in targets]


def resting_height(body) -> float:
    """Height above the ground of a body's centre when it rests: a sphere's radius, half a
    box's height (the demo's boxes lie unrotated about x and y)."""
    shape = body.parameters
    return float(shape[0]) if len(shape) == 1 else float(shape[2]) / 2


def cycle_port(session: "common.Session", cycle_s: float, frame_every: int):
    """The world node's WorldPort (gui.ros.world_port) through a Session: a control row's
    forces are persistent Set External Forces for its duration, the world advanced by Step
    Once, a frame every ``frame_every`` cycles."""
    from gui.ros.world_port import ClientWorldPort
    from odin_common.interface import ForceKind

    class CyclePort(ClientWorldPort):
        def set_servo(self, command) -> None:
            raise common.ExperimentError("the sphere has no joints to servo")

        def advance(self, duration: float, forces=()) -> list:
            cycles = round(duration / cycle_s)
            if cycles < 1 or abs(cycles * cycle_s - duration) > 1e-6:
                raise common.ExperimentError(f"a row of {duration} s is not a whole number "
                                             f"of {cycle_s} s cycles")
            client = session.client
            ids = [client.add_body_force(body, ForceKind.FORCE, vector)
                   for body, vector in forces]
            for _ in range(cycles):
                if (session.cycles + 1) % frame_every == 0:
                    session.cycle_and_frame()
                else:
                    session.cycle(1)
            for force_id in ids:
                client.remove_body_force(force_id)
            self._states.clear()            # bodies are read again (Get State)
            return []

    return CyclePort(session.client)


def _states(client, names) -> dict:
    response = client.call("get_state", objects=list(names))
    return {b.id: (np.array(b.position), float(np.linalg.norm(b.linear)))
            for b in response.bodies}


def run(frames: bool = True) -> dict:
    from gui.core.control_path import run_control_path
    p = dict(PARAMETERS)
    _, plan = common.load_plan(PROBLEM)
    bodies = {b.id: b for b in plan.bodies() if not b.geometry_only}
    handle = plan.robot()
    world = plan.world
    cycle_s = world.step * world.steps_per_cycle
    with common.Session("sphere", WORLD, CAMERA, track=set(bodies), frames=frames,
                        contacts=True) as s:
        s.client.execute(plan)
        built = _states(s.client, [SPHERE])[SPHERE][0]
        every = p["frame_every_cycles"]
        s.cycle_and_frame()
        while s.sim_time < p["settle_s"] - 1e-9:
            if (s.cycles + 1) % every == 0:
                s.cycle_and_frame()
            else:
                s.cycle(1)
        settled = _states(s.client, bodies)
        route_from = s.sim_time
        start = settled[SPHERE][0][:2]
        goal = handle.goal.base_pose[:2, 3]
        targets = route(start, p["route_corners_m"], goal, p["speed_m_s"] * p["row_s"])
        targets = np.vstack([targets, np.repeat(goal[None], p["hold_rows"], axis=0)])
        rows = control_rows(handle, targets, p)
        results = run_control_path(cycle_port(s, cycle_s, every), handle, rows)
        s.frame()
        s.finish()
        facts = analyse(s, p, bodies, handle, built, settled, targets, results, route_from)
        common.write_summary(s, facts, p)
    return facts


def analyse(s, p, bodies, handle, built, settled, targets, results, route_from) -> dict:
    start = handle.start.base_pose[:3, 3]
    goal = handle.goal.base_pose[:2, 3]
    rest = {}
    for name, body in bodies.items():
        position, speed = settled[name]
        rest[name] = {"height_m": round(float(position[2]), 4),
                      "rests_at_m": resting_height(body),
                      "speed_m_s": round(speed, 5),
                      "at_rest_on_the_ground": bool(
                          abs(position[2] - resting_height(body)) <= REST_TOLERANCE_M
                          and speed < REST_SPEED_M_S)}
    t, xyz, _ = s.trajectory(SPHERE)
    on_route = t >= route_from - 1e-9
    radius = resting_height(bodies[SPHERE])
    reached = np.array([r.base_position[:2] for r in results])
    tracking = np.linalg.norm(reached - targets, axis=1)
    corners = {f"{c}": round(float(np.min(np.linalg.norm(xyz[on_route, :2] - c, axis=1))), 4)
               for c in p["route_corners_m"]}
    inner = p["walls_inner_face_m"]
    with s.record.lock:
        pairs = {k: v for k, v in s.record.contact_pairs.items() if k >= route_from - 1e-9}
    rolling = [t for t, listed in pairs.items()
               if not any({a, b} == {SPHERE, GROUND} for a, b in listed)]
    moved = {}
    for name in bodies:
        if name == SPHERE:
            continue
        times, path, _ = s.trajectory(name)
        path = path[times >= route_from - 1e-9]
        moved[name] = round(float(np.linalg.norm(path - settled[name][0], axis=1).max()), 5)
    return {"outcome": {
        "rest": rest,
        "everything_rests_on_the_ground": all(r["at_rest_on_the_ground"] for r in rest.values()),
        "sphere_built_at_m": [round(float(v), 4) for v in built],
        "query_start_m": [round(float(v), 4) for v in start],
        "query_goal_xy_m": [round(float(v), 4) for v in goal],
        "sphere_settled_at_m": [round(float(v), 4) for v in settled[SPHERE][0]],
        "starts_at_its_query_start": bool(np.linalg.norm(built - start) < 1e-6
                                          and np.linalg.norm(settled[SPHERE][0][:2]
                                                             - start[:2]) < 0.01),
        "starts_inside_the_walls": bool(np.all(np.abs(built[:2]) < inner - radius)),
        "rows": len(results),
        "route_starts_at_s": round(route_from, 6),
        "route_length_m": round(float(np.sum(np.linalg.norm(np.diff(
            np.vstack([settled[SPHERE][0][:2], targets]), axis=0), axis=1))), 3),
        "max_distance_to_row_target_m": round(float(tracking.max()), 4),
        "closest_to_each_corner_m": corners,
        "first_row_moves_toward_its_target": bool(
            np.linalg.norm(reached[0] - targets[0])
            < np.linalg.norm(settled[SPHERE][0][:2] - targets[0])),
        "distance_to_goal_at_end_m": round(float(np.linalg.norm(reached[-1] - goal)), 4),
        "max_abs_xy_m": round(float(np.abs(xyz[:, :2]).max()), 4),
        "stayed_inside_the_walls": bool(np.abs(xyz[:, :2]).max() < inner - radius),
        "height_on_route_m": [round(float(xyz[on_route, 2].min()), 4),
                              round(float(xyz[on_route, 2].max()), 4)],
        "cycles_on_route_without_ground_contact": len(rolling),
        "obstacles_moved_m": moved,
    }, "contacts": s.contact_rates()}


#: the sphere ends this near its goal (m); it lags its moving targets by up to ROUTE_LAG_M
GOAL_TOLERANCE_M = 0.02
ROUTE_LAG_M = 0.6
#: the route passes each corner within this (m)
CORNER_TOLERANCE_M = 0.3
#: the blocks and walls are not touched: they move less than this (m)
STILL_M = 0.005


def checks(o: dict) -> dict:
    """Each outcome the run must hold, by name (run.py's verdict and the test)."""
    low, high = o["height_on_route_m"]
    radius = o["rest"][SPHERE]["rests_at_m"]
    return {
        "everything rests on the ground": o["everything_rests_on_the_ground"],
        "the sphere starts at its query start": o["starts_at_its_query_start"],
        "inside the walls": o["starts_inside_the_walls"] and o["stayed_inside_the_walls"],
        "the first row moves it toward its target": o["first_row_moves_toward_its_target"],
        "it follows the route": o["max_distance_to_row_target_m"] < ROUTE_LAG_M and all(
            d < CORNER_TOLERANCE_M for d in o["closest_to_each_corner_m"].values()),
        "it ends at the goal": o["distance_to_goal_at_end_m"] < GOAL_TOLERANCE_M,
        "it rolls on the ground": o["cycles_on_route_without_ground_contact"] == 0
        and radius - 0.01 < low and high < radius + 0.01,
        "the blocks and walls stay where they rest": all(
            d < STILL_M for d in o["obstacles_moved_m"].values()),
    }


def verdict(facts: dict) -> tuple:
    """(outcome held, one line per fact) for run.py."""
    o = facts["outcome"]
    held = checks(o)
    lines = [f"{name}: {'yes' if ok else 'NO'}" for name, ok in held.items()]
    lines.append(f"built at {o['sphere_built_at_m']} (query start {o['query_start_m']}), "
                 f"{o['rows']} rows over {o['route_length_m']} m from "
                 f"{o['route_starts_at_s']} s, at most {o['max_distance_to_row_target_m']} m "
                 f"behind its targets, corners within {o['closest_to_each_corner_m']} m, "
                 f"{o['distance_to_goal_at_end_m']} m from the goal at the end")
    lines.append(f"contacts: {facts['contacts']}")
    return all(held.values()), lines
