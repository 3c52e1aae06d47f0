"""The plan of one loaded problem: its instances in order, then its attachments, behind the
world settings and ground plane of Kautham's physics where it applies (ROS-free). What it
builds is told in ``gui.core.translate``'s docstring; a car's wheels are ``car``'s, a
fixed-base robot's base and chain drive ``chain``'s, a link's joint and motors ``joints``'.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Dict, List, Optional, Tuple

import numpy as np

from gui.core import inertia as inertia_rule
from gui.core.bodies import shape_to_body, shape_volume, with_surface
from gui.core.kautham import environment
from gui.core.kautham.problem import PHYSICS_PLANNERS
from gui.core.model import (CAR, FIXED_BASE, FREE_BODY, MOBILE, Instance, LinkModel, Problem,
                             warn_once)
from gui.core.plan import (HOLD, BodySpec, BuildPlan, EntityStep, HoldStep, JointStep, LinkBody,
                           ObjectStep, RobotHandle, StepSizeStep, WorldStep, body_step)
from gui.core.translate import car, chain
from gui.core.translate.joints import (fixed_joint, joint_motors, link_drive, link_joint,
                                       motor_kind)
from gui.core.world_settings import default_world, kautham_world
from gui.errors import ProblemError
from odin_common.defaults import SERVO_MAX_SPEED
from odin_common.interface import MotorKind, Shape as ShapeKind, default_motor_id
from odin_common.specs import (CompositeSpec, EntitySpec, JointSpec, ObjectSpec, Surface,
                               WORLD_SURFACE)

GROUND = "ground"
"""The ground plane's object ID (another name is taken if an instance has it)."""


LIGHTEST_LINK = 0.001
"""kg: the least a URDF robot link without ``<inertial>`` weighs (a tiny shape's volume at
``BuildDefaults.massless_density`` would make it thousands of times lighter than its
neighbours, which ODE's solvers handle badly)."""


@dataclass(frozen=True)
class BuildDefaults:
    """How a problem is built. ``ground``: Kautham's physics (its world settings, a ground
    plane) for every problem (True), none (False: Odin's default world settings, no ground
    plane), or where Kautham simulates the problem (None: ``Problem.physics``); every plan
    sets every world parameter and step value either way (``gui.core.world_settings``).
    ``start_at_query``: robots built at the query's start (True or None: where Kautham
    leaves a problem it loads; Home when there is no query) or at Home (False: as the
    thesis's tool built 2012 problems).
    ``hold_start``: robots' joints held by servos where they are built (``HoldStep``), or
    left to their motors at zero speed (False: as the thesis's experiments were run).
    ``link_mass``, ``massless_density``: what a link whose file gives no mass weighs
    (``_Planner._default_mass``).
    ``inertia``: "auto", "file" or "shape" (``gui.core.inertia``). ``max_contact_sink``: m,
    the deepest a body may rest in a contact the planner's CFM softens
    (``gui.core.world_settings``)."""
    link_mass: float = 1.0          # kg, a link or movable obstacle without a mass
    massless_density: float = 1000.0    # kg/m^3, a URDF robot link without <inertial>
    internal_collisions: bool = False
    ground: Optional[bool] = None
    start_at_query: Optional[bool] = None
    hold_start: bool = True
    inertia: str = inertia_rule.AUTO
    placeholder_factor: float = 10.0
    max_contact_sink: float = 0.01


def plan_problem(problem: Problem, defaults: BuildDefaults = BuildDefaults()) -> BuildPlan:
    """The plan that builds ``problem`` (``gui.core.translate``'s docstring)."""
    return _Planner(problem, defaults).plan()


class _Planner:
    """One plan: the problem's instances in order, then attachments."""

    def __init__(self, problem: Problem, defaults: BuildDefaults):
        self.problem, self.defaults = problem, defaults
        self.physics = problem.physics if defaults.ground is None else defaults.ground
        self.start_at_query = defaults.start_at_query is not False
        attached = {a.obstacle for a in problem.attachments}
        # bodies: movable obstacles (2012 .rob scenes), attached ones, and every current
        # obstacle under Kautham's physics (its ODE environment makes them all dynamic); in a
        # geometric problem Kautham never moves the others
        self.dynamic = {i.name for i in problem.obstacles
                        if i.movable or i.name in attached
                        or (self.physics and problem.format == "current")}
        # Kautham's controls place a free-flying or mobile robot's base (and a robot standing
        # as an obstacle, a 2012 .rob scene with joints, stays where it is put): without
        # Kautham's physics nothing else moves them, so their base is held (kinematic)
        self.hold_free_bases = not self.physics
        # a current problem's obstacle body (its URDF gives a mass: an object a task may
        # carry) stays where the problem puts it until a task attaches it: without Kautham's
        # physics only an attachment moves an obstacle (the thesis's 2012 movable scenes fall
        # and are pushed, as Odin always built them)
        self.hold_obstacles = not self.physics and problem.format == "current"
        self.attached = attached
        # Kautham's chain planner drives its chain's joints as PlanarChainEnvironment does,
        # its car planner sets its car's wheel axes as CarEnvironment does
        planned = PHYSICS_PLANNERS.get(problem.planner.name) if problem.physics else None
        self.chain_environment = planned == FIXED_BASE
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
        self._holds()
        # every world parameter and step value, whatever the world held before (issue 28)
        world = default_world()
        if self.physics:
            world, ignored = kautham_world(self.problem, self.masses,
                                           self.defaults.max_contact_sink)
            self.ignored.extend(ignored)
        front = [WorldStep(world.parameters, world.own_parameters),
                 StepSizeStep(world.step, world.steps_per_cycle, world.rate,
                              "step" in world.own)]
        if self.physics:
            front.append(ObjectStep(self._ground()))
        warn_once(self.ignored[len(self.problem.ignored):], "gui.core.translate")
        return BuildPlan(problem=self.problem, steps=front + self.steps, robots=self.handles,
                         world=world, physics=self.physics, ignored=self.ignored)

    def _ground(self) -> ObjectSpec:
        taken = {i.name for i in self.problem.instances}
        name, n = GROUND, 1
        while name in taken:
            n += 1
            name = f"{GROUND}_{n}"
        surface = car.GROUND_SURFACE if self.car_environment else WORLD_SURFACE
        return ObjectSpec(name=name, parameters=(), shape=ShapeKind.PLANE, geometry_only=True,
                          color=environment.GROUND_COLOR, surface=surface)

    # -- instances ----------------------------------------------------------------------------
    def _configuration(self, inst: Instance) -> Tuple[np.ndarray, np.ndarray]:
        """(base pose, joint values) the instance is built at."""
        if inst.role == "robot" and self.start_at_query and inst.start is not None:
            return inst.start.base_pose, np.asarray(inst.start.joints, dtype=float)
        return inst.base_pose, inst.model.home()

    def _instance(self, inst: Instance) -> None:
        base_pose, built_at = self._configuration(inst)
        static = inst.role == "obstacle" and inst.name not in self.dynamic
        specs, bodies = self._links(inst, base_pose, built_at, static)
        single = len(inst.model.links) == 1
        if static or (single and inst.role == "obstacle"):
            self.steps.extend(body_step(s) for s in specs)
            if not static and self.hold_obstacles and inst.name not in self.attached:
                self.steps.append(JointStep(f"{inst.name}/{HOLD}", inst.name,
                                            fixed_joint(specs[0].id, "")))
            return
        robot = inst.role == "robot"
        holding: List[JointStep] = []
        if robot and inst.kind == FIXED_BASE and not single:
            specs, holding = chain.hold_base(inst.name, specs, self.problem.format,
                                              self.physics)
        held = self.hold_free_bases and (not robot or inst.kind in (FREE_BODY, MOBILE))
        if held:
            specs = [dataclasses.replace(specs[0], fixed=True)] + specs[1:]
        self.steps.append(EntityStep(EntitySpec(
            name=inst.name,
            objects=tuple(s for s in specs if isinstance(s, ObjectSpec)),
            composites=tuple(s for s in specs if isinstance(s, CompositeSpec)),
            internal_collisions=self.defaults.internal_collisions)))
        handle = RobotHandle(inst, bodies, [], home=inst.model.home(), built_at=built_at,
                             base_pose=base_pose, kind=inst.kind, base_mass=specs[0].mass,
                             base_held=held)
        if not single:
            self.steps.extend(holding)
            self._joints(inst, handle, base_pose, built_at)
        if robot or not single:
            self.handles.append(handle)

    def _links(self, inst: Instance, base_pose: np.ndarray, built_at: np.ndarray,
               static: bool) -> Tuple[List[BodySpec], List[LinkBody]]:
        """The body spec of each of ``inst``'s links built at ``base_pose`` and ``built_at``,
        and where each link's body is (recorded for attachments)."""
        model = inst.model
        single = len(model.links) == 1
        specs, bodies = [], []
        for link, pose in zip(model.links, model.link_poses(base_pose, built_at)):
            name = inst.name if single else f"{inst.name}/{link.name}"
            if link.shape is None:
                raise ProblemError(f"link {link.name!r} of {inst.name!r} has no geometry (no "
                                   "<collision> or <visual> shape): Odin builds every link as "
                                   "a body with a shape; give it one (a small sphere will do)",
                                   link.source or None)
            mass = link.mass if link.mass is not None else self._default_mass(inst, link)
            spec, offset = shape_to_body(name, link.shape, pose, mass, static)
            if not static:
                spec = self._mass_properties(spec, link, name, mass, offset)
                self.masses.append((name, mass))
            specs.append(with_surface(spec, self._surface(inst, link, name)))
            bodies.append(LinkBody(spec.id, offset))
            self.link_bodies[(inst.name, link.name)] = bodies[-1]
        self.base_bodies[inst.name] = bodies[0]
        if not inst.collision:   # <Collision enabled="false">: the world never pairs it
            specs = [dataclasses.replace(s, no_collisions=True) for s in specs]
        return specs, bodies

    def _default_mass(self, inst: Instance, link: LinkModel) -> float:
        """kg, a link whose file gives no mass: a URDF robot's link without ``<inertial>``
        (massless to URDF and to Kautham, which no body can be) weighs its shape's volume at
        ``BuildDefaults.massless_density``; any other (a .rob link, an obstacle, a link
        without a shape) ``BuildDefaults.link_mass``, as Kautham's ODE environment gives an
        obstacle without a mass 1 kg."""
        if inst.role != "robot" or inst.model.kind != "urdf" or link.shape is None:
            return self.defaults.link_mass
        volume = shape_volume(link.shape)
        if volume <= 0:
            return self.defaults.link_mass
        return max(self.defaults.massless_density * volume, LIGHTEST_LINK)

    def _surface(self, inst: Instance, link: LinkModel, name: str) -> Surface:
        """The contact surface of ``inst``'s ``link`` (body ``name``): its URDF's, but for
        the friction of Kautham's car planner (``car.car_environment_surface``)."""
        if not self.car_environment:
            return link.surface
        surface, ignored = car.car_environment_surface(inst, link, name)
        if ignored is not None:
            self.ignored.append(ignored)
        return surface

    def _mass_properties(self, spec: BodySpec, link: LinkModel, name: str, mass: float,
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
        """A joint step per link but the base, then the motor steps of the movable ones."""
        model = inst.model
        frames = model.joint_frames(base_pose, built_at)
        value = dict(zip(model.movable_links(), built_at))
        bodies = handle.bodies
        motors, wheels = [], 0
        for i, link in enumerate(model.links):
            if link.parent is None:
                continue
            key = f"{inst.name}/{link.name}"
            parent_id, child_id = bodies[link.parent].body_id, bodies[i].body_id
            if not link.movable:
                self.steps.append(JointStep(key, inst.name, fixed_joint(parent_id, child_id)))
                continue
            if car.is_wheel(inst, link):
                steering, spin = car.wheel_axes(link, frames[i], base_pose, wheels,
                                                self.car_environment)
                joint = car.wheel_joint(frames[i], steering, spin, parent_id, child_id)
                kind, axis, wheels = MotorKind.ANGULAR, 1, wheels + 1   # the URDF's joint spins
            else:
                joint = link_joint(link, frames[i], value[i], parent_id, child_id)
                kind, axis = motor_kind(link), 0
            motors.extend(self._movable_joint(inst, link, handle, key, joint, kind, axis))
        self.steps.extend(motors)
        handle.motor_ids = [default_motor_id(j) for j in handle.joint_ids]

    def _movable_joint(self, inst: Instance, link: LinkModel, handle: RobotHandle, key: str,
                       joint: JointSpec, kind: MotorKind, axis: int) -> list:
        """Adds the joint's step and records it in ``handle``; returns its motor steps."""
        self.steps.append(JointStep(key, inst.name, joint, limits=link.limits))
        drive, ignored = link_drive(link, self.problem.physics)
        if ignored is not None:
            self.ignored.append(ignored)
        if self.chain_environment and inst.kind == FIXED_BASE:
            drive = chain.planar_chain_drive(drive)
        handle.joint_keys.append(key)
        handle.joint_ids.append(joint.default_id)
        handle.joint_axes.append(axis)
        handle.max_forces.append(drive.effort)
        handle.max_speeds.append(drive.speed)
        return joint_motors(key, inst.name, joint, drive, kind)

    def _holds(self) -> None:
        """A HoldStep per robot whose joints all have a driving motor: its servos hold it
        where it is built (a car's wheels are left to their motors at zero speed)."""
        if not self.defaults.hold_start:
            return
        for handle in self.handles:
            if (handle.instance.role != "robot" or handle.kind == CAR or not handle.joint_keys
                    or len(handle.motor_ids) != len(handle.joint_keys)):
                continue
            speeds = tuple(float(v) if v else SERVO_MAX_SPEED for v in handle.max_speeds)
            self.steps.append(HoldStep(handle.name, tuple(handle.joint_keys), speeds))

    # -- attachments ---------------------------------------------------------------------------
    def _attachments(self) -> None:
        """A FIXED joint between each attached obstacle's base and its link, as placed."""
        for a in self.problem.attachments:
            link = self.link_bodies[(a.robot, a.link)]
            obstacle = self.base_bodies[a.obstacle]
            self.steps.append(JointStep(f"{a.robot}/{a.link}+{a.obstacle}", a.robot,
                                        fixed_joint(link.body_id, obstacle.body_id)))
