"""Body state vectors and propagations over a scene: what a planner asks of the world.

A body state vector is the bodies' dynamic state as one flat float64 vector (Core's
``body_state_vector`` says its layout); a propagation runs the world for a while from a
snapshot, a state vector or now, under goals and forces of its own, recording every pair that
collides on the way. Everything is checked before anything changes; a refused or cancelled
propagation leaves the world as it was.
"""
from __future__ import annotations

import functools
import time
from typing import List, Mapping, Optional, Sequence, Tuple

import numpy as np

from odin_common import limits
from odin_common.interface import ForceKind
from odin_common.limits import shown
from virtual_world.core import (exemptions, forces, guard, long_calls, motors, readout,
                                snapshots, validation as check)
from virtual_world.core.records import BodyState, Propagation, StatePropagation
from virtual_world.core.scene import Scene
from virtual_world.errors import CoreError, InvalidArgument
from virtual_world.ode import bodies


# ---------------------------------------------------------------------- body state vectors

def state_vector(scene: Scene) -> np.ndarray:
    """The scene's body state vector now (Core.body_state_vector)."""
    return np.concatenate(([float(scene.c.rand_seed)],
                           bodies.read_states(_body_ptrs(scene)).ravel(),
                           exemptions.live(scene)))


def _body_ptrs(scene: Scene) -> list:
    return [o.body.ptr for o in scene.objects.values() if o.body is not None]


def checked_state_vector(scene: Scene, vector: Sequence[float]) -> np.ndarray:
    """``vector`` as contiguous float64 when it is a body state vector of this scene (its
    size, finite values, a 32-bit generator state); InvalidArgument otherwise."""
    vector = sized_state_vector(scene, vector)
    fault = bodies.state_vector_fault(vector, len(scene.exempt_pairs))
    if fault >= 0:
        raise state_vector_fault(vector, fault, len(scene.exempt_pairs))
    return vector


def sized_state_vector(scene: Scene, vector: Sequence[float]) -> np.ndarray:
    """``vector`` as contiguous float64 when it has the size of this scene's body state
    vectors; its values are checked by state_vector_fault."""
    try:
        vector = np.ascontiguousarray(vector, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidArgument(f"a body state vector holds numbers; got "
                              f"{str(vector)[:60]}") from None
    exempt = len(scene.exempt_pairs)
    size = 1 + scene.body_array().count * bodies.BODY_STATE_SIZE + exempt
    if vector.shape != (size,):
        pairs = f" + {exempt} exempt pairs" if exempt else ""
        raise InvalidArgument(f"a body state vector of this world has {size} finite "
                              f"values (1 + {bodies.BODY_STATE_SIZE} per body{pairs}); "
                              f"got shape {vector.shape}")
    return vector


def put_state_vector(scene: Scene, vector: np.ndarray) -> None:
    """Puts back a checked body state vector (checked_state_vector), bit for bit."""
    ptrs = _body_ptrs(scene)
    end = 1 + len(ptrs) * bodies.BODY_STATE_SIZE
    bodies.write_states(ptrs, vector[1:end].reshape(len(ptrs), bodies.BODY_STATE_SIZE))
    exemptions.put_live(scene, vector[end:])
    scene.c.clear_records()
    scene.carried = {}
    scene.c.rand_seed = int(vector[0])


def state_vector_fault(vector: np.ndarray, index: int, exempt: int) -> InvalidArgument:
    """The refusal of a body state vector whose value ``index`` cannot be put back (its last
    ``exempt`` values are exempt pairs' states)."""
    if index == 0:
        return InvalidArgument(f"random generator state {shown(float(vector[0]))} is not a "
                               "32-bit integer")
    if index >= vector.size - exempt:
        return InvalidArgument(f"an exempt pair's state is 0.0 or 1.0; value {index} is "
                               f"{shown(float(vector[index]))}")
    return InvalidArgument(f"a body state vector's values are finite; value {index} is "
                           f"{shown(float(vector[index]))}")


# ---------------------------------------------------------------------- propagations

def propagate(scene: Scene, duration: float, step_size: float,
              motor_goals: Optional[Mapping[str, Sequence[float]]], body_forces: Sequence[Mapping],
              start: str, keep: bool, start_state: Optional[Sequence[float]],
              read_states: bool, cancelled: Optional[long_calls.Cancel]) -> Propagation:
    """Core.propagate: runs the scene from the snapshot ``start``, the body state vector
    ``start_state`` or now, under ``motor_goals`` and ``body_forces``; back to the state
    before the call unless ``keep`` (and always after a refusal or a cancel)."""
    step_size, steps = steps_of(duration, step_size)
    check.shared(limits.check_work, f"propagate {duration:.6g} s at {step_size:g} s",
                 steps, scene.body_array().count)
    keep = check.flag("keep", keep)
    start_snapshot = snapshots.named(scene, start) if start else None
    if start_snapshot is not None:
        snapshots.check_fits(scene, start_snapshot, f"snapshot {shown(start)}")
    if start_state is not None and len(start_state):
        if start_snapshot is not None:
            raise InvalidArgument("give a start snapshot or a start state, not both")
        start_state = checked_state_vector(scene, start_state)
    else:
        start_state = None
    before = snapshots.take(scene)
    started = time.perf_counter()
    try:
        if start_snapshot is not None:
            snapshots.put_back(scene, start_snapshot)
        if start_state is not None:
            put_state_vector(scene, start_state)
        if motor_goals:
            motors.set_velocities(scene, motor_goals)
        added = [forces.add_body_force(scene, **dict(f)) for f in body_forces]
        result = _run(scene, steps, step_size, read_states, cancelled)
        for force_id in added:
            forces.remove_body_force(scene, force_id)
    except Exception:
        snapshots.put_back(scene, before)   # a refused control changes nothing
        raise
    if not keep:
        snapshots.put_back(scene, before)
    return result._replace(wall_time=time.perf_counter() - started, kept=keep)


def propagate_state(scene: Scene, start_state: Sequence[float], duration: float,
                    step_size: float, pushes: Sequence[Tuple[str, Sequence[float]]]
                    ) -> StatePropagation:
    """Core.propagate_state: from ``start_state``, in one C call, under ``pushes`` ((object
    id, force N world) each); the scene stays in the state reached."""
    step_size, steps = steps_of(duration, step_size)
    start_state = sized_state_vector(scene, start_state)
    try:
        checked = checked_pushes(scene, pushes)
    except CoreError:
        checked_state_vector(scene, start_state)     # a bad state is said first
        raise
    state, steps, pairs = scene.c.propagate(scene.body_array(), start_state, checked,
                                            step_size, steps)
    if steps < 0:        # C checks the state's values before it changes anything
        raise state_vector_fault(start_state, -1 - steps, len(scene.exempt_pairs))
    scene.carried = {}
    scene.sim_time += step_size * steps
    guard.collect(scene, step_size)
    return StatePropagation(state, scene.pair_names(pairs), steps)


def propagate_row(scene: Scene, start_state: Sequence[float], count: int, duration: float,
                  step_size: float, pushes: Sequence[Tuple[str, Sequence[float]]],
                  keep: bool) -> List[StatePropagation]:
    """Core.propagate_row: ``count`` planner's propagations of ``duration`` s in a row, each
    ``propagate_state`` from the state the one before reached (bit for bit those calls one by
    one), under ``pushes`` in each; back to the state before the call unless ``keep`` (and
    always after a refusal). Checked first: the count, and its work within
    limits.MAX_BODY_STEPS_PER_CALL."""
    count = check.count("row", count)
    step_size, steps = steps_of(duration, step_size)
    check.shared(limits.check_work, f"a row of {count} propagations of {duration:.6g} s at "
                 f"{step_size:g} s", count * steps, scene.body_array().count)
    keep = check.flag("keep", keep)
    before = snapshots.take(scene)
    row: List[StatePropagation] = []
    try:
        state = start_state
        for _ in range(count):
            row.append(propagate_state(scene, state, duration, step_size, pushes))
            state = row[-1].state
    except Exception:
        snapshots.put_back(scene, before)   # a refused row changes nothing
        raise
    if not keep:
        snapshots.put_back(scene, before)
    return row


def _run(scene: Scene, steps: int, step_size: float, read_states: bool = True,
         cancelled: Optional[long_calls.Cancel] = None) -> Propagation:
    """Steps with every step's collisions recorded; what a propagation answers."""
    readout.carry_collisions(scene, set())
    carried, scene.carried = scene.carried, {}
    start_time, start_step = scene.sim_time, scene.c.step_count
    scene.c.record_every_step = True
    try:
        steps = long_calls.run_steps(scene, step_size, steps, cancelled)
    finally:
        scene.c.record_every_step = False
    collisions = tuple(sorted(
        c._replace(first_time=start_time + (step - start_step) * step_size)
        for c, step in readout.named_records(scene)))
    scene.c.clear_records()
    scene.carried = carried
    states = tuple(BodyState(i, *(tuple(v.tolist()) for v in readout.body_state(scene, i)))
                   for i, o in scene.objects.items() if o.body is not None) \
        if read_states else ()
    return Propagation(start_time, step_size, steps, states, collisions, 0.0, False,
                       state_vector(scene))


def checked_pushes(scene: Scene, pushes: Sequence[Tuple[str, Sequence[float]]]) -> list:
    """(object id, force N world) pairs as (body ptr, force) for CWorld.propagate, each
    checked as add_body_force checks a force at the centre of mass."""
    checked = []
    for push in pushes:
        try:
            object_id, vector = push
        except (TypeError, ValueError):
            raise InvalidArgument(f"force {shown(push)} is not (object id, force vector)") from None
        checked.append((scene.body_object(object_id, "force").body.ptr,
                        forces.checked_vector(object_id, ForceKind.FORCE, vector)))
    return checked


def steps_of(duration: float, step_size: float) -> Tuple[float, int]:
    """(step_size, the number of steps) of a propagation of ``duration`` s, both checked;
    remembered for plain floats (a planner asks the same every step)."""
    if type(duration) is float and type(step_size) is float:   # noqa: E721 - not bool
        return _remembered_steps(duration, step_size)
    return _checked_steps(duration, step_size)


@functools.lru_cache(maxsize=64)
def _remembered_steps(duration: float, step_size: float) -> Tuple[float, int]:
    return _checked_steps(duration, step_size)


def _checked_steps(duration: float, step_size: float) -> Tuple[float, int]:
    duration = check.number("duration", duration)
    step_size = check.step_size(step_size)
    if duration <= 0:
        raise InvalidArgument(f"duration={shown(duration)} must be positive")
    return step_size, check.step_count(max(1, round(min(duration / step_size, 1e18))),
                                       f"duration={shown(duration)} s at step {shown(step_size)} s")
