"""The planning bridge's back end over ROS: a pool of VirtualWorld nodes (``WorldPool``), on
this machine or on several hosts of the ROS graph, each holding the problem's world.

Every propagation is one Propagate call that starts from the planner's state vector
(``start_state``) and answers the state reached (``state``), so any world of the pool can serve
any request, and a batch (``PoolBackend.propagate`` of several requests) is fanned out over
the worlds at once. The worlds are deterministic: the answers are bit for bit those of the
Core back end (``gui.planning.backend.CoreBackend``). The pool's worlds belong to the planner:
each is cleared (New Scene), paused and built from the problem when the back end starts.
"""
from __future__ import annotations

from typing import List, Sequence

import numpy as np

from gui.core.build import BuildPlan
from gui.errors import PlanningError
from gui.planning.backend import Outcome, row_forces, send_plan
from gui.planning.problem import PlanningProblem
from odin_common.interface import body_record
from odin_common.messages import body_force_message
from odin_common.rotations import quaternion_to_matrix


class PoolBackend:
    """``problem``'s world built in every world node at ``namespaces`` (e.g.
    "/w0/virtual_world"); propagations fanned out over them."""

    def __init__(self, plan: BuildPlan, problem: PlanningProblem, namespaces: Sequence[str],
                 timeout: float = 30.0):
        from gui.ros.client import WorldClient
        from virtual_world.pool import PoolError, WorldPool
        self.problem = problem
        self.propagations = 0
        self._pool_error = PoolError
        try:
            self.pool = WorldPool(namespaces, timeout=timeout, node_name="planner")
        except PoolError as error:
            raise PlanningError(str(error)) from None
        try:
            for namespace in namespaces:
                client = WorldClient(namespace, timeout=timeout)
                try:
                    client.new_scene()
                    client.pause()
                    send_plan(client, plan)
                    self.step = client.step_values().step
                finally:
                    client.close()
            self._start, self._base_index, self._base_com = self._read_start()
        except PoolError as error:
            self.pool.close()
            raise PlanningError(str(error)) from None
        except Exception:
            self.pool.close()
            raise

    def _read_start(self):
        answers = self.pool.broadcast("get_state")
        vectors = [np.asarray(a.state_vector, dtype=np.float64) for a in answers]
        if any(v.tobytes() != vectors[0].tobytes() for v in vectors[1:]):
            raise PlanningError("the pool's worlds built the problem differently (their body "
                                "states differ): are they all the same Odin?")
        ids = [body.id for body in answers[0].bodies]
        if self.problem.base_body not in ids:
            raise PlanningError(f"the pool's worlds have no body {self.problem.base_body!r}")
        index = ids.index(self.problem.base_body)
        com = answers[0].centers_of_mass[index]
        return vectors[0], index, np.array([com.x, com.y, com.z])

    @property
    def size(self) -> int:
        return self.pool.size

    def start_state(self) -> np.ndarray:
        return self._start.copy()

    def base_state(self, state):
        position, _, linear = self._base(state)
        return position, linear

    def _base(self, state):
        """The base's (origin m, quaternion (w, x, y, z), linear velocity m/s), world frame,
        in a state vector: its record holds the centre of mass (the Core's body_state)."""
        record = body_record(state, self._base_index)
        quaternion = np.array(record["quaternion"])
        origin = np.array(record["position"]) - quaternion_to_matrix(quaternion) @ self._base_com
        return origin, quaternion, np.array(record["linear"])

    def propagate(self, requests) -> List[Outcome]:
        fields = [self._request(np.asarray(state, dtype=np.float64), control)
                  for state, control in requests]
        try:
            answers = self.pool.propagate(fields)
        except self._pool_error as error:
            raise PlanningError(str(error)) from None
        self.propagations += len(answers)
        return [self._outcome(answer) for answer in answers]

    def _request(self, state: np.ndarray, control) -> dict:
        base = self._base(state)
        forces = [body_force_message(f["object_id"], int(f["kind"]), f["vector"])
                  for f in row_forces(self.problem, control, base)]
        return dict(start_state=state.tolist(), duration=self.problem.step, step=self.step,
                    forces=forces, keep=False)

    def _outcome(self, answer) -> Outcome:
        base = answer.states[self._base_index]
        return Outcome(np.asarray(answer.state, dtype=np.float64), np.array(base.position),
                       np.array(base.linear),
                       tuple((c.first, c.second) for c in answer.collisions))

    def close(self) -> None:
        self.pool.close()


__all__ = ["PoolBackend"]
