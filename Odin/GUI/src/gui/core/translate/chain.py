"""A fixed-base robot (``gui.core.model.FIXED_BASE``: a chain or tree, a manipulator): how its
base is held, and how Kautham's chain planner drives its joints (ROS-free).

Under Kautham's physics (one of its ODE planners) a current problem's base is a dynamic body
held to the world by a FIXED joint, as KauthamOpenDEEnvironment holds its planar chain;
anywhere else (a 2012 problem, as Odin always built them; a geometric planner's problem, where
Kautham simulates nothing and the base stands where the problem puts it) a fixed (kinematic)
body: it never moves, whatever its motors or a body it overlaps push (the YuMi's arm bases lie
inside its torso; held by a joint, they were pushed 13-20 mm and their arms with them), and
the world makes no contact between it and static geometry. Under Kautham's chain planner every
joint is driven as PlanarChainEnvironment drives it (``gui.core.kautham.environment``),
whatever its URDF says.
"""
from __future__ import annotations

import dataclasses
from typing import List, Tuple

from gui.core.kautham import environment
from gui.core.plan import BodySpec, JointStep
from gui.core.translate.joints import Drive, fixed_joint


def hold_base(name: str, specs: List[BodySpec], problem_format: str, physics: bool
              ) -> Tuple[List[BodySpec], List[JointStep]]:
    """The link specs of the robot ``name`` (base first) with its base held as a problem of
    ``problem_format`` ("2012" or "current") built with Kautham's physics or without
    (``physics``) holds it, and the steps that hold it (after the robot's entity is built)."""
    if problem_format == "current" and physics:
        return specs, [JointStep(f"{name}/<base>", name, fixed_joint(specs[0].id, ""))]
    return [dataclasses.replace(specs[0], fixed=True)] + specs[1:], []


def planar_chain_drive(drive: Drive) -> Drive:
    """``drive`` with PlanarChainEnvironment's limits: up to 1 rad/s under 7 N m."""
    return drive._replace(effort=environment.CHAIN_JOINT_TORQUE,
                          speed=environment.CHAIN_JOINT_SPEED)
