"""A geometric search's path as Kautham hands it on (ROS-free): interpolated as Kautham's
``omplPlanner::trySolve`` does, and written as OMPL's rows.

Kautham 5.1.1 (src/planner/omplg/omplplanner.cpp, ``trySolve``) treats an exact solution in
two steps: it simplifies it as ``_Simplify Solution`` asks (``gui.planning.geometric.solve``
does that, ``GeometricSettings.simplify``), then, whatever that parameter says, calls OMPL's
``PathGeometric::interpolate()``: each segment of the path, of length d, is cut into
``ceil(d / L)`` equal pieces, L being the space's longest valid segment. L is 1 % of the
space's maximum extent (the fraction Kautham's planners set, OMPL's default), except in
Kautham's RRT and RRTConnect, which take ``Range / 5`` when the Range is at most 4 L, so that
five states fall within a Range step (their ``_validSegmentCount``). Kautham's space is the
configuration space; Odin's search space is the control space [0, 1]^k with each control
scaled by how far it moves the robots in Kautham's metric (``GeometricResult.scales``,
gui.planning.geometric_robots.control_scales): lengths are measured there, its maximum extent
is the norm of the scales (sqrt(k) unscaled, a 2012 problem's).

The interpolation is linear in the control space, and a straight segment of the control space
is exactly the motion the search checked (``GeometricWorld.motion_points``): every state added
lies on a motion found valid, so the states written are as collision-free as the path. (A
tracked run moves straight in joint space between waypoints; where a joint's limit clamps the
mapping of a control segment, or a base turns, more waypoints keep it closer to the checked
motion.)

OMPL rows are what ``PathGeometric::printAsMatrix`` writes for Kautham's OMPL space, its
configuration space (Kautham's ``getPath``; the Kautham peer's ``--matrix``): one state per
line, each value followed by a space, a blank line after the last; a state is the same
configuration of every robot as a task file's ``<Conf>`` row (``geometric.task_rows``), which
``run_path --tracked`` reads as OMPL rows (``gui.core.kautham.solutions``). Values are written
to full precision (``repr``), not printAsMatrix's six digits: a joint at its limit stays
within it.
"""
from __future__ import annotations

import math
import os
import pathlib
from typing import Optional, Sequence

import numpy as np

from gui.errors import PlanningError

LONGEST_SEGMENT_FRACTION = 0.01
"""Of the space's maximum extent: Kautham's longest valid segment (setLongestValidSegmentFraction
in each of its OMPL planners' constructors, and OMPL's default)."""
RANGE_STEP_STATES = 5
"""Kautham's ``_validSegmentCount``: states within a Range step of its RRT and RRTConnect."""
RANGE_STEP_PLANNERS = frozenset({"RRT", "RRTConnect"})
"""OMPL's names of the planners whose Kautham wrappers shorten the segment to Range / 5
(omplRRTplanner.cpp, omplRRTConnectplanner.cpp; Kautham's PRM, RRT* and KPIECE keep 1 %)."""


def longest_segment(size: int, planner: str, range_: Optional[float] = None,
                    scales: Optional[Sequence[float]] = None) -> float:
    """The longest segment the interpolation leaves, in the search's units (``scales``: its
    per-control scales, None: all 1), for a space of ``size`` controls searched by
    ``planner`` (OMPL's name) with Kautham's ``Range`` ``range_`` (None: OMPL's default, 20 %
    of the extent, never shortened)."""
    if size < 1:
        raise PlanningError(f"a control space of {size} dimensions")
    extent = math.sqrt(size) if scales is None else float(np.linalg.norm(scales))
    longest = LONGEST_SEGMENT_FRACTION * extent
    if planner in RANGE_STEP_PLANNERS and range_ is not None \
            and range_ <= (RANGE_STEP_STATES - 1) * longest:
        longest = range_ / RANGE_STEP_STATES
    return longest


def interpolate(path: np.ndarray, longest: float,
                scales: Optional[Sequence[float]] = None) -> np.ndarray:
    """``path`` (n, k) with each segment cut into ``ceil(d / longest)`` equal pieces (d its
    length, each control scaled by ``scales``, None: all 1; one piece for a repeated state),
    its own states kept: OMPL's ``PathGeometric::interpolate()``. A path of fewer than two
    states is returned as it is."""
    path = np.asarray(path, dtype=float)
    weights = np.ones(path.shape[1]) if scales is None else np.asarray(scales, dtype=float)
    if not (math.isfinite(longest) and longest > 0):
        raise PlanningError(f"longest segment {longest!r} must be positive")
    if len(path) < 2:
        return path.copy()
    pieces = [path[:1]]
    for a, b in zip(path[:-1], path[1:]):
        count = max(1, math.ceil(float(np.linalg.norm((b - a) * weights)) / longest))
        fractions = np.arange(1, count + 1, dtype=float)[:, None] / count
        inner = a + fractions[:-1] * (b - a)
        pieces += [inner, b[None, :]]       # b itself, not a + 1.0 (b - a): no rounding
    return np.concatenate(pieces)


def kautham_path(path: np.ndarray, planner: str, range_: Optional[float] = None,
                 scales: Optional[Sequence[float]] = None) -> np.ndarray:
    """A search's path (n, k) (``GeometricResult.path``, simplified as the search's settings
    asked) interpolated as Kautham does after its simplification (module docstring), in the
    search's metric (``GeometricResult.scales``)."""
    path = np.asarray(path, dtype=float)
    if len(path) < 2:
        return path.copy()
    return interpolate(path, longest_segment(path.shape[1], planner, range_, scales), scales)


def ompl_rows_text(rows: Sequence[Sequence[float]]) -> str:
    """``rows`` (``geometric.task_rows``) as printAsMatrix lays them out (module docstring)."""
    return "".join("".join(f"{float(v)!r} " for v in row) + "\n" for row in rows) + "\n"


def write_ompl_rows(path, rows: Sequence[Sequence[float]]) -> None:
    """Writes ``rows`` as OMPL rows, through a file beside it renamed into place (a reader
    never sees half a file)."""
    target = pathlib.Path(path)
    part = target.with_name(f".{target.name}.{os.getpid()}.part")
    try:
        part.write_text(ompl_rows_text(rows))
        os.replace(part, target)
    finally:
        part.unlink(missing_ok=True)


__all__ = ["LONGEST_SEGMENT_FRACTION", "RANGE_STEP_PLANNERS", "RANGE_STEP_STATES",
           "interpolate", "kautham_path", "longest_segment", "ompl_rows_text",
           "write_ompl_rows"]
