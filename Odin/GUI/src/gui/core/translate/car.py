"""A car (``gui.core.model.CAR``): a base on wheels, each wheel on a hinge-2, and the contact
friction Kautham's car planner gives every body (ROS-free).

Under Kautham's car planner the wheels' axes are CarEnvironment's world axes, whatever the
car's pose or URDF, and every body's friction is the one CarEnvironment gives its kind
(``gui.core.kautham.environment.CAR_FRICTION``); any other car takes its axes from its own
frame and keeps its URDF's surfaces. Axes are world frame, friction a Coulomb mu.
"""
from __future__ import annotations

import dataclasses
from typing import Optional, Tuple

import numpy as np

from gui.core.kautham import environment
from gui.core.model import CAR, REVOLUTE, Ignored, Instance, LinkModel
from gui.core.translate.joints import floats
from odin_common.interface import JointParameter, JointType
from odin_common.specs import JointSpec, Surface

GROUND_SURFACE = Surface(friction=environment.CAR_FRICTION["ground"])
"""The ground plane's contact surface in a problem of Kautham's car planner."""


def is_wheel(inst: Instance, link: LinkModel) -> bool:
    """Whether ``link`` is one of a car's wheels: a revolute link on the car's base."""
    return inst.kind == CAR and link.parent == 0 and link.joint == REVOLUTE


def wheel_axes(link: LinkModel, frame: np.ndarray, base_pose: np.ndarray, index: int,
               car_environment: bool) -> Tuple[np.ndarray, np.ndarray]:
    """(steering axis, spin axis), world frame, of the ``index``-th wheel of a car (in its
    link order) whose joint frame is ``frame`` and base at ``base_pose`` ((4, 4), world).

    For Kautham's car planner (``car_environment``), CarEnvironment's: it sets world axes
    whatever the car's pose or URDF (steering about +z for the first two wheels, -z for the
    others, spin about +y), so a positive wheel speed turns the chassis about +y relative to
    its wheels and rolls the car toward world -x. Otherwise axes the car's own frame gives:
    steering along the base's z, opposite for the wheels ahead of the base's origin along its
    x and for the others (the rear wheels steer against the front ones, as Kautham's four do);
    spin about the wheel joint's axis; both reversed, as a robot's hinges are (a hinge-2's
    angles and rates are body1's turn relative to body2), so a positive steering turns the
    front wheels left (counter-clockwise seen from above) and a positive wheel speed turns a
    wheel about its joint's axis (a car whose wheels turn about its y rolls along its +x)."""
    if car_environment:
        return np.array((0.0, 0.0, 1.0 if index < 2 else -1.0)), np.array((0.0, 1.0, 0.0))
    ahead = (np.linalg.inv(base_pose) @ np.append(frame[:3, 3], 1.0))[0] > 0.0
    return base_pose[:3, 2] * (-1.0 if ahead else 1.0), -(frame[:3, :3] @ link.axis)


def wheel_joint(frame: np.ndarray, steering: np.ndarray, spin: np.ndarray, parent_id: str,
                child_id: str) -> JointSpec:
    """A car's wheel on a hinge-2 at the wheel joint's origin (``frame``, world): the chassis
    body1, the axes (world frame) as given, CarEnvironment's soft suspension along the
    steering axis."""
    return JointSpec(type=JointType.HINGE2, body1=parent_id, body2=child_id,
                     anchor=floats(frame[:3, 3]), axis1=floats(steering), axis2=floats(spin),
                     parameters=((JointParameter.SUSPENSION_ERP, 1, environment.SUSPENSION_ERP),
                                 (JointParameter.SUSPENSION_CFM, 1, environment.SUSPENSION_CFM)))


def car_environment_surface(inst: Instance, link: LinkModel, name: str
                            ) -> Tuple[Surface, Optional[Ignored]]:
    """The contact surface of ``inst``'s ``link`` (body ``name``) in a problem of Kautham's
    car planner: its URDF's, with the friction CarEnvironment gives the body's kind; and the
    URDF friction this overrides, listed as ignored (None: the URDF gave none)."""
    kind = "robot" if inst.role == "robot" else \
        "manipulable" if inst.name in environment.MANIPULABLE else "fixed"
    ignored = None
    if link.surface.friction is not None:
        ignored = Ignored(link.source, link.line, f'contact friction {link.surface.friction:g} '
                          f'of {name}', "Kautham's car environment sets every contact's "
                          f"friction ({kind}: {environment.CAR_FRICTION[kind]:g})")
    return dataclasses.replace(link.surface, friction=environment.CAR_FRICTION[kind]), ignored
