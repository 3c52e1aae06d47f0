"""A loaded problem -> the VirtualWorld requests that build it, as plain data (ROS-free).

``plan_problem(problem)`` returns a ``gui.core.plan.BuildPlan`` (its steps, robot handles and
what they answer are told there).

How a problem maps to the world:
- Kautham's physics (``Problem.physics``: one of its ODE planners; ``BuildDefaults.ground``
  asks for it in any problem): first Set World and Set Step with what Kautham's ODE
  environment uses (``gui.core.world_settings``), then an infinite ground plane at z = 0
  (``GROUND``, static).
- A robot with joints -> one Build Entity (one object or composite per link, internal
  collisions off), then per link one Set Joint: revolute -> HINGE, prismatic -> SLIDER (anchor
  and axis from the joint frame where the robot is built, world frame; LO_STOP/HI_STOP from the
  limits, relative to the value the joint is built at), a non-movable link -> FIXED joint to
  its parent; a car's wheels -> HINGE2 with CarEnvironment's suspension (ERP 0.4 / CFM 0.8):
  for a car of Kautham's car planner CarEnvironment's world axes (steering about +z for the
  first two wheels, -z for the others, spin about +y, whatever the car's pose: a positive
  wheel speed rolls it toward world -x) and its contact friction by body kind
  (``environment.CAR_FRICTION``, the ground's too); for any other car axes from its own frame
  (steering about the base's up, opposite for the wheels ahead of its centre and the others;
  both reversed like a hinge's, so that a positive steering turns left and a positive wheel
  speed rolls the car along its +x). Then one Set Motor per movable joint
  (angular for hinges and hinge-2s, linear for sliders; zero speed, so the robot holds its
  pose; the joint's effort limit as its force limit, infinite without one; the chain of
  Kautham's chain planner gets PlanarChainEnvironment's 7 N m and 1 rad/s for every joint
  instead, whatever its URDF says), id "motor:" + joint id; a joint with friction gets a second
  motor at zero speed whose force limit is the friction ("friction:" + joint id), a joint
  with damping a third at zero speed, unlimited force and CFM 1 / damping, which makes ODE
  apply exactly -damping x the joint's rate ("damping:" + joint id); under Kautham's own
  physics (one of its ODE planners) no joint has either, as in its ODE environment.
- The base by the robot's kind (``gui.core.model``): FIXED_BASE -> in a 2012 problem a fixed
  (kinematic) body that never moves; in a current one a dynamic body held by a FIXED joint to
  the world (Kautham's chain); FREE_BODY, MOBILE, CAR -> a dynamic body, free.
- A robot is built at its start (the query's ``<Init>``) in current problems, at Home in 2012
  ones (``BuildDefaults.start_at_query``); ``RobotHandle.built_at`` keeps the joint values the
  world's joint readings are relative to.
- A robot made of one link (a bare shape or a one-link URDF) is a free-flying body: an entity
  of one object, no joint.
- A static obstacle -> Build Object/Composite with ``geometry_only``. A movable obstacle (a .rob
  scene, a URDF with masses, ``<Scene movable="true">``, any obstacle under Kautham's physics,
  an attached obstacle) -> bodies with masses; a multi-link one is built like a robot but its
  base is left free. ``<InitialAttachedObstacle>`` -> a FIXED joint between the link and the
  obstacle's (base) body, as they are placed.
- Shapes: a mesh -> mesh object (vertices in the link frame); one primitive -> primitive
  object whose body sits at the primitive's pose in the link; anything else -> a composite
  whose frame is the link frame (one part per primitive, one for the mesh), id ">p1>p2...".
- Masses: the file's mass, else ``BuildDefaults.link_mass`` (a .rob ``<Weight>`` is a planner
  weight, not a mass); a composite's mass is shared among its parts in proportion to their
  volumes. Inertia (``gui.core.inertia``): the URDF's tensor about its centre of mass where it
  is a rigid body's and plausible for the link's shape, the shape's at uniform density
  otherwise. Contact surfaces: the link's (URDF contact coefficients) on its object or parts.
- Names (thesis 8.3): links are "robot/link" (Kautham's own .cntr naming), one-link instances
  keep the instance name; instance names come from the robot's name or the obstacle's file
  name, numbered "_2", "_3"... on collision; composite parts are "name#k".
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Dict, NamedTuple, Optional, Tuple

import numpy as np

from gui.core import inertia as inertia_rule
from gui.core.kautham import environment
from gui.core.kautham.problem import PHYSICS_PLANNERS
from gui.core.kinematics import pose_to_position_quaternion
from gui.core.model import CAR, FIXED_BASE, REVOLUTE, Ignored, Instance, Problem, warn_once
from gui.core.plan import (BodySpec, BuildPlan, EntityStep, JointStep, LinkBody, MotorStep,
                           ObjectStep, RobotHandle, StepSizeStep, WorldStep, body_step)
from gui.core.shapes import Shape
from gui.core.world_settings import kautham_world
from odin_common.interface import (JointParameter, JointType, MotorKind, Shape as ShapeKind,
                                   default_motor_id)
from odin_common.specs import (CompositeSpec, EntitySpec, JointSpec, MotorSpec, ObjectSpec,
                               PartSpec, Surface, WORLD_SURFACE)
from odin_common.step_values import StepValues

GROUND = "ground"
"""The ground plane's object ID (another name is taken if an instance has it)."""


@dataclass(frozen=True)
class BuildDefaults:
    """How a problem is built. ``ground``: Kautham's physics (Set World, Set Step, a ground
    plane) for every problem (True), none (False), or where Kautham simulates the problem
    (None: ``Problem.physics``). ``start_at_query``: robots built at the query's start (True),
    at Home (False), or the start in current problems and Home in 2012 ones (None).
    ``inertia``: "auto", "file" or "shape" (``gui.core.inertia``). ``max_contact_sink``: m,
    the deepest a body may rest in a contact the planner's CFM softens
    (``gui.core.world_settings``)."""
    link_mass: float = 1.0          # kg, a link or movable obstacle without a mass
    internal_collisions: bool = False
    ground: Optional[bool] = None
    start_at_query: Optional[bool] = None
    inertia: str = inertia_rule.AUTO
    placeholder_factor: float = 10.0
    max_contact_sink: float = 0.01


def _volume(part_kind: str, parameters: tuple, vertices=None, triangles=None) -> float:
    if part_kind != "mesh":
        return inertia_rule.primitive_volume(part_kind, parameters)
    tri = vertices[triangles]
    signed = float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6)
    if abs(signed) > 0:
        return abs(signed)
    extent = vertices.max(0) - vertices.min(0)
    return float(np.prod(np.maximum(extent, 1e-6)))


def _flat(a) -> tuple:
    return tuple(float(v) for v in np.asarray(a, dtype=float).ravel())


def shape_to_body(name: str, shape: Shape, link_pose: np.ndarray, mass: float,
                  static: bool) -> Tuple[BodySpec, np.ndarray]:
    """The spec (object or composite) for a shape whose frame is at ``link_pose``, and the
    body's pose in that frame (identity but for a lone primitive)."""
    pieces = []
    if shape.mesh is not None:
        mesh = shape.mesh
        pieces.append(("mesh", np.ascontiguousarray(mesh.vertices, dtype=np.float64).ravel(),
                       np.ascontiguousarray(mesh.triangles, dtype=np.uint32).ravel(),
                       np.eye(4), mesh.color, _volume("mesh", (), mesh.vertices, mesh.triangles)))
    for prim in shape.primitives:
        pieces.append((prim.kind, tuple(prim.parameters), (), prim.pose, prim.color,
                       _volume(prim.kind, prim.parameters)))
    if len(pieces) == 1:
        kind, params, indices, offset, color, _ = pieces[0]
        position, quaternion = pose_to_position_quaternion(link_pose @ offset)
        spec = ObjectSpec(name=name, parameters=params, indices=indices, mass=mass,
                          position=position, orientation=quaternion, color=tuple(color),
                          geometry_only=static)
        return spec, offset
    total = sum(p[5] for p in pieces) or 1.0
    parts = []
    for k, (kind, params, indices, offset, color, volume) in enumerate(pieces):
        position, quaternion = pose_to_position_quaternion(offset)
        parts.append(PartSpec(name=f"{name}#{k}", parameters=params, indices=indices,
                              mass=max(mass * volume / total, mass * 1e-6),
                              position=position, orientation=quaternion, color=tuple(color)))
    position, quaternion = pose_to_position_quaternion(link_pose)
    return CompositeSpec(parts=tuple(parts), position=position, orientation=quaternion,
                         geometry_only=static), np.eye(4)


def _with_surface(spec: BodySpec, surface) -> BodySpec:
    """``spec`` with the link's contact surface on its object or on every part."""
    if not surface.is_set:
        return spec
    if isinstance(spec, ObjectSpec):
        return dataclasses.replace(spec, surface=surface)
    return dataclasses.replace(spec, parts=tuple(dataclasses.replace(p, surface=surface)
                                                 for p in spec.parts))


class _Drive(NamedTuple):
    """How a movable joint is driven and resisted: ``effort`` (N m or N) and ``speed`` (rad/s
    or m/s) limits, None where none; ``friction`` (N m or N) and ``damping`` (N m s/rad or
    N s/m), 0 for none."""
    effort: Optional[float]
    speed: Optional[float]
    friction: float
    damping: float


class _Planner:
    """One plan: the problem's instances in order, then attachments."""

    def __init__(self, problem: Problem, defaults: BuildDefaults):
        self.problem, self.defaults = problem, defaults
        self.physics = problem.physics if defaults.ground is None else defaults.ground
        start = defaults.start_at_query
        self.start_at_query = problem.format == "current" if start is None else start
        attached = {a.obstacle for a in problem.attachments}
        # bodies: movable obstacles, attached ones, and every current obstacle under
        # Kautham's physics (its ODE environment makes them all dynamic)
        self.dynamic = {i.name for i in problem.obstacles
                        if i.movable or i.name in attached
                        or (self.physics and problem.format == "current")}
        # Kautham's chain planner drives its chain's joints as PlanarChainEnvironment does,
        # its car planner sets its car's wheel axes as CarEnvironment does
        planned = PHYSICS_PLANNERS.get(problem.planner.name) if problem.physics else None
        self.chain_drive = planned == FIXED_BASE
        self.car_environment = planned == CAR
        self.steps: list = []
        self.handles: list = []
        self.ignored: list = list(problem.ignored)
        self.base_bodies: Dict[str, LinkBody] = {}     # instance name -> its base's body
        self.link_bodies: Dict[Tuple[str, str], LinkBody] = {}
        self.masses: list = []                          # (body ID, kg) of dynamic bodies

    def plan(self) -> BuildPlan:
        for inst in self.problem.instances:
            self._instance(inst)
        self._attachments()
        world = None
        front: list = []
        if self.physics:
            world, ignored = kautham_world(self.problem, self.masses, StepValues().step,
                                           self.defaults.max_contact_sink)
            self.ignored.extend(ignored)
            front.append(WorldStep(world.parameters))
            if world.step is not None:
                front.append(StepSizeStep(world.step, world.steps_per_cycle, world.rate))
            front.append(ObjectStep(self._ground()))
        warn_once(self.ignored[len(self.problem.ignored):], "gui.core.build")
        return BuildPlan(problem=self.problem, steps=front + self.steps, robots=self.handles,
                         world=world, ignored=self.ignored)

    def _ground(self) -> ObjectSpec:
        taken = {i.name for i in self.problem.instances}
        name, n = GROUND, 1
        while name in taken:
            n += 1
            name = f"{GROUND}_{n}"
        surface = Surface(friction=environment.CAR_FRICTION["ground"]) \
            if self.car_environment else WORLD_SURFACE
        return ObjectSpec(name=name, parameters=(), shape=ShapeKind.PLANE, geometry_only=True,
                          color=environment.GROUND_COLOR, surface=surface)

    # -- instances ----------------------------------------------------------------------------
    def _configuration(self, inst: Instance) -> Tuple[np.ndarray, np.ndarray]:
        """(base pose, joint values) the instance is built at."""
        model = inst.model
        if inst.role == "robot" and self.start_at_query and inst.start is not None:
            return inst.start.base_pose, np.asarray(inst.start.joints, dtype=float)
        return inst.base_pose, model.home()

    def _instance(self, inst: Instance) -> None:
        model = inst.model
        base_pose, built_at = self._configuration(inst)
        poses = model.link_poses(base_pose, built_at)
        static = inst.role == "obstacle" and inst.name not in self.dynamic
        single = len(model.links) == 1
        specs, bodies = [], []
        for link, pose in zip(model.links, poses):
            name = inst.name if single else f"{inst.name}/{link.name}"
            mass = link.mass if link.mass is not None else self.defaults.link_mass
            spec, offset = shape_to_body(name, link.shape, pose, mass, static)
            if not static:
                spec = self._mass_properties(spec, link, name, mass, offset)
                self.masses.append((name, mass))
            specs.append(_with_surface(spec, self._surface(inst, link, name)))
            bodies.append(LinkBody(spec.id, offset))
            self.link_bodies[(inst.name, link.name)] = bodies[-1]
        self.base_bodies[inst.name] = bodies[0]
        if not inst.collision:   # <Collision enabled="false">: the world never pairs it
            specs = [dataclasses.replace(s, no_collisions=True) for s in specs]
        if static or (single and inst.role == "obstacle"):
            self.steps.extend(body_step(s) for s in specs)
            return
        robot = inst.role == "robot"
        held_by_joint = robot and inst.kind == FIXED_BASE and not single \
            and self.problem.format == "current"
        if robot and inst.kind == FIXED_BASE and not single and not held_by_joint:
            # A 2012 robot's base is a fixed (kinematic) body, as Odin always built them: it
            # never moves, whatever the motors push.
            specs[0] = dataclasses.replace(specs[0], fixed=True)
        self.steps.append(EntityStep(EntitySpec(
            name=inst.name,
            objects=tuple(s for s in specs if isinstance(s, ObjectSpec)),
            composites=tuple(s for s in specs if isinstance(s, CompositeSpec)),
            internal_collisions=self.defaults.internal_collisions)))
        handle = RobotHandle(inst, bodies, [], home=model.home(), built_at=built_at,
                             base_pose=base_pose, kind=inst.kind, base_mass=specs[0].mass)
        if not single:
            if held_by_joint:   # Kautham's chain: the base held to the world by a fixed joint
                self.steps.append(JointStep(f"{inst.name}/<base>", inst.name, JointSpec(
                    type=JointType.FIXED, body1=bodies[0].body_id, body2="")))
            self._joints(inst, handle, base_pose, built_at)
        if robot or not single:
            self.handles.append(handle)

    def _surface(self, inst: Instance, link, name: str) -> Surface:
        """The contact surface of ``inst``'s ``link`` (body ``name``): its URDF's, with the
        friction Kautham's car environment gives the body's kind in its problems
        (``environment.CAR_FRICTION``; a URDF friction it overrides is listed as ignored)."""
        if not self.car_environment:
            return link.surface
        kind = "robot" if inst.role == "robot" else \
            "manipulable" if inst.name in environment.MANIPULABLE else "fixed"
        if link.surface.friction is not None:
            self.ignored.append(Ignored(
                link.source, link.line, f'contact friction {link.surface.friction:g} of '
                f'{name}', "Kautham's car environment sets every contact's friction "
                f"({kind}: {environment.CAR_FRICTION[kind]:g})"))
        return dataclasses.replace(link.surface, friction=environment.CAR_FRICTION[kind])

    def _mass_properties(self, spec: BodySpec, link, name: str, mass: float,
                         offset: np.ndarray) -> BodySpec:
        given, ignored = inertia_rule.choose(link, name, mass, offset, self.defaults.inertia,
                                             self.defaults.placeholder_factor)
        if ignored is not None:
            self.ignored.append(ignored)
        if given is None:
            return spec
        return dataclasses.replace(spec, inertia=given.inertia,
                                   center_of_mass=given.center_of_mass)

    # -- joints and motors ---------------------------------------------------------------------
    def _joints(self, inst: Instance, handle: RobotHandle, base_pose: np.ndarray,
                built_at: np.ndarray) -> None:
        model = inst.model
        frames = model.joint_frames(base_pose, built_at)
        value = dict(zip(model.movable_links(), built_at))
        bodies = handle.bodies
        motors, wheels = [], 0
        for i, link in enumerate(model.links):
            if link.parent is None:
                continue
            key = f"{inst.name}/{link.name}"
            parent_id = bodies[link.parent].body_id
            if not link.movable:
                self.steps.append(JointStep(key, inst.name, JointSpec(
                    type=JointType.FIXED, body1=parent_id, body2=bodies[i].body_id)))
                continue
            frame = frames[i]
            if inst.kind == CAR and link.parent == 0 and link.joint == REVOLUTE:
                steering, spin = self._wheel_axes(link, frame, base_pose, wheels)
                joint = _wheel(frame, steering, spin, parent_id, bodies[i].body_id)
                motor_kind, wheels = MotorKind.ANGULAR, wheels + 1
                handle.joint_axes.append(1)         # the URDF's wheel joint is the spin
            else:
                joint = self._joint(link, frame, value[i], parent_id, bodies[i].body_id)
                motor_kind = MotorKind.ANGULAR if link.joint == REVOLUTE else MotorKind.LINEAR
                handle.joint_axes.append(0)
            self.steps.append(JointStep(key, inst.name, joint, limits=link.limits))
            handle.joint_keys.append(key)
            handle.joint_ids.append(joint.default_id)
            drive = self._drive(inst, link)
            handle.max_forces.append(drive.effort)
            handle.max_speeds.append(drive.speed)
            motors.extend(self._motors(key, inst.name, joint, drive, motor_kind))
        self.steps.extend(motors)
        handle.motor_ids = [default_motor_id(j) for j in handle.joint_ids]

    @staticmethod
    def _joint(link, frame: np.ndarray, value: float, parent_id: str, child_id: str
               ) -> JointSpec:
        # ODE measures a hinge's angle (a slider's position) as body1's motion relative to
        # body2; the parent is body1, so the axis is reversed: the world's joint value, its
        # stops and its motor's goal speed then all have the sign of Kautham's joint value.
        axis = -(frame[:3, :3] @ link.axis)
        params = ()
        if link.limits is not None:
            params = ((JointParameter.LO_STOP, 1, float(link.limits[0] - value)),
                      (JointParameter.HI_STOP, 1, float(link.limits[1] - value)))
        return JointSpec(type=JointType.HINGE if link.joint == REVOLUTE else JointType.SLIDER,
                         body1=parent_id, body2=child_id, anchor=_flat(frame[:3, 3]),
                         axis1=_flat(axis), parameters=params)

    def _wheel_axes(self, link, frame: np.ndarray, base_pose: np.ndarray, index: int
                    ) -> Tuple[np.ndarray, np.ndarray]:
        """(steering axis, spin axis), world frame, of the ``index``-th wheel of a car (in its
        link order), as its hinge-2 is sent (module docstring).

        For Kautham's car planner, CarEnvironment's: it sets world axes whatever the car's
        pose or URDF (steering about +z for the first two wheels, -z for the others, spin
        about +y), so a positive wheel speed turns the chassis about +y relative to its wheels
        and rolls the car toward world -x. Otherwise axes the car's own frame gives: steering
        along the base's z, opposite for the wheels ahead of the base's origin along its x and
        for the others (the rear wheels steer against the front ones, as Kautham's four do);
        spin about the wheel joint's axis; both reversed, as a robot's hinges are (a
        hinge-2's angles and rates are body1's turn relative to body2), so a positive
        steering turns the front wheels left (counter-clockwise seen from above) and a
        positive wheel speed turns a wheel about its joint's axis (a car whose wheels turn
        about its y rolls along its +x)."""
        if self.car_environment:
            return np.array((0.0, 0.0, 1.0 if index < 2 else -1.0)), np.array((0.0, 1.0, 0.0))
        ahead = (np.linalg.inv(base_pose) @ np.append(frame[:3, 3], 1.0))[0] > 0.0
        return base_pose[:3, 2] * (-1.0 if ahead else 1.0), -(frame[:3, :3] @ link.axis)

    def _drive(self, inst: Instance, link) -> "_Drive":
        """How a movable joint is driven and resisted: its URDF's limits and ``<dynamics>``;
        under Kautham's own physics no ``<dynamics>`` (its ODE environment never reads it;
        warned), and for the chain of Kautham's chain planner the limits PlanarChainEnvironment
        drives it with, whatever its URDF's."""
        effort, speed, friction, damping = link.effort, link.velocity, link.friction, \
            link.damping
        if self.problem.physics and (friction > 0 or damping > 0):
            self.ignored.append(Ignored(
                link.source, link.line, f'<dynamics> of joint "{link.name}"',
                "Kautham's ODE environment applies no joint friction or damping"))
            friction = damping = 0.0
        if self.chain_drive and inst.kind == FIXED_BASE:
            effort, speed = environment.CHAIN_JOINT_TORQUE, environment.CHAIN_JOINT_SPEED
        return _Drive(effort, speed, friction, damping)

    @staticmethod
    def _motors(key: str, owner: str, joint: JointSpec, drive: "_Drive",
                kind: MotorKind) -> list:
        """The joint's driving motor (``drive.effort`` as its force limit), and the motors
        that give it its friction and damping."""
        axes = 2 if joint.type == JointType.HINGE2 else 1
        forces = (drive.effort,) * axes if drive.effort else ()
        out = [MotorStep(key, owner, MotorSpec(joint=joint.default_id, kind=kind,
                                               max_forces=forces))]
        if drive.friction > 0:
            out.append(MotorStep(key, owner, MotorSpec(
                joint=joint.default_id, kind=kind, max_forces=(drive.friction,) * axes,
                id=f"friction:{joint.default_id}"), purpose="friction"))
        if drive.damping > 0:
            # a motor at zero speed whose constraint has CFM c gives a force -(rate) / c
            # (ODE solves J v = goal - CFM lambda): viscous damping of 1 / c
            out.append(MotorStep(key, owner, MotorSpec(
                joint=joint.default_id, kind=kind, id=f"damping:{joint.default_id}"),
                purpose="damping", parameters=tuple(
                    (JointParameter.CFM, axis, 1.0 / drive.damping)
                    for axis in range(1, axes + 1))))
        return out

    # -- attachments ---------------------------------------------------------------------------
    def _attachments(self) -> None:
        for a in self.problem.attachments:
            link = self.link_bodies[(a.robot, a.link)]
            obstacle = self.base_bodies[a.obstacle]
            self.steps.append(JointStep(f"{a.robot}/{a.link}+{a.obstacle}", a.robot, JointSpec(
                type=JointType.FIXED, body1=link.body_id, body2=obstacle.body_id)))


def _wheel(frame: np.ndarray, steering: np.ndarray, spin: np.ndarray, parent_id: str,
           child_id: str) -> JointSpec:
    """A car's wheel on a hinge-2 at the wheel joint's origin: the chassis body1, the axes
    (world frame) as given, CarEnvironment's soft suspension along the steering axis."""
    return JointSpec(type=JointType.HINGE2, body1=parent_id, body2=child_id,
                     anchor=_flat(frame[:3, 3]), axis1=_flat(steering), axis2=_flat(spin),
                     parameters=((JointParameter.SUSPENSION_ERP, 1, environment.SUSPENSION_ERP),
                                 (JointParameter.SUSPENSION_CFM, 1, environment.SUSPENSION_CFM)))


def plan_problem(problem: Problem, defaults: BuildDefaults = BuildDefaults()) -> BuildPlan:
    """The plan that builds ``problem`` (module docstring)."""
    return _Planner(problem, defaults).plan()
