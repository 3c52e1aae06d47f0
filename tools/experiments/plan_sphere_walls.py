"""Past the thesis (issue 17): OMPL's KPIECE1 plans Kautham's second ODE sphere demo,
``k-PMPSphere.xml``, through Odin's physics; the plan drives the sphere to its goal in a fresh
world node.

Scene: the public ``k-PMPSphere.xml`` exactly as the GUI loads it: the arena of ``Sphere.xml``
(four walls 9 m long, an infinite ground plane, the 25 kg sphere of radius 0.25 m) with its four
blocks moved out to x = +-3.3 and +-4 m, and three more walls inside it (wall4 at the centre,
wall5 and wall6 turned 45 degrees at y = +-2.5 m), all of which the sphere must not touch. The
query crosses the arena from (-1.51, 1.78) m to (1.89, -2.58) m, past the inner walls.

Planning and execution as ``plan_sphere`` (its docstring): KPIECE1 with a fixed seed over the
Core back end, the problem's own planner parameters (Goal Bias 0.6, 2 to 30 steps of 0.03 s a
control), the plan written as a control path, read back and run as ``rosrun GUI run_path
--controls`` runs it in a world node that was only built from the problem. The same outcome
and checks (``plan_sphere.checks``): solved, replayed bit for bit, in the goal region, no
wall touched (inner walls included), inside the arena.
"""
from __future__ import annotations

import common
import plan_sphere

PROBLEM = common.KAUTHAM_DIR / "current_2025" / "demos" / "OMPL_ode_demos" / "Sphere" / \
    "k-PMPSphere.xml"
PARAMETERS = dict(plan_sphere.PARAMETERS, seed=1, time_limit_s=300.0)
#: the whole arena: the route crosses it corner to corner
CAMERA = common.Camera(eye=(0.0, -9.0, 9.5), target=(0.0, 0.4, 0.0))


def run(frames: bool = True) -> dict:
    return plan_sphere.run(frames, PROBLEM, "plan_sphere_walls", PARAMETERS, CAMERA)


checks = plan_sphere.checks
verdict = plan_sphere.verdict
