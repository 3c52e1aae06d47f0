"""Set Velocity's and Set Servo's rules over a scene: objects' velocities, motors' goal speeds
and servos, and the drive of their joints.

Both requests give their per-axis lists flat, one value per motor axis in the motors' order;
the split per motor is a rule of the world, so it is here, once, for the Portal and for a Core
driven in process alike. Everything is checked before anything changes (core.objects checks
the velocities, core.motors the goals and servos, core.kinematic the drive).
"""
from __future__ import annotations

from typing import Dict, Mapping, Sequence, Tuple

from odin_common.interface import ServoDrive
from odin_common.limits import shown
from virtual_world.core import kinematic, motors, objects
from virtual_world.core.scene import Scene
from virtual_world.errors import InvalidArgument

#: Set Servo's per-axis lists, in the request's order; ``targets`` is always given
SERVO_LISTS = ("targets", "rates", "gains", "max_speeds", "max_forces")


def set_velocity(scene: Scene, object_id: str, linear, angular, motor_ids: Sequence[str],
                 velocities: Sequence[float]) -> None:
    """Set Velocity (Core.set_velocity): the object's velocities (None: kept) and the motors'
    goal speeds from one flat list, all checked before any is set."""
    if len(motor_ids) == 0 and not object_id:
        raise InvalidArgument("nothing to set: give an object or motors")
    if object_id and linear is None and angular is None:
        raise InvalidArgument(f"object {shown(object_id)} given without set_linear or "
                              "set_angular")
    if object_id:
        scene.body_object(object_id, "set_velocity")
        linear, angular = objects.check_velocities(scene, linear, angular)
    goals = motors.split_per_axis(scene, motor_ids, velocities) if len(motor_ids) else {}
    motors.set_velocities(scene, goals)
    if object_id:
        objects.set_velocity(scene, object_id, linear, angular)


def split_servo_lists(scene: Scene, motor_ids: Sequence[str],
                      lists: Mapping[str, Sequence[float]]
                      ) -> Dict[str, Dict[str, Tuple[float, ...]]]:
    """{motor id: {list name: its values}} from Set Servo's flat ``lists`` (SERVO_LISTS ->
    one value per motor axis, in the motors' order): ``targets`` always split, each other list
    only when non-empty (empty: not given, the servo's default). Unknown motors and lists of
    the wrong length raise."""
    servos = {motor_id: {} for motor_id in motor_ids}
    for name in SERVO_LISTS:
        values = list(lists.get(name, ()))
        if name == "targets" or values:
            for motor_id, split in motors.split_per_axis(scene, motor_ids, values,
                                                         name).items():
                servos[motor_id][name] = split
    return servos


def set_servo(scene: Scene, motor_ids: Sequence[str], lists: Mapping[str, Sequence[float]],
              drive: int = ServoDrive.UNCHANGED) -> None:
    """Servo mode for the motors from Set Servo's flat ``lists`` (split_servo_lists), and
    ``drive`` (ServoDrive) for their joints; all checked before anything changes."""
    servos = split_servo_lists(scene, list(motor_ids), lists)
    links = kinematic.plan(scene, list(servos), drive)
    motors.set_servos(scene, servos)
    if links is not None:
        kinematic.install(scene, links)


def release_servos(scene: Scene, motor_ids: Sequence[str],
                   drive: int = ServoDrive.UNCHANGED) -> None:
    """Motors back from servo mode to speed goals, at zero; ``drive`` as set_servo's."""
    for motor_id in motor_ids:
        scene.motor(motor_id)
    links = kinematic.plan(scene, motor_ids, drive)
    motors.release_servos(scene, motor_ids)
    if links is not None:
        kinematic.install(scene, links)


def set_drive(scene: Scene, motor_ids: Sequence[str], drive: int) -> None:
    """The drive (ServoDrive) of the motors' joints alone, all or nothing."""
    links = kinematic.plan(scene, motor_ids, drive)
    if links is not None:
        kinematic.install(scene, links)
