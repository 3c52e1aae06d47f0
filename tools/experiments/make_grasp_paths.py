"""Makes the grasp experiment's path files in ``Odin/GUI/paths/`` (see the README there).

    python tools/experiments/make_grasp_paths.py

The TX90 + SAH hand of TX90_RHand_ICRA10_5PMD_TwoCan.xml; 24 values per row, radians, in the
robot file's order of movable joints (6 arm joints, Palm, Thumb, then the four fingers' Base,
Prox, Med, Dist). The hand frame is the Palm link's (at Home: x the palm's normal, y along the
row of fingers towards the thumb, z along the fingers; the fingers close towards +x, the
palm's side). The "grasp point" is fixed in that frame at GRASP_OFFSET: inside the ring the
closed fingers make, where the can's axis should pass (found by drawing the closed hand around
the can with the Viewer's renderer).

- ``grasp_initial.txt``: one row, the starting position: the hand open with the thumb turned to
  face the fingers (joint "Thumb" at THUMB_OPPOSED), fingers horizontal and pointing away from
  the robot, the palm facing the can from 0.10 m beside it (and 0.03 m higher), found by
  inverse kinematics (``ik.py``, damped least squares on the DH model).
- ``grasp_approach.txt``: the position path: the grasp point moved on a straight line to the
  can's axis, one IK solution per waypoint (each started from the previous one), hand open.
  The experiment doubles its precision once (``gui.core.paths.double_precision``).
"""
from __future__ import annotations

import pathlib
import sys

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import common  # noqa: E402
import ik  # noqa: E402

PROBLEM = "TX90_RHand_ICRA10_5PMD_TwoCan.xml"
CAN_AT = np.array([-0.30, 1.00, 0.5603])     # m: where the grasp experiment puts the can
GRASP_OFFSET = np.array([0.045, -0.02, 0.15])   # m, Palm frame: the can's centre, inside
                                              # the ring the closed fingers make (+x: palm side)
PRE_GRASP = (-0.10, 0.03)                     # m: away from the palm (-x), and up
WAYPOINTS = 9
THUMB_OPPOSED = -1.4   # rad, joint "Thumb": the thumb turned to face the fingers across the can
ARM = list(range(6))
PALM_LINK = 7


def hand_target(position: np.ndarray) -> np.ndarray:
    """Grasp frame in the world: fingers (z) pointing away from the robot's axis, the row of
    fingers (y) up, the palm's normal (x) horizontal, anticlockwise seen from above."""
    radial = np.array([position[0], position[1], 0.0])
    radial /= np.linalg.norm(radial)
    up = np.array([0.0, 0.0, 1.0])
    T = np.eye(4)
    T[:3, 0] = np.cross(up, radial)
    T[:3, 1] = up
    T[:3, 2] = radial
    T[:3, 3] = position
    return T


def compute() -> dict:
    problem, plan = common.load_plan(common.EXAMPLES / PROBLEM)
    handle = plan.robots[0]
    model, base = handle.instance.model, handle.instance.base_pose
    offset = np.eye(4)
    offset[:3, 3] = GRASP_OFFSET
    q = handle.home.copy()
    q[:6] = [1.9, 0.6, 1.2, 0.0, 1.0, 0.0]       # a rough elbow-up guess near the table
    q[7] = THUMB_OPPOSED
    target = hand_target(CAN_AT)
    start = target.copy()
    start[:3, 3] += PRE_GRASP[0] * target[:3, 0] + np.array([0.0, 0.0, PRE_GRASP[1]])
    rows = []
    for k, s in enumerate(np.linspace(0.0, 1.0, WAYPOINTS)):
        goal = start.copy()
        goal[:3, 3] = (1 - s) * start[:3, 3] + s * target[:3, 3]
        q, position_error, angle_error = ik.solve(model, base, q, PALM_LINK, offset, goal, ARM)
        if position_error > 1e-4 or angle_error > 1e-3:
            raise RuntimeError(f"waypoint {k}: IK did not converge ({position_error:.2e} m, "
                               f"{angle_error:.2e} rad)")
        rows.append(q.copy())
    return {"initial": rows[0], "approach": np.array(rows), "handle": handle}


def write(rows: np.ndarray, path: pathlib.Path, title: str) -> None:
    header = (f"# {title}\n# TX90 SAHand Right (TX90_RHand_ICRA10_5PMD_TwoCan.xml), radians, "
              "24 movable joints in the robot file's order.\n# Made by "
              "tools/experiments/make_grasp_paths.py (IK over the DH model); see README.md.\n")
    body = "\n".join(" ".join(f"{v:.6f}" for v in row) for row in np.atleast_2d(rows))
    path.write_text(header + body + "\n")


def main() -> int:
    result = compute()
    common.PATHS_DIR.mkdir(parents=True, exist_ok=True)
    write(result["initial"], common.PATHS_DIR / "grasp_initial.txt",
          "Grasp experiment: initial position (one row)")
    write(result["approach"], common.PATHS_DIR / "grasp_approach.txt",
          "Grasp experiment: position path, pre-grasp to grasp (one row per cycle)")
    print(f"wrote {common.PATHS_DIR}/grasp_initial.txt and grasp_approach.txt "
          f"({len(result['approach'])} rows)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
