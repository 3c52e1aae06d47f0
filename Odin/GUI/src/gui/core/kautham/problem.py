"""Kautham problem files, 2012 and current, into a ``gui.core.model.Problem`` (SI units).

2012 format (the thesis's)::

    <Problem> <Robot robot="x.rob|x.iv" scale> <Home X Y Z WX WY WZ TH/> <Limits/>... </Robot>
              <Scene scene="x.iv|x.wrl|x.rob" scale> <Location .../> <Collision Enable/> </Scene>
              <Planner>...</Planner> </Problem>

Home and Location positions are in mm and TH in degrees; a robot file that is a bare shape is a
free-flying robot; a scene that is a .rob is a movable obstacle, any other scene a static one.
Paths are relative to the problem file.

Current format (Kautham 5): ``<Robot robot="x.urdf|x.dh" scale>`` and
``<Obstacle obstacle="x.urdf|x.iv" scale>``, both placed by ``<Home>`` in m and rad;
``<Controls robot="x.cntr"/>``. Model files are looked up in a ``models`` folder beside the
problem or any folder above it (Kautham's demos/models), then beside the problem. An obstacle
is a movable body when its URDF gives a mass, static geometry otherwise.

A file is of the current format when it has ``<Obstacle>`` or ``<Controls>`` elements or a
.urdf/.dh robot. ``<Planner>``, ``<Queries>``, ``<Limits>``, ``<InvKinematic>``, ``<Start>``
and ``<Goal>`` are read past: Odin does not use them, and a quirk there never stops a load.
"""
from __future__ import annotations

import os
import pathlib
import re
from typing import Optional

import numpy as np

from gui.errors import ProblemError
from gui.core.kautham.controls import read_cntr
from gui.core.kautham.robot_rob import read_dh_robot, read_shape_robot
from gui.core.kautham.units import LEGACY, SI, Units
from gui.core.kautham.urdf import read_urdf
from gui.core.kautham.xmlfile import Node, read_xml
from gui.core.kinematics import pose_from_axis_angle
from gui.core.model import Instance, Problem, RobotModel
from gui.core.shapes import COIN_SUFFIXES, TRIMESH_SUFFIXES

_NAME_BAD = re.compile(r"[>&]")


def load_problem(path: os.PathLike | str) -> Problem:
    """Reads a problem with every robot, obstacle and shape it references.

    Raises ``ProblemError`` (or its ``ShapeError`` subclass) naming the file and line of the
    first thing that cannot be read; nothing is returned half-loaded."""
    path = pathlib.Path(path)
    root = read_xml(path, "problem file")
    if root.tag != "Problem":
        raise root.error(f"expected a <Problem> element, found <{root.tag}>")
    current = any(True for _ in root.findall("Obstacle")) or root.find("Controls") is not None \
        or any(pathlib.PurePath(r.get("robot") or "").suffix.lower() in (".urdf", ".dh")
               for r in root.findall("Robot"))
    units = SI if current else LEGACY
    names = _Names()
    instances: list[Instance] = []
    robots = []
    for node in root.children:
        tag = node.tag.lower()
        if tag == "robot":
            inst = _robot(node, path, units, current, names)
            robots.append(inst)
            instances.append(inst)
        elif tag == "scene":
            instances.append(_obstacle(node, "scene", "Location", path, units, current, names))
        elif tag == "obstacle":
            instances.append(_obstacle(node, "obstacle", "Home", path, units, current, names))
        elif tag == "controls":
            _controls(node, path, robots, current)
    if not robots and not instances:
        raise root.error("has neither robots nor scene objects")
    return Problem(source=str(path), format="current" if current else "2012",
                   instances=instances)


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


def _resolve(rel: str, node: Node, problem: pathlib.Path, current: bool) -> pathlib.Path:
    candidates = []
    if current:
        for folder in [problem.parent, *problem.parent.parents]:
            candidates.append(folder / "models" / rel)
    candidates.append(problem.parent / rel)
    for c in candidates:
        if c.is_file():
            return c
    raise node.error(f"file \"{rel}\" not found (looked in: "
                     + ", ".join(str(c.parent) for c in candidates[:3])
                     + (", ..." if len(candidates) > 3 else "") + ")")


def _pose(node: Optional[Node], units: Units) -> np.ndarray:
    if node is None:
        return np.eye(4)
    position = [node.number(c, 0.0) * units.length for c in ("X", "Y", "Z")]
    axis = [node.number(c, 0.0) for c in ("WX", "WY", "WZ")]
    angle = node.number("TH", 0.0) * units.angle
    if angle != 0.0 and not any(axis):
        raise node.error("TH is not zero but the axis WX WY WZ is")
    return pose_from_axis_angle(position, axis if any(axis) else (0, 0, 1), angle)


def _scale(node: Node) -> float:
    scale = node.number("scale", 1.0)
    if scale <= 0:
        raise node.error(f"scale=\"{node.get('scale')}\" must be positive")
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


def _robot(node: Node, problem: pathlib.Path, units: Units, current: bool,
           names: _Names) -> Instance:
    rel = node.require("robot")
    file = _resolve(rel, node, problem, current)
    model = _read_model(file, _scale(node), units, node)
    return Instance(name=names.take(model.name), role="robot", model=model,
                    base_pose=_pose(node.find("Home"), units), movable=True,
                    source=str(problem), line=node.line)


def _obstacle(node: Node, attr: str, pose_tag: str, problem: pathlib.Path, units: Units,
              current: bool, names: _Names) -> Instance:
    rel = node.require(attr)
    file = _resolve(rel, node, problem, current)
    model = _read_model(file, _scale(node), units, node)
    if model.kind == "rob":
        movable = True               # a scene that is a robot: a movable obstacle
    elif model.kind == "urdf":
        movable = any(link.mass is not None for link in model.links)
    else:
        movable = False
    collision = True
    col = node.find("Collision")
    if col is not None:
        collision = col.flag("Enable", True)
    return Instance(name=names.take(file.stem), role="obstacle", model=model,
                    base_pose=_pose(node.find(pose_tag), units), movable=movable,
                    collision=collision, source=str(problem), line=node.line)


def _controls(node: Node, problem: pathlib.Path, robots: list, current: bool) -> None:
    rel = node.get("robot")
    if not rel:
        return  # obstacle controls: Odin does not use them
    file = _resolve(rel, node, problem, current)
    controls = read_cntr(file)
    if robots:
        robots[0].model.controls = controls
