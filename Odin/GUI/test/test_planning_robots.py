"""The planning bridge (gui.planning, issue 17) on Kautham's other physics demos, as they are
(tools/kautham/ode_demos): the planar chain, whose base is held and whose tool the planner
follows, and the car; their servo-driven propagations restore exactly and replay bit for bit
in a fresh world as run_path runs them; the planner's parameters the problem gives are the
search's."""

import numpy as np
import pytest

from gui.core.translate import plan_problem
from gui.core.control_path import ControlRow, run_control_path
from gui.planning.backend import CoreBackend
from gui.planning.bridge import plan, replay
from gui.planning.problem import SearchSettings, planning_problem
from gui_core_world import CoreWorld, quiet_plan

CHAIN = ("demos", "OMPL_ode_demos", "Chain", "k-PMPChain.xml")
CAR = ("demos", "OMPL_ode_demos", "Car", "k-PMPCar.xml")


def _plan(ode_demos_dir, parts):
    return quiet_plan(ode_demos_dir.joinpath(*parts))


@pytest.fixture
def chain_plan(ode_demos_dir):
    return _plan(ode_demos_dir, CHAIN)


def test_the_chain_problem_follows_its_gripper_to_the_goal_s_forward_kinematics(chain_plan):
    problem = planning_problem(chain_plan)
    assert problem.base_body == "Chain/base_link"
    # the last link before the chain forks into its fingers: Kautham's body 3
    assert problem.tracked_body == "Chain/gripper"
    assert problem.tool_bodies == {"Chain/gripper", "Chain/finger1", "Chain/finger2"}
    # <Goal> 0.513 0.194 0.134: joint1 -1.55 + 0.513 * 3.1, joint2 -2.1 + 0.194 * 4.2; the
    # chain hangs along -y from its base at the origin (joint 1 0.02 m out, links of 0.2 m,
    # all scaled 11), its joints turning about the world's z (Home turns the base's y there)
    q1, q2 = -1.55 + 0.513 * 3.1, -2.1 + 0.194 * 4.2
    length = 0.2 * 11
    expected = [length * (np.sin(q1) + np.sin(q1 + q2)),
                -0.02 * 11 - length * (np.cos(q1) + np.cos(q1 + q2))]
    assert problem.goal_xy == pytest.approx(expected, abs=1e-6)
    assert problem.searched == (0, 1, 2)
    assert problem.forbidden == {"box1", "redCube1", "redCube2", "redCube3"}


def test_a_held_chain_pushes_with_its_tool_only(chain_plan):
    problem = planning_problem(chain_plan)
    assert problem.forbidden_contacts([("Chain/gripper", "box2"), ("Chain/link1", "ground"),
                                       ("Chain/link1", "Chain/link2")]) == []
    assert problem.forbidden_contacts([("box2", "Chain/link2")]) == [("box2", "Chain/link2")]
    assert problem.forbidden_contacts([("Chain/finger1", "redCube2")]) == \
        [("Chain/finger1", "redCube2")]
    # nothing but the ground may touch a fixed obstacle, not even a box the tool pushes
    # (PlanarChainEnvironment's isValidCollision)
    assert problem.forbidden_contacts([("box2", "box1"), ("box1", "ground"),
                                       ("box2", "box3"), ("redCube2", "box1")]) == \
        [("box2", "box1"), ("redCube2", "box1")]
    # what the robot touched, once per pair of objects: not itself, not others' contacts
    assert problem.robot_contacts([("box2", "Chain/finger1"), ("box1", "ground"),
                                   ("Chain/link1", "Chain/link2"),
                                   ("Chain/finger1", "box2")]) == [("Chain/finger1", "box2")]


def test_the_problem_s_planner_parameters_are_the_search_s(chain_plan):
    settings = SearchSettings.of_problem(chain_plan)
    # k-PMPChain.xml: Min Control Steps 1, Max Control Steps 30, Goal Bias 0.05, Max Speed 10
    assert (settings.min_control_steps, settings.max_control_steps) == (1, 30)
    assert settings.goal_bias == pytest.approx(0.05) and settings.max_speed == 10
    assert chain_plan.problem.planner.search.time_limit == 90
    assert SearchSettings.of_problem(chain_plan, max_control_steps=8,
                                     goal_tolerance=None).max_control_steps == 8


def test_the_car_follows_its_chassis_with_two_controls(ode_demos_dir):
    problem = planning_problem(_plan(ode_demos_dir, CAR))
    assert problem.tracked_body == problem.base_body == "SimpleCar/base_link"
    assert problem.control_size == 2 and problem.searched == (0, 1)
    assert problem.forbidden == {"wall5", "wall6", "wallb1", "wallb2", "wallb3", "wallb4"}
    assert np.hypot(*problem.goal_xy) > 4.0      # across the arena


@pytest.mark.parametrize("parts,controls", [
    (CHAIN, [(0.9, 0.2, 0.5)] * 6 + [(0.1, 0.8, 0.5)] * 5),
    (CAR, [(0.7, 1.0)] * 6 + [(0.2, 0.9)] * 5),
])
def test_servo_propagations_restore_exactly_and_replay_in_a_fresh_world(
        ode_demos_dir, parts, controls):
    built = _plan(ode_demos_dir, parts)
    backend = CoreBackend(built, planning_problem(built))
    try:
        state = backend.start_state()
        middle = None
        for k, control in enumerate(controls):
            outcome = backend.propagate([(state, control)])[0]
            state = outcome.state
            if k == 5:
                middle = outcome
        # from a restored middle state, after other work, the same continuation
        backend.propagate([(backend.start_state(), (0.5,) * len(controls[0]))])
        again = middle.state
        for control in controls[6:]:
            again = backend.propagate([(again, control)])[0].state
        assert again.tobytes() == state.tobytes()
        rows = [ControlRow(c, backend.problem.step) for c in controls]
        planned_end = replay(backend, rows)
    finally:
        backend.close()
    world = CoreWorld()
    try:
        fresh = plan_problem(built.problem)
        world.execute(fresh)
        run_control_path(world, fresh.robot(), rows)
        assert world.core.body_state_vector().tobytes() == state.tobytes()
    finally:
        world.close()
    assert np.isfinite(planned_end).all()


def test_kpiece_moves_the_chain_s_gripper_toward_its_goal(chain_plan):
    backend = CoreBackend(chain_plan, planning_problem(chain_plan))
    try:
        start = backend.tracked_state(backend.start_state())[0]
        result = plan(backend, "KPIECE1", time_limit=3.0, seed=5)
    finally:
        backend.close()
    problem = backend.problem
    assert result.rows and result.propagations > 100
    assert result.goal_distance < problem.goal_distance(start) - 0.3
