"""Loading a build plan into a running world, all or nothing (issue 39).

A world node checks each request as it comes: a problem it refuses midway (a body beyond
``world_extent``, one object more than its ``~max_objects``, a mesh over
``~max_mesh_triangles``, a name it refuses) would leave half a robot, without its motors, in
place of the scene before. So ``load_scene`` first builds the whole plan in a VirtualWorld
Core of this process (``rehearse``: the same ROS-free Core the node runs, started from the
node's world parameters, step values and resource limits, then set as the plan sets them) and
sends it to the node only when every step was taken there. The Core being the node's own
rules, what the rehearsal takes the node takes, but for what only the node knows (another
client's requests in between); if the node still refuses a step, what this load built is
removed and the world parameters and step values it set are put back, and the error names the
step.

With ``keep`` (the plan added to the scene the world holds), the rehearsal checks the plan
alone, with the room the world has left under ``max_objects``: a clash with what the world
holds (a name already taken) is found by the node only, and then undone as above, leaving
the scene as it was.

This module is the one home of the rule: ``load_problem`` (gui.tools) and the window's Open
file (gui.window.simulation_tab) call ``load_scene``. It needs no ROS: ``client`` is a
``gui.ros.client.WorldClient`` (only its methods are called).
"""
from __future__ import annotations

import dataclasses
from typing import Optional

import numpy as np

from gui.core.plan import BuildPlan, BuiltIds
from gui.core.world_port import Progress
from gui.errors import GuiError
from gui.planning import rehearsal_cache
from gui.planning.core_world import CoreWorld
from odin_common.errors import OdinError
from odin_common.limits import ResourceLimits
from odin_common.step_values import StepValues
from odin_common.world_parameters import WorldParameters



class _RehearsalWorld(CoreWorld):
    """A CoreWorld whose Set Step is checked as the node checks it (a CoreWorld of the
    planner takes the plan's step values as they are)."""

    def set_step(self, step=None, steps_per_cycle=None, cycle_time=None, rate=None):
        from virtual_world.core.step_values import resolve
        self._step_values, _ = resolve(self._step_values, step=step or 0.0,
                                       steps_per_cycle=steps_per_cycle or 0,
                                       cycle_time=cycle_time or 0.0, rate=rate or 0.0)
        return self._step_values


def rehearse(plan: BuildPlan, parameters: WorldParameters, step_values: StepValues,
             resources: ResourceLimits) -> None:
    """Builds every step of ``plan`` in a Core of this process that starts as the world does
    (its ``parameters``, ``step_values`` and ``resources``); raises GuiError naming the first
    step the Core refuses ("step k/n (label) ..."). ``plan`` is left as it was (the world IDs
    of the rehearsal are not recorded in it)."""
    world = _RehearsalWorld(parameters, resources, step_values)
    try:
        ids = BuiltIds()
        for k, step in enumerate(plan.steps, start=1):
            try:
                _check_request_size(step, resources)
                step.send(world, ids)
            except OdinError as error:
                raise GuiError(f"step {k}/{len(plan.steps)} ({step.label()}) would be "
                               f"refused: {_one_line(error)}") from None
    finally:
        world.close()


def _rehearse_once(plan: BuildPlan, parameters: WorldParameters, step_values: StepValues,
                   resources: ResourceLimits, plan_key: Optional[str]) -> None:
    """``rehearse``, unless the same plan was taken before by a Core that started as this
    world (``rehearsal_cache``); a plan taken is remembered."""
    world_key = rehearsal_cache.world_digest(parameters, step_values, resources)
    if rehearsal_cache.taken(plan_key, world_key):
        return
    rehearse(plan, parameters, step_values, resources)
    rehearsal_cache.remember(plan_key, world_key)


def _check_request_size(step, resources: ResourceLimits) -> None:
    """The node reads no message over its ``max_request_mb`` (it drops the connection, which
    a Core never sees): a step whose bodies' mesh arrays alone (float64 parameters, uint32
    indices: the bulk of its request) are larger is refused here. What the rest of a request
    adds (names, poses: bytes per body) can still tip one just under it over: the node then
    refuses it, and load_scene undoes the load."""
    size = sum(8 * np.size(shape.parameters) + 4 * np.size(shape.indices)
               for body in step.bodies for shape in getattr(body, "parts", (body,)))
    limit = resources.max_request_mb * 2 ** 20
    if size > limit:
        raise GuiError(f"its request holds {size:,} bytes of mesh arrays, more than the "
                       f"world reads in one message ({limit:,} bytes: max_request_mb "
                       f"{resources.max_request_mb})")


def warm_up() -> None:
    """Imports what a rehearsal's Core imports when it first meets a mesh (trimesh, for its
    mass: 0.5 s), so that a tool can do it while it waits for something else."""
    import trimesh  # noqa: F401
    import virtual_world.core  # noqa: F401


def load_scene(client, plan: BuildPlan, keep: bool = False,
               progress: Optional[Progress] = None, plan_key: Optional[str] = None) -> dict:
    """Builds ``plan`` in the world of ``client`` (a WorldClient) whole, after New Scene
    unless ``keep``, or changes nothing: rehearsed first (``rehearse``, unless the same plan
    was taken by a Core that started as this world: ``rehearsal_cache``; ``plan_key``: its
    ``plan_digest`` when the caller has it), sent only if every step was taken; a step the
    world still refuses is undone (``_undo``). Returns ``client.execute``'s answer (the
    world's IDs, robots, overlaps); raises GuiError, one line naming the problem and the
    step."""
    before = client.world()
    source = plan.problem.source
    try:
        _rehearse_once(plan, before.parameters, before.step_values,
                       _room(client.resource_limits(), before, keep),
                       plan_key or rehearsal_cache.plan_digest(plan))
    except OdinError as error:
        raise GuiError(f"{source}: {_one_line(error)}; nothing was sent: the world is "
                       "unchanged") from None
    if not keep:
        client.new_scene()
    ids, answered = BuiltIds(), [0]

    def counted(k: int, step, answer: str) -> None:
        answered[0] = k
        if progress is not None:
            progress(k, step, answer)

    try:
        return client.execute(plan, progress=counted, ids=ids)
    except OdinError as error:
        k = answered[0] + 1
        what = (f"step {k}/{len(plan.steps)} ({plan.steps[k - 1].label()})"
                if k <= len(plan.steps) else "declaring its robots (Set Robot)")
        raise GuiError(f"{source}: the world refused {what}, which the rehearsal took: "
                       f"{_one_line(error)}; {_undo(client, plan, before, ids, keep)}") from None


def _room(resources: ResourceLimits, before, keep: bool) -> ResourceLimits:
    """The limits the plan must fit: the world's, less the objects it holds when it keeps
    them (``before``: its Get World)."""
    if not keep:
        return resources
    room = resources.max_objects - len(before.objects)
    if room < 1:
        raise GuiError(f"the world holds {len(before.objects):,} objects, its limit "
                       f"(max_objects {resources.max_objects:,}): no room to add any")
    return dataclasses.replace(resources, max_objects=room)


def _undo(client, plan: BuildPlan, before, ids: BuiltIds, keep: bool) -> str:
    """Removes what a refused load built (everything, after its New Scene; its bodies, with
    their joints and motors, and its robots, with ``keep``), sets the world parameters and
    step values of ``before`` (Get World before the load) again and, if it was running,
    starts the world again; says what it did."""
    try:
        if keep:
            held = set(client.world().objects)
            for world_id in ids.bodies.values():
                if world_id in held and world_id not in before.objects:
                    client.remove_object(world_id)
        else:
            client.new_scene()
        kept = {robot.name for robot in before.robots}
        planned = {handle.name for handle in plan.robots}
        for robot in client.world().robots:
            if robot.name in planned and robot.name not in kept:
                client.remove_robot(robot.name)
        client.set_world(**before.parameters.as_dict())
        values = before.step_values
        client.set_step(step=values.step, steps_per_cycle=values.steps_per_cycle,
                        rate=values.rate)
        if before.simulating:       # a plan's first step pauses the world
            client.start()
    except OdinError as error:
        return f"undoing what it built failed too: {_one_line(error)}"
    if keep:
        return "what it built was removed: the scene is as it was"
    return "what it built was removed (the scene before it was cleared by its New Scene)"


def _one_line(error: BaseException) -> str:
    return " ".join(str(error).split())


__all__ = ["load_scene", "rehearse", "warm_up"]
