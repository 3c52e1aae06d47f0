"""Kautham problem files, 2012 and current, into a ``gui.core.model.Problem`` (SI units).

2012 format (the thesis's)::

    <Problem> <Robot robot="x.rob|x.iv" scale> <Home X Y Z WX WY WZ TH/> <Limits/>... </Robot>
              <Scene scene="x.iv|x.wrl|x.rob" scale movable> <Location .../>
                     <Collision Enable/> </Scene>
              <Planner>...</Planner> </Problem>

Home, Location and Limits positions are in mm and TH in degrees; a robot file that is a bare
shape is a free-flying robot; a scene that is a .rob is a movable obstacle, any other scene a
static one, unless ``movable`` says otherwise (the thesis's ``<Scene movable="false">``). Paths
are relative to the problem file.

Current format (Kautham 5): ``<Robot robot="x.urdf|x.dh" scale>`` and ``<Obstacle
obstacle="x.urdf|x.iv" scale>``, both placed by ``<Home>`` in m and rad (``<KauthamName
name>`` renames one, ``<Collision enabled>`` turns its collisions off), ``<Controls
robot="x.cntr"/>``, ``<InitialAttachedObstacle robot link obstacle/>``. Model files are looked
up in a ``models`` folder beside the problem or any folder above it (Kautham's demos/models),
then beside the problem. An obstacle is a movable body when its URDF gives a mass, static
geometry otherwise; under one of Kautham's ODE planners (``Problem.physics``) every obstacle is
a body, as in Kautham's ODE environment.

A file is of the current format when it has ``<Obstacle>`` or ``<Controls>`` elements or a
.urdf/.dh robot.

The planner and the query: ``<Planner><Parameters><Name>`` says whether Kautham simulates the
problem (its ODE planners) and which robot kind its environment drives; its ERP, CFM, Max
Contacts and PropagationStepSize parameters are read (``Planner.settings``), and its Min/Max
Control Steps, Goal Bias, Max Speed and _Max Planning Time for the planning bridge
(``Planner.search``). The first
``<Query>`` (``<Init>``/``<Goal>`` control vectors, or ``<RobotControl name init goal>``) maps
through the controls (``gui.core.kautham.controls``) to each robot's start and goal
configuration. In a current problem a value Odin uses that is wrong is an error naming the
file and line; in a 2012 problem the query and the planner are informational (Odin builds it at
Home, as the thesis's Odin did) and a quirk there is listed, never an error.

Everything else a problem holds that Odin does not use is listed in ``Problem.ignored`` (and
logged once as a warning), never dropped silently.
"""
from __future__ import annotations

import logging
import os
import pathlib
import re
from typing import List, Optional

import numpy as np

from gui.core.kautham.controls import (BASE_DOFS, LEGACY_OFFSET_DEFAULT, control_map,
                                       control_parts, free_flyer_control_set, read_cntr)
from gui.core.kautham.robot_rob import read_dh_robot, read_shape_robot
from gui.core.kautham.units import LEGACY, SI, Units, scale_problem
from gui.core.kautham.urdf import read_urdf
from gui.core.kautham.xmlfile import Node, parse_number, read_xml
from gui.core.kinematics import pose_from_axis_angle
from gui.core.model import (CAR, FIXED_BASE, FREE_BODY, MOBILE, REVOLUTE, Attachment,
                            Control, ControlSet, Ignored, Instance, Planner, PlannerPhysics,
                            PlannerSearch, Problem, RobotModel, warn_once)
from gui.core.shapes import COIN_SUFFIXES, TRIMESH_SUFFIXES
from gui.errors import ProblemError
from odin_common.limits import shown

log = logging.getLogger("gui.core.kautham")

_NAME_BAD = re.compile(r"[>&]")

PHYSICS_PLANNERS = {
    "KPIECE2DPlanner": FREE_BODY, "RRT2DPlanner": FREE_BODY, "Syclop2DPlanner": FREE_BODY,
    "KnowledgeOrientedKPIECE2DPlanner": FREE_BODY,
    "KnowledgeOrientedRRT2DPlanner": FREE_BODY,
    "KnowledgeOrientedSyclop2DPlanner": FREE_BODY,
    "KPIECECarPlanner": CAR, "KPIECEChainPlanner": FIXED_BASE,
}
"""Kautham's ODE planners and the robot kind the environment each creates drives (its
2D environments push a free body, CarEnvironment drives a car, PlanarChainEnvironment a chain
with a fixed base)."""

PLANNER_PHYSICS = {"Error Reduction Parameter": "erp", "Constraint Force Mixing": "cfm",
                   "Max Contacts": "max_contacts", "PropagationStepSize": "step"}
"""The ODE planners' parameters Odin applies (PlannerPhysics field names)."""
PLANNER_SEARCH = {"Min Control Steps": "min_control_steps",
                  "Max Control Steps": "max_control_steps", "Goal Bias": "goal_bias",
                  "Max Speed": "max_speed", "_Max Planning Time": "time_limit"}
"""The ODE planners' parameters Odin's planning bridge uses (PlannerSearch field names)."""
PLANNER_GEOMETRIC = {"Range": "range", "Goal Bias": "goal_bias",
                     "_Max Planning Time": "time_limit", "Max Planning Time": "time_limit",
                     "Simplify Solution": "simplify", "_Simplify Solution": "simplify",
                     "MaxNearestNeighbors": "max_neighbours", "Max. Neighs": "max_neighbours",
                     "DistanceThreshold": "neighbour_distance",
                     "Neigh Thresshold": "neighbour_distance", "Max. Samples": "max_samples"}
"""The geometric planners' parameters Odin's geometric planning uses (gui.planning.geometric:
GeometricSettings field names)."""
_WHOLE_PARAMETERS = ("max_contacts", "min_control_steps", "max_control_steps",
                     "max_neighbours", "max_samples")

_ROBOT_CHILDREN = {
    "home": None, "limits": None, "kauthamname": None,
    "invkinematic": "Kautham's inverse kinematics; Odin has none of its own",
    "weightse3": "a planner's weights of the base in distances",
    "viewlink": "the link Kautham's view follows",
    "constraint": "a planner's constraint on the robot",
    "constrainedkinematic": "Kautham's constrained kinematics",
    "start": "Kautham 1's base pose, which Kautham 2 and later do not read: the robot stands at "
             "the query's <Init>, else at <Home> (the origin without one)",
    "goal": "Kautham 1's goal base pose, which Kautham 2 and later do not read (a query's "
            "<Goal> is the goal)",
}
_OBSTACLE_CHILDREN = {"home": None, "location": None, "collision": None, "kauthamname": None,
                      "limits": "an obstacle's control limits (obstacle controls are not "
                                "used)"}
_CAR_WHEELS = 3      # a car has at least this many wheels

_NOT_PROBLEMS = {
    "benchmark": "is a Kautham benchmark file (<Benchmark>: problems and planners to compare), "
                 "not a problem: `rosrun GUI benchmark` reads it",
    "config": "is a Kautham configuration file (<Config>: the files of a task-planning demo), "
              "not a problem",
}
"""Kautham's other XML files that mention <Problem>, by root element: the refusal says what
the file is."""


def load_problem(path: os.PathLike | str) -> Problem:
    """Reads a problem with every robot, obstacle and shape it references.

    Raises ``ProblemError`` (or its ``ShapeError`` subclass) naming the file and line of the
    first thing that cannot be read; nothing is returned half-loaded."""
    path = pathlib.Path(path)
    root = read_xml(path, "problem file")
    if root.tag != "Problem":
        raise root.error(_NOT_PROBLEMS.get(root.tag.lower(),
                                           f"expected a <Problem> element, found <{root.tag}>"))
    current = any(True for _ in root.findall("Obstacle")) or root.find("Controls") is not None \
        or any(pathlib.PurePath(r.get("robot") or "").suffix.lower() in (".urdf", ".dh")
               for r in root.findall("Robot"))
    loader = _Loader(path, root, SI if current else LEGACY, current)
    problem = loader.load()
    warn_once(problem.ignored, log.name)
    return problem


class _Names:
    """Unique names: the first keeps its name, the next get "_2", "_3"... (thesis 8.3)."""

    def __init__(self):
        self.used: set = set()

    def take(self, name: str) -> str:
        base = _NAME_BAD.sub("_", name.strip()) or "object"
        candidate, n = base, 1
        while candidate in self.used:
            n += 1
            candidate = f"{base}_{n}"
        self.used.add(candidate)
        return candidate


class _Loader:
    """One load: the problem's elements in file order, then controls, kinds and the query."""

    def __init__(self, path: pathlib.Path, root: Node, units: Units, current: bool):
        self.path, self.root, self.units, self.current = path, root, units, current
        self.names = _Names()
        self.instances: List[Instance] = []
        self.ignored: List[Ignored] = []
        self.cntr: Optional[ControlSet] = None
        self.controls_node: Optional[Node] = None
        self.planner: Optional[Planner] = None
        self.planner_node: Optional[Node] = None
        self.attachment_nodes: List[Node] = []

    def ignore(self, node: Node, what: str, why: str) -> None:
        self.ignored.append(Ignored(node.path, node.line, what, why))

    # -- elements ------------------------------------------------------------------------
    def load(self) -> Problem:
        for node in self.root.children:
            tag = node.tag.lower()
            if tag == "robot":
                self.instances.append(self._robot(node))
            elif tag == "scene":
                self.instances.append(self._obstacle(node, "scene", "Location"))
            elif tag == "obstacle":
                self.instances.append(self._obstacle(node, "obstacle", "Home"))
            elif tag == "controls":
                self._controls(node)
            elif tag == "planner":
                self.planner_node = node
            elif tag == "initialattachedobstacle":
                self.attachment_nodes.append(node)
            else:
                self.ignore(node, f"<{node.tag}>", "not an element of Kautham's problems")
        if not self.instances:
            raise self.root.error("has neither robots nor scene objects")
        robots = [i for i in self.instances if i.role == "robot"]
        if self.planner_node is not None:
            self.planner = self._planner(self.planner_node)
        self._assign_controls(robots)
        for robot in robots:
            robot.kind = self._kind(robot)
        if self.planner_node is not None:
            self._query(self.planner_node, robots)
        attachments = [self._attachment(node) for node in self.attachment_nodes]
        for inst in self.instances:
            self.ignored.extend(inst.model.ignored)
        return Problem(source=str(self.path), format="current" if self.current else "2012",
                       instances=self.instances, planner=self.planner,
                       attachments=attachments, ignored=self.ignored)

    def _robot(self, node: Node) -> Instance:
        rel = node.require("robot")
        file = _resolve(rel, node, self.path, self.current)
        model = _read_model(file, _scale(node), self.units, node)
        renamed = node.find("KauthamName")
        if renamed is not None:
            model.name = renamed.require("name").strip() or model.name
        self._ignore_children(node, _ROBOT_CHILDREN)
        return Instance(name=self.names.take(model.name), role="robot", model=model,
                        base_pose=_pose(node.find("Home"), self.units, self.ignored),
                        movable=True,
                        source=str(self.path), line=node.line, limits=self._limits(node))

    def _limits(self, node: Node) -> dict:
        """{"X" | "Y" | "Z": (min, max) m}; other <Limits> (the 2012 WX..TH) are listed."""
        out, other = {}, []
        for lim in node.findall("Limits"):
            name = (lim.get("name") or "").strip()
            if name in ("X", "Y", "Z"):
                low, high = (float(v) for v in lim.scaled_lengths(
                    f"<Limits name=\"{name}\"> min max", (lim.number("min"), lim.number("max")),
                    self.units.length))
                if low > high:
                    raise lim.error(f"min={lim.get('min')} is above max={lim.get('max')}")
                out[name] = (low, high)
            else:
                other.append(lim)
        if other:
            self.ignore(other[0], "<Limits name=\"" + "|".join(
                (lim.get("name") or "").strip() for lim in other) + "\">", "only the base's "
                "X, Y and Z limits map controls (its orientation comes from X1..X3)")
        return out

    def _ignore_children(self, node: Node, known: dict) -> None:
        for child in node.children:
            why = known.get(child.tag.lower(), "an element Odin does not know")
            if why is not None:
                self.ignore(child, f"<{node.tag}> <{child.tag}>", why)

    def _obstacle(self, node: Node, attr: str, pose_tag: str) -> Instance:
        rel = node.require(attr)
        file = _resolve(rel, node, self.path, self.current)
        model = _read_model(file, _scale(node), self.units, node)
        renamed = node.find("KauthamName")
        if renamed is not None:
            model.name = renamed.require("name").strip() or model.name
        if model.kind == "rob":
            movable = True               # a scene that is a robot: a movable obstacle
        elif model.kind == "urdf":
            movable = any(link.mass is not None for link in model.links)
        else:
            movable = False
        if node.get("movable") is not None:
            movable = node.flag("movable", movable)
        collision = True
        col = node.find("Collision")
        for attribute in ("enabled", "Enable") if col is not None else ():
            if col.get(attribute) is not None:     # current spelling, then the 2012 one
                collision = col.flag(attribute, True)
                break
        pose_node = node.find(pose_tag)
        if pose_node is None and pose_tag == "Location":
            pose_node = node.find("Home")       # a 2012 .rob scene is placed by its <Home>
        self._ignore_children(node, _OBSTACLE_CHILDREN)
        return Instance(name=self.names.take(file.stem), role="obstacle", model=model,
                        base_pose=_pose(pose_node, self.units, self.ignored), movable=movable,
                        collision=collision, source=str(self.path), line=node.line)

    def _controls(self, node: Node) -> None:
        """The first <Controls>, as Kautham reads it (``child("Controls")``); a later one is
        listed as ignored."""
        if self.controls_node is not None:
            self.ignore(node, "a second <Controls>", f"Kautham reads the first only (line "
                        f"{self.controls_node.line})")
            return
        self.controls_node = node
        if node.get("obstacle"):
            self.ignore(node, f"<Controls obstacle=\"{node.get('obstacle')}\">",
                        "obstacle controls: Odin does not move obstacles by controls")
        rel = node.get("robot")
        if rel:
            self.cntr = read_cntr(_resolve(rel, node, self.path, self.current))

    # -- controls and kinds ---------------------------------------------------------------
    def _assign_controls(self, robots: List[Instance]) -> None:
        if self.cntr is not None:
            for robot in robots:
                robot.controls = control_map(robot, self.cntr, prefixed=True, robots=robots)
                robot.model.controls = self.cntr
            return
        if self.current:
            default = default_control_set(robots)
            for robot in robots:
                robot.controls = control_map(robot, default, prefixed=True)
            return
        for robot in robots:                 # 2012: each .rob's own set, over its controls
            own = robot.model.controls
            if own is None and robot.model.kind == "shape":
                own = free_flyer_control_set()
            if own is not None:
                try:
                    robot.controls = control_map(robot, own, prefixed=False,
                                                 offset_default=LEGACY_OFFSET_DEFAULT)
                except ProblemError as error:
                    self.ignored.append(Ignored(error.path or "", error.line,
                                                "<ControlSet>", error.reason))

    def _kind(self, robot: Instance) -> str:
        model = robot.model
        if len(model.links) == 1:
            return FREE_BODY
        planned = PHYSICS_PLANNERS.get(self.planner.name) if self.planner else None
        if planned == CAR or is_car(model):
            return CAR
        if planned == FIXED_BASE:
            return FIXED_BASE
        if model.free_base or self._controls_move_base(robot):
            return MOBILE
        return FIXED_BASE

    def _controls_move_base(self, robot: Instance) -> bool:
        """Whether the robot's controls move its base (Kautham's se3Enabled): a current
        problem's .cntr, or a 2012 .rob's own <ControlSet>, naming X, Y, Z, X1, X2 or X3 in
        a control or the offset (2012 Robot::setControlSet)."""
        if robot.controls is None or not robot.controls.se3:
            return False
        return self.cntr is not None if self.current else True

    # -- the planner and the query ------------------------------------------------------------
    def _planner(self, node: Node) -> Planner:
        parameters = node.find("Parameters")
        if parameters is None:
            self.ignore(node, "<Planner>", "no <Parameters>: no planner named")
            return Planner("", False, source=node.path, line=node.line)
        name_node = parameters.find("Name")
        name = name_node.text.strip() if name_node is not None else ""
        physics = name in PHYSICS_PLANNERS
        values, search, geometric, unused = {}, {}, {}, []
        for parameter in parameters.findall("Parameter"):
            pname = (parameter.get("name") or "").strip()
            field = PLANNER_PHYSICS.get(pname, PLANNER_SEARCH.get(pname)) if physics else \
                PLANNER_GEOMETRIC.get(pname)
            if field is None:
                unused.append(pname)
                continue
            try:
                value = parse_text_number(parameter)
            except ProblemError:
                if self.current and physics:    # a physics setting Odin cannot read
                    raise
                unused.append(pname)
                continue
            value = _planner_parameter(parameter, pname, field, value)
            if not physics:
                geometric[field] = value
                continue
            (values if pname in PLANNER_PHYSICS else search)[field] = value
        if unused:
            self.ignore(parameters, f"planner {name or '(unnamed)'} parameters "
                        + ", ".join(f'"{u}"' for u in unused),
                        "Odin's planning bridge sets these up itself (gui.planning)" if physics
                        else "Kautham's display settings (Speed Factor: the path samples its "
                        "GUI's animation advances per frame), samplers or costs, which Odin's "
                        "geometric planning does not have (gui.planning.geometric)")
        for child in parameters.children:
            if child.tag.lower() == "localplanner":
                self.ignore(child, "<Parameters> <LocalPlanner>", "Kautham 2012's local "
                            "planner's step: Odin checks every motion all along, to its "
                            "resolution (gui.planning.geometric_world)")
            elif child.tag.lower() not in ("name", "parameter"):
                self.ignore(child, f"<Parameters> <{child.tag}>", "a planner's setting")
        if name and not physics:
            self.ignore(name_node, f"planner {name}", "not one of Kautham's ODE planners: "
                        "the problem is built without Kautham's physics (no ground, "
                        "obstacles with a mass only are bodies)")
        return Planner(name, physics, PlannerPhysics(**values), PlannerSearch(**search),
                       tuple(geometric.items()), node.path, parameters.line)

    def _query(self, planner: Node, robots: List[Instance]) -> None:
        queries = planner.find("Queries")
        found = list(queries.findall("Query")) if queries is not None else []
        if not found:
            return
        for extra in found[1:]:
            self.ignore(extra, "a second <Query>", "the problem is built at the first query's "
                        "start (Kautham's)")
        try:
            self._first_query(found[0], robots)
        except ProblemError as error:
            if self.current:
                raise
            self.ignored.append(Ignored(error.path or "", error.line, "<Query>",
                                        f"cannot be used: {error.reason}"))

    def _first_query(self, query: Node, robots: List[Instance]) -> None:
        """Each robot's start and goal from the query's control vectors. A current problem
        has one control set for all its robots (a .cntr file, or Kautham's default one), so
        every robot maps the whole vector; in a 2012 problem each robot has its own set and the
        vector is theirs end to end, in robot order (Kautham 2012's
        ``WorkSpace::moveRobotsTo``: robot i takes the next ``getNumControls()`` values)."""
        mapped = control_parts(robots, legacy=not self.current)
        if not mapped:
            self.ignore(query, "<Query>", "no robot has controls to map it through")
            return
        if self.current:
            names = mapped[0][0].controls.names
        else:
            names = tuple(n for r, _ in mapped for n in r.controls.names)
        size = len(names)
        init = goal = None
        for child in query.children:
            tag = child.tag.lower()
            if tag in ("init", "goal"):
                values = parse_text_numbers(child)
                if not self.current:
                    _check_dim(child, len(values))
                if len(values) != size:
                    raise child.error(f"<{child.tag}> has {len(values)} values, the controls "
                                      f"are {size} ({', '.join(names)})")
                if tag == "init":
                    init = values
                else:
                    goal = values
            elif tag == "robotcontrol":
                init, goal = self._robot_control(child, names, init, goal)
            else:
                self.ignore(child, f"<Query> <{child.tag}>", "obstacle controls: Odin does "
                            "not move obstacles by controls")
        for robot, part in mapped:
            if init is not None:
                robot.start = robot.controls.configuration(robot, _fill(init)[part])
            if goal is not None:
                robot.goal = robot.controls.configuration(robot, _fill(goal)[part])

    def _robot_control(self, node: Node, names, init, goal):
        name = node.require("name").strip()
        if name not in names:
            raise node.error(f"RobotControl \"{name}\" is not a control of the control file "
                             f"({', '.join(names)})")
        k = names.index(name)
        init = list(init) if init is not None else [None] * len(names)
        goal = list(goal) if goal is not None else [None] * len(names)
        init[k] = node.number("init")
        goal[k] = node.number("goal")
        return init, goal

    def _attachment(self, node: Node) -> Attachment:
        robot_name, link_name, obstacle_name = (node.require(a).strip()
                                                for a in ("robot", "link", "obstacle"))
        robot = next((i for i in self.instances if i.role == "robot"
                      and robot_name in (i.name, i.model.name)), None)
        if robot is None:
            raise node.error(f"no robot named \"{robot_name}\" to attach to")
        if link_name not in [link.name for link in robot.model.links]:
            raise node.error(f"robot \"{robot_name}\" has no link \"{link_name}\"")
        obstacle = next((i for i in self.instances if i.role == "obstacle"
                         and obstacle_name in (i.name, i.model.name)), None)
        if obstacle is None:
            raise node.error(f"no obstacle named \"{obstacle_name}\" to attach")
        return Attachment(robot.name, link_name, obstacle.name, node.path, node.line)


def _fill(values) -> list:
    """A control vector from <RobotControl> elements: a control not given is 0 (Kautham's)."""
    return [0.0 if v is None else float(v) for v in values]


def _planner_parameter(node: Node, name: str, field: str, value: float):
    """A planner parameter's value, checked: the counts whole numbers >= 1 (Max Contacts,
    Min/Max Control Steps), Goal Bias in [0, 1], a speed or time positive."""
    if field in _WHOLE_PARAMETERS:
        if value != int(value) or value < 1:
            raise node.error(f"{name} {node.text.strip()!r} is not a whole number >= 1")
        return int(value)
    if field == "goal_bias" and not 0.0 <= value <= 1.0:
        raise node.error(f"Goal Bias {node.text.strip()!r} is not in [0, 1]")
    if field in ("max_speed", "time_limit", "range", "neighbour_distance") and not value > 0.0:
        raise node.error(f"{name} {node.text.strip()!r} is not positive")
    return value


def parse_text_number(node: Node) -> float:
    values = parse_text_numbers(node)
    if len(values) != 1:
        raise node.error(f"<{node.tag}> holds {len(values)} numbers, expected one")
    return values[0]


def _check_dim(node: Node, count: int) -> None:
    """Kautham 2012 reads a query's ``<Init>`` or ``<Goal>`` only when its dim= is its count
    of values (``Problem::createCSpaceFromFile``; the count is then checked against the
    controls). A dim= that is not a whole number is read past, as Odin reads the corpus's
    other quirks in values nothing else uses, and so is a missing one (Kautham 2012 would
    refuse it; problems written by hand leave it out)."""
    declared = (node.get("dim") or "").strip()
    if declared.isdigit() and int(declared) != count:
        raise node.error(f'<{node.tag} dim="{declared}"> has {count} values (Kautham 2012 '
                         "reads a query whose dim= is its count of values)")


def parse_text_numbers(node: Node) -> list:
    """The numbers an element's text holds (spaces between them)."""
    return [parse_number(t, f"<{node.tag}>", node.path, node.line) for t in node.text.split()]


def default_control_set(robots: List[Instance]) -> ControlSet:
    """Kautham's controls when a problem names no control file (``setDefaultRobotControls``):
    per robot, one control for each of X, Y, Z whose limits differ, X1, X2, X3 and each
    movable joint, in that order, each moving its DOF by 1 from 0.5."""
    controls = []
    for robot in robots:
        dofs = [a for a in ("X", "Y", "Z")
                if robot.limits.get(a, (0.0, 0.0))[0] != robot.limits.get(a, (0.0, 0.0))[1]]
        dofs += list(BASE_DOFS[3:])
        dofs += [robot.model.links[i].name for i in robot.model.movable_links()]
        controls += [Control(f"{robot.name}/{d}", 1.0, {f"{robot.name}/{d}": 1.0})
                     for d in dofs]
    return ControlSet(offset={}, controls=controls, source="(Kautham's default controls)")


def is_car(model: RobotModel) -> bool:
    """A base on wheels: at least three revolute joints, all on the base link, about axes
    horizontal in the base frame, and no other movable joint."""
    movable = model.movable_links()
    if len(movable) < _CAR_WHEELS:
        return False
    for i in movable:
        link = model.links[i]
        if link.parent != 0 or link.joint != REVOLUTE:
            return False
        axis = link.pre[:3, :3] @ link.axis
        if abs(axis[2]) > 0.1:
            return False
    return True


def _resolve(rel: str, node: Node, problem: pathlib.Path, current: bool) -> pathlib.Path:
    candidates = []
    if current:
        for folder in [problem.parent, *problem.parent.parents]:
            candidates.append(folder / "models" / rel)
    candidates.append(problem.parent / rel)
    for c in candidates:
        if os.path.lexists(c):    # the first there, whatever it is: its reader says if it
            return c              # is not a file (a FIFO, a device, a link loop)
    # every folder, in the order searched: the last one, beside the problem, is where a
    # problem's other files usually are, so a shortened list would hide it
    raise node.error(f"file \"{rel}\" not found (looked in: "
                     + ", ".join(str(c.parent) for c in candidates) + ")")


def _pose(node: Optional[Node], units: Units, ignored: List[Ignored]) -> np.ndarray:
    """The world pose (4, 4; m) of a ``<Home>`` or ``<Location>``: X Y Z, then the rotation
    TH about WX WY WZ.

    An angle about a zero axis is no rotation, as in Kautham: its
    ``SE3Conf::fromAxisToQuaternion`` (src/sampling/se3conf.cpp) multiplies the axis by
    sin(TH/2), which leaves the quaternion's vector part zero. Such a TH is listed in
    ``ignored`` (it says nothing)."""
    if node is None:
        return np.eye(4)
    position = node.scaled_lengths(f"<{node.tag}> X Y Z",
                                   [node.number(c, 0.0) for c in ("X", "Y", "Z")], units.length)
    axis = [node.number(c, 0.0) for c in ("WX", "WY", "WZ")]
    angle = node.number("TH", 0.0) * units.angle
    if angle != 0.0 and not any(axis):
        ignored.append(Ignored(node.path, node.line, f"<{node.tag} TH=\"{node.get('TH')}\">",
                               "a rotation about the zero axis WX WY WZ: no rotation, as "
                               "in Kautham (its quaternion has a zero vector part)"))
        angle = 0.0
    return pose_from_axis_angle(position, axis if any(axis) else (0, 0, 1), angle)


def _scale(node: Node) -> float:
    scale = node.number("scale", 1.0)
    problem = scale_problem(scale)
    if problem is not None:
        raise node.error(f"<{node.tag} scale={shown(node.get('scale'))}> {problem}")
    return scale


def _read_model(file: pathlib.Path, scale: float, units: Units, node: Node) -> RobotModel:
    suffix = file.suffix.lower()
    if suffix in (".rob", ".dh"):
        return read_dh_robot(file, scale)
    if suffix == ".urdf":
        return read_urdf(file, scale)
    if suffix in COIN_SUFFIXES or suffix in TRIMESH_SUFFIXES:
        return read_shape_robot(file, scale, units)
    raise node.error(f"unknown kind of model file \"{file.name}\"")


__all__ = ["load_problem", "PHYSICS_PLANNERS", "PLANNER_PHYSICS", "default_control_set",
           "is_car", "parse_text_numbers"]
