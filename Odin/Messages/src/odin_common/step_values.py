"""The four step values of the world node (thesis 4.5, Set Step), with their defaults and
ranges; the rule that resolves a partial Set Step is the world's (virtual_world.core.step_values).

* ``step``            -- s, simulated time of one ODE step (the Core's step size);
* ``steps_per_cycle`` -- ODE steps taken in one Portal cycle;
* ``cycle_time``      -- s, simulated time of one Portal cycle, always ``step * steps_per_cycle``;
* ``rate``            -- Hz, Portal cycles (and so publications) per wall-clock second.

The defaults (thesis table 4.1) make one simulated second last one wall-clock second.
"""
from __future__ import annotations

import dataclasses

MAX_STEP = 1.0            # s: beyond this ODE's first-order integration is meaningless
MAX_STEPS_PER_CYCLE = 1_000_000
MAX_RATE = 1000.0         # Hz


@dataclasses.dataclass(frozen=True)
class StepValues:
    """Step values in force; see the module docstring for units."""

    step: float = 0.001
    steps_per_cycle: int = 40
    rate: float = 25.0

    @property
    def cycle_time(self) -> float:
        return self.step * self.steps_per_cycle

    @property
    def period(self) -> float:
        """s, wall-clock time of one Portal cycle."""
        return 1.0 / self.rate


__all__ = ["StepValues", "MAX_STEP", "MAX_STEPS_PER_CYCLE", "MAX_RATE"]
