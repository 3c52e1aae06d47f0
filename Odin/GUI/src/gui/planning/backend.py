"""Back ends of the planning bridge: where propagations run (ROS-free here).

A ``Backend`` propagates a batch of requests, each (state, control): put the world in the
state (``Core.body_state_vector``'s layout), apply the control for one propagation step as a
control path row (``gui.core.control_path.actuation``: for a free body, the force that would
carry the base to the control's position in the step; for a car or joints, the servo
settings, sent before the step as ``run_path`` sends them), step, and answer the state
reached, the tracked link's position and velocity, and the pairs that collided on the way. A
planner's propagation of a control for n steps is n such calls in a row, exactly as
``run_path`` runs the n rows of the control path it becomes (one kept Propagate per row), so
that the written plan replays bit for bit in a fresh world.

``CoreBackend``: the VirtualWorld's Core in this process (``gui.planning.core_world``), built
from the problem's plan (fastest: no messages). It also makes a search's steps whole in C
(``propagate_into``): the problem's rule of forbidden contacts and bounds held by the Core
(``Core.plan_rule``), each step's state, verdict and tracked link written straight into the
planner's memory (``Core.propagate_checked``). ``gui.planning.pool.PoolBackend``: world nodes
over ROS.

Every back end reads the tracked link out of state vectors by the Core's C arithmetic
(``tracked_link``), so that a search in C, a replay and every back end agree bit for bit.
"""
from __future__ import annotations

from typing import Dict, List, NamedTuple, Optional, Protocol, Sequence, Tuple

import numpy as np

from gui.core.control_path import Actuation, ControlRow, ServoCommand, actuation, reads_base
from gui.core.plan import BuildPlan
from gui.core.world_port import BodyState
from gui.errors import PlanningError
from gui.planning.core_world import CoreWorld
from gui.planning.problem import (FORBIDDEN_ROLE_PAIRS, PlanningProblem, goal_refusal,
                                  start_refusal)
from odin_common.interface import BODY_STATE_SIZE, BODY_STATE_SLICES
from odin_common.rotations import quaternion_to_matrix
from virtual_world.core.checked_propagation import TrackedLink


class Outcome(NamedTuple):
    """After one propagation step: ``state`` the world's body state vector; ``position`` (3,) m,
    the tracked link's origin, and ``velocity`` (3,) m/s, its body's (world frame);
    ``collisions``: the pairs (names) that collided during the step."""
    state: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    collisions: Tuple[Tuple[str, str], ...]


class Backend(Protocol):
    """Where propagations run; every back end answers the same outcomes for the same
    requests (the worlds are deterministic)."""
    problem: PlanningProblem

    def start_state(self) -> np.ndarray:
        """The body state vector of the world as the problem built it."""

    def tracked_state(self, state: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """The tracked link's origin (3,) m and its body's velocity (3,) m/s (world frame) in
        a body state vector."""

    def propagate(self, requests: Sequence[Tuple[np.ndarray, Sequence[float]]]
                  ) -> List[Outcome]:
        """One propagation step per (state vector, control in [0, 1]^k); outcomes in order."""

    def close(self) -> None: ...

    # optional: ``check_query()``, PlanningError when the query cannot be solved whatever the
    # search does (gui.planning.problem.check_query); ``bridge.plan`` asks it before searching


def tracked_link(problem: PlanningProblem, slots: Dict[str, Tuple[int, np.ndarray]]
                 ) -> TrackedLink:
    """``problem``'s tracked link read out of body state vectors whose bodies are ``slots``
    ({object id: (index among the vector's bodies, centre of mass (3,) m in the object
    frame)}), by odin_plan.c's arithmetic."""
    index, com = slots[problem.tracked_body]
    return TrackedLink(index, com, problem.tracked_link_origin)


def step_actuation(problem: PlanningProblem, control: Sequence[float], base) -> Actuation:
    """What applying ``control`` for one propagation step asks of the world (servo settings,
    forces), the robot's base being in ``base`` (position m, quaternion (w, x, y, z), linear
    velocity m/s; world frame) when the step starts."""
    return actuation(problem.handle, ControlRow(tuple(control), problem.step), base)


class VectorBodies:
    """Bodies read out of body state vectors (``Core.body_state_vector``'s layout) without a
    world: ``slots`` {object id: (its index among the vector's bodies, its centre of mass (3,)
    m in the object frame)}. Gives what the Core's body_state gives for the world in that
    state, bit for bit (the same arithmetic on the same numbers)."""

    def __init__(self, slots: Dict[str, Tuple[int, np.ndarray]]):
        self._slots = {}
        for name, (index, com) in slots.items():
            start = 1 + index * BODY_STATE_SIZE
            com = np.asarray(com, dtype=np.float64)
            self._slots[name] = (*(slice(start + f.start, start + f.stop)
                                   for f in (_POSITION, _QUATERNION, _LINEAR, _ANGULAR)),
                                 com, not com.any())

    def body(self, state: np.ndarray, name: str) -> BodyState:
        """The body ``name``'s state (gui.core.world_port.BodyState: frame origin, quaternion,
        velocities) in ``state``: read-only (views of it)."""
        position, quaternion, linear, angular, com, centred = self._slots[name]
        position, quaternion = state[position], state[quaternion]
        if centred:
            x, y, z = position.tolist()
            if x and y and z:
                # origin = position - R @ 0 = position: subtracting a zero changes no value
                # but a zero's sign, hence the non-zero position (body_state's very bits)
                return BodyState(position, quaternion, state[linear], state[angular])
        return BodyState(position - quaternion_to_matrix(quaternion) @ com, quaternion,
                         state[linear], state[angular])


_POSITION, _QUATERNION, _LINEAR, _ANGULAR = (
    BODY_STATE_SLICES[name] for name in ("position", "quaternion", "linear", "angular"))


class CoreBackend:
    """The problem's world built in a Core of this process; propagations one after another,
    each one Core.propagate_state (one C call)."""

    def __init__(self, plan: BuildPlan, problem: PlanningProblem):
        self.problem = problem
        self.world = CoreWorld()
        try:
            self.world.execute(plan)
            core = self.world.core
            self._start = core.body_state_vector()
            bodies = core.state()[0]
            slots = {b.id: (index, b.center_of_mass) for index, b in enumerate(bodies)}
            self._rule = core.plan_rule(
                problem.contact_roles(core.object_ids()), FORBIDDEN_ROLE_PAIRS,
                problem.tracked_body, problem.tracked_link_origin, problem.base_bounds,
                problem.settings.max_speed)
            self._world_step = self.world.step_values().step
        except Exception:
            self.world.close()
            raise
        self.bodies = VectorBodies(slots)
        self._tracked_link = tracked_link(problem, slots)
        self.propagations = 0
        self._servo_sent: Optional[ServoCommand] = None
        # a robot whose actuation depends on its control alone (a car, a chain) is given the
        # same one for the same control: a control is held over many steps
        self._reads_base = reads_base(problem.handle)
        self._last: Tuple[Optional[tuple], Optional[Actuation]] = (None, None)

    def start_state(self) -> np.ndarray:
        return self._start.copy()

    def tracked_state(self, state):
        state = self.world.core.checked_state_vector(state)
        return self._tracked(state)

    def _tracked(self, state: np.ndarray):
        values = self._tracked_link.values(state)
        return values[:3], values[3:]

    def propagate(self, requests):
        return [self._one(state, control) for state, control in requests]

    def _one(self, state, control) -> Outcome:
        state = np.asarray(state, dtype=np.float64)
        act = self._actuate(state, control)
        # propagate_state checks the state's values before it changes anything
        result = self.world.core.propagate_state(state, self.problem.step, self._world_step,
                                                 act.forces)
        self.propagations += 1
        position, linear = self._tracked(result.state)
        return Outcome(result.state, position, linear, result.pairs)

    def propagate_into(self, state: np.ndarray, control, states: np.ndarray,
                       tracked: np.ndarray) -> None:
        """One propagation step of ``control`` from ``state`` (float64 body state vector),
        checked in C by the problem's rule: the state reached and then its verdict (1.0
        invalid: a forbidden contact on the way, or the tracked link out of its bounds; 0.0
        valid) into ``states`` ((1, state size + 1) float64), the tracked link's origin (m)
        and velocity (m/s) into ``tracked`` ((1, 6)). The state is ``propagate``'s, bit for
        bit; the arrays may be a planner's own memory (gui.planning.ompl_memory)."""
        act = self._actuate(state, control)
        self.world.core.propagate_checked(self._rule, state, self.problem.step,
                                          self._world_step, act.forces, 1, states, tracked)
        self.propagations += 1

    def _actuate(self, state: np.ndarray, control) -> Actuation:
        """``control``'s actuation from ``state``, its servo settings sent to the world when
        they are not the ones it holds."""
        if state.shape != self._start.shape:
            self.world.core.checked_state_vector(state)     # raises: the Core's refusal
        act = self._actuation(state, control)
        if act.servo is not None and act.servo != self._servo_sent:
            self.world.core.checked_state_vector(state)     # a bad state changes no servo
            # the same settings again change nothing: a control held over several steps
            # is sent once (this world's servos are set by this back end alone)
            self.world.set_servo(act.servo)
            self._servo_sent = act.servo
        return act

    def _actuation(self, state: np.ndarray, control) -> Actuation:
        """``step_actuation`` for ``control`` from ``state``, the last one again for the same
        control when the base's state does not enter it."""
        if self._reads_base:
            return step_actuation(self.problem, control,
                                  self.bodies.body(state, self.problem.base_body))
        key = tuple(control)
        if key != self._last[0]:
            self._last = (key, step_actuation(self.problem, key, None))
        return self._last[1]

    def refusal(self) -> Optional[Tuple[str, str]]:
        """(OMPL's status, one line) when the problem's query cannot be solved whatever the
        search does: "Invalid start" (gui.planning.problem.start_refusal) or "Invalid goal"
        (goal_refusal), asked of this world put back in its start state; None when it can."""
        self.world.core.set_body_state_vector(self._start)
        for status, refused in (("Invalid start", start_refusal),
                                ("Invalid goal", goal_refusal)):
            why = refused(self.problem, self.world)
            if why is not None:
                return status, why
        return None

    def check_query(self) -> None:
        """PlanningError with ``refusal``'s line when the query cannot be solved."""
        refusal = self.refusal()
        if refusal is not None:
            raise PlanningError(refusal[1])

    def close(self) -> None:
        self.world.close()


def check_query_in_core(plan: BuildPlan, problem: PlanningProblem) -> None:
    """``CoreBackend.check_query`` in a world of its own, built and closed here (a few ms):
    the check before any search, whatever back end the search then uses."""
    backend = CoreBackend(plan, problem)
    try:
        backend.check_query()
    finally:
        backend.close()


__all__ = ["Outcome", "Backend", "CoreBackend", "VectorBodies", "check_query_in_core",
           "step_actuation"]
