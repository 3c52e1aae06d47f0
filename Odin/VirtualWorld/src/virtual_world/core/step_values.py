"""How a partial Set Step request resolves against the step values in force (thesis 4.5);
the values, their units and ranges are odin_common.step_values'.

``cycle_time`` is not free: it follows from ``step`` and ``steps_per_cycle``, and a request may
give it instead of one of them. On conflict ``step`` and ``cycle_time`` win over
``steps_per_cycle``, which is rounded to the nearest whole number of steps; the cycle time in
force is then recomputed.
"""
from __future__ import annotations

import math

from odin_common.limits import MIN_STEP, shown
from odin_common.step_values import MAX_RATE, MAX_STEP, MAX_STEPS_PER_CYCLE, StepValues
from virtual_world.errors import InvalidArgument

_RELATIVE_TOLERANCE = 1e-9


def _positive(name: str, value: float, upper: float, lower: float = 0.0) -> float:
    """``value`` if finite and in (0, upper] (and >= lower); the refusal quotes it short."""
    if not math.isfinite(value) or value <= 0.0 or value > upper or value < lower:
        low = f"[{lower:g}" if lower > 0 else "(0"
        raise InvalidArgument(f"{name} must be in {low}, {upper:g}], got {shown(value)}")
    return float(value)


def resolve(current: StepValues, step: float = 0.0, steps_per_cycle: int = 0,
            cycle_time: float = 0.0, rate: float = 0.0) -> tuple[StepValues, str]:
    """New step values from a request in which 0 means "not given".

    Returns the values in force and a note saying what was derived or adjusted (empty when the
    request was taken as it is). Raises ``InvalidArgument`` and changes nothing on a bad value.
    """
    given_step = step != 0.0
    given_count = steps_per_cycle != 0
    given_cycle = cycle_time != 0.0
    if not (given_step or given_count or given_cycle or rate != 0.0):
        raise InvalidArgument("no step value given (step, steps_per_cycle, cycle_time, rate)")
    new_step = _positive("step", step, MAX_STEP, MIN_STEP) if given_step else current.step
    if given_count and not 1 <= steps_per_cycle <= MAX_STEPS_PER_CYCLE:
        raise InvalidArgument(f"steps_per_cycle must be in [1, {MAX_STEPS_PER_CYCLE}], "
                              f"got {shown(steps_per_cycle)}")
    new_rate = _positive("rate", rate, MAX_RATE) if rate != 0.0 else current.rate
    notes = []
    if given_cycle:
        cycle = _positive("cycle_time", cycle_time, MAX_STEP * MAX_STEPS_PER_CYCLE)
        if given_count and not given_step:
            new_step = _positive("step (cycle_time / steps_per_cycle)",
                                 cycle / steps_per_cycle, MAX_STEP, MIN_STEP)
            count = steps_per_cycle
        else:
            count = _steps_in(cycle, new_step)
            if given_count and count != steps_per_cycle:
                notes.append(f"steps_per_cycle {steps_per_cycle} conflicts with cycle_time "
                             f"{cycle:g} s / step {new_step:g} s: using {count}")
            if not math.isclose(count * new_step, cycle, rel_tol=1e-6):
                notes.append(f"cycle_time {cycle:g} s is not a whole number of steps: "
                             f"using {count} steps = {count * new_step:g} s")
    elif given_count:
        count = steps_per_cycle
    else:
        # Only the step (and/or the rate) changed: keep the simulated time per cycle.
        count = _steps_in(current.cycle_time, new_step) if given_step else current.steps_per_cycle
        if given_step and not math.isclose(count * new_step, current.cycle_time, rel_tol=1e-6):
            notes.append(f"cycle_time {current.cycle_time:g} s kept as near as whole steps "
                         f"allow: {count * new_step:g} s")
    return StepValues(new_step, count, new_rate), "; ".join(notes)


def _steps_in(cycle_time: float, step: float) -> int:
    count = round(cycle_time / step * (1.0 + _RELATIVE_TOLERANCE))
    if count < 1:
        raise InvalidArgument(f"cycle_time {cycle_time:g} s is shorter than one step of {step:g} s")
    if count > MAX_STEPS_PER_CYCLE:
        raise InvalidArgument(f"cycle_time {cycle_time:g} s needs {float(count):.3g} steps of "
                              f"{step:g} s, "
                              f"more than {MAX_STEPS_PER_CYCLE}")
    return count
