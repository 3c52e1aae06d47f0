"""gui.core.execution.TrackingPort over the VirtualWorld's Core (no ROS), for GUI Core tests:
what ClientTrackingPort asks of the world node, asked of the Core directly."""
from __future__ import annotations

import numpy as np

from gui.core.control_path import ServoCommand
from gui_core_world import CorePort, CoreWorld
from odin_common.interface import ForceKind, JointType
from odin_common.specs import JointSpec


class CoreTrackingPort:
    def __init__(self, world: CoreWorld):
        self.world = world
        self.core = world.core
        self._servo = CorePort(world)

    def step(self) -> float:
        return self.world.step_values.step

    def gravity(self) -> np.ndarray:
        return np.asarray(self.core.world_parameters.gravity, dtype=float)

    def masses(self, body_ids) -> float:
        return float(sum(self.core.mass_properties(b)[0] for b in body_ids))

    def joint_positions(self, joint_ids) -> np.ndarray:
        states = {s.id: s for s in self.core.joint_states()}
        return np.array([states[j].positions[0] for j in joint_ids], dtype=float)

    def body_state(self, body_id: str):
        return tuple(np.asarray(v) for v in self.core.body_state(body_id))

    def set_servo(self, command: ServoCommand) -> None:
        self._servo.set_servo(command)

    def set_body_velocity(self, body_id: str, linear, angular) -> None:
        self.core.set_velocity(body_id, linear=tuple(linear), angular=tuple(angular))

    def advance(self, duration: float, forces):
        result = self.core.propagate(duration, self.step(), body_forces=[
            dict(object_id=body, kind=ForceKind.FORCE, vector=tuple(vector))
            for body, vector in forces], keep=True)
        return [(c.first, c.second, c.depth, c.first_time - result.start_time)
                for c in result.collisions]

    def attach(self, body1: str, body2: str) -> str:
        return self.core.add_joint(JointSpec(type=JointType.FIXED, body1=body1, body2=body2))

    def detach(self, joint_id: str) -> None:
        self.core.remove_joint(joint_id)
