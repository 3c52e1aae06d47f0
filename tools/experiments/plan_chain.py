"""Past the thesis (issue 17): OMPL's KPIECE1 plans Kautham's ODE chain demo through Odin's
physics, and the plan it writes moves the chain's gripper to its goal in a fresh world node.

Scene: Kautham's ``OMPL_ode_demos/Chain/k-PMPChain.xml`` exactly as the GUI loads it
(vendored from Kautham's repository: tools/kautham/ode_demos): a planar chain (PlanerChain1
scaled 11 times: two links of 2.2 m, a gripper with two fingers) whose base is held 0.5 m
above the ground, its joints turning about the vertical; six obstacles resting on an infinite
ground plane. Kautham's chain planner drives the chain as its PlanarChainEnvironment does: each
joint at up to 1 rad/s under 7 N m, no joint damping or friction (gui.core.build). Its types
decide what may be touched: box2 is "freeManipulatable", which only the gripper and fingers
may push; box1 and the red cubes are "fixed", which nothing of the chain may touch. The
query's ``<Goal>`` puts the gripper around box1 with link2 lying where box2 stands, so box2
must be pushed out of the way first.

Planning (``gui.planning``, the in-process Core back end, as ``rosrun GUI plan --goal-tolerance
0.05`` runs it): KPIECE1 with a fixed OMPL seed searches the chain's joint targets (chain.cntr),
each held 1 to 30 steps of 0.02 s (the problem's own parameters), until the gripper's origin is
within 0.05 m of where the goal configuration puts it, in the plane (Kautham's
KauthamDEGoalRegion threshold, "only final link position"). The solution is written as a
Kautham control path, read back and run as ``rosrun GUI run_path --controls`` runs it in a
world node only built from the problem, with a Viewer frame every ``frame_every_rows`` rows.

Outcome (summary.json): the planner's statistics; where the executed plan leaves the gripper
against where the planner's own replay left it (the same bits); its distance to the goal; the
pairs the chain touched; how far each obstacle moved.
"""
from __future__ import annotations

import numpy as np

import common
import plan_sphere
from sphere import WORLD, _states

PROBLEM = common.ROOT / "tools" / "kautham" / "ode_demos" / "demos" / "OMPL_ode_demos" / \
    "Chain" / "k-PMPChain.xml"
PARAMETERS = {
    "planner": "KPIECE1",
    "seed": 4,
    "time_limit_s": 60.0,
    "goal_tolerance_m": 0.05,
    "frame_every_rows": 30,
}
#: almost straight down on the chain's half of the scene (its base at the bottom)
CAMERA = common.Camera(eye=(-0.2, -1.2, 9.0), target=(-0.2, -2.4, 0.3))
#: the fixed obstacles do not move more than this in the plane (m): never touched
STILL_M = 0.005
#: box2 is pushed at least this far (m) clear of where link2 lies at the goal
PUSHED_M = 0.1
PUSHED = "box2"


def run(frames: bool = True) -> dict:
    """Plans the chain demo's query and runs the plan in a fresh world node (module
    docstring)."""
    from gui.core.control_path import (ClientPort, control_size, read_control_path,
                                       run_control_path, write_control_path)
    p = dict(PARAMETERS)
    _, searched = common.load_plan(PROBLEM)
    problem, result = plan_sphere.search(searched, p)
    _, plan = common.load_plan(PROBLEM)        # a fresh plan for the fresh world
    bodies = {b.id: b for b in plan.bodies() if not b.geometry_only}
    handle = plan.robot()
    with common.Session("plan_chain", WORLD, CAMERA, track=set(bodies), frames=frames,
                        contacts=True) as s:
        path = s.out / "plan.path"
        write_control_path(path, result.rows, comments=(
            f"planned by {p['planner']}, seed {p['seed']} (tools/experiments/plan_chain.py)",
            "each row: the chain's controls (link1, link2, gripper) in [0, 1], then the "
            "duration (s)"))
        rows = read_control_path(path, control_size(handle))
        if s.client.world().simulating:
            s.client.pause()
        s.client.execute(plan)
        obstacles = [name for name in bodies if name not in problem.robot_bodies]
        before = _states(s.client, obstacles)
        s.frame()
        client = plan_sphere.FramedClient(s, p["frame_every_rows"])
        port = ClientPort(client, real_time=False)
        results = run_control_path(port, handle, rows)
        if len(rows) % p["frame_every_rows"]:
            s.frame()
        end = problem.tracked_origin(*port.body_state(problem.tracked_body)[:2])
        after = _states(s.client, obstacles)
        s.finish()
        facts = analyse(s, problem, result, rows, results, client.collisions, end, before,
                        after)
        common.write_summary(s, facts, p)
    return facts


def analyse(s, problem, result, rows, results, collisions, end, before, after) -> dict:
    touched = problem.robot_contacts((a, b) for row in collisions for a, b, _, _ in row)
    return {"outcome": {
        **plan_sphere.plan_facts(problem, result, rows, results, end),
        "tracked_link": problem.tracked_body,
        "chain_touched": [list(pair) for pair in touched],
        "forbidden_contacts": [list(pair) for pair in problem.forbidden_contacts(touched)],
        "obstacles_moved_in_the_plane_m": plan_sphere.moved_in_the_plane(before, after,
                                                                         before),
        "fixed_obstacles": sorted(problem.forbidden),
    }, "contacts": s.contact_rates()}


def checks(o: dict) -> dict:
    """Each outcome the run must hold, by name (run.py's verdict and the test)."""
    moved = o["obstacles_moved_in_the_plane_m"]
    return {
        "KPIECE1 solved it": o["planner"]["solved"],
        "the path file holds the plan": o["rows_read_back_identical"]
        and o["rows_run"] == o["rows_written"] > 0,
        "the fresh world replays the plan": o["replay_difference_m"]
        < plan_sphere.REPLAY_TOLERANCE_M,
        "the gripper ends in the goal region": o["in_goal_region"],
        "only the gripper and fingers push, and only box2": not o["forbidden_contacts"],
        "box2 pushed out of link2's way": moved[PUSHED] > PUSHED_M,
        "the fixed obstacles never move": all(moved[name] < STILL_M
                                              for name in o["fixed_obstacles"]),
    }


def verdict(facts: dict) -> tuple:
    """(outcome held, one line per fact) for run.py."""
    o = facts["outcome"]
    return plan_sphere.plan_verdict(checks(o), o, o["chain_touched"], "obstacles moved")
