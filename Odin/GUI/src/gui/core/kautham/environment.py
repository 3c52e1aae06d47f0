"""What Kautham's ODE environments (``src/planner/omplOpenDE/Setup/`` in the Kautham
repository) do to a problem, as constants Odin's build plans and controls use: one home.

KauthamOpenDEEnvironment.cpp: an infinite ground plane at z = 0 (``dCreatePlane(space, 0, 0,
1, 0)``), gravity -9.8 m/s^2, the world's ERP 0.8 and CFM 1e-5; every obstacle link a dynamic
body with its URDF mass (0 becomes 1 kg); a planar chain's base held to the world by a fixed
joint. CarEnvironment.cpp: four wheels on hinge-2 joints (steering axis vertical, the first
two wheels' up, the others' down; suspension ERP 0.4, CFM 0.8); its controls are a steering
angle in [-0.5, 0.5] rad, reached at a rate of 1/s under 2 N m, and a wheel speed in
[-5, 10] rad/s under 50 N m. PlanarChainEnvironment.cpp: motor speeds in [-1, 1] rad/s on
the joints under a torque limit of 7 N m, whatever the URDF's limits say (its demo chain's
URDF gives 0.1 rad/s and 300 N m); Odin's servo then moves a held chain's joints toward their
targets under those limits (gui.core.control_path). twoDRobotEnvironment.cpp and
ConstraintAware2DRobotEnvironment.cpp: a force on the free body.

Each environment types every body (KauthamOpenDEEnvironment's ``InstknowledgeInference``, by
name): the robot's links "robBody", the obstacles it names ``MANIPULABLE`` (the cubes, boxes
and cylinders of its demos) "freeManipulatable", which a robot may push, every other obstacle
"fixed", which a robot must not touch; and its ``setupContact`` gives each pair of types a
friction coefficient. ``CAR_FRICTION`` is CarEnvironment's.
"""
from __future__ import annotations

GRAVITY = (0.0, 0.0, -9.8)
"""m/s^2, world frame."""
WORLD_ERP = 0.8
WORLD_CFM = 1e-5
GROUND_COLOR = (0.55, 0.57, 0.6, 1.0)
"""The ground plane's colour (Kautham draws none; the Viewer's floor colour otherwise)."""
OBSTACLE_MASS = 1.0
"""kg: an obstacle whose file gives no mass (Kautham's 0 becomes 1)."""

SUSPENSION_ERP = 0.4
SUSPENSION_CFM = 0.8
STEERING_RANGE = (-0.5, 0.5)
"""rad: the car's steering control, low and high."""
WHEEL_SPEED_RANGE = (-5.0, 10.0)
"""rad/s: the car's wheel speed control, low and high."""
STEERING_GAIN = 1.0
"""1/s: steering speed per radian of steering error."""
STEERING_MAX_TORQUE = 2.0
"""N m: the steering motor's force limit."""
WHEEL_MAX_TORQUE = 50.0
"""N m: the wheel motor's force limit."""

CHAIN_JOINT_SPEED = 1.0
"""rad/s: the fastest a held chain's joint moves (PlanarChainEnvironment's control bounds)."""
CHAIN_JOINT_TORQUE = 7.0
"""N m: a held chain's joint motor's force limit (PlanarChainEnvironment's dParamFMax)."""

MANIPULABLE = frozenset(
    [f"cubeDE{k}" for k in ("", 1, 2, 3, 4, 5, 6, 7, 8)] + ["cylinder1", "cylinder2",
                                                            "cylinder3", "SimpleCar"]
    + [f"box{k}" for k in (2, 3, 4, 5)])
"""Obstacles (by name) KauthamOpenDEEnvironment types "freeManipulatable"."""

CAR_FRICTION = {"robot": 5.0, "ground": 5.0, "manipulable": 0.1, "fixed": 0.1}
"""Contact friction (Coulomb mu) of each kind of body in a problem of Kautham's car planner,
so that two bodies in contact, whose frictions Odin mixes by taking the smaller, get
CarEnvironment's ``setupContact``: the robot on the ground 5 (its wheels grip), a pushed cube
on the ground, on a wall or a wall on the ground 0.1. One pair differs: Kautham gives the
robot against a manipulable body 0.0001, which one coefficient per body cannot give without
also making the cube slide on the ground; here it is 0.1."""
