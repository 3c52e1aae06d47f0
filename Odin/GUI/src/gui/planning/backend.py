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

``CoreBackend``: the VirtualWorld's Core in this process, built from the problem's plan
(fastest: no messages). ``gui.planning.pool.PoolBackend``: world nodes over ROS.
"""
from __future__ import annotations

from typing import Dict, List, NamedTuple, Optional, Protocol, Sequence, Tuple

import numpy as np

from gui.core.control_path import Actuation, BodyState, ControlRow, ServoCommand, actuation
from gui.core.overlaps import settle_overlaps
from gui.core.plan import BuildPlan, BuiltIds
from gui.planning.problem import PlanningProblem
from odin_common.interface import BODY_STATE_SIZE, BODY_STATE_SLICES, ForceKind
from odin_common.rotations import quaternion_to_matrix
from odin_common.step_values import StepValues


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


class CoreWorld:
    """A VirtualWorld Core behind the WorldClient methods a build plan calls (``execute``
    sends the whole plan), and ``step_values``, the Set Step values in force."""

    def __init__(self, parameters=None, resources=None,
                 step_values: Optional[StepValues] = None):
        """``parameters`` (WorldParameters), ``resources`` (ResourceLimits) and
        ``step_values``: the world's to start from (None: the defaults)."""
        from virtual_world.core import Core
        from odin_common.limits import ResourceLimits
        self.core = Core(parameters, ResourceLimits() if resources is None else resources)
        self.step_values = StepValues() if step_values is None else step_values

    def close(self) -> None:
        self.core.close()

    def pause(self) -> bool:
        """A Core steps only when asked: it is always paused."""
        return False

    def set_world(self, **changes):
        return self.core.set_world_parameters(**changes)

    def set_step(self, step=None, steps_per_cycle=None, cycle_time=None, rate=None):
        self.step_values = StepValues(step, steps_per_cycle, rate)
        return self.step_values

    def build_entity(self, spec):
        return self.core.build_entity(spec)

    def build_object(self, spec) -> str:
        return self.core.build_object(spec).id

    def build_composite(self, spec) -> str:
        return self.core.build_composite(spec).id

    def add_joint(self, spec) -> str:
        return self.core.add_joint(spec)

    def add_motor(self, spec) -> str:
        return self.core.add_motor(spec)

    def set_joint_parameters(self, joint_id, parameters) -> None:
        self.core.set_joint_parameters(joint_id, parameters)

    def set_servo(self, command: ServoCommand) -> None:
        """Set Servo's lists split per motor, as the world node splits them."""
        servos = {m: {} for m in command.motors}
        for name in ("targets", "rates", "gains", "max_speeds", "max_forces"):
            values = getattr(command, name)
            if name == "targets" or len(values):
                for motor, split in self.core.split_per_axis(list(command.motors),
                                                             list(values), name).items():
                    servos[motor][name] = split
        self.core.set_servos(servos)

    def exempt_overlaps(self, min_depth: float) -> list:
        return [(c.first, c.second, c.depth) for c in self.core.exempt_overlaps(min_depth)]

    def check_collision(self, poses) -> list:
        return [(c.first, c.second, c.depth) for c in self.core.check_collision(poses)]

    def execute(self, plan: BuildPlan) -> dict:
        return send_plan(self, plan)


def send_plan(world, plan: BuildPlan) -> dict:
    """Sends every step of ``plan`` to ``world`` (a CoreWorld or a gui.ros WorldClient),
    records the world's IDs in it and settles the parts it built inside each other as the
    world node's loads do (gui.core.overlaps.settle_overlaps, answered as "overlaps" and
    "overlaps_exempt", warned about by no one); no robot is declared (the planner's worlds
    publish nothing anyone reads)."""
    ids = BuiltIds()
    for step in plan.steps:
        step.send(world, ids)
    plan.record_world_ids(ids)
    overlaps, exempt = settle_overlaps(world, plan)
    return {**ids.as_dict(), "overlaps": overlaps, "overlaps_exempt": exempt}


def step_actuation(problem: PlanningProblem, control: Sequence[float], base) -> Actuation:
    """What applying ``control`` for one propagation step asks of the world (servo settings,
    forces), the robot's base being in ``base`` (position m, quaternion (w, x, y, z), linear
    velocity m/s; world frame) when the step starts."""
    return actuation(problem.handle, ControlRow(tuple(control), problem.step), base)


class CorePort:
    """gui.core.control_path.ControlPort over a CoreWorld: each row one kept propagation, as
    ``run_path``'s ClientPort runs it on a world node."""

    def __init__(self, world: CoreWorld):
        self.world = world

    def body_state(self, body_id: str):
        position, quaternion, linear, _ = self.world.core.body_state(body_id)
        return np.asarray(position), np.asarray(quaternion), np.asarray(linear)

    def set_servo(self, command: ServoCommand) -> None:
        self.world.set_servo(command)

    def set_body_velocity(self, body_id: str, linear, angular) -> None:
        self.world.core.set_velocity(body_id, linear=tuple(linear), angular=tuple(angular))

    def advance(self, duration: float, forces):
        # a control path reads the world through body_state: the answer's states go unread
        return self.world.core.propagate(duration, self.world.step_values.step,
                                         body_forces=force_requests(forces), keep=True,
                                         read_states=False)


def force_requests(forces) -> list:
    """An actuation's forces as Propagate's body forces (keyword arguments of add_body_force)."""
    return [dict(object_id=body, kind=ForceKind.FORCE, vector=tuple(vector))
            for body, vector in forces]


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
                                   for f in (_POSITION, _QUATERNION, _LINEAR)),
                                 com, not com.any())

    def body(self, state: np.ndarray, name: str) -> BodyState:
        """The body ``name``'s (frame origin (3,) m, quaternion (w, x, y, z), linear velocity
        (3,) m/s of its centre of mass), world frame, in ``state``: read-only (views of it)."""
        position, quaternion, linear, com, centred = self._slots[name]
        position, quaternion = state[position], state[quaternion]
        if centred:
            x, y, z = position.tolist()
            if x and y and z:
                # origin = position - R @ 0 = position: subtracting a zero changes no value
                # but a zero's sign, hence the non-zero position (body_state's very bits)
                return position, quaternion, state[linear]
        return position - quaternion_to_matrix(quaternion) @ com, quaternion, state[linear]


_POSITION, _QUATERNION, _LINEAR = (BODY_STATE_SLICES[name]
                                   for name in ("position", "quaternion", "linear"))


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
        except Exception:
            self.world.close()
            raise
        self.bodies = VectorBodies({b.id: (index, b.center_of_mass)
                                    for index, b in enumerate(bodies)})
        self.port = CorePort(self.world)
        self.propagations = 0
        self._servo_sent: Optional[ServoCommand] = None

    def start_state(self) -> np.ndarray:
        return self._start.copy()

    def tracked_state(self, state):
        state = self.world.core.checked_state_vector(state)
        return self._tracked(state)

    def _tracked(self, state: np.ndarray):
        position, quaternion, linear = self.bodies.body(state, self.problem.tracked_body)
        return self.problem.tracked_origin(position, quaternion), linear.copy()

    def propagate(self, requests):
        return [self._one(state, control) for state, control in requests]

    def _one(self, state, control) -> Outcome:
        core, problem = self.world.core, self.problem
        state = np.asarray(state, dtype=np.float64)
        if state.shape != self._start.shape:
            core.checked_state_vector(state)     # raises: the Core's refusal of its size
        act = step_actuation(problem, control, self.bodies.body(state, problem.base_body))
        if act.servo is not None and act.servo != self._servo_sent:
            core.checked_state_vector(state)     # a bad state changes no servo either
            # the same settings again change nothing: a control held over several steps
            # is sent once (this world's servos are set by this back end alone)
            self.port.set_servo(act.servo)
            self._servo_sent = act.servo
        # propagate_state checks the state's values before it changes anything
        result = core.propagate_state(state, problem.step, self.world.step_values.step,
                                      act.forces)
        self.propagations += 1
        position, linear = self._tracked(result.state)
        return Outcome(result.state, position, linear, result.pairs)

    def close(self) -> None:
        self.world.close()


__all__ = ["Outcome", "Backend", "CoreWorld", "CorePort", "CoreBackend", "VectorBodies",
           "force_requests", "send_plan", "step_actuation"]
