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
