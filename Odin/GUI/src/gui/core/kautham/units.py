"""Units of Kautham's two generations of files."""
from __future__ import annotations

import math
from dataclasses import dataclass


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
