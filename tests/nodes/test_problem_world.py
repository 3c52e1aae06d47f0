"""A problem's world is the problem's (issue 28): loading a problem sets every world parameter
and step value, so what ran before it in the node changes nothing.

One node runs Kautham's car problem (0.05 s steps, 20 Hz, Kautham's ERP and gravity), is left
with the exact solver and a changed gravity and damping as ``run_path --solver worldstep`` and
the Settings tab leave them, then loads the grasp scene (the TX90 with its hand, a 2012 problem
without physics); a fresh node loads the same grasp scene. Both hold the same parameters and
step values, and after 2 s of simulated time every body's state is the same bit for bit.
Before, the grasp scene inherited the car's 0.05 s steps and the solver left behind."""
from __future__ import annotations

import numpy as np
import pytest

pytestmark = [pytest.mark.forked, pytest.mark.slow]

CAR = "demos/OMPL_ode_demos/Car/k-PMPCar.xml"
GRASP = "legacy_2012/examples/TX90_RHand_ICRA10_5PMD_TwoCan.xml"
SECONDS = 2.0


def _load(client, problem_file):
    """New Scene, then the problem as load_problem builds it."""
    import logging

    from gui.core.kautham.problem import load_problem
    from gui.core.translate import plan_problem
    client.new_scene()
    logging.disable(logging.WARNING)        # what Odin does not use: the loader's tests
    try:
        plan = plan_problem(load_problem(problem_file))
    finally:
        logging.disable(logging.NOTSET)
    client.execute(plan)
    return plan


def _run(client, seconds: float):
    """``seconds`` of simulated time, cycle by cycle (the node is paused)."""
    client.step_once(round(seconds / client.step_values().cycle_time))


def _world(client):
    """(parameters, step values, every body's raw state vector) after 2 s of the grasp."""
    world = client.world()
    state = np.array(client.call("get_state").state_vector)
    return world.parameters, world.step_values, state


def test_the_grasp_scene_after_the_car_is_the_grasp_scene_of_a_fresh_node(
        ros_master, kautham_dir, ode_demos_dir):
    from gui.ros.client import WorldClient
    from odin_common.interface import Solver
    ros_master.rosrun("VirtualWorld", "virtualWorld", "_simulate:=false")
    ros_master.rosrun("VirtualWorld", "virtualWorld", "_simulate:=false", "__ns:=/fresh")
    used = WorldClient()
    fresh = WorldClient("/fresh/virtual_world")

    car = _load(used, ode_demos_dir / CAR)
    assert used.step_values().step == pytest.approx(car.world.step) and car.world.step > 0.01
    _run(used, 1.0)
    # what a run_path --solver worldstep and a Settings tab leave behind
    used.set_world(solver=Solver.WORLDSTEP, gravity=(0.0, 0.0, -1.62), linear_damping=0.01)

    _load(used, kautham_dir / GRASP)
    _load(fresh, kautham_dir / GRASP)
    _run(used, SECONDS)
    _run(fresh, SECONDS)
    parameters, steps, state = _world(used)
    fresh_parameters, fresh_steps, fresh_state = _world(fresh)
    assert parameters == fresh_parameters
    assert parameters.solver == Solver.AUTO and parameters.gravity == (0.0, 0.0, -9.81)
    assert steps == fresh_steps and steps.step == pytest.approx(0.001)
    assert state.tobytes() == fresh_state.tobytes()
    used.close()
    fresh.close()
