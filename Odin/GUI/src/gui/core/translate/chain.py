"""A fixed-base robot (``gui.core.model.FIXED_BASE``: a chain or tree, a manipulator): how its
base is held, and how Kautham's chain planner drives its joints (ROS-free).

In a 2012 problem the base is a fixed (kinematic) body, as Odin always built them; in a
current one a dynamic body held to the world by a FIXED joint, as KauthamOpenDEEnvironment
holds its planar chain. Under Kautham's chain planner every joint is driven as
PlanarChainEnvironment drives it (``gui.core.kautham.environment``), whatever its URDF says.
"""
from __future__ import annotations

import dataclasses
from typing import List, Tuple

from gui.core.kautham import environment
from gui.core.plan import BodySpec, JointStep
from gui.core.translate.joints import Drive, fixed_joint


def hold_base(name: str, specs: List[BodySpec], problem_format: str
              ) -> Tuple[List[BodySpec], List[JointStep]]:
    """The link specs of the robot ``name`` (base first) with its base held as a problem of
    ``problem_format`` ("2012" or "current") holds it, and the steps that hold it (after the
    robot's entity is built)."""
    if problem_format == "current":
        return specs, [JointStep(f"{name}/<base>", name, fixed_joint(specs[0].id, ""))]
    # it never moves, whatever the motors push
    return [dataclasses.replace(specs[0], fixed=True)] + specs[1:], []


def planar_chain_drive(drive: Drive) -> Drive:
    """``drive`` with PlanarChainEnvironment's limits: up to 1 rad/s under 7 N m."""
    return drive._replace(effort=environment.CHAIN_JOINT_TORQUE,
                          speed=environment.CHAIN_JOINT_SPEED)
