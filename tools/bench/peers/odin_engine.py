"""The peers' scenes (scenes.py) in Odin's Core, with its defaults (the auto solver: dWorldStep
on the arm's and the grasp's articulated islands, QuickStep of 20 iterations on the spheres'
contacts; sweep and prune, 3 contacts a pair, mu 1): the plane a static PLANE geometry, the spheres
objects, the arm's links capsules on hinges held by servos (Set Servo: position targets,
motors of MOTOR_MAX_TORQUE), the fingers boxes on sliders squeezing with FINGER_FORCE."""
from __future__ import annotations

import math

import scenes
from measure import rotate
from odin_common.interface import JointType, MotorKind, Shape, Solver
from virtual_world.core import Core, JointSpec, MotorSpec, ObjectSpec, WorldParameters

#: the capsule's z turned onto x: (w, x, y, z), a quarter turn about y
Z_ONTO_X = (math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0)


class Sim:
    def __init__(self, scene: str, parameters: WorldParameters = None):
        """``scene`` (scenes.SCENES) in a Core of ``parameters`` (Odin's defaults if None)."""
        self.core = Core(parameters)
        self.bodies = 0
        self.settings = {"solver": Solver(self.core.world_parameters.solver).name,
                         "iterations": self.core.world_parameters.quickstep_iterations}
        if scene.startswith(("spheres", "pile", "rest")):
            self._spheres(scene)
        else:
            self._arm()
            if scene == "grasp":
                self._hand()

    def _spheres(self, scene: str) -> None:
        self.core.build_object(ObjectSpec("ground", [], shape=Shape.PLANE, geometry_only=True))
        for k, (centre, sides) in enumerate(scenes.walls(scene)):
            self.core.build_object(ObjectSpec(f"wall{k}", list(sides), position=centre,
                                              geometry_only=True))
        self.spheres = []
        for i, position in enumerate(scenes.sphere_positions(scene)):
            self.core.build_object(ObjectSpec(f"s{i}", [scenes.RADIUS], mass=scenes.SPHERE_MASS,
                                              position=position))
            self.spheres.append(f"s{i}")
        self.bodies = len(self.spheres)

    def _arm(self) -> None:
        core, servos = self.core, []
        parent = ""
        for k, (anchor, axis, start, end, mass) in enumerate(scenes.links()):
            length = math.dist(start, end)
            centre = tuple((a + b) / 2 for a, b in zip(start, end))
            vertical = abs(end[2] - start[2]) > 1e-9
            core.build_object(ObjectSpec(f"link{k}", [scenes.LINK_RADIUS, length], mass=mass,
                                         position=centre, shape=Shape.CAPSULE,
                                         orientation=(1, 0, 0, 0) if vertical else Z_ONTO_X))
            joint = core.add_joint(JointSpec(JointType.HINGE, f"link{k}", parent, anchor=anchor,
                                             axis1=axis))
            motor = core.add_motor(MotorSpec(joint=joint, max_forces=[scenes.MOTOR_MAX_TORQUE]))
            servos.append(motor)
            parent = f"link{k}"
        core.set_servo(servos, [0.0] * len(servos))
        self.bodies = 7
        self._flange_local = (scenes.FLANGE[0] - centre[0], 0.0, 0.0)   # in link6's frame: x
        self._flange_local = rotate((Z_ONTO_X[0], 0, -Z_ONTO_X[2], 0), self._flange_local)

    def _hand(self) -> None:
        core = self.core
        centre, sides, mass = scenes.PALM
        core.build_object(ObjectSpec("palm", list(sides), mass=mass, position=centre))
        core.add_joint(JointSpec(JointType.FIXED, "palm", "link6"))
        core.build_object(ObjectSpec("can", [scenes.CAN_RADIUS, scenes.CAN_LENGTH],
                                     mass=scenes.CAN_MASS, position=scenes.CAN))
        fingers = []
        for k, (position, direction) in enumerate(scenes.fingers()):
            core.build_object(ObjectSpec(f"finger{k}", list(scenes.FINGER_SIDES),
                                         mass=scenes.FINGER_MASS, position=position))
            joint = core.add_joint(JointSpec(JointType.SLIDER, f"finger{k}", "palm",
                                             axis1=direction))
            motor = core.add_motor(MotorSpec(joint=joint, kind=MotorKind.LINEAR,
                                             max_forces=[scenes.FINGER_FORCE]))
            fingers.append(motor)
        core.set_velocity(motors=fingers, velocities=[scenes.FINGER_SPEED] * len(fingers))
        self.bodies = 11

    def step(self, n: int) -> None:
        self.core.step(scenes.STEP, n)

    def sphere_positions(self):
        names, positions, _ = self.core.poses()
        row = {name: k for k, name in enumerate(names)}
        return [tuple(map(float, positions[row[name]])) for name in self.spheres]

    def tip(self):
        position, quaternion, _, _ = self.core.body_state("link6")
        offset = rotate(tuple(map(float, quaternion)), self._flange_local)
        return tuple(float(p) + o for p, o in zip(position, offset))

    def can(self):
        return tuple(map(float, self.core.body_state("can")[0]))


def build(scene: str) -> Sim:
    return Sim(scene)
