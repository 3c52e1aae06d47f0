"""Past the thesis (issue 17): OMPL's KPIECE1 plans Kautham's ODE chain demo through Odin's
physics, and the plan it writes moves the chain's gripper to its goal in a fresh world node.

Scene: Kautham's ``OMPL_ode_demos/Chain/k-PMPChain.xml`` exactly as the GUI loads it
(vendored from Kautham's repository: tools/kautham/ode_demos): a planar chain (PlanerChain1
scaled 11 times: two links of 2.2 m, a gripper with two fingers) whose base is held 0.5 m
above the ground, its joints turning about the vertical; six obstacles resting on an infinite
ground plane. Kautham's chain planner drives the chain as its PlanarChainEnvironment does: each
joint at up to 1 rad/s under 7 N m, no joint damping or friction (gui.core.translate.chain).
Its types decide what may be touched: box2 is "freeManipulatable", which only the gripper and
fingers may push; box1 and the red cubes are "fixed", which nothing of the chain may touch. The
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

import common
import plan_sphere

PROBLEM = common.ROOT / "tools" / "kautham" / "ode_demos" / "demos" / "OMPL_ode_demos" / \
    "Chain" / "k-PMPChain.xml"
PARAMETERS = {
    "planner": "KPIECE1",
    "seed": 4,
    "time_limit_s": 300.0,       # a bound for a busy machine: the seed decides the plan
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
    return plan_sphere.plan_and_run("plan_chain", PROBLEM, PARAMETERS, CAMERA, frames,
                                    "the chain's controls (link1, link2, gripper)", analyse)


def analyse(s, e: "plan_sphere.Executed") -> dict:
    return {"outcome": {**plan_sphere.obstacle_facts(e, "chain_touched"),
                        "tracked_link": e.problem.tracked_body},
            "contacts": s.contact_rates()}


def checks(o: dict) -> dict:
    """Each outcome the run must hold, by name (run.py's verdict and the test)."""
    moved = o["obstacles_moved_in_the_plane_m"]
    return {
        **plan_sphere.replay_checks(o),
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
