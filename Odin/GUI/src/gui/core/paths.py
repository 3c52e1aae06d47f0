"""Path files (thesis 7.4.3) and what they become: Set Position and Set Velocity data.

A path file is plain text, one configuration per line: the values of the robot's movable
joints in the robot file's order, separated by spaces, tabs or commas. Blank lines and lines
starting with '#' are skipped. Units: 2012 Kautham files are in degrees (and mm for prismatic
joints), current ones in radians (and m); ``read_path(..., units=...)`` converts to SI. A Kautham
task file (``<Conf>`` elements, current format, radians) is read too. Velocity paths hold one
motor-speed row per publication cycle (deg/s or rad/s; mm/s or m/s).

- Initial position: one row -> forward kinematics -> one Set Position with every link.
- Position path: each row -> one Set Position per cycle.
- Velocity path: each row -> one Set Velocity (all motors) per cycle.
- "Double path precision": ``double_precision(rows)`` inserts the midpoint between consecutive
  rows (linear interpolation, thesis 8.3); apply it n times for 2^n finer paths.
- Jumps: a position path row that moves a joint further than MAX_ROW_JUMP (revolute) or
  MAX_ROW_SLIDE (prismatic) from the row before (``check_row_jumps``), or its first row from
  where the robot is (``check_first_row``), is refused, with a hint when the file's values look
  like the other unit (a radian path read in degrees is the usual cause).
"""
from __future__ import annotations

import math
import os
import pathlib
import re
from dataclasses import dataclass
from typing import Optional

import numpy as np

from gui.core.sizes import read_input_file
from gui.errors import PathFileError
from gui.core.kautham.xmlfile import parse_xml_bytes
from gui.core.model import PRISMATIC

DEGREES, RADIANS = "degrees", "radians"

MAX_ROW_JUMP = 0.5
"""rad: the most a revolute joint may move in one row of a position path (12.5 rad/s at the
world's 25 Hz, beyond any robot's joint speed Odin drives)."""

MAX_ROW_SLIDE = 0.1
"""m: the most a prismatic joint may move in one row of a position path (2.5 m/s at 25 Hz),
well under the 57-fold factor a value read in the wrong unit makes (mm read as m: 1000)."""

_ONE_TURN = 2.0 * math.pi
"""rad: revolute values all within it look like radians; one past it looks like degrees."""
_SPLIT = re.compile(r"[\s,;]+")


def read_path(path: os.PathLike | str, n_values: Optional[int] = None) -> np.ndarray:
    """Rows of numbers as written in the file (no unit conversion): (rows, n_values).

    Every row must have ``n_values`` numbers (or as many as the first row)."""
    return read_rows(path, n_values)[0]


def read_rows(path: os.PathLike | str, n_values: Optional[int] = None,
              meaning: str = "one per movable joint", data: Optional[bytes] = None) -> tuple:
    """``read_path``'s rows and the line each came from; ``meaning`` says what a row holds
    (for the error of a row of the wrong length). ``data``: the file's bytes when the caller
    has read them (``gui.core.sizes.read_input_file``), else the file is read here."""
    p = pathlib.Path(path)
    if data is None:
        data = read_input_file(p, "path file", PathFileError)
    text = data.decode(errors="replace")
    if text.lstrip().startswith("<"):
        root = parse_xml_bytes(data, str(p))
        lines = [(c.line, c.text) for c in _iter(root) if c.tag == "Conf"]
    else:
        lines = list(enumerate(text.splitlines(), start=1))
    rows, numbers = [], []
    for number, line in lines:
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        parts = [t for t in _SPLIT.split(line) if t]
        try:
            row = [float(t) for t in parts]
        except ValueError:
            bad = next(t for t in parts if not _is_number(t))
            raise PathFileError(f"{bad!r} is not a number", p, number) from None
        if not all(math.isfinite(v) for v in row):
            raise PathFileError("a value is not finite", p, number)
        expected = n_values if n_values is not None else (len(rows[0]) if rows else len(row))
        if len(row) != expected:
            raise PathFileError(f"{len(row)} values, expected {expected} ({meaning})", p,
                                number)
        rows.append(row)
        numbers.append(number)
    if not rows:
        raise PathFileError("holds no row of values", p)
    return np.array(rows, dtype=float), numbers


def _is_number(token: str) -> bool:
    try:
        float(token)
        return True
    except ValueError:
        return False


def _iter(node):
    yield node
    for child in node.children:
        yield from _iter(child)


def to_si(rows: np.ndarray, joint_kinds: list, units: str) -> np.ndarray:
    """Converts rows in ``units`` (DEGREES: deg and mm; RADIANS: rad and m) to rad and m."""
    if units == RADIANS:
        return np.asarray(rows, dtype=float)
    if units != DEGREES:
        raise ValueError(f"units must be {DEGREES!r} or {RADIANS!r}, not {units!r}")
    factors = np.array([0.001 if kind == PRISMATIC else math.pi / 180.0
                        for kind in joint_kinds])
    return np.asarray(rows, dtype=float) * factors


def double_precision(rows: np.ndarray) -> np.ndarray:
    """Inserts the midpoint between every two consecutive rows: n rows -> 2n - 1."""
    rows = np.asarray(rows, dtype=float)
    if len(rows) < 2:
        return rows.copy()
    out = np.empty((2 * len(rows) - 1, rows.shape[1]))
    out[0::2] = rows
    out[1::2] = 0.5 * (rows[:-1] + rows[1:])
    return out


def refine(rows: np.ndarray, times: int) -> np.ndarray:
    for _ in range(times):
        rows = double_precision(rows)
    return rows


def load_robot_path(path: os.PathLike | str, handle, units: str) -> np.ndarray:
    """Reads a path file for the robot ``handle`` (gui.core.plan.RobotHandle) in SI units."""
    return read_robot_path(path, handle, units).rows


@dataclass(frozen=True)
class RobotPath:
    """A path file read for one robot: ``rows`` in rad and m, ``written`` as in the file (in
    ``units``), ``lines`` (1-based) each row came from, the movable joints' ``names`` and
    ``kinds`` (gui.core.model's REVOLUTE, PRISMATIC) in the columns' order."""
    path: str
    rows: np.ndarray
    written: np.ndarray
    lines: list
    units: str
    names: list
    kinds: list


def read_robot_path(path: os.PathLike | str, handle, units: str) -> RobotPath:
    """Reads a path file for the robot ``handle`` (gui.core.plan.RobotHandle), ``units`` as
    ``to_si`` takes them."""
    model = handle.instance.model
    kinds = [model.links[i].joint for i in model.movable_links()]
    written, lines = read_rows(path, len(kinds))
    return RobotPath(str(path), to_si(written, kinds, units), written, lines, units,
                     model.joint_names(), kinds)


def check_row_jumps(path: RobotPath) -> None:
    """PathFileError at the first row that moves a joint more than MAX_ROW_JUMP rad
    (revolute) or MAX_ROW_SLIDE m (prismatic) from the row before."""
    steps = np.abs(np.diff(path.rows, axis=0))
    for k, step in enumerate(steps, start=1):
        _check_step(path, k, step, "the row before")


def check_first_row(path: RobotPath, start: np.ndarray) -> None:
    """PathFileError when the first row moves a joint more than the bounds of
    ``check_row_jumps`` from ``start`` (rad / m per movable joint, where the robot is; NaN:
    a joint not known, not compared)."""
    step = np.abs(path.rows[0] - np.asarray(start, dtype=float))
    _check_step(path, 0, np.where(np.isnan(step), 0.0, step), "where the robot is")


def _check_step(path: RobotPath, k: int, step: np.ndarray, before: str) -> None:
    """PathFileError, one line, if row ``k``'s ``step`` (rad / m per joint from ``before``)
    passes its joint's bound."""
    for j, (moved, kind) in enumerate(zip(step, path.kinds)):
        prismatic = kind == PRISMATIC
        bound = MAX_ROW_SLIDE if prismatic else MAX_ROW_JUMP
        if moved <= bound:
            continue
        size = (f"{moved:.3g} m ({moved * 1000:.3g} mm)" if prismatic
                else f"{moved:.3g} rad ({math.degrees(moved):.3g} deg)")
        limit = (f"{bound:g} m (MAX_ROW_SLIDE)" if prismatic
                 else f"{bound:g} rad (MAX_ROW_JUMP)")
        raise PathFileError(f"joint {path.names[j]} moves {size} in one row from {before}, "
                            f"more than {limit}{_unit_hint(path)}; --allow-jumps to run it "
                            f"anyway", path.path, path.lines[k])


def _unit_hint(path: RobotPath) -> str:
    """"; the path is read in X: --Y if it is in Y" when its revolute values look like Y
    (all within one turn: radians; one past it: degrees), else ""."""
    revolute = [j for j, kind in enumerate(path.kinds) if kind != PRISMATIC]
    if not revolute:
        return ""
    largest = float(np.max(np.abs(path.written[:, revolute])))
    if path.units == DEGREES and largest <= _ONE_TURN:
        return ("; the path is read in degrees (--degrees, a 2012 problem's default): "
                "--radians if it is in radians")
    if path.units == RADIANS and largest > _ONE_TURN:
        return ("; the path is read in radians (--radians, a current problem's default): "
                "--degrees if it is in degrees")
    return ""
