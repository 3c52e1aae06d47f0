"""A control planner's propagations with its validity rule checked in C (Core.plan_rule,
Core.propagate_checked).

A control planner (gui.planning.bridge) asks the world one propagation per step of a control
and then whether the state reached is valid: whether a pair of objects collided that must not
(its forbidden contacts) and whether the tracked link stayed in its bounds. Asked through
``propagate_state``, each step returns to Python with the pairs' names, which Python judges.
Here the rule is data the C world holds for the search (``PlanRule``: a role per object, the
pairs of roles that may not touch, the tracked link's body, offset and bounds), and one C call
(odin_plan.c) makes a row of propagations, each one odin_world_propagate's ODE calls (so bit
for bit ``propagate_state``'s states), judges each and writes its state, verdict and tracked
values straight into arrays the caller gives, which may be a planner's own memory.
"""
from __future__ import annotations

import weakref
from typing import Mapping, NamedTuple, Sequence, Tuple

import numpy as np

from odin_common import limits
from odin_common.limits import shown
from virtual_world.core import guard, validation as check
from virtual_world.core.propagation import (checked_pushes, state_vector_fault, steps_of,
                                            sized_state_vector)
from virtual_world.core.scene import Scene
from virtual_world.errors import InvalidArgument
from virtual_world.ode import bodies
from virtual_world.ode.plan_rules import RuleMemory

MAX_ROLES = 16
"""Roles a rule may give objects (its table of forbidden pairs is MAX_ROLES squared at most)."""


class PlanRule:
    """A planner's validity rule held in C memory for one scene as built (Core.plan_rule):
    the scene it was made for and its revision, so that a rule is never used on geoms it does
    not know."""

    def __init__(self, scene: Scene, memory: RuleMemory):
        self._scene = weakref.ref(scene)
        self._revision = scene.revision
        self._memory = memory           # the rule's C memory, owned here
        self.struct = memory.struct     # OdinPlanRule *

    def tracked_values(self, state: Sequence[float]) -> np.ndarray:
        """(6,) the tracked link's origin (m) and its body's linear velocity (m/s), world
        frame, in the body state vector ``state``: what ``propagate_checked`` writes."""
        return _tracked_values(self._memory, state)

    def check_for(self, scene: Scene) -> None:
        if self._scene() is not scene or self._revision != scene.revision:
            raise InvalidArgument("this plan rule was made for another world, or before "
                                  "objects were added or removed: make it again (plan_rule)")


class CheckedRow(NamedTuple):
    """What ``Core.propagate_checked`` made: ``made`` propagations, row i of ``states`` the
    state vector reached by the i-th and then its verdict (1.0 invalid, 0.0 valid), row i of
    ``tracked`` the tracked link's origin (m) and its body's linear velocity (m/s), world
    frame. The arrays are the ones given (or new ones), ``made`` rows of them written."""
    made: int
    states: np.ndarray
    tracked: np.ndarray


def plan_rule(scene: Scene, roles: Mapping[str, int], forbidden: Sequence[Tuple[int, int]],
              tracked_body: str, tracked_offset: Sequence[float], bounds: Sequence[Sequence[float]],
              max_speed: float) -> PlanRule:
    """Core.plan_rule: ``roles`` {object id: role 1..MAX_ROLES-1} (an object not named has
    role 0), ``forbidden`` the pairs of roles (either order) whose collision makes a
    propagation invalid; ``tracked_body`` the object whose body carries the tracked link,
    ``tracked_offset`` (3,) m the link's origin in that body's frame; ``bounds`` (3, 2) m,
    world, low and high of the link's origin per axis; ``max_speed`` m/s, the body's linear
    speed bound per axis. Checked first."""
    role_of_object = {}
    for object_id, role in roles.items():
        scene.object(object_id)              # raises for an unknown object
        role_of_object[object_id] = check.count(f"role of {shown(object_id)}", role, 1)
        if role >= MAX_ROLES:
            raise InvalidArgument(f"role of {shown(object_id)} is {role}: at most "
                                  f"{MAX_ROLES - 1}")
    table = np.zeros((MAX_ROLES, MAX_ROLES), dtype=np.uint8)
    for pair in forbidden:
        try:
            first, second = (check.count("forbidden role", r, 0) for r in pair)
        except (TypeError, ValueError):
            raise InvalidArgument(f"forbidden pair {shown(pair)} is not two roles") from None
        if max(first, second) >= MAX_ROLES:
            raise InvalidArgument(f"forbidden pair {shown(pair)}: roles are below {MAX_ROLES}")
        table[first, second] = table[second, first] = 1
    serials = np.zeros(scene.next_serial, dtype=np.uint8)
    for record in scene.geometries.values():
        serials[record.owner.data.serial] = role_of_object.get(record.object_id, 0)
    body = scene.body_object(tracked_body, "tracked")
    order = [o.body.ptr for o in scene.objects.values() if o.body is not None]
    offset = check.vector("tracked_offset", tracked_offset, 3)
    try:
        box = np.asarray(bounds, dtype=float)
    except (TypeError, ValueError):
        box = np.empty(0)
    # low above high is a box nothing is in (every propagation invalid), as a planner has it
    if box.shape != (3, 2) or np.isnan(box).any():
        raise InvalidArgument(f"bounds {shown(bounds)} are not (3, 2) numbers, m: low and "
                              "high per axis")
    speed = check.number("max_speed", max_speed, allow_inf=True)
    if not speed > 0:
        raise InvalidArgument(f"max_speed={shown(max_speed)} m/s must be positive")
    memory = RuleMemory(order.index(body.body.ptr), body.com, offset, serials.tobytes(),
                        table.tobytes(), MAX_ROLES, box[:, 0], box[:, 1], speed)
    return PlanRule(scene, memory)


def propagate_checked(scene: Scene, rule: PlanRule, start_state: Sequence[float], count: int,
                      duration: float, step_size: float,
                      pushes: Sequence[Tuple[str, Sequence[float]]], states, tracked,
                      stop_at_invalid: bool) -> CheckedRow:
    """Core.propagate_checked: ``count`` propagations of ``duration`` s under ``pushes``,
    from ``start_state``, each from the one before, judged by ``rule``; the scene stays in
    the state reached."""
    rule.check_for(scene)
    count = check.count("count", count)
    step_size, steps = steps_of(duration, step_size)
    if count > 1:
        check.shared(limits.check_work, f"a row of {count} propagations of {duration:.6g} s at "
                     f"{step_size:g} s", count * steps, scene.body_array().count)
    # the world's state vector length now (Exempt Overlaps changes it without a new object)
    start_state = sized_state_vector(scene, start_state)
    states = _out("states", states, (count, start_state.size + 1))
    tracked = _out("tracked", tracked, (count, 6))
    checked = checked_pushes(scene, pushes)
    made = scene.c.propagate_checked(scene.body_array(), rule.struct, start_state, checked,
                                     step_size, steps, count, stop_at_invalid, states, tracked)
    if made < 0:        # C checks the state's values before it changes anything
        raise state_vector_fault(start_state, -1 - made, len(scene.exempt_pairs))
    scene.carried = {}
    scene.sim_time += step_size * steps * made
    guard.collect(scene, step_size)
    return CheckedRow(made, states, tracked)


def _out(what: str, array, shape: Tuple[int, int]) -> np.ndarray:
    """``array`` when it is a writable C-ordered float64 (rows, shape[1]) array with at least
    shape[0] rows; a new one for None."""
    if array is None:
        return np.empty(shape)
    if not isinstance(array, np.ndarray) or array.dtype != np.float64 or array.ndim != 2 or \
            not array.flags.c_contiguous or not array.flags.writeable or \
            array.shape[1] != shape[1] or array.shape[0] < shape[0]:
        raise InvalidArgument(f"{what} must be a writable C-ordered float64 array of at least "
                              f"{shape[0]} rows of {shape[1]} values")
    return array


def _tracked_values(memory: RuleMemory, state) -> np.ndarray:
    """(6,) the tracked link's origin (m) and its body's linear velocity (m/s), world frame,
    in the body state vector ``state`` (odin_plan_tracked), checked to hold the body."""
    state = np.ascontiguousarray(state, dtype=np.float64)
    index = memory.tracked_index
    if state.ndim != 1 or state.size < 1 + (index + 1) * bodies.BODY_STATE_SIZE:
        raise InvalidArgument(f"a body state vector of shape {state.shape} has no body "
                              f"{index}")
    return memory.tracked_values(state)


class TrackedLink:
    """A tracked link read out of body state vectors without a world, by the arithmetic
    ``propagate_checked`` uses (odin_plan_tracked): the link's origin on body ``index`` of the
    vectors (in their order), at ``offset`` (3,) m in the frame of that body, whose centre of
    mass is ``com`` (3,) m in that frame."""

    def __init__(self, index: int, com: Sequence[float], offset: Sequence[float]):
        self._memory = RuleMemory(check.count("tracked body index", index, 0),
                                  check.vector("com", com), check.vector("offset", offset))

    def values(self, state: Sequence[float]) -> np.ndarray:
        """(6,) the link's origin (m) and its body's linear velocity (m/s), world frame."""
        return _tracked_values(self._memory, state)
