"""A planner's success that is one (issue 41, finding 1): a control search counts as solved only
when its plan, replayed from the start, ends in the goal region with no invalid contact on the
way; a query no search can solve (its goal inside a fixed obstacle, outside the limits) is
refused before any search; a replay that disagrees with the search says what differs; the
same for the benchmark's runs.

The problems are written here: a 25 kg ball of radius 0.25 m pushed by a force in a walled
arena (Kautham's 2D sphere environment: sp3.cntr-like controls, KPIECE2DPlanner), a dividing
wall across its middle, a short wall ("post") near the way, two blocks it may push (named as
Kautham's manipulable cubes). Every wall is a free body of the world, as in Kautham's ODE
environment: before the fix KPIECE1 "solved" a goal inside the dividing wall by pushing a
block into the wall until the wall slid 0.94 m aside, and a goal beside the arena's wall by
shoving the dividing wall 4 m and knocking the north wall 1 m, both printed as "Exact
solution" and exit 0."""
from __future__ import annotations

import dataclasses
import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from gui.errors import PlanningError
from gui.planning.backend import CoreBackend
from gui.planning.bridge import plan
from gui.planning.problem import planning_problem
from gui_core_world import quiet_plan
from kautham_files import write_problem

BALL = """<?xml version="1.0"?>
<robot name="ball"><link name="base">
 <inertial><mass value="25"/><inertia ixx="0.625" iyy="0.625" izz="0.625" ixy="0" ixz="0"
  iyz="0"/></inertial>
 <collision><geometry><sphere radius="0.25"/></geometry></collision></link></robot>
"""
CONTROLS = """<?xml version="1.0"?>
<ControlSet>
 <Offset><DOF name="ball/X" value="0.5"/><DOF name="ball/Y" value="0.5"/>
  <DOF name="ball/Z" value="0.5"/></Offset>
 <Control name="ball/x" eigValue="1.0"><DOF name="ball/X" value="1.0"/></Control>
 <Control name="ball/y" eigValue="1.0"><DOF name="ball/Y" value="1.0"/></Control>
 <Control name="ball/z" eigValue="1.0"><DOF name="ball/Z" value="1.0"/></Control>
</ControlSet>
"""
# name: (box size m, mass kg, home x y z m, turn about z rad)
BODIES = {
    "divider": ((5.8, 0.5, 0.48), 5.0, (0.0, 0.0, 0.24), 0.0),
    "post": ((1.7, 0.5, 0.5), 2.0, (1.5, -2.0, 0.25), np.pi / 4),
    "cubeDE1": ((0.5, 0.5, 0.5), 0.5, (0.0, -3.0, 0.25), 0.0),
    "cubeDE2": ((0.5, 0.5, 0.5), 0.5, (1.0, -0.75, 0.25), 0.0),
    "rim1": ((9.0, 0.5, 0.5), 2.0, (4.8, 0.0, 0.25), np.pi / 2),
    "rim2": ((9.0, 0.5, 0.5), 2.0, (-4.8, 0.0, 0.25), np.pi / 2),
    "rim3": ((9.0, 0.5, 0.5), 2.0, (0.0, 4.8, 0.25), 0.0),
    "rim4": ((9.0, 0.5, 0.5), 2.0, (0.0, -4.8, 0.25), 0.0),
}
FIXED = {"divider", "post", "rim1", "rim2", "rim3", "rim4"}
START = "0.5 0.36 0.4"          # the ball at (0, -1.4) m, below the dividing wall
IN_THE_WALL = "0.5 0.5 0.4"     # (0, 0) m: the dividing wall's middle
BY_THE_NORTH_WALL = "0.5 0.11 0.4"   # (0, -3.9) m: cubeDE1 pushed straight there hits rim4
NEARBY = "0.65 0.4 0.4"         # (1.5, -1.0) m: open floor


def _box(name: str, size, mass: float) -> str:
    a, b, c = size
    ixx, iyy, izz = (mass / 12 * (b * b + c * c), mass / 12 * (a * a + c * c),
                     mass / 12 * (a * a + b * b))
    return (f'<?xml version="1.0"?><robot name="{name}"><link name="base"><inertial>'
            f'<mass value="{mass}"/><inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="0" '
            f'ixz="0" iyz="0"/></inertial><collision><geometry><box size="{a} {b} {c}"/>'
            '</geometry></collision></link></robot>')


def arena(folder: pathlib.Path, goal: str, name: str = "arena.xml") -> pathlib.Path:
    """The arena problem (module docstring) with the query's ``goal`` (controls in [0, 1]:
    x = -5 + 10 c m), written in ``folder``."""
    files = {"ball.urdf": BALL, "ball.cntr": CONTROLS}
    obstacles = []
    for body, (size, mass, (x, y, z), turn) in BODIES.items():
        files[f"{body}.urdf"] = _box(body, size, mass)
        obstacles.append(f'<Obstacle obstacle="{body}.urdf" scale="1"><Home X="{x}" Y="{y}" '
                         f'Z="{z}" WX="0" WY="0" WZ="1" TH="{turn}"/></Obstacle>')
    problem = f"""<?xml version="1.0"?>
<Problem name="arena">
 <Robot robot="ball.urdf" scale="1">
  <Limits name="X" min="-5.0" max="5.0"/><Limits name="Y" min="-5.0" max="5.0"/>
  <Limits name="Z" min="-1" max="2.0"/>
  <Home X="10.0" Y="10.0" Z="0.0" WX="0.0" WY="0.0" WZ="1.0" TH="0.0"/>
 </Robot>
 {chr(10).join(obstacles)}
 <Controls robot="ball.cntr"/>
 <Planner><Parameters>
  <Name>KPIECE2DPlanner</Name>
  <Parameter name="_Max Planning Time">30</Parameter>
  <Parameter name="Goal Bias">0.6</Parameter>
  <Parameter name="Max Control Steps">30</Parameter>
  <Parameter name="Min Control Steps">2</Parameter>
  <Parameter name="PropagationStepSize">0.03</Parameter>
 </Parameters>
 <Queries><Query><Init>{START}</Init><Goal>{goal}</Goal></Query></Queries>
 </Planner>
</Problem>
"""
    return write_problem(folder, files, name, problem)


def _backend(path, backend_class=CoreBackend):
    built = quiet_plan(path)
    return backend_class(built, planning_problem(built))


class Unfaithful(CoreBackend):
    """A back end whose world does not repeat itself once the search is over: when asked for
    the start state again (the replay starts there), every step after it also reports the
    ball touching the dividing wall (``lie="touch"``) or ends 1 m east of where it is
    (``lie="shift"``), as a world that drifted between the search and the replay would."""
    lie = "touch"

    def __init__(self, *args):
        super().__init__(*args)
        self.starts = 0

    def start_state(self):
        self.starts += 1
        return super().start_state()

    def propagate(self, requests):
        outcomes = super().propagate(requests)
        if self.starts < 2:
            return outcomes
        if self.lie == "touch":
            return [o._replace(collisions=o.collisions + (("ball", "divider"),))
                    for o in outcomes]
        return [o._replace(position=o.position + np.array([1.0, 0.0, 0.0])) for o in outcomes]


def _fixed_moved_m(backend, end_state) -> dict:
    """{fixed obstacle: how far it moved in the plane (m) from the start to ``end_state``}."""
    start = backend.start_state()
    return {name: float(np.hypot(*(backend.bodies.body(end_state, name).position
                                   - backend.bodies.body(start, name).position)[:2]))
            for name in FIXED}


# -- the rule ----------------------------------------------------------------------------------
def test_nothing_but_the_ground_may_touch_a_fixed_obstacle(tmp_path):
    """Kautham's 2D environment forbids only the robot's contacts with a fixed obstacle; a
    block the ball pushed into the dividing wall moved it, and the plan counted as solved."""
    problem = planning_problem(quiet_plan(arena(tmp_path, NEARBY)))
    assert problem.forbidden == FIXED
    assert problem.forbidden_contacts([("ball", "cubeDE1"), ("cubeDE1", "ground"),
                                       ("ground", "ball"), ("divider", "ground")]) == []
    assert problem.forbidden_contacts([("ball", "rim1")]) == [("ball", "rim1")]
    assert problem.forbidden_contacts([("cubeDE1", "divider"), ("rim3", "divider"),
                                       ("cubeDE2", "cubeDE1")]) == \
        [("cubeDE1", "divider"), ("rim3", "divider")]


def test_a_search_no_longer_pushes_a_block_through_the_walls(tmp_path):
    """The goal beside the arena's south wall, a block on the way: seed 4 found a plan that
    pushed cubeDE2 into the dividing wall, shoved it 4 m and knocked the north wall 1 m. Now
    its plan touches no fixed obstacle and none moves."""
    backend = _backend(arena(tmp_path, BY_THE_NORTH_WALL))
    try:
        result = plan(backend, "KPIECE1", time_limit=120.0, seed=4)
        assert result.solved, result.statistics()
        state, touched = backend.start_state(), set()
        for row in result.rows:
            outcome = backend.propagate([(state, row.controls)])[0]
            state = outcome.state
            touched |= {frozenset(p) for p in outcome.collisions}
        moved = _fixed_moved_m(backend, state)
    finally:
        backend.close()
    assert not [p for p in touched if p & FIXED and "ground" not in p], touched
    assert max(moved.values()) < 1e-3, moved
    assert result.verdict.startswith("solved: the replay of its ")


# -- before the search ---------------------------------------------------------------------------
def test_a_goal_inside_a_fixed_wall_is_refused_before_any_search(tmp_path):
    backend = _backend(arena(tmp_path, IN_THE_WALL))
    try:
        with pytest.raises(PlanningError) as error:
            plan(backend, "KPIECE1", time_limit=30.0, seed=1)
        assert backend.propagations == 0             # no search time spent
    finally:
        backend.close()
    message = str(error.value)
    # the ball's centre 0.2 m up, in the middle of the 0.48 m high, 0.5 m thick wall
    assert "\n" not in message and "(0.000, 0.000, 0.200) m" in message
    assert "ball is 450.0 mm into divider" in message, message


def test_a_goal_outside_the_limits_is_refused_in_one_line(tmp_path):
    """Kautham's controls map a goal within the <Limits>; a problem whose limits leave the goal
    out (here: narrowed after reading) has no valid state there."""
    from gui.planning.problem import goal_refusal
    backend = _backend(arena(tmp_path, NEARBY))
    try:
        narrow = dataclasses.replace(backend.problem,
                                     base_bounds=np.array([[-5.0, 1.0], [-5, 5], [-1, 2]]))
        backend.problem = narrow
        backend.world.core.set_body_state_vector(backend.start_state())
        why = goal_refusal(narrow, backend.world)
        with pytest.raises(PlanningError, match="outside the problem's <Limits>"):
            plan(backend, "KPIECE1", time_limit=30.0, seed=1)
    finally:
        backend.close()
    assert why == ("the query's goal puts ball at (1.500, -1.000, 0.200) m, outside the "
                   "problem's <Limits>: x 1.500 not in [-5, 1] m")


# -- after the search ------------------------------------------------------------------------
@pytest.mark.parametrize("lie, differs", [
    ("touch", "its replay makes an invalid step at row 1 (0.030 s): ball touches divider, "
              "which is forbidden"),
    ("shift", "outside the 0.25 m goal region"),
])
def test_a_replay_that_disagrees_with_the_search_is_no_solution_and_says_so(tmp_path, lie,
                                                                           differs):
    class Lying(Unfaithful):
        pass
    Lying.lie = lie
    backend = _backend(arena(tmp_path, NEARBY), Lying)
    try:
        result = plan(backend, "KPIECE1", time_limit=60.0, seed=2)
    finally:
        backend.close()
    assert result.status == "Exact solution"         # what the search claimed
    assert not result.solved and result.rows
    assert result.disagreement.startswith("OMPL reports an exact solution, but ")
    assert differs in result.disagreement
    assert result.verdict.startswith("not solved: the replay disagrees with the search")
    assert result.statistics()["verdict"] == result.verdict


def test_a_faithful_replay_keeps_the_rule_and_repeats_the_search(tmp_path):
    from gui.planning.bridge import verify
    backend = _backend(arena(tmp_path, NEARBY))
    try:
        result = plan(backend, "KPIECE1", time_limit=60.0, seed=2)
        again = verify(backend, result.rows)
    finally:
        backend.close()
    assert result.solved and not result.disagreement and not result.invalid
    assert again.invalid == ""
    assert again.final_position.tobytes() == result.final_position.tobytes()


# -- the plan tool -----------------------------------------------------------------------------
LYING_PLAN_TOOL = """
import sys
import numpy as np
from gui.planning import backend
real_start, real_propagate = backend.CoreBackend.start_state, backend.CoreBackend.propagate

def start_state(self):
    self.starts = getattr(self, "starts", 0) + 1
    return real_start(self)

def propagate(self, requests):
    outcomes = real_propagate(self, requests)
    if getattr(self, "starts", 0) < 2:
        return outcomes
    return [o._replace(collisions=o.collisions + (("ball", "divider"),)) for o in outcomes]

backend.CoreBackend.start_state, backend.CoreBackend.propagate = start_state, propagate
from gui.tools.plan import main
sys.exit(main())
"""


def _plan_tool(*args, code="import sys; from gui.tools.plan import main; sys.exit(main())"):
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          timeout=300)


def _errors(run) -> list:
    return [line for line in run.stderr.splitlines() if "warning" not in line]


def test_the_plan_tool_refuses_a_goal_inside_a_wall_in_one_line_before_searching(tmp_path):
    out = tmp_path / "plan.path"
    run = _plan_tool(str(arena(tmp_path, IN_THE_WALL)), "--seed", "1", "--time", "30",
                     "--out", str(out))
    errors = _errors(run)
    assert run.returncode == 2, run.stdout + run.stderr
    assert len(errors) == 1 and errors[0].startswith("plan: error: the query's goal")
    assert "ball is 450.0 mm into divider" in errors[0]
    assert "searching" not in run.stdout and not out.exists()


def test_the_plan_tool_says_its_verdict_not_ompl_s_status(tmp_path):
    out = tmp_path / "plan.path"
    run = _plan_tool(str(arena(tmp_path, NEARBY)), "--seed", "2", "--time", "60",
                     "--out", str(out))
    assert run.returncode == 0, run.stderr
    verdict = [line for line in run.stdout.splitlines() if line.startswith("plan: solved:")]
    assert len(verdict) == 1 and "in the goal region, with no forbidden contact" in verdict[0]
    statistics = json.loads(run.stdout[run.stdout.index("{"):run.stdout.rindex("}") + 1])
    assert statistics["verdict"] == verdict[0][len("plan: "):]
    assert out.exists()


def test_the_plan_tool_exits_1_saying_what_the_replay_shows_against_the_search(tmp_path):
    out = tmp_path / "plan.path"
    run = _plan_tool(str(arena(tmp_path, NEARBY)), "--seed", "2", "--time", "60",
                     "--out", str(out), code=LYING_PLAN_TOOL)
    errors = _errors(run)
    assert run.returncode == 1, run.stdout + run.stderr
    assert len(errors) == 1, errors
    assert errors[0].startswith("plan: error: ") and "the replay disagrees with the search " \
        "(KPIECE1, seed 2): OMPL reports an exact solution, but its replay makes an invalid " \
        "step at row 1 (0.030 s): ball touches divider" in errors[0]
    assert errors[0].endswith("; nothing written")
    assert "plan: solved" not in run.stdout and not out.exists()


# -- the benchmark -------------------------------------------------------------------------------
def test_a_benchmark_records_a_goal_inside_a_wall_unsearched_and_says_why(tmp_path):
    out = tmp_path / "out"
    run = subprocess.run(
        [sys.executable, "-c", "import sys; from gui.tools.benchmark import main; "
         "sys.exit(main())", "--problem", str(arena(tmp_path, IN_THE_WALL, "wall.xml")),
         "--planners", "KPIECE1", "--runs", "2", "--time", "30", "--workers", "0",
         "--no-plots", "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    runs = [json.loads(line) for line in (out / "runs.jsonl").read_text().splitlines()[1:]]
    assert [(r["solved"], r["status"], r["propagations"]) for r in runs] == \
        [(False, "Invalid goal", 0)] * 2
    assert all("ball is 450.0 mm into divider" in r["error"] for r in runs)
    log = (out / "wall.log").read_text()
    assert "not searched (Invalid goal): the query's goal" in log


def test_a_benchmark_run_whose_replay_disagrees_is_not_solved_and_its_log_says_why(
        tmp_path, monkeypatch):
    from gui.planning import backend as backends
    from gui.planning.benchmark import prepare
    from gui.planning.benchmark_run import RunResult, search
    from gui.planning.benchmark_spec import command_line_experiments
    from gui.tools.benchmark import _setup_text
    monkeypatch.setattr(backends, "CoreBackend", Unfaithful)
    problem = str(arena(tmp_path, NEARBY))
    answer = search(problem, "KPIECE1", 2, 60.0, {}, lambda: False)
    assert not answer["solved"] and answer["approximate"]
    assert answer["status"] == "Approximate solution"
    assert answer["error"].startswith("the replay disagrees with the search: OMPL reports an "
                                      "exact solution, but its replay makes an invalid step")
    prepared = prepare(command_line_experiments([problem], ["KPIECE1"], 1, 60.0), seed=2)
    (experiment, entries), = prepared.experiments
    result = RunResult(experiment.name, entries[0].name, 0, "KPIECE1", 2, **answer)
    text = _setup_text(prepared, entries, [], {entries[0].name: [result]})
    assert f"KPIECE1 run 0 (seed 2): not solved: {answer['error']}" in text
