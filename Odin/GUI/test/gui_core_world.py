"""The VirtualWorld's Core standing in for the world node in GUI Core tests (no ROS): a
client with the WorldClient methods build plans call, and a control port over it.

The plan's steps call only these methods, as they do WorldClient's; the node tests and the
experiments send the same plans through the real client."""
from __future__ import annotations

import numpy as np

from gui.core.build import BuildPlan, BuiltIds
from gui.core.control_path import ServoCommand
from odin_common.interface import ForceKind
from odin_common.step_values import StepValues
from virtual_world.core import Core


class CoreWorld:
    """A Core behind WorldClient's build methods; ``step`` is the Set Step value in force."""

    def __init__(self):
        self.core = Core()
        self.step_values = StepValues()

    def close(self) -> None:
        self.core.close()

    # -- what build plans call -----------------------------------------------------------------
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

    def execute(self, plan: BuildPlan) -> dict:
        ids = BuiltIds()
        for step in plan.steps:
            step.send(self, ids)
        plan.record_world_ids(ids)
        return ids.as_dict()

    # -- stepping ------------------------------------------------------------------------------
    def run(self, seconds: float) -> None:
        """Steps the world ``seconds`` of simulated time at the step in force."""
        h = self.step_values.step
        self.core.step(h, max(1, round(seconds / h)))

    def position(self, object_id: str) -> np.ndarray:
        return np.asarray(self.core.body_state(object_id)[0])

    def speed(self, object_id: str) -> float:
        return float(np.linalg.norm(self.core.body_state(object_id)[2]))


class CorePort:
    """gui.core.control_path.ControlPort over a CoreWorld: each row one kept propagation."""

    def __init__(self, world: CoreWorld):
        self.world = world

    def body_state(self, body_id: str):
        position, quaternion, linear, _ = self.world.core.body_state(body_id)
        return np.asarray(position), np.asarray(quaternion), np.asarray(linear)

    def set_servo(self, command: ServoCommand) -> None:
        core = self.world.core
        servos = {m: {} for m in command.motors}
        for name in ("targets", "rates", "gains", "max_speeds", "max_forces"):
            values = getattr(command, name)
            if name == "targets" or len(values):
                for motor, split in core.split_per_axis(list(command.motors), list(values),
                                                        name).items():
                    servos[motor][name] = split
        core.set_servos(servos)

    def advance(self, duration: float, forces) -> None:
        self.world.core.propagate(duration, self.world.step_values.step, body_forces=[
            dict(object_id=body, kind=ForceKind.FORCE, vector=tuple(vector))
            for body, vector in forces], keep=True)
