"""The planning bridge's pool back end (gui.planning.pool, issue 17): two world nodes hold the
Sphere problem; propagations from the planner's state vectors, fanned out over them, answer
bit for bit what the Core back end answers, and a plan searched through the pool replays in the
Core to the same place; the chain's servo controls answer the same through the pool;
`rosrun GUI plan --backend pool` refuses an absent world in one line."""
from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

pytestmark = pytest.mark.forked

NAMESPACES = ["/w0/virtual_world", "/w1/virtual_world"]
SPHERE = ("current_2025", "demos", "OMPL_ode_demos", "Sphere", "Sphere.xml")


def _same(a, b) -> bool:
    return (a.state.tobytes() == b.state.tobytes() and a.position.tobytes() == b.position.tobytes()
            and a.velocity.tobytes() == b.velocity.tobytes() and a.collisions == b.collisions)


def test_the_pool_answers_what_the_core_answers_and_plans_that_replay(ros_master, kautham_dir,
                                                                      plan_of):
    for namespace in ("/w0", "/w1"):
        ros_master.rosrun("VirtualWorld", "virtualWorld", f"__ns:={namespace}")
    for namespace in NAMESPACES:
        ros_master.wait_for_service(f"{namespace}/propagate")
    from gui.planning.backend import CoreBackend
    from gui.planning.bridge import plan, replay
    from gui.planning.problem import planning_problem
    from gui.planning.pool import PoolBackend
    sphere_file = kautham_dir.joinpath(*SPHERE)
    sphere = plan_of(sphere_file)
    problem = planning_problem(sphere)
    core = CoreBackend(sphere, problem)
    pool = PoolBackend(plan_of(sphere_file), planning_problem(plan_of(sphere_file)), NAMESPACES)
    try:
        assert pool.size == 2
        assert pool.start_state().tobytes() == core.start_state().tobytes()
        for got, want in zip(pool.tracked_state(pool.start_state()),
                             core.tracked_state(core.start_state())):
            assert got.tobytes() == want.tobytes()
        rng = np.random.default_rng(3)
        vectors = [core.start_state()]
        for _ in range(3):                   # a chain of steps, then a fan from its states
            vectors.append(core.propagate([(vectors[-1], (0.9, 0.2, 0.4))])[0].state)
        requests = [(vectors[k % 4], tuple(rng.random(2)) + (0.4,)) for k in range(8)]
        fanned, alone = pool.propagate(requests), core.propagate(requests)
        assert all(_same(a, b) for a, b in zip(fanned, alone))
        assert pool.propagations == 8
        result = plan(pool, "KPIECE1", time_limit=3.0, seed=11)
        assert result.propagations > 50 and result.rows
        assert replay(core, result.rows).tobytes() == result.final_position.tobytes()
    finally:
        pool.close()
        core.close()


def test_servo_controls_through_the_pool_answer_what_the_core_answers(ros_master,
                                                                      ode_demos_dir, plan_of):
    """The chain's controls are a Set Servo and a Propagate made by one world: whichever
    world serves a request, and whatever it served before, the answer is the Core's."""
    for namespace in ("/w0", "/w1"):
        ros_master.rosrun("VirtualWorld", "virtualWorld", f"__ns:={namespace}")
    for namespace in NAMESPACES:
        ros_master.wait_for_service(f"{namespace}/propagate")
    from gui.planning.backend import CoreBackend
    from gui.planning.problem import planning_problem
    from gui.planning.pool import PoolBackend
    chain = plan_of(ode_demos_dir / "demos" / "OMPL_ode_demos" / "Chain" / "k-PMPChain.xml")
    core = CoreBackend(chain, planning_problem(chain))
    pool = PoolBackend(chain, planning_problem(chain), NAMESPACES)
    try:
        vectors = [core.start_state()]
        for _ in range(3):
            vectors.append(core.propagate([(vectors[-1], (0.9, 0.1, 0.5))])[0].state)
        rng = np.random.default_rng(5)
        requests = [(vectors[k % 4], tuple(rng.random(3))) for k in range(10)]
        fanned, alone = pool.propagate(requests), core.propagate(requests)
        assert all(_same(a, b) for a, b in zip(fanned, alone))
    finally:
        pool.close()
        core.close()


def test_a_held_control_is_one_round_trip_a_row(ros_master, ode_demos_dir, plan_of):
    """The chain's control held over many propagations, each from the state the last reached
    (as OMPL holds a control): the first asks the world for the whole row, the others are
    answered from it, bit for bit the Core's (issue 42: one round trip a control, not a
    step); another control, or a state off the row, asks again."""
    ros_master.rosrun("VirtualWorld", "virtualWorld", "__ns:=/w0")
    ros_master.wait_for_service(f"{NAMESPACES[0]}/propagate")
    from gui.planning.backend import CoreBackend
    from gui.planning.problem import planning_problem
    from gui.planning.pool import PoolBackend
    chain = plan_of(ode_demos_dir / "demos" / "OMPL_ode_demos" / "Chain" / "k-PMPChain.xml")
    problem = planning_problem(chain)
    core = CoreBackend(chain, problem)
    pool = PoolBackend(chain, planning_problem(chain), NAMESPACES[:1])
    trips = []
    map_calls = pool.pool.map_calls
    pool.pool.map_calls = lambda calls: (trips.append(len(calls)), map_calls(calls))[1]
    try:
        held = problem.settings.max_control_steps
        for control, steps in (((0.9, 0.1, 0.5), held), ((0.2, 0.7, 0.4), 3)):
            mine, theirs = pool.start_state(), core.start_state()
            for _ in range(steps):
                a = pool.propagate([(mine, control)])[0]
                b = core.propagate([(theirs, control)])[0]
                assert _same(a, b)
                mine, theirs = a.state, b.state
        assert trips == [1, 1]                   # a round trip for each control's row
        assert pool.propagations == held + 3
    finally:
        pool.close()
        core.close()


def test_parallel_searches_share_the_pool_one_world_each(ros_master, kautham_dir, tmp_path):
    """`plan --parallel 2` over two worlds: each search builds the problem in its own world
    (a process of its own, a node of its own) and the first solution is written."""
    for namespace in ("/w0", "/w1"):
        ros_master.rosrun("VirtualWorld", "virtualWorld", f"__ns:={namespace}")
    for namespace in NAMESPACES:
        ros_master.wait_for_service(f"{namespace}/propagate")
    out = tmp_path / "p.path"
    run = subprocess.run(["rosrun", "GUI", "plan", str(kautham_dir.joinpath(*SPHERE)),
                          "--backend", "pool", "--worlds", ",".join(NAMESPACES),
                          "--parallel", "2", "--seed", "7", "--time", "60", "--out", str(out)],
                         capture_output=True, text=True, timeout=300, env=ros_master.env)
    assert run.returncode == 0, run.stderr
    statistics = json.loads(run.stdout[run.stdout.index("{"):run.stdout.rindex("}") + 1])
    assert statistics["solved"] and statistics["seed"] in (7, 8)
    assert sorted(s["seed"] for s in statistics["searches"]) == [7, 8]
    assert out.exists()


def test_plan_with_the_pool_refuses_an_absent_world_in_one_line(ros_master, kautham_dir,
                                                                 tmp_path):
    out = tmp_path / "p.path"
    run = subprocess.run(["rosrun", "GUI", "plan", str(kautham_dir.joinpath(*SPHERE)),
                          "--backend", "pool", "--worlds", "/nobody/virtual_world",
                          "--world-timeout", "2", "--time", "1", "--out", str(out)],
                         capture_output=True, text=True, timeout=120, env=ros_master.env)
    assert run.returncode == 2, run.stderr
    errors = [line for line in run.stderr.splitlines() if not line.startswith("plan: warning")]
    assert errors == ["plan: error: /nobody/virtual_world: no world answering after 2 s"]
    assert not out.exists()


def test_a_pool_world_killed_during_the_search_ends_plan_with_its_one_line(ros_master,
                                                                           kautham_dir,
                                                                           tmp_path):
    """The world dies while the planner searches (a goal too tight to reach first): plan
    says so in one line on stderr and exits 2; before, 55 lines of nanobind's "leaked
    instances" report followed it (OMPL's objects were still alive at the interpreter's
    teardown)."""
    node = ros_master.rosrun("VirtualWorld", "virtualWorld", "__ns:=/w9")
    ros_master.wait_for_service("/w9/virtual_world/propagate")
    out = tmp_path / "never.path"
    search = subprocess.Popen(
        ros_master.rosrun_command(["rosrun", "GUI", "plan", str(kautham_dir.joinpath(*SPHERE)),
                                   "--backend", "pool", "--worlds", "/w9/virtual_world",
                                   "--goal-tolerance", "1e-6", "--seed", "3", "--time", "120",
                                   "--out", str(out)]),
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ros_master.env,
        stdin=subprocess.DEVNULL)
    try:
        for line in search.stdout:
            if "searching for up to" in line:
                break
        node.kill()
        node.wait(30)
        _, stderr = search.communicate(timeout=120)
    finally:
        if search.poll() is None:
            search.kill()
    errors = [line for line in stderr.splitlines() if not line.startswith("plan: warning")]
    assert search.returncode == 2, stderr
    assert len(errors) == 1 and errors[0].startswith("plan: error: "), stderr
    assert "nanobind" not in stderr and "Traceback" not in stderr
    assert not out.exists()


def test_a_pool_world_killed_before_plan_starts_is_said_in_one_line(ros_master, kautham_dir,
                                                                    tmp_path):
    """A world killed (SIGKILL) stays registered with the master: waiting for it, rospy
    tried to contact it and logged "failed to contact, will keep trying" on stderr around
    the tool's one line."""
    node = ros_master.rosrun("VirtualWorld", "virtualWorld", "__ns:=/w8")
    ros_master.wait_for_service("/w8/virtual_world/propagate")
    node.kill()
    node.wait(30)
    out = tmp_path / "never.path"
    run = subprocess.run(
        ros_master.rosrun_command(["rosrun", "GUI", "plan", str(kautham_dir.joinpath(*SPHERE)),
                                   "--backend", "pool", "--worlds", "/w8/virtual_world",
                                   "--world-timeout", "3", "--time", "1", "--out", str(out)]),
        capture_output=True, text=True, timeout=120, env=ros_master.env)
    errors = [line for line in run.stderr.splitlines() if not line.startswith("plan: warning")]
    assert run.returncode == 2, run.stderr
    assert errors == ["plan: error: /w8/virtual_world: no world answering after 3 s"]
    assert not out.exists()
