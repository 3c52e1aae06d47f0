"""Kautham's plans as paths Odin can execute: one path of waypoints per robot, in SI joint
space, with the attach/detach events of a task (ROS-free).

``read_solution(path, problem, robot=None, units=None)`` recognises the file by its content:

- a legacy solution file (``.kps``, Kautham 2012's ``Planner::saveData``): a root ``<Planner>``
  holding ``<SampleSet>`` (``<Sample>`` rows of normalised control values in [0, 1]) and
  ``<Queries>``; the first ``<Query Solved="True">``'s ``<Result name="Path">`` lists sample
  indices. A sample is a control vector as the query's ``<Init>`` is
  (``gui.core.kautham.controls.control_parts``): every robot's controls (a current problem's
  robots share one vector; a 2012 problem's take theirs end to end, robot order), each
  robot's share mapped through its controls and limits; in a 2012 problem of several robots
  a sample as long as one robot's controls is that robot's alone (``robot``'s, the first
  by default), the others not moved by the plan. The query's ``Init`` and ``Goal`` are
  indices into the ``<SampleSet>`` (``Planner::loadData`` sets its start and goal samples from
  them and moves the robots to the path's first sample): the path runs from ``Init`` to
  ``Goal``, which may be the problem's query reversed, so a file whose path starts or ends
  elsewhere is refused (``Solution.query``);
- a task file (current Kautham, ``PlannerWidget::saveDataOMPL`` / ``taskmotionPathLoad``): a
  root ``<Task>`` of ``<Transit>``, ``<Transfer object robot link>`` and ``<MultiTransfer
  numobjects object1.. robot link>`` sections holding ``<Conf>`` rows. ``robot`` and ``link``
  are indices (the problem's robot order, the robot's link order with the base as 0) or
  names. The object is attached at the section's first row and detached at its last.
  ``<Initialstate>`` (obstacle poses) is refused: Odin builds obstacles where the problem
  puts them;
- OMPL's path output (``PathGeometric::printAsMatrix``, Kautham's ``getPath``): plain rows;
- raw rows of one robot's movable joints (the thesis's path files, ``gui.core.paths``), or of
  every robot's, end to end in robot order.

A ``<Conf>`` row and an OMPL row are a mapped configuration of every robot in the problem's
order (Kautham's ``loadSampleFromLine``): for a robot whose controls move its base (Kautham's
``isSE3Enabled``), 7 values x y z (m, world) qx qy qz qw (its base's orientation, world,
x y z w as Kautham and OMPL write it); then one value per joint of the robot (rad or m), every
link but the base counted, fixed ones too (Kautham's ``getNumJoints``; the values of fixed
joints are read and dropped). A row with only the movable joints' values per robot is read
too. Plain rows of a 2012 problem are raw rows (degrees and mm unless ``units`` says
otherwise); of a current problem, OMPL rows when their length is the problem's layout (and
not ``robot``'s movable joints), raw rows otherwise.

``robot`` names the robot a file of one robot's values drives (default: the first); a file
of every robot's (a task file, OMPL rows, a .kps sample of all the controls, raw rows of
all the robots) drives every robot it holds whatever ``robot`` says: ``Solution.paths`` says
which robots a plan moves (``run_path --robot`` with a plan of several robots is refused).

Any malformed or mismatched file raises ``PathFileError`` naming the file and the row's line;
nothing is returned in part.
"""
from __future__ import annotations

import math
import os
import pathlib
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from gui.core.kautham.controls import control_parts
from gui.core.kautham.xmlfile import Node, parse_xml_bytes
from gui.core.model import Instance, Problem
from gui.core.paths import DEGREES, RADIANS, read_rows, to_si
from gui.core.sizes import read_input_file
from gui.errors import PathFileError, ProblemError
from odin_common.rotations import quaternion_to_matrix

KPS, TASK, OMPL, ROWS = "kps", "task", "ompl", "rows"
SE3_VALUES = 7
"""x y z qx qy qz qw: a robot's base in a mapped configuration row."""
ATTACH, DETACH = "attach", "detach"


@dataclass(frozen=True, eq=False)
class RobotWaypoints:
    """One robot's path: ``joints`` (n, d) rad or m, its movable joints in
    ``RobotModel.movable_links()`` order; ``base_poses`` (n, 4, 4) world poses of its base
    (None: the file does not move the base); ``lines`` the file line of each waypoint."""
    robot: str
    joints: np.ndarray
    base_poses: Optional[np.ndarray]
    lines: Tuple[int, ...]


@dataclass(frozen=True)
class AttachEvent:
    """At waypoint ``index`` (the same index in every robot's path), ``action`` (ATTACH or
    DETACH) ``obstacle`` to / from ``link`` of ``robot`` (instance and link names)."""
    index: int
    action: str
    robot: str
    link: str
    obstacle: str
    line: int


@dataclass(frozen=True)
class KpsQuery:
    """A ``.kps`` query: the indices of its ``Init`` and ``Goal`` samples in the file's
    ``<SampleSet>`` (where its path starts and ends) and the ``<Query>``'s line."""
    init: int
    goal: int
    line: int

    def describe(self) -> str:
        """"sample i to sample g"."""
        return f"sample {self.init} to sample {self.goal}"


@dataclass(frozen=True, eq=False)
class Solution:
    """What a plan file holds: ``format`` (KPS, TASK, OMPL or ROWS), one ``RobotWaypoints``
    per robot it moves (same number of waypoints each), its attach/detach events and, for a
    ``.kps`` whose query names them, the query's samples (``KpsQuery``)."""
    source: str
    format: str
    paths: Dict[str, RobotWaypoints]
    events: Tuple[AttachEvent, ...] = ()
    query: Optional[KpsQuery] = None

    @property
    def waypoint_count(self) -> int:
        return len(next(iter(self.paths.values())).joints)


def read_solution(path: os.PathLike | str, problem: Problem, robot: Optional[str] = None,
                  units: Optional[str] = None) -> Solution:
    """The plan in ``path`` for ``problem`` (module docstring); ``robot``: the robot raw rows
    drive (default: the first); ``units``: DEGREES or RADIANS for raw rows (default: degrees
    for 2012 problems, radians otherwise)."""
    p = pathlib.Path(path)
    if not problem.robots:
        raise PathFileError(f"problem {problem.source} has no robot to move", p)
    if robot is not None:
        _robot(p, problem, robot)               # a name that is no robot's: said first
    data = read_input_file(p, "path file", PathFileError)
    text = data.decode(errors="replace")
    if text.lstrip().startswith("<"):
        root = _parse_xml(p, data)
        if root.tag == "Planner" or root.find("SampleSet") is not None:
            return _read_kps(p, root, problem, robot)
        if root.tag == "Task":
            return _read_task(p, root, problem)
        raise PathFileError(f"root element <{root.tag}> is neither a Kautham solution "
                            "(<Planner> with <SampleSet>) nor a task file (<Task>)", p,
                            root.line)
    return _read_plain_rows(p, data, problem, robot, units)


def _parse_xml(p: pathlib.Path, data: bytes) -> Node:
    try:
        return parse_xml_bytes(data, str(p))
    except PathFileError:
        raise
    except ProblemError as error:
        raise PathFileError(error.reason, p, error.line) from None


# -- legacy .kps ---------------------------------------------------------------------------------
def _read_kps(p: pathlib.Path, root: Node, problem: Problem, robot: Optional[str]
              ) -> Solution:
    sample_set = root.find("SampleSet")
    if sample_set is None:
        raise PathFileError("<Planner> holds no <SampleSet>: no configuration", p, root.line)
    samples = list(sample_set.findall("Sample"))
    query_node, result = _kps_path_result(p, root)
    try:
        indices = [int(t) for t in result.text.split()]
    except ValueError:
        raise PathFileError(f"<Result name=\"Path\"> holds {result.text.strip()!r}, not "
                            "sample indices", p, result.line) from None
    if not indices:
        raise PathFileError("<Result name=\"Path\"> lists no sample", p, result.line)
    query = _kps_query(p, query_node, indices, len(samples))
    parts = _mapped_robots(p, problem)
    vectors, lines = [], []
    for index in indices:
        if not 0 <= index < len(samples):
            raise PathFileError(f"sample index {index} is not in the <SampleSet> (0.."
                                f"{len(samples) - 1})", p, result.line)
        sample = samples[index]
        values = _numbers(p, sample)
        if not vectors:                 # the path's first sample says whose controls it holds
            parts = _sample_robots(p, parts, robot, len(values), index, sample.line)
        size = max(part.stop for _, part in parts)
        if len(values) != size:
            raise PathFileError(f"<Sample> {index} has {len(values)} values, the controls are "
                                f"{size} ({_describe_parts(parts)})", p, sample.line)
        if not all(0.0 <= v <= 1.0 for v in values):
            raise PathFileError(f"<Sample> {index} holds values outside [0, 1] (normalised "
                                "controls)", p, sample.line)
        vectors.append(values)
        lines.append(sample.line)
    paths = {}
    for instance, part in parts:
        configurations = [instance.controls.configuration(instance, v[part]) for v in vectors]
        base = None
        if instance.controls.se3:
            base = np.array([c.base_pose for c in configurations])
        paths[instance.name] = RobotWaypoints(
            instance.name, np.array([c.joints for c in configurations], dtype=float), base,
            tuple(lines))
    return Solution(str(p), KPS, paths, query=query)


def _kps_query(p: pathlib.Path, query: Node, path: Sequence[int],
               sample_count: int) -> Optional[KpsQuery]:
    """The query's Init and Goal sample indices (None when it names neither), checked
    against the SampleSet and the path's ends."""
    named = {}
    for name in ("Init", "Goal"):
        raw = query.get(name)
        if raw is None:
            continue
        try:
            named[name] = int(raw.strip())
        except ValueError:
            raise PathFileError(f"<Query {name}=\"{raw}\">: not a sample index", p,
                                query.line) from None
        if not 0 <= named[name] < sample_count:
            raise PathFileError(f"<Query {name}=\"{raw}\">: no such sample in the "
                                f"<SampleSet> (0..{sample_count - 1})", p, query.line)
    if not named:
        return None
    init, goal = named.get("Init", path[0]), named.get("Goal", path[-1])
    if (path[0], path[-1]) != (init, goal):
        raise PathFileError(f"the query runs from sample {init} to sample {goal}, its path "
                            f"from sample {path[0]} to sample {path[-1]}", p, query.line)
    return KpsQuery(init, goal, query.line)


def _kps_path_result(p: pathlib.Path, root: Node) -> Tuple[Node, Node]:
    """(the first solved ``<Query>``, its ``<Result name="Path">``)."""
    queries = root.find("Queries")
    found = list(queries.findall("Query")) if queries is not None else []
    if not found:
        raise PathFileError("holds no configuration: no <Queries>/<Query> with a "
                            "<Result name=\"Path\">", p, root.line)
    for query in found:
        if query.get("Solved", "True").strip().lower() == "false":
            continue
        for result in query.findall("Result"):
            if result.get("name", "").strip() == "Path":
                return query, result
    raise PathFileError("no solved <Query> has a <Result name=\"Path\">", p, found[0].line)


def _mapped_robots(p: pathlib.Path, problem: Problem) -> List[Tuple[Instance, slice]]:
    """The robots with controls and their slices of a sample (``control_parts``)."""
    parts = control_parts(problem.robots, legacy=problem.format == "2012")
    if not parts:
        raise PathFileError(f"no robot of {problem.source} has controls to map the file's "
                            "normalised samples through", p)
    return parts


def _sample_robots(p: pathlib.Path, parts: List[Tuple[Instance, slice]], robot: Optional[str],
                   size: int, index: int, line: int) -> List[Tuple[Instance, slice]]:
    """Whose controls a sample of ``size`` values holds: every robot's (``parts``) when it
    is as long as their vector, else ``robot``'s (the first robot with controls by default)
    when as long as its own controls (a 2012 problem's robots each have theirs)."""
    every = max(part.stop for _, part in parts)
    if size == every:
        return parts
    chosen = next((r for r, _ in parts if robot in (None, r.name)), None)
    if chosen is not None and size == chosen.controls.size:
        return [(chosen, slice(0, size))]
    one = "" if chosen is None or chosen.controls.size == every else \
        f", or {chosen.controls.size} ({chosen.name}'s: {', '.join(chosen.controls.names)})"
    raise PathFileError(f"<Sample> {index} has {size} values, the controls are {every} "
                        f"({_describe_parts(parts)}){one}", p, line)


def _describe_parts(parts: List[Tuple[Instance, slice]]) -> str:
    """The controls of a sample of ``parts``: their names, by robot when several share it
    end to end."""
    if len(parts) == 1 or parts[-1][1].start == 0:      # one robot, or a shared vector
        return ", ".join(parts[0][0].controls.names)
    return " + ".join(f"{r.name}: {r.controls.size}" for r, _ in parts)


def _numbers(p: pathlib.Path, node: Node) -> List[float]:
    out = []
    for token in node.text.split():
        try:
            value = float(token)
        except ValueError:
            raise PathFileError(f"{token!r} is not a number in <{node.tag}>", p,
                                node.line) from None
        if not math.isfinite(value):
            raise PathFileError(f"a value of <{node.tag}> is not finite", p, node.line)
        out.append(value)
    return out


# -- task files ----------------------------------------------------------------------------------
def _read_task(p: pathlib.Path, root: Node, problem: Problem) -> Solution:
    layout = RowLayout.of(problem)
    rows, lines, events = [], [], []
    for section in root.children:
        if section.tag == "Transit":
            objects: List[str] = []
        elif section.tag == "Transfer":
            objects = [_required(p, section, "object")]
        elif section.tag == "MultiTransfer":
            objects = _multi_objects(p, section)
        elif section.tag == "Initialstate":
            raise PathFileError("<Initialstate> (obstacle poses) is not supported: Odin "
                                "builds obstacles where the problem puts them", p,
                                section.line)
        else:
            raise PathFileError(f"<{section.tag}> in a <Task>: expected <Transit>, "
                                "<Transfer> or <MultiTransfer>", p, section.line)
        confs = [c for c in section.children if c.tag == "Conf"]
        if not confs:
            raise PathFileError(f"<{section.tag}> holds no <Conf>", p, section.line)
        first = len(rows)
        for conf in confs:
            rows.append(_numbers(p, conf))
            lines.append(conf.line)
        if objects:
            robot, link = _transfer_target(p, section, problem)
            for name in objects:
                _check_obstacle(p, section, problem, name)
                events.append(AttachEvent(first, ATTACH, robot, link, name, section.line))
                events.append(AttachEvent(len(rows) - 1, DETACH, robot, link, name,
                                          section.line))
    if not rows:
        raise PathFileError("<Task> holds no <Conf> row", p, root.line)
    return Solution(str(p), TASK, layout.split(p, rows, lines), tuple(events))


def _required(p: pathlib.Path, node: Node, name: str) -> str:
    value = node.get(name)
    if value is None or not value.strip():
        raise PathFileError(f"<{node.tag}> has no {name}=\"...\"", p, node.line)
    return value.strip()


def _multi_objects(p: pathlib.Path, node: Node) -> List[str]:
    raw = _required(p, node, "numobjects")
    if not raw.isdigit() or int(raw) < 1:
        raise PathFileError(f"numobjects=\"{raw}\" is not a positive count", p, node.line)
    return [_required(p, node, f"object{k}") for k in range(1, int(raw) + 1)]


def _transfer_target(p: pathlib.Path, node: Node, problem: Problem) -> Tuple[str, str]:
    """(robot instance name, link name) of a Transfer: indices (Kautham's) or names."""
    robots = problem.robots
    raw = _required(p, node, "robot")
    if raw.isdigit():
        if int(raw) >= len(robots):
            raise PathFileError(f"robot=\"{raw}\": the problem has {len(robots)} robots", p,
                                node.line)
        instance = robots[int(raw)]
    else:
        instance = next((r for r in robots if raw in (r.name, r.model.name)), None)
        if instance is None:
            raise PathFileError(f"robot=\"{raw}\": no such robot (robots: "
                                + ", ".join(r.name for r in robots) + ")", p, node.line)
    links = instance.model.links
    raw = _required(p, node, "link")
    if raw.isdigit():
        if int(raw) >= len(links):
            raise PathFileError(f"link=\"{raw}\": robot {instance.name} has {len(links)} "
                                "links", p, node.line)
        return instance.name, links[int(raw)].name
    if raw not in [link.name for link in links]:
        raise PathFileError(f"link=\"{raw}\": robot {instance.name} has no such link", p,
                            node.line)
    return instance.name, raw


def _check_obstacle(p: pathlib.Path, node: Node, problem: Problem, name: str) -> None:
    if not any(name in (o.name, o.model.name) for o in problem.obstacles):
        raise PathFileError(f"object \"{name}\": no such obstacle (obstacles: "
                            + ", ".join(o.name for o in problem.obstacles) + ")", p, node.line)


# -- mapped configuration rows (task files, OMPL) ------------------------------------------------
@dataclass(frozen=True)
class RowLayout:
    """How a mapped configuration row splits per robot: (instance, SE3 prefix?, joint count
    written, indices of the movable joints among them)."""
    robots: Tuple[Tuple[Instance, bool, int, Tuple[int, ...]], ...]

    @staticmethod
    def of(problem: Problem, movable_only: bool = False) -> "RowLayout":
        entries = []
        for instance in problem.robots:
            se3 = instance.controls is not None and instance.controls.se3
            model = instance.model
            movable = model.movable_links()
            if movable_only:
                entries.append((instance, se3, len(movable), tuple(range(len(movable)))))
            else:               # every link but the base: movable link i is value i - 1
                entries.append((instance, se3, len(model.links) - 1,
                                tuple(i - 1 for i in movable)))
        return RowLayout(tuple(entries))

    @property
    def size(self) -> int:
        return sum((SE3_VALUES if se3 else 0) + n for _, se3, n, _ in self.robots)

    def describe(self) -> str:
        return " + ".join(f"{i.name}: " + ("7 (x y z qx qy qz qw) + " if se3 else "")
                          + f"{n} joints" for i, se3, n, _ in self.robots)

    def split(self, p: pathlib.Path, rows: Sequence[Sequence[float]],
              lines: Sequence[int]) -> Dict[str, RobotWaypoints]:
        """One RobotWaypoints per robot from rows of this layout (the other layout, movable
        joints only, is tried when a row's length is not this one's)."""
        layout = self
        if rows and len(rows[0]) != self.size:
            alternative = RowLayout(tuple((i, se3, len(m), tuple(range(len(m))))
                                          for i, se3, _, m in self.robots))
            if len(rows[0]) == alternative.size:
                layout = alternative
        bases: Dict[str, list] = {i.name: [] for i, *_ in layout.robots}
        joints: Dict[str, list] = {i.name: [] for i, *_ in layout.robots}
        for row, line in zip(rows, lines):
            if len(row) != layout.size:
                raise PathFileError(f"{len(row)} values, expected {layout.size} "
                                    f"({layout.describe()})", p, line)
            k = 0
            for instance, se3, n, movable in layout.robots:
                if se3:
                    bases[instance.name].append(_se3_pose(p, row[k:k + SE3_VALUES], line))
                    k += SE3_VALUES
                values = np.asarray(row[k:k + n], dtype=float)
                joints[instance.name].append(values[list(movable)])
                k += n
        out = {}
        for instance, se3, _, movable in layout.robots:
            _check_limits(p, instance, joints[instance.name], lines)
            out[instance.name] = RobotWaypoints(
                instance.name, np.array(joints[instance.name], dtype=float).reshape(
                    len(rows), len(movable)),
                np.array(bases[instance.name]) if se3 else None, tuple(lines))
        return out


def _se3_pose(p: pathlib.Path, values: Sequence[float], line: int) -> np.ndarray:
    x, y, z, qx, qy, qz, qw = values
    norm = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    if norm < 1e-6:
        raise PathFileError("the base's quaternion (values 4..7, qx qy qz qw) is zero", p, line)
    pose = np.eye(4)
    pose[:3, :3] = quaternion_to_matrix(np.array([qw, qx, qy, qz]) / norm)
    pose[:3, 3] = (x, y, z)
    return pose


LIMIT_SLACK = 1e-6
"""rad or m: how far past a joint's limit a file value may be (rounding in the file)."""


def _check_limits(p: pathlib.Path, instance: Instance, rows: Sequence[np.ndarray],
                  lines: Sequence[int]) -> None:
    model = instance.model
    for k, i in enumerate(model.movable_links()):
        link = model.links[i]
        if link.limits is None:
            continue
        low, high = link.limits
        for row, line in zip(rows, lines):
            if not low - LIMIT_SLACK <= row[k] <= high + LIMIT_SLACK:
                raise PathFileError(f"{instance.name} joint {link.name} = {row[k]:g} is "
                                    f"outside its limits [{low:g}, {high:g}]", p, line)


# -- plain rows ----------------------------------------------------------------------------------
def _read_plain_rows(p: pathlib.Path, data: bytes, problem: Problem, robot: Optional[str],
                     units: Optional[str]) -> Solution:
    """OMPL rows (a current problem's layout, unless as long as ``robot``'s movable joints),
    else raw rows of one robot's movable joints or, as long as every robot's, of all of them
    end to end (module docstring)."""
    instance = _robot(p, problem, robot)
    movable = len(instance.model.movable_links())
    first, _ = read_rows(p, None, data=data)
    width = first.shape[1]
    layout = None
    if problem.format != "2012":
        layout = RowLayout.of(problem)
        if width in (layout.size, RowLayout.of(problem, movable_only=True).size) \
                and (robot is None or width != movable):
            raw, lines = read_rows(p, width, f"a configuration: {layout.describe()}", data)
            return Solution(str(p), OMPL, layout.split(p, raw.tolist(), lines))
    every = [r for r in problem.robots if r.model.movable_links()]
    total = sum(len(r.model.movable_links()) for r in every)
    robots = every if len(every) > 1 and width == total else [instance]
    meaning = f"one per movable joint of {instance.name}"
    if len(every) > 1:
        meaning += f"; {total} for every robot's, end to end"
    if layout is not None:
        meaning += f"; {layout.size} for a configuration: {layout.describe()}"
    raw, lines = read_rows(p, sum(len(r.model.movable_links()) for r in robots), meaning, data)
    unit = units or (DEGREES if problem.format == "2012" else RADIANS)
    paths, k = {}, 0
    for one in robots:
        kinds = [one.model.links[i].joint for i in one.model.movable_links()]
        joints = to_si(raw[:, k:k + len(kinds)], kinds, unit)
        k += len(kinds)
        _check_limits(p, one, list(joints), lines)
        paths[one.name] = RobotWaypoints(one.name, joints, None, tuple(lines))
    return Solution(str(p), ROWS, paths)


def _robot(p: pathlib.Path, problem: Problem, name: Optional[str]) -> Instance:
    for instance in problem.robots:
        if name in (None, instance.name):
            return instance
    raise PathFileError(f"no robot named {name!r} (robots: "
                        + ", ".join(r.name for r in problem.robots) + ")", p)


__all__ = ["KPS", "TASK", "OMPL", "ROWS", "ATTACH", "DETACH", "SE3_VALUES", "RobotWaypoints",
           "AttachEvent", "KpsQuery", "Solution", "RowLayout", "read_solution"]
