"""The VirtualWorld's Core standing in for the world node in GUI Core tests (no ROS): a
client with the WorldClient methods build plans call, and a control port over it.

The plan's steps call only these methods, as they do WorldClient's; the node tests and the
experiments send the same plans through the real client."""
from __future__ import annotations

import logging

import numpy as np

from gui.core.translate import plan_problem
from gui.planning import backend as planning_backend


class CoreWorld(planning_backend.CoreWorld):
    """gui.planning's in-process world (a Core behind WorldClient's build methods), with
    stepping and read-outs for the tests."""

    # -- stepping ------------------------------------------------------------------------------
    def run(self, seconds: float) -> None:
        """Steps the world ``seconds`` of simulated time at the step in force."""
        h = self.step_values.step
        self.core.step(h, max(1, round(seconds / h)))

    def position(self, object_id: str) -> np.ndarray:
        return np.asarray(self.core.body_state(object_id)[0])

    def speed(self, object_id: str) -> float:
        return float(np.linalg.norm(self.core.body_state(object_id)[2]))


CorePort = planning_backend.CorePort


def quiet_plan(problem_file):
    """The build plan of a Kautham problem file, its warnings about what Odin does not use
    silenced (the loader's own tests check them)."""
    from gui.core.kautham.problem import load_problem
    logging.disable(logging.WARNING)
    try:
        return plan_problem(load_problem(problem_file))
    finally:
        logging.disable(logging.NOTSET)
