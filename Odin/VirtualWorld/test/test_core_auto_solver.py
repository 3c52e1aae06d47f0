"""The auto solver (the default): each step dWorldStep while the whole step is small (at most
AUTO_SOLVER_MAX_ROWS rows, each joint counted at its most) or an island is articulated (joints,
motors) and the largest island has at most AUTO_SOLVER_MAX_ISLAND_ROWS rows (ODE's own count),
QuickStep otherwise. An arm held by its servos must not sag (it does under QuickStep), a few
bodies on the ground keep the exact solver (the pinned planning experiments were recorded so),
a pile and many bodies at rest take QuickStep, a big articulated island with contacts takes the
exact solver up to the bound, and the choice, depending on the state only, keeps results
bit-identical."""
import math

import pytest

import virtual_world.ode.world
from odin_common.defaults import (AUTO_SOLVER_ARTICULATION_ROWS, AUTO_SOLVER_MAX_ISLAND_ROWS,
                                  AUTO_SOLVER_MAX_ROWS)
from odin_common.interface import JointType, Shape, Solver
from virtual_world.core import Core, JointSpec, MotorSpec, ObjectSpec, WorldParameters

from test_core_snapshots import pile, state_bytes

H = 0.001
LINK = 0.135                     # m: 7 links reach 0.945 m, the KUKA LWR's stretched length
LINK_MASS = 2.0                  # kg
ARM_Z = 0.5                      # m
#: a capsule's z turned onto x: (w, x, y, z), a quarter turn about y
Z_ONTO_X = (math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0)


def arm(core, links=7):
    """``links`` capsules (seven by default) stretched along +x, hinged alternately about y
    and z, each held at 0 by a servo of 300 N m: the worst pose for gravity (the tip's lever is
    the whole arm). Returns the tip link's name."""
    parent, servos = "", []
    for k in range(links):
        core.build_object(ObjectSpec(f"link{k}", [0.04, LINK - 0.02], mass=LINK_MASS,
                                     position=((k + 0.5) * LINK, 0.0, ARM_Z),
                                     shape=Shape.CAPSULE, orientation=Z_ONTO_X))
        axis = (0.0, 1.0, 0.0) if k % 2 == 0 else (0.0, 0.0, 1.0)
        joint = core.add_joint(JointSpec(JointType.HINGE, f"link{k}", parent,
                                         anchor=(k * LINK, 0.0, ARM_Z), axis1=axis))
        servos.append(core.add_motor(MotorSpec(joint=joint, max_forces=[300.0])))
        parent = f"link{k}"
    core.set_servo(servos, [0.0] * len(servos))
    return parent


def sag_mm(core, tip, seconds=2.0):
    """The largest drop of the tip link's centre (mm) over ``seconds`` of 1 ms steps."""
    z0, worst = core.body_state(tip)[0][2], 0.0
    for _ in range(round(seconds / H / 50)):
        core.step(H, 50)
        worst = max(worst, z0 - core.body_state(tip)[0][2])
    return 1000.0 * worst


GROUND = ObjectSpec("ground", [20, 20, 1], position=(0, 0, -0.5), geometry_only=True)


def resting_spheres(core, n, first_row_y=-2):
    """``n`` spheres of 0.1 m resting apart on GROUND, rows of ten along x from y =
    ``first_row_y`` (m): one contact each, no two touching."""
    for i in range(n):
        core.build_object(ObjectSpec(f"s{i}", [0.1], position=(i % 10 - 4.5,
                                                               i // 10 + first_row_y, 0.0999)))


def last_step(core):
    """What the last step met and chose: (contacts, (island rows, articulated rows), solver)."""
    return core.last_step_contacts, core.last_step_island_rows, core.last_step_solver


def test_auto_is_the_default():
    assert WorldParameters().solver == Solver.AUTO


@pytest.mark.parametrize("solver,holds", [(Solver.AUTO, True), (Solver.QUICKSTEP, False)])
def test_an_arm_held_by_its_servos_does_not_sag_under_the_default_solver(solver, holds):
    core = Core(WorldParameters(solver=solver))
    try:
        tip = arm(core)
        sag = sag_mm(core, tip)
        if holds:
            assert sag < 1.0, sag
            assert core.last_step_solver == Solver.WORLDSTEP
        else:               # QuickStep's 20 iterations let the same arm sag (why auto exists)
            assert sag > 1.0, sag
            assert core.last_step_solver == Solver.QUICKSTEP
    finally:
        core.close()


@pytest.fixture
def island_rule_only(monkeypatch):
    """AUTO_SOLVER_MAX_ROWS at 0: the small-system clause narrowed to steps without a joint
    (free fall) and AUTO_SOLVER_ARTICULATION_ROWS at 0: any articulation large, so a test
    sees the island rule alone on scenes the small-system clause would send to dWorldStep
    anyway."""
    monkeypatch.setattr(virtual_world.ode.world, "AUTO_SOLVER_MAX_ROWS", 0)
    monkeypatch.setattr(virtual_world.ode.world, "AUTO_SOLVER_ARTICULATION_ROWS", 0)


def _run(solver, build, steps):
    core = Core(WorldParameters(solver=solver))
    try:
        build(core)
        core.step(H, steps)
        return state_bytes(core), core.last_step_solver
    finally:
        core.close()


def test_an_arm_held_by_servos_counts_ode_rows_a_hinge_5_and_its_powered_motor_1(
        island_rule_only):
    core = Core()
    try:
        arm(core)
        core.step(H, 1)
        assert core.last_step_island_rows == (7 * 6, 7 * 6)    # one island, no contact
        assert core.last_step_solver == Solver.WORLDSTEP
    finally:
        core.close()


def test_an_arm_the_small_system_clause_counts_too_large_is_exact_whatever_odes_count():
    """14 servo-held hinges: 126 rows as the small-system clause counts them (9 a hinge and its
    motor), past its bound, yet 84 by ODE's count, within it: the island clause counts the
    articulation as the small-system clause does, so no arm falls between the two (counted
    ODE's way, such an arm took QuickStep: this one folded, its tip 0.6 m down in 2 s)."""
    links = 14
    assert links * 6 <= AUTO_SOLVER_MAX_ROWS < links * 9
    core = Core()
    try:
        tip = arm(core, links)
        sag = sag_mm(core, tip)
        assert last_step(core) == (0, (links * 6, links * 6), Solver.WORLDSTEP)
        assert sag < 1.0, sag
    finally:
        core.close()


def test_auto_is_dworldstep_on_the_arm_and_quickstep_on_a_pile_bit_for_bit():
    arm_auto, chosen = _run(Solver.AUTO, arm, 300)
    assert chosen == Solver.WORLDSTEP
    assert arm_auto == _run(Solver.WORLDSTEP, arm, 300)[0]
    # 60 spheres piled in a box: hundreds of contact rows, contacts only
    assert 60 * 3 * 3 > AUTO_SOLVER_MAX_ROWS
    settled = _run(Solver.AUTO, pile, 1500)
    assert settled[1] == Solver.QUICKSTEP
    # while they fall (no rows: a small system) auto takes dWorldStep: the runs differ
    assert settled[0] != _run(Solver.QUICKSTEP, pile, 1500)[0]


@pytest.mark.parametrize("bodies", [1, AUTO_SOLVER_MAX_ROWS // 3])
def test_a_few_bodies_resting_on_the_ground_keep_the_exact_solver(bodies):
    """Contacts only, but few: the small-system clause holds (3 rows a contact), as it did when
    the planning experiments (a sphere, a car on the ground) were pinned; one more body and the
    step is a pile's business (QuickStep)."""
    for n, solver in ((bodies, Solver.WORLDSTEP), (AUTO_SOLVER_MAX_ROWS // 3 + 1,
                                                   Solver.QUICKSTEP)):
        core = Core()
        try:
            core.build_object(GROUND)
            resting_spheres(core, n)
            core.step(H, 5)
            assert core.last_step_contacts == n
            assert core.last_step_solver == solver, n
        finally:
            core.close()


def test_a_small_arm_among_many_contacts_keeps_quickstep_as_before_the_island_rule():
    """A 4-link arm (36 rows of joints as the small-system clause counts them, under the
    articulation bound) beside 50 spheres resting on the ground (150 contact rows): the step
    is no small system and the arm no articulation of the island rule, so auto keeps
    QuickStep, as it did when the planning experiments (a car among contacts: 36 rows) were
    pinned."""
    assert 4 * 9 < AUTO_SOLVER_ARTICULATION_ROWS
    core = Core()
    try:
        arm(core, links=4)
        core.build_object(GROUND)
        resting_spheres(core, 50, first_row_y=-4)
        core.step(H, 2)
        assert last_step(core) == (50, (24, 24), Solver.QUICKSTEP)
    finally:
        core.close()


@pytest.mark.parametrize("links", [5, 7])
def test_an_arm_of_five_servo_held_joints_or_more_among_many_contacts_is_exact_and_holds(links):
    """An arm of five or seven servo-held joints (45 or 63 rows as the small-system clause
    counts them: at the articulation bound, AUTO_SOLVER_ARTICULATION_ROWS, or past it) beside
    the same 50 resting spheres: the step is no small system, but the arm is an articulation,
    solved exactly, and it holds its pose where QuickStep's iterations let it sag."""
    assert links * 9 >= AUTO_SOLVER_ARTICULATION_ROWS
    sags = {}
    for solver in (Solver.AUTO, Solver.QUICKSTEP):
        core = Core(WorldParameters(solver=solver))
        try:
            tip = arm(core, links=links)
            core.build_object(GROUND)
            resting_spheres(core, 50, first_row_y=-4)
            core.step(H, 2)
            if solver == Solver.AUTO:
                assert last_step(core) == (50, (6 * links, 6 * links), Solver.WORLDSTEP)
            sags[solver] = sag_mm(core, tip)
        finally:
            core.close()
    assert sags[Solver.AUTO] < 1.0 < sags[Solver.QUICKSTEP], sags


def sphere_chain(core, n, radius=0.05, gap=0.12):
    """``n`` spheres resting in a row on the ground, the first held to the world and each to
    the next by a ball joint (3 rows each), one contact each (3 rows): one island of 6 n rows,
    3 n of them articulated."""
    core.build_object(ObjectSpec("ground", [40, 40, 1], position=(0, 0, -0.5),
                                 geometry_only=True))
    parent = ""
    for i in range(n):
        core.build_object(ObjectSpec(f"c{i}", [radius], position=(i * gap, 0.0,
                                                                    radius - 0.0001)))
        core.add_joint(JointSpec(JointType.BALL, f"c{i}", parent,
                                 anchor=((i - 0.5) * gap, 0.0, radius - 0.0001)))
        parent = f"c{i}"


@pytest.mark.parametrize("links", [AUTO_SOLVER_MAX_ISLAND_ROWS // 6,
                                   AUTO_SOLVER_MAX_ISLAND_ROWS // 6 + 1])
def test_an_articulated_island_with_contacts_takes_the_exact_solver_up_to_the_bound(links):
    assert 3 * links > AUTO_SOLVER_MAX_ROWS      # a large articulation: past the small system
    core = Core()
    try:
        sphere_chain(core, links)
        core.step(H, 2)
        assert core.last_step_contacts == links
        assert core.last_step_island_rows == (6 * links, 3 * links)
        exact = 6 * links <= AUTO_SOLVER_MAX_ISLAND_ROWS
        assert core.last_step_solver == (Solver.WORLDSTEP if exact else Solver.QUICKSTEP)
    finally:
        core.close()


def test_a_choice_that_changes_mid_run_is_bit_identical_run_after_run_and_from_a_snapshot(
        monkeypatch):
    """A pile with one sphere held to the world (articulated): while the spheres fall apart the
    islands are small (dWorldStep); piled up, the largest island passes a bound of 60 rows
    (QuickStep). The same calls give the same bytes, and a snapshot taken while falling replays
    them."""
    monkeypatch.setattr(virtual_world.ode.world, "AUTO_SOLVER_MAX_ROWS", 0)
    monkeypatch.setattr(virtual_world.ode.world, "AUTO_SOLVER_ARTICULATION_ROWS", 0)
    monkeypatch.setattr(virtual_world.ode.world, "AUTO_SOLVER_MAX_ISLAND_ROWS", 60)

    def held_pile(core):
        pile(core)
        core.add_joint(JointSpec(JointType.BALL, "s0", "", anchor=(-0.21, -0.21, 0.12)))

    first = _run(Solver.AUTO, held_pile, 1200)[0]
    assert _run(Solver.AUTO, held_pile, 1200)[0] == first
    core = Core()
    try:
        held_pile(core)
        core.step(H, 100)
        assert core.last_step_solver == Solver.WORLDSTEP   # still in the air
        core.save_state("falling")
        core.step(H, 1100)
        assert core.last_step_solver == Solver.QUICKSTEP
        assert core.last_step_island_rows[0] > 60
        assert state_bytes(core) == first
        core.restore_state("falling")
        core.step(H, 1100)
        assert state_bytes(core) == first
    finally:
        core.close()


def test_explicit_solvers_keep_their_meaning():
    for solver in (Solver.QUICKSTEP, Solver.WORLDSTEP):
        core = Core(WorldParameters(solver=solver))
        try:
            pile(core, n=9)
            arm(core)
            core.step(H, 200)
            assert core.last_step_solver == solver
        finally:
            core.close()


@pytest.mark.parametrize("ground_first", [True, False])
def test_bodies_at_rest_on_the_static_ground_take_quickstep(ground_first):
    """50 spheres resting apart on the ground (the rest scenes): 150 rows, past the
    small-system clause, and 50 islands of one contact whichever geometry the contact names
    first, nothing articulated: QuickStep, without searching the islands (the measure reads
    0, 0)."""
    assert 50 * 3 > AUTO_SOLVER_MAX_ROWS
    core = Core()
    try:
        if ground_first:
            core.build_object(GROUND)
        resting_spheres(core, 50)
        if not ground_first:
            core.build_object(GROUND)
        core.step(H, 5)
        assert last_step(core) == (50, (0, 0), Solver.QUICKSTEP)
    finally:
        core.close()
