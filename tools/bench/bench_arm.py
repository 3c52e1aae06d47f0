"""Benchmark of a real robot arm held by its motors: ``arm_sag_quickstep_mm``.

The KUKA LWR of Kautham's public problem ``legacy_2012/examples/Kuka_two_columns.xml``, built
in the Core by the GUI's build plan (ROS-free, as the GUI builds it), stretched out at its Home
configuration (all joints 0: horizontal, gravity's worst case), every joint's motor a servo
holding 0, gravity on, 10 s of 1 ms steps. The figure is the largest drop of the tip link's
centre (mm) under the default solver (auto: dWorldStep on this arm's island of 42 rows), the fast
default the issue asks for; goal <= 1.0 mm.

Beside it, each in a process of its own, rounds alternating: the same arm under explicit
QuickStep (20 iterations; ``arm_sag_plain_quickstep_mm``, the sag users met before) and the
steps/s of both, as a ratio measured side by side (``arm_auto_over_quickstep_speed``).

``flagship_hold_drift_mm``: Kautham's flagship problem
``legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml`` (the TX90 with the SAH hand and two
cans) loaded by the GUI's loader into a fresh Core with the default world parameters and
nothing else set (the plan's servos hold the start pose), 10 s of the problem's 1 ms steps: the
largest distance (mm) of the arm's tool link (Tcp) from where it started; goal <= 1.0 (issue
28: the defaults hold robots).
"""
import os
import pathlib
import statistics
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "Odin" / "GUI" / "test"))

from forked import in_child  # noqa: E402

PROBLEM = "legacy_2012/examples/Kuka_two_columns.xml"
SECONDS = 10.0
STEP = 0.001
CHUNK = 100                     # steps between two reads of the tip
ROUNDS = int(os.environ.get("ODIN_BENCH_ROUNDS", "3"))


def _hold(solver: int) -> dict:
    """The arm held for SECONDS under ``solver``: its largest sag (mm) and steps/s (step
    calls only)."""
    from gui.core.translate import plan_problem
    from gui.core.kautham.problem import load_problem
    from gui_core_world import CoreWorld
    world = CoreWorld()
    try:
        plan = plan_problem(load_problem(pathlib.Path(os.environ["ODIN_KAUTHAM_DIR"]) / PROBLEM))
        world.execute(plan)
        core = world.core
        core.set_world_parameters(solver=solver, gravity=(0.0, 0.0, -9.81))
        robot = plan.robot()
        core.set_servo(robot.motor_ids, [0.0] * len(robot.motor_ids))
        tip = robot.bodies[-1].body_id
        z0, worst, stepping = world.position(tip)[2], 0.0, 0.0
        for _ in range(round(SECONDS / STEP / CHUNK)):
            t = time.perf_counter()
            core.step(STEP, CHUNK)
            stepping += time.perf_counter() - t
            worst = max(worst, z0 - world.position(tip)[2])
        return {"sag_mm": 1000.0 * worst, "steps_per_s": SECONDS / STEP / stepping,
                "solver_used": int(core.last_step_solver)}
    finally:
        world.close()


FLAGSHIP = "legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml"
FLAGSHIP_TOOL = "TX90 SAHand Right/Tcp"


def _flagship_hold() -> dict:
    """The flagship scene under the defaults for SECONDS: the tool link's and any link's
    largest distance from its start (mm), and the solver the last step used."""
    from gui_core_world import CoreWorld, quiet_plan
    world = CoreWorld()
    try:
        plan = quiet_plan(pathlib.Path(os.environ["ODIN_KAUTHAM_DIR"]) / FLAGSHIP)
        world.execute(plan)
        worst = world.drift_mm([b.body_id for b in plan.robot().bodies], SECONDS, CHUNK)
        return {"tool_mm": worst[FLAGSHIP_TOOL], "any_link_mm": max(worst.values()),
                "solver_used": int(world.core.last_step_solver)}
    finally:
        world.close()


def run(out_dir: pathlib.Path) -> dict:
    from odin_common.interface import Solver
    from odin_common.world_parameters import default
    auto, plain = [], []
    for _ in range(ROUNDS):
        auto.append(in_child(_hold, int(default("solver"))))
        plain.append(in_child(_hold, int(Solver.QUICKSTEP)))
    ratios = [a["steps_per_s"] / q["steps_per_s"] for a, q in zip(auto, plain)]
    print(f"arm: default solver {auto}, QuickStep {plain}", flush=True)
    flagship = in_child(_flagship_hold)
    print(f"flagship TX90 + hand held under the defaults: {flagship}", flush=True)
    return {"flagship_hold_drift_mm": round(flagship["tool_mm"], 4),
            "arm_sag_quickstep_mm": round(max(a["sag_mm"] for a in auto), 4),
            "arm_sag_plain_quickstep_mm": round(max(q["sag_mm"] for q in plain), 3),
            "arm_auto_over_quickstep_speed": round(statistics.median(ratios), 3)}
