"""The planning bridge's back end over ROS: a pool of VirtualWorld nodes (``WorldPool``), on
this machine or on several hosts of the ROS graph, each holding the problem's world.

Every propagation is one Propagate call that starts from the planner's state vector
(``start_state``) and answers the state reached (``state``), so any world of the pool can serve
any request, and a batch (``PoolBackend.propagate`` of several requests) is fanned out over
the worlds at once. A control that sets servos (a car, joints) is a Set Servo and the
Propagate after it, made by the same world one after the other: every control sets the same
servo values in full, so what an earlier request left set never matters. The worlds are
deterministic: the answers are bit for bit those of the Core back end
(``gui.planning.backend.CoreBackend``). The pool's worlds belong to the planner:
each is cleared (New Scene), paused and built from the problem when the back end starts.
"""
from __future__ import annotations

from typing import List, Sequence

import numpy as np

from gui.core.plan import BuildPlan
from gui.errors import PlanningError
from gui.core.world_port import build
from gui.planning.backend import Outcome, VectorBodies, step_actuation
from gui.planning.core_world import force_requests
from gui.planning.problem import PlanningProblem
from odin_common.messages import body_force_message


class PoolBackend:
    """``problem``'s world built in every world node at ``namespaces`` (e.g.
    "/w0/virtual_world"); propagations fanned out over them."""

    def __init__(self, plan: BuildPlan, problem: PlanningProblem, namespaces: Sequence[str],
                 timeout: float = 30.0):
        from gui.ros.client import WorldClient
        from gui.ros.pool import PoolError, WorldPool
        from gui.ros.world_port import ClientWorldPort
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
                    # no robot declared: the planner's worlds publish nothing anyone reads
                    build(ClientWorldPort(client), plan)
                    self.step = client.step_values().step
                finally:
                    client.close()
            self._start, self.bodies, self._tracked_index = self._read_start()
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
        slots = {}
        for name in (self.problem.base_body, self.problem.tracked_body):
            if name not in ids:
                raise PlanningError(f"the pool's worlds have no body {name!r}")
            com = answers[0].centers_of_mass[ids.index(name)]
            slots[name] = (ids.index(name), np.array([com.x, com.y, com.z]))
        return vectors[0], VectorBodies(slots), ids.index(self.problem.tracked_body)

    @property
    def size(self) -> int:
        return self.pool.size

    def start_state(self) -> np.ndarray:
        return self._start.copy()

    def tracked_state(self, state):
        body = self._body(state, self.problem.tracked_body)
        return self.problem.tracked_origin(body.position, body.quaternion), body.linear.copy()

    def _body(self, state, name: str):
        """A body's state (gui.core.world_port.BodyState) in a state vector of the problem's
        world."""
        state = np.asarray(state, dtype=np.float64)
        if state.shape != self._start.shape:
            raise PlanningError(f"a state vector of the problem's world has "
                                f"{self._start.size} values; got shape {state.shape}")
        return self.bodies.body(state, name)

    def propagate(self, requests) -> List[Outcome]:
        calls = [self._calls(np.asarray(state, dtype=np.float64), control)
                 for state, control in requests]
        try:
            answers = self.pool.map_calls(calls)
        except self._pool_error as error:
            raise PlanningError(str(error)) from None
        self.propagations += len(answers)
        return [self._outcome(answer) for answer in answers]

    def _calls(self, state: np.ndarray, control) -> list:
        """The calls one world makes for one request: Set Servo when the control sets servos,
        then the Propagate from ``state``."""
        act = step_actuation(self.problem, control, self._body(state, self.problem.base_body))
        forces = [body_force_message(f["object_id"], int(f["kind"]), f["vector"])
                  for f in force_requests(act.forces)]
        calls = []
        if act.servo is not None:
            calls.append(("set_servo", act.servo.request_fields()))
        calls.append(("propagate", dict(start_state=state.tolist(), duration=self.problem.step,
                                        step=self.step, forces=forces, keep=False)))
        return calls

    def _outcome(self, answer) -> Outcome:
        body = answer.states[self._tracked_index]
        position = self.problem.tracked_origin(np.array(body.position),
                                               np.array(body.orientation))
        return Outcome(np.asarray(answer.state, dtype=np.float64), position,
                       np.array(body.linear),
                       tuple((c.first, c.second) for c in answer.collisions))

    def close(self) -> None:
        self.pool.close()


__all__ = ["PoolBackend"]
