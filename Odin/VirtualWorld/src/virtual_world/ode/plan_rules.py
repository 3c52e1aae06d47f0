"""The C side of a control planner's rule (odin_step.h's OdinPlanRule, odin_plan.c): the
struct and the arrays it points at, made together and kept together (virtual_world.core's
checked_propagation owns them), and the tracked link's read-out."""
from __future__ import annotations

from typing import Sequence

import numpy as np

from virtual_world.ode.bindings import ffi, lib


class RuleMemory:
    """One OdinPlanRule (``struct``, an ``OdinPlanRule *``) and the C arrays it points at,
    alive as long as this object: the tracked link (body ``tracked_index`` of the body state
    vectors, its centre of mass ``com`` and the link's origin ``offset``, (3,) m in the
    body's frame), and for a propagation's verdicts a role per geom serial (``roles``, one
    byte each), an ``n_roles`` x ``n_roles`` table of forbidden role pairs (``table``, one
    byte each), the link's box ``low``/``high`` (m, world) and ``max_speed`` (m/s). Values
    are taken as given: the caller has checked them."""

    def __init__(self, tracked_index: int, com: Sequence[float], offset: Sequence[float],
                 roles: bytes = b"", table: bytes = b"", n_roles: int = 0,
                 low: Sequence[float] = (0.0, 0.0, 0.0), high: Sequence[float] = (0.0, 0.0, 0.0),
                 max_speed: float = 0.0):
        self._roles = ffi.new("unsigned char[]", roles or b"\0")
        self._table = ffi.new("unsigned char[]", table or b"\0")
        self.struct = ffi.new("OdinPlanRule *", {
            "role_of_serial": self._roles, "n_serials": len(roles),
            "forbidden": self._table, "n_roles": n_roles, "tracked": tracked_index,
            "com": [float(v) for v in com], "offset": [float(v) for v in offset],
            "low": [float(v) for v in low], "high": [float(v) for v in high],
            "max_speed": float(max_speed)})
        self.tracked_index = tracked_index

    def tracked_values(self, state: np.ndarray) -> np.ndarray:
        """(6,) the tracked link's origin (m) and its body's linear velocity (m/s), world
        frame, in ``state`` (contiguous float64, long enough to hold the tracked body)."""
        out = np.empty(6)
        lib.odin_plan_tracked(self.struct, ffi.from_buffer("double[]", state),
                              ffi.from_buffer("double[]", out, require_writable=True))
        return out
