"""Set Step's resolution of partial requests (thesis 4.5), without ROS."""
import pytest

from virtual_world.errors import InvalidArgument
from virtual_world.core.step_values import StepValues, resolve

DEFAULT = StepValues()


def test_defaults_are_table_4_1_and_real_time():
    assert (DEFAULT.step, DEFAULT.steps_per_cycle, DEFAULT.rate) == (0.001, 40, 25.0)
    assert DEFAULT.cycle_time == pytest.approx(0.04)
    assert DEFAULT.cycle_time * DEFAULT.rate == pytest.approx(1.0)


@pytest.mark.parametrize("request_, expected", [
    (dict(step=0.002), (0.002, 20, 25.0)),                      # keeps the cycle time
    (dict(steps_per_cycle=10), (0.001, 10, 25.0)),              # keeps the step
    (dict(cycle_time=0.1), (0.001, 100, 25.0)),                 # keeps the step
    (dict(rate=10.0), (0.001, 40, 10.0)),                       # rate alone
    (dict(step=0.0005, steps_per_cycle=10), (0.0005, 10, 25.0)),
    (dict(steps_per_cycle=4, cycle_time=0.02), (0.005, 4, 25.0)),
    (dict(step=0.001, cycle_time=0.001, rate=10.0), (0.001, 1, 10.0)),   # table 10.1
    (dict(step=0.001, steps_per_cycle=40, cycle_time=0.04, rate=25.0), (0.001, 40, 25.0)),
])
def test_partial_requests_resolve(request_, expected):
    values, _ = resolve(DEFAULT, **request_)
    assert (values.step, values.steps_per_cycle, values.rate) == pytest.approx(expected)
    assert values.cycle_time == pytest.approx(values.step * values.steps_per_cycle)


def test_on_conflict_step_and_cycle_time_win_over_the_count():
    values, note = resolve(DEFAULT, step=0.002, steps_per_cycle=7, cycle_time=0.04)
    assert (values.step, values.steps_per_cycle) == (0.002, 20)
    assert "conflicts" in note


def test_a_cycle_time_that_is_no_whole_number_of_steps_is_rounded_and_said():
    values, note = resolve(DEFAULT, step=0.003, cycle_time=0.01)
    assert values.steps_per_cycle == 3 and values.cycle_time == pytest.approx(0.009)
    assert "whole number" in note


@pytest.mark.parametrize("request_", [
    dict(), dict(step=-0.001), dict(step=float("nan")), dict(step=float("inf")),
    dict(rate=-1.0), dict(rate=1e9), dict(step=0.01, cycle_time=0.001),
    dict(cycle_time=float("nan")), dict(step=2.0), dict(steps_per_cycle=10**9),
])
def test_bad_requests_are_refused(request_):
    with pytest.raises(InvalidArgument):
        resolve(DEFAULT, **request_)
