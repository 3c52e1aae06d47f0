"""Past the thesis (issue 17): OMPL's KPIECE1 plans Kautham's ODE sphere demo through Odin's
physics, and the plan it writes drives the sphere to its goal in a fresh world node.

Scene: the public ``Sphere.xml`` exactly as the GUI loads it (``sphere.py`` describes it: a
25 kg sphere of radius 0.25 m at the query's ``<Init>``, four 0.5 kg blocks it may push, four
walls it must not touch, an infinite ground plane).

Planning (``gui.planning``, the in-process Core back end, as ``rosrun GUI plan`` runs it):
KPIECE1 with a fixed OMPL seed and a wall-clock limit searches the sphere's x and y controls
(``sp3.cntr``, each held 2 to 30 steps of 0.03 s) until the sphere's centre is within the goal
region (0.25 m of the query's ``<Goal>`` in the plane), every motion simulated from the whole
world's state. The solution is written as a Kautham control path (``plan.path``, one row per
step), read back, and run as ``rosrun GUI run_path --controls`` runs it (one kept Propagate per
row, ``gui.ros.world_port.ClientWorldPort``) in a world node that was only built from the
problem, with a Viewer frame every ``frame_every_rows`` rows.

Outcome (summary.json): the planner's statistics; where the executed plan leaves the sphere
against where the planner's own replay left it (the worlds are deterministic: the same bits);
its distance to the goal; the pairs it touched on the way (walls are forbidden); how far each
block moved; whether it stayed inside the walls.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

import common
from sphere import PROBLEM, SPHERE, WORLD, _states, resting_height

PARAMETERS = {
    "planner": "KPIECE1",
    "seed": 7,
    "time_limit_s": 120.0,       # a bound for a busy machine: the seed decides the plan
    "frame_every_rows": 2,
    "walls_inner_face_m": 4.55,    # wall centres at 4.8 m, 0.5 m thick
}
#: closer than sphere.py's: the plan stays within 2 m of the centre
CAMERA = common.Camera(eye=(-0.3, -4.2, 4.6), target=(-0.3, 0.3, 0.0))
#: the walls do not move more than this in the plane (m): they are never touched
STILL_M = 0.005


class FramedClient:
    """The WorldClient a ``ClientWorldPort`` drives, seen through: each Propagate's collisions are
    kept, the Session's simulated time follows the world's, and every ``frame_every`` rows the
    Viewer's picture is saved."""

    def __init__(self, session: "common.Session", frame_every: int):
        self.session = session
        self.frame_every = frame_every
        self.collisions: list = []       # per row: ((first, second, depth m, t s), ...)

    def __getattr__(self, name):
        return getattr(self.session.client, name)

    def propagate(self, *args, **kwargs):
        s = self.session
        started = time.perf_counter()
        result = s.client.propagate(*args, **kwargs)
        s.stepping_wall += time.perf_counter() - started
        s.sim_time = result.start_time + result.steps * result.step
        s.cycles += 1
        self.collisions.append(result.collisions)
        if len(self.collisions) % self.frame_every == 0:
            s.frame()
        return result


def search(plan, p: dict):
    """(problem, PlanResult): KPIECE1 over the Core back end, as ``rosrun GUI plan`` runs it
    (``--goal-tolerance`` from ``p["goal_tolerance_m"]`` where given)."""
    from gui.planning.backend import CoreBackend
    from gui.planning.bridge import plan as plan_query
    from gui.planning.problem import SearchSettings, planning_problem
    problem = planning_problem(plan, settings=SearchSettings.of_problem(
        plan, goal_tolerance=p.get("goal_tolerance_m")))
    backend = CoreBackend(plan, problem)
    try:
        result = plan_query(backend, p["planner"], p["time_limit_s"], p["seed"])
    finally:
        backend.close()
    if not result.solved:
        raise common.ExperimentError(
            f"{p['planner']} (seed {p['seed']}) found no solution in {p['time_limit_s']} s: "
            f"the closest plan ends {result.goal_distance:.3f} m from the goal")
    return problem, result


def run(frames: bool = True, problem_file=PROBLEM, name: str = "plan_sphere",
        parameters: dict = PARAMETERS, camera: "common.Camera" = CAMERA) -> dict:
    """Plans ``problem_file``'s query (a Sphere demo) and runs the plan in a fresh world node
    (the module docstring); the experiment ``name`` writes out/experiments/<name>/."""
    def outcome(s, e: Executed) -> dict:
        return analyse(s, e.parameters, e.problem, e.result, e.rows, e.results, e.collisions,
                       e.before, e.after, resting_height(e.bodies[SPHERE]))
    return plan_and_run(name, problem_file, parameters, camera, frames,
                        "the sphere's controls", outcome)


@dataclass
class Executed:
    """A plan and its run in the fresh world node: what a planning experiment analyses."""
    parameters: dict
    problem: object                  # gui.planning.problem.PlanningProblem
    result: object                   # gui.planning.bridge.PlanResult
    bodies: dict                     # {object ID: ObjectSpec} the world built (no static ones)
    rows: list                       # the control rows read back from plan.path
    results: list                    # per row, what running it answered (control_path)
    collisions: list                 # per row: ((first, second, depth m, t s), ...)
    before: dict                     # {object ID: state} before the first row and after
    after: dict                      # the last (sphere._states)
    tracked_pose: tuple              # the tracked link's (position m, quaternion (w, x, y, z))


def plan_and_run(name: str, problem_file, parameters: dict, camera: "common.Camera",
                 frames: bool, controls: str, outcome) -> dict:
    """Plans ``problem_file``'s query with ``parameters`` (``search``), writes the plan as
    out/experiments/<name>/plan.path (its rows: ``controls`` in [0, 1], then the duration),
    reads it back and runs it in a world node only built from the problem, with a Viewer frame
    every ``frame_every_rows`` rows; ``outcome(session, Executed)`` makes the facts written
    to summary.json, which are returned."""
    from gui.core.control_path import (control_size, read_control_path, run_control_path,
                                       write_control_path)
    from gui.ros.world_port import ClientWorldPort
    p = dict(parameters)
    _, searched = common.load_plan(problem_file)
    problem, result = search(searched, p)
    _, plan = common.load_plan(problem_file)       # a fresh plan for the fresh world
    bodies = {b.id: b for b in plan.bodies() if not b.geometry_only}
    handle = plan.robot()
    with common.Session(name, WORLD, camera, track=set(bodies), frames=frames,
                        contacts=True) as s:
        path = s.out / "plan.path"
        write_control_path(path, result.rows, comments=(
            f"planned by {p['planner']}, seed {p['seed']} (tools/experiments/{name}.py)",
            f"each row: {controls} in [0, 1], then the duration (s)"))
        rows = read_control_path(path, control_size(handle))
        if s.client.world().simulating:
            s.client.pause()
        s.client.execute(plan)
        before = _states(s.client, bodies)
        s.frame()
        client = FramedClient(s, p["frame_every_rows"])
        port = ClientWorldPort(client)
        results = run_control_path(port, handle, rows)
        if len(rows) % p["frame_every_rows"]:
            s.frame()
        tracked_pose = tuple(port.body_state(problem.tracked_body)[:2])
        after = _states(s.client, bodies)
        s.finish()
        facts = outcome(s, Executed(p, problem, result, bodies, rows, results,
                                    client.collisions, before, after, tracked_pose))
        common.write_summary(s, facts, p)
    return facts


def analyse(s, p, problem, result, rows, results, collisions, before, after,
            radius: float) -> dict:
    executed = np.array([r.base_position for r in results])
    end = executed[-1]
    touched = problem.robot_contacts((a, b) for row in collisions for a, b, _, _ in row)
    # in the plane: the blocks are built 0.27 m above where they rest and fall meanwhile
    moved = moved_in_the_plane(before, after, [name for name in before if name != SPHERE])
    inner = p["walls_inner_face_m"]
    return {"outcome": {
        **plan_facts(problem, result, rows, results, end),
        "start_m": [round(float(v), 4) for v in before[SPHERE][0]],
        "sphere_touched": [list(pair) for pair in touched],
        "forbidden_contacts": [list(pair) for pair in problem.forbidden_contacts(touched)],
        "max_abs_xy_m": round(float(np.abs(executed[:, :2]).max()), 4),
        "stayed_inside_the_walls": bool(np.abs(executed[:, :2]).max()
                                        < inner - radius),
        "obstacles_moved_in_the_plane_m": moved,
    }, "contacts": s.contact_rates()}


def plan_facts(problem, result, rows, results, end) -> dict:
    """What every planning experiment reports of its plan: the planner's statistics, the
    goal, the rows written, read back and run, and where the fresh world ended the tracked
    link (``end``, (3,) m) against the planner's own replay and the goal."""
    return {
        "planner": result.statistics(),
        "goal_xy_m": [round(float(v), 4) for v in problem.goal_xy],
        "goal_tolerance_m": problem.settings.goal_tolerance,
        "rows_written": len(result.rows),
        "rows_read_back_identical": list(rows) == list(result.rows),
        "rows_run": len(results),
        "plan_duration_s": round(sum(r.duration for r in rows), 4),
        "planned_end_m": [float(v) for v in result.final_position],
        "executed_end_m": [float(v) for v in end],
        "replay_difference_m": float(np.linalg.norm(end - result.final_position)),
        "replay_bit_identical": end.tobytes() == np.asarray(result.final_position).tobytes(),
        "distance_to_goal_at_end_m": round(problem.goal_distance(end), 4),
        "in_goal_region": bool(problem.in_goal(end)),
    }


def moved_in_the_plane(before: dict, after: dict, names) -> dict:
    """{name: m} how far each body moved in x and y between two ``_states`` readings."""
    return {name: round(float(np.linalg.norm(after[name][0][:2] - before[name][0][:2])), 4)
            for name in names}


#: the executed plan ends where the planner's replay ended, within this (m): determinism
REPLAY_TOLERANCE_M = 1e-9


def replay_checks(o: dict) -> dict:
    """The checks every planning experiment makes of its plan and the plan's run."""
    return {
        "KPIECE1 solved it": o["planner"]["solved"],
        "the path file holds the plan": o["rows_read_back_identical"]
        and o["rows_run"] == o["rows_written"] > 0,
        "the fresh world replays the plan": o["replay_difference_m"] < REPLAY_TOLERANCE_M,
    }


def obstacle_facts(e: Executed, touched_key: str) -> dict:
    """The facts of a robot's plan among obstacles it may push and obstacles it must not touch:
    ``plan_facts`` (the end: where the tracked link's origin ended), the pairs it touched
    (under ``touched_key``), the forbidden ones among them, how far each obstacle moved in the
    plane, and which obstacles are fixed."""
    problem = e.problem
    end = problem.tracked_origin(*e.tracked_pose)
    touched = problem.robot_contacts((a, b) for row in e.collisions for a, b, _, _ in row)
    obstacles = [name for name in e.bodies if name not in problem.robot_bodies]
    return {
        **plan_facts(problem, e.result, e.rows, e.results, end),
        touched_key: [list(pair) for pair in touched],
        "forbidden_contacts": [list(pair) for pair in problem.forbidden_contacts(touched)],
        "obstacles_moved_in_the_plane_m": moved_in_the_plane(e.before, e.after, obstacles),
        "fixed_obstacles": sorted(problem.forbidden),
    }


def checks(o: dict) -> dict:
    """Each outcome the run must hold, by name (run.py's verdict and the test)."""
    return {
        **replay_checks(o),
        "it ends in the goal region": o["in_goal_region"],
        "it never touches a wall": not o["forbidden_contacts"] and all(
            d < STILL_M for name, d in o["obstacles_moved_in_the_plane_m"].items()
            if name.startswith("wall")),
        "inside the walls": o["stayed_inside_the_walls"],
    }


def verdict(facts: dict) -> tuple:
    """(outcome held, one line per fact) for run.py."""
    o = facts["outcome"]
    return plan_verdict(checks(o), o, o["sphere_touched"], "blocks pushed")


def plan_verdict(held: dict, o: dict, touched: list, moved: str) -> tuple:
    """(every check ``held``, one line per check and one of the plan's figures): a planning
    experiment's verdict, ``touched`` the pairs its robot touched, ``moved`` what its
    ``obstacles_moved_in_the_plane_m`` are called."""
    lines = [f"{name}: {'yes' if ok else 'NO'}" for name, ok in held.items()]
    stats = o["planner"]
    lines.append(f"{stats['planner']} seed {stats['seed']}: {stats['time_s']} s, "
                 f"{stats['propagations']} propagations, {o['rows_run']} rows "
                 f"({o['plan_duration_s']} s); ends {o['distance_to_goal_at_end_m']} m from the "
                 f"goal, {o['replay_difference_m']:.3g} m from the planned end "
                 f"(bit-identical: {o['replay_bit_identical']}); touched {touched}; "
                 f"{moved} {o['obstacles_moved_in_the_plane_m']} m")
    return all(held.values()), lines
