"""``gui.core.world_port.WorldPort`` over a world node: ``ClientWorldPort`` adapts a
``gui.ros.client.WorldClient`` (its typed methods only), and the runs that drive a world node
through it (``run_on_client``, ``run_tracked_on_client``, ``hold_on_client``) pause a running
world for their time and start it again after.

Each ``advance`` is one kept Propagate of the paused world: the world runs the duration at its
own step, as fast as it goes, and answers every body's state after it, which the port keeps
until something changes the state (so a control path reads its robot without a Get State).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional, Sequence

import numpy as np

from gui.core.contacts import ContactLedger
from gui.core.control_path import ControlRow, RowResult, hold, run_control_path
from gui.core.execution import TrackingDefaults, TrackingReport, execute_tracked
from gui.core.kautham.solutions import Solution
from gui.core.plan import ServoCommand
from gui.core.world_port import BodyState, Built, Collision, Forces, Pair
from odin_common.interface import ForceKind, JointType
from odin_common.specs import JointSpec
from odin_common.step_values import StepValues


@dataclass
class ClientWorldPort:
    """A WorldPort over ``client`` (a gui.ros.client.WorldClient); the world must be paused
    while it advances (the runs below pause it). ``real_time``: an advance takes at least its
    duration of wall-clock time (``sleep`` waits), so that a Viewer shows the motion at its
    pace."""
    client: object
    real_time: bool = False
    sleep: Callable[[float], None] = time.sleep
    _step_values: Optional[StepValues] = None
    _states: Dict[str, BodyState] = field(default_factory=dict)

    # -- building ------------------------------------------------------------------------------
    def pause(self) -> bool:
        return self.client.pause()

    def set_world(self, **changes):
        return self.client.set_world(**changes)

    def set_step(self, step=None, steps_per_cycle=None, cycle_time=None, rate=None):
        self._step_values = self.client.set_step(step, steps_per_cycle, cycle_time, rate)
        return self._step_values

    def build_entity(self, spec) -> Built:
        return self.client.build_entity(spec)

    def build_object(self, spec) -> str:
        return self.client.build_object(spec)

    def build_composite(self, spec) -> str:
        return self.client.build_composite(spec)

    def add_joint(self, spec) -> str:
        return self.client.add_joint(spec)

    def add_motor(self, spec) -> str:
        return self.client.add_motor(spec)

    def set_joint_parameters(self, joint_id: str, parameters: Sequence) -> None:
        self.client.set_joint_parameters(joint_id, parameters)

    def exempt_overlaps(self, min_depth: float) -> List[Pair]:
        return self.client.exempt_overlaps(min_depth)

    def check_collision(self, poses: Sequence) -> List[Pair]:
        return self.client.check_collision(poses)

    # -- reading ---------------------------------------------------------------------------
    def step_values(self) -> StepValues:
        if self._step_values is None:
            self._step_values = self.client.step_values()
        return self._step_values

    def gravity(self) -> np.ndarray:
        return np.asarray(self.client.world_parameters().gravity, dtype=float)

    def masses(self, body_ids: Sequence[str]) -> float:
        return float(sum(self.client.masses(body_ids)))

    def joint_positions(self, joint_ids: Sequence[str]) -> np.ndarray:
        return self.client.joint_positions(joint_ids)

    def body_state(self, body_id: str) -> BodyState:
        if body_id not in self._states:
            self._states[body_id] = BodyState(*self.client.body_kinematics(body_id))
        return self._states[body_id]

    # -- running -----------------------------------------------------------------------------
    def set_servo(self, command: ServoCommand) -> None:
        self.client.set_servo(command)

    def set_body_velocity(self, body_id: str, linear, angular) -> None:
        self.client.set_body_velocity(body_id, linear=list(linear), angular=list(angular))
        self._states.pop(body_id, None)

    def advance(self, duration: float, forces: Forces = ()) -> List[Collision]:
        started = time.monotonic()
        result = self.client.propagate(duration, forces=[
            dict(object_id=body, kind=ForceKind.FORCE, vector=list(vector))
            for body, vector in forces], keep=True)
        self._states = {i: BodyState(*(np.array(v) for v in s))
                        for i, s in result.states.items()}
        if self.real_time:
            self.sleep(max(0.0, duration - (time.monotonic() - started)))
        return [Collision(a, b, float(depth), float(when) - result.start_time)
                for a, b, depth, when in result.collisions]

    def attach(self, body1: str, body2: str) -> str:
        return self.client.add_joint(JointSpec(type=JointType.FIXED, body1=body1,
                                               body2=body2))

    def detach(self, joint_id: str) -> None:
        self.client.remove_joint(joint_id)


def _paused(client, run: Callable[[], object]):
    """``run()`` with the world paused, started again afterwards if it was running."""
    running = client.world().simulating
    if running:
        client.pause()
    try:
        return run()
    finally:
        if running:
            client.start()


def run_on_client(client, handle, rows: Sequence[ControlRow],
                  real_time: bool = True,
                  progress: Optional[Callable[[RowResult], None]] = None,
                  sleep: Callable[[float], None] = time.sleep,
                  stop: Optional[Callable[[], bool]] = None,
                  watch: Optional[str] = None,
                  contacts: Optional[ContactLedger] = None,
                  others: Sequence = ()) -> List[RowResult]:
    """``gui.core.control_path.run_control_path`` on ``client``'s world (``watch``: its body
    to report; ``contacts``: told the pairs met; ``others``: more robots and their rows),
    the world paused meanwhile. Stopped by ``stop()``, the robots are held where they are
    (``gui.core.control_path.hold``) before the world runs again."""
    def run() -> List[RowResult]:
        port = ClientWorldPort(client, real_time, sleep)
        results = run_control_path(port, handle, rows, progress=progress, stop=stop,
                                   watch=watch, contacts=contacts, others=others)
        if stop is not None and stop():
            for robot in [handle, *(other for other, _ in others)]:
                hold(port, robot)
        return results
    return _paused(client, run)


def run_tracked_on_client(client, plan, solution: Solution,
                          defaults: TrackingDefaults = TrackingDefaults(),
                          progress: Optional[Callable[[float, float], None]] = None,
                          real_time: bool = False,
                          stop: Optional[Callable[[], bool]] = None,
                          from_here: bool = False) -> TrackingReport:
    """``gui.core.execution.execute_tracked`` on ``client``'s world (``from_here`` as
    there), the world paused meanwhile. Stopped by ``stop()``, each robot of the solution is
    held where it is before the world runs again."""
    def run() -> TrackingReport:
        port = ClientWorldPort(client)
        report = execute_tracked(port, plan, solution, defaults, progress=progress,
                                 real_time=real_time, stop=stop, from_here=from_here)
        if stop is not None and stop():
            for name in solution.paths:
                hold(port, plan.robot(name))
        return report
    return _paused(client, run)


def hold_on_client(client, handle) -> None:
    """Holds ``handle``'s robot where it is in ``client``'s world (``control_path.hold``)."""
    hold(ClientWorldPort(client), handle)


__all__ = ["ClientWorldPort", "run_on_client", "run_tracked_on_client", "hold_on_client"]
