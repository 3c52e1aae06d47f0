"""The planning bridge's back end over ROS: a pool of VirtualWorld nodes (``WorldPool``), on
this machine or on several hosts of the ROS graph, each holding the problem's world.

Every propagation is one Propagate call that starts from the planner's state vector
(``start_state``) and answers the state reached (``state``), so any world of the pool can serve
any request, and a batch (``PoolBackend.propagate`` of several requests) is fanned out over
the worlds at once. A control that sets servos (a car, joints) is a Set Servo and the
Propagate after it, made by the same world one after the other: every control sets the same
servo values in full, so what an earlier request left set never matters. The worlds are
deterministic: the answers are bit for bit those of the Core back end
(``gui.planning.backend.CoreBackend``).

A control whose actuation depends on it alone (a car's, a chain's: not a free base's, whose
force reads the base's state) is held by OMPL over many propagations in a row, each from the
state the one before reached. The first of them asks the world for the whole row at once
(Propagate's ``row``: ``max_control_steps`` propagations, every one's state answered), and
the following ones are answered from it: one round trip a control, not a step (a round trip
costs about as much as twenty of the car's steps). The propagations past where OMPL stops
(the control's shorter duration, an invalid state) are computed and not used.

The pool's worlds belong to the planner: each is cleared (New Scene), paused and built from the
problem when the back end starts.
"""
from __future__ import annotations

from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from gui.core.plan import BuildPlan
from gui.errors import PlanningError
from gui.core.world_port import build
from gui.core.control_path import reads_base
from gui.planning.backend import Outcome, VectorBodies, step_actuation, tracked_link
from gui.planning.core_world import force_requests
from gui.planning.problem import PlanningProblem
from odin_common.messages import body_force_message


ROW_MEMORY = 20_000
"""Propagations kept from the rows fetched (about 3 kB each for the car): past this many, the
memory is cleared and the next requests fetch rows afresh."""


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
        self._rows = not reads_base(problem.handle)
        self._row_length = problem.settings.max_control_steps
        # (control, a state's bytes) -> the outcome of that control from that state, from the
        # rows fetched (bounded: cleared when full)
        self._next: Dict[Tuple[tuple, bytes], Outcome] = {}
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
            self._start, self.bodies, self._tracked_link = self._read_start()
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
        return vectors[0], VectorBodies(slots), tracked_link(self.problem, slots)

    @property
    def size(self) -> int:
        return self.pool.size

    def start_state(self) -> np.ndarray:
        return self._start.copy()

    def tracked_state(self, state):
        values = self._tracked_link.values(self._checked(state))
        return values[:3], values[3:]

    def _body(self, state, name: str):
        """A body's state (gui.core.world_port.BodyState) in a state vector of the problem's
        world."""
        return self.bodies.body(self._checked(state), name)

    def _checked(self, state) -> np.ndarray:
        state = np.asarray(state, dtype=np.float64)
        if state.shape != self._start.shape:
            raise PlanningError(f"a state vector of the problem's world has "
                                f"{self._start.size} values; got shape {state.shape}")
        return state

    def propagate(self, requests) -> List[Outcome]:
        out: List[Optional[Outcome]] = []
        asked, calls = [], []
        for k, (state, control) in enumerate(requests):
            state, control = np.asarray(state, dtype=np.float64), tuple(control)
            known = self._next.get((control, state.tobytes())) if self._rows else None
            out.append(known)
            if known is None:
                asked.append((k, state, control))
                calls.append(self._calls(state, control))
        try:
            answers = self.pool.map_calls(calls) if calls else []
        except self._pool_error as error:
            raise PlanningError(str(error)) from None
        for (k, state, control), answer in zip(asked, answers):
            out[k] = self._row(state, control, answer) if self._rows else self._outcome(answer)
        self.propagations += len(out)
        return out

    def _calls(self, state: np.ndarray, control) -> list:
        """The calls one world makes for one request: Set Servo when the control sets servos,
        then the Propagate from ``state`` (of a whole row when the control is held alone)."""
        act = step_actuation(self.problem, control, self._body(state, self.problem.base_body))
        forces = [body_force_message(f["object_id"], int(f["kind"]), f["vector"])
                  for f in force_requests(act.forces)]
        calls = []
        if act.servo is not None:
            calls.append(("set_servo", act.servo.request_fields()))
        calls.append(("propagate", dict(start_state=state.tolist(), duration=self.problem.step,
                                        step=self.step, forces=forces, keep=False,
                                        row=self._row_length if self._rows else 0)))
        return calls

    def _row(self, state: np.ndarray, control: tuple, answer) -> Outcome:
        """The first propagation of a row's answer; the others kept for the requests that
        continue it (module docstring)."""
        if len(self._next) > ROW_MEMORY:
            self._next.clear()
        size = state.size
        vectors = np.asarray(answer.row_states, dtype=np.float64).reshape(-1, size)
        pairs = [(c.first, c.second) for c in answer.collisions]
        first = None
        at = 0
        for vector, count in zip(vectors, answer.row_pairs):
            tracked = self._tracked_link.values(vector)
            outcome = Outcome(vector, tracked[:3], tracked[3:], tuple(pairs[at:at + count]))
            at += count
            self._next[(control, state.tobytes())] = outcome
            if first is None:
                first = outcome
            state = vector
        return first

    def _outcome(self, answer) -> Outcome:
        state = np.asarray(answer.state, dtype=np.float64)
        tracked = self._tracked_link.values(state)
        return Outcome(state, tracked[:3], tracked[3:],
                       tuple((c.first, c.second) for c in answer.collisions))

    def close(self) -> None:
        self.pool.close()


__all__ = ["PoolBackend"]
