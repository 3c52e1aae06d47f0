"""The peers' scenes (scenes.py) in PyBullet (Bullet 3), set up as its quickstart guide
recommends: a DIRECT (no GUI) client, setTimeStep, its default solver (sequential impulse, 50
iterations), lateral friction 1 like Odin's (Bullet's default is 0.5). The arm is one
multibody (Featherstone, minimal coordinates) held by POSITION_CONTROL motors of
MOTOR_MAX_TORQUE; the hand's palm is a fixed link, the fingers prismatic links driven by
VELOCITY_CONTROL with FINGER_FORCE; bodies are made in one createMultiBody call
(batchPositions) where they can be."""
from __future__ import annotations

import math

import pybullet as p

import scenes

#: capsule's z turned onto x: (x, y, z, w) as PyBullet takes quaternions
Z_ONTO_X_XYZW = (0.0, math.sin(math.pi / 4), 0.0, math.cos(math.pi / 4))


class Sim:
    def __init__(self, scene: str):
        self.client = p.connect(p.DIRECT)
        p.setGravity(0, 0, scenes.GRAVITY, physicsClientId=self.client)
        p.setTimeStep(scenes.STEP, physicsClientId=self.client)
        self.settings = {"solver": "sequential impulse",
                         "iterations": p.getPhysicsEngineParameters(
                             physicsClientId=self.client)["numSolverIterations"]}
        if scene in ("arm7", "grasp"):
            self._arm(scene)
        else:
            self._spheres(scene)

    def _static(self, shape: int, position=(0, 0, 0)) -> None:
        body = p.createMultiBody(0, shape, basePosition=position, physicsClientId=self.client)
        p.changeDynamics(body, -1, lateralFriction=scenes.FRICTION, physicsClientId=self.client)

    def _spheres(self, scene: str) -> None:
        c = self.client
        self._static(p.createCollisionShape(p.GEOM_PLANE, physicsClientId=c))
        for centre, sides in scenes.walls(scene):
            self._static(p.createCollisionShape(p.GEOM_BOX, halfExtents=[s / 2 for s in sides],
                                                physicsClientId=c), centre)
        sphere = p.createCollisionShape(p.GEOM_SPHERE, radius=scenes.RADIUS, physicsClientId=c)
        positions = scenes.sphere_positions(scene)
        made = p.createMultiBody(scenes.SPHERE_MASS, sphere, batchPositions=positions,
                                 physicsClientId=c)
        self._sphere_ids = list(made) if isinstance(made, (tuple, list)) else [made]
        for body in self._sphere_ids:
            p.changeDynamics(body, -1, lateralFriction=scenes.FRICTION, physicsClientId=c)
        self.bodies = len(positions)

    def _arm(self, scene: str) -> None:
        c = self.client
        masses, shapes, positions, inertial, parents, types, axes = [], [], [], [], [], [], []
        previous = (0.0, 0.0, 0.0)
        for k, (anchor, axis, start, end, mass) in enumerate(scenes.links()):
            vertical = abs(end[2] - start[2]) > 1e-9
            shapes.append(p.createCollisionShape(
                p.GEOM_CAPSULE, radius=scenes.LINK_RADIUS, height=math.dist(start, end),
                collisionFrameOrientation=(0, 0, 0, 1) if vertical else Z_ONTO_X_XYZW,
                physicsClientId=c))
            masses.append(mass)
            positions.append([a - b for a, b in zip(anchor, previous)])
            inertial.append([(s + e) / 2 - a for s, e, a in zip(start, end, anchor)])
            parents.append(k)          # link k's parent: the base (0) or link k - 1 (k)
            types.append(p.JOINT_REVOLUTE)
            axes.append(axis)
            previous = anchor
        self._last_link, self._flange_local = 6, [f - a for f, a in zip(scenes.FLANGE, previous)]
        if scene == "grasp":
            centre, sides, mass = scenes.PALM
            shapes.append(p.createCollisionShape(p.GEOM_BOX, halfExtents=[s / 2 for s in sides],
                                                 physicsClientId=c))
            masses.append(mass)
            positions.append([a - b for a, b in zip(centre, previous)])
            inertial.append([0, 0, 0])
            parents.append(7)
            types.append(p.JOINT_FIXED)
            axes.append([0, 0, 1])
            for position, direction in scenes.fingers():
                shapes.append(p.createCollisionShape(
                    p.GEOM_BOX, halfExtents=[s / 2 for s in scenes.FINGER_SIDES],
                    physicsClientId=c))
                masses.append(scenes.FINGER_MASS)
                positions.append([a - b for a, b in zip(position, centre)])
                inertial.append([0, 0, 0])
                parents.append(8)
                types.append(p.JOINT_PRISMATIC)
                axes.append(direction)
        n = len(masses)
        self.arm = p.createMultiBody(
            0, -1, basePosition=(0, 0, 0), linkMasses=masses, linkCollisionShapeIndices=shapes,
            linkVisualShapeIndices=[-1] * n, linkPositions=positions,
            linkOrientations=[(0, 0, 0, 1)] * n, linkInertialFramePositions=inertial,
            linkInertialFrameOrientations=[(0, 0, 0, 1)] * n, linkParentIndices=parents,
            linkJointTypes=types, linkJointAxis=axes, useMaximalCoordinates=False,
            physicsClientId=c)
        for link in range(-1, n):
            p.changeDynamics(self.arm, link, lateralFriction=scenes.FRICTION, physicsClientId=c)
        p.setJointMotorControlArray(self.arm, list(range(7)), p.POSITION_CONTROL,
                                    targetPositions=[0.0] * 7,
                                    forces=[scenes.MOTOR_MAX_TORQUE] * 7, physicsClientId=c)
        self.bodies = n
        if scene == "grasp":
            p.setJointMotorControlArray(self.arm, [8, 9], p.VELOCITY_CONTROL,
                                        targetVelocities=[scenes.FINGER_SPEED] * 2,
                                        forces=[scenes.FINGER_FORCE] * 2, physicsClientId=c)
            can = p.createCollisionShape(p.GEOM_CYLINDER, radius=scenes.CAN_RADIUS,
                                         height=scenes.CAN_LENGTH, physicsClientId=c)
            self.can_body = p.createMultiBody(scenes.CAN_MASS, can, basePosition=scenes.CAN,
                                              physicsClientId=c)
            p.changeDynamics(self.can_body, -1, lateralFriction=scenes.FRICTION,
                             physicsClientId=c)
            self.bodies += 1

    def step(self, n: int) -> None:
        step, c = p.stepSimulation, self.client
        for _ in range(n):
            step(physicsClientId=c)

    def sphere_positions(self):
        return [tuple(p.getBasePositionAndOrientation(b, physicsClientId=self.client)[0])
                for b in self._sphere_ids]

    def tip(self):
        state = p.getLinkState(self.arm, self._last_link, computeForwardKinematics=True,
                               physicsClientId=self.client)
        position, orientation = state[4], state[5]      # the link frame: its joint
        return p.multiplyTransforms(position, orientation, self._flange_local, (0, 0, 0, 1))[0]

    def can(self):
        return tuple(p.getBasePositionAndOrientation(self.can_body,
                                                     physicsClientId=self.client)[0])


def build(scene: str) -> Sim:
    return Sim(scene)
