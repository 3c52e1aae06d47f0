"""The world as a GUI algorithm sees it: one seam, ``WorldPort`` (ROS-free).

Building a plan (``gui.core.plan``'s steps, ``gui.core.overlaps``), running a control path
(``gui.core.control_path``), following a plan under the servos (``gui.core.execution``) and
holding a robot where it is all ask the world through this one protocol. It has exactly two
implementations, each beside what it adapts:

- ``gui.ros.world_port.ClientWorldPort``: a world node, through a ``gui.ros.client.WorldClient``
  (each ``advance`` one kept Propagate of the paused world);
- ``gui.planning.core_world.CoreWorld``: a VirtualWorld Core in this process (the planner's
  worlds, the rehearsal of a load, the tests).

The two answer the same numbers for the same calls, bit for bit
(``tests/nodes/test_world_port_conformance.py`` runs a control path and a tracked path through
both and compares them).

Units are SI (m, rad, kg, s); positions, velocities and quaternions (w, x, y, z) are in the
world frame.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Callable, List, NamedTuple, Optional, Protocol, Sequence, Tuple

import numpy as np

from gui.core.overlaps import settle_overlaps
from gui.core.plan import BuildPlan, BuiltIds

if TYPE_CHECKING:
    from gui.core.plan import ServoCommand
    from odin_common.specs import CompositeSpec, EntitySpec, JointSpec, MotorSpec, ObjectSpec
    from odin_common.step_values import StepValues
    from odin_common.world_parameters import WorldParameters


class BodyState(NamedTuple):
    """One body's state, world frame: ``position`` (3,) m of the object's frame origin,
    ``quaternion`` (w, x, y, z), ``linear`` (3,) m/s of the centre of mass, ``angular`` (3,)
    rad/s."""
    position: np.ndarray
    quaternion: np.ndarray
    linear: np.ndarray
    angular: np.ndarray


class Collision(NamedTuple):
    """A pair that collided during an ``advance``: the two geometries' names, the deepest
    ``depth`` m, and ``time`` s from the start of the advance when first seen."""
    first: str
    second: str
    depth: float
    time: float


class Built(NamedTuple):
    """Build Entity's answer: the entity's ``name`` and its members' world IDs (objects
    first)."""
    name: str
    ids: Tuple[str, ...]


Forces = Sequence[Tuple[str, Sequence[float]]]
"""Forces acting during one advance: (body ID, (3,) N at its centre of mass, world frame)."""

Progress = Callable[[int, object, str], None]
"""``progress(k, step, answer)`` after step k (1-based) of a build plan was answered."""

Pair = Tuple[str, str, float]
"""Check Collision's and Exempt Overlaps' pair: (first geometry, second, depth m)."""


class WorldPort(Protocol):
    """What a GUI algorithm asks of the world: building a plan, running it, reading it."""

    # -- building (gui.core.plan's steps, gui.core.overlaps) ---------------------------------
    def pause(self) -> bool:
        """The world stops advancing by itself; answers the state in force (False)."""

    def set_world(self, **changes) -> "WorldParameters":
        """Set World (odin_common.world_parameters names and units), all or nothing."""

    def set_step(self, step=None, steps_per_cycle=None, cycle_time=None,
                 rate=None) -> "StepValues":
        """Set Step (s, steps, s, Hz; None: not given); answers the values in force."""

    def build_entity(self, spec: "EntitySpec") -> Built: ...

    def build_object(self, spec: "ObjectSpec") -> str: ...

    def build_composite(self, spec: "CompositeSpec") -> str: ...

    def add_joint(self, spec: "JointSpec") -> str: ...

    def add_motor(self, spec: "MotorSpec") -> str: ...

    def set_joint_parameters(self, joint_id: str, parameters: Sequence) -> None:
        """(JointParameter, axis 1..3, value) triples, all or nothing."""

    def exempt_overlaps(self, min_depth: float) -> List[Pair]:
        """Exempt Overlaps deeper than ``min_depth`` m; answers those pairs."""

    def check_collision(self, poses: Sequence) -> List[Pair]:
        """Check Collision with bodies at ``poses`` ((ID, position, quaternion)); no change."""

    # -- reading -----------------------------------------------------------------------------
    def step_values(self) -> "StepValues":
        """The Set Step values in force."""

    def gravity(self) -> np.ndarray:
        """(3,) m/s^2."""

    def masses(self, body_ids: Sequence[str]) -> float:
        """The bodies' total mass, kg."""

    def joint_positions(self, joint_ids: Sequence[str]) -> np.ndarray:
        """Each joint's first axis position (rad or m), in order."""

    def body_state(self, body_id: str) -> BodyState: ...

    # -- running ------------------------------------------------------------------------------
    def set_servo(self, command: "ServoCommand") -> None:
        """Set Servo (its lists one value per motor axis, split per motor by the world)."""

    def set_body_velocity(self, body_id: str, linear: Sequence[float],
                          angular: Sequence[float]) -> None:
        """Set Velocity of one body: (3,) m/s and (3,) rad/s."""

    def advance(self, duration: float, forces: Forces = ()) -> List[Collision]:
        """Runs the paused world ``duration`` s at its step, ``forces`` acting meanwhile;
        answers the pairs that collided."""

    def attach(self, body1: str, body2: str) -> str:
        """A FIXED joint between two bodies (``body2`` "": the static world); its ID."""

    def detach(self, joint_id: str) -> None: ...


def build(world: WorldPort, plan: BuildPlan, progress: Optional[Progress] = None,
          ids: Optional[BuiltIds] = None) -> Tuple[BuiltIds, list, bool]:
    """Sends every step of ``plan`` to ``world`` in order (``progress(k, step, answer)`` after
    each), records the world's IDs in the plan, and settles the parts it built inside each
    other (gui.core.overlaps.settle_overlaps); answers (the world's IDs, those overlaps,
    whether they are exempt). Stops at the first refusal: what was built before stays built,
    its IDs in ``ids`` when given (gui.planning.rehearsal.load_scene removes them)."""
    ids = BuiltIds() if ids is None else ids
    for k, step in enumerate(plan.steps, start=1):
        answer = step.send(world, ids)
        if progress is not None:
            progress(k, step, answer)
    plan.record_world_ids(ids)
    overlaps, exempt = settle_overlaps(world, plan)
    return ids, overlaps, exempt


__all__ = ["BodyState", "Built", "Collision", "Forces", "Pair", "Progress", "WorldPort",
           "build"]
