"""``gui.core.world_port.WorldPort`` over a VirtualWorld Core in this process (no ROS): the
planner's worlds (``gui.planning.backend``), the rehearsal of a load
(``gui.planning.rehearsal``) and the GUI Core's tests.

Each call is the Core's own, as the world node's Portal makes it for the same service (Set
Servo split per motor axis by the Core; an advance one kept propagation at the step in
force), so that what runs here runs bit for bit the same in a world node
(``tests/nodes/test_world_port_conformance.py``).
"""
from __future__ import annotations

from typing import List, Optional, Sequence

import numpy as np

from gui.core.plan import BuildPlan, ServoCommand
from gui.core.world_port import BodyState, Built, Collision, Forces, Pair, build
from odin_common.interface import ForceKind, JointType
from odin_common.specs import JointSpec
from odin_common.step_values import StepValues


class CoreWorld:
    """A WorldPort over a Core of this process (``core``, public for tests and planners that
    step it directly). A Core steps only when asked: it is always paused."""

    def __init__(self, parameters=None, resources=None,
                 step_values: Optional[StepValues] = None):
        """``parameters`` (WorldParameters), ``resources`` (ResourceLimits) and
        ``step_values``: the world's to start from (None: the defaults)."""
        from virtual_world.core import Core
        from odin_common.limits import ResourceLimits
        self.core = Core(parameters, ResourceLimits() if resources is None else resources)
        self._step_values = StepValues() if step_values is None else step_values

    def close(self) -> None:
        self.core.close()

    def execute(self, plan: BuildPlan) -> dict:
        """Builds ``plan`` (gui.core.world_port.build); answers the world's IDs ({"bodies",
        "joints", "motors"}) and the overlaps it settled ("overlaps", "overlaps_exempt"). No
        robot is declared: a Core publishes nothing anyone reads."""
        ids, overlaps, exempt = build(self, plan)
        return {**ids.as_dict(), "overlaps": overlaps, "overlaps_exempt": exempt}

    # -- building ------------------------------------------------------------------------------
    def pause(self) -> bool:
        return False

    def set_world(self, **changes):
        return self.core.set_world_parameters(**changes)

    def set_step(self, step=None, steps_per_cycle=None, cycle_time=None, rate=None):
        """The values as given: a planner's world takes the plan's step values as they are
        (gui.planning.rehearsal checks them as the node does)."""
        self._step_values = StepValues(step, steps_per_cycle, rate)
        return self._step_values

    def build_entity(self, spec) -> Built:
        built = self.core.build_entity(spec)
        return Built(built.name, tuple(built.ids))

    def build_object(self, spec) -> str:
        return self.core.build_object(spec).id

    def build_composite(self, spec) -> str:
        return self.core.build_composite(spec).id

    def add_joint(self, spec) -> str:
        return self.core.add_joint(spec)

    def add_motor(self, spec) -> str:
        return self.core.add_motor(spec)

    def set_joint_parameters(self, joint_id: str, parameters: Sequence) -> None:
        self.core.set_joint_parameters(joint_id, parameters)

    def exempt_overlaps(self, min_depth: float) -> List[Pair]:
        return [(c.first, c.second, c.depth) for c in self.core.exempt_overlaps(min_depth)]

    def check_collision(self, poses: Sequence) -> List[Pair]:
        return [(c.first, c.second, c.depth) for c in self.core.check_collision(poses)]

    # -- reading -------------------------------------------------------------------------------
    def step_values(self) -> StepValues:
        return self._step_values

    def gravity(self) -> np.ndarray:
        return np.asarray(self.core.world_parameters.gravity, dtype=float)

    def masses(self, body_ids: Sequence[str]) -> float:
        if not len(body_ids):               # Get State's empty list asks for every body
            return 0.0
        bodies, _, _ = self.core.state(list(body_ids))
        return float(sum(b.mass for b in bodies))

    def joint_positions(self, joint_ids: Sequence[str]) -> np.ndarray:
        if not len(joint_ids):
            return np.empty(0)
        _, joints, _ = self.core.state(joints=list(joint_ids))
        return np.array([j.positions[0] for j in joints], dtype=float)

    def body_state(self, body_id: str) -> BodyState:
        return BodyState(*(np.asarray(v) for v in self.core.body_state(body_id)))

    # -- running ---------------------------------------------------------------------------------
    def set_servo(self, command: ServoCommand) -> None:
        self.core.set_servo(**command.request_fields())

    def set_body_velocity(self, body_id: str, linear, angular) -> None:
        self.core.set_velocity(body_id, linear=tuple(linear), angular=tuple(angular))

    def advance(self, duration: float, forces: Forces = ()) -> List[Collision]:
        # the port reads bodies through body_state: the answer's states go unread
        result = self.core.propagate(duration, self._step_values.step,
                                     body_forces=force_requests(forces), keep=True,
                                     read_states=False)
        return [Collision(c.first, c.second, c.depth, c.first_time - result.start_time)
                for c in result.collisions]

    def attach(self, body1: str, body2: str) -> str:
        return self.core.add_joint(JointSpec(type=JointType.FIXED, body1=body1, body2=body2))

    def detach(self, joint_id: str) -> None:
        self.core.remove_joint(joint_id)


def force_requests(forces: Forces) -> list:
    """Forces (body ID, (3,) N, world) as Propagate's body forces (keyword arguments of the
    Core's add_body_force)."""
    return [dict(object_id=body, kind=ForceKind.FORCE, vector=tuple(vector))
            for body, vector in forces]


__all__ = ["CoreWorld", "force_requests"]
