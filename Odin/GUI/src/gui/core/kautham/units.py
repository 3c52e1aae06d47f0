"""Units of Kautham's two generations of files, and the bounds of the numbers they scale.

A problem's ``scale=``, a URDF ``<mesh scale>`` and the file units multiply every length a
model holds (squared for inertia, cubed for a mesh's volume and so its mass), so an absurd
scale or length turns into infinities (``1e308`` squared) or a body no world can hold. Each is
checked where it is read, against the world's own bounds: a length (a position, a size, a
mesh vertex) at most ``MAX_LENGTH``, the largest ``world_extent`` a world accepts; a scale
between ``MIN_SCALE`` and ``MAX_SCALE``, which map the smallest size a world builds
(``odin_common.limits.MIN_SIZE``) to that extent and back; a mass at most ``MAX_MASS``; an
inertia at most ``MAX_INERTIA``. So every number the tools print is finite.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from odin_common.limits import MAX_INERTIA, MAX_MASS, MIN_SIZE
from odin_common.world_parameters import PARAMETERS

MAX_LENGTH = float(next(p.high for p in PARAMETERS if p.name == "world_extent"))
"""m: the longest length (|coordinate|, size) a model may hold: the largest world extent."""
MAX_SCALE = MAX_LENGTH / MIN_SIZE
"""The largest scale factor (the smallest primitive a world builds, made the world's size)."""
MIN_SCALE = MIN_SIZE / MAX_LENGTH
"""The smallest scale factor."""


@dataclass(frozen=True)
class Units:
    """Factors from a file's numbers to SI."""
    length: float      # file length unit in metres
    angle: float       # file angle unit in radians
    name: str

    def deg_or_rad(self) -> str:
        return "degrees" if self.angle != 1.0 else "radians"


LEGACY = Units(length=0.001, angle=math.pi / 180.0, name="2012 (mm, degrees)")
SI = Units(length=1.0, angle=1.0, name="current (m, radians)")


def scale_problem(value: float) -> Optional[str]:
    """Why ``value`` cannot be a scale factor (finite, in [MIN_SCALE, MAX_SCALE]), or None."""
    if not math.isfinite(value) or not MIN_SCALE <= value <= MAX_SCALE:
        return (f"must be a finite number from {MIN_SCALE:g} to {MAX_SCALE:g} (a size of "
                f"{MIN_SIZE:g} m made the {MAX_LENGTH:g} m of the largest world, and back)")
    return None


def lengths_problem(values, scale: float = 1.0, unit: str = "m") -> Optional[str]:
    """Why lengths ``values`` (any shape, file units) times ``scale`` (``unit`` per file unit)
    cannot be a model's (not finite, or past MAX_LENGTH), or None. Joint limits in rad are
    held to the same bound (``unit="rad"``): a control maps [0, 1] onto high - low, which must
    stay finite."""
    array = np.asarray(values, dtype=float)
    if array.size == 0:
        return None
    with np.errstate(over="ignore", invalid="ignore"):
        largest = float(np.max(np.abs(array))) * abs(scale)
    if not math.isfinite(largest) or largest > MAX_LENGTH:
        where = "of the largest world (world_extent)" if unit == "m" else "a model may hold"
        return f"reaches {largest:.3g} {unit}, beyond the {MAX_LENGTH:g} {unit} {where}"
    return None


def mass_problem(mass: float) -> Optional[str]:
    """Why ``mass`` kg cannot be a body's (not finite, or past MAX_MASS), or None."""
    if not math.isfinite(mass) or mass > MAX_MASS:
        return f"{mass:.3g} kg is more than the {MAX_MASS:g} kg of the heaviest body (MAX_MASS)"
    return None


def inertia_problem(tensor) -> Optional[str]:
    """Why a (3, 3) inertia tensor (kg m^2) cannot be a body's (not finite, or an entry past
    MAX_INERTIA), or None."""
    array = np.asarray(tensor, dtype=float)
    largest = float(np.max(np.abs(array)))
    if not math.isfinite(largest) or largest > MAX_INERTIA:
        return (f"inertia reaches {largest:.3g} kg m^2, more than the {MAX_INERTIA:g} kg m^2 "
                f"a world accepts (MAX_INERTIA)")
    return None
