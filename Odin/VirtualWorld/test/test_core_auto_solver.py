"""The auto solver (the default): each step dWorldStep while the constraint rows to solve are
at most AUTO_SOLVER_MAX_ROWS, QuickStep above. An arm held by its servos must not sag (it does
under QuickStep), a pile must still go to QuickStep, and the choice, depending on the state
only, keeps results bit-identical."""
import math

import pytest

from odin_common.interface import AUTO_SOLVER_MAX_ROWS, JointType, Shape, Solver
from virtual_world.core import Core, ObjectSpec, WorldParameters

from test_core_snapshots import pile, state_bytes

H = 0.001
LINK = 0.135                     # m: 7 links reach 0.945 m, the KUKA LWR's stretched length
LINK_MASS = 2.0                  # kg
ARM_Z = 0.5                      # m
#: a capsule's z turned onto x: (w, x, y, z), a quarter turn about y
Z_ONTO_X = (math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0)


def arm(core):
    """Seven capsules stretched along +x, hinged alternately about y and z, each held at 0 by
    a servo of 300 N m: the worst pose for gravity (the tip's lever is the whole arm). Returns
    the tip link's name."""
    parent, servos = "", {}
    for k in range(7):
        core.build_object(ObjectSpec(f"link{k}", [0.04, LINK - 0.02], mass=LINK_MASS,
                                     position=((k + 0.5) * LINK, 0.0, ARM_Z),
                                     shape=Shape.CAPSULE, orientation=Z_ONTO_X))
        axis = (0.0, 1.0, 0.0) if k % 2 == 0 else (0.0, 0.0, 1.0)
        joint = core.create_joint(JointType.HINGE, f"link{k}", parent,
                                  anchor=(k * LINK, 0.0, ARM_Z), axis1=axis)
        servos[core.create_motor(joint=joint, max_forces=[300.0])] = {"targets": [0.0]}
        parent = f"link{k}"
    core.set_servos(servos)
    return parent


def sag_mm(core, tip, seconds=2.0):
    """The largest drop of the tip link's centre (mm) over ``seconds`` of 1 ms steps."""
    z0, worst = core.body_state(tip)[0][2], 0.0
    for _ in range(round(seconds / H / 50)):
        core.step(H, 50)
        worst = max(worst, z0 - core.body_state(tip)[0][2])
    return 1000.0 * worst


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


def _run(solver, build, steps):
    core = Core(WorldParameters(solver=solver))
    try:
        build(core)
        core.step(H, steps)
        return state_bytes(core), core.last_step_solver
    finally:
        core.close()


def test_auto_is_dworldstep_on_the_arm_and_quickstep_on_a_pile_bit_for_bit():
    arm_auto, chosen = _run(Solver.AUTO, arm, 300)
    assert chosen == Solver.WORLDSTEP
    assert arm_auto == _run(Solver.WORLDSTEP, arm, 300)[0]
    # 60 spheres resting in a box: hundreds of contact rows, far above the bound
    assert 60 * 3 * 3 > AUTO_SOLVER_MAX_ROWS
    settled = _run(Solver.AUTO, pile, 1500)
    assert settled[1] == Solver.QUICKSTEP
    # while they fall (no contact yet) auto takes dWorldStep: the runs differ, both land
    assert settled[0] != _run(Solver.QUICKSTEP, pile, 1500)[0]


def test_a_pile_that_crosses_the_bound_is_bit_identical_run_after_run_and_from_a_snapshot():
    """The spheres fall freely (no rows: dWorldStep) and land (contacts: QuickStep), so the
    choice changes mid-run; the same calls give the same bytes, and a snapshot taken while
    falling replays them."""
    first = _run(Solver.AUTO, pile, 1200)[0]
    assert _run(Solver.AUTO, pile, 1200)[0] == first
    core = Core()
    try:
        pile(core)
        core.step(H, 100)
        assert core.last_step_solver == Solver.WORLDSTEP   # still in the air
        core.save_state("falling")
        core.step(H, 1100)
        assert core.last_step_solver == Solver.QUICKSTEP
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
def test_contacts_with_the_static_ground_count(ground_first):
    """50 spheres resting apart on the ground, one contact each (3 rows): 150 rows, over the
    bound, whichever geometry the contact names first."""
    assert 50 * 3 > AUTO_SOLVER_MAX_ROWS
    core = Core()
    try:
        ground = ObjectSpec("ground", [20, 20, 1], position=(0, 0, -0.5), geometry_only=True)
        if ground_first:
            core.build_object(ground)
        for i in range(50):
            core.build_object(ObjectSpec(f"s{i}", [0.1], position=(i % 10 - 4.5, i // 10 - 2,
                                                                   0.0999)))
        if not ground_first:
            core.build_object(ground)
        core.step(H, 5)
        assert core.last_step_contacts == 50
        assert core.last_step_solver == Solver.QUICKSTEP
    finally:
        core.close()
