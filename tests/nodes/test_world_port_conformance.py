"""The world seam's two implementations answer alike (gui.core.world_port): the same control
paths, tracked paths and holds, run through a world node (gui.ros.world_port.ClientWorldPort
over a WorldClient) and through a Core of this process (gui.planning.core_world.CoreWorld),
give the same numbers bit for bit: every row's base position and tracked body's state, every
tracked sample, and the whole body state vector after them.

The world node runs its problems one after another, each after New Scene, as a user's session
does; each Core is fresh: what the node ran before changes nothing."""
from __future__ import annotations

import logging

import numpy as np
import pytest

pytestmark = pytest.mark.forked

CAR = ("demos", "OMPL_ode_demos", "Car", "k-PMPCar.xml")
CHAIN = ("demos", "OMPL_ode_demos", "Chain", "k-PMPChain.xml")
SPHERE = ("current_2025", "demos", "OMPL_ode_demos", "Sphere", "Sphere.xml")
TRO = ("legacy_2012", "examples", "TRO")


def _plan(problem_file, **defaults):
    from gui.core.kautham.problem import load_problem
    from gui.core.translate import BuildDefaults, plan_problem
    logging.disable(logging.WARNING)
    try:
        return plan_problem(load_problem(problem_file), BuildDefaults(**defaults))
    finally:
        logging.disable(logging.NOTSET)


def _rows(handle, seed: int, count: int, step: float):
    """``count`` control rows of random controls, each a few of the world's steps long."""
    from gui.core.control_path import ControlRow, control_size
    rng = np.random.default_rng(seed)
    return [ControlRow(tuple(float(c) for c in rng.random(control_size(handle))),
                       step * int(rng.integers(5, 30))) for _ in range(count)]


def _bits(values) -> bytes:
    return b"".join(np.asarray(v, dtype=np.float64).tobytes() for v in values)


def _control_path_run(port, plan, seed: int) -> list:
    """A control path of random rows, the robot held where it ends, then 0.1 s more: what
    the port answered, as bytes."""
    from gui.core.control_path import hold, run_control_path
    handle = plan.robot()
    tracked = handle.bodies[-1].body_id
    rows = _rows(handle, seed, 12, port.step_values().step)
    results = run_control_path(port, handle, rows, watch=tracked)
    hold(port, handle)
    port.advance(0.1)
    answers = [_bits([r.base_position, *r.watched]) for r in results]
    return answers + [_bits(port.body_state(b.body_id)) for b in handle.bodies]


def _state_vector(client) -> bytes:
    return np.asarray(client.call("get_state").state_vector, dtype=np.float64).tobytes()


def test_control_paths_and_holds_answer_alike_through_the_node_and_the_core(world,
                                                                            ode_demos_dir):
    """A car (servos on hinge-2 wheels) and a chain (joint servos), one after the other in
    the node."""
    from gui.planning.core_world import CoreWorld
    from gui.ros.client import WorldClient
    from gui.ros.world_port import ClientWorldPort
    client = WorldClient()
    try:
        for seed, problem in enumerate((CAR, CHAIN)):
            problem_file = ode_demos_dir.joinpath(*problem)
            client.new_scene()
            plan = _plan(problem_file)
            client.execute(plan)
            through_node = _control_path_run(ClientWorldPort(client), plan, seed)
            core = CoreWorld()
            try:
                plan = _plan(problem_file)
                core.execute(plan)
                assert through_node == _control_path_run(core, plan, seed), problem
                assert _state_vector(client) == core.core.body_state_vector().tobytes()
            finally:
                core.close()
    finally:
        client.close()


def test_a_free_body_pushed_by_forces_answers_alike(world, kautham_dir):
    """Kautham's Sphere: each row a force on a free body for its duration."""
    from gui.planning.core_world import CoreWorld
    from gui.ros.client import WorldClient
    from gui.ros.world_port import ClientWorldPort
    problem_file = kautham_dir.joinpath(*SPHERE)
    client, core = WorldClient(), CoreWorld()
    try:
        plan = _plan(problem_file)
        client.execute(plan)
        through_node = _control_path_run(ClientWorldPort(client), plan, 7)
        plan = _plan(problem_file)
        core.execute(plan)
        assert through_node == _control_path_run(core, plan, 7)
        assert _state_vector(client) == core.core.body_state_vector().tobytes()
    finally:
        core.close()
        client.close()


def _tracked_run(port, plan, solution) -> list:
    from gui.core.execution import execute_tracked
    report = execute_tracked(port, plan, solution)
    return [_bits(report.errors), _bits(report.actuals), _bits([report.goal_error]),
            repr(report.collisions).encode(), repr(report.segments).encode()]


def test_tracked_paths_answer_alike_through_the_node_and_the_core(world, kautham_dir):
    """Kautham 2012's 2DRR solution (.kps) followed by the servos from the query's start."""
    from gui.core.kautham.problem import load_problem
    from gui.core.kautham.solutions import read_solution
    from gui.planning.core_world import CoreWorld
    from gui.ros.client import WorldClient
    from gui.ros.world_port import ClientWorldPort
    tro = kautham_dir.joinpath(*TRO)
    problem_file, solution_file = tro / "2DRR_obstacle.xml", tro / "2DRR_obstacle_sol.kps"
    solution = read_solution(solution_file, load_problem(problem_file))
    client, core = WorldClient(), CoreWorld()
    try:
        plan = _plan(problem_file, start_at_query=True)
        client.execute(plan)
        through_node = _tracked_run(ClientWorldPort(client), plan, solution)
        plan = _plan(problem_file, start_at_query=True)
        core.execute(plan)
        assert through_node == _tracked_run(core, plan, solution)
        assert _state_vector(client) == core.core.body_state_vector().tobytes()
    finally:
        core.close()
        client.close()
