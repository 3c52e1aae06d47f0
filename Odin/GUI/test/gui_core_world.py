"""The VirtualWorld's Core standing in for the world node in GUI Core tests (no ROS):
gui.planning's CoreWorld (the WorldPort over a Core), with stepping and read-outs for the tests.

The plan's steps, control paths and tracked paths ask only the WorldPort's methods; the node
tests and the experiments run the same through the world node (gui.ros.world_port)."""
from __future__ import annotations

import logging

import numpy as np

from gui.core.translate import plan_problem
from gui.planning import core_world


class CoreWorld(core_world.CoreWorld):
    """gui.planning's in-process world (a Core behind WorldClient's build methods), with
    stepping and read-outs for the tests."""

    # -- stepping ------------------------------------------------------------------------------
    def run(self, seconds: float) -> None:
        """Steps the world ``seconds`` of simulated time at the step in force."""
        h = self.step_values().step
        self.core.step(h, max(1, round(seconds / h)))

    def position(self, object_id: str) -> np.ndarray:
        return np.asarray(self.core.body_state(object_id)[0])

    def speed(self, object_id: str) -> float:
        return float(np.linalg.norm(self.core.body_state(object_id)[2]))

    def drift_mm(self, object_ids, seconds: float, chunk: int = 500) -> dict:
        """Steps ``seconds`` at the step in force, reading every ``chunk`` steps: {object:
        its largest distance (mm) from where it was when called}."""
        start = {i: self.position(i) for i in object_ids}
        worst = dict.fromkeys(object_ids, 0.0)
        h = self.step_values().step
        for _ in range(max(1, round(seconds / h / chunk))):
            self.core.step(h, chunk)
            for i in object_ids:
                moved = 1000.0 * float(np.linalg.norm(self.position(i) - start[i]))
                worst[i] = max(worst[i], moved)
        return worst


def quiet_plan(problem_file):
    """The build plan of a Kautham problem file, its warnings about what Odin does not use
    silenced (the loader's own tests check them)."""
    from gui.core.kautham.problem import load_problem
    logging.disable(logging.WARNING)
    try:
        return plan_problem(load_problem(problem_file))
    finally:
        logging.disable(logging.NOTSET)
