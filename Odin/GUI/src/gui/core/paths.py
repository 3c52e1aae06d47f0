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
- Several robots, mobile bases (``read_robot_paths``): a row may carry, per robot, its base's
  position first (``base_axes``: the axes X, Y, Z its Kautham controls move, in that order, m,
  world frame; m/s in a velocity path), then its movable joints, as Kautham's controls order
  a robot's DOFs. A row as long as every robot's columns holds them all, robot after robot in
  the problem's order; otherwise it is one robot's (``run_path --robot``, the first by
  default). A base whose columns a row does not carry stays where it is when the path starts
  (``RobotRows.base_pose``): a row moves a base along its columns only, its orientation and
  other axes kept.
- "Double path precision": ``double_precision(rows)`` inserts the midpoint between consecutive
  rows (linear interpolation, thesis 8.3); apply it n times for 2^n finer paths.
- Jumps: a position path row that moves a joint further than MAX_ROW_JUMP (revolute) or
  MAX_ROW_SLIDE (prismatic) from the row before (``check_row_jumps``), or its first row from
  where the robot is (``check_first_row``: ``present_joints`` reads it from the world), is
  refused, with a hint when the file's values look like the other unit (a radian path read in
  degrees is the usual cause). The refusal names the user's way to read the other unit or
  run the path anyway (``JumpOptions``): run_path's options, or the window's controls.
"""
from __future__ import annotations

import math
import os
import pathlib
import re
from dataclasses import dataclass
from typing import List, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from gui.core.sizes import read_input_file
from gui.errors import PathFileError
from gui.core.kautham.xmlfile import parse_xml_bytes
from gui.core.model import FREE_BODY, MOBILE, PRISMATIC
from odin_common.rotations import quaternion_to_matrix

DEGREES, RADIANS = "degrees", "radians"

MAX_ROW_JUMP = 0.5
"""rad: the most a revolute joint may move in one row of a position path (12.5 rad/s at the
world's 25 Hz, beyond any robot's joint speed Odin drives)."""

MAX_ROW_SLIDE = 0.1
"""m: the most a prismatic joint may move in one row of a position path (2.5 m/s at 25 Hz),
well under the 57-fold factor a value read in the wrong unit makes (mm read as m: 1000)."""



class JumpOptions(NamedTuple):
    """How the user reads a path in degrees or in radians and runs it past a jump, as a
    refusal of a jump names them (``check_row_jumps``)."""
    degrees: str = "--degrees"
    radians: str = "--radians"
    allow: str = "--allow-jumps"


COMMAND_LINE = JumpOptions()
"""run_path's options."""

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
    ``units``), ``lines`` (1-based) each row came from, the columns' ``names`` and ``kinds``
    (gui.core.model's REVOLUTE, PRISMATIC; a base's column counts as PRISMATIC: m, or mm in
    degrees) in their order: the base's columns first (``base_axes``: 0, 1, 2 for X, Y, Z,
    world frame; none when the file does not move the base), then the movable joints.
    ``robot``: the robot's name."""
    path: str
    rows: np.ndarray
    written: np.ndarray
    lines: list
    units: str
    names: list
    kinds: list
    robot: str = ""
    base_axes: Tuple[int, ...] = ()

    @property
    def joints(self) -> np.ndarray:
        """(n, movable joints): the joints' columns, rad or m (rad/s or m/s)."""
        return self.rows[:, len(self.base_axes):]


def read_robot_path(path: os.PathLike | str, handle, units: str) -> RobotPath:
    """Reads a path file for the robot ``handle`` (gui.core.plan.RobotHandle), ``units`` as
    ``to_si`` takes them."""
    model = handle.instance.model
    kinds = [model.links[i].joint for i in model.movable_links()]
    written, lines = read_rows(path, len(kinds))
    return RobotPath(str(path), to_si(written, kinds, units), written, lines, units,
                     model.joint_names(), kinds, handle.name)


AXES = ("X", "Y", "Z")
"""The base's position DOFs as Kautham's controls name them (world axes in a path's row)."""


def base_axes(handle) -> Tuple[int, ...]:
    """The axes (0, 1, 2: X, Y, Z) of a robot's base a path's row may carry: those its
    Kautham controls move when they drive its base (a FREE_BODY or MOBILE robot, Kautham's
    SE3 base), else none (a held base; a car, which its wheels drive). Its orientation (X1,
    X2, X3: Kuffner's parameters, not an angle) is not a column: as a control path does, Odin
    moves a base's position and keeps its orientation."""
    controls = handle.instance.controls
    if handle.kind not in (FREE_BODY, MOBILE) or controls is None or not controls.se3:
        return ()
    return tuple(controls.moved_base_axes())


def read_robot_paths(path: os.PathLike | str, handles: Sequence, units: str,
                     robot: Optional[str] = None) -> List[RobotPath]:
    """A position or velocity path file for a problem's robots (``handles``: their
    gui.core.plan.RobotHandle, robots only, the problem's order), one RobotPath per robot it
    drives (module docstring): a row as long as every robot's columns (each robot with its
    base's, or every robot without) drives them all; else one robot's, ``robot``'s (the
    first by default), with or without its base's columns. ``units`` as ``to_si`` takes
    them. A row of another length is refused with the lengths it could have."""
    p = pathlib.Path(path)
    chosen = next((h for h in handles if robot in (None, h.name)), None)
    if chosen is None:
        raise PathFileError(f"no robot named {robot!r} (robots: "
                            + ", ".join(h.name for h in handles) + ")", p)
    written, lines = read_rows(p)
    driven = [h for h in handles if _columns(h, True)[0]]
    layouts = []                 # (handle, with its base's columns?) per robot, in order
    if len(driven) > 1:
        layouts += [[(h, True) for h in driven], [(h, False) for h in driven]]
    layouts += [[(chosen, True)], [(chosen, False)]]
    widths = [sum(len(_columns(h, base)[0]) for h, base in layout) for layout in layouts]
    if written.shape[1] not in widths:
        seen, expected = set(), []
        for width, layout in zip(widths, layouts):
            if width not in seen and width:
                seen.add(width)
                expected.append(f"{width} ({_describe(layout)})")
        if not expected:
            raise PathFileError(f"robot {chosen.name} has no joint and no base a row could "
                                "move", p, lines[0])
        raise PathFileError(f"{written.shape[1]} values, expected " + " or ".join(expected),
                            p, lines[0])
    layout = layouts[widths.index(written.shape[1])]
    out, k = [], 0
    for handle, base in layout:
        names, kinds = _columns(handle, base)
        axes = base_axes(handle) if base else ()
        if len(layout) > 1:          # two robots' joints may have the same names
            names = names[:len(axes)] + [f"{handle.name}/{n}" for n in names[len(axes):]]
        part = written[:, k:k + len(names)]
        k += len(names)
        out.append(RobotPath(str(p), to_si(part, kinds, units), part, lines, units, names,
                             kinds, handle.name, axes))
    return out


def _columns(handle, base: bool) -> Tuple[list, list]:
    """(names, kinds) of a robot's columns in a row: its base's axes (when ``base``), then
    its movable joints."""
    model = handle.instance.model
    axes = base_axes(handle) if base else ()
    return ([AXES[a] for a in axes] + model.joint_names(),
            [PRISMATIC] * len(axes) + [model.links[i].joint for i in model.movable_links()])


def _describe(layout) -> str:
    """"every robot: a: base X Y, 2 joints + b: 2 joints", "a: 2 joints"."""
    text = " + ".join(
        f"{h.name}: " + (f"base {' '.join(AXES[a] for a in base_axes(h))}, "
                         if base and base_axes(h) else "")
        + f"{len(h.instance.model.movable_links())} joints" for h, base in layout)
    return f"every robot: {text}" if len(layout) > 1 else text


def base_link_pose(handle, position: Sequence[float], quaternion: Sequence[float]
                   ) -> np.ndarray:
    """(4, 4), world: the pose of ``handle``'s base link when its base body is at
    ``position`` (m, world) and ``quaternion`` (w, x, y, z, world)."""
    body = np.eye(4)
    body[:3, :3] = quaternion_to_matrix(np.asarray(quaternion, dtype=float))
    body[:3, 3] = position
    return body @ np.linalg.inv(handle.bodies[0].offset)


@dataclass(frozen=True)
class RobotRows:
    """One robot's rows as a position or velocity path sends them: its plan ``handle``,
    ``rows`` (n, b + j) in SI, its base's columns first (``base_axes``, world frame), and
    ``base_pose`` (4, 4, world): where its base is when the path starts. A position row
    places the base there, moved along its columns only (its orientation and other axes
    kept); a velocity row gives the base the velocity of its columns (0 along the other
    axes, its turn unchanged)."""
    handle: object
    rows: np.ndarray
    base_axes: Tuple[int, ...] = ()
    base_pose: Optional[np.ndarray] = None

    def situations(self, k: int) -> list:
        """Row ``k``'s Set Position: (body ID, position m, quaternion (w, x, y, z)), world
        frame, of every link (the base where the robot was built without ``base_pose``)."""
        row = self.rows[k]
        base = np.array(self.handle.base_pose if self.base_pose is None else self.base_pose,
                        dtype=float)
        for column, axis in enumerate(self.base_axes):
            base[axis, 3] = row[column]
        return self.handle.situations(row[len(self.base_axes):], base)

    def speeds(self, k: int) -> np.ndarray:
        """Row ``k``'s motor speeds (rad/s or m/s, one per movable joint)."""
        return self.rows[k, len(self.base_axes):]

    def base_velocity(self, k: int) -> Optional[Tuple[str, Tuple[float, float, float]]]:
        """Row ``k``'s (base body ID, linear velocity m/s world), None without base columns."""
        if not self.base_axes:
            return None
        velocity = np.zeros(3)
        velocity[list(self.base_axes)] = self.rows[k, :len(self.base_axes)]
        return self.handle.bodies[0].body_id, tuple(float(v) for v in velocity)


def check_row_jumps(path: RobotPath, options: JumpOptions = COMMAND_LINE) -> None:
    """PathFileError at the first row that moves a joint more than MAX_ROW_JUMP rad
    (revolute) or MAX_ROW_SLIDE m (prismatic) from the row before; its message names
    ``options`` (the other unit, running it anyway)."""
    steps = np.abs(np.diff(path.rows, axis=0))
    for k, step in enumerate(steps, start=1):
        _check_step(path, k, step, "the row before", options)


def check_first_row(path: RobotPath, start: np.ndarray,
                    options: JumpOptions = COMMAND_LINE) -> None:
    """PathFileError when the first row moves a joint more than the bounds of
    ``check_row_jumps`` from ``start`` (rad / m per movable joint, where the robot is; NaN:
    a joint not known, not compared)."""
    step = np.abs(path.rows[0] - np.asarray(start, dtype=float))
    _check_step(path, 0, np.where(np.isnan(step), 0.0, step), "where the robot is", options)


def present_joints(world, handle) -> np.ndarray:
    """Where the robot ``handle`` (gui.core.plan.RobotHandle) has its movable joints in
    ``world`` (rad / m; a gui.ros.client.WorldClient or a gui.core.world_port.WorldPort:
    its ``joint_positions``): ``built_at`` plus each world joint's reading; NaN for a joint
    the world does not read as its first value (a car's wheel spin) or holds no joint for."""
    present = np.full(len(handle.built_at), np.nan)
    ids = list(handle.joint_ids)
    axes = list(handle.joint_axes) or [0] * len(ids)
    readings = world.joint_positions(ids)
    for j, (value, axis) in enumerate(zip(readings, axes)):
        if axis == 0:
            present[j] = handle.built_at[j] + value
    return present


def _check_step(path: RobotPath, k: int, step: np.ndarray, before: str,
                options: JumpOptions) -> None:
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
        what = (f"the base of {path.robot} along {path.names[j]}" if j < len(path.base_axes)
                else f"joint {path.names[j]}")      # a base's column: bound as prismatic
        raise PathFileError(f"{what} moves {size} in one row from {before}, "
                            f"more than {limit}{_unit_hint(path, options)}; {options.allow} "
                            f"to run it anyway", path.path, path.lines[k])


def _unit_hint(path: RobotPath, options: JumpOptions) -> str:
    """"; the path is read in X: --Y if it is in Y" (``options``' names) when its revolute
    values look like Y (all within one turn: radians; one past it: degrees), else ""."""
    revolute = [j for j, kind in enumerate(path.kinds) if kind != PRISMATIC]
    if not revolute:
        return ""
    largest = float(np.max(np.abs(path.written[:, revolute])))
    if path.units == DEGREES and largest <= _ONE_TURN:
        return (f"; the path is read in degrees ({options.degrees}, a 2012 problem's "
                f"default): {options.radians} if it is in radians")
    if path.units == RADIANS and largest > _ONE_TURN:
        return (f"; the path is read in radians ({options.radians}, a current problem's "
                f"default): {options.degrees} if it is in degrees")
    return ""
