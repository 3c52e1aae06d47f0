"""Checks of the Core's arguments. Each returns the value in the form the Core uses or raises
InvalidArgument naming ``what`` and the offending value; none calls ODE."""
from __future__ import annotations

import math
from typing import Callable, TypeVar

import numpy as np

from odin_common import errors as common
from odin_common import rotations
from virtual_world.errors import InvalidArgument

R = TypeVar("R")


def shared(check: Callable[..., R], *args, **kwargs) -> R:
    """Runs a check shared by every node (odin_common), raising the Core's own error."""
    try:
        return check(*args, **kwargs)
    except common.InvalidArgument as error:
        raise InvalidArgument(str(error)) from None


def number(what: str, value, allow_inf: bool = False) -> float:
    if isinstance(value, bool):
        raise InvalidArgument(f"{what}={value!r} is not a number")
    try:
        result = float(value)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}={value!r} is not a number") from None
    if math.isnan(result) or (not allow_inf and math.isinf(result)):
        raise InvalidArgument(f"{what}={value!r} is not finite")
    return result


def vector(what: str, value, n: int = 3) -> np.ndarray:
    """(n,) float, finite."""
    try:
        array = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidArgument(f"{what}={value!r} is not a vector of {n} numbers") from None
    if array.shape != (n,):
        raise InvalidArgument(f"{what}={value!r} has {array.size} values, expected {n}")
    if not np.all(np.isfinite(array)):
        raise InvalidArgument(f"{what}={value!r} is not finite")
    return array


def flat_vector(what: str, value) -> np.ndarray:
    """(k,) float, finite, any length k (a sequence of numbers)."""
    try:
        count = len(value)
    except TypeError:
        raise InvalidArgument(f"{what}={value!r} is not a sequence of numbers") from None
    return vector(what, value, count)


def axis(what: str, value) -> np.ndarray:
    """(3,) unit vector."""
    a = vector(what, value)
    norm = float(np.linalg.norm(a))
    if norm < 1e-9:
        raise InvalidArgument(f"{what}={value!r} is a zero axis")
    return a / norm


def quaternion(what: str, value) -> np.ndarray:
    """(4,) unit quaternion (w, x, y, z), normalised (odin_common.rotations' tolerance)."""
    return shared(rotations.unit_quaternion, value, what)


def name(what: str, value, allow_marker: bool = False) -> str:
    """A non-empty string; without allow_marker it may not hold '>' (the composite mark)."""
    if not isinstance(value, str) or not value:
        raise InvalidArgument(f"{what}={value!r} must be a non-empty string")
    if not allow_marker and ">" in value:
        raise InvalidArgument(f"{what}={value!r} must not contain '>'")
    return value


def text(what: str, value) -> str:
    """Any string, "" included (an ID that may be left to its default)."""
    if not isinstance(value, str):
        raise InvalidArgument(f"{what}={value!r} is not a string")
    return value


def flag(what: str, value) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidArgument(f"{what}={value!r} is not a bool")
    return bool(value)


def count(what: str, value, low: int = 1) -> int:
    """An integer >= low (a bool is not one)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise InvalidArgument(f"{what}={value!r} must be an integer >= {low}")
    return int(value)
