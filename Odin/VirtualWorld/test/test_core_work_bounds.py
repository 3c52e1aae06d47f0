"""A call's work is bounded in body-steps (odin_common.limits.MAX_BODY_STEPS_PER_CALL), not in
steps alone: one Propagate of 1,000 s over 200 bodies had held a world for ten minutes."""
import time

import pytest

from odin_common.limits import MAX_BODY_STEPS_PER_CALL
from virtual_world.core import Core, ObjectSpec, WorldParameters
from virtual_world.core.loop import WorldLoop
from virtual_world.core.step_values import StepValues
from virtual_world.errors import InvalidArgument


@pytest.fixture
def crowd():
    """40 free spheres in a row: 40 bodies that step."""
    core = Core(WorldParameters(gravity=(0.0, 0.0, 0.0)))
    for k in range(40):
        core.build_object(ObjectSpec(f"s{k}", [0.1], position=(k * 0.5, 0.0, 0.0)))
    yield core
    core.close()


def test_a_propagation_beyond_the_body_step_bound_is_refused_at_once_naming_both(crowd):
    """500 s at 1 ms over 40 bodies is 2e7 body-steps (within the per-call step count):
    refused before a step, naming the steps, the bodies and the bound; nothing changed."""
    assert crowd.body_count == 40
    started = time.perf_counter()
    with pytest.raises(InvalidArgument,
                       match=r"5e\+05 steps x 40 bodies = 2e\+07 body-steps.*"
                             r"MAX_BODY_STEPS_PER_CALL"):
        crowd.propagate(500.0, 0.001, keep=True)
    assert time.perf_counter() - started < 1.0
    assert crowd.sim_time == 0.0


def test_a_propagation_within_the_bound_runs(crowd):
    steps = MAX_BODY_STEPS_PER_CALL // 40 // 1000     # a thousandth of the bound
    result = crowd.propagate(steps * 0.001, 0.001)
    assert result.steps == steps


def test_a_step_once_beyond_the_body_step_bound_is_refused_before_a_cycle():
    """100 cycles of 1,000 steps over 200 bodies is 2e7 body-steps: refused, and the loop
    advances nothing."""
    advanced = []
    loop = WorldLoop(lambda step, count: advanced.append(count) or 0.0, lambda report: None,
                     StepValues(0.001, 1000), bodies=lambda: 200)
    with pytest.raises(InvalidArgument, match="200 bodies.*MAX_BODY_STEPS_PER_CALL"):
        loop.step_cycles(100)
    assert advanced == []
    loop.step_cycles(2)
    assert advanced == [1000, 1000]


def _pile() -> Core:
    """40 spheres falling onto a ground box and each other: contacts in every step."""
    core = Core()
    core.build_object(ObjectSpec("ground", [20.0, 20.0, 0.2], position=(0, 0, -0.1),
                                 geometry_only=True))
    for k in range(40):
        core.build_object(ObjectSpec(f"p{k}", [0.1], position=(
            (k % 4) * 0.15, (k // 4 % 3) * 0.15, 0.3 + 0.25 * (k // 12))))
    return core


def test_a_propagation_run_in_pieces_is_bit_for_bit_the_one_run_at_once():
    """12,000 steps over 40 bodies run in pieces between looks at ``cancelled`` (from one
    step, growing): the state, the steps and the collisions (with their first times) are
    those of one run."""
    looks = []
    with _pile() as once, _pile() as pieces:
        whole = once.propagate(12.0, 0.001, keep=True)
        split = pieces.propagate(12.0, 0.001, keep=True,
                                 cancelled=lambda: looks.append(1) and False)
        assert len(looks) >= 3
        assert split.steps == whole.steps == 12_000
        assert split.state.tobytes() == whole.state.tobytes()
        assert split.collisions == whole.collisions and whole.collisions
        assert pieces.sim_time == once.sim_time


def test_a_cancelled_propagation_leaves_the_world_as_it_was_even_when_kept():
    """The caller gone after the second piece: Cancelled, and the world is in the state it
    had before the call (a Propagate is all or nothing), its simulated time too."""
    from virtual_world.core.long_calls import Cancelled
    with _pile() as core:
        core.step(0.001, 10)
        before, time_before = core.body_state_vector(), core.sim_time
        looks = []
        with pytest.raises(Cancelled, match="the caller has gone"):
            core.propagate(60.0, 0.001, keep=True,
                           cancelled=lambda: looks.append(1) or len(looks) > 2)
        assert core.body_state_vector().tobytes() == before.tobytes()
        assert core.sim_time == time_before


def test_a_step_once_whose_caller_has_gone_stops_between_cycles():
    advanced = []
    loop = WorldLoop(lambda step, count: advanced.append(count) or 0.0, lambda report: None,
                     StepValues(0.001, 10))
    loop.step_cycles(50, cancelled=lambda: len(advanced) >= 3)
    assert advanced == [10, 10, 10]
