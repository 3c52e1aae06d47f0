"""The kinematic drive: joints whose links follow their motors' commanded speeds exactly.

Servos and speed goals drive a joint through its motor, which pushes under its maximum force:
the thesis's dynamic motors, the default. A position-controlled industrial arm instead follows
its path exactly and pushes what it meets. Set Servo's `drive` KINEMATIC (`Core.set_drive`,
`WorldClient.set_drive`) gives that to the listed motors' joints, hinges or sliders driven on
their own axis:

- each joint's value moves at exactly the speed its motor commands, step by step: the servo's
  clamp(rate + gain (target - q), +-max_speed), or a Set Velocity goal; the motor's force limit
  no longer applies;
- the joint's link (the body beyond it) becomes an ODE kinematic body. Before every step, parents
  first, the C loop (`odin_kinematic.c`) computes by forward kinematics where the link is at the
  step's end (its pose relative to its parent's, turned about or moved along the joint's axis,
  on the parent's pose at the step's end) and gives the body the velocities that carry it there
  (ODE's finite rotation: exact to rounding). Velocities rather than poses, so that contacts and
  the joints to dynamic bodies see the motion and nothing is teleported; each step starts from
  the present poses alone, so a snapshot or a state vector puts a driven robot back bit for bit;
- a link is infinitely heavy for everything else: what is in its way is pushed, however heavy;
  a link that would leave the world's extent (world parameter world_extent) stops at its edge;
- ODE leaves every joint and motor between two kinematic bodies, or a kinematic body and the
  world, out of its LCP: an arm under the drive costs the solver nothing. A joint between a link
  and a dynamic body stays in the LCP, the link's side moving as commanded (a finger on a
  kinematic palm). Under the contact policy a link gets contacts with dynamic bodies only (none
  could act on static geometry, fixed objects or other links); while it moves, its pairs with
  those are still collided on the steps that record pairs, and reported, without contacts;
- the links hang from what never moves: each joint's other body must be the world, a fixed
  object or the link of another kinematic joint (a chain is driven from its base outwards). A
  request that would leave a link without such a parent, a joint of another type or a motor not
  on its joint's axis is refused and changes nothing;
- DYNAMIC gives the joints back to their motors (the link's mass back, its velocity kept);
  removing a motor, its joint or one of its objects does so for its link and every link beyond
  it. Set Position may move links: the drive carries on from where they are put.

``scene.kinematic`` maps each kinematic motor to its link, parents first.
"""
from __future__ import annotations

from typing import Dict, Iterable, Optional, Sequence

from odin_common.interface import JointType, ServoDrive
from odin_common.limits import shown
from virtual_world.core import guard
from virtual_world.core.scene import Scene
from virtual_world.errors import InvalidArgument, Unsupported
from virtual_world.ode import bodies
from virtual_world.ode import joints as ode_joints

#: joint types the drive moves (one value each: an angle or a position)
DRIVEN_TYPES = (JointType.HINGE, JointType.SLIDER)


def plan(scene: Scene, motor_ids: Sequence[str], drive: int) -> Optional[Dict[str, str]]:
    """The links ({motor id: link}, parents first) once ``drive`` (ServoDrive) is given to the
    motors' joints: KINEMATIC adds them to the drive, DYNAMIC takes them out; None for
    UNCHANGED. Checks everything, changes nothing (``install`` applies it)."""
    if isinstance(drive, bool) or drive not in set(ServoDrive):
        raise InvalidArgument(f"drive {shown(drive)} is not UNCHANGED (0), DYNAMIC (1) or "
                              "KINEMATIC (2)")
    drive = ServoDrive(drive)
    if drive == ServoDrive.UNCHANGED:
        return None
    for motor_id in motor_ids:
        _check_drivable(scene, motor_id)
    wanted = list(scene.kinematic)
    if drive == ServoDrive.KINEMATIC:
        wanted += [m for m in motor_ids if m not in scene.kinematic]
    else:
        leaving = set(motor_ids)
        wanted = [m for m in wanted if m not in leaving]
    return links_of(scene, wanted)


def _check_drivable(scene: Scene, motor_id: str) -> None:
    motor = scene.motor(motor_id)
    joint = scene.joints.get(motor.joint) if motor.joint else None
    if joint is None or not motor.on_joint_axes or joint.type not in DRIVEN_TYPES:
        raise Unsupported(f"motor {shown(motor_id)} cannot take the kinematic drive: it must be "
                          "made on a hinge or a slider with the joint's own axis")


def links_of(scene: Scene, motor_ids: Iterable[str]) -> Dict[str, str]:
    """{motor id: its link}, parents first: each joint's link is its body whose other body is
    held (the world, a fixed object or an earlier link). Refuses a set that is no such forest."""
    pending = list(dict.fromkeys(motor_ids))
    driver: Dict[str, str] = {}             # joint id -> the motor that drives it
    for motor_id in pending:
        joint_id = scene.motors[motor_id].joint
        if joint_id in driver:
            raise InvalidArgument(f"motors {shown(driver[joint_id])} and {shown(motor_id)} both "
                                  f"drive joint {shown(joint_id)}: one motor drives a joint "
                                  "kinematically")
        driver[joint_id] = motor_id
    links: Dict[str, str] = {}
    held = {o for o, obj in scene.objects.items() if obj.fixed}
    while pending:
        progress = []
        for motor_id in pending:
            joint = scene.joints[scene.motors[motor_id].joint]
            free = [b for b in joint.bodies if b and b not in held]
            if len(free) != 1:      # both held, or neither (yet)
                continue
            if free[0] in scene.parked:
                raise InvalidArgument(f"motor {shown(motor_id)}: its link {shown(free[0])} is "
                                      "parked by the divergence guard")
            links[motor_id] = free[0]
            held.add(free[0])
            progress.append(motor_id)
        if not progress:
            joint_id = scene.motors[pending[0]].joint
            bodies_ = scene.joints[joint_id].bodies
            raise InvalidArgument(
                f"motor {shown(pending[0])}: its joint {shown(joint_id)} between "
                f"{shown(bodies_[0] or 'world')}"
                f" and {shown(bodies_[1] or 'world')} needs exactly one body held by the world, a "
                "fixed object or a kinematic link (drive the joints between it and the world "
                "kinematically too)")
        pending = [m for m in pending if m not in links]
    return links


def install(scene: Scene, links: Dict[str, str]) -> None:
    """Makes exactly ``links`` ({motor id: link}, parents first) kinematic and hands C the
    array; the rest dynamic again. Nothing to do when they already are (a snapshot put back,
    every propagation, which planners run by the thousand)."""
    if dict(links) == scene.kinematic:
        return
    now = set(links.values())
    for object_id in set(scene.kinematic.values()) - now:
        bodies.set_kinematic_link(scene.objects[object_id].body.ptr, False)
    for object_id in now - set(scene.kinematic.values()):
        bodies.set_kinematic_link(scene.objects[object_id].body.ptr, True)
    scene.kinematic = dict(links)
    refresh(scene)
    guard.refresh(scene)


def refresh(scene: Scene) -> None:
    """Hands C the links with their motors' present slots (after the motor goals were
    rebuilt); first forgets each link whose motor, joint or parent link is gone."""
    kept: Dict[str, str] = {}
    for motor_id, object_id in scene.kinematic.items():
        motor = scene.motors.get(motor_id)
        joint = scene.joints.get(motor.joint) if motor is not None else None
        parent = "" if joint is None else next((b for b in joint.bodies if b != object_id), "")
        held = parent == "" or parent in kept.values() or (
            parent in scene.objects and scene.objects[parent].fixed)
        if joint is not None and object_id in scene.objects and held:
            kept[motor_id] = object_id
    for object_id in set(scene.kinematic.values()) - set(kept.values()):
        if object_id in scene.objects:
            bodies.set_kinematic_link(scene.objects[object_id].body.ptr, False)
    changed = len(kept) != len(scene.kinematic)
    scene.kinematic = kept
    index = {object_id: k for k, object_id in enumerate(kept.values())}
    rows = []
    for motor_id, object_id in kept.items():
        joint = scene.joints[scene.motors[motor_id].joint]
        parent = next((b for b in joint.bodies if b != object_id), "")
        rows.append((scene.objects[object_id].body.ptr,
                     scene.objects[parent].body.ptr if parent else None,
                     index.get(parent, -1), scene.motor_slots[motor_id], joint.owner.ptr,
                     ode_joints.ODE_JOINT_TYPE[joint.type]))
    scene.c.set_kinematic_links(rows)
    if changed:
        guard.refresh(scene)


def kinematic_objects(scene: Scene) -> list:
    """The objects the kinematic drive moves, parents first."""
    return list(scene.kinematic.values())
