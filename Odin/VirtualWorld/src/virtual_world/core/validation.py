"""Checks of the Core's arguments. Each returns the value in the form the Core uses or raises
InvalidArgument naming ``what`` and the offending value; none calls ODE."""
from __future__ import annotations

import dataclasses
import math
from typing import Callable, TypeVar

import numpy as np

from odin_common import errors as common
from odin_common import limits, rotations
from odin_common.interface import COMPOSITE_MARK
from odin_common.limits import shown
from virtual_world.errors import InvalidArgument

R = TypeVar("R")


def shared(check: Callable[..., R], *args, **kwargs) -> R:
    """Runs a check shared by every node (odin_common), raising the Core's own error."""
    try:
        return check(*args, **kwargs)
    except common.InvalidArgument as error:
        raise InvalidArgument(str(error)) from None


def number(what: str, value, allow_inf: bool = False) -> float:
    if isinstance(value, (bool, str, bytes)):     # float("1e3") would read a string
        raise InvalidArgument(f"{what}={shown(value)} is not a number")
    try:
        result = float(value)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}={shown(value)} is not a number") from None
    if math.isnan(result) or (not allow_inf and math.isinf(result)):
        raise InvalidArgument(f"{what}={shown(value)} is not finite")
    return result


def vector(what: str, value, n: int = 3) -> np.ndarray:
    """(n,) float, finite."""
    try:
        array = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}={shown(value)} is not a vector of {n} numbers") from None
    if array.shape != (n,):
        raise InvalidArgument(f"{what}={shown(value)} has {array.size} values, expected {n}")
    if not np.isfinite(array).all():
        raise InvalidArgument(f"{what}={shown(value)} is not finite")
    return array


def flat_vector(what: str, value) -> np.ndarray:
    """(k,) float, finite, any length k (a sequence of numbers)."""
    try:
        count = len(value)
    except TypeError:
        raise InvalidArgument(f"{what}={shown(value)} is not a sequence of numbers") from None
    return vector(what, value, count)


def axis(what: str, value) -> np.ndarray:
    """(3,) unit vector."""
    a = vector(what, value)
    norm = float(np.linalg.norm(a))
    if math.isinf(norm):    # (1e200, 0, 1e200): brought to ~1 first. Only then: dividing
        a = a / float(np.max(np.abs(a)))    # every axis by its largest first would change
        norm = float(np.linalg.norm(a))     # the last bit of ordinary ones, and so motions
    if norm < 1e-9:
        raise InvalidArgument(f"{what}={shown(value)} is a zero axis")
    return a / norm


def quaternion(what: str, value) -> np.ndarray:
    """(4,) unit quaternion (w, x, y, z), normalised (odin_common.rotations' tolerance)."""
    return shared(rotations.unit_quaternion, value, what)


def name(what: str, value, allow_marker: bool = False) -> str:
    """A name a request stores (odin_common.limits.check_name: non-empty, at most
    MAX_NAME_BYTES, printable); without allow_marker it may not hold the composite mark
    (odin_common.interface.COMPOSITE_MARK)."""
    shared(limits.check_name, what, value)
    if not allow_marker and COMPOSITE_MARK in value:
        raise InvalidArgument(f"{what}={shown(value)} must not contain "
                              f"{COMPOSITE_MARK!r}")
    return value


def text(what: str, value) -> str:
    """Any string, "" included (an ID that may be left to its default)."""
    if not isinstance(value, str):
        raise InvalidArgument(f"{what}={shown(value)} is not a string")
    return value


def flag(what: str, value) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidArgument(f"{what}={shown(value)} is not a bool")
    return bool(value)


def count(what: str, value, low: int = 1) -> int:
    """An integer >= low (a bool is not one)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise InvalidArgument(f"{what}={shown(value)} must be an integer >= {low}")
    return int(value)


def surface(what: str, value):
    """A Surface (odin_common.specs) with its values in range; the friction direction made
    unit."""
    from odin_common.specs import Surface
    if not isinstance(value, Surface):
        raise InvalidArgument(f"{what}: {shown(value)} is not a Surface")
    if value.friction is not None:
        mu = number(f"{what}: friction", value.friction, allow_inf=True)
        if mu < 0:
            raise InvalidArgument(f"{what}: friction={shown(mu)} must be >= 0 (math.inf: "
                                  "infinite)")
    direction = value.friction_direction
    if value.friction2 is not None:
        if number(f"{what}: friction2", value.friction2) < 0:
            raise InvalidArgument(f"{what}: friction2={shown(value.friction2)} must be >= 0")
        direction = tuple(axis(f"{what}: friction_direction", direction).tolist())
    if value.bounce is not None:
        e = number(f"{what}: bounce", value.bounce)
        if not 0 <= e <= 1:
            raise InvalidArgument(f"{what}: bounce={shown(e)} must be in [0, 1]")
        if number(f"{what}: bounce_velocity", value.bounce_velocity) < 0:
            raise InvalidArgument(f"{what}: bounce_velocity={shown(value.bounce_velocity)} "
                                  "must be >= 0")
    if value.stiffness is not None:
        if number(f"{what}: stiffness", value.stiffness) <= 0:
            raise InvalidArgument(f"{what}: stiffness={shown(value.stiffness)} must be > 0")
        if number(f"{what}: damping", value.damping) < 0:
            raise InvalidArgument(f"{what}: damping={shown(value.damping)} must be >= 0")
    return dataclasses.replace(value, friction_direction=direction)


def mass(what: str, value: float) -> float:
    """A body's mass, kg, within odin_common.limits."""
    if value <= 0:
        raise InvalidArgument(f"{what}: mass {value:.6g} must be positive")
    if not limits.MIN_MASS <= value <= limits.MAX_MASS:
        raise InvalidArgument(f"{what}: mass {value:.6g} kg is outside the limits "
                              f"[{limits.MIN_MASS:g}, {limits.MAX_MASS:g}] kg")
    return value


def ignored_mass(what: str, value: float) -> float:
    """The mass of a geometry-only object, which has no body: 0 (the message's default) or a
    mass a body could have; a negative or out-of-range one is refused, never ignored."""
    return value if value == 0.0 else mass(what, value)


def color(what: str, value) -> tuple:
    """RGBA, each finite and in [0, 1] (all zero: the Viewer's default colour); what the
    Viewer draws, so the world refuses what the Viewer would."""
    rgba = vector(what, value, 4)
    if np.any(rgba < 0.0) or np.any(rgba > 1.0):
        raise InvalidArgument(f"{what}={shown(value)}: each of r, g, b, a must be in [0, 1]")
    return tuple(rgba.tolist())


def at_most(what: str, magnitude: float, limit: float, unit: str) -> None:
    """InvalidArgument unless ``magnitude`` <= ``limit`` (the field and the limit named)."""
    if magnitude > limit:
        raise InvalidArgument(f"{what}: {magnitude:.6g} {unit} is beyond the limit "
                              f"{limit:g} {unit}")


def within_extent(what: str, position: np.ndarray, extent: float) -> np.ndarray:
    """A position (m) no farther than the world's extent along any axis (world_extent)."""
    at_most(what, float(np.max(np.abs(position))), extent, "m from the origin (world_extent)")
    return position


def step_count(count: int, what: str) -> int:
    """A number of steps for one call, at most limits.MAX_STEPS_PER_CALL; ``what`` names the
    request in the refusal."""
    if count > limits.MAX_STEPS_PER_CALL:
        raise InvalidArgument(f"{what} asks for {float(count):.3g} steps; one call runs at most "
                              f"{limits.MAX_STEPS_PER_CALL:,} (ask in pieces)")
    return int(count)


def step_size(value) -> float:
    """A step, s, within odin_common.limits and step_values' MAX_STEP."""
    from odin_common.step_values import MAX_STEP
    value = number("step_size", value)
    if not limits.MIN_STEP <= value <= MAX_STEP:
        raise InvalidArgument(f"step_size={value:.6g} s is outside [{limits.MIN_STEP:g}, "
                              f"{MAX_STEP:g}] s")
    return value
