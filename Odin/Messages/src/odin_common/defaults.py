"""Odin's tuning constants, in one table: the values that are choices (a solver's thresholds,
a servo's gain and speed, how objects are drawn) rather than facts of the interface. The
interface's facts (the .msg/.srv constants, joint and service tables, message layouts) are in
``odin_common.interface``; the world parameters a user sets at start or with Set World, with
their defaults and ranges, in ``odin_common.world_parameters``; the ranges a request must
stay within in ``odin_common.limits``.

Each value has its unit and why it is what it is. Changing one changes behaviour: the pinned
plans and experiments (docs/PERFORMANCE.md) were recorded with these values.
"""
from __future__ import annotations

from typing import Tuple

# ---------------------------------------------------------------- Solver.AUTO's thresholds

AUTO_SOLVER_MAX_ROWS = 120
"""Constraint rows: Solver.AUTO's small-system bound, the most a whole step may have (each
joint counted at its most: 6 for a hinge, slider or fixed joint, 3 for a contact, ball or
motor) to be solved by dWorldStep whatever its islands; the pinned planning experiments were
recorded under this clause, so it stays beside the island rule (docs/PERFORMANCE.md). The
island rule takes an articulation (AUTO_SOLVER_ARTICULATION_ROWS) that this clause does not
admit among other bodies' rows."""

AUTO_SOLVER_ARTICULATION_ROWS = 45
"""Constraint rows: Solver.AUTO's island rule, an island whose joints and motors alone,
counted as AUTO_SOLVER_MAX_ROWS counts them (9 for a hinge held by its servo), have at least
this many rows is an articulation dWorldStep solves (while the largest island stays within
AUTO_SOLVER_MAX_ISLAND_ROWS): five servo-held joints or more, any manipulator arm, with or
without its gripper or hand. QuickStep's iterations let such a chain shake off its pose among
other bodies' contacts: a YuMi arm and gripper on its kinematic base (9 joints) moved 6.4 mm in
2 s, a UR arm of MADAR (6) 3.4 mm; under dWorldStep 0.04 mm. Smaller articulations among
contacts keep QuickStep, as Kautham's car (36 rows) had when its plans were pinned (they and
the chain's and the sphere's stay bit-identical); docs/PERFORMANCE.md."""

AUTO_SOLVER_MAX_ISLAND_ROWS = 400
"""Constraint rows: Solver.AUTO's bound on the largest island of a step for dWorldStep (each
joint counted as ODE 0.16 does: 5 for a hinge or slider, 6 for a fixed joint, 3 for a ball or
a contact, plus 1 per powered or limited axis; a motor 1 per powered axis). ODE steps islands
one by one and dWorldStep's cost is cubic in an island's rows: the bound keeps the TX90 + hand
grasping a can (about 300 rows) exact and sends a pile of 100 spheres (about 700) to
QuickStep; measured in docs/PERFORMANCE.md."""

# ---------------------------------------------------------------------------------- servos

SERVO_GAIN = 20.0
"""1/s: a servo's default position gain (Set Servo's ``gains`` when none is given): its
motor's speed per unit of position error, so that the error decays with a time constant of
1/gain (50 ms)."""

SERVO_MAX_SPEED = 2.0
"""rad/s or m/s: a servo's default speed limit (Set Servo's ``max_speeds`` when none is
given); a robot's own limits (its URDF velocities) take its place."""

# ---------------------------------------------------------------------------------- display

DEFAULT_COLOR: Tuple[float, float, float, float] = (0.62, 0.70, 0.82, 1.0)
"""(r, g, b, a) in [0, 1]: how an object sent with an all-zero colour is drawn (the Viewer,
the world's markers and generated robot descriptions)."""

COLLIDING_COLOR: Tuple[float, float, float, float] = (0.35, 0.35, 0.35, 1.0)
"""(r, g, b, a) in [0, 1]: an object while the world reports it colliding (thesis 6.4.1: dark
grey)."""

PLANE_DRAWN_SIZE = 60.0
"""m: a plane (infinite in the world) is drawn as a square floor this wide..."""

PLANE_DRAWN_THICKNESS = 0.002
"""m: ...and this thin, its top face on the plane (a box: a marker has no infinite plane)."""


__all__ = ["AUTO_SOLVER_MAX_ROWS", "AUTO_SOLVER_ARTICULATION_ROWS", "AUTO_SOLVER_MAX_ISLAND_ROWS",
           "SERVO_GAIN", "SERVO_MAX_SPEED", "DEFAULT_COLOR", "COLLIDING_COLOR",
           "PLANE_DRAWN_SIZE", "PLANE_DRAWN_THICKNESS"]
