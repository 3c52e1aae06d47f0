"""The divergence guard's Python side: which bodies C checks after every step (the dynamic
ones not parked), and what it found (odin_step.c parks a body that went wrong before ODE's
collision code can see it: a body whose bounds overflow ODE's broad phase makes ODE end the
process).

A divergence is reported once, as a Divergence: the object, why (not finite, too fast,
spinning too fast, beyond the world's extent), the value that broke the bound and the state
the step left it in. A parked object stays parked (kinematic, still, colliding with nothing)
until it is removed or a snapshot taken before it diverged is put back.
"""
from __future__ import annotations

from typing import Iterable, List

from virtual_world.core.records import Divergence
from virtual_world.core.scene import Scene
from virtual_world.ode import bodies

REASONS = {1: "a value is not finite", 2: "faster than divergence_speed",
           3: "spinning faster than divergence_angular_speed",
           4: "beyond world_extent from the origin"}


def guarded(scene: Scene) -> List[str]:
    """The objects C checks (and, under auto_disable, lets sleep): every object with a dynamic
    body, not parked and not moved by the kinematic drive."""
    driven = set(scene.kinematic.values())
    return [i for i, o in scene.objects.items()
            if o.body is not None and not o.fixed and i not in scene.parked and i not in driven]


def refresh(scene: Scene) -> None:
    """Hands C the guarded bodies. Called whenever that set changes, and before a body goes
    (C must never see a freed body)."""
    scene.c.set_guarded([scene.objects[i].body.ptr for i in guarded(scene)])


def collect(scene: Scene, step_size: float) -> List[Divergence]:
    """The divergences of the last step call, named, now parked; kept in scene.divergences
    until taken."""
    parked = scene.c.divergences()
    if not parked:
        return []      # the usual case, and a planner's propagation's: no look-up to build
    by_address = {o.body.address: i for i, o in scene.objects.items() if o.body is not None}
    found = []
    for address, reason, value, position, velocity, angular, step in parked:
        object_id = by_address[address]
        event = Divergence(object_id, REASONS[reason], value, position, velocity, angular,
                           scene.sim_time + (step - scene.c.step_count) * step_size)
        scene.parked[object_id] = event
        found.append(event)
    scene.divergences.extend(found)
    return found


def set_parked(scene: Scene, parked: Iterable[str]) -> None:
    """Makes exactly ``parked`` parked (a snapshot put back): the others dynamic again, their
    collisions back."""
    wanted = set(parked)
    for object_id in list(scene.parked):
        if object_id not in wanted:
            obj = scene.objects[object_id]
            bodies.unpark(obj.body.ptr, collide=not obj.spec.no_collisions)
            del scene.parked[object_id]
    for object_id in wanted - set(scene.parked):
        bodies.park(scene.objects[object_id].body.ptr)
        scene.parked[object_id] = None
    refresh(scene)
